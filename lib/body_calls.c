/* body_calls.c - the body calls a game reaches for beyond the basics:
 * angular impulses, damping after creation, frame conversions, the shape
 * back as a def, and the previous pose for interpolation. */
#include "body_args.h"
#include "body_motion.h"
#include "deferred.h"
#include "ranges.h"
#include "world.h"

CAROM_API carom_status carom_body_apply_angular_impulse(carom_world *w, carom_body_id id, carom_vec3 impulse)
{
    const char *fn = "body_apply_angular_impulse";
    SLOT_OR_FAIL(fn);
    if (w->in_callback) return world_defer_op(w, DEFER_ANGULAR_IMPULSE, id, impulse, NULL, fn);
    UNLOCKED_OR_FAIL(fn);
    return motion_apply_angular_impulse(w, slot, impulse);
}

CAROM_API carom_status carom_body_set_damping(carom_world *w, carom_body_id id, double linear, double angular)
{
    const char *fn = "body_set_damping";
    SLOT_OR_FAIL(fn);
    UNLOCKED_OR_FAIL(fn);
    if (!(isfinite(linear) && linear >= 0 && linear <= RANGE_DAMPING_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: linear damping %g is outside [0, 1e6] 1/s", fn, linear);
    if (!(isfinite(angular) && angular >= 0 && angular <= RANGE_DAMPING_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: angular damping %g is outside [0, 1e6] 1/s", fn, angular);
    w->bodies.linear_damping[slot] = linear;
    w->bodies.angular_damping[slot] = angular;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_damping(const carom_world *w, carom_body_id id, double *linear, double *angular)
{
    const char *fn = "body_get_damping";
    SLOT_OR_FAIL(fn);
    if (!linear && !angular) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: both outputs are NULL", fn);
    if (linear) *linear = w->bodies.linear_damping[slot];
    if (angular) *angular = w->bodies.angular_damping[slot];
    return CAROM_OK;
}

/* Frame conversions of the body origin frame (as position/orientation). */
static carom_status convert(const carom_world *w, carom_body_id id, carom_vec3 in, carom_vec3 *out, int to_world,
                            int is_point, const char *fn)
{
    SLOT_OR_FAIL(fn);
    OUT_OR_FAIL(out, fn);
    if (!args_finite(in)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: the vector must be finite", fn);
    xform x = body_xform(&w->bodies, slot);
    vec3 v = args_v3(in);
    if (is_point) *out = args_c3(to_world ? xf_point(x, v) : xf_inv_point(x, v));
    else *out = args_c3(to_world ? q_rotate(x.q, v) : q_inv_rotate(x.q, v));
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_world_point(const carom_world *w, carom_body_id id, carom_vec3 local, carom_vec3 *out)
{
    return convert(w, id, local, out, 1, 1, "body_get_world_point");
}
CAROM_API carom_status carom_body_get_local_point(const carom_world *w, carom_body_id id, carom_vec3 world, carom_vec3 *out)
{
    return convert(w, id, world, out, 0, 1, "body_get_local_point");
}
CAROM_API carom_status carom_body_get_world_vector(const carom_world *w, carom_body_id id, carom_vec3 local, carom_vec3 *out)
{
    return convert(w, id, local, out, 1, 0, "body_get_world_vector");
}
CAROM_API carom_status carom_body_get_local_vector(const carom_world *w, carom_body_id id, carom_vec3 world, carom_vec3 *out)
{
    return convert(w, id, world, out, 0, 0, "body_get_local_vector");
}

CAROM_API carom_status carom_body_get_shape(const carom_world *w, carom_body_id id, carom_shape_def *out)
{
    const char *fn = "body_get_shape";
    SLOT_OR_FAIL(fn);
    OUT_OR_FAIL(out, fn);
    const shape *sh = &w->bodies.shapes[slot];
    carom_shape_def d = carom_shape_sphere(1.0);
    d.type = (carom_shape_type)sh->type;
    d.radius = sh->radius;
    d.half_height = sh->half_height;
    d.half_extents.x = sh->half_extents.x; d.half_extents.y = sh->half_extents.y; d.half_extents.z = sh->half_extents.z;
    if (sh->type == SHAPE_HULL) {
        /* the hull's own vertices, x y z packed: valid while the body lives */
        d.points = &sh->hull->vertices[0].x;
        d.point_count = sh->hull->vertex_count;
    }
    if (sh->type == SHAPE_PLANE) {
        d.normal = args_c3(sh->plane_normal);
        d.offset = sh->plane_offset;
    }
    *out = d;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_previous_position(const carom_world *w, carom_body_id id, carom_vec3 *out)
{
    const char *fn = "body_get_previous_position";
    SLOT_OR_FAIL(fn);
    OUT_OR_FAIL(out, fn);
    *out = args_c3(w->bodies.previous_origin[slot]);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_previous_orientation(const carom_world *w, carom_body_id id, carom_quat *out)
{
    const char *fn = "body_get_previous_orientation";
    SLOT_OR_FAIL(fn);
    OUT_OR_FAIL(out, fn);
    quat q = w->bodies.previous_rotation[slot];
    out->w = q.w; out->x = q.x; out->y = q.y; out->z = q.z;
    return CAROM_OK;
}
