/* test_collide_analytic.c - the closed-form pairs against hand-computed depths,
 * normals and points, and 10,000 random configurations per pair checked
 * against independent brute-force distances (clamping, golden-section search,
 * sampled separating directions). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "collide_analytic.h"

#define PI 3.14159265358979323846
#ifndef SWEEP_CASES /* -DSWEEP_CASES=1000000 for a long soak */
#define SWEEP_CASES 10000
#endif
#define SWEEP_SEED 0x9e3779b97f4a7c15ULL

/* ---- construction --------------------------------------------------------- */

static shape make(int type)
{
    shape s;
    memset(&s, 0, sizeof s);
    s.type = type;
    return s;
}
static shape sphere(double r) { shape s = make(SHAPE_SPHERE); s.radius = r; return s; }
static shape box(double x, double y, double z) { shape s = make(SHAPE_BOX); s.half_extents = v3(x, y, z); return s; }
static shape capsule(double r, double hh) { shape s = make(SHAPE_CAPSULE); s.radius = r; s.half_height = hh; return s; }
static shape plane(vec3 n, double offset)
{
    shape s = make(SHAPE_PLANE);
    s.plane_normal = n;
    s.plane_offset = offset;
    return s;
}
static shape ground(void) { return plane(v3(0, 0, 1), 0.0); }
static xform at(double x, double y, double z) { xform t = {v3(x, y, z), q_identity()}; return t; }
static xform at_rot(double x, double y, double z, vec3 axis, double angle)
{
    xform t = {v3(x, y, z), q_axis_angle(axis, angle)};
    return t;
}
/* capsule axis (local z) turned onto world x / world y */
static xform capsule_along_x(double x, double y, double z) { return at_rot(x, y, z, v3(0, 1, 0), 0.5 * PI); }
static xform capsule_along_y(double x, double y, double z) { return at_rot(x, y, z, v3(1, 0, 0), 0.5 * PI); }

typedef int (*pair_fn)(const shape *, xform, const shape *, xform, double, manifold *);

/* ---- assertions ----------------------------------------------------------- */

static void near(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) fail_msg("%s: got %.15g, want %.15g (tol %g)", what, got, want, tol);
}
static void near_v(vec3 got, vec3 want, double tol, const char *what)
{
    if (!(v3_len(v3_sub(got, want)) <= tol))
        fail_msg("%s: got (%.12g %.12g %.12g), want (%.12g %.12g %.12g)", what, got.x, got.y, got.z, want.x, want.y,
                 want.z);
}
/* the point with the given id, or fail */
static const manifold_point *point_with_id(const manifold *m, uint32_t id)
{
    for (int i = 0; i < m->count; i++)
        if (m->points[i].id == id) return &m->points[i];
    fail_msg("no point with id %u among %d", (unsigned)id, m->count);
    return NULL;
}
static double min_separation(const manifold *m)
{
    double s = INFINITY;
    for (int i = 0; i < m->count; i++) s = dmin(s, m->points[i].separation);
    return s;
}

/* ---- independent geometry --------------------------------------------------- */

static double point_segment_distance(vec3 p, vec3 a, vec3 b)
{
    vec3 d = v3_sub(b, a);
    double l2 = v3_len2(d);
    double t = l2 > 0 ? v3_dot(v3_sub(p, a), d) / l2 : 0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return v3_len(v3_sub(p, v3_madd(a, t, d)));
}

static void capsule_ends_world(const shape *s, xform x, vec3 *p0, vec3 *p1)
{
    vec3 u = q_rotate(x.q, v3(0, 0, 1));
    *p0 = v3_madd(x.p, -s->half_height, u);
    *p1 = v3_madd(x.p, s->half_height, u);
}

/* signed distance from world point p to shape s at x (< 0 inside) */
static double signed_distance(const shape *s, xform x, vec3 p)
{
    switch (s->type) {
    case SHAPE_SPHERE: return v3_len(v3_sub(p, x.p)) - s->radius;
    case SHAPE_CAPSULE: {
        vec3 p0, p1;
        capsule_ends_world(s, x, &p0, &p1);
        return point_segment_distance(p, p0, p1) - s->radius;
    }
    case SHAPE_BOX: {
        vec3 l = xf_inv_point(x, p), h = s->half_extents;
        vec3 q = v3_sub(v3_abs(l), h);
        double outside = v3_len(v3_max(q, v3_zero()));
        double inside = dmin(dmax(q.x, dmax(q.y, q.z)), 0.0);
        return outside + inside;
    }
    case SHAPE_PLANE: {
        vec3 n = q_rotate(x.q, s->plane_normal);
        return v3_dot(n, p) - (s->plane_offset + v3_dot(n, x.p));
    }
    default: fail_msg("unexpected shape type %d", s->type); return 0;
    }
}

/* minimum of a convex function on [0, 1] by golden-section search */
typedef double (*convex_fn)(double t, const void *ctx);
static double golden_min(convex_fn f, const void *ctx, double *t_min)
{
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    double lo = 0, hi = 1, x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1, ctx), f2 = f(x2, ctx);
    for (int i = 0; i < 90; i++) {
        if (f1 <= f2) { hi = x2; x2 = x1; f2 = f1; x1 = hi - g * (hi - lo); f1 = f(x1, ctx); }
        else { lo = x1; x1 = x2; f1 = f2; x2 = lo + g * (hi - lo); f2 = f(x2, ctx); }
    }
    double best = 0, fb = f(0, ctx), fe = f(1, ctx), fm = f(0.5 * (lo + hi), ctx);
    if (fe < fb) { fb = fe; best = 1; }
    if (fm < fb) { fb = fm; best = 0.5 * (lo + hi); }
    *t_min = best;
    return fb;
}

typedef struct seg_ctx { vec3 a0, a1, b0, b1; vec3 h; } seg_ctx;
static double seg_to_seg(double s, const void *ctx)
{
    const seg_ctx *c = ctx;
    return point_segment_distance(v3_lerp(c->a0, c->a1, s), c->b0, c->b1);
}
static double box_outside_distance(vec3 l, vec3 h)
{
    return v3_len(v3_max(v3_sub(v3_abs(l), h), v3_zero()));
}
static double seg_to_box(double t, const void *ctx)
{
    const seg_ctx *c = ctx;
    return box_outside_distance(v3_lerp(c->a0, c->a1, t), c->h);
}

/* overlap of the segment [s0, s1] (box frame) and the box [-h, h] along unit l, for
 * the box on the negative side: box max minus segment min */
static double oriented_overlap(vec3 s0, vec3 s1, vec3 h, vec3 l)
{
    return v3_dot(h, v3_abs(l)) - dmin(v3_dot(s0, l), v3_dot(s1, l));
}

/* ---- random configurations (local state, fixed seed) -------------------------- */

typedef struct rng { uint64_t s; } rng;
static double uniform(rng *r, double lo, double hi)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    uint64_t x = r->s * 0x2545F4914F6CDD1DULL;
    return lo + (hi - lo) * (double)(x >> 11) * (1.0 / 9007199254740992.0);
}
static vec3 random_vec(rng *r, double ext) { return v3(uniform(r, -ext, ext), uniform(r, -ext, ext), uniform(r, -ext, ext)); }
static vec3 random_unit(rng *r)
{
    for (;;) {
        vec3 v = random_vec(r, 1.0);
        double l = v3_len(v);
        if (l > 0.1 && l <= 1.0) return v3_scale(v, 1.0 / l);
    }
}
static quat random_quat(rng *r)
{
    quat q = {uniform(r, -1, 1), uniform(r, -1, 1), uniform(r, -1, 1), uniform(r, -1, 1)};
    return q_normalize(q);
}
static shape random_shape(rng *r, int type)
{
    switch (type) {
    case SHAPE_SPHERE: return sphere(uniform(r, 0.05, 1.0));
    case SHAPE_BOX: return box(uniform(r, 0.05, 1.5), uniform(r, 0.05, 1.5), uniform(r, 0.05, 1.5));
    case SHAPE_CAPSULE: return capsule(uniform(r, 0.05, 0.8), uniform(r, 0.0, 1.0) < 0.05 ? 0.0 : uniform(r, 0.01, 1.5));
    default: return plane(random_unit(r), uniform(r, -1, 1));
    }
}
/* b placed around a; sometimes exactly on a's centre, sometimes aligned with a */
static void random_pair_xforms(rng *r, xform *xa, xform *xb)
{
    xa->p = random_vec(r, 1.0);
    xa->q = random_quat(r);
    double kind = uniform(r, 0, 1);
    xb->p = kind < 0.05 ? xa->p : v3_add(xa->p, v3_scale(random_unit(r), uniform(r, 0.0, 3.5)));
    xb->q = kind > 0.9 ? xa->q : random_quat(r);
}

/* The checks every manifold must pass: finite, unit normal, at most 4 points,
 * each below the speculative distance, and each point's two surface points
 * (point -/+ separation/2 along the normal) inside or on shapes a and b. */
static void check_common_tol(const shape *a, xform xa, const shape *b, xform xb, double spec, const manifold *m,
                             int count, int icase, double surface_tol)
{
    if (!v3_is_finite(m->normal) || fabs(v3_len(m->normal) - 1.0) > 1e-9)
        fail_msg("case %d: normal (%g %g %g) not finite unit", icase, m->normal.x, m->normal.y, m->normal.z);
    if (count != m->count || count < 0 || count > MANIFOLD_MAX_POINTS)
        fail_msg("case %d: count %d / %d", icase, count, m->count);
    for (int i = 0; i < m->count; i++) {
        const manifold_point *p = &m->points[i];
        if (!v3_is_finite(p->point) || !isfinite(p->separation)) fail_msg("case %d: point %d not finite", icase, i);
        if (!(p->separation < spec)) fail_msg("case %d: separation %g not below speculative %g", icase, p->separation, spec);
        vec3 pa = v3_madd(p->point, -0.5 * p->separation, m->normal);
        vec3 pb = v3_madd(p->point, 0.5 * p->separation, m->normal);
        double da = signed_distance(a, xa, pa), db = signed_distance(b, xb, pb);
        if (da > surface_tol || db > surface_tol)
            fail_msg("case %d: point %d (id %u, sep %g) surface points outside: a %g, b %g", icase, i,
                     (unsigned)p->id, p->separation, da, db);
        for (int j = 0; j < i; j++)
            if (m->points[j].id == p->id) fail_msg("case %d: duplicate id %u", icase, (unsigned)p->id);
    }
}

static void check_common(const shape *a, xform xa, const shape *b, xform xb, double spec, const manifold *m,
                         int count, int icase)
{
    check_common_tol(a, xa, b, xb, spec, m, count, icase, 1e-9);
}

/* whether a true separation lies clearly on one side of spec: then the count must agree */
static void check_count_against(double true_sep, double spec, const manifold *m, int icase)
{
    if (true_sep < spec - 1e-9 && m->count == 0) fail_msg("case %d: true separation %g < spec %g but no point", icase, true_sep, spec);
    if (true_sep > spec + 1e-9 && m->count != 0) fail_msg("case %d: true separation %g > spec %g but %d points", icase, true_sep, spec, m->count);
}

/* ---- segment_segment_closest ----------------------------------------------------- */

static void test_segment_segment_closest(void **state)
{
    (void)state;
    double s, t;
    /* perpendicular, crossing above each other's middles */
    near(segment_segment_closest(v3(-1, 0, 0), v3(1, 0, 0), v3(0, -1, 1), v3(0, 1, 1), &s, &t), 1.0, 1e-15, "cross d2");
    near(s, 0.5, 1e-15, "cross s");
    near(t, 0.5, 1e-15, "cross t");
    /* skew, closest at an end of the second: lines meet at x=3 beyond the first segment's end x=1 */
    near(segment_segment_closest(v3(-1, 0, 0), v3(1, 0, 0), v3(3, -1, 2), v3(3, 1, 2), &s, &t), 4.0 + 4.0, 1e-12, "end d2");
    near(s, 1.0, 1e-15, "end s");
    near(t, 0.5, 1e-15, "end t");
    /* parallel and offset by (0, 0, 2): any closest pair is 2 apart */
    near(segment_segment_closest(v3(0, 0, 0), v3(2, 0, 0), v3(1, 0, 2), v3(3, 0, 2), &s, &t), 4.0, 1e-12, "parallel d2");
    near(v3_len(v3_sub(v3(2 * s, 0, 0), v3(1 + 2 * t, 0, 2))), 2.0, 1e-12, "parallel pair");
    /* points */
    near(segment_segment_closest(v3(1, 2, 3), v3(1, 2, 3), v3(1, 2, 5), v3(1, 2, 5), &s, &t), 4.0, 0, "points d2");
    /* a point against a segment: foot at t = 0.25 */
    near(segment_segment_closest(v3(1, 1, 0), v3(1, 1, 0), v3(0, 0, 0), v3(4, 0, 0), &s, &t), 1.0, 1e-15, "point-seg d2");
    near(t, 0.25, 1e-15, "point-seg t");
}

/* ---- sphere pairs --------------------------------------------------------------- */

static void test_sphere_sphere(void **state)
{
    (void)state;
    shape a = sphere(1.0), b = sphere(0.5);
    manifold m;
    /* gap 0.5 beyond a 0.1 margin */
    assert_int_equal(collide_sphere_sphere(&a, at(0, 0, 0), &b, at(2, 0, 0), 0.1, &m), 0);
    near_v(m.normal, v3(1, 0, 0), 1e-15, "separated normal");
    /* within a 1.0 margin: gap 0.5, midway between x=1 and x=1.5 */
    assert_int_equal(collide_sphere_sphere(&a, at(0, 0, 0), &b, at(2, 0, 0), 1.0, &m), 1);
    near(m.points[0].separation, 0.5, 1e-15, "speculative sep");
    near_v(m.points[0].point, v3(1.25, 0, 0), 1e-15, "speculative point");
    /* touching along (0, 3, 4)/5 */
    assert_int_equal(collide_sphere_sphere(&a, at(1, 1, 1), &b, at(1, 1 + 0.9, 1 + 1.2), 0.0 + 1e-12, &m), 1);
    near(m.points[0].separation, 0.0, 1e-15, "touching sep");
    near_v(m.normal, v3(0, 0.6, 0.8), 1e-15, "touching normal");
    near_v(m.points[0].point, v3(1, 1.6, 1.8), 1e-15, "touching point");
    /* deep: centres 0.5 apart, overlap 1.0: surfaces at x=1 (a) and x=0 (b) */
    assert_int_equal(collide_sphere_sphere(&a, at(0, 0, 0), &b, at(0.5, 0, 0), 0.0, &m), 1);
    near(m.points[0].separation, -1.0, 1e-15, "deep sep");
    near_v(m.points[0].point, v3(0.5, 0, 0), 1e-15, "deep point");
    /* coincident: +z, overlap the sum of radii */
    assert_int_equal(collide_sphere_sphere(&a, at(3, 2, 1), &b, at(3, 2, 1), 0.0, &m), 1);
    near_v(m.normal, v3(0, 0, 1), 0, "coincident normal");
    near(m.points[0].separation, -1.5, 1e-15, "coincident sep");
    assert_true(v3_is_finite(m.points[0].point));
}

static void test_sphere_plane(void **state)
{
    (void)state;
    shape s = sphere(0.5), g = ground();
    manifold m;
    assert_int_equal(collide_sphere_plane(&s, at(0, 0, 0.7), &g, at(0, 0, 0), 0.1, &m), 0);
    near_v(m.normal, v3(0, 0, -1), 0, "separated normal");
    assert_int_equal(collide_sphere_plane(&s, at(2, 3, 0.7), &g, at(0, 0, 0), 0.5, &m), 1);
    near(m.points[0].separation, 0.2, 1e-15, "speculative sep");
    near_v(m.points[0].point, v3(2, 3, 0.1), 1e-15, "speculative point");
    assert_int_equal(collide_sphere_plane(&s, at(0, 0, 0.5), &g, at(0, 0, 0), 0.0 + 1e-12, &m), 1);
    near(m.points[0].separation, 0.0, 1e-15, "touching sep");
    /* a plane in its own frame: local normal +z, offset 0.5, body at (0,0,1) turned
     * 90 degrees about y: world normal +x, world plane x = 0.5 + dot(x, (0,0,1)) = 0.5 */
    shape p = plane(v3(0, 0, 1), 0.5), big = sphere(0.75);
    assert_int_equal(collide_sphere_plane(&big, at(1.0, 3, 4), &p, at_rot(0, 0, 1, v3(0, 1, 0), 0.5 * PI), 0.0, &m), 1);
    near_v(m.normal, v3(-1, 0, 0), 1e-15, "rotated normal");
    near(m.points[0].separation, -0.25, 1e-15, "rotated sep");
    near_v(m.points[0].point, v3(0.375, 3, 4), 1e-15, "rotated point");
}

static void test_sphere_box(void **state)
{
    (void)state;
    shape b = box(1, 2, 3), s = sphere(0.5);
    manifold m;
    /* face region: gap 0.5 */
    assert_int_equal(collide_sphere_box(&s, at(2, 0, 0), &b, at(0, 0, 0), 0.1, &m), 0);
    assert_int_equal(collide_sphere_box(&s, at(2, 0, 0), &b, at(0, 0, 0), 1.0, &m), 1);
    near_v(m.normal, v3(-1, 0, 0), 1e-15, "face normal");
    near(m.points[0].separation, 0.5, 1e-15, "face sep");
    near_v(m.points[0].point, v3(1.25, 0, 0), 1e-15, "face point");
    /* edge region: offset (0.3, 0.4) from the edge x=1, y=2: touching */
    assert_int_equal(collide_sphere_box(&s, at(1.3, 2.4, 0.5), &b, at(0, 0, 0), 1e-12, &m), 1);
    near(m.points[0].separation, 0.0, 1e-15, "edge sep");
    near_v(m.normal, v3(-0.6, -0.8, 0), 1e-15, "edge normal");
    near_v(m.points[0].point, v3(1, 2, 0.5), 1e-15, "edge point");
    /* corner region: offset (1, 2, 2) from the corner (1, 2, 3): distance 3 */
    assert_int_equal(collide_sphere_box(&s, at(2, 4, 5), &b, at(0, 0, 0), 3.0, &m), 1);
    near(m.points[0].separation, 2.5, 1e-15, "corner sep");
    near_v(m.normal, v3(-1.0 / 3, -2.0 / 3, -2.0 / 3), 1e-15, "corner normal");
    /* centre inside, 0.2 under the +x face: pushed out through it */
    assert_int_equal(collide_sphere_box(&s, at(0.8, 0.5, -1), &b, at(0, 0, 0), 0.0, &m), 1);
    near_v(m.normal, v3(-1, 0, 0), 1e-15, "inside normal");
    near(m.points[0].separation, -0.7, 1e-15, "inside sep");
    near_v(m.points[0].point, v3(0.65, 0.5, -1), 1e-15, "inside point");
    /* centre at the box centre: the nearest face is x (half extent 1) */
    assert_int_equal(collide_sphere_box(&s, at(0, 0, 0), &b, at(0, 0, 0), 0.0, &m), 1);
    near(m.points[0].separation, -1.5, 1e-15, "centred sep");
    near(fabs(m.normal.x), 1.0, 1e-15, "centred normal");
    /* unit cube turned 45 degrees about z: its vertical edge at x = sqrt 2 */
    shape c = box(1, 1, 1);
    assert_int_equal(collide_sphere_box(&s, at(2, 0, 0.3), &c, at_rot(0, 0, 0, v3(0, 0, 1), 0.25 * PI), 0.1, &m), 1);
    near(m.points[0].separation, 2.0 - sqrt(2.0) - 0.5, 1e-14, "rotated sep");
    near_v(m.normal, v3(-1, 0, 0), 1e-14, "rotated normal");
    near_v(m.points[0].point, v3(0.5 * (sqrt(2.0) + 1.5), 0, 0.3), 1e-14, "rotated point");
}

static void test_sphere_capsule(void **state)
{
    (void)state;
    shape c = capsule(0.5, 1.0), s = sphere(0.25);
    manifold m;
    /* beside the axis: gap 0.25 */
    assert_int_equal(collide_sphere_capsule(&s, at(1, 0, 0.5), &c, at(0, 0, 0), 0.1, &m), 0);
    assert_int_equal(collide_sphere_capsule(&s, at(1, 0, 0.5), &c, at(0, 0, 0), 0.3, &m), 1);
    near_v(m.normal, v3(-1, 0, 0), 1e-15, "side normal");
    near(m.points[0].separation, 0.25, 1e-15, "side sep");
    near_v(m.points[0].point, v3(0.625, 0, 0.5), 1e-15, "side point");
    /* beyond the +z end: nearest the end point (0, 0, 1) */
    assert_int_equal(collide_sphere_capsule(&s, at(0, 0, 2), &c, at(0, 0, 0), 0.3, &m), 1);
    near_v(m.normal, v3(0, 0, -1), 1e-15, "end normal");
    near(m.points[0].separation, 0.25, 1e-15, "end sep");
    /* touching at the end */
    assert_int_equal(collide_sphere_capsule(&s, at(0, 0, 1.75), &c, at(0, 0, 0), 1e-12, &m), 1);
    near(m.points[0].separation, 0.0, 1e-15, "end touching sep");
    near_v(m.points[0].point, v3(0, 0, 1.5), 1e-15, "end touching point");
    /* centre on the axis: a finite normal across the axis, overlap both radii */
    assert_int_equal(collide_sphere_capsule(&s, at(0, 0, 0.3), &c, at(0, 0, 0), 0.0, &m), 1);
    near(m.points[0].separation, -0.75, 1e-15, "on-axis sep");
    near(v3_len(m.normal), 1.0, 1e-15, "on-axis normal unit");
    near(m.normal.z, 0.0, 1e-15, "on-axis normal across the axis");
    /* capsule lying along x, sphere above x = 0.5: deep by 0.25 */
    assert_int_equal(collide_sphere_capsule(&s, at(0.5, 0, 0.5), &c, capsule_along_x(0, 0, 0), 0.0, &m), 1);
    near_v(m.normal, v3(0, 0, -1), 1e-15, "rotated normal");
    near(m.points[0].separation, -0.25, 1e-15, "rotated sep");
    near_v(m.points[0].point, v3(0.5, 0, 0.375), 1e-15, "rotated point");
}

/* ---- capsule pairs ---------------------------------------------------------------- */

static void test_capsule_capsule(void **state)
{
    (void)state;
    shape a = capsule(0.25, 1.0), b = capsule(0.25, 1.0);
    manifold m;
    /* crossing at right angles, axes 1 apart */
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_y(0, 0, 1), 0.4, &m), 0);
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_y(0, 0, 1), 0.6, &m), 1);
    near_v(m.normal, v3(0, 0, 1), 1e-15, "cross normal");
    near(m.points[0].separation, 0.5, 1e-15, "cross sep");
    near_v(m.points[0].point, v3(0, 0, 0.5), 1e-15, "cross point");
    /* crossing axes that intersect: normal along the common perpendicular, towards b */
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_y(0.2, 0, 0), 0.0, &m), 1);
    near_v(m.normal, v3(0, 0, 1), 1e-15, "intersecting normal");
    near(m.points[0].separation, -0.5, 1e-15, "intersecting sep");
    /* parallel along x, b shifted by 0.5 in x: overlap x in [-0.5, 1], gap 0.1 */
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_x(0.5, 0, 0.6), 0.05, &m), 0);
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_x(0.5, 0, 0.6), 0.2, &m), 2);
    near_v(m.normal, v3(0, 0, 1), 1e-15, "parallel normal");
    near(point_with_id(&m, 1)->separation, 0.1, 1e-15, "parallel low sep");
    near(point_with_id(&m, 2)->separation, 0.1, 1e-15, "parallel high sep");
    near_v(point_with_id(&m, 1)->point, v3(-0.5, 0, 0.3), 1e-15, "parallel low point");
    near_v(point_with_id(&m, 2)->point, v3(1.0, 0, 0.3), 1e-15, "parallel high point");
    /* parallel, touching, side by side along y */
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_x(0, 0.5, 0), 1e-12, &m), 2);
    near_v(m.normal, v3(0, 1, 0), 1e-15, "touching normal");
    near(min_separation(&m), 0.0, 1e-15, "touching sep");
    /* nearly parallel: b tilted by 0.02 rad in the xz plane, centre 0.6 up. Its low
     * end (-cos, 0, 0.6 - sin) is closest, straight above a: normal +z. The high point
     * of the overlap is a's point x = cos, where b's nearest point is at axial offset
     * o = cos^2 - 0.6 sin from b's centre: x = cos o, height 0.6 + sin o. */
    double th = 0.02, co = cos(th), si = sin(th);
    xform tilted = {v3(0, 0, 0.6), q_mul(q_axis_angle(v3(0, 1, 0), -th), q_axis_angle(v3(0, 1, 0), 0.5 * PI))};
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, tilted, 0.5, &m), 2);
    near_v(m.normal, v3(0, 0, 1), 1e-12, "tilted normal");
    near(point_with_id(&m, 1)->separation, 0.6 - si - 0.5, 1e-12, "tilted low sep");
    near(point_with_id(&m, 2)->separation, 0.6 + si * (co * co - 0.6 * si) - 0.5, 1e-12, "tilted high sep");
    near(point_with_id(&m, 1)->point.x, -co, 1e-12, "tilted low x");
    near(point_with_id(&m, 2)->point.x, 0.5 * (co + co * (co * co - 0.6 * si)), 1e-12, "tilted high x");
    /* coincident: finite unit normal across the axes, overlap both radii */
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(1, 2, 3), &b, capsule_along_x(1, 2, 3), 0.0, &m), 2);
    near_v(m.normal, v3(0, 0, 1), 1e-15, "coincident normal");
    near(point_with_id(&m, 1)->separation, -0.5, 1e-15, "coincident sep 1");
    near(point_with_id(&m, 2)->separation, -0.5, 1e-15, "coincident sep 2");
    /* end to end along x, gap 0.5 between the caps: one point */
    assert_int_equal(collide_capsule_capsule(&a, capsule_along_x(0, 0, 0), &b, capsule_along_x(3.0, 0, 0), 0.6, &m), 1);
    near_v(m.normal, v3(1, 0, 0), 1e-15, "end-end normal");
    near(m.points[0].separation, 0.5, 1e-15, "end-end sep");
    near_v(m.points[0].point, v3(1.5, 0, 0), 1e-15, "end-end point");
}

static void test_capsule_plane(void **state)
{
    (void)state;
    shape c = capsule(0.5, 1.0), g = ground();
    manifold m;
    /* lying on the ground: both ends touch */
    assert_int_equal(collide_capsule_plane(&c, capsule_along_x(0, 0, 0.5), &g, at(0, 0, 0), 0.01, &m), 2);
    near_v(m.normal, v3(0, 0, -1), 0, "lying normal");
    near(point_with_id(&m, 0)->separation, 0.0, 1e-15, "lying sep 0");
    near(point_with_id(&m, 1)->separation, 0.0, 1e-15, "lying sep 1");
    /* local -z end is world -x */
    near_v(point_with_id(&m, 0)->point, v3(-1, 0, 0), 1e-15, "lying point 0");
    near_v(point_with_id(&m, 1)->point, v3(1, 0, 0), 1e-15, "lying point 1");
    /* above by 0.2: beyond a 0.1 margin, within 0.3 */
    assert_int_equal(collide_capsule_plane(&c, capsule_along_x(0, 0, 0.7), &g, at(0, 0, 0), 0.1, &m), 0);
    assert_int_equal(collide_capsule_plane(&c, capsule_along_x(0, 0, 0.7), &g, at(0, 0, 0), 0.3, &m), 2);
    near(m.points[0].separation, 0.2, 1e-15, "hover sep");
    /* standing: only the low end */
    assert_int_equal(collide_capsule_plane(&c, at(0, 0, 1.4), &g, at(0, 0, 0), 0.1, &m), 1);
    assert_int_equal(m.points[0].id, 0);
    near(m.points[0].separation, -0.1, 1e-15, "standing sep");
    near_v(m.points[0].point, v3(0, 0, -0.05), 1e-15, "standing point");
    /* tilted 30 degrees from vertical, centre at 1.0: ends at 1 -/+ cos 30 */
    xform t30 = at_rot(0, 0, 1.0, v3(0, 1, 0), PI / 6);
    assert_int_equal(collide_capsule_plane(&c, t30, &g, at(0, 0, 0), 0.1, &m), 1);
    near(m.points[0].separation, 1.0 - cos(PI / 6) - 0.5, 1e-14, "tilted sep");
    near(m.points[0].point.x, -sin(PI / 6), 1e-14, "tilted point x");
    /* sunk: 0.3 deep */
    assert_int_equal(collide_capsule_plane(&c, capsule_along_x(0, 0, 0.2), &g, at(0, 0, 0), 0.0, &m), 2);
    near(min_separation(&m), -0.3, 1e-15, "sunk sep");
}

static void test_capsule_box(void **state)
{
    (void)state;
    shape b = box(2, 2, 0.5), c = capsule(0.25, 1.0);
    manifold m;
    /* lying on the top face: two points at the ends, ids of face +z (5): 16, 17 */
    assert_int_equal(collide_capsule_box(&c, capsule_along_x(0, 0, 0.75), &b, at(0, 0, 0), 0.01, &m), 2);
    near_v(m.normal, v3(0, 0, -1), 1e-15, "lying normal");
    near(point_with_id(&m, 16)->separation, 0.0, 1e-15, "lying sep lo");
    near(point_with_id(&m, 17)->separation, 0.0, 1e-15, "lying sep hi");
    near_v(point_with_id(&m, 16)->point, v3(-1, 0, 0.5), 1e-15, "lying point lo");
    near_v(point_with_id(&m, 17)->point, v3(1, 0, 0.5), 1e-15, "lying point hi");
    /* beyond the margin */
    assert_int_equal(collide_capsule_box(&c, capsule_along_x(0, 0, 0.95), &b, at(0, 0, 0), 0.1, &m), 0);
    /* one end lifted by a small tilt: the ends at heights 0.8 -/+ sin */
    double th = 0.05;
    xform lifted = {v3(0, 0, 0.8), q_mul(q_axis_angle(v3(0, 1, 0), -th), q_axis_angle(v3(0, 1, 0), 0.5 * PI))};
    assert_int_equal(collide_capsule_box(&c, lifted, &b, at(0, 0, 0), 0.2, &m), 2);
    near(point_with_id(&m, 16)->separation, 0.8 - sin(th) - 0.5 - 0.25, 1e-14, "lifted sep lo");
    near(point_with_id(&m, 17)->separation, 0.8 + sin(th) - 0.5 - 0.25, 1e-14, "lifted sep hi");
    /* hanging over the +x edge: the segment x in [1, 3] clipped to x <= 2 */
    assert_int_equal(collide_capsule_box(&c, capsule_along_x(2, 0, 0.7), &b, at(0, 0, 0), 0.1, &m), 2);
    near_v(point_with_id(&m, 16)->point, v3(1, 0, 0.475), 1e-15, "overhang point lo");
    near_v(point_with_id(&m, 17)->point, v3(2, 0, 0.475), 1e-15, "overhang point hi");
    near(point_with_id(&m, 17)->separation, -0.05, 1e-15, "overhang sep");
    /* sunk so the axis is 0.1 below the top face: the same face, the same ids */
    assert_int_equal(collide_capsule_box(&c, capsule_along_x(0, 0, 0.4), &b, at(0, 0, 0), 0.0, &m), 2);
    near_v(m.normal, v3(0, 0, -1), 1e-15, "sunk normal");
    near(point_with_id(&m, 16)->separation, -0.35, 1e-15, "sunk sep lo");
    near(point_with_id(&m, 17)->separation, -0.35, 1e-15, "sunk sep hi");
    near_v(point_with_id(&m, 16)->point, v3(-1, 0, 0.5 - 0.175), 1e-15, "sunk point");
    /* standing on the top face: only the low end */
    assert_int_equal(collide_capsule_box(&c, at(0.5, 0.5, 1.75), &b, at(0, 0, 0), 0.1, &m), 1);
    near(m.points[0].separation, 0.0, 1e-15, "standing sep");
    near_v(m.points[0].point, v3(0.5, 0.5, 0.5), 1e-15, "standing point");

    /* across the edge x = 1, z = 1 of a unit cube, the capsule along (1, 0, -1)/sqrt 2
     * with its centre d out along (1, 0, 1)/sqrt 2 from the edge: one point */
    shape cube = box(1, 1, 1);
    double d = 0.2, k = d / sqrt(2.0);
    xform across = at_rot(1 + k, 0.3, 1 + k, v3(0, 1, 0), 0.75 * PI); /* local z -> (1, 0, -1)/sqrt 2 */
    vec3 diag = v3(1 / sqrt(2.0), 0, 1 / sqrt(2.0));
    assert_int_equal(collide_capsule_box(&c, across, &cube, at(0, 0, 0), 0.0, &m), 1);
    near_v(m.normal, v3_neg(diag), 1e-14, "edge normal");
    near(m.points[0].separation, d - 0.25, 1e-14, "edge sep");
    near_v(m.points[0].point, v3_madd(v3(1, 0.3, 1), 0.5 * (d - 0.25), diag), 1e-14, "edge point");
    /* the same, the axis 0.05 inside the edge: separating-axis edge case, id 32 + 4*1 + 3 */
    d = -0.05;
    k = d / sqrt(2.0);
    across.p = v3(1 + k, 0.3, 1 + k);
    assert_int_equal(collide_capsule_box(&c, across, &cube, at(0, 0, 0), 0.0, &m), 1);
    near_v(m.normal, v3_neg(diag), 1e-14, "crossing edge normal");
    near(m.points[0].separation, d - 0.25, 1e-14, "crossing edge sep");
    near_v(m.points[0].point, v3_madd(v3(1, 0.3, 1), 0.5 * (d - 0.25), diag), 1e-14, "crossing edge point");
    assert_int_equal(m.points[0].id, 32 + 4 + 3);
    /* straight down through the cube's middle: the x face (first of the tied x, y)
     * with the segment clipped to z in [-1, 1] */
    shape tall = capsule(0.25, 2.0);
    assert_int_equal(collide_capsule_box(&tall, at(0, 0, 0), &cube, at(0, 0, 0), 0.0, &m), 2);
    near(fabs(m.normal.x), 1.0, 1e-15, "through normal");
    near(point_with_id(&m, 4)->separation, -1.25, 1e-15, "through sep lo");
    near(point_with_id(&m, 5)->separation, -1.25, 1e-15, "through sep hi");
    near(point_with_id(&m, 4)->point.z, -1.0, 1e-15, "through lo z");
    near(point_with_id(&m, 5)->point.z, 1.0, 1e-15, "through hi z");
    /* a box turned 90 degrees about z: the capsule on its top face still gets two points */
    assert_int_equal(collide_capsule_box(&c, capsule_along_x(0.1, 0.2, 0.74), &b, at_rot(0, 0, 0, v3(0, 0, 1), 0.5 * PI), 0.0, &m), 2);
    near(min_separation(&m), -0.01, 1e-14, "turned box sep");
    near_v(m.normal, v3(0, 0, -1), 1e-14, "turned box normal");
}

static void test_box_plane(void **state)
{
    (void)state;
    shape b = box(1, 2, 0.5), g = ground();
    manifold m;
    /* resting flat: the four bottom corners (no +z bit), at the corners */
    assert_int_equal(collide_box_plane(&b, at(0, 0, 0.5), &g, at(0, 0, 0), 0.02, &m), 4);
    near_v(m.normal, v3(0, 0, -1), 0, "rest normal");
    for (uint32_t id = 0; id < 4; id++) {
        const manifold_point *p = point_with_id(&m, id);
        near(p->separation, 0.0, 1e-15, "rest sep");
        near_v(p->point, v3(id & 1 ? 1 : -1, id & 2 ? 2 : -2, 0), 1e-15, "rest point");
    }
    /* small perturbations keep the ids */
    for (int i = 0; i < 50; i++) {
        double e = 1e-3 * (i - 25) / 25.0;
        xform x = {v3(0.3 * e, -e, 0.5 + 0.2 * e), q_normalize(q_mul(q_axis_angle(v3(1, 0, 0), e), q_axis_angle(v3(0, 1, 0), -0.7 * e)))};
        assert_int_equal(collide_box_plane(&b, x, &g, at(0, 0, 0), 0.02, &m), 4);
        for (uint32_t id = 0; id < 4; id++) point_with_id(&m, id);
    }
    /* beyond the margin */
    assert_int_equal(collide_box_plane(&b, at(0, 0, 0.7), &g, at(0, 0, 0), 0.1, &m), 0);
    /* unit cube on an edge (45 degrees about x), 0.01 deep: the two corners of the bottom edge */
    shape cube = box(1, 1, 1);
    double c = sqrt(2.0) - 0.01;
    assert_int_equal(collide_box_plane(&cube, at_rot(0, 0, c, v3(1, 0, 0), 0.25 * PI), &g, at(0, 0, 0), 0.1, &m), 2);
    for (int i = 0; i < 2; i++) {
        near(m.points[i].separation, -0.01, 1e-14, "edge sep");
        near(fabs(m.points[i].point.x), 1.0, 1e-14, "edge point x");
        near(m.points[i].point.y, 0.0, 1e-14, "edge point y");
        near(m.points[i].point.z, -0.005, 1e-14, "edge point z");
    }
    /* on a corner: the diagonal (1,1,1) turned onto -z, 0.02 deep: one point */
    vec3 diag = v3_normalize(v3(1, 1, 1));
    quat q = q_axis_angle(v3_cross(diag, v3(0, 0, -1)), acos(-diag.z));
    xform corner = {v3(0, 0, sqrt(3.0) - 0.02), q};
    assert_int_equal(collide_box_plane(&cube, corner, &g, at(0, 0, 0), 0.1, &m), 1);
    assert_int_equal(m.points[0].id, 7);
    near(m.points[0].separation, -0.02, 1e-14, "corner sep");
    near_v(m.points[0].point, v3(0, 0, -0.01), 1e-14, "corner point");
    /* thin plate within a wide margin: all 8 corners qualify, the 4 bottom ones kept */
    shape plate = box(1, 1, 0.01);
    assert_int_equal(collide_box_plane(&plate, at(0, 0, 0.01), &g, at(0, 0, 0), 0.5, &m), 4);
    for (uint32_t id = 0; id < 4; id++) near(point_with_id(&m, id)->separation, 0.0, 1e-15, "plate sep");
    /* a tilted plane: normal (0, 1, 1)/sqrt 2 through the origin, a cube turned to match
     * resting 0.1 above it: four points at separation 0.1 */
    quat tilt = q_axis_angle(v3(1, 0, 0), -0.25 * PI); /* z -> (0, 1, 1)/sqrt 2 */
    vec3 n = q_rotate(tilt, v3(0, 0, 1));
    xform on_slope = {v3_scale(n, 1.1), tilt};
    assert_int_equal(collide_box_plane(&cube, on_slope, &g, at_rot(0, 0, 0, v3(1, 0, 0), -0.25 * PI), 0.2, &m), 4);
    near_v(m.normal, v3_neg(n), 1e-15, "slope normal");
    for (uint32_t id = 0; id < 4; id++) near(point_with_id(&m, id)->separation, 0.1, 1e-14, "slope sep");
}

/* The same resting contacts 1e5 m from the origin, under small wobbles: the
 * same ids, separations within 1e-9 of the hand values. */
static void test_far_and_wobbling(void **state)
{
    (void)state;
    vec3 far = v3(1e5, -1e5, 3e4);
    shape b = box(2, 2, 0.5), c = capsule(0.25, 1.0), s = sphere(0.5), g = ground();
    xform ground_at = {far, q_identity()};
    manifold m;
    for (int i = 0; i <= 40; i++) {
        double e = 1e-4 * (i - 20) / 20.0; /* tilt (rad) and shift (m) */
        /* yaw 3e about z, then pitch e about y: a body point (x, y, z) rises by
         * -(x cos 3e - y sin 3e) sin e + z (cos e - 1) */
        quat wobble = q_mul(q_axis_angle(v3(0, 1, 0), e), q_axis_angle(v3(0, 0, 1), 3 * e));
        /* capsule lying on the box top face: ids 16, 17; its ends at x = -1, +1 */
        xform cx = capsule_along_x(far.x + e, far.y, far.z + 0.75 + e);
        cx.q = q_mul(wobble, cx.q);
        xform bx = {far, q_identity()};
        assert_int_equal(collide_capsule_box(&c, cx, &b, bx, 0.01, &m), 2);
        near(point_with_id(&m, 16)->separation, e + cos(3 * e) * sin(e), 1e-9, "far capsule-box lo");
        near(point_with_id(&m, 17)->separation, e - cos(3 * e) * sin(e), 1e-9, "far capsule-box hi");
        /* box resting on the ground: ids 0..3, bottom corners (+-2, +-2, -0.5) */
        xform bw = {v3_add(far, v3(e, -e, 0.5 + e)), wobble};
        assert_int_equal(collide_box_plane(&b, bw, &g, ground_at, 0.01, &m), 4);
        for (uint32_t id = 0; id < 4; id++) {
            double x = id & 1 ? 2 : -2, y = id & 2 ? 2 : -2;
            double rise = -(x * cos(3 * e) - y * sin(3 * e)) * sin(e) - 0.5 * (cos(e) - 1);
            near(point_with_id(&m, id)->separation, e + rise, 1e-9, "far box-plane");
        }
        /* capsule on capsule, crossed logs 0.5 apart: one point */
        assert_int_equal(collide_capsule_capsule(&c, capsule_along_x(far.x, far.y, far.z), &c, capsule_along_y(far.x + e, far.y, far.z + 0.5 + e), 0.01, &m), 1);
        near(m.points[0].separation, e, 1e-9, "far capsule-capsule");
        near_v(m.normal, v3(0, 0, 1), 1e-9, "far capsule-capsule normal");
        /* sphere on the box */
        assert_int_equal(collide_sphere_box(&s, at(far.x + 0.3, far.y - 0.2, far.z + 1.0 + e), &b, bx, 0.01, &m), 1);
        near(m.points[0].separation, e, 1e-9, "far sphere-box");
    }
}

/* ---- random sweeps ------------------------------------------------------------------ */

static void sweep_sphere_sphere(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED};
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_SPHERE), b = random_shape(&r, SHAPE_SPHERE);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_sphere_sphere(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        double want = v3_len(v3_sub(xb.p, xa.p)) - a.radius - b.radius;
        check_count_against(want, spec, &m, i);
        if (n) {
            if (fabs(m.points[0].separation - want) > 1e-12) fail_msg("case %d: sep %g want %g", i, m.points[0].separation, want);
            if (v3_len(v3_sub(xb.p, xa.p)) > 1e-6 &&
                v3_len(v3_sub(m.normal, v3_normalize(v3_sub(xb.p, xa.p)))) > 1e-9)
                fail_msg("case %d: normal not along the centres", i);
        }
    }
}

static void sweep_sphere_plane(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 1};
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_SPHERE), b = random_shape(&r, SHAPE_PLANE);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_sphere_plane(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        double want = signed_distance(&b, xb, xa.p) - a.radius;
        check_count_against(want, spec, &m, i);
        if (n && fabs(m.points[0].separation - want) > 1e-12) fail_msg("case %d: sep %g want %g", i, m.points[0].separation, want);
        if (v3_len(v3_add(m.normal, q_rotate(xb.q, b.plane_normal))) > 1e-12) fail_msg("case %d: normal not -plane normal", i);
    }
}

static void sweep_sphere_box(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 2};
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_SPHERE), b = random_shape(&r, SHAPE_BOX);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_sphere_box(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        /* independently: outside, the distance to the clamped point; inside, to the nearest face */
        vec3 c = xf_inv_point(xb, xa.p), h = b.half_extents;
        vec3 clamped = v3_max(v3_neg(h), v3_min(h, c));
        double out = v3_len(v3_sub(c, clamped));
        double in = dmin(h.x - fabs(c.x), dmin(h.y - fabs(c.y), h.z - fabs(c.z)));
        double want = (out > 0 ? out : -in) - a.radius;
        check_count_against(want, spec, &m, i);
        if (n && fabs(m.points[0].separation - want) > 1e-12) fail_msg("case %d: sep %g want %g", i, m.points[0].separation, want);
        if (n && out > 1e-6) {
            vec3 expect = q_rotate(xb.q, v3_normalize(v3_sub(clamped, c)));
            if (v3_len(v3_sub(m.normal, expect)) > 1e-9) fail_msg("case %d: normal off", i);
        }
    }
}

static void sweep_sphere_capsule(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 3};
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_SPHERE), b = random_shape(&r, SHAPE_CAPSULE);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_sphere_capsule(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        seg_ctx ctx;
        capsule_ends_world(&b, xb, &ctx.b0, &ctx.b1);
        ctx.a0 = ctx.a1 = xa.p;
        double t, dist = golden_min(seg_to_seg, &ctx, &t);
        double want = dist - a.radius - b.radius;
        check_count_against(want, spec, &m, i);
        if (n && fabs(m.points[0].separation - want) > 1e-9) fail_msg("case %d: sep %.12g want %.12g", i, m.points[0].separation, want);
    }
}

static void sweep_capsule_capsule(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 4};
    int two_point = 0;
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_CAPSULE), b = random_shape(&r, SHAPE_CAPSULE);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_capsule_capsule(&a, xa, &b, xb, spec, &m);
        seg_ctx ctx;
        capsule_ends_world(&a, xa, &ctx.a0, &ctx.a1);
        capsule_ends_world(&b, xb, &ctx.b0, &ctx.b1);
        /* two points of nearly parallel capsules are both measured along the one
         * normal, so their surface points may stray sideways by up to the length
         * times the sine of the angle between the axes */
        vec3 da = v3_sub(ctx.a1, ctx.a0), db = v3_sub(ctx.b1, ctx.b0);
        double stray = n == 2 ? v3_len(v3_cross(v3_normalize(da), v3_normalize(db))) * dmax(v3_len(da), v3_len(db)) : 0;
        check_common_tol(&a, xa, &b, xb, spec, &m, n, i, 1e-9 + stray);
        two_point += n == 2;
        /* distance between the axes: golden section over a's axis of the distance to b's */
        double s, dist = golden_min(seg_to_seg, &ctx, &s);
        double want = dist - a.radius - b.radius;
        check_count_against(want, spec, &m, i);
        if (n && fabs(min_separation(&m) - want) > 1e-9)
            fail_msg("case %d: min sep %.12g want %.12g (%d points)", i, min_separation(&m), want, n);
        if (dist > 1e-3) {
            /* the closest-point displacement of two convex sets is unique */
            vec3 pa = v3_lerp(ctx.a0, ctx.a1, s);
            seg_ctx back = {ctx.b0, ctx.b1, pa, pa, v3_zero()};
            double tb;
            golden_min(seg_to_seg, &back, &tb);
            vec3 dir = v3_normalize(v3_sub(v3_lerp(ctx.b0, ctx.b1, tb), pa));
            if (v3_len(v3_sub(dir, m.normal)) > 1e-5) fail_msg("case %d: normal off by %g", i, v3_len(v3_sub(dir, m.normal)));
        }
    }
    if (two_point < 50) fail_msg("only %d parallel cases: the sweep does not reach the two-point path", two_point);
}

static void sweep_capsule_plane(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 5};
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_CAPSULE), b = random_shape(&r, SHAPE_PLANE);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_capsule_plane(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        vec3 p0, p1;
        capsule_ends_world(&a, xa, &p0, &p1);
        double s0 = signed_distance(&b, xb, p0) - a.radius, s1 = signed_distance(&b, xb, p1) - a.radius;
        int want_n = (s0 < spec) + (s1 < spec);
        if (fabs(s0 - spec) > 1e-9 && fabs(s1 - spec) > 1e-9 && n != want_n) fail_msg("case %d: %d points want %d", i, n, want_n);
        if (n && fabs(min_separation(&m) - dmin(s0, s1)) > 1e-12) fail_msg("case %d: min sep off", i);
    }
}

static void sweep_capsule_box(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 6};
    rng dirs = {SWEEP_SEED + 60};
    int crossing = 0, two_point = 0;
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_CAPSULE), b = random_shape(&r, SHAPE_BOX);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_capsule_box(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        two_point += n == 2;
        vec3 w0, w1;
        capsule_ends_world(&a, xa, &w0, &w1);
        seg_ctx ctx = {xf_inv_point(xb, w0), xf_inv_point(xb, w1), v3_zero(), v3_zero(), b.half_extents};
        double t, dist = golden_min(seg_to_box, &ctx, &t);
        if (dist > 1e-6) {
            double want = dist - a.radius;
            check_count_against(want, spec, &m, i);
            if (n && fabs(min_separation(&m) - want) > 1e-9)
                fail_msg("case %d: min sep %.12g want %.12g", i, min_separation(&m), want);
            if (n && dist > 1e-3) {
                vec3 p = v3_lerp(ctx.a0, ctx.a1, t), h = b.half_extents;
                vec3 q = v3_max(v3_neg(h), v3_min(h, p));
                vec3 expect = q_rotate(xb.q, v3_normalize(v3_sub(q, p)));
                if (v3_len(v3_sub(expect, m.normal)) > 1e-5) fail_msg("case %d: normal off by %g", i, v3_len(v3_sub(expect, m.normal)));
            }
        } else if (dist == 0.0) {
            /* the axis crosses the box: the normal must be a least-overlap direction
             * (no sampled direction separates less), and no point deeper than that */
            crossing++;
            if (n == 0) fail_msg("case %d: crossing but no point", i);
            vec3 l = q_inv_rotate(xb.q, v3_neg(m.normal));
            double depth = oriented_overlap(ctx.a0, ctx.a1, b.half_extents, l);
            double sampled = INFINITY;
            for (int k = 0; k < 300; k++) {
                vec3 u = random_unit(&dirs);
                sampled = dmin(sampled, dmin(oriented_overlap(ctx.a0, ctx.a1, b.half_extents, u),
                                             oriented_overlap(ctx.a0, ctx.a1, b.half_extents, v3_neg(u))));
            }
            if (depth > sampled + 1e-9) fail_msg("case %d: overlap %.12g along the normal, %.12g along a sample", i, depth, sampled);
            if (min_separation(&m) < -depth - a.radius - 1e-9) fail_msg("case %d: point deeper than the overlap", i);
            if (min_separation(&m) > -a.radius + 1e-9) fail_msg("case %d: crossing but min sep %g > -radius", i, min_separation(&m));
        }
    }
    if (crossing < 200 || two_point < 50) fail_msg("sweep too thin: %d crossing, %d two-point", crossing, two_point);
}

/* Capsules moved to within +-2e-9 and +-2e-7 of touching a box (the code switches
 * from closest points to separating axes at 1e-9), and capsules lying almost flat near
 * a face (the two-point path): separations must match the gap set up. */
static void sweep_capsule_box_touching(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 8};
    int flat_two = 0;
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_CAPSULE), b = random_shape(&r, SHAPE_BOX);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        int flat = i % 2;
        if (flat) {
            /* lying along a random face, tilted by at most 0.01 rad, somewhere over it */
            int axis = (int)uniform(&r, 0, 3), side = uniform(&r, 0, 1) < 0.5 ? -1 : 1;
            vec3 out = v3_scale(v3(axis == 0, axis == 1, axis == 2), side), t1, t2;
            v3_basis(out, &t1, &t2);
            double ang = uniform(&r, 0, 2 * PI), tilt = uniform(&r, -0.01, 0.01);
            vec3 dir = v3_normalize(v3_madd(v3_add(v3_scale(t1, cos(ang)), v3_scale(t2, sin(ang))), tilt, out));
            vec3 z = v3(0, 0, 1);
            quat local = v3_dot(z, dir) < -0.999999 ? q_axis_angle(v3(1, 0, 0), PI)
                                                      : q_axis_angle(v3_cross(z, dir), acos(dmax(-1, dmin(1, v3_dot(z, dir)))));
            vec3 h = b.half_extents;
            vec3 c = v3(uniform(&r, -h.x, h.x), uniform(&r, -h.y, h.y), uniform(&r, -h.z, h.z));
            /* the centre's height over the face: radius plus -0.05 .. 0.1 */
            c = v3_madd(c, side * (v3_get(h, axis) + a.radius + uniform(&r, -0.05, 0.1)) - v3_get(c, axis), v3(axis == 0, axis == 1, axis == 2));
            xa.q = q_mul(xb.q, local);
            xa.p = xf_point(xb, c);
        }
        vec3 w0, w1;
        capsule_ends_world(&a, xa, &w0, &w1);
        seg_ctx ctx = {xf_inv_point(xb, w0), xf_inv_point(xb, w1), v3_zero(), v3_zero(), b.half_extents};
        double t, dist = golden_min(seg_to_box, &ctx, &t);
        double gap = dist;
        if (!flat) {
            if (dist < 1e-3) continue;
            /* slide the capsule along the closest-point direction to a tiny gap */
            vec3 p = v3_lerp(ctx.a0, ctx.a1, t), h = b.half_extents;
            vec3 dir = v3_normalize(v3_sub(p, v3_max(v3_neg(h), v3_min(h, p))));
            double g = i % 4 == 0 ? 2e-9 : 2e-7; /* straddling the 1e-9 switch, and around it */
            gap = uniform(&r, -g, g);
            xa.p = v3_madd(xa.p, gap - dist, q_rotate(xb.q, dir));
        }
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_capsule_box(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        if (flat && gap < 1e-6) {
            /* the axis dips into the face (or grazes it): by at most 0.05 + 1.5 sin 0.01 < 0.07 */
            if (n == 0 || min_separation(&m) < -a.radius - 0.07 || min_separation(&m) > gap - a.radius + 1e-9)
                fail_msg("case %d: %d points, min sep %.12g for a sunk axis, radius %.12g", i, n, min_separation(&m), a.radius);
        } else if (gap >= 1e-6) {
            check_count_against(gap - a.radius, spec, &m, i);
            if (n && fabs(min_separation(&m) - (gap - a.radius)) > 1e-9)
                fail_msg("case %d: min sep %.12g want %.12g", i, min_separation(&m), gap - a.radius);
        } else if (gap >= 0) {
            /* near the separating-axis switch (1e-9): a gap of 0 .. gap */
            if (n == 0 || min_separation(&m) < -a.radius - 1e-9 || min_separation(&m) > gap - a.radius + 1e-9)
                fail_msg("case %d: %d points, min sep %.12g for a gap of %g, radius %.12g", i, n, min_separation(&m), gap, a.radius);
        } else {
            /* moved in by -gap: the penetration depth is at most that */
            if (n == 0 || min_separation(&m) < gap - a.radius - 1e-9 || min_separation(&m) > -a.radius + 1e-9)
                fail_msg("case %d: %d points, min sep %.12g for an overlap of %g", i, n, min_separation(&m), -gap);
        }
        flat_two += flat && n == 2;
    }
    if (flat_two < SWEEP_CASES / 10) fail_msg("only %d flat two-point cases", flat_two);
}

static void sweep_box_plane(void **state)
{
    (void)state;
    rng r = {SWEEP_SEED + 7};
    for (int i = 0; i < SWEEP_CASES; i++) {
        shape a = random_shape(&r, SHAPE_BOX), b = random_shape(&r, SHAPE_PLANE);
        xform xa, xb;
        random_pair_xforms(&r, &xa, &xb);
        double spec = uniform(&r, 0, 0.3);
        manifold m;
        int n = collide_box_plane(&a, xa, &b, xb, spec, &m);
        check_common(&a, xa, &b, xb, spec, &m, n, i);
        /* brute force: every corner's signed distance; the kept ones are the deepest */
        double sep[8];
        int below = 0;
        for (int c = 0; c < 8; c++) {
            vec3 h = a.half_extents;
            sep[c] = signed_distance(&b, xb, xf_point(xa, v3(c & 1 ? h.x : -h.x, c & 2 ? h.y : -h.y, c & 4 ? h.z : -h.z)));
            below += sep[c] < spec;
        }
        int want_n = below < 4 ? below : 4;
        if (n != want_n) fail_msg("case %d: %d points, want %d", i, n, want_n);
        for (int k = 0; k < n; k++) {
            uint32_t id = m.points[k].id;
            if (id > 7 || fabs(m.points[k].separation - sep[id]) > 1e-12) fail_msg("case %d: id %u sep off", i, (unsigned)id);
            int deeper = 0; /* corners strictly deeper than this one must all be kept */
            for (int c = 0; c < 8; c++) deeper += sep[c] < sep[id] - 1e-12;
            if (deeper >= 4) fail_msg("case %d: corner %u kept over deeper ones", i, (unsigned)id);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_segment_segment_closest),
        cmocka_unit_test(test_sphere_sphere),
        cmocka_unit_test(test_sphere_plane),
        cmocka_unit_test(test_sphere_box),
        cmocka_unit_test(test_sphere_capsule),
        cmocka_unit_test(test_capsule_capsule),
        cmocka_unit_test(test_capsule_plane),
        cmocka_unit_test(test_capsule_box),
        cmocka_unit_test(test_box_plane),
        cmocka_unit_test(test_far_and_wobbling),
        cmocka_unit_test(sweep_sphere_sphere),
        cmocka_unit_test(sweep_sphere_plane),
        cmocka_unit_test(sweep_sphere_box),
        cmocka_unit_test(sweep_sphere_capsule),
        cmocka_unit_test(sweep_capsule_capsule),
        cmocka_unit_test(sweep_capsule_plane),
        cmocka_unit_test(sweep_capsule_box),
        cmocka_unit_test(sweep_capsule_box_touching),
        cmocka_unit_test(sweep_box_plane),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
