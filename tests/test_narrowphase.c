/* test_narrowphase.c - collide() against hand-computed answers for every pair
 * type, an independent brute-force 15-axis SAT over 10,000 random box pairs,
 * hulls built from box corners against the box path, feature-id stability
 * under jitter, a finiteness sweep over every pair of shape types, and every
 * overlap found by GJK has a contact point. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include "narrowphase.h"
#include "compound.h"
#include "shape.h"
#include "mesh.h"
#include <stdlib.h>
#include "world.h"
#include "gjk.h"
#include "helpers.h"
#include "heightfield.h"


/* ---- helpers ------------------------------------------------------------------ */

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
static shape cylinder(double r, double hh) { shape s = make(SHAPE_CYLINDER); s.radius = r; s.half_height = hh; return s; }
static shape ground(void) { shape s = make(SHAPE_PLANE); s.plane_normal = v3(0, 0, 1); s.plane_offset = 0; return s; }
static xform at(double x, double y, double z) { xform t = {v3(x, y, z), q_identity()}; return t; }
static xform at_rot(double x, double y, double z, vec3 axis, double angle)
{
    xform t = {v3(x, y, z), q_axis_angle(axis, angle)};
    return t;
}

/* Hull from xyz triples (asserts success). */
static shape hull_shape(const double *pts, int n)
{
    char err[128];
    shape s = make(SHAPE_HULL);
    s.hull = hull_build(pts, n, err, (int)sizeof err);
    if (!s.hull) print_error("hull_build: %s\n", err);
    assert_non_null(s.hull);
    return s;
}

static shape box_hull(vec3 he)
{
    double p[24];
    for (int i = 0; i < 8; i++) {
        p[3 * i] = (i & 1) ? he.x : -he.x;
        p[3 * i + 1] = (i & 2) ? he.y : -he.y;
        p[3 * i + 2] = (i & 4) ? he.z : -he.z;
    }
    return hull_shape(p, 8);
}

static int run(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *m)
{
    collide_cache c;
    memset(&c, 0, sizeof c);
    c.feature = -1;
    return collide(a, xa, b, xb, spec, &c, m);
}

static double min_sep(const manifold *m)
{
    double s = 1e300;
    for (int i = 0; i < m->count; i++) s = fmin(s, m->points[i].separation);
    return s;
}

static void sort_seps(const manifold *m, double out[MANIFOLD_MAX_POINTS])
{
    for (int i = 0; i < m->count; i++) out[i] = m->points[i].separation;
    for (int i = 1; i < m->count; i++)
        for (int j = i; j > 0 && out[j] < out[j - 1]; j--) {
            double t = out[j];
            out[j] = out[j - 1];
            out[j - 1] = t;
        }
}

#define NEAR(got, want, tol)                                                                  \
    do {                                                                                      \
        double g_ = (got), w_ = (want);                                                       \
        if (!(fabs(g_ - w_) <= (tol))) {                                                      \
            print_error("line %d: %s = %.12f, expected %.12f\n", __LINE__, #got, g_, w_);    \
            fail();                                                                           \
        }                                                                                     \
    } while (0)

#define NEAR_V(got, want, tol)                                                                \
    do {                                                                                      \
        vec3 gv_ = (got), wv_ = (want);                                                       \
        NEAR(gv_.x, wv_.x, tol);                                                              \
        NEAR(gv_.y, wv_.y, tol);                                                              \
        NEAR(gv_.z, wv_.z, tol);                                                              \
    } while (0)

/* Checks that hold for every manifold: unit finite normal, finite points, count <= 4. */
static void check_sane(const manifold *m)
{
    assert_true(m->count >= 0 && m->count <= MANIFOLD_MAX_POINTS);
    assert_true(v3_is_finite(m->normal));
    NEAR(v3_len(m->normal), 1.0, 1e-9);
    for (int i = 0; i < m->count; i++) {
        assert_true(v3_is_finite(m->points[i].point));
        assert_true(isfinite(m->points[i].separation));
    }
}

/* collide(a, b) then collide(b, a): same count, negated normal, same separations. */
static int run_both(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *m)
{
    manifold r;
    run(a, xa, b, xb, spec, m);
    run(b, xb, a, xa, spec, &r);
    check_sane(m);
    check_sane(&r);
    assert_int_equal(r.count, m->count);
    if (m->count > 0) NEAR_V(r.normal, v3_neg(m->normal), 1e-9);
    double s1[MANIFOLD_MAX_POINTS], s2[MANIFOLD_MAX_POINTS];
    sort_seps(m, s1);
    sort_seps(&r, s2);
    for (int i = 0; i < m->count; i++) NEAR(s2[i], s1[i], 1e-9);
    return m->count;
}

/* Independent sphere-box distance: clamp in the box frame. */
static double sphere_box_expected(vec3 c_world, double r, vec3 he, xform xb, vec3 *normal_a_to_b)
{
    vec3 c = q_inv_rotate(xb.q, v3_sub(c_world, xb.p));
    vec3 q = v3(fmax(-he.x, fmin(he.x, c.x)), fmax(-he.y, fmin(he.y, c.y)), fmax(-he.z, fmin(he.z, c.z)));
    double d = v3_len(v3_sub(c, q));
    if (d > 0) {
        *normal_a_to_b = q_rotate(xb.q, v3_scale(v3_sub(q, c), 1.0 / d));
        return d - r;
    }
    double dx = he.x - fabs(c.x), dy = he.y - fabs(c.y), dz = he.z - fabs(c.z);
    vec3 out;
    double depth;
    if (dx <= dy && dx <= dz) { out = v3(c.x < 0 ? -1 : 1, 0, 0); depth = dx; }
    else if (dy <= dz) { out = v3(0, c.y < 0 ? -1 : 1, 0); depth = dy; }
    else { out = v3(0, 0, c.z < 0 ? -1 : 1); depth = dz; }
    *normal_a_to_b = q_rotate(xb.q, v3_neg(out)); /* the sphere leaves through `out`: b moves the other way */
    return -depth - r;
}

/* ---- 1. hand cases -------------------------------------------------------------- */

static void test_sphere_sphere(void **state)
{
    (void)state;
    manifold m;
    shape s = sphere(0.5), t = sphere(0.25);
    assert_int_equal(run_both(&s, at(0, 0, 0), &s, at(1.5, 0, 0), 0.02, &m), 0);   /* beyond speculative */
    assert_int_equal(run_both(&s, at(0, 0, 0), &s, at(1.03, 0, 0), 0.02, &m), 0);
    assert_int_equal(run_both(&s, at(0, 0, 0), &s, at(1.01, 0, 0), 0.02, &m), 1);  /* speculative */
    NEAR(m.points[0].separation, 0.01, 1e-12);
    NEAR_V(m.normal, v3(1, 0, 0), 1e-12);
    NEAR_V(m.points[0].point, v3(0.505, 0, 0), 1e-12);
    assert_int_equal(run_both(&s, at(0, 0, 0), &s, at(0, 1.0, 0), 0.02, &m), 1);   /* touching */
    NEAR(m.points[0].separation, 0, 1e-12);
    NEAR_V(m.normal, v3(0, 1, 0), 1e-12);
    /* overlapping along a diagonal: distance 0.6, radii 0.75 */
    vec3 d = v3_scale(v3_normalize(v3(1, 2, -2)), 0.6);
    assert_int_equal(run_both(&s, at(1, 1, 1), &t, at(1 + d.x, 1 + d.y, 1 + d.z), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.15, 1e-12);
    NEAR_V(m.normal, v3_normalize(v3(1, 2, -2)), 1e-12);
    /* surfaces at 0.5 and 0.6 - 0.25 = 0.35 along n: midway 0.425 */
    NEAR_V(m.points[0].point, v3_madd(v3(1, 1, 1), 0.425, v3_normalize(v3(1, 2, -2))), 1e-12);
    run(&s, at(1, 2, 3), &s, at(1, 2, 3), 0.02, &m);                               /* coincident */
    check_sane(&m);
    assert_int_equal(m.count, 1);
    NEAR(m.points[0].separation, -1.0, 1e-12);
}

static void test_sphere_plane(void **state)
{
    (void)state;
    manifold m;
    shape s = sphere(0.5), g = ground();
    assert_int_equal(run_both(&s, at(3, 4, 0.6), &g, at(0, 0, 0), 0.02, &m), 0);
    assert_int_equal(run_both(&s, at(3, 4, 0.51), &g, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, 0.01, 1e-12);
    assert_int_equal(run_both(&s, at(3, 4, 0.4), &g, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.1, 1e-12);
    NEAR_V(m.normal, v3(0, 0, -1), 1e-12);                                           /* from the sphere into the plane */
    NEAR_V(m.points[0].point, v3(3, 4, -0.05), 1e-12);
    /* tilted plane with an offset: normal (0, 0.6, 0.8), offset 1; centre (0, 1, 1): dot = 1.4 */
    shape tp = make(SHAPE_PLANE);
    tp.plane_normal = v3(0, 0.6, 0.8);
    tp.plane_offset = 1.0;
    assert_int_equal(run_both(&s, at(0, 1, 1), &tp, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.1, 1e-12);
    NEAR_V(m.normal, v3(0, -0.6, -0.8), 1e-12);
    /* plane moved by its transform: ground raised to z = 2 and the sphere at z = 2.45 */
    assert_int_equal(run_both(&s, at(0, 0, 2.45), &g, at(5, 5, 2), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.05, 1e-12);
}

static void test_sphere_box(void **state)
{
    (void)state;
    manifold m;
    shape b = box(0.5, 1.0, 1.5);
    const double r = 0.3;
    shape s = sphere(r);
    /* corner, edge, face regions, inside near a face, rotated box */
    vec3 centres[6] = {v3(1.0, 1.3, 1.9), v3(0.2, 1.4, 1.7), v3(0.9, 0.2, 0.3), v3(0.1, 0.1, 0.1),
                       v3(0.45, -0.2, 0.4), v3(-0.1, 0.95, -1.2)};
    xform poses[2] = {at(0, 0, 0), at_rot(0.3, -0.2, 0.1, v3(1, 2, 3), 0.7)};
    for (int p = 0; p < 2; p++)
        for (int i = 0; i < 6; i++) {
            vec3 c = p == 0 ? centres[i] : xf_point(poses[1], centres[i]);
            vec3 n;
            double want = sphere_box_expected(c, r, b.half_extents, poses[p], &n);
            assert_int_equal(run_both(&s, at(c.x, c.y, c.z), &b, poses[p], 1.0, &m), 1);
            NEAR(m.points[0].separation, want, 1e-12);
            NEAR_V(m.normal, n, 1e-12);
        }
    /* face region by hand: centre 0.9 from the +x face plane at 0.5: gap 0.4 - 0.3 = 0.1 */
    assert_int_equal(run(&s, at(0.9, 0, 0), &b, at(0, 0, 0), 0.2, &m), 1);
    NEAR(m.points[0].separation, 0.1, 1e-12);
    NEAR_V(m.normal, v3(-1, 0, 0), 1e-12);
    NEAR_V(m.points[0].point, v3(0.55, 0, 0), 1e-12);
    assert_int_equal(run(&s, at(0.9, 0, 0), &b, at(0, 0, 0), 0.02, &m), 0);
    /* corner region by hand: corner (0.5, 1, 1.5), offset (0.2, 0.2, 0.1): distance 0.3 -> touching */
    assert_int_equal(run(&s, at(0.7, 1.2, 1.6), &b, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, 0.0, 1e-12);
}

static void test_sphere_capsule(void **state)
{
    (void)state;
    manifold m;
    shape s = sphere(0.5), cap = capsule(0.2, 0.5);
    assert_int_equal(run_both(&s, at(0.6, 0, 0.3), &cap, at(0, 0, 0), 0.02, &m), 1);   /* beside the segment */
    NEAR(m.points[0].separation, 0.6 - 0.7, 1e-12);
    NEAR_V(m.normal, v3(-1, 0, 0), 1e-12);
    NEAR_V(m.points[0].point, v3(0.15, 0, 0.3), 1e-12);
    assert_int_equal(run_both(&s, at(0, 0.3, 1.0), &cap, at(0, 0, 0), 0.02, &m), 1);   /* over the end cap */
    NEAR(m.points[0].separation, sqrt(0.09 + 0.25) - 0.7, 1e-12);
    NEAR_V(m.normal, v3_normalize(v3(0, -0.3, -0.5)), 1e-12);
    assert_int_equal(run_both(&s, at(0, 0, 2), &cap, at(0, 0, 0), 0.02, &m), 0);
    /* capsule lying along x (rotated about y), sphere above its middle */
    assert_int_equal(run_both(&s, at(0.2, 0, 0.69), &cap, at_rot(0, 0, 0, v3(0, 1, 0), 0.5 * PI_), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.01, 1e-12);
    NEAR_V(m.normal, v3(0, 0, -1), 1e-12);
}

static void test_capsule_pairs(void **state)
{
    (void)state;
    manifold m;
    shape c = capsule(0.25, 0.5), g = ground();
    xform lying = at_rot(0, 0, 0.24, v3(0, 1, 0), 0.5 * PI_);                        /* axis along x */
    assert_int_equal(run_both(&c, lying, &g, at(0, 0, 0), 0.02, &m), 2);            /* lying: two points */
    for (int i = 0; i < 2; i++) {
        NEAR(m.points[i].separation, -0.01, 1e-12);
        NEAR(fabs(m.points[i].point.x), 0.5, 1e-12);
        NEAR(m.points[i].point.z, -0.005, 1e-12);
    }
    NEAR_V(m.normal, v3(0, 0, -1), 1e-12);
    assert_int_equal(run_both(&c, at(0, 0, 0.74), &g, at(0, 0, 0), 0.02, &m), 1);   /* standing: one point */
    NEAR(m.points[0].separation, -0.01, 1e-12);
    /* tilted 30 degrees about y: the low end at z = 0.68 - 0.5 cos 30 - 0.25 */
    double zl = 0.68 - 0.5 * cos(PI_ / 6) - 0.25;
    assert_int_equal(run_both(&c, at_rot(0, 0, 0.68, v3(0, 1, 0), PI_ / 6), &g, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, zl, 1e-12);

    /* parallel capsules side by side: two points, gap 0.45 - 0.5 */
    xform beside = at_rot(0, 0.45, 0.24, v3(0, 1, 0), 0.5 * PI_);
    assert_int_equal(run_both(&c, lying, &c, beside, 0.02, &m), 2);
    for (int i = 0; i < 2; i++) {
        NEAR(m.points[i].separation, -0.05, 1e-12);
        NEAR(m.points[i].point.y, 0.225, 1e-12);
    }
    NEAR_V(m.normal, v3(0, 1, 0), 1e-12);
    /* parallel but offset along the axis by 0.6: the overlap [0.1, 0.5] of the segments */
    xform shifted = at_rot(0.6, 0.45, 0.24, v3(0, 1, 0), 0.5 * PI_);
    assert_int_equal(run_both(&c, lying, &c, shifted, 0.02, &m), 2);
    NEAR(fmin(m.points[0].point.x, m.points[1].point.x), 0.1, 1e-12);
    NEAR(fmax(m.points[0].point.x, m.points[1].point.x), 0.5, 1e-12);
    /* crossed at 90 degrees: one point, gap 0.45 - 0.5 along z */
    xform over = at_rot(0, 0, 0.24 + 0.45, v3(1, 0, 0), 0.5 * PI_);                 /* axis along y */
    assert_int_equal(run_both(&c, lying, &c, over, 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.05, 1e-12);
    NEAR_V(m.normal, v3(0, 0, 1), 1e-12);
    NEAR_V(m.points[0].point, v3(0, 0, 0.24 + 0.225), 1e-12);
    run(&c, at(0, 0, 0), &c, at(0, 0, 0), 0.02, &m);                                /* coincident */
    check_sane(&m);
    assert_true(m.count >= 1);

    /* capsule against a box */
    shape b = box(1, 1, 0.5);
    assert_int_equal(run_both(&c, lying, &b, at(0, 0, -0.5), 0.02, &m), 2);         /* lying on a box */
    for (int i = 0; i < 2; i++) NEAR(m.points[i].separation, -0.01, 1e-12);
    NEAR_V(m.normal, v3(0, 0, -1), 1e-12);
    assert_int_equal(run_both(&c, at(0.3, 0.2, 0.76), &b, at(0, 0, -0.5), 0.02, &m), 1); /* standing on a box */
    NEAR(m.points[0].separation, 0.01, 1e-12);
    NEAR_V(m.points[0].point, v3(0.3, 0.2, 0.005), 1e-12);
    /* upright capsule beside the box's +x face: 2 points (segment clipped to the face), gap 0.05 */
    assert_int_equal(run_both(&c, at(1.3, 0, -0.5), &b, at(0, 0, -0.5), 0.1, &m), 2);
    for (int i = 0; i < 2; i++) NEAR(m.points[i].separation, 0.05, 1e-12);
    NEAR_V(m.normal, v3(-1, 0, 0), 1e-12);
    /* capsule end over the box's top edge (x = 1, z = 0): distance from (1.2, 0, 0.2) is 0.2*sqrt2 */
    assert_int_equal(run_both(&c, at(1.2, 0, 0.7), &b, at(0, 0, -0.5), 0.1, &m), 1);
    NEAR(m.points[0].separation, 0.2 * sqrt(2.0) - 0.25, 1e-12);
    NEAR_V(m.normal, v3_normalize(v3(-1, 0, -1)), 1e-12);
}

static void test_box_plane(void **state)
{
    (void)state;
    manifold m;
    shape b = box(0.5, 0.5, 0.5), g = ground();
    assert_int_equal(run_both(&b, at(0, 0, 0.5), &g, at(0, 0, 0), 0.02, &m), 4);    /* resting: 4 corners */
    NEAR_V(m.normal, v3(0, 0, -1), 1e-12);
    for (int i = 0; i < 4; i++) {
        NEAR(m.points[i].separation, 0, 1e-12);
        NEAR(fabs(m.points[i].point.x), 0.5, 1e-12);
        NEAR(fabs(m.points[i].point.y), 0.5, 1e-12);
        NEAR(m.points[i].point.z, 0, 1e-12);
    }
    /* all four corners distinct */
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) assert_true(v3_len(v3_sub(m.points[i].point, m.points[j].point)) > 0.5);
    /* a 1 cm box, all eight corners within the 2 cm look-ahead: the four points
     * are still the bottom face's (a top corner among them leaves the box
     * standing on fewer supports than it has) */
    shape small = box(0.005, 0.005, 0.005);
    assert_int_equal(run_both(&small, at_rot(0.3, -0.2, 0.005, v3(0, 0, 1), 0.4), &g, at(0, 0, 0), 0.02, &m), 4);
    for (int i = 0; i < 4; i++) NEAR(m.points[i].separation, 0, 1e-12);
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) assert_true(v3_len(v3_sub(m.points[i].point, m.points[j].point)) > 0.005);
    /* tilted 0.2 rad onto an edge: the top face's corners stick out farther in
     * the plane than the bottom face's, and still must not be chosen */
    double th = 0.2, z0 = 0.005 * (cos(th) + sin(th));
    assert_int_equal(run_both(&small, at_rot(0, 0, z0, v3(1, 0, 0), th), &g, at(0, 0, 0), 0.02, &m), 4);
    for (int i = 0; i < 4; i++) assert_true(m.points[i].separation < 0.01 * sin(th) + 1e-12);
    /* 45 degrees about x: an edge down, two points at depth 0.05 */
    double h = 0.5 * sqrt(2.0);
    assert_int_equal(run_both(&b, at_rot(0, 0, h - 0.05, v3(1, 0, 0), 0.25 * PI_), &g, at(0, 0, 0), 0.02, &m), 2);
    for (int i = 0; i < 2; i++) {
        NEAR(m.points[i].separation, -0.05, 1e-12);
        NEAR(fabs(m.points[i].point.x), 0.5, 1e-12);
        NEAR(m.points[i].point.y, 0, 1e-12);
        NEAR(m.points[i].point.z, -0.025, 1e-12);
    }
    assert_true(m.points[0].point.x * m.points[1].point.x < 0);
    /* a corner down (rotated about x then y by 45): lowest corner at z0 - sqrt(3)/2 ... one point */
    quat q = q_mul(q_axis_angle(v3(0, 1, 0), atan(sqrt(0.5))), q_axis_angle(v3(1, 0, 0), 0.25 * PI_));
    xform xc = {v3(0, 0, 0.5 * sqrt(3.0) - 0.03), q};
    assert_int_equal(run_both(&b, xc, &g, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.03, 1e-12);
}

static void test_box_box(void **state)
{
    (void)state;
    manifold m;
    shape b = box(0.5, 0.5, 0.5);
    /* aligned stack: 4 points, normal +z, touching, at the corners */
    assert_int_equal(run_both(&b, at(0, 0, 0.5), &b, at(0, 0, 1.5), 0.02, &m), 4);
    NEAR_V(m.normal, v3(0, 0, 1), 1e-12);
    for (int i = 0; i < 4; i++) {
        NEAR(m.points[i].separation, 0, 1e-12);
        NEAR(fabs(m.points[i].point.x), 0.5, 1e-12);
        NEAR(fabs(m.points[i].point.y), 0.5, 1e-12);
        NEAR(m.points[i].point.z, 1.0, 1e-12);
    }
    /* deep overlap along x (0.3 of 1.0) */
    run_both(&b, at(0, 0, 0), &b, at(0.7, 0.1, 0), 0.02, &m);
    assert_int_equal(m.count, 4);
    NEAR_V(m.normal, v3(1, 0, 0), 1e-12);
    NEAR(min_sep(&m), -0.3, 1e-12);
    /* deep overlap along -y with different sizes: b2 half 0.2, centre y = -0.6: overlap 0.5 + 0.2 - 0.6 */
    shape small = box(0.2, 0.2, 0.2);
    run_both(&b, at(0, 0, 0), &small, at(0.05, -0.6, 0.1), 0.02, &m);
    NEAR_V(m.normal, v3(0, -1, 0), 1e-12);
    NEAR(min_sep(&m), -0.1, 1e-12);
    /* rotated 45 degrees about z on top of another: a face contact, 4 points, depth 0.01 */
    assert_int_equal(run_both(&b, at(0, 0, 0.5), &b, at_rot(0, 0, 1.49, v3(0, 0, 1), 0.25 * PI_), 0.02, &m), 4);
    NEAR_V(m.normal, v3(0, 0, 1), 1e-12);
    for (int i = 0; i < 4; i++) {
        NEAR(m.points[i].separation, -0.01, 1e-12);
        NEAR(m.points[i].point.z, 0.995, 1e-12);
        /* inside both squares: |x|,|y| <= 0.5 and |x|+|y| <= sqrt(2)/2, up to the
         * documented 0.5 mm clip tolerance for parallel faces (CLIP_TOLERANCE
         * in narrowphase.c keeps ids stable; points may sit that far outside) */
        const double clip_tol = 5e-4 + 1e-9;
        assert_true(fabs(m.points[i].point.x) <= 0.5 + clip_tol && fabs(m.points[i].point.y) <= 0.5 + clip_tol);
        assert_true(fabs(m.points[i].point.x) + fabs(m.points[i].point.y) <= sqrt(0.5) + clip_tol * sqrt(2.0));
    }
    /* edge on edge, crossed at 90 degrees: one point */
    double h = 0.5 * sqrt(2.0);
    xform e1 = at_rot(0, 0, 0, v3(1, 0, 0), 0.25 * PI_);                             /* top edge along x at z = h */
    xform e2 = at_rot(0, 0, 2 * h - 0.02, v3(0, 1, 0), 0.25 * PI_);                  /* bottom edge along y */
    assert_int_equal(run_both(&b, e1, &b, e2, 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.02, 1e-9);
    NEAR_V(m.normal, v3(0, 0, 1), 1e-9);
    NEAR_V(m.points[0].point, v3(0, 0, h - 0.01), 1e-9);
    /* the same edges 0.01 apart: one speculative point */
    xform e3 = at_rot(0, 0, 2 * h + 0.01, v3(0, 1, 0), 0.25 * PI_);
    assert_int_equal(run_both(&b, e1, &b, e3, 0.02, &m), 1);
    NEAR(m.points[0].separation, 0.01, 1e-9);
    /* separated beyond speculative */
    assert_int_equal(run_both(&b, at(0, 0, 0), &b, at(0, 0, 1.1), 0.02, &m), 0);
    assert_int_equal(run_both(&b, e1, &b, at_rot(0, 0, 2 * h + 0.05, v3(0, 1, 0), 0.25 * PI_), 0.02, &m), 0);
    /* order swap on a generic overlap */
    run_both(&b, at(0, 0, 0), &b, at_rot(0.7, 0.1, 0.05, v3(0.2, 0.1, 1), 0.1), 0.02, &m);
    assert_true(m.count > 0);
}

static void test_cylinder_pairs(void **state)
{
    (void)state;
    manifold m;
    shape cy = cylinder(0.5, 0.25), g = ground(), b = box(1, 1, 0.5);
    assert_int_equal(run_both(&cy, at(0, 0, 0.24), &g, at(0, 0, 0), 0.02, &m), 4);  /* standing on its cap */
    for (int i = 0; i < 4; i++) {
        NEAR(m.points[i].separation, -0.01, 1e-12);
        NEAR(hypot(m.points[i].point.x, m.points[i].point.y), 0.5, 1e-12);          /* on the rim */
        NEAR(m.points[i].point.z, -0.005, 1e-12);
    }
    xform lying = at_rot(0, 0, 0.49, v3(1, 0, 0), 0.5 * PI_);                        /* axis along y */
    assert_int_equal(run_both(&cy, lying, &g, at(0, 0, 0), 0.02, &m), 2);           /* on its side: a line */
    for (int i = 0; i < 2; i++) {
        NEAR(m.points[i].separation, -0.01, 1e-12);
        NEAR(fabs(m.points[i].point.y), 0.25, 1e-12);
        NEAR(m.points[i].point.x, 0, 1e-12);
    }
    /* tilted about x by 30 degrees: the lowest rim point is one point */
    double zl = 0.46 - 0.25 * cos(PI_ / 6) - 0.5 * sin(PI_ / 6);
    assert_int_equal(run_both(&cy, at_rot(0, 0, 0.46, v3(1, 0, 0), PI_ / 6), &g, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, zl, 1e-12);

    /* cylinder standing on a box (libccd picks the face) */
    run_both(&cy, at(0, 0, 0.74), &b, at(0, 0, 0), 0.02, &m);
    assert_true(m.count >= 3);
    NEAR(min_sep(&m), -0.01, 1e-9);
    NEAR_V(m.normal, v3(0, 0, -1), 1e-9);
    for (int i = 0; i < m.count; i++) NEAR(m.points[i].point.z, 0.495, 1e-9);
    /* cylinder lying on a box: 2 points along the bottom line */
    assert_int_equal(run_both(&cy, at_rot(0.2, 0.1, 0.99, v3(1, 0, 0), 0.5 * PI_), &b, at(0, 0, 0), 0.02, &m), 2);
    for (int i = 0; i < 2; i++) {
        NEAR(m.points[i].separation, -0.01, 1e-9);
        NEAR(m.points[i].point.x, 0.2, 1e-9);
        NEAR(fabs(m.points[i].point.y - 0.1), 0.25, 1e-9);
    }
    NEAR_V(m.normal, v3(0, 0, -1), 1e-9);
    /* beside each other, separated beyond speculative */
    assert_int_equal(run_both(&cy, at(1.6, 0, 0), &b, at(0, 0, 0), 0.02, &m), 0);
}

static void test_hull_pairs(void **state)
{
    (void)state;
    manifold m;
    /* tetrahedron with an interior point that hull_build must drop */
    double pts[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 0.2, 0.2};
    shape h = hull_shape(pts, 5), g = ground();
    assert_int_equal(h.hull->vertex_count, 4);
    assert_int_equal(run_both(&h, at(0, 0, -0.01), &g, at(0, 0, 0), 0.02, &m), 3);  /* a face on the plane */
    for (int i = 0; i < 3; i++) NEAR(m.points[i].separation, -0.01, 1e-12);
    NEAR_V(m.normal, v3(0, 0, -1), 1e-12);
    /* upside down (about x by pi): the apex (0,0,1) -> (0,0,-1); lift by 0.97: one point at depth 0.03 */
    assert_int_equal(run_both(&h, at_rot(0, 0, 0.97, v3(1, 0, 0), PI_), &g, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.03, 1e-12);
    NEAR_V(m.points[0].point, v3(0, 0, -0.015), 1e-12);

    /* sphere over the slanted face x + y + z = 1 */
    shape s = sphere(0.25);
    assert_int_equal(run_both(&s, at(0.3, 0.3, 1.2), &h, at(0, 0, 0), 0.5, &m), 1);
    NEAR(m.points[0].separation, 0.8 / sqrt(3.0) - 0.25, 1e-9);
    NEAR_V(m.normal, v3_scale(v3(1, 1, 1), -1.0 / sqrt(3.0)), 1e-9);
    /* sphere beyond the vertex (1,0,0) along +x: distance 0.3 */
    assert_int_equal(run_both(&s, at(1.3, 0, 0), &h, at(0, 0, 0), 0.1, &m), 1);
    NEAR(m.points[0].separation, 0.05, 1e-9);
    NEAR_V(m.normal, v3(-1, 0, 0), 1e-9);
    /* sphere below the face z = 0 overlapping by 0.05 */
    assert_int_equal(run_both(&s, at(0.2, 0.2, -0.2), &h, at(0, 0, 0), 0.02, &m), 1);
    NEAR(m.points[0].separation, -0.05, 1e-9);
    NEAR_V(m.normal, v3(0, 0, 1), 1e-9);

    /* hull on hull: the tetrahedron's face z = 0 on a cube hull's top (z = 1): 3 points depth 0.01 */
    shape cube = box_hull(v3(1, 1, 1));
    assert_int_equal(run_both(&cube, at(0, 0, 0), &h, at(-0.3, -0.2, 0.99), 0.02, &m), 3);
    for (int i = 0; i < 3; i++) {
        NEAR(m.points[i].separation, -0.01, 1e-9);
        NEAR(m.points[i].point.z, 0.995, 1e-9);
    }
    NEAR_V(m.normal, v3(0, 0, 1), 1e-9);
    /* hull cube against a real box, aligned stack: 4 points, depth 0.02 */
    shape bx = box(0.5, 0.5, 0.5);
    assert_int_equal(run_both(&cube, at(0, 0, 0), &bx, at(0.2, 0.1, 1.48), 0.02, &m), 4);
    for (int i = 0; i < 4; i++) NEAR(m.points[i].separation, -0.02, 1e-9);
    NEAR_V(m.normal, v3(0, 0, 1), 1e-9);
    /* separated hulls */
    assert_int_equal(run_both(&cube, at(0, 0, 0), &h, at(0, 0, 1.5), 0.02, &m), 0);
    hull_free(cube.hull);
    hull_free(h.hull);
}

/* ---- 2./3. random boxes against an independent brute-force SAT ----------------- */

static quat rnd_quat(uint64_t *s)
{
    /* uniform on the sphere of unit quaternions: normalised Gaussian-free rejection */
    for (;;) {
        quat q = {2 * rnd(s) - 1, 2 * rnd(s) - 1, 2 * rnd(s) - 1, 2 * rnd(s) - 1};
        double l = q_len(q);
        if (l > 0.1 && l <= 1.0) return q_normalize(q);
    }
}

static void corners(vec3 he, xform x, vec3 out[8])
{
    for (int i = 0; i < 8; i++)
        out[i] = xf_point(x, v3((i & 1) ? he.x : -he.x, (i & 2) ? he.y : -he.y, (i & 4) ? he.z : -he.z));
}

typedef struct sat_result {
    double best;          /* largest separation over the 15 axes */
    vec3 axis;            /* its axis, oriented from a to b */
    int kind;             /* 0: face of a, 1: face of b, 2: edge pair */
    double second;        /* runner-up over all axes (other axes than the winner) */
    double face_a, face_b, edge; /* best per family */
} sat_result;

/* Brute force: for every axis, (min over b's corners) - (max over a's corners). */
static sat_result brute_sat(vec3 hea, xform xa, vec3 heb, xform xb)
{
    vec3 ca[8], cb[8];
    corners(hea, xa, ca);
    corners(heb, xb, cb);
    vec3 ua[3] = {q_rotate(xa.q, v3(1, 0, 0)), q_rotate(xa.q, v3(0, 1, 0)), q_rotate(xa.q, v3(0, 0, 1))};
    vec3 ub[3] = {q_rotate(xb.q, v3(1, 0, 0)), q_rotate(xb.q, v3(0, 1, 0)), q_rotate(xb.q, v3(0, 0, 1))};
    vec3 axes[15];
    int kind[15], n = 0;
    for (int i = 0; i < 3; i++) { axes[n] = ua[i]; kind[n++] = 0; }
    for (int i = 0; i < 3; i++) { axes[n] = ub[i]; kind[n++] = 1; }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) { axes[n] = v3_cross(ua[i], ub[j]); kind[n++] = 2; }
    sat_result r;
    r.best = r.second = r.face_a = r.face_b = r.edge = -1e300;
    r.axis = v3(0, 0, 1);
    r.kind = 0;
    for (int k = 0; k < 15; k++) {
        if (v3_len(axes[k]) < 1e-6) continue; /* parallel edges: no axis */
        vec3 ax = v3_normalize(axes[k]);
        double pa[2] = {1e300, -1e300}, pb[2] = {1e300, -1e300};
        for (int i = 0; i < 8; i++) {
            double da = v3_dot(ax, ca[i]), db = v3_dot(ax, cb[i]);
            pa[0] = fmin(pa[0], da); pa[1] = fmax(pa[1], da);
            pb[0] = fmin(pb[0], db); pb[1] = fmax(pb[1], db);
        }
        /* orient from a to b: the sign with the larger separation */
        double s = pb[0] - pa[1], s_neg = pa[0] - pb[1];
        if (s_neg > s) { s = s_neg; ax = v3_neg(ax); }
        if (kind[k] == 0) r.face_a = fmax(r.face_a, s);
        else if (kind[k] == 1) r.face_b = fmax(r.face_b, s);
        else r.edge = fmax(r.edge, s);
        if (s > r.best) { r.second = r.best; r.best = s; r.axis = ax; r.kind = kind[k]; }
        else if (s > r.second) r.second = s;
    }
    return r;
}

typedef struct box_case { shape a, b; xform xa, xb; } box_case;

static box_case random_boxes(uint64_t *s)
{
    box_case c;
    c.a = box(0.1 + 1.9 * rnd(s), 0.1 + 1.9 * rnd(s), 0.1 + 1.9 * rnd(s));
    c.b = box(0.1 + 1.9 * rnd(s), 0.1 + 1.9 * rnd(s), 0.1 + 1.9 * rnd(s));
    c.xa.p = v3(4 * rnd(s) - 2, 4 * rnd(s) - 2, 4 * rnd(s) - 2);
    c.xa.q = rnd_quat(s);
    c.xb.q = rnd_quat(s);
    /* place b along a random direction so that the support extents overlap
     * by a random fraction: from deep overlap to just separated */
    vec3 dir = v3_normalize(v3(rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5));
    double ra = 0, rb = 0;
    vec3 da = q_inv_rotate(c.xa.q, dir), db = q_inv_rotate(c.xb.q, dir);
    ra = fabs(da.x) * c.a.half_extents.x + fabs(da.y) * c.a.half_extents.y + fabs(da.z) * c.a.half_extents.z;
    rb = fabs(db.x) * c.b.half_extents.x + fabs(db.y) * c.b.half_extents.y + fabs(db.z) * c.b.half_extents.z;
    double f = rnd(s);
    double dist = (ra + rb) * (f < 0.85 ? 0.4 + 0.6 * f / 0.85 : 1.0 + 0.1 * (f - 0.85) / 0.15);
    c.xb.p = v3_madd(c.xa.p, dist, dir);
    return c;
}

#define CASE_FAIL(seed, k, ...)                                                               \
    do {                                                                                      \
        print_error("seed 0x%llx case %d: ", (unsigned long long)(seed), (k));                \
        print_error(__VA_ARGS__);                                                             \
        fail();                                                                               \
    } while (0)

static void print_case(const box_case *c)
{
    print_error("  a half (%.17g %.17g %.17g) at (%.17g %.17g %.17g) q (%.17g %.17g %.17g %.17g)\n",
                c->a.half_extents.x, c->a.half_extents.y, c->a.half_extents.z, c->xa.p.x, c->xa.p.y, c->xa.p.z,
                c->xa.q.w, c->xa.q.x, c->xa.q.y, c->xa.q.z);
    print_error("  b half (%.17g %.17g %.17g) at (%.17g %.17g %.17g) q (%.17g %.17g %.17g %.17g)\n",
                c->b.half_extents.x, c->b.half_extents.y, c->b.half_extents.z, c->xb.p.x, c->xb.p.y, c->xb.p.z,
                c->xb.q.w, c->xb.q.x, c->xb.q.y, c->xb.q.z);
}

/* The narrowphase prefers a face axis unless an edge axis separates by more
 * than 1 mm, and a's face unless b's separates by more than 0.5 mm (both
 * documented in narrowphase.c). Ties within this margin are skipped. */
#define TIE_MARGIN 2e-3

static void test_random_box_box_against_brute_force(void **state)
{
    (void)state;
    const uint64_t seed = 0x9E3779B97F4A7C15ULL;
    const double spec = 0.02;
    uint64_t s = seed;
    int overlapping = 0, face_depths = 0, normals = 0, edges = 0;
    for (int k = 0; k < 10000; k++) {
        box_case c = random_boxes(&s);
        sat_result r = brute_sat(c.a.half_extents, c.xa, c.b.half_extents, c.xb);
        manifold m;
        run(&c.a, c.xa, &c.b, c.xb, spec, &m);
        if (!(m.count >= 0 && m.count <= 4 && v3_is_finite(m.normal) && fabs(v3_len(m.normal) - 1) < 1e-9)) {
            print_case(&c);
            CASE_FAIL(seed, k, "bad manifold: count %d normal (%g %g %g)\n", m.count, m.normal.x, m.normal.y, m.normal.z);
        }
        for (int i = 0; i < m.count; i++)
            if (!(v3_is_finite(m.points[i].point) && isfinite(m.points[i].separation))) {
                print_case(&c);
                CASE_FAIL(seed, k, "non-finite point %d\n", i);
            }
        if (r.best >= spec) {
            if (m.count != 0) {
                print_case(&c);
                CASE_FAIL(seed, k, "separated by %.6f but %d points\n", r.best, m.count);
            }
            continue;
        }
        if (r.best >= 0) continue; /* speculative band: points optional */
        overlapping++;
        if (m.count == 0) {
            print_case(&c);
            CASE_FAIL(seed, k, "overlapping by %.6f but no points\n", -r.best);
        }
        double got = min_sep(&m);
        double other_face = r.kind == 0 ? r.face_b : r.face_a;
        if (r.kind != 2 && r.best - other_face > TIE_MARGIN) {
            /* a face axis wins: the manifold's deepest point has the SAT depth */
            face_depths++;
            if (!(fabs(got - r.best) <= 1e-9)) {
                print_case(&c);
                CASE_FAIL(seed, k, "face axis (%s): depth %.15f, brute force %.15f\n", r.kind ? "b" : "a", got, r.best);
            }
        }
        if (r.kind == 2 && r.best - fmax(r.face_a, r.face_b) > TIE_MARGIN) {
            /* an edge pair wins clearly: one point at the brute-force separation */
            edges++;
            if (m.count != 1 || !(fabs(m.points[0].separation - r.best) <= 1e-9)) {
                print_case(&c);
                CASE_FAIL(seed, k, "edge axis: %d points, separation %.15f, brute force %.15f\n", m.count,
                          m.count ? m.points[0].separation : 0.0, r.best);
            }
        }
        if (r.best - r.second > TIE_MARGIN) {
            normals++;
            if (!(v3_len(v3_sub(m.normal, r.axis)) <= 1e-6)) {
                print_case(&c);
                CASE_FAIL(seed, k, "normal (%.9f %.9f %.9f), brute force (%.9f %.9f %.9f) kind %d\n", m.normal.x,
                          m.normal.y, m.normal.z, r.axis.x, r.axis.y, r.axis.z, r.kind);
            }
        }
    }
    /* the generator must actually exercise every branch */
    assert_true(overlapping > 5000);
    assert_true(face_depths > 3000);
    assert_true(normals > 3000);
    assert_true(edges > 50);
}

/* Hulls built from a box's 8 corners collide like the boxes. */
static void test_hull_boxes_agree_with_box_path(void **state)
{
    (void)state;
    const uint64_t seed = 0xD1B54A32D192ED03ULL;
    uint64_t s = seed;
    int compared = 0, normals = 0;
    for (int k = 0; k < 10000; k++) {
        box_case c = random_boxes(&s);
        shape ha = box_hull(c.a.half_extents), hb = box_hull(c.b.half_extents);
        manifold mb, mh;
        run(&c.a, c.xa, &c.b, c.xb, 0.02, &mb);
        run(&ha, c.xa, &hb, c.xb, 0.02, &mh);
        check_sane(&mh);
        sat_result r = brute_sat(c.a.half_extents, c.xa, c.b.half_extents, c.xb);
        if (r.best < 0) {
            compared++;
            if (mb.count == 0 || mh.count == 0) {
                print_case(&c);
                CASE_FAIL(seed, k, "overlap %.6f: box %d points, hull %d points\n", -r.best, mb.count, mh.count);
            }
            if (!(fabs(min_sep(&mb) - min_sep(&mh)) <= 1e-9)) {
                print_case(&c);
                CASE_FAIL(seed, k, "box depth %.15f, hull depth %.15f (brute %.15f)\n", min_sep(&mb), min_sep(&mh), r.best);
            }
            double other_face = r.kind == 0 ? r.face_b : r.face_a;
            if (r.kind != 2 && r.best - r.second > TIE_MARGIN && r.best - other_face > TIE_MARGIN) {
                normals++;
                if (!(v3_len(v3_sub(mb.normal, mh.normal)) <= 1e-6)) {
                    print_case(&c);
                    CASE_FAIL(seed, k, "box normal (%.9f %.9f %.9f), hull normal (%.9f %.9f %.9f)\n", mb.normal.x,
                              mb.normal.y, mb.normal.z, mh.normal.x, mh.normal.y, mh.normal.z);
                }
            }
        }
        hull_free(ha.hull);
        hull_free(hb.hull);
    }
    if (!(compared > 5000 && normals > 2500)) {
        print_error("compared %d, normals %d\n", compared, normals);
        fail();
    }
}

/* ---- 4. feature ids ------------------------------------------------------------- */

static void test_feature_ids_survive_jitter(void **state)
{
    (void)state;
    shape b = box(0.5, 0.5, 0.5);
    manifold m0, m;
    assert_int_equal(run(&b, at(0, 0, 0.5), &b, at(0, 0, 1.5), 0.02, &m0), 4);
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) assert_true(m0.points[i].id != m0.points[j].id);
    uint64_t s = 0x5EED1D5ULL;
    for (int k = 0; k < 1000; k++) {
        /* translation and rotation angle each below 1e-5 */
        vec3 dp = v3_scale(v3_normalize(v3(rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5)), 1e-5 * rnd(&s));
        vec3 axis = v3(rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5);
        xform xb = {v3_add(v3(0, 0, 1.5), dp), q_axis_angle(axis, 1e-5 * rnd(&s))};
        run(&b, at(0, 0, 0.5), &b, xb, 0.02, &m);
        if (m.count != 4) {
            print_error("jitter case %d: %d points\n", k, m.count);
            fail();
        }
        for (int i = 0; i < 4; i++) {
            int found = 0;
            for (int j = 0; j < 4; j++) found += m.points[i].id == m0.points[j].id;
            for (int j = i + 1; j < 4; j++) assert_true(m.points[i].id != m.points[j].id);
            if (found != 1) {
                print_error("jitter case %d: id 0x%x not in the resting set\n", k, (unsigned)m.points[i].id);
                fail();
            }
        }
    }
}

/* Box-box face contacts pinned to the ids, order, separations and reference
 * choice the general polytope clipper (poly_from_box + poly_face_contact)
 * gave before the box path clipped boxes directly: the contact cache matches
 * points by these ids across steps, so a change here loses warm starts. */
typedef struct pinned_point { uint32_t id; double sep; vec3 p; } pinned_point;

static void check_pinned(const char *name, const shape *a, xform xa, const shape *b, xform xb, int feature, int flip,
                         vec3 normal, int want_feature, int want_flip, int n, const pinned_point *want)
{
    collide_cache c;
    memset(&c, 0, sizeof c);
    c.feature = feature;
    c.flip = flip;
    manifold m;
    int got = collide(a, xa, b, xb, 0.02, &c, &m);
    if (got != n || c.feature != want_feature || c.flip != want_flip) {
        print_error("%s: %d points feature %d flip %d, expected %d, %d, %d\n", name, got, c.feature, c.flip, n,
                    want_feature, want_flip);
        fail();
    }
    NEAR_V(m.normal, normal, 1e-12);
    for (int i = 0; i < n; i++) {
        if (m.points[i].id != want[i].id) {
            print_error("%s: point %d id 0x%08x, expected 0x%08x\n", name, i, (unsigned)m.points[i].id,
                        (unsigned)want[i].id);
            fail();
        }
        NEAR(m.points[i].separation, want[i].sep, 1e-12);
        NEAR_V(m.points[i].point, want[i].p, 1e-12);
    }
}

static void test_box_box_pinned_ids(void **state)
{
    (void)state;
    shape b = box(0.5, 0.5, 0.5), s = box(0.2, 0.3, 0.1), big = box(1, 1, 0.25);
    xform o = at(0, 0, 0);
    /* aligned stack (parallel faces: the clip tolerance keeps the corners) */
    static const pinned_point aligned[4] = {{0x00450000u, 0, {-0.5, -0.5, 1}}, {0x00450002u, 0, {-0.5, 0.5, 1}},
                                            {0x00450003u, 0, {0.5, 0.5, 1}}, {0x00450001u, 0, {0.5, -0.5, 1}}};
    check_pinned("aligned", &b, at(0, 0, 0.5), &b, at(0, 0, 1.5), -1, 0, v3(0, 0, 1), 4, 0, 4, aligned);
    /* turned 45 degrees: eight clipped points reduced to four */
    static const pinned_point rot45[4] = {
        {0x00450080u, -0.010000000000000009, {-0.20660678118654752, -0.50049999999999994, 0.995}},
        {0x00450283u, -0.010000000000000009, {0.20660678118654749, 0.50049999999999994, 0.995}},
        {0x00450382u, -0.010000000000000009, {-0.50049999999999994, 0.20660678118654749, 0.995}},
        {0x00450183u, -0.010000000000000009, {0.50049999999999994, 0.20660678118654752, 0.995}}};
    xform x45 = {v3(0, 0, 1.49), q_axis_angle(v3(0, 0, 1), 0.7853981633974483)};
    check_pinned("rot45", &b, at(0, 0, 0.5), &b, x45, -1, 0, v3(0, 0, 1), 4, 0, 4, rot45);
    /* a small tilted box over a big box's corner: b's face is the reference */
    static const pinned_point overhang[4] = {
        {0x20540084u, -0.0023972159463905851, {0.74926613107914186, -0.99999662799683908, 0.24880144983529159}},
        {0x20540005u, -0.0047564419956154236, {0.99997762163784076, -0.99999330943152287, 0.24762189370304563}},
        {0x20540185u, -0.0036301033537709526, {0.99998292089599727, -0.59962798656403271, 0.24818503586248802}},
        {0x20540187u, -0.0012650691187584551, {0.74851374390737224, -0.60010111544984879, 0.24936749594756433}}};
    xform xo = {v3(0.95, -0.9, 0.25 + 0.1 - 0.004), q_axis_angle(v3(0.3, 1, 0.2), 0.01)};
    check_pinned("overhang", &big, o, &s, xo, -1, 0,
                 v3(0.0094097067429413251, -0.0028132660855664949, 0.99995177031342053), 5, 1, 4, overhang);
    /* a box tipped 0.1 rad on its edge: b's face, two points */
    static const pinned_point tipped[2] = {{0x20450003u, -0.0029999999999999749, {0.48901749139092232, 0.5, 0.2485}},
                                           {0x20450001u, -0.0029999999999999749, {0.48901749139092232, -0.1, 0.2485}}};
    xform xt = {v3(0.3, 0.2, 0.25 + 0.1 * cos(0.1) + 0.2 * sin(0.1) - 0.003), q_axis_angle(v3(0, 1, 0), 0.1)};
    check_pinned("tipped", &s, xt, &big, o, -1, 0, v3(0, 0, -1), 4, 1, 2, tipped);
    /* nearly parallel faces: last step's reference (b's) is kept, else a's is taken */
    static const pinned_point keep_b[4] = {
        {0x20450000u, -0.0020599979996000495, {-0.1, -0.24997999400013332, 0.24897000100019998}},
        {0x20450002u, -0.0019399980004000117, {-0.1, 0.35001999399986666, 0.24903000099979999}},
        {0x20450003u, -0.0019399980004000117, {0.3, 0.35001999399986666, 0.24903000099979999}},
        {0x20450001u, -0.0020599979996000495, {0.3, -0.24997999400013332, 0.24897000100019998}}};
    static const pinned_point take_a[4] = {
        {0x00540384u, -0.0020599980408000096, {0.3, -0.24998019999993598, 0.24897000100019998}},
        {0x00540285u, -0.0019399980392000027, {0.3, 0.350019800000064, 0.24903000099979997}},
        {0x00540187u, -0.0019399980392000027, {-0.1, 0.350019800000064, 0.24903000099979997}},
        {0x00540387u, -0.0020599980408000096, {-0.1, -0.24998019999993598, 0.24897000100019998}}};
    xform xk = {v3(0.1, 0.05, 0.25 + 0.1 - 0.002), q_axis_angle(v3(1, 0, 0), 2e-4)};
    check_pinned("keep_b", &s, xk, &big, o, 4, 1, v3(0, 0, -1), 4, 1, 4, keep_b);
    check_pinned("take_a", &s, xk, &big, o, -1, 0, v3(0, 0.00019999999866666669, -0.99999998000000012), 5, 0, 4,
                 take_a);
}

/* A bumpy two-sided mesh and a height field with a hole, both about 1 m. */
static void add_level_shapes(shape *shapes)
{
    double v[15] = {-0.6, -0.6, 0, 0.6, -0.6, 0.1, 0.6, 0.6, -0.1, -0.6, 0.6, 0.2, 0, 0, 0.3};
    int t[12] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
    char err[128];
    shapes[SHAPE_MESH].mesh = mesh_build(v, 5, t, 4, 1, err, (int)sizeof err);
    assert_non_null(shapes[SHAPE_MESH].mesh);
    double h[16] = {0, 0.1, 0, 0.2, 0.1, 0.3, -0.1, 0, 0, 0.2, 0.1, 0, 0.3, 0, 0.1, 0};
    int hole = 4;
    shapes[SHAPE_HEIGHTFIELD].field = heightfield_build(h, 4, 4, 0.4, 0.4, &hole, 1, err, (int)sizeof err);
    assert_non_null(shapes[SHAPE_HEIGHTFIELD].field);
}

/* ---- 5. every pair of shape types stays finite ----------------------------------- */

static void test_every_pair_is_finite(void **state)
{
    (void)state;
    double pts[21] = {0.3, 0, 0, -0.3, 0, 0, 0, 0.3, 0, 0, -0.3, 0, 0, 0, 0.4, 0, 0, -0.4, 0.1, 0.1, 0.1};
    shape shapes[SHAPE_TYPE_COUNT] = {sphere(0.4), box(0.3, 0.4, 0.5), capsule(0.2, 0.4), cylinder(0.35, 0.3),
                                      make(SHAPE_HULL), ground(), make(SHAPE_MESH), make(SHAPE_HEIGHTFIELD)};
    shapes[4] = hull_shape(pts, 7);
    add_level_shapes(shapes);
    const uint64_t seed = 0xF1A17E5EEDULL;
    uint64_t s = seed;
    for (int a = 0; a < SHAPE_TYPE_COUNT; a++)
        for (int b = 0; b < SHAPE_TYPE_COUNT; b++)
            for (int k = 0; k < 2000; k++) {
                double span = k % 4 == 0 ? 0.05 : 1.2;
                xform xa = {v3(span * (rnd(&s) - 0.5), span * (rnd(&s) - 0.5), span * (rnd(&s) - 0.5)), rnd_quat(&s)};
                xform xb = {v3(span * (rnd(&s) - 0.5), span * (rnd(&s) - 0.5), span * (rnd(&s) - 0.5)), rnd_quat(&s)};
                if (k % 10 == 1) xb = xa;                     /* coincident and aligned */
                if (k % 10 == 2) { xb.p = xa.p; }             /* concentric, rotated */
                if (k % 10 == 3) { xb.q = xa.q; }             /* aligned axes */
                manifold m;
                int n = run(&shapes[a], xa, &shapes[b], xb, k % 2 ? 0.02 : 0.0, &m);
                int ok = n == m.count && n >= 0 && n <= 4 && v3_is_finite(m.normal) && fabs(v3_len(m.normal) - 1) < 1e-9;
                for (int i = 0; i < m.count && ok; i++) ok = v3_is_finite(m.points[i].point) && isfinite(m.points[i].separation);
                if (!ok) {
                    print_error("seed 0x%llx types %d-%d case %d: count %d normal (%g %g %g)\n", (unsigned long long)seed,
                                a, b, k, n, m.normal.x, m.normal.y, m.normal.z);
                    fail();
                }
            }
    for (int i = 0; i < SHAPE_TYPE_COUNT; i++) shape_free_data(&shapes[i]);
}

/* A pose that overflowed (inf/NaN position or rotation) gives no contact for
 * every pair type, and no feature search indexes with "no best face". */
static void test_non_finite_poses_give_no_contact(void **state)
{
    (void)state;
    double pts[21] = {0.3, 0, 0, -0.3, 0, 0, 0, 0.3, 0, 0, -0.3, 0, 0, 0, 0.4, 0, 0, -0.4, 0.1, 0.1, 0.1};
    shape shapes[SHAPE_TYPE_COUNT] = {sphere(0.4), box(0.3, 0.4, 0.5), capsule(0.2, 0.4), cylinder(0.35, 0.3),
                                      make(SHAPE_HULL), ground(), make(SHAPE_MESH), make(SHAPE_HEIGHTFIELD)};
    shapes[4] = hull_shape(pts, 7);
    add_level_shapes(shapes);
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    for (int a = 0; a < SHAPE_TYPE_COUNT; a++)
        for (int b = 0; b < SHAPE_TYPE_COUNT; b++)
            for (int k = 0; k < 12; k++) {
                xform xa = at(0, 0, 0), xb = at(0.1, 0, 0.2);
                xform *x = k % 2 ? &xb : &xa;
                if (k / 2 % 2) x->p.y = bad[k / 4];
                else x->q.x = bad[k / 4];
                manifold m;
                collide_cache cache;
                memset(&cache, 0, sizeof cache);
                cache.feature = -1;
                assert_int_equal(collide(&shapes[a], xa, &shapes[b], xb, 0.02, &cache, &m), 0);
                assert_int_equal(m.count, 0);
                assert_true(v3_is_finite(m.normal));
            }
    for (int i = 0; i < SHAPE_TYPE_COUNT; i++) shape_free_data(&shapes[i]);
}

/* ---- every overlap has a contact point (was test_overlap_contacts.c) ---- */

/* the narrowphase reports every overlap: each pair
 * of convex shapes (random sizes and orientations) is brought together
 * along a random line until GJK (an independent algorithm, lib/gjk.c) finds
 * them touching, then pushed 1 mm .. 128 mm further; at each depth the
 * manifold must hold a point with separation <= 0. Cylinders included: their
 * pairs work on the true round shape (they were 16-sided prisms, which let
 * them start overlapping up to r (1 - cos(pi / 16)) later: 8 mm here). */

static uint64_t rng = 88172645463325252ull;
static double urand(void) { return rnd(&rng); } /* helpers.h's xorshift64, the same sequence */
static double srand1(void) { return 2 * urand() - 1; }

enum { N_TYPES = 5 };
static const char *const type_names[N_TYPES] = {"sphere", "box", "capsule", "cylinder", "hull"};
static double hull_points[8 * 3];

static carom_shape_def make_def(int type, double s)
{
    switch (type) {
    case 0: return carom_shape_sphere(0.5 * s);
    case 1: return carom_shape_box(0.5 * s, 0.3 * s, 0.4 * s);
    case 2: return carom_shape_capsule(0.3 * s, 0.4 * s);
    case 3: return carom_shape_cylinder(0.4 * s, 0.4 * s);
    default:
        for (int i = 0; i < 8; i++) {
            hull_points[3 * i] = ((i & 1) ? 0.5 : -0.4) * s + 0.05 * srand1();
            hull_points[3 * i + 1] = ((i & 2) ? 0.45 : -0.3) * s;
            hull_points[3 * i + 2] = ((i & 4) ? 0.3 : -0.5) * s;
        }
        return carom_shape_hull(hull_points, 8);
    }
}

static carom_quat random_quat(void)
{
    double a = srand1(), b = srand1(), c = srand1(), d = srand1(), l = sqrt(a * a + b * b + c * c + d * d);
    carom_quat q = {a / l, b / l, c / l, d / l};
    return q;
}

static double deepest_point(const shape *a, xform xa, const shape *b, xform xb)
{
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(a, xa, b, xb, 0.0, &cache, &m);
    double s = INFINITY;
    for (int i = 0; i < m.count; i++) s = fmin(s, m.points[i].separation);
    return s;
}

static const shape *shape_of(carom_world *w, carom_body_id id, xform *x)
{
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    *x = body_xform(&w->bodies, slot);
    return &w->bodies.shapes[slot];
}

static void test_every_overlap_has_a_point(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    int checked = 0, missed = 0;
    for (int ta = 0; ta < N_TYPES; ta++)
        for (int tb = 0; tb < N_TYPES; tb++)
            for (int rep = 0; rep < 40; rep++) {
                carom_body_def d = carom_body_def_default();
                d.type = CAROM_BODY_STATIC;
                d.shape = make_def(ta, 0.8 + 0.4 * urand());
                d.orientation = random_quat();
                carom_body_id A = carom_body_create(w, &d);
                d.shape = make_def(tb, 0.8 + 0.4 * urand());
                d.orientation = random_quat();
                d.position.x = 50;
                carom_body_id B = carom_body_create(w, &d);
                xform xa, xb;
                const shape *sa = shape_of(w, A, &xa), *sb = shape_of(w, B, &xb);
                xb.p = v3(0, 0, 0);
                vec3 dir = v3_normalize(v3(srand1(), srand1(), srand1()));
                double lo = 0, hi = 3; /* A's offset along dir from B: overlapping at lo, apart at hi */
                for (int it = 0; it < 60; it++) {
                    double mid = 0.5 * (lo + hi);
                    xform x = xa;
                    x.p = v3_scale(dir, mid);
                    gjk_proxy pa = {sa, NULL, 0, x}, pb = {sb, NULL, 0, xb};
                    if (gjk_distance(&pa, &pb).overlap) lo = mid;
                    else hi = mid;
                }
                for (double depth = 1e-3; depth <= 0.13; depth *= 2) {
                    xform x = xa;
                    x.p = v3_scale(dir, hi - depth);
                    checked++;
                    if (deepest_point(sa, x, sb, xb) <= 0) continue;
                    missed++;
                    print_error("%s against %s rep %d: %.3f m into each other, the narrowphase has no point\n",
                                type_names[ta], type_names[tb], rep, depth);
                }
                carom_body_destroy(w, A);
                carom_body_destroy(w, B);
            }
    print_message("overlaps: %d poses 1 mm .. 128 mm deep, %d without a contact point\n", checked, missed);
    assert_int_equal(missed, 0);
    carom_world_destroy(w);
}

/* ---- cylinder pairs against a brute force on the exact surfaces ---------------- */

/* Exact signed distance of world point p to s at x (sphere, box, capsule,
 * cylinder, or a hull made of a centred box's corners). */
static double exact_sdf(const shape *s, xform x, vec3 p)
{
    vec3 l = xf_inv_point(x, p);
    switch (s->type) {
    case SHAPE_SPHERE: return v3_len(l) - s->radius;
    case SHAPE_CAPSULE: {
        double z = fmax(-s->half_height, fmin(s->half_height, l.z));
        return v3_len(v3(l.x, l.y, l.z - z)) - s->radius;
    }
    case SHAPE_CYLINDER: {
        double dr = hypot(l.x, l.y) - s->radius, dz = fabs(l.z) - s->half_height;
        double o = hypot(fmax(dr, 0), fmax(dz, 0));
        return o > 0 ? o : fmax(dr, dz);
    }
    default: {
        vec3 h = s->half_extents;
        if (s->type == SHAPE_HULL) {
            h = v3_zero();
            for (int i = 0; i < s->hull->vertex_count; i++) h = v3_max(h, v3_abs(s->hull->vertices[i]));
        }
        vec3 q = v3_sub(v3_abs(l), h);
        return v3_len(v3_max(q, v3_zero())) + fmin(fmax(q.x, fmax(q.y, q.z)), 0);
    }
    }
}

static int surface_pieces(const shape *s) { return s->type == SHAPE_SPHERE ? 1 : s->type == SHAPE_BOX || s->type == SHAPE_HULL ? 6 : 3; }

/* Piece k of s's exact surface at (u, v) in [0, 1]^2, in s's frame. */
static vec3 surface_point(const shape *s, int k, double u, double v)
{
    double th = 2 * PI_ * u;
    switch (s->type) {
    case SHAPE_SPHERE: {
        double ph = PI_ * v;
        return v3_scale(v3(sin(ph) * cos(th), sin(ph) * sin(th), cos(ph)), s->radius);
    }
    case SHAPE_CAPSULE: {
        double r = s->radius, hh = s->half_height;
        if (k == 0) return v3(r * cos(th), r * sin(th), (2 * v - 1) * hh);
        double ph = 0.5 * PI_ * v, sg = k == 1 ? 1 : -1;
        return v3(r * sin(ph) * cos(th), r * sin(ph) * sin(th), sg * (hh + r * cos(ph)));
    }
    case SHAPE_CYLINDER: {
        double r = s->radius, hh = s->half_height;
        if (k == 0) return v3(r * cos(th), r * sin(th), (2 * v - 1) * hh);
        return v3(r * v * cos(th), r * v * sin(th), k == 1 ? hh : -hh);
    }
    default: {
        vec3 h = s->half_extents;
        if (s->type == SHAPE_HULL) {
            h = v3_zero();
            for (int i = 0; i < s->hull->vertex_count; i++) h = v3_max(h, v3_abs(s->hull->vertices[i]));
        }
        int ax = k / 2;
        double c[3], e[3] = {h.x, h.y, h.z};
        c[ax] = (k & 1) ? -e[ax] : e[ax];
        c[(ax + 1) % 3] = (2 * u - 1) * e[(ax + 1) % 3];
        c[(ax + 2) % 3] = (2 * v - 1) * e[(ax + 2) % 3];
        return v3(c[0], c[1], c[2]);
    }
    }
}

/* min over a's exact surface of b's exact signed distance: a 32 x 32 grid on
 * each piece, then a pattern search from the best three cells. */
static double surface_min_sdf(const shape *a, xform xa, const shape *b, xform xb)
{
    enum { N = 32 };
    double best = INFINITY;
    for (int k = 0; k < surface_pieces(a); k++) {
        double su[3] = {0, 0, 0}, sv[3] = {0, 0, 0}, sd[3] = {INFINITY, INFINITY, INFINITY};
        for (int i = 0; i <= N; i++)
            for (int j = 0; j <= N; j++) {
                double u = (double)i / N, v = (double)j / N;
                double d = exact_sdf(b, xb, xf_point(xa, surface_point(a, k, u, v)));
                for (int t = 0; t < 3; t++)
                    if (d < sd[t]) {
                        for (int q = 2; q > t; q--) { sd[q] = sd[q - 1]; su[q] = su[q - 1]; sv[q] = sv[q - 1]; }
                        sd[t] = d; su[t] = u; sv[t] = v;
                        break;
                    }
            }
        for (int t = 0; t < 3; t++) {
            double u = su[t], v = sv[t], d = sd[t], step = 1.0 / N;
            for (int it = 0; it < 200 && step > 1e-13; it++) {
                int moved = 0;
                for (int du = -1; du <= 1; du++)
                    for (int dv = -1; dv <= 1; dv++) {
                        if (!du && !dv) continue;
                        double nu = fmin(1, fmax(0, u + du * step)), nv = fmin(1, fmax(0, v + dv * step));
                        double nd = exact_sdf(b, xb, xf_point(xa, surface_point(a, k, nu, nv)));
                        if (nd < d) { d = nd; u = nu; v = nv; moved = 1; }
                    }
                if (!moved) step *= 0.5;
            }
            best = fmin(best, d);
        }
    }
    return best;
}

/* The signed gap between a and b by the brute force: the distance when apart,
 * negative when they overlap. */
static double brute_gap(const shape *a, xform xa, const shape *b, xform xb)
{
    return fmin(surface_min_sdf(a, xa, b, xb), surface_min_sdf(b, xb, a, xa));
}

typedef struct cyl_stats { int poses, apart, touching, deep; double worst_early, worst_moved; } cyl_stats;

static void check_cylinder_pose(const shape *a, xform xa, const shape *b, xform xb, double d, double spec,
                                const char *what, cyl_stats *st)
{
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(a, xa, b, xb, spec, &cache, &m);
    st->poses++;
    if (d > spec + 1e-6) {
        if (m.count != 0) print_error("%s: %d points at distance %.6f beyond the look-ahead\n", what, m.count, d);
        assert_int_equal(m.count, 0);
        return;
    }
    if (d > 1e-6) st->apart++;
    else if (d > -1e-3) st->touching++;
    else st->deep++;
    if (d < spec - 1e-6 && m.count == 0) print_error("%s: no point at distance %.6f\n", what, d);
    if (d >= spec - 1e-6) return;
    assert_true(m.count > 0);
    assert_true(fabs(v3_len(m.normal) - 1) < 1e-9);
    double smin = INFINITY;
    for (int i = 0; i < m.count; i++) smin = fmin(smin, m.points[i].separation);
    /* never more room than there is, nor less by more than a face's preference (1 mm) */
    if (smin > fmax(d, 0) + 1e-6 || (d > 0 && smin < d - 1e-3 - 1e-6))
        print_error("%s: separation %.7f, brute-force gap %.7f\n", what, smin, d);
    assert_true(smin <= fmax(d, 0) + 1e-6);
    if (d > 0) assert_true(smin >= d - 1e-3 - 1e-6);
    if (d > 0) st->worst_early = fmax(st->worst_early, d - smin);
    /* a moved along the normal by the separation: touching (not apart by more
     * than the face preference, not overlapping) */
    xform moved = {v3_madd(xa.p, smin, m.normal), xa.q};
    double dm = brute_gap(a, moved, b, xb);
    if (dm < -1e-6 || dm > 1e-3 + 1e-6) print_error("%s: moved by the separation %.7f along the normal, gap %.7f\n", what, smin, dm);
    assert_true(dm >= -1e-6 && dm <= 1e-3 + 1e-6);
    st->worst_moved = fmax(st->worst_moved, fabs(dm));
    /* every point half its separation from a surface: on the true shapes (a
     * capsule's points are its core's offset by the radius against the
     * normal, as for every capsule against a face: inside it, up to r, where
     * its axis is tilted to the face; its ends, the deepest, are on it) */
    for (int i = 0; i < m.count; i++) {
        vec3 p = m.points[i].point;
        double sp = m.points[i].separation;
        double da = exact_sdf(a, xa, v3_madd(p, -0.5 * sp, m.normal)), db = exact_sdf(b, xb, v3_madd(p, 0.5 * sp, m.normal));
        if (a->type == SHAPE_CAPSULE && da < 0 && da >= -a->radius) da = 0;
        if (b->type == SHAPE_CAPSULE && db < 0 && db >= -b->radius) db = 0;
        double on = fmin(fabs(da), fabs(db));
        if (on > 1e-6) print_error("%s: point %d is %.2e from both surfaces (id %x sep %.4f, count %d)\n", what, i, on, m.points[i].id, sp, m.count);
        assert_true(on <= 1e-6);
    }
}

/* A cylinder against a sphere, box, capsule, cylinder and box-shaped hull in
 * random sizes and orientations, brought to touching along a random line
 * (GJK places them; every check is on the brute force), then set apart or
 * pushed in, both argument orders. */
static void test_cylinder_pairs_against_brute_force(void **state)
{
    (void)state;
    uint64_t r = 0x9e3779b97f4a7c15ull;
    const double offsets[] = {0.06, 0.02, 2e-3, 1e-4, -1e-4, -3e-3, -0.03, -0.25};
    const double spec = 0.04;
    cyl_stats st = {0, 0, 0, 0, 0, 0};
    for (int t = 0; t < 5; t++)
        for (int rep = 0; rep < 12; rep++) {
            double s1 = 0.2 + 0.8 * rnd(&r), s2 = 0.2 + 0.8 * rnd(&r), s3 = 0.2 + 0.8 * rnd(&r);
            shape cy = cylinder(0.5 * s1, 0.5 * s2), o;
            switch (t) {
            case 0: o = sphere(0.5 * s3); break;
            case 1: o = box(0.5 * s3, 0.3 * s1, 0.4 * s2); break;
            case 2: o = capsule(0.3 * s3, 0.4 * s1); break;
            case 3: o = cylinder(0.4 * s3, 0.3 * s2 + 0.1); break;
            default: o = box_hull(v3(0.4 * s3, 0.5 * s1, 0.3 * s2)); break;
            }
            vec3 ax = v3_normalize(v3(2 * rnd(&r) - 1, 2 * rnd(&r) - 1, 2 * rnd(&r) - 1));
            vec3 bx = v3_normalize(v3(2 * rnd(&r) - 1, 2 * rnd(&r) - 1, 2 * rnd(&r) - 1));
            /* poses by rep % 4: standing, lying (the flat and line contacts),
             * random, tilted 0.1 .. 0.7 rad (on its rim) over the other */
            int kind = rep % 4, aligned = kind != 2;
            double qa = kind == 0 ? 0 : kind == 1 ? 0.5 * PI_ : kind == 2 ? 2 * PI_ * rnd(&r) : 0.1 + 0.6 * rnd(&r);
            vec3 tilt_axis = v3_normalize(v3(cos(2 * PI_ * rnd(&r)), sin(2 * PI_ * rnd(&r)), 0));
            xform xc = {v3(0, 0, 0), q_axis_angle(kind < 2 ? v3(1, 0, 0) : kind == 3 ? tilt_axis : ax, qa)};
            xform xo = {v3(0, 0, 0), aligned ? q_identity() : q_axis_angle(bx, 2 * PI_ * rnd(&r))};
            vec3 dir = aligned ? v3(0.3 * (2 * rnd(&r) - 1), 0.3 * (2 * rnd(&r) - 1), 1) : v3(2 * rnd(&r) - 1, 2 * rnd(&r) - 1, 2 * rnd(&r) - 1);
            dir = v3_normalize(dir);
            double lo = 0, hi = 4;
            for (int it = 0; it < 60; it++) {
                double mid = 0.5 * (lo + hi);
                xform x = xo;
                x.p = v3_scale(dir, mid);
                gjk_proxy pa = {&cy, NULL, 0, xc}, pb = {&o, NULL, 0, x};
                if (gjk_distance(&pa, &pb).overlap) lo = mid;
                else hi = mid;
            }
            /* far from the origin too */
            vec3 far = rep % 3 == 2 ? v3(1e4, -2e4, 3e3) : v3_zero();
            for (size_t k = 0; k < sizeof offsets / sizeof offsets[0]; k++) {
                xform x = xo, c = xc;
                /* offsets along dir are not gaps: the brute force says what they are */
                x.p = v3_add(far, v3_scale(dir, hi + offsets[k]));
                c.p = far;
                double d = brute_gap(&cy, c, &o, x);
                char what[96];
                snprintf(what, sizeof what, "cylinder against %s rep %d offset %g", type_names[o.type], rep, offsets[k]);
                check_cylinder_pose(&cy, c, &o, x, d, spec, what, &st);
                snprintf(what, sizeof what, "%s against cylinder rep %d offset %g", type_names[o.type], rep, offsets[k]);
                check_cylinder_pose(&o, x, &cy, c, d, spec, what, &st);
            }
            if (o.type == SHAPE_HULL) hull_free(o.hull);
        }
    print_message("cylinder pairs: %d poses (%d apart within the look-ahead, %d touching, %d deep); separation at most "
                  "%.2e m below the brute-force gap; moved by it along the normal, %.2e m from touching\n",
                  st.poses, st.apart, st.touching, st.deep, st.worst_early, st.worst_moved);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_sphere),
        cmocka_unit_test(test_sphere_plane),
        cmocka_unit_test(test_sphere_box),
        cmocka_unit_test(test_sphere_capsule),
        cmocka_unit_test(test_capsule_pairs),
        cmocka_unit_test(test_box_plane),
        cmocka_unit_test(test_box_box),
        cmocka_unit_test(test_cylinder_pairs),
        cmocka_unit_test(test_cylinder_pairs_against_brute_force),
        cmocka_unit_test(test_hull_pairs),
        cmocka_unit_test(test_random_box_box_against_brute_force),
        cmocka_unit_test(test_hull_boxes_agree_with_box_path),
        cmocka_unit_test(test_feature_ids_survive_jitter),
        cmocka_unit_test(test_box_box_pinned_ids),
        cmocka_unit_test(test_every_pair_is_finite),
        cmocka_unit_test(test_non_finite_poses_give_no_contact),
        cmocka_unit_test(test_every_overlap_has_a_point),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
