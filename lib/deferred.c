/* deferred.c - velocity changes from event callbacks, applied after them
 * (see deferred.h). Each op runs exactly once, through the same checked
 * change (body_motion.c) the public entry makes outside the step. */
#include "array.h"
#include "body_motion.h"
#include "deferred.h"

carom_status world_defer_op(carom_world *w, deferred_kind kind, carom_body_id id, carom_vec3 value,
                            const carom_vec3 *point, const char *fn)
{
    if (!(isfinite(value.x) && isfinite(value.y) && isfinite(value.z)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: the vector must be finite", fn);
    if (point && !(isfinite(point->x) && isfinite(point->y) && isfinite(point->z)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: point must be finite", fn);
    step_scratch *s = &w->scratch;
    if (!array_reserve((void **)&s->deferred_ops, &s->deferred_op_capacity, s->deferred_op_count + 1,
                       sizeof *s->deferred_ops))
        return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    deferred_op *op = &s->deferred_ops[s->deferred_op_count++];
    op->kind = kind;
    op->id = id;
    op->value = value;
    op->has_point = point != NULL;
    if (point) op->point = *point;
    return CAROM_OK;
}

void world_run_deferred_ops(carom_world *w)
{
    step_scratch *s = &w->scratch;
    /* ops never queue more ops: the world is unlocked and out of its callbacks */
    for (int i = 0; i < s->deferred_op_count; i++) {
        deferred_op op = s->deferred_ops[i];
        int slot = body_store_slot(&w->bodies, op.id.index1, op.id.generation);
        if (slot < 0) continue; /* destroyed since */
        switch (op.kind) {
        case DEFER_IMPULSE: motion_apply_impulse(w, slot, op.value, op.has_point ? &op.point : NULL); break;
        case DEFER_ANGULAR_IMPULSE: motion_apply_angular_impulse(w, slot, op.value); break;
        case DEFER_LINEAR_VELOCITY: motion_set_linear_velocity(w, slot, op.value); break;
        case DEFER_ANGULAR_VELOCITY: motion_set_angular_velocity(w, slot, op.value); break;
        case DEFER_FORCE: motion_apply_force(w, slot, op.value); break;
        case DEFER_TORQUE: motion_apply_torque(w, slot, op.value); break;
        case DEFER_FORCE_AT_POINT: motion_apply_force_at_point(w, slot, op.value, op.point); break;
        }
    }
    s->deferred_op_count = 0;
}
