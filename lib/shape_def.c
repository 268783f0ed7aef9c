/* shape_def.c - validation of a public shape def and its conversion to the
 * internal shape (see shape_def.h). */
#include <stdio.h>
#include <string.h>
#include <stddef.h>
#include "heightfield.h"
#include "material.h"
#include "mesh.h"
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

/* The reason sd is not a valid shape for a body of this type into msg (no
 * function name: the caller adds its own); 1 if it is valid. */
int shape_def_reason(const carom_shape_def *sd, carom_body_type type, char *msg, size_t size)
{
#define FAIL(...) return snprintf(msg, size, __VA_ARGS__), 0
    switch (sd->type) {
    case CAROM_SHAPE_SPHERE:
        if (!length_ok(sd->radius)) FAIL("sphere radius %g is outside " LENGTH_RANGE, sd->radius);
        break;
    case CAROM_SHAPE_BOX:
        if (!length_ok(sd->half_extents.x) || !length_ok(sd->half_extents.y) || !length_ok(sd->half_extents.z))
            FAIL("box half extents (%g, %g, %g) must each be in " LENGTH_RANGE, sd->half_extents.x,
                 sd->half_extents.y, sd->half_extents.z);
        break;
    case CAROM_SHAPE_CAPSULE:
    case CAROM_SHAPE_CYLINDER: {
        const char *name = sd->type == CAROM_SHAPE_CAPSULE ? "capsule" : "cylinder";
        if (!length_ok(sd->radius)) FAIL("%s radius %g is outside " LENGTH_RANGE, name, sd->radius);
        if (!length_ok(sd->half_height))
            FAIL("%s half_height %g is outside " LENGTH_RANGE, name, sd->half_height);
        break;
    }
    case CAROM_SHAPE_HULL:
        if (!sd->points || sd->point_count < 4 || sd->point_count > 100000)
            FAIL("a hull needs 4..100000 points (got %d%s)", sd->point_count, sd->points ? "" : ", NULL array");
        for (int i = 0; i < 3 * sd->point_count; i++)
            if (!(fabs(sd->points[i]) <= RANGE_LENGTH_MAX))
                FAIL("hull point %d has coordinate %g; each must be finite with |c| <= 1e6 m", i / 3,
                     sd->points[i]);
        break;
    case CAROM_SHAPE_COMPOUND: /* the children are checked with the body def */
        break;
    case CAROM_SHAPE_MESH:
    case CAROM_SHAPE_HEIGHTFIELD: {
        /* their data come with the body def (body_create builds them) */
        const char *what = sd->type == CAROM_SHAPE_MESH ? "mesh" : "heightfield";
        if (type == CAROM_BODY_DYNAMIC)
            FAIL("a %s can only be a static or kinematic body "
                 "(use a hull or a compound of convex pieces for a dynamic one)", what);
        break;
    }
    case CAROM_SHAPE_PLANE:
        if (type != CAROM_BODY_STATIC) FAIL("a plane can only be a static body");
        if (!normal_ok(sd->normal)) FAIL("plane normal must be finite with length >= 1e-12");
        if (!(fabs(sd->offset / len_c(sd->normal)) <= RANGE_COORDINATE_MAX))
            FAIL("plane offset %g is outside [-1e12, 1e12] m", sd->offset / len_c(sd->normal));
        break;
    default:
        FAIL("unknown shape type %d", (int)sd->type);
    }
#undef FAIL
    return 1;
}

carom_status shape_def_check(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn)
{
    if (!sd) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: shape is NULL", fn);
    char msg[WORLD_ERROR_SIZE];
    if (!shape_def_reason(sd, type, msg, sizeof msg)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: %s", fn, msg);
    return CAROM_OK;
}

/* The reason alone into msg (as carom_world_def_check's); "" when valid. */
static carom_status public_result(int ok, const char *reason, char *msg, size_t msg_size)
{
    if (msg && msg_size) snprintf(msg, msg_size, "%s", ok ? "" : reason);
    return ok ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT;
}

CAROM_API carom_status carom_shape_def_check(const carom_shape_def *def, carom_body_type type, char *msg, size_t msg_size)
{
    char buf[WORLD_ERROR_SIZE];
    int ok = def != NULL;
    if (!ok) snprintf(buf, sizeof buf, "shape is NULL");
    else if (type != CAROM_BODY_STATIC && type != CAROM_BODY_KINEMATIC && type != CAROM_BODY_DYNAMIC) {
        snprintf(buf, sizeof buf, "unknown body type %d", (int)type);
        ok = 0;
    } else ok = shape_def_reason(def, type, buf, sizeof buf);
    return public_result(ok, buf, msg, msg_size);
}

/* ---- the data of a mesh, a height field, a compound ------------------------- */

int mesh_def_reason(const carom_mesh_def *md, char *msg, size_t size)
{
    if (!md || md->size < offsetof(carom_mesh_def, two_sided) + sizeof(int)) {
        snprintf(msg, size, "mesh: def.mesh is %s", md ? "too small (use carom_mesh_def_default())" : "NULL");
        return 0;
    }
    return mesh_check(md->vertices, md->vertex_count, md->triangles, md->triangle_count, msg, (int)size);
}

int heightfield_def_reason(const carom_heightfield_def *hd, char *msg, size_t size)
{
    if (!hd || hd->size < offsetof(carom_heightfield_def, hole_count) + sizeof(int)) {
        snprintf(msg, size, "heightfield: def.heightfield is %s",
                 hd ? "too small (use carom_heightfield_def_default())" : "NULL");
        return 0;
    }
    return heightfield_check(hd->heights, hd->rows, hd->columns, hd->cell_x, hd->cell_y, hd->holes, hd->hole_count,
                             msg, (int)size);
}

carom_compound_child compound_child_at(const carom_compound_child *children, int i)
{
    carom_compound_child c = carom_compound_child_default(carom_shape_sphere(0.5));
    size_t stride = children[0].size;
    const carom_compound_child *src =
        (const carom_compound_child *)(const void *)((const char *)children + stride * (size_t)i);
    memcpy(&c, src, stride < sizeof c ? stride : sizeof c);
    return c;
}

static int finite_within(carom_vec3 v, double max)
{
    return finite_c(v) && fabs(v.x) <= max && fabs(v.y) <= max && fabs(v.z) <= max;
}
static int unit_quat(carom_quat q)
{
    double l2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    return isfinite(l2) && fabs(sqrt(l2) - 1.0) <= 1e-6;
}

/* What is wrong with one child, written after its "children[i]" (".density
 * must be ...", ": sphere radius ..."); 1 if nothing is. */
static int child_reason(const carom_compound_child *c, char *msg, size_t size)
{
#define CFAIL(...) return snprintf(msg, size, __VA_ARGS__), 0
    carom_shape_type t = c->shape.type;
    if (t != CAROM_SHAPE_SPHERE && t != CAROM_SHAPE_BOX && t != CAROM_SHAPE_CAPSULE && t != CAROM_SHAPE_CYLINDER &&
        t != CAROM_SHAPE_HULL)
        CFAIL(".shape must be convex (sphere, box, capsule, cylinder or hull), got type %d", (int)t);
    char why[WORLD_ERROR_SIZE / 2];
    if (!shape_def_reason(&c->shape, CAROM_BODY_DYNAMIC, why, sizeof why)) CFAIL(": %s", why);
    if (!finite_within(c->position, RANGE_LENGTH_MAX)) CFAIL(".position must be finite (within 1e6 m)");
    if (!unit_quat(c->orientation)) CFAIL(".orientation must be a finite unit quaternion");
    if (!(isfinite(c->friction) && c->friction >= 0 && c->friction <= RANGE_FRICTION_MAX))
        CFAIL(".friction must be in [0, 1e3]");
    if (!(isfinite(c->restitution) && c->restitution >= 0 && c->restitution <= 1))
        CFAIL(".restitution must be in [0, 1]");
    if (!(c->density >= RANGE_DENSITY_MIN && c->density <= RANGE_DENSITY_MAX))
        CFAIL(".density must be in [1e-6, 1e9] kg/m^3");
    if (c->material && !material_valid(c->material, why, sizeof why)) CFAIL(".%s", why);
    return 1;
#undef CFAIL
}

int compound_children_reason(const carom_compound_child *children, int count, char *msg, size_t size)
{
#define CFAIL(...) return snprintf(msg, size, __VA_ARGS__), 0
    if (!children || count < 1) CFAIL("a compound needs children (got %d%s)", count, children ? "" : ", NULL array");
    if (count > COMPOUND_MAX_CHILDREN)
        CFAIL("a compound takes at most %d children (got %d)", COMPOUND_MAX_CHILDREN, count);
    if (children[0].size < offsetof(carom_compound_child, density) + sizeof(double))
        CFAIL("children[0].size %u too small: use carom_compound_child_default()", (unsigned)children[0].size);
    for (int i = 0; i < count; i++) {
        carom_compound_child c = compound_child_at(children, i);
        char why[WORLD_ERROR_SIZE - 64];
        if (!child_reason(&c, why, sizeof why)) CFAIL("children[%d]%s (child %d counting from 1)", i, why, i + 1);
    }
    return 1;
#undef CFAIL
}

CAROM_API carom_status carom_mesh_def_check(const carom_mesh_def *def, char *msg, size_t msg_size)
{
    char buf[WORLD_ERROR_SIZE];
    return public_result(mesh_def_reason(def, buf, sizeof buf), buf, msg, msg_size);
}

CAROM_API carom_status carom_heightfield_def_check(const carom_heightfield_def *def, char *msg, size_t msg_size)
{
    char buf[WORLD_ERROR_SIZE];
    return public_result(heightfield_def_reason(def, buf, sizeof buf), buf, msg, msg_size);
}

CAROM_API carom_status carom_compound_check(const carom_compound_child *children, int count, char *msg, size_t msg_size)
{
    char buf[WORLD_ERROR_SIZE];
    return public_result(compound_children_reason(children, count, buf, sizeof buf), buf, msg, msg_size);
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
