/* forces.c - forces and torques for the next step (the solver integrates
 * them: linear acceleration f / m, angular momentum + torque h per
 * sub-step), force thresholds and the contact force events. */
#include "body_args.h"
#include "deferred.h"
#include "events.h"
#include "forces.h"
#include "ranges.h"

/* The torque's angular acceleration I^-1 tau, bounded as a force's f / m is. */
static carom_status add_torque(carom_world *w, int slot, vec3 torque, const char *fn)
{
    body_store *s = &w->bodies;
    vec3 total = v3_add(s->torque[slot], torque);
    double alpha = v3_len(m3_mulv(s->inv_inertia_world[slot], total));
    if (!(alpha <= RANGE_ACCELERATION_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "%s: the body's total torque %g N m gives an angular acceleration above 1e9 rad/s^2", fn,
                          v3_len(total));
    s->torque[slot] = total;
    s->flags[slot] |= BODY_HAS_FORCE;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_apply_torque(carom_world *w, carom_body_id id, carom_vec3 torque)
{
    const char *fn = "body_apply_torque";
    SLOT_OR_FAIL(fn);
    if (w->in_callback) return world_defer_op(w, DEFER_TORQUE, id, torque, NULL, fn);
    UNLOCKED_OR_FAIL(fn);
    if (!args_finite(torque)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: torque must be finite", fn);
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC || (s->flags[slot] & BODY_LOCK_ROTATION)) return CAROM_OK;
    carom_status st = add_torque(w, slot, args_v3(torque), fn);
    if (st == CAROM_OK) world_wake_body(w, slot);
    return st;
}

CAROM_API carom_status carom_body_apply_force_at_point(carom_world *w, carom_body_id id, carom_vec3 force,
                                                       carom_vec3 point)
{
    const char *fn = "body_apply_force_at_point";
    SLOT_OR_FAIL(fn);
    if (w->in_callback) return world_defer_op(w, DEFER_FORCE_AT_POINT, id, force, &point, fn);
    UNLOCKED_OR_FAIL(fn);
    if (!args_finite(force)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: force must be finite", fn);
    if (!args_finite(point)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: point must be finite", fn);
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC) return CAROM_OK;
    vec3 f = args_v3(force), arm_torque = v3_cross(v3_sub(args_v3(point), s->center[slot]), f);
    if (!v3_is_finite(arm_torque))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: the torque about the centre of mass is not finite", fn);
    /* both parts checked before either is kept: a refused call changes nothing */
    vec3 old_force = s->force[slot], old_torque = s->torque[slot];
    uint32_t old_flags = s->flags[slot];
    carom_status st = carom_body_apply_force(w, id, force);
    if (st == CAROM_OK && !(s->flags[slot] & BODY_LOCK_ROTATION)) st = add_torque(w, slot, arm_torque, fn);
    if (st != CAROM_OK) {
        s->force[slot] = old_force;
        s->torque[slot] = old_torque;
        s->flags[slot] = old_flags;
    }
    return st;
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

/* The lower positive threshold of the two, or 0 when neither asks. */
static double pair_threshold(double a, double b)
{
    if (a > 0 && b > 0) return a < b ? a : b;
    return a > 0 ? a : b;
}

void forces_raise_events(carom_world *w, const contact_constraint *constraints, int count, double dt)
{
    const body_store *s = &w->bodies;
    /* Most worlds set no threshold: one sequential pass over the bodies is
     * cheaper than visiting every constraint's two bodies at random. */
    int any = 0;
    for (int i = 0; i < s->count && !any; i++) any = s->force_threshold[i] > 0;
    if (!any) return;
    for (int k = 0; k < count; k++) {
        const contact_constraint *con = &constraints[k];
        const contact *c = &w->contacts.items[con->contact];
        int sa = s->ids[c->id_a].slot, sb = s->ids[c->id_b].slot;
        double threshold = pair_threshold(s->force_threshold[sa], s->force_threshold[sb]);
        if (!(threshold > 0)) continue;
        double total = 0.0;
        vec3 weighted = v3_zero();
        for (int j = 0; j < con->count; j++) {
            double impulse = dmax(con->p[j].total_normal_impulse, 0.0);
            total += impulse;
            weighted = v3_madd(weighted, impulse, con->m->points[j].point);
        }
        double force = total / dt;
        if (!(force > threshold)) continue;
        events_force(w, con->contact, force * dt, force, v3_scale(weighted, 1.0 / total));
    }
}
