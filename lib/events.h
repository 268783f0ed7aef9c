/* events.h - the contact events of a step, built here and nowhere else: the
 * collision stage reports touches, the solver impacts, the sensor stage
 * overlaps. */
#ifndef CAROM_EVENTS_H
#define CAROM_EVENTS_H

#include "carom/carom.h"
#include "constraint.h"
#include "vecmath.h"

/* A begin or end event for contact contact_index (its first point, its
 * normal). 0 on out of memory (the event is dropped). */
int events_touch(carom_world *w, int contact_index, carom_event_type type);
/* A hit event for contact contact_index: at its point `point` along the
 * manifold normal, with the step's normal and friction impulse magnitudes
 * and the approach speed; average force over dt. */
int events_hit(carom_world *w, int contact_index, int point, double normal_impulse, double tangent_impulse,
               double approach_speed, double dt);
/* A force event for contact contact_index: the step's total normal
 * impulse, its average force and the centre of pressure. */
int events_force(carom_world *w, int contact_index, double normal_impulse, double force, vec3 point);
/* After the solve: a FORCE event for each solved pair whose total normal
 * force over the step (the points' impulses summed over every pass, / dt)
 * exceeds the lower positive force_threshold of its two bodies. */
void events_raise_forces(carom_world *w, const contact_constraint *constraints, int count, double dt);
/* A sensor event (sensor.c): b is the body that began or ended overlapping
 * sensor a; point its centre of mass (zero when it is gone). */
int events_sensor(carom_world *w, carom_event_type type, carom_body_id sensor, carom_body_id other, carom_vec3 point);

#endif
