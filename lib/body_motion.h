/* body_motion.h - velocity and force changes on a live body (body_motion.c).
 * `slot` is a live body's slot and the world is unlocked and out of its
 * callbacks (the caller has checked both); each checks its values, fails
 * with the public entry's message and leaves the body unchanged on error.
 * Called by the public entries of the same names (carom_body_...) and by
 * the replay of deferred.c. */
#ifndef CAROM_BODY_MOTION_H
#define CAROM_BODY_MOTION_H

#include "world.h"

carom_status motion_set_linear_velocity(carom_world *w, int slot, carom_vec3 v);
carom_status motion_set_angular_velocity(carom_world *w, int slot, carom_vec3 av);
/* point NULL: at the centre of mass */
carom_status motion_apply_impulse(carom_world *w, int slot, carom_vec3 j, const carom_vec3 *point);
carom_status motion_apply_angular_impulse(carom_world *w, int slot, carom_vec3 impulse);
/* Forces and torques are kept for the next step. */
carom_status motion_apply_force(carom_world *w, int slot, carom_vec3 force);
carom_status motion_apply_torque(carom_world *w, int slot, carom_vec3 torque);
carom_status motion_apply_force_at_point(carom_world *w, int slot, carom_vec3 force, carom_vec3 point);

#endif
