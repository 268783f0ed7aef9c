/* forces.c - forces and torques for the next step (the solver integrates
 * them: linear acceleration f / m, angular momentum + torque h per
 * sub-step) and the bodies' force thresholds (their events: events.c). */
#include "body_args.h"
#include "body_motion.h"
#include "deferred.h"
#include "ranges.h"

CAROM_API carom_status carom_body_apply_torque(carom_world *w, carom_body_id id, carom_vec3 torque)
{
    const char *fn = "body_apply_torque";
    SLOT_OR_FAIL(fn);
    if (w->in_callback) return world_defer_op(w, DEFER_TORQUE, id, torque, NULL, fn);
    UNLOCKED_OR_FAIL(fn);
    return motion_apply_torque(w, slot, torque);
}

CAROM_API carom_status carom_body_apply_force_at_point(carom_world *w, carom_body_id id, carom_vec3 force,
                                                       carom_vec3 point)
{
    const char *fn = "body_apply_force_at_point";
    SLOT_OR_FAIL(fn);
    if (w->in_callback) return world_defer_op(w, DEFER_FORCE_AT_POINT, id, force, &point, fn);
    UNLOCKED_OR_FAIL(fn);
    return motion_apply_force_at_point(w, slot, force, point);
}

CAROM_API carom_status carom_body_get_applied_force(const carom_world *w, carom_body_id id, carom_vec3 *force,
                                                    carom_vec3 *torque)
{
    const char *fn = "body_get_applied_force";
    SLOT_OR_FAIL(fn);
    if (!force && !torque) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: both outputs are NULL", fn);
    if (force) *force = args_c3(w->bodies.force[slot]);
    if (torque) *torque = args_c3(w->bodies.torque[slot]);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_force_threshold(carom_world *w, carom_body_id id, double threshold)
{
    const char *fn = "body_set_force_threshold";
    SLOT_OR_FAIL(fn);
    UNLOCKED_OR_FAIL(fn);
    if (!(isfinite(threshold) && threshold >= 0))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: threshold must be finite and >= 0 (N)", fn);
    w->bodies.force_threshold[slot] = threshold;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_force_threshold(const carom_world *w, carom_body_id id, double *out)
{
    const char *fn = "body_get_force_threshold";
    SLOT_OR_FAIL(fn);
    if (!out) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: output pointer is NULL", fn);
    *out = w->bodies.force_threshold[slot];
    return CAROM_OK;
}
