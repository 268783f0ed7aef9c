/* body_api.c - the public body functions: validated create/destroy, getters
 * and setters. Every entry checks its input and leaves the world unchanged
 * on error. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "world.h"
#include "material.h"
#include "ranges.h"
#include "shape_def.h"
#include "mesh.h"
#include "body_motion.h"
#include "deferred.h"
#include "heightfield.h"
#include "compound.h"

#define MAX_COORDINATE RANGE_COORDINATE_MAX

/* A moving body's shape spans enough ulps of its coordinates (ranges.h). */
static int resolved_at(const shape *sh, vec3 p)
{
    double far = dmax(fabs(p.x), dmax(fabs(p.y), fabs(p.z)));
    return shape_thickness(sh) >= RANGE_THICKNESS_PER_COORDINATE * far;
}

static carom_status fail_unresolved(carom_world *w, const char *fn, const shape *sh, vec3 p)
{
    double far = dmax(fabs(p.x), dmax(fabs(p.y), fabs(p.z)));
    return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                      "%s: a moving body %g m thick (half) at %g m from the origin is below what the coordinates resolve "
                      "there: at least 1e-13 of them, %g m",
                      fn, shape_thickness(sh), far, RANGE_THICKNESS_PER_COORDINATE * far);
}

static vec3 to_v3(carom_vec3 v) { return v3(v.x, v.y, v.z); }
static carom_vec3 from_v3(vec3 v) { carom_vec3 r = {v.x, v.y, v.z}; return r; }
static int finite_c(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static double len_c(carom_vec3 v) { return sqrt(v.x * v.x + v.y * v.y + v.z * v.z); } /* inf when huge */
static int normal_ok(carom_vec3 n)
{
    double l = len_c(n);
    return finite_c(n) && isfinite(l) && l >= RANGE_NORMAL_MIN;
}
static int quat_ok(carom_quat q)
{
    double l2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    return isfinite(l2) && fabs(sqrt(l2) - 1.0) <= 1e-6;
}

CAROM_API int carom_body_is_valid(const carom_world *w, carom_body_id id)
{
    return w && body_store_slot(&w->bodies, id.index1, id.generation) >= 0;
}

/* Slot of id, or -1 with the world's error set (fn names the caller). */
static int lookup(const carom_world *w, carom_body_id id, const char *fn)
{
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    if (slot < 0) world_fail(w, CAROM_ERROR_STALE_ID, "%s: body has been destroyed (or the id is invalid)", fn);
    return slot;
}

#define GET_SLOT(w, id, fn)                                                        \
    if (!(w)) return CAROM_ERROR_INVALID_ARGUMENT;                                 \
    int slot = lookup((w), (id), (fn));                                            \
    if (slot < 0) return CAROM_ERROR_STALE_ID;
#define REQUIRE_UNLOCKED(w, fn)                                                    \
    if ((w)->locked) return world_fail((w), CAROM_ERROR_LOCKED, "%s: the world is locked (inside step or a callback)", (fn));
#define REQUIRE_OUT(p, fn)                                                         \
    if (!(p)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: output pointer is NULL", (fn));

static void refresh_proxy(carom_world *w, int slot)
{
    aabb fat = world_body_fat_aabb(w, slot, WORLD_AABB_MARGIN);
    w->bodies.fat_box[slot] = fat;
    bp_move_proxy(w->bp, w->bodies.proxy[slot], fat);
}

/* ---- validation of a body def ------------------------------------------------ */

/* The shape rules are shared with the shape queries (shape_def.c). */
static int check_shape(carom_world *w, const carom_shape_def *sd, carom_body_type type)
{
    return shape_def_check(w, sd, type, "body_create") == CAROM_OK;
}

/* A dynamic body's mass and inertia (fn names the caller): inside the ranges
 * the solver's products and inverses stay finite. The principal moments are
 * bounded through the trace (>= the largest) and det / trace^2 (<= the smallest),
 * their spread through trace^3 / det (ranges.h). */
static int check_mass_props(const carom_world *w, const mass_props *mp, const char *fn)
{
    if (!(mp->mass >= RANGE_MASS_MIN && mp->mass <= RANGE_MASS_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: mass %g kg is outside [1e-9, 1e15] kg", fn, mp->mass), 0;
    double trace = mp->inertia.c0.x + mp->inertia.c1.y + mp->inertia.c2.z;
    double smallest = m3_det(mp->inertia) / (trace * trace);
    if (!(trace <= RANGE_INERTIA_MAX && smallest >= RANGE_INERTIA_MIN))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "%s: principal moments of inertia in [%g, %g] kg m^2 must lie within [1e-24, 1e30] "
                          "(the body is too small, too thin or too light for its mass)", fn, smallest, trace), 0;
    double anisotropy = trace * trace * trace / m3_det(mp->inertia);
    if (!(anisotropy <= RANGE_ANISOTROPY_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "%s: inertia anisotropy trace^3/det %g is above 1e12 (a largest/smallest principal moment "
                          "ratio above about 1e11: the body is too thin for double precision)", fn, anisotropy), 0;
    return 1;
}

/* |v| within the world's clamp (max_linear_speed / max_angular_speed). */
static int speed_ok(carom_vec3 v, double max) { return finite_c(v) && len_c(v) <= max; }

static int check_children(carom_world *w, const carom_body_def *d)
{
    char msg[WORLD_ERROR_SIZE];
    if (compound_children_reason(d->children, d->child_count, msg, sizeof msg)) return 1;
    return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: %s", msg), 0;
}

static int check_body_def(carom_world *w, const carom_body_def *d)
{
#define FAIL(...) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, __VA_ARGS__), 0
    if (d->type != CAROM_BODY_STATIC && d->type != CAROM_BODY_KINEMATIC && d->type != CAROM_BODY_DYNAMIC)
        FAIL("body_create: unknown body type %d", (int)d->type);
    if (!finite_c(d->position)) FAIL("body_create: position must be finite");
    if (fabs(d->position.x) > MAX_COORDINATE || fabs(d->position.y) > MAX_COORDINATE || fabs(d->position.z) > MAX_COORDINATE)
        FAIL("body_create: position (%g, %g, %g) is beyond 1e12 m", d->position.x, d->position.y, d->position.z);
    if (!quat_ok(d->orientation)) FAIL("body_create: orientation must be a finite unit quaternion {w,x,y,z}");
    if (!finite_c(d->linear_velocity)) FAIL("body_create: linear velocity must be finite");
    if (!finite_c(d->angular_velocity)) FAIL("body_create: angular velocity must be finite");
    if (!speed_ok(d->linear_velocity, w->def.max_linear_speed))
        FAIL("body_create: linear speed %g m/s is above the world's max_linear_speed %g m/s", len_c(d->linear_velocity),
             w->def.max_linear_speed);
    if (!speed_ok(d->angular_velocity, world_spin_limit(&w->def)))
        FAIL("body_create: angular speed %g rad/s is above the world's max_angular_speed %g rad/s",
             len_c(d->angular_velocity), world_spin_limit(&w->def));
    if (!(isfinite(d->mass) && d->mass >= 0)) FAIL("body_create: mass must be finite and >= 0 (got %g)", d->mass);
    if (d->mass > 0 && !(d->mass >= RANGE_MASS_MIN && d->mass <= RANGE_MASS_MAX))
        FAIL("body_create: mass %g kg is outside [1e-9, 1e15] kg", d->mass);
    if (!(isfinite(d->density) && d->density >= 0)) FAIL("body_create: density must be finite and >= 0 (got %g)", d->density);
    if (d->density != 0 && !(d->density >= RANGE_DENSITY_MIN && d->density <= RANGE_DENSITY_MAX))
        FAIL("body_create: density %g kg/m^3 is outside [1e-6, 1e9] kg/m^3 (or 0: unused)", d->density);
    if (d->type == CAROM_BODY_DYNAMIC && d->mass == 0 && d->density == 0)
        FAIL("body_create: a dynamic body needs mass > 0 or density > 0");
    if (!(isfinite(d->friction) && d->friction >= 0 && d->friction <= RANGE_FRICTION_MAX))
        FAIL("body_create: friction %g is outside [0, 1000]", d->friction);
    if (!(isfinite(d->restitution) && d->restitution >= 0 && d->restitution <= 1))
        FAIL("body_create: restitution must be in [0, 1]");
    if (!(isfinite(d->linear_damping) && d->linear_damping >= 0 && d->linear_damping <= RANGE_DAMPING_MAX))
        FAIL("body_create: linear damping %g is outside [0, 1e6] 1/s", d->linear_damping);
    if (!(isfinite(d->angular_damping) && d->angular_damping >= 0 && d->angular_damping <= RANGE_DAMPING_MAX))
        FAIL("body_create: angular damping %g is outside [0, 1e6] 1/s", d->angular_damping);
    if (!(fabs(d->gravity_scale) <= RANGE_GRAVITY_SCALE_MAX))
        FAIL("body_create: gravity scale %g is outside [-1e4, 1e4]", d->gravity_scale);
    if (d->lock_to_plane && !normal_ok(d->plane_normal))
        FAIL("body_create: plane_normal must be finite with length >= 1e-12");
    if (!(isfinite(d->force_threshold) && d->force_threshold >= 0))
        FAIL("body_create: force_threshold must be finite and >= 0 (N; 0: no force events)");
    char msg[160];
    if (d->material && !material_valid(d->material, msg, sizeof msg)) FAIL("body_create: %s", msg);
#undef FAIL
    if (d->shape.type == CAROM_SHAPE_COMPOUND) return check_children(w, d);
    return check_shape(w, &d->shape, d->type);
}

static void build_shape(const carom_shape_def *sd, shape *s)
{
    memset(s, 0, sizeof *s);
    s->type = (int)sd->type;
    s->radius = sd->radius;
    s->half_height = sd->half_height;
    s->half_extents = to_v3(sd->half_extents);
    if (sd->type == CAROM_SHAPE_PLANE) {
        double len = v3_len(to_v3(sd->normal));
        s->plane_normal = v3_scale(to_v3(sd->normal), 1.0 / len);
        s->plane_offset = sd->offset / len;
    }
}

/* The hull of a shape def into sh->hull; 0 with the error set (who: "" or "children[i]: "). */
static int build_hull(carom_world *w, const carom_shape_def *sd, shape *sh, const char *who)
{
    char err[160];
    sh->hull = hull_build(sd->points, sd->point_count, err, (int)sizeof err);
    if (!sh->hull) {
        world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: %sbad hull: %s", who, err);
        return 0;
    }
    int fv = 0;
    for (int f = 0; f < sh->hull->face_count; f++) fv += sh->hull->faces[f].count;
    if (sh->hull->vertex_count > HULL_MAX_VERTICES || sh->hull->face_count > HULL_MAX_FACES ||
        fv > HULL_MAX_FACE_VERTICES || sh->hull->edge_count > HULL_MAX_FACE_VERTICES / 2) {
        world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                   "body_create: %shull has %d vertices and %d faces; at most %d and %d (simplify the point set)", who,
                   sh->hull->vertex_count, sh->hull->face_count, HULL_MAX_VERTICES, HULL_MAX_FACES);
        hull_free(sh->hull);
        sh->hull = NULL;
        return 0;
    }
    return 1;
}

static int build_compound(carom_world *w, const carom_body_def *d, shape *sh)
{
    int n = d->child_count;
    compound *c = compound_alloc(n);
    if (!c) {
        world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "body_create: out of memory");
        return 0;
    }
    for (int i = 0; i < n; i++) {
        carom_compound_child cd = compound_child_at(d->children, i);
        build_shape(&cd.shape, &c->children[i]);
        c->count = i + 1; /* so a failure below frees what was built */
        char who[32];
        snprintf(who, sizeof who, "children[%d]: ", i);
        if (cd.shape.type == CAROM_SHAPE_HULL && !build_hull(w, &cd.shape, &c->children[i], who)) {
            compound_free(c);
            return 0;
        }
        xform pose = {to_v3(cd.position), q_normalize((quat){cd.orientation.w, cd.orientation.x, cd.orientation.y, cd.orientation.z})};
        c->poses[i] = pose;
        c->friction[i] = cd.friction;
        c->restitution[i] = cd.restitution;
        c->density[i] = cd.density;
        c->rolling_resistance[i] = 0.0;
        c->combine[i] = CAROM_COMBINE_DEFAULT;
        if (cd.material)
            material_apply(cd.material, &c->friction[i], &c->restitution[i], &c->rolling_resistance[i], &c->combine[i]);
    }
    sh->compound = c;
    return 1;
}

CAROM_API carom_body_id carom_body_create(carom_world *w, const carom_body_def *user_def)
{
    carom_body_id null_id = carom_null_body();
    if (!w) return null_id;
    if (w->locked) {
        world_fail(w, CAROM_ERROR_LOCKED, "body_create: cannot create bodies inside step or a callback");
        return null_id;
    }
    if (!user_def) { world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: def is NULL"); return null_id; }
    if (user_def->size < offsetof(carom_body_def, shape) + sizeof(carom_shape_def)) {
        world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: def size %u too small: use carom_body_def_default()",
                   (unsigned)user_def->size);
        return null_id;
    }
    carom_body_def d = carom_body_def_default();
    memcpy(&d, user_def, user_def->size < sizeof d ? user_def->size : sizeof d);
    if (!check_body_def(w, &d)) return null_id;

    shape sh;
    build_shape(&d.shape, &sh);
    if (d.shape.type == CAROM_SHAPE_MESH) {
        char err[WORLD_ERROR_SIZE];
        if (!mesh_def_reason(d.mesh, err, sizeof err)) {
            world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: %s", err);
            return null_id;
        }
        const carom_mesh_def *md = d.mesh;
        sh.mesh = mesh_build(md->vertices, md->vertex_count, md->triangles, md->triangle_count, md->two_sided, err,
                             (int)sizeof err);
        if (!sh.mesh) {
            world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: %s", err);
            return null_id;
        }
    }
    if (d.shape.type == CAROM_SHAPE_HEIGHTFIELD) {
        char err[WORLD_ERROR_SIZE];
        if (!heightfield_def_reason(d.heightfield, err, sizeof err)) {
            world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: %s", err);
            return null_id;
        }
        const carom_heightfield_def *hd = d.heightfield;
        sh.field = heightfield_build(hd->heights, hd->rows, hd->columns, hd->cell_x, hd->cell_y, hd->holes,
                                     hd->hole_count, err, (int)sizeof err);
        if (!sh.field) {
            world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_create: %s", err);
            return null_id;
        }
    }
    if (d.shape.type == CAROM_SHAPE_HULL && !build_hull(w, &d.shape, &sh, "")) return null_id;
    if (d.shape.type == CAROM_SHAPE_COMPOUND && !build_compound(w, &d, &sh)) return null_id;
    mass_props mp = {0, {0, 0, 0}, {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
    if (sh.type == SHAPE_COMPOUND) {
        mp = compound_mass(sh.compound);
        if (d.mass > 0 && mp.mass > 0) { /* the given mass rescales every child */
            double k = d.mass / mp.mass;
            mp.mass = d.mass;
            mp.inertia = m3_scale(mp.inertia, k);
        }
    } else if (sh.type != SHAPE_PLANE) {
        mp = d.mass > 0 ? shape_mass_from_mass(&sh, d.mass) : shape_mass_from_density(&sh, d.density);
    }
    if (d.type == CAROM_BODY_DYNAMIC && !check_mass_props(w, &mp, "body_create")) {
        shape_free_data(&sh);
        return null_id;
    }
    if (d.type != CAROM_BODY_STATIC && !resolved_at(&sh, to_v3(d.position))) {
        fail_unresolved(w, "body_create", &sh, to_v3(d.position));
        shape_free_data(&sh);
        return null_id;
    }
    if (!body_store_reserve(&w->bodies)) {
        shape_free_data(&sh);
        world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "body_create: out of memory");
        return null_id;
    }

    body_store *s = &w->bodies;
    int id_index;
    int slot = body_store_add(s, &id_index);
    quat q = q_normalize((quat){d.orientation.w, d.orientation.x, d.orientation.y, d.orientation.z});
    int dynamic = d.type == CAROM_BODY_DYNAMIC;
    s->type[slot] = (int)d.type;
    s->flags[slot] = (d.lock_rotation ? BODY_LOCK_ROTATION : 0) | (d.lock_to_plane ? BODY_LOCK_PLANE : 0) |
                     (d.bullet ? BODY_BULLET : 0) | (d.enable_sleep ? BODY_ENABLE_SLEEP : 0) |
                     (d.sensor ? BODY_SENSOR : 0) |
                     ((d.awake || !d.enable_sleep) && d.type != CAROM_BODY_STATIC ? BODY_AWAKE : 0);
    s->rotation[slot] = q;
    s->local_center[slot] = mp.center;
    s->center[slot] = v3_add(to_v3(d.position), q_rotate(q, mp.center));
    s->velocity[slot] = d.type == CAROM_BODY_STATIC ? v3_zero() : to_v3(d.linear_velocity);
    s->angular_velocity[slot] = d.type == CAROM_BODY_STATIC || d.lock_rotation ? v3_zero() : to_v3(d.angular_velocity);
    s->force[slot] = v3_zero();
    s->torque[slot] = v3_zero();
    s->force_threshold[slot] = d.force_threshold;
    s->mass[slot] = mp.mass;
    s->inv_mass[slot] = dynamic ? 1.0 / mp.mass : 0.0;
    s->inertia_local[slot] = mp.inertia;
    s->inv_inertia_local[slot] = dynamic ? m3_inverse(mp.inertia) : m3_zero();
    s->friction[slot] = d.friction;
    s->restitution[slot] = d.restitution;
    s->rolling_resistance[slot] = 0.0;
    s->combine[slot] = CAROM_COMBINE_DEFAULT;
    if (d.material) material_apply(d.material, &s->friction[slot], &s->restitution[slot], &s->rolling_resistance[slot],
                                   &s->combine[slot]);
    s->linear_damping[slot] = d.linear_damping;
    s->angular_damping[slot] = d.angular_damping;
    s->gravity_scale[slot] = d.gravity_scale;
    /* read only with lock_to_plane: an unread value (even a NaN) stays out of the state */
    s->plane_normal[slot] = d.lock_to_plane ? v3_normalize(to_v3(d.plane_normal)) : v3(0, 1, 0);
    s->plane_offset[slot] = v3_dot(s->plane_normal[slot], s->center[slot]);
    /* created asleep: already rested for the sleep time, so the first step
     * does not wake it (as set_awake(false) leaves it) */
    s->sleep_time[slot] = (s->flags[slot] & BODY_AWAKE) || d.type == CAROM_BODY_STATIC ? 0.0 : w->def.sleep_time;
    s->shapes[slot] = sh;
    s->user_data[slot] = d.user_data;
    s->previous_origin[slot] = to_v3(d.position);
    s->previous_rotation[slot] = q;
    s->collided[slot] = (xform){to_v3(d.position), q};
    s->category[slot] = d.category;
    s->filter_mask[slot] = d.mask;
    s->group[slot] = d.group;
    s->solver_index[slot] = -1;
    if (d.lock_to_plane) {
        /* keep only in-plane motion: velocity in the plane, spin about its normal */
        vec3 n = s->plane_normal[slot];
        s->velocity[slot] = v3_madd(s->velocity[slot], -v3_dot(s->velocity[slot], n), n);
        s->angular_velocity[slot] = v3_scale(n, v3_dot(s->angular_velocity[slot], n));
    }
    body_update_inertia(s, slot);
    aabb fat = world_body_fat_aabb(w, slot, WORLD_AABB_MARGIN);
    s->fat_box[slot] = fat;
    s->proxy[slot] = bp_create_proxy(w->bp, fat, d.type == CAROM_BODY_STATIC, id_index);
    if (s->proxy[slot] < 0) {
        body_store_remove(s, slot);
        shape_free_data(&sh);
        world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "body_create: out of memory (broadphase)");
        return null_id;
    }
    return world_make_id(w, id_index);
}

CAROM_API carom_status carom_body_try_create(carom_world *w, const carom_body_def *def, carom_body_id *out)
{
    if (!out) return w ? world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_try_create: out is NULL") : CAROM_ERROR_INVALID_ARGUMENT;
    *out = carom_body_create(w, def);
    if (!carom_body_id_is_null(*out)) return CAROM_OK;
    return w ? w->last_status : CAROM_ERROR_INVALID_ARGUMENT;
}

CAROM_API carom_status carom_body_destroy(carom_world *w, carom_body_id id)
{
    GET_SLOT(w, id, "body_destroy");
    if (w->in_callback) {
        step_scratch *sc = &w->scratch;
        for (int i = 0; i < sc->deferred_count; i++)
            if (sc->deferred_destroy[i] == (int)id.index1 - 1) return CAROM_OK;
        if (!array_reserve((void **)&sc->deferred_destroy, &sc->deferred_capacity, sc->deferred_count + 1,
                           sizeof *sc->deferred_destroy))
            return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "body_destroy: out of memory");
        sc->deferred_destroy[sc->deferred_count++] = (int)id.index1 - 1;
        return CAROM_OK;
    }
    REQUIRE_UNLOCKED(w, "body_destroy");
    (void)slot;
    world_destroy_body(w, (int)id.index1 - 1);
    return CAROM_OK;
}

/* ---- getters --------------------------------------------------------------- */

CAROM_API carom_status carom_body_get_type(const carom_world *w, carom_body_id id, carom_body_type *out)
{
    GET_SLOT(w, id, "body_get_type");
    REQUIRE_OUT(out, "body_get_type");
    *out = (carom_body_type)w->bodies.type[slot];
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_shape_type(const carom_world *w, carom_body_id id, carom_shape_type *out)
{
    GET_SLOT(w, id, "body_get_shape_type");
    REQUIRE_OUT(out, "body_get_shape_type");
    *out = (carom_shape_type)w->bodies.shapes[slot].type;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_position(const carom_world *w, carom_body_id id, carom_vec3 *out)
{
    GET_SLOT(w, id, "body_get_position");
    REQUIRE_OUT(out, "body_get_position");
    *out = from_v3(body_origin(&w->bodies, slot));
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_orientation(const carom_world *w, carom_body_id id, carom_quat *out)
{
    GET_SLOT(w, id, "body_get_orientation");
    REQUIRE_OUT(out, "body_get_orientation");
    quat q = w->bodies.rotation[slot];
    out->w = q.w; out->x = q.x; out->y = q.y; out->z = q.z;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_center_of_mass(const carom_world *w, carom_body_id id, carom_vec3 *out)
{
    GET_SLOT(w, id, "body_get_center_of_mass");
    REQUIRE_OUT(out, "body_get_center_of_mass");
    *out = from_v3(w->bodies.center[slot]);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_linear_velocity(const carom_world *w, carom_body_id id, carom_vec3 *out)
{
    GET_SLOT(w, id, "body_get_linear_velocity");
    REQUIRE_OUT(out, "body_get_linear_velocity");
    *out = from_v3(w->bodies.velocity[slot]);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_angular_velocity(const carom_world *w, carom_body_id id, carom_vec3 *out)
{
    GET_SLOT(w, id, "body_get_angular_velocity");
    REQUIRE_OUT(out, "body_get_angular_velocity");
    *out = from_v3(w->bodies.angular_velocity[slot]);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_mass(const carom_world *w, carom_body_id id, double *out)
{
    GET_SLOT(w, id, "body_get_mass");
    REQUIRE_OUT(out, "body_get_mass");
    *out = w->bodies.type[slot] == CAROM_BODY_DYNAMIC ? w->bodies.mass[slot] : 0.0;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_inertia(const carom_world *w, carom_body_id id, double out[9])
{
    GET_SLOT(w, id, "body_get_inertia");
    REQUIRE_OUT(out, "body_get_inertia");
    mat3 m = w->bodies.inertia_local[slot];
    vec3 c[3] = {m.c0, m.c1, m.c2};
    for (int col = 0; col < 3; col++) {
        out[0 * 3 + col] = c[col].x;
        out[1 * 3 + col] = c[col].y;
        out[2 * 3 + col] = c[col].z;
    }
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_local_center(const carom_world *w, carom_body_id id, carom_vec3 *out)
{
    GET_SLOT(w, id, "body_get_local_center");
    REQUIRE_OUT(out, "body_get_local_center");
    *out = from_v3(w->bodies.local_center[slot]);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_friction(const carom_world *w, carom_body_id id, double *out)
{
    GET_SLOT(w, id, "body_get_friction");
    REQUIRE_OUT(out, "body_get_friction");
    *out = w->bodies.friction[slot];
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_restitution(const carom_world *w, carom_body_id id, double *out)
{
    GET_SLOT(w, id, "body_get_restitution");
    REQUIRE_OUT(out, "body_get_restitution");
    *out = w->bodies.restitution[slot];
    return CAROM_OK;
}

CAROM_API void *carom_body_get_user_data(const carom_world *w, carom_body_id id)
{
    if (!w) return NULL;
    int slot = lookup(w, id, "body_get_user_data");
    return slot < 0 ? NULL : w->bodies.user_data[slot];
}

CAROM_API int carom_body_is_awake(const carom_world *w, carom_body_id id)
{
    if (!w) return 0;
    int slot = lookup(w, id, "body_is_awake");
    return slot >= 0 && (w->bodies.flags[slot] & BODY_AWAKE) != 0;
}

CAROM_API carom_status carom_body_get_kinetic_energy(const carom_world *w, carom_body_id id, double *out)
{
    GET_SLOT(w, id, "body_get_kinetic_energy");
    REQUIRE_OUT(out, "body_get_kinetic_energy");
    const body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_DYNAMIC) { *out = 0; return CAROM_OK; }
    mat3 r = m3_from_quat(s->rotation[slot]);
    *out = kinetic_energy(s->mass[slot], m3_rotate_tensor(r, s->inertia_local[slot]), s->velocity[slot],
                          s->angular_velocity[slot]);
    return CAROM_OK;
}

/* ---- setters --------------------------------------------------------------- */

CAROM_API carom_status carom_body_set_position(carom_world *w, carom_body_id id, carom_vec3 p)
{
    GET_SLOT(w, id, "body_set_position");
    REQUIRE_UNLOCKED(w, "body_set_position");
    if (!finite_c(p) || fabs(p.x) > MAX_COORDINATE || fabs(p.y) > MAX_COORDINATE || fabs(p.z) > MAX_COORDINATE)
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_position: position (%g, %g, %g) must be finite with |x| <= 1e12 m", p.x, p.y, p.z);
    body_store *s = &w->bodies;
    if (s->type[slot] != CAROM_BODY_STATIC && !resolved_at(&s->shapes[slot], to_v3(p)))
        return fail_unresolved(w, "body_set_position", &s->shapes[slot], to_v3(p));
    s->center[slot] = v3_add(to_v3(p), q_rotate(s->rotation[slot], s->local_center[slot]));
    s->previous_origin[slot] = to_v3(p); /* a teleport: nothing to interpolate across */
    if (s->flags[slot] & BODY_LOCK_PLANE) s->plane_offset[slot] = v3_dot(s->plane_normal[slot], s->center[slot]);
    refresh_proxy(w, slot);
    world_wake_body(w, slot);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_orientation(carom_world *w, carom_body_id id, carom_quat q)
{
    GET_SLOT(w, id, "body_set_orientation");
    REQUIRE_UNLOCKED(w, "body_set_orientation");
    if (!quat_ok(q)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_orientation: need a finite unit quaternion");
    body_store *s = &w->bodies;
    vec3 origin = body_origin(s, slot);
    s->rotation[slot] = q_normalize((quat){q.w, q.x, q.y, q.z});
    s->center[slot] = v3_add(origin, q_rotate(s->rotation[slot], s->local_center[slot]));
    s->previous_rotation[slot] = s->rotation[slot];
    body_update_inertia(s, slot);
    refresh_proxy(w, slot);
    world_wake_body(w, slot);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_linear_velocity(carom_world *w, carom_body_id id, carom_vec3 v)
{
    GET_SLOT(w, id, "body_set_linear_velocity");
    if (w->in_callback) return world_defer_op(w, DEFER_LINEAR_VELOCITY, id, v, NULL, "body_set_linear_velocity");
    REQUIRE_UNLOCKED(w, "body_set_linear_velocity");
    return motion_set_linear_velocity(w, slot, v);
}

CAROM_API carom_status carom_body_set_angular_velocity(carom_world *w, carom_body_id id, carom_vec3 av)
{
    GET_SLOT(w, id, "body_set_angular_velocity");
    if (w->in_callback) return world_defer_op(w, DEFER_ANGULAR_VELOCITY, id, av, NULL, "body_set_angular_velocity");
    REQUIRE_UNLOCKED(w, "body_set_angular_velocity");
    return motion_set_angular_velocity(w, slot, av);
}

CAROM_API carom_status carom_body_set_mass(carom_world *w, carom_body_id id, double mass)
{
    GET_SLOT(w, id, "body_set_mass");
    REQUIRE_UNLOCKED(w, "body_set_mass");
    body_store *s = &w->bodies;
    if (!(isfinite(mass) && mass > 0)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_mass: mass must be positive and finite (got %g)", mass);
    if (s->type[slot] != CAROM_BODY_DYNAMIC)
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "body_set_mass: only dynamic bodies have mass");
    mass_props mp = shape_mass_from_mass(&s->shapes[slot], mass);
    if (!check_mass_props(w, &mp, "body_set_mass")) return CAROM_ERROR_INVALID_ARGUMENT;
    vec3 origin = body_origin(s, slot);
    s->mass[slot] = mp.mass;
    s->inv_mass[slot] = 1.0 / mp.mass;
    s->local_center[slot] = mp.center;
    s->center[slot] = v3_add(origin, q_rotate(s->rotation[slot], mp.center));
    s->inertia_local[slot] = mp.inertia;
    s->inv_inertia_local[slot] = m3_inverse(mp.inertia);
    body_update_inertia(s, slot);
    world_wake_body(w, slot);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_type(carom_world *w, carom_body_id id, carom_body_type type)
{
    GET_SLOT(w, id, "body_set_type");
    REQUIRE_UNLOCKED(w, "body_set_type");
    body_store *s = &w->bodies;
    if (type != CAROM_BODY_STATIC && type != CAROM_BODY_KINEMATIC && type != CAROM_BODY_DYNAMIC)
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_type: unknown type %d", (int)type);
    if (s->type[slot] == (int)type) return CAROM_OK;
    if (s->shapes[slot].type == SHAPE_PLANE)
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "body_set_type: a plane must stay static");
    if (type == CAROM_BODY_DYNAMIC && (s->shapes[slot].type == SHAPE_MESH || s->shapes[slot].type == SHAPE_HEIGHTFIELD))
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "body_set_type: a mesh or heightfield cannot be dynamic");
    if (type != CAROM_BODY_STATIC) {
        vec3 origin = v3_sub(s->center[slot], q_rotate(s->rotation[slot], s->local_center[slot]));
        if (!resolved_at(&s->shapes[slot], origin)) return fail_unresolved(w, "body_set_type", &s->shapes[slot], origin);
    }
    if (type == CAROM_BODY_DYNAMIC) {
        mass_props mp = {s->mass[slot], s->local_center[slot], s->inertia_local[slot]};
        if (!(s->mass[slot] > 0)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_type: body has no mass");
        if (!check_mass_props(w, &mp, "body_set_type")) return CAROM_ERROR_INVALID_ARGUMENT;
    }
    int proxy = bp_create_proxy(w->bp, s->fat_box[slot], type == CAROM_BODY_STATIC, s->id_index[slot]);
    if (proxy < 0) return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "body_set_type: out of memory");
    bp_destroy_proxy(w->bp, s->proxy[slot]);
    s->proxy[slot] = proxy;
    world_remove_body_contacts(w, s->id_index[slot]);
    s->type[slot] = (int)type;
    int dynamic = type == CAROM_BODY_DYNAMIC;
    s->inv_mass[slot] = dynamic ? 1.0 / s->mass[slot] : 0.0;
    s->inv_inertia_local[slot] = dynamic ? m3_inverse(s->inertia_local[slot]) : m3_zero();
    if (type == CAROM_BODY_STATIC) {
        s->velocity[slot] = v3_zero();
        s->angular_velocity[slot] = v3_zero();
        s->flags[slot] &= ~(uint32_t)BODY_AWAKE;
    } else {
        world_wake_body(w, slot);
    }
    body_update_inertia(s, slot);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_friction(carom_world *w, carom_body_id id, double friction)
{
    GET_SLOT(w, id, "body_set_friction");
    REQUIRE_UNLOCKED(w, "body_set_friction");
    if (!(isfinite(friction) && friction >= 0 && friction <= RANGE_FRICTION_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_friction: friction %g is outside [0, 1000]", friction);
    w->bodies.friction[slot] = friction;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_restitution(carom_world *w, carom_body_id id, double restitution)
{
    GET_SLOT(w, id, "body_set_restitution");
    REQUIRE_UNLOCKED(w, "body_set_restitution");
    if (!(isfinite(restitution) && restitution >= 0 && restitution <= 1))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_restitution: restitution must be in [0, 1]");
    w->bodies.restitution[slot] = restitution;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_gravity_scale(carom_world *w, carom_body_id id, double scale)
{
    GET_SLOT(w, id, "body_set_gravity_scale");
    REQUIRE_UNLOCKED(w, "body_set_gravity_scale");
    if (!(fabs(scale) <= RANGE_GRAVITY_SCALE_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_set_gravity_scale: scale %g is outside [-1e4, 1e4]", scale);
    w->bodies.gravity_scale[slot] = scale;
    world_wake_body(w, slot);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_bullet(carom_world *w, carom_body_id id, int bullet)
{
    GET_SLOT(w, id, "body_set_bullet");
    REQUIRE_UNLOCKED(w, "body_set_bullet");
    if (bullet) w->bodies.flags[slot] |= BODY_BULLET;
    else w->bodies.flags[slot] &= ~(uint32_t)BODY_BULLET;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_user_data(carom_world *w, carom_body_id id, void *user_data)
{
    GET_SLOT(w, id, "body_set_user_data");
    w->bodies.user_data[slot] = user_data;
    return CAROM_OK;
}

CAROM_API carom_status carom_body_set_awake(carom_world *w, carom_body_id id, int awake)
{
    GET_SLOT(w, id, "body_set_awake");
    REQUIRE_UNLOCKED(w, "body_set_awake");
    body_store *s = &w->bodies;
    if (s->type[slot] == CAROM_BODY_STATIC) return CAROM_OK;
    if (awake) world_wake_body(w, slot);
    else if (s->flags[slot] & BODY_ENABLE_SLEEP) {
        s->flags[slot] &= ~(uint32_t)BODY_AWAKE;
        s->sleep_time[slot] = w->def.sleep_time;
        s->velocity[slot] = v3_zero();
        s->angular_velocity[slot] = v3_zero();
    }
    return CAROM_OK;
}

CAROM_API carom_status carom_body_apply_impulse(carom_world *w, carom_body_id id, carom_vec3 j, const carom_vec3 *point)
{
    GET_SLOT(w, id, "body_apply_impulse");
    if (w->in_callback) return world_defer_op(w, DEFER_IMPULSE, id, j, point, "body_apply_impulse");
    REQUIRE_UNLOCKED(w, "body_apply_impulse");
    return motion_apply_impulse(w, slot, j, point);
}

CAROM_API carom_status carom_body_apply_force(carom_world *w, carom_body_id id, carom_vec3 force)
{
    GET_SLOT(w, id, "body_apply_force");
    if (w->in_callback) return world_defer_op(w, DEFER_FORCE, id, force, NULL, "body_apply_force");
    REQUIRE_UNLOCKED(w, "body_apply_force");
    return motion_apply_force(w, slot, force);
}
