/* body_motion.c - velocity and force changes on a live body (see
 * body_motion.h): every check after the id lookup and the lock, with the
 * public entry's wording. The public entries (body_api.c, body_calls.c,
 * forces.c) and the replay of the changes queued inside callbacks
 * (deferred.c) both call these, so neither calls the other. */
#include "body_args.h"
#include "body_motion.h"
#include "ranges.h"

static double len_c(carom_vec3 v) { return sqrt(v.x * v.x + v.y * v.y + v.z * v.z); } /* inf when huge */
static int speed_ok(carom_vec3 v, double max) { return args_finite(v) && len_c(v) <= max; }

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

carom_status motion_set_linear_velocity(carom_world *w, int slot, carom_vec3 v)
{
    if (!args_finite(v)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_linear_velocity: velocity must be finite");
    if (!speed_ok(v, w->def.max_linear_speed))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "body_set_linear_velocity: speed %g m/s is above the world's max_linear_speed %g m/s", len_c(v),
                          w->def.max_linear_speed);
    body_store *s = &w->bodies;
    if (s->type[slot] == CAROM_BODY_STATIC)
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "body_set_linear_velocity: a static body cannot move");
    vec3 nv = args_v3(v);
    if (s->flags[slot] & BODY_LOCK_PLANE) nv = v3_madd(nv, -v3_dot(nv, s->plane_normal[slot]), s->plane_normal[slot]);
    s->velocity[slot] = nv;
    world_wake_body(w, slot);
    return CAROM_OK;
}

carom_status motion_set_angular_velocity(carom_world *w, int slot, carom_vec3 av)
{
    if (!args_finite(av)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_angular_velocity: must be finite");
    if (!speed_ok(av, world_spin_limit(&w->def)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "body_set_angular_velocity: speed %g rad/s is above the world's max_angular_speed %g rad/s",
                          len_c(av), world_spin_limit(&w->def));
    body_store *s = &w->bodies;
    if (s->type[slot] == CAROM_BODY_STATIC)
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "body_set_angular_velocity: a static body cannot move");
    vec3 nw = args_v3(av);
    if (s->flags[slot] & BODY_LOCK_ROTATION) nw = v3_zero();
    if (s->flags[slot] & BODY_LOCK_PLANE) nw = v3_scale(s->plane_normal[slot], v3_dot(nw, s->plane_normal[slot]));
    s->angular_velocity[slot] = nw;
    world_wake_body(w, slot);
    return CAROM_OK;
}

carom_status motion_apply_impulse(carom_world *w, int slot, carom_vec3 j, const carom_vec3 *point)
{
    if (!args_finite(j)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_apply_impulse: impulse must be finite");
    if (point && !args_finite(*point)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_apply_impulse: point must be finite");
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC) return CAROM_OK; /* infinite mass: no effect */
    vec3 jv = args_v3(j);
    vec3 dv = v3_scale(jv, s->inv_mass[slot]);
    vec3 dw = v3_zero();
    if (point) dw = m3_mulv(s->inv_inertia_world[slot], v3_cross(v3_sub(args_v3(*point), s->center[slot]), jv));
    vec3 nv = v3_add(s->velocity[slot], dv), nw = v3_add(s->angular_velocity[slot], dw);
    if (s->flags[slot] & BODY_LOCK_PLANE) {
        vec3 n = s->plane_normal[slot];
        nv = v3_madd(nv, -v3_dot(nv, n), n);
        nw = v3_scale(n, v3_dot(nw, n));
    }
    if (!v3_is_finite(nv) || !v3_is_finite(nw))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_apply_impulse: resulting velocity is not finite");
    if (v3_len(nv) > w->def.max_linear_speed)
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "body_apply_impulse: resulting speed %g m/s is above the world's max_linear_speed %g m/s",
                          v3_len(nv), w->def.max_linear_speed);
    if (v3_len(nw) > world_spin_limit(&w->def))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "body_apply_impulse: resulting spin %g rad/s is above the world's max_angular_speed %g rad/s",
                          v3_len(nw), world_spin_limit(&w->def));
    s->velocity[slot] = nv;
    s->angular_velocity[slot] = nw;
    world_wake_body(w, slot);
    return CAROM_OK;
}

carom_status motion_apply_force(carom_world *w, int slot, carom_vec3 force)
{
    if (!args_finite(force)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_apply_force: force must be finite");
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC) return CAROM_OK;
    vec3 total = v3_add(s->force[slot], args_v3(force));
    if (!(v3_len(total) * s->inv_mass[slot] <= RANGE_ACCELERATION_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "body_apply_force: the body's total force %g N over its mass %g kg is above 1e9 m/s^2",
                          v3_len(total), s->mass[slot]);
    s->force[slot] = total;
    s->flags[slot] |= BODY_HAS_FORCE;
    world_wake_body(w, slot);
    return CAROM_OK;
}

carom_status motion_apply_angular_impulse(carom_world *w, int slot, carom_vec3 impulse)
{
    const char *fn = "body_apply_angular_impulse";
    if (!args_finite(impulse)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: impulse must be finite", fn);
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC || (s->flags[slot] & BODY_LOCK_ROTATION)) return CAROM_OK;
    vec3 nw = v3_add(s->angular_velocity[slot], m3_mulv(s->inv_inertia_world[slot], args_v3(impulse)));
    if (s->flags[slot] & BODY_LOCK_PLANE) nw = v3_scale(s->plane_normal[slot], v3_dot(nw, s->plane_normal[slot]));
    if (!(v3_len(nw) <= world_spin_limit(&w->def)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "%s: resulting spin %g rad/s is above the world's max_angular_speed %g rad/s", fn, v3_len(nw),
                          world_spin_limit(&w->def));
    s->angular_velocity[slot] = nw;
    world_wake_body(w, slot);
    return CAROM_OK;
}

carom_status motion_apply_torque(carom_world *w, int slot, carom_vec3 torque)
{
    const char *fn = "body_apply_torque";
    if (!args_finite(torque)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: torque must be finite", fn);
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC || (s->flags[slot] & BODY_LOCK_ROTATION)) return CAROM_OK;
    carom_status st = add_torque(w, slot, args_v3(torque), fn);
    if (st == CAROM_OK) world_wake_body(w, slot);
    return st;
}

carom_status motion_apply_force_at_point(carom_world *w, int slot, carom_vec3 force, carom_vec3 point)
{
    const char *fn = "body_apply_force_at_point";
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
    carom_status st = motion_apply_force(w, slot, force);
    if (st == CAROM_OK && !(s->flags[slot] & BODY_LOCK_ROTATION)) st = add_torque(w, slot, arm_torque, fn);
    if (st != CAROM_OK) {
        s->force[slot] = old_force;
        s->torque[slot] = old_torque;
        s->flags[slot] = old_flags;
    }
    return st;
}
