/* shape_def.c - validation of a public shape def and its conversion to the
 * internal shape (see shape_def.h). */
#include <stdio.h>
#include <string.h>
#include "narrowphase.h"
#include "ranges.h"
#include "shape_def.h"

static vec3 to_v3(carom_vec3 v) { return v3(v.x, v.y, v.z); }
static int finite_c(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static int length_ok(double x) { return x >= RANGE_LENGTH_MIN && x <= RANGE_LENGTH_MAX; }
static double len_c(carom_vec3 v) { return sqrt(v.x * v.x + v.y * v.y + v.z * v.z); } /* inf when huge */
static int normal_ok(carom_vec3 n)
{
    double l = len_c(n);
    return finite_c(n) && isfinite(l) && l >= RANGE_NORMAL_MIN;
}

#define LENGTH_RANGE "[1e-6, 1e6] m"

/* 1 if sd is a valid shape for a body of this type, else 0 with "fn: why" in msg. */
static int check_shape(char *msg, size_t size, const carom_shape_def *sd, carom_body_type type, const char *fn)
{
    /* (the messages are the body's: fn names the caller) */
#define FAIL(...) return snprintf(msg, size, __VA_ARGS__), 0
    switch (sd->type) {
    case CAROM_SHAPE_SPHERE:
        if (!length_ok(sd->radius)) FAIL("%s: sphere radius %g is outside " LENGTH_RANGE, fn, sd->radius);
        break;
    case CAROM_SHAPE_BOX:
        if (!length_ok(sd->half_extents.x) || !length_ok(sd->half_extents.y) || !length_ok(sd->half_extents.z))
            FAIL("%s: box half extents (%g, %g, %g) must each be in " LENGTH_RANGE, fn, sd->half_extents.x,
                 sd->half_extents.y, sd->half_extents.z);
        break;
    case CAROM_SHAPE_CAPSULE:
    case CAROM_SHAPE_CYLINDER: {
        const char *name = sd->type == CAROM_SHAPE_CAPSULE ? "capsule" : "cylinder";
        if (!length_ok(sd->radius)) FAIL("%s: %s radius %g is outside " LENGTH_RANGE, fn, name, sd->radius);
        if (!length_ok(sd->half_height))
            FAIL("%s: %s half_height %g is outside " LENGTH_RANGE, fn, name, sd->half_height);
        break;
    }
    case CAROM_SHAPE_HULL:
        if (!sd->points || sd->point_count < 4 || sd->point_count > 100000)
            FAIL("%s: a hull needs 4..100000 points (got %d%s)", fn, sd->point_count, sd->points ? "" : ", NULL array");
        for (int i = 0; i < 3 * sd->point_count; i++)
            if (!(fabs(sd->points[i]) <= RANGE_LENGTH_MAX))
                FAIL("%s: hull point %d has coordinate %g; each must be finite with |c| <= 1e6 m", fn, i / 3,
                     sd->points[i]);
        break;
    case CAROM_SHAPE_COMPOUND: /* the children are checked with the body def */
        break;
    case CAROM_SHAPE_MESH:
    case CAROM_SHAPE_HEIGHTFIELD: {
        /* their data come with the body def (body_create builds them) */
        const char *what = sd->type == CAROM_SHAPE_MESH ? "mesh" : "heightfield";
        if (type == CAROM_BODY_DYNAMIC)
            FAIL("%s: a %s can only be a static or kinematic body "
                 "(use a hull or a compound of convex pieces for a dynamic one)", fn, what);
        break;
    }
    case CAROM_SHAPE_PLANE:
        if (type != CAROM_BODY_STATIC) FAIL("%s: a plane can only be a static body", fn);
        if (!normal_ok(sd->normal)) FAIL("%s: plane normal must be finite with length >= 1e-12", fn);
        if (!(fabs(sd->offset / len_c(sd->normal)) <= RANGE_COORDINATE_MAX))
            FAIL("%s: plane offset %g is outside [-1e12, 1e12] m", fn, sd->offset / len_c(sd->normal));
        break;
    default:
        FAIL("%s: unknown shape type %d", fn, (int)sd->type);
    }
#undef FAIL
    return 1;
}

carom_status shape_def_check(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn)
{
    if (!sd) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: shape is NULL", fn);
    char msg[WORLD_ERROR_SIZE];
    if (!check_shape(msg, sizeof msg, sd, type, fn)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s", msg);
    return CAROM_OK;
}

CAROM_API carom_status carom_shape_def_check(const carom_shape_def *def, carom_body_type type, char *msg, size_t msg_size)
{
    char buf[WORLD_ERROR_SIZE];
    int ok = def != NULL;
    if (!ok) snprintf(buf, sizeof buf, "shape_def_check: shape is NULL");
    else if (type != CAROM_BODY_STATIC && type != CAROM_BODY_KINEMATIC && type != CAROM_BODY_DYNAMIC) {
        snprintf(buf, sizeof buf, "shape_def_check: unknown body type %d", (int)type);
        ok = 0;
    } else ok = check_shape(buf, sizeof buf, def, type, "shape_def_check");
    if (msg && msg_size) snprintf(msg, msg_size, "%s", ok ? "" : buf);
    return ok ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT;
}

carom_status shape_from_def(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn,
                            shape *s)
{
    memset(s, 0, sizeof *s);
    carom_status st = shape_def_check(w, sd, type, fn);
    if (st != CAROM_OK) return st;
    s->type = (int)sd->type;
    s->radius = sd->radius;
    s->half_height = sd->half_height;
    s->half_extents = to_v3(sd->half_extents);
    if (sd->type == CAROM_SHAPE_PLANE) {
        double len = v3_len(to_v3(sd->normal));
        s->plane_normal = v3_scale(to_v3(sd->normal), 1.0 / len);
        s->plane_offset = sd->offset / len;
    }
    if (sd->type != CAROM_SHAPE_HULL) return CAROM_OK;
    char err[160];
    s->hull = hull_build(sd->points, sd->point_count, err, (int)sizeof err);
    if (!s->hull) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: bad hull: %s", fn, err);
    int fv = 0;
    for (int f = 0; f < s->hull->face_count; f++) fv += s->hull->faces[f].count;
    if (s->hull->vertex_count > HULL_MAX_VERTICES || s->hull->face_count > HULL_MAX_FACES ||
        fv > HULL_MAX_FACE_VERTICES || s->hull->edge_count > HULL_MAX_FACE_VERTICES / 2) {
        int nv = s->hull->vertex_count, nf = s->hull->face_count;
        hull_free(s->hull);
        s->hull = NULL;
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "%s: hull has %d vertices and %d faces; at most %d and %d (simplify the point set)", fn, nv, nf,
                          HULL_MAX_VERTICES, HULL_MAX_FACES);
    }
    return CAROM_OK;
}
