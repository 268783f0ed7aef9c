/* query.c - what a game asks the world between steps: ray casts (closest and
 * every hit), shape casts, exact overlaps and closest distances, each through
 * a query filter (category mask and/or callback).
 *
 * Each query finds candidates in the broadphase and then asks one function
 * per kind (ray_body, cast_body, pair_distance) about a candidate's shape:
 * each switches on the shape type, planes analytically, every convex shape
 * through GJK (gjk.c). A new shape type is one case in each.
 *
 * Precision far from the origin: every computation runs in a frame centred
 * on the query (or, for rays, starts next to the body), so the error grows
 * with the size of the shapes, not with their distance from the origin. */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "gjk.h"
#include "mesh.h"
#include "narrowphase.h"
#include "query.h"
#include "ranges.h"
#include "shape_def.h"
#include "world.h"
#include "heightfield.h"
#include "compound.h"

static vec3 to_v3(carom_vec3 v) { return v3(v.x, v.y, v.z); }
static carom_vec3 from_v3(vec3 v) { carom_vec3 r = {v.x, v.y, v.z}; return r; }

/* ---- filtering --------------------------------------------------------------- */

typedef struct query_context {
    const carom_world *w;
    const carom_query_filter *filter;
} query_context;

static int body_visible(const query_context *q, int id_index)
{
    const body_store *s = &q->w->bodies;
    int slot = s->ids[id_index].slot;
    if (slot < 0 || (s->flags[slot] & BODY_SENSOR)) return 0; /* triggers are not in the way */
    if (!q->filter) return 1;
    if (!(s->category[slot] & q->filter->mask)) return 0;
    return !q->filter->fn || q->filter->fn(q->filter->context, world_make_id(q->w, id_index));
}

/* A filter callback runs with the world locked, so it cannot change what the
 * query is walking. The lock is bookkeeping, not simulation state. */
static int query_lock(const carom_world *w)
{
    carom_world *mw = (carom_world *)(uintptr_t)w;
    int was = mw->locked;
    mw->locked = 1;
    return was;
}
static void query_unlock(const carom_world *w, int was) { ((carom_world *)(uintptr_t)w)->locked = was; }

/* ---- one body's shape --------------------------------------------------------- */

/* 1 when body-frame point p is inside the shape or on its surface. */
static int shape_contains_local(const shape *s, vec3 p)
{
    switch (s->type) {
    case SHAPE_SPHERE: return v3_len2(p) <= s->radius * s->radius;
    case SHAPE_BOX: {
        vec3 h = s->half_extents;
        return fabs(p.x) <= h.x && fabs(p.y) <= h.y && fabs(p.z) <= h.z;
    }
    case SHAPE_CAPSULE: {
        double z = dmax(-s->half_height, dmin(s->half_height, p.z));
        return v3_len2(v3_sub(p, v3(0, 0, z))) <= s->radius * s->radius;
    }
    case SHAPE_CYLINDER:
        return fabs(p.z) <= s->half_height && p.x * p.x + p.y * p.y <= s->radius * s->radius;
    case SHAPE_HULL:
        for (int f = 0; f < s->hull->face_count; f++)
            if (v3_dot(s->hull->faces[f].normal, p) > s->hull->faces[f].offset) return 0;
        return 1;
    case SHAPE_PLANE: return v3_dot(s->plane_normal, p) <= s->plane_offset;
    default: return 0;
    }
}

/* shape_ray_cast_local, and which part of a compound or level shape was
 * hit (-1: the shape is one part). */
static int ray_cast_part(const shape *s, vec3 o, vec3 d, double max_t, double *t, vec3 *n, int *part)
{
    *part = -1;
    uint32_t index = 0;
    switch (s->type) {
    case SHAPE_COMPOUND: return compound_ray_cast_local(s->compound, o, d, max_t, t, n, part);
    case SHAPE_MESH:
        if (!mesh_ray_cast(s->mesh, o, d, max_t, t, n, &index)) return 0;
        *part = (int)index;
        return 1;
    case SHAPE_HEIGHTFIELD:
        if (!heightfield_ray_cast(s->field, o, d, max_t, t, n, &index)) return 0;
        *part = (int)index;
        return 1;
    default: return shape_ray_cast_local(s, o, d, max_t, t, n);
    }
}

/* The lowest-index child of a compound that holds the body-frame point, or -1. */
static int compound_child_containing(const compound *c, vec3 p)
{
    for (int i = 0; i < c->count; i++)
        if (shape_contains_local(&c->children[i], xf_inv_point(c->poses[i], p))) return i;
    return -1;
}

/* Ray origin + t dir, t in [0, max_t], against the body at slot (world
 * frame). Starts inside: t = 0, normal against the ray, and *part the
 * compound child holding the origin (-1 for other shapes). */
static int ray_body(const body_store *s, int slot, vec3 origin, vec3 dir, double max_t, double *t, vec3 *normal,
                    int *part)
{
    const shape *sh = &s->shapes[slot];
    *part = -1;
    xform x = body_xform(s, slot);
    vec3 o = xf_inv_point(x, origin), d = q_inv_rotate(x.q, dir);
    int inside_child = sh->type == SHAPE_COMPOUND ? compound_child_containing(sh->compound, o) : -1;
    if (sh->type == SHAPE_COMPOUND ? inside_child >= 0 : shape_contains_local(sh, o)) {
        *t = 0.0;
        *normal = v3_neg(v3_normalize(dir));
        *part = inside_child;
        return 1;
    }
    double t0 = 0.0;
    if (sh->type != SHAPE_PLANE) {
        /* begin the local cast just outside the bounding sphere: from far away
         * the shapes' quadratics cancel |o|^2 against r^2 and lose digits */
        double dd = v3_len2(d), reach = 2.0 * shape_bounding_radius(sh);
        double closest = -v3_dot(o, d) / dd, back = reach / sqrt(dd);
        if (closest - back > max_t) return 0; /* the segment ends before the shape's sphere */
        t0 = dmax(0.0, closest - back);
    }
    double tl;
    vec3 nl;
    if (!ray_cast_part(sh, v3_madd(o, t0, d), d, max_t - t0, &tl, &nl, part)) return 0;
    *t = t0 + tl;
    *normal = q_rotate(x.q, nl);
    return 1;
}

/* A body's shape placed in the query frame centred on ref. */
static gjk_proxy body_proxy(const body_store *s, int slot, vec3 ref)
{
    gjk_proxy p;
    p.s = &s->shapes[slot];
    p.points = NULL;
    p.point_count = 0;
    p.x = body_xform(s, slot);
    p.x.p = v3_sub(p.x.p, ref);
    return p;
}

/* A plane's outward normal and offset in the query frame. */
static void plane_in_frame(const gjk_proxy *plane, vec3 *n, double *offset)
{
    *n = q_rotate(plane->x.q, plane->s->plane_normal);
    *offset = plane->s->plane_offset + v3_dot(*n, plane->x.p);
}

/* Full-shape support point of a proxy (radius included), query frame. */
static vec3 proxy_support(const gjk_proxy *p, vec3 dir)
{
    return xf_point(p->x, shape_support_local(p->s, q_inv_rotate(p->x.q, dir)));
}

/* ---- meshes and height fields: the triangles near the query, one by one ---- */

static int is_triangles(const shape *s) { return s->type == SHAPE_MESH || s->type == SHAPE_HEIGHTFIELD; }

/* A query-frame box as a box in the frame x (bounds of its corners there). */
static aabb box_in_frame(aabb box, xform x)
{
    aabb r = {v3(INFINITY, INFINITY, INFINITY), v3(-INFINITY, -INFINITY, -INFINITY)};
    for (int i = 0; i < 8; i++) {
        vec3 c = v3(i & 1 ? box.hi.x : box.lo.x, i & 2 ? box.hi.y : box.lo.y, i & 4 ? box.hi.z : box.lo.z);
        vec3 l = xf_inv_point(x, c);
        r.lo = v3_min(r.lo, l);
        r.hi = v3_max(r.hi, l);
    }
    return r;
}

typedef struct triangle_query {
    const gjk_proxy *a, *b;   /* the convex query shape; the mesh body */
    vec3 translation;
    int cast;                 /* 1: sweep, else: distance */
    int found;
    gjk_cast_result hit;
    uint32_t hit_index;       /* the triangle of hit */
    gjk_result nearest;
} triangle_query;

static int visit_triangle(void *ctx, const vec3 v[3], unsigned active_edges, uint32_t index)
{
    (void)active_edges;
    triangle_query *q = ctx;
    gjk_proxy tri = {NULL, v, 3, q->b->x};
    if (q->cast) {
        gjk_cast_result r = gjk_shape_cast(q->a, q->translation, &tri);
        if (r.hit && (!q->found || r.fraction < q->hit.fraction)) { q->hit = r; q->hit_index = index; q->found = 1; }
        return !(q->found && q->hit.fraction == 0.0);
    }
    gjk_result r = gjk_distance(q->a, &tri);
    if (!q->found || r.distance < q->nearest.distance) { q->nearest = r; q->found = 1; }
    return !r.overlap;
}

/* The triangles of B (a mesh or height field) whose bounds meet the
 * query-frame box. */
static void query_triangles(triangle_query *q, aabb box)
{
    const shape *sb = q->b->s;
    aabb local = box_in_frame(box, q->b->x);
    if (sb->type == SHAPE_MESH) mesh_query(sb->mesh, local, visit_triangle, q);
    else heightfield_query(sb->field, local, visit_triangle, q);
}

static aabb proxy_aabb(const gjk_proxy *p) { return shape_aabb(p->s, p->x); }

/* A shape GJK takes as it is (convex and bounded). */
static int is_convex(const shape *s) { return s->type != SHAPE_PLANE && !is_triangles(s) && s->type != SHAPE_COMPOUND; }

/* Child i of a compound proxy, placed in the query frame. */
static gjk_proxy compound_child(const gjk_proxy *p, int i)
{
    const compound *c = p->s->compound;
    gjk_proxy child = {&c->children[i], NULL, 0, {xf_point(p->x, c->poses[i].p), q_mul(p->x.q, c->poses[i].q)}};
    return child;
}

/* Sweep of convex A along translation against B (any shape); *part: the
 * compound child or triangle hit (-1: B is one part, or no hit). */
static gjk_cast_result cast_body(const gjk_proxy *a, vec3 translation, const gjk_proxy *b, int *part)
{
    *part = -1;
    if (b->s->type == SHAPE_COMPOUND) { /* the first child hit */
        gjk_cast_result best = {0, 0, v3_zero(), v3_zero()};
        for (int i = 0; i < b->s->compound->count; i++) {
            gjk_proxy child = compound_child(b, i);
            int unused;
            gjk_cast_result r = cast_body(a, translation, &child, &unused);
            if (r.hit && (!best.hit || r.fraction < best.fraction)) { best = r; *part = i; }
        }
        return best;
    }
    if (is_triangles(b->s)) {
        triangle_query q;
        memset(&q, 0, sizeof q);
        q.a = a;
        q.b = b;
        q.translation = translation;
        q.cast = 1;
        aabb start = proxy_aabb(a), end = {v3_add(start.lo, translation), v3_add(start.hi, translation)};
        query_triangles(&q, aabb_union(start, end));
        if (q.found) *part = (int)q.hit_index;
        return q.hit;
    }
    if (b->s->type != SHAPE_PLANE) return gjk_shape_cast(a, translation, b);
    gjk_cast_result r = {0, 0, v3_zero(), v3_zero()};
    vec3 n;
    double offset;
    plane_in_frame(b, &n, &offset);
    vec3 deepest = proxy_support(a, v3_neg(n));
    double gap = v3_dot(n, deepest) - offset, closing = -v3_dot(n, translation);
    if (gap <= 0) {
        r.hit = 1;
        r.point = deepest;
        r.normal = v3_neg(v3_normalize(translation));
        return r;
    }
    if (!(closing > 0) || gap > closing) return r;
    r.hit = 1;
    r.fraction = gap / closing;
    r.point = v3_madd(deepest, r.fraction, translation);
    r.normal = n;
    return r;
}

/* Closest points of A and B (query frame; not both planes). Overlapping
 * convex shapes get minus the narrowphase's deepest penetration. */
static gjk_result pair_distance(const gjk_proxy *a, const gjk_proxy *b, double reach)
{
    gjk_result r;
    memset(&r, 0, sizeof r);
    if (a->s->type == SHAPE_COMPOUND || b->s->type == SHAPE_COMPOUND) { /* the nearest child */
        int on_a = a->s->type == SHAPE_COMPOUND;
        const gjk_proxy *c = on_a ? a : b;
        r.distance = INFINITY;
        for (int i = 0; i < c->s->compound->count; i++) {
            gjk_proxy child = compound_child(c, i);
            gjk_result ri = on_a ? pair_distance(&child, b, reach) : pair_distance(a, &child, reach);
            if (ri.distance < r.distance) r = ri;
        }
        return r;
    }
    if (is_triangles(a->s) || is_triangles(b->s)) {
        /* the nearest triangle within reach (a surface: no penetration depth) */
        int flip = is_triangles(a->s);
        triangle_query q;
        memset(&q, 0, sizeof q);
        q.a = flip ? b : a;
        q.b = flip ? a : b;
        r.distance = INFINITY;
        if (q.a->s->type == SHAPE_PLANE || is_triangles(q.a->s)) return r; /* no convex side */
        query_triangles(&q, aabb_fatten(proxy_aabb(q.a), reach));
        r.distance = INFINITY;
        if (!q.found) return r;
        r = q.nearest;
        if (flip) {
            vec3 t = r.point_a;
            r.point_a = r.point_b;
            r.point_b = t;
            r.normal = v3_neg(r.normal);
        }
        return r;
    }
    if (a->s->type == SHAPE_PLANE || b->s->type == SHAPE_PLANE) {
        int a_is_plane = a->s->type == SHAPE_PLANE;
        const gjk_proxy *plane = a_is_plane ? a : b, *other = a_is_plane ? b : a;
        vec3 n;
        double offset;
        plane_in_frame(plane, &n, &offset);
        vec3 deepest = proxy_support(other, v3_neg(n));
        double gap = v3_dot(n, deepest) - offset;
        vec3 on_plane = v3_madd(deepest, -gap, n);
        r.distance = gap;
        r.overlap = gap <= 0;
        r.point_a = a_is_plane ? on_plane : deepest;
        r.point_b = a_is_plane ? deepest : on_plane;
        r.normal = a_is_plane ? n : v3_neg(n);
        return r;
    }
    r = gjk_distance(a, b);
    if (!r.overlap) return r;
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(a->s, a->x, b->s, b->x, 0.0, &cache, &m);
    int deepest = -1;
    for (int i = 0; i < m.count; i++)
        if (m.points[i].separation < 0 && (deepest < 0 || m.points[i].separation < m.points[deepest].separation))
            deepest = i;
    if (deepest < 0) return r; /* touching: distance 0 */
    double sep = m.points[deepest].separation;
    vec3 p = m.points[deepest].point;
    r.distance = sep;
    r.normal = m.normal;
    r.point_a = v3_madd(p, -0.5 * sep, m.normal);
    r.point_b = v3_madd(p, 0.5 * sep, m.normal);
    return r;
}

/* ---- which part of a body a query shape overlaps -------------------------------- */

typedef struct lowest_overlap {
    const gjk_proxy *a;       /* the convex query shape */
    xform x;                  /* the mesh's frame */
    int part;                 /* the lowest overlapping triangle so far, -1: none */
} lowest_overlap;

static int visit_overlapping_triangle(void *ctx, const vec3 v[3], unsigned active_edges, uint32_t index)
{
    (void)active_edges;
    lowest_overlap *o = ctx;
    if (o->part >= 0 && index >= (uint32_t)o->part) return 1; /* a lower one overlaps already */
    gjk_proxy tri = {NULL, v, 3, o->x};
    if (gjk_distance(o->a, &tri).overlap) o->part = (int)index;
    return 1; /* every triangle: the tree's order is not the index order */
}

/* The lowest-index part of B (compound child, mesh triangle, height-field
 * cell*2 + half) that convex A overlaps, by the test carom_world_overlap
 * applies to the part: so a body it reports always names one. -1 for a
 * one-part B. */
static int overlap_part(const gjk_proxy *a, const gjk_proxy *b)
{
    if (b->s->type == SHAPE_COMPOUND) {
        for (int i = 0; i < b->s->compound->count; i++) {
            gjk_proxy child = compound_child(b, i);
            if (gjk_distance(a, &child).overlap) return i;
        }
        return -1;
    }
    if (!is_triangles(b->s)) return -1;
    lowest_overlap o = {a, b->x, -1};
    aabb local = box_in_frame(proxy_aabb(a), b->x);
    if (b->s->type == SHAPE_MESH) mesh_query(b->s->mesh, local, visit_overlapping_triangle, &o);
    else heightfield_query(b->s->field, local, visit_overlapping_triangle, &o);
    return o.part;
}

typedef struct nearest_triangle {
    gjk_proxy point;          /* the point, in the mesh's frame */
    double distance;          /* to the nearest triangle so far */
    int part;                 /* that triangle, -1: none yet */
} nearest_triangle;

static int visit_nearest_triangle(void *ctx, const vec3 v[3], unsigned active_edges, uint32_t index)
{
    (void)active_edges;
    nearest_triangle *q = ctx;
    gjk_proxy tri = {NULL, v, 3, q->point.x};
    double d = gjk_distance(&q->point, &tri).distance;
    /* a point on a shared edge: the lower index, whatever the tree's order */
    if (q->part < 0 || d < q->distance || (d == q->distance && index < (uint32_t)q->part)) {
        q->distance = d;
        q->part = (int)index;
    }
    return 1;
}

int query_triangle_near(const shape *s, xform x, vec3 p, double reach)
{
    if (!is_triangles(s)) return -1;
    vec3 local = xf_inv_point(x, p);
    nearest_triangle q = {{NULL, &local, 1, {v3_zero(), q_identity()}}, INFINITY, -1};
    vec3 r = v3(reach, reach, reach);
    aabb box = {v3_sub(local, r), v3_add(local, r)};
    if (s->type == SHAPE_MESH) mesh_query(s->mesh, box, visit_nearest_triangle, &q);
    else heightfield_query(s->field, box, visit_nearest_triangle, &q);
    return q.part;
}

int query_shapes_overlap(const shape *a, xform xa, const shape *b, xform xb)
{
    if (a->type == SHAPE_PLANE || is_triangles(a)) { /* the convex one (or a compound) first */
        const shape *t = a; a = b; b = t;
        xform tx = xa; xa = xb; xb = tx;
    }
    if (a->type == SHAPE_PLANE || is_triangles(a)) return 0;
    gjk_proxy pa = {a, NULL, 0, {v3_zero(), xa.q}}, pb = {b, NULL, 0, {v3_sub(xb.p, xa.p), xb.q}};
    gjk_result r = is_convex(a) && is_convex(b) ? gjk_distance(&pa, &pb) : pair_distance(&pa, &pb, 0.0);
    return r.overlap || r.distance <= 0;
}

/* ---- input checks ------------------------------------------------------------- */

static int quat_ok(carom_quat q)
{
    double l2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    return isfinite(l2) && fabs(sqrt(l2) - 1.0) <= 1e-6;
}

/* Checks a query shape and pose and builds the shape (a caller frees its hull). */
static int query_shape(const carom_world *w, const char *fn, const carom_shape_def *def, carom_vec3 position,
                       carom_quat orientation, shape *out, xform *pose)
{
    if (!def) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: shape is NULL", fn), 0;
    if (def->type == CAROM_SHAPE_PLANE || def->type == CAROM_SHAPE_MESH || def->type == CAROM_SHAPE_HEIGHTFIELD ||
        def->type == CAROM_SHAPE_COMPOUND)
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT,
                          "%s: shape must be convex and bounded (not a plane, mesh, height field or compound)", fn), 0;
    if (!v3_is_finite(to_v3(position)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: position must be finite", fn), 0;
    if (!quat_ok(orientation))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: orientation must be a finite unit quaternion", fn), 0;
    if (shape_from_def(w, def, CAROM_BODY_DYNAMIC, fn, out) != CAROM_OK) return 0;
    pose->p = to_v3(position);
    pose->q = q_normalize((quat){orientation.w, orientation.x, orientation.y, orientation.z});
    return 1;
}

/* ---- candidates --------------------------------------------------------------- */

typedef struct candidate_list {
    int *items;
    int count, capacity;
    int failed;
} candidate_list;

static int collect_candidate(void *ctx, int id_index)
{
    candidate_list *l = ctx;
    if (!array_reserve((void **)&l->items, &l->capacity, l->count + 1, sizeof *l->items)) {
        l->failed = 1;
        return 0;
    }
    l->items[l->count++] = id_index;
    return 1;
}

static int compare_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Id indices of the bodies whose bounds meet box, ascending (a stable order
 * whatever the tree's shape). 0 on out of memory. */
static int find_candidates(const carom_world *w, aabb box, candidate_list *l)
{
    memset(l, 0, sizeof *l);
    bp_query(w->bp, box, collect_candidate, l);
    if (l->failed) { free(l->items); l->items = NULL; return 0; }
    if (l->count > 1) qsort(l->items, (size_t)l->count, sizeof *l->items, compare_int);
    return 1;
}

/* ---- rays --------------------------------------------------------------------- */

/* A hit and the part of the body it is on (-1: the body is one part). */
typedef struct part_hit {
    carom_ray_hit hit;
    int part;
} part_hit;

typedef struct ray_hits {
    query_context q;
    part_hit *items;
    int count, capacity;
    int all, failed;
    part_hit best;
} ray_hits;

static double ray_visit(void *ctx, int id_index, vec3 origin, vec3 dir, double max_t)
{
    ray_hits *h = ctx;
    const body_store *s = &h->q.w->bodies;
    int slot = s->ids[id_index].slot;
    double t;
    vec3 n;
    int part;
    if (slot < 0 || !ray_body(s, slot, origin, dir, h->all ? 1.0 : max_t, &t, &n, &part))
        return max_t;
    if (!body_visible(&h->q, id_index)) return max_t;
    part_hit hit;
    hit.hit.body = world_make_id(h->q.w, id_index);
    hit.hit.point = from_v3(v3_madd(origin, t, dir));
    hit.hit.normal = from_v3(n);
    hit.hit.fraction = t;
    hit.part = part;
    if (!h->all) {
        h->best = hit;
        h->count = 1;
        return t; /* clip: only closer hits from now on */
    }
    if (!array_reserve((void **)&h->items, &h->capacity, h->count + 1, sizeof *h->items)) {
        h->failed = 1;
        return -1.0;
    }
    h->items[h->count++] = hit;
    return max_t;
}

static int check_ray(const carom_world *w, const char *fn, carom_vec3 origin, carom_vec3 translation)
{
    if (!v3_is_finite(to_v3(origin)) || !v3_is_finite(to_v3(translation)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: origin and translation must be finite", fn), 0;
    return 1;
}

/* The closest hit and its part (child may be NULL): the public closest-hit
 * casts, their checks and messages under fn. */
static int ray_cast_closest(const carom_world *w, const char *fn, carom_vec3 origin, carom_vec3 translation,
                            const carom_query_filter *filter, carom_ray_hit *hit, int *child)
{
    if (child) *child = -1;
    if (!w) return -1;
    if (!hit) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: hit is NULL", fn), -1;
    if (!check_ray(w, fn, origin, translation)) return -1;
    memset(hit, 0, sizeof *hit);
    if (v3_len2(to_v3(translation)) == 0) return 0;
    ray_hits h;
    memset(&h, 0, sizeof h);
    h.q.w = w;
    h.q.filter = filter;
    int was = query_lock(w);
    bp_ray_cast(w->bp, to_v3(origin), to_v3(translation), 1.0, ray_visit, &h);
    query_unlock(w, was);
    if (h.count) {
        *hit = h.best.hit;
        if (child) *child = h.best.part;
    }
    return h.count;
}

CAROM_API int carom_world_ray_cast_filtered(const carom_world *w, carom_vec3 origin, carom_vec3 translation,
                                            const carom_query_filter *filter, carom_ray_hit *hit)
{
    return ray_cast_closest(w, "ray_cast", origin, translation, filter, hit, NULL);
}

CAROM_API int carom_world_ray_cast(const carom_world *w, carom_vec3 origin, carom_vec3 translation, carom_ray_hit *hit)
{
    return carom_world_ray_cast_filtered(w, origin, translation, NULL, hit);
}

CAROM_API int carom_world_ray_cast_child(const carom_world *w, carom_vec3 origin, carom_vec3 translation,
                                         carom_ray_hit *hit, int *child)
{
    return ray_cast_closest(w, "ray_cast_child", origin, translation, NULL, hit, child);
}

static int compare_hits(const void *pa, const void *pb)
{
    const carom_ray_hit *a = &((const part_hit *)pa)->hit, *b = &((const part_hit *)pb)->hit;
    if (a->fraction != b->fraction) return a->fraction < b->fraction ? -1 : 1;
    return (a->body.index1 > b->body.index1) - (a->body.index1 < b->body.index1);
}

/* Every hit, nearest first, and the part of each (children may be NULL). */
static int ray_cast_every(const carom_world *w, const char *fn, carom_vec3 origin, carom_vec3 translation,
                          const carom_query_filter *filter, carom_ray_hit *hits, int *children, int capacity)
{
    if (!w) return -1;
    if (capacity < 0 || (capacity > 0 && !hits))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: bad output array", fn), -1;
    if (!check_ray(w, fn, origin, translation)) return -1;
    if (v3_len2(to_v3(translation)) == 0) return 0;
    ray_hits h;
    memset(&h, 0, sizeof h);
    h.q.w = w;
    h.q.filter = filter;
    h.all = 1;
    int was = query_lock(w);
    bp_ray_cast(w->bp, to_v3(origin), to_v3(translation), 1.0, ray_visit, &h);
    query_unlock(w, was);
    if (h.failed) {
        free(h.items);
        return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn), -1;
    }
    if (h.count > 1) qsort(h.items, (size_t)h.count, sizeof *h.items, compare_hits);
    for (int i = 0; i < h.count && i < capacity; i++) {
        hits[i] = h.items[i].hit;
        if (children) children[i] = h.items[i].part;
    }
    free(h.items);
    return h.count;
}

CAROM_API int carom_world_ray_cast_all(const carom_world *w, carom_vec3 origin, carom_vec3 translation,
                                       const carom_query_filter *filter, carom_ray_hit *hits, int capacity)
{
    return ray_cast_every(w, "ray_cast_all", origin, translation, filter, hits, NULL, capacity);
}

CAROM_API int carom_world_ray_cast_all_children(const carom_world *w, carom_vec3 origin, carom_vec3 translation,
                                                const carom_query_filter *filter, carom_ray_hit *hits, int *children,
                                                int capacity)
{
    return ray_cast_every(w, "ray_cast_all_children", origin, translation, filter, hits, children, capacity);
}

/* ---- shape casts, overlaps, distances ----------------------------------------- */

/* The first body the sweep touches, and the part of it (child may be NULL). */
static int shape_cast_first(const carom_world *w, const char *fn, const carom_shape_def *def, carom_vec3 position,
                            carom_quat orientation, carom_vec3 translation, const carom_query_filter *filter,
                            carom_ray_hit *hit, int *child)
{
    if (child) *child = -1;
    if (!w) return -1;
    if (!hit) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: hit is NULL", fn), -1;
    if (!v3_is_finite(to_v3(translation)))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: translation must be finite", fn), -1;
    shape sh;
    xform pose;
    if (!query_shape(w, fn, def, position, orientation, &sh, &pose)) return -1;
    memset(hit, 0, sizeof *hit);
    vec3 T = to_v3(translation);
    aabb start = shape_aabb(&sh, pose), end = start;
    end.lo = v3_add(end.lo, T);
    end.hi = v3_add(end.hi, T);
    candidate_list l;
    if (!find_candidates(w, aabb_union(start, end), &l)) {
        hull_free(sh.hull);
        return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn), -1;
    }
    query_context q = {w, filter};
    gjk_proxy a = {&sh, NULL, 0, {v3_zero(), pose.q}};
    int found = 0;
    int was = query_lock(w);
    for (int i = 0; i < l.count; i++) {
        int slot = w->bodies.ids[l.items[i]].slot;
        gjk_proxy b = body_proxy(&w->bodies, slot, pose.p);
        int part;
        gjk_cast_result r = cast_body(&a, T, &b, &part);
        if (!r.hit || (found && r.fraction >= hit->fraction) || !body_visible(&q, l.items[i])) continue;
        found = 1;
        hit->body = world_make_id(w, l.items[i]);
        hit->fraction = r.fraction;
        hit->point = from_v3(v3_add(r.point, pose.p));
        hit->normal = from_v3(r.normal);
        if (child) *child = part;
    }
    query_unlock(w, was);
    free(l.items);
    hull_free(sh.hull);
    return found;
}

CAROM_API int carom_world_shape_cast(const carom_world *w, const carom_shape_def *def, carom_vec3 position,
                                     carom_quat orientation, carom_vec3 translation,
                                     const carom_query_filter *filter, carom_ray_hit *hit)
{
    return shape_cast_first(w, "shape_cast", def, position, orientation, translation, filter, hit, NULL);
}

CAROM_API int carom_world_shape_cast_child(const carom_world *w, const carom_shape_def *def, carom_vec3 position,
                                           carom_quat orientation, carom_vec3 translation,
                                           const carom_query_filter *filter, carom_ray_hit *hit, int *child)
{
    return shape_cast_first(w, "shape_cast_child", def, position, orientation, translation, filter, hit, child);
}

/* The overlapping bodies, and (children not NULL) the lowest part of each
 * the shape overlaps. */
static int overlap_bodies(const carom_world *w, const char *fn, const carom_shape_def *def, carom_vec3 position,
                          carom_quat orientation, const carom_query_filter *filter, carom_body_id *ids, int *children,
                          int capacity)
{
    if (!w) return -1;
    if (capacity < 0 || (capacity > 0 && !ids))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: bad output array", fn), -1;
    shape sh;
    xform pose;
    if (!query_shape(w, fn, def, position, orientation, &sh, &pose)) return -1;
    candidate_list l;
    if (!find_candidates(w, shape_aabb(&sh, pose), &l)) {
        hull_free(sh.hull);
        return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn), -1;
    }
    query_context q = {w, filter};
    gjk_proxy a = {&sh, NULL, 0, {v3_zero(), pose.q}};
    int count = 0;
    int was = query_lock(w);
    for (int i = 0; i < l.count; i++) {
        int slot = w->bodies.ids[l.items[i]].slot;
        gjk_proxy b = body_proxy(&w->bodies, slot, pose.p);
        gjk_result r = is_convex(b.s) ? gjk_distance(&a, &b) : pair_distance(&a, &b, 0.0);
        if (!r.overlap || !body_visible(&q, l.items[i])) continue;
        if (count < capacity) {
            ids[count] = world_make_id(w, l.items[i]);
            if (children) children[count] = overlap_part(&a, &b);
        }
        count++;
    }
    query_unlock(w, was);
    free(l.items);
    hull_free(sh.hull);
    return count;
}

CAROM_API int carom_world_overlap(const carom_world *w, const carom_shape_def *def, carom_vec3 position,
                                  carom_quat orientation, const carom_query_filter *filter, carom_body_id *ids,
                                  int capacity)
{
    return overlap_bodies(w, "overlap", def, position, orientation, filter, ids, NULL, capacity);
}

CAROM_API int carom_world_overlap_children(const carom_world *w, const carom_shape_def *def, carom_vec3 position,
                                           carom_quat orientation, const carom_query_filter *filter,
                                           carom_body_id *ids, int *children, int capacity)
{
    return overlap_bodies(w, "overlap_children", def, position, orientation, filter, ids, children, capacity);
}

static void fill_distance(carom_distance_result *out, const gjk_result *r, vec3 ref)
{
    out->distance = r->distance;
    out->point_a = from_v3(v3_add(r->point_a, ref));
    out->point_b = from_v3(v3_add(r->point_b, ref));
    out->normal = from_v3(r->normal);
}

CAROM_API carom_status carom_world_body_distance(const carom_world *w, carom_body_id a, carom_body_id b,
                                                 carom_distance_result *out)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (!out) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "distance: output pointer is NULL");
    const body_store *s = &w->bodies;
    int sa = body_store_slot(s, a.index1, a.generation), sb = body_store_slot(s, b.index1, b.generation);
    if (sa < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "distance: body a has been destroyed (or the id is invalid)");
    if (sb < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "distance: body b has been destroyed (or the id is invalid)");
    if (sa == sb) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "distance: a and b are the same body");
    if (s->shapes[sa].type == SHAPE_PLANE && s->shapes[sb].type == SHAPE_PLANE)
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "distance: both bodies are planes");
    vec3 ref = body_origin(s, sa);
    gjk_proxy pa = body_proxy(s, sa, ref), pb = body_proxy(s, sb, ref);
    gjk_result r = pair_distance(&pa, &pb, 4 * RANGE_COORDINATE_MAX); /* every triangle */
    if (!isfinite(r.distance))
        return world_fail(w, CAROM_ERROR_UNSUPPORTED, "distance: a mesh or height field against a plane or another mesh");
    memset(out, 0, sizeof *out);
    out->body = b;
    fill_distance(out, &r, ref);
    return CAROM_OK;
}

CAROM_API int carom_world_shape_distance(const carom_world *w, const carom_shape_def *def, carom_vec3 position,
                                         carom_quat orientation, double max_distance,
                                         const carom_query_filter *filter, carom_distance_result *out)
{
    const char *fn = "shape_distance";
    if (!w) return -1;
    if (!out) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: output pointer is NULL", fn), -1;
    if (!(isfinite(max_distance) && max_distance >= 0))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: max_distance must be finite and >= 0 (got %g)", fn,
                          max_distance), -1;
    shape sh;
    xform pose;
    if (!query_shape(w, fn, def, position, orientation, &sh, &pose)) return -1;
    candidate_list l;
    if (!find_candidates(w, aabb_fatten(shape_aabb(&sh, pose), max_distance), &l)) {
        hull_free(sh.hull);
        return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn), -1;
    }
    query_context q = {w, filter};
    gjk_proxy a = {&sh, NULL, 0, {v3_zero(), pose.q}};
    int found = 0;
    memset(out, 0, sizeof *out);
    int was = query_lock(w);
    for (int i = 0; i < l.count; i++) {
        int slot = w->bodies.ids[l.items[i]].slot;
        gjk_proxy b = body_proxy(&w->bodies, slot, pose.p);
        gjk_result r = pair_distance(&a, &b, max_distance);
        if (r.distance > max_distance || (found && r.distance >= out->distance)) continue;
        if (!body_visible(&q, l.items[i])) continue;
        found = 1;
        out->body = world_make_id(w, l.items[i]);
        fill_distance(out, &r, pose.p);
    }
    query_unlock(w, was);
    free(l.items);
    hull_free(sh.hull);
    return found;
}
