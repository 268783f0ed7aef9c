/* impact.h - the collision phase of the step: impacts resolved at the
 * geometry of the moment of contact, in order, before the contact solve. */
#ifndef CAROM_IMPACT_H
#define CAROM_IMPACT_H

#include "constraint.h"

/* Resolves this step's impacts on the step's starting velocities (bodies[]):
 * each manifold with restitution whose bodies touch, or will touch within dt
 * along their motion, gets the seed's collision impulse (restitution along
 * the normal, Coulomb friction) at the point and normal of the moment it
 * touches; impacts are repeated in order until no pair approaches (the
 * propagation model), so momentum passes through chains and racks. Records
 * what each body travelled before its impact for impact_finish. Returns 0 on
 * out of memory (nothing was changed). */
/* impact.c's memory, kept between steps in the world's scratch. */
typedef struct impact_memory {
    void *block;                 /* per-body states, then the pairs */
    size_t capacity;
    int bodies;                  /* solver bodies impact_resolve recorded, 0: none */
} impact_memory;
void impact_memory_free(impact_memory *m);

int impact_resolve(carom_world *w, contact_constraint *cc, int ncon, int nb, double dt);
/* After the sub-steps: each body that bounced travelled the whole step with
 * its post-impact velocity; correct it by what it travelled before the
 * impact with its old velocity, -dv tau dt, so it keeps the rest of the step
 * after the bounce instead of losing it. */
void impact_finish(carom_world *w, int nb);

/* Restitution threshold in effect for a contact: the user's threshold, but
 * no more than the approach speed a resting contact picks up from the
 * closing acceleration (gravity and forces) in two steps, so slow approaches
 * bounce where nothing pushes the bodies together. closing_acceleration < 0
 * means the bodies are pushed towards each other. */
static inline double impact_threshold(double threshold, double closing_acceleration, double dt)
{
    double resting = closing_acceleration < 0.0 ? -2.0 * closing_acceleration * dt : 0.0;
    return threshold < resting ? threshold : resting;
}

#endif
