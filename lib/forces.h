/* forces.h - the step's side of forces.c: contact force events. */
#ifndef CAROM_FORCES_H
#define CAROM_FORCES_H

#include "constraint.h"
#include "world.h"

/* After the solve: a FORCE event for each solved pair whose total normal
 * force over the step (the points' impulses summed over every pass, / dt)
 * exceeds the lower positive force_threshold of its two bodies. */
void forces_raise_events(carom_world *w, const contact_constraint *constraints, int count, double dt);

#endif
