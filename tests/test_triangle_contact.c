/* test_triangle_contact.c - every convex shape (sphere, capsule, box,
 * cylinder, hull) against one triangle, checked against an independent
 * brute-force computation: apart, touching and deep, over the face, beyond
 * an edge and beyond a vertex, and the same poses with the edges internal.
 *
 * The brute force knows only each shape's definition (its support function
 * and the exact distance from a point to it, written here from the shape's
 * parameters; a hull by its face polygons) and the triangle's vertices:
 *  - the distance between shape and triangle: the smallest point-to-shape
 *    distance over the triangle, a convex function of the barycentric
 *    coordinates (a dense grid, then a shrinking pattern search);
 *  - gap(u) = min over the shape of u . y - max over the triangle of u . x:
 *    the exact room between them along a direction u (a one-sided triangle
 *    collides as the prism below it, so only u . n >= 0 counts); no
 *    direction has more room than the signed distance.
 * Checks for every pose: a contact exists when the distance (or, overlapping
 * over the face, the depth of the shape's lowest point) is within the
 * look-ahead; the normal is unit and on the front side; no contact claims
 * more room than gap() along its own normal; spheres and capsules get
 * exactly the signed distance. Cylinders too are held to 1e-7 m: they collide
 * as the true round shape (as 16-sided prisms they read up to the sagitta
 * r (1 - cos(pi/16)) = 5.8 mm too far here, and only 63 of 244 contacts had
 * the distance; now more than half must). With every edge internal a
 * contact has the face normal, and no point is deeper than the shape's
 * lowest point along it. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "helpers.h"
#include "narrowphase.h"
#include "manifold.h"
#include "shape.h"
#include "triangle_contact.h"

#define SPEC 0.05

static const vec3 tri[3] = {{-1.0, -0.8, 0.05}, {1.2, -0.6, 0.1}, {0.1, 1.1, -0.05}};

static double lcg(unsigned *s) { *s = *s * 1664525u + 1013904223u; return (*s >> 8) / 16777216.0; }

static quat random_quat(unsigned *seed)
{
    quat q = {lcg(seed) - 0.5, lcg(seed) - 0.5, lcg(seed) - 0.5, lcg(seed) - 0.5};
    return q_normalize(q);
}

static const double hull_points[8][3] = {{0.3, 0, 0}, {-0.25, 0.12, 0}, {0, 0.3, 0.06}, {0, -0.26, 0.02},
                                         {0.06, 0.06, 0.24}, {-0.06, 0, -0.24}, {0.14, -0.12, 0.12},
                                         {-0.12, -0.14, -0.12}};

static shape make_shape(int type)
{
    shape s;
    memset(&s, 0, sizeof s);
    s.type = type;
    s.radius = 0.3;
    s.half_height = 0.4;
    s.half_extents = v3(0.3, 0.2, 0.45);
    if (type == SHAPE_HULL) {
        char err[128];
        s.hull = hull_build(&hull_points[0][0], 8, err, sizeof err);
        assert_non_null(s.hull);
    }
    return s;
}

/* max over the shape at x of u . y, from the shape's own parameters */
static double support(const shape *s, xform x, vec3 u)
{
    vec3 l = q_inv_rotate(x.q, u); /* u in the shape's frame */
    double c = v3_dot(u, x.p);
    switch (s->type) {
    case SHAPE_SPHERE: return c + s->radius;
    case SHAPE_CAPSULE: return c + s->half_height * fabs(l.z) + s->radius;
    case SHAPE_BOX: return c + s->half_extents.x * fabs(l.x) + s->half_extents.y * fabs(l.y) + s->half_extents.z * fabs(l.z);
    case SHAPE_CYLINDER: return c + s->half_height * fabs(l.z) + s->radius * sqrt(fmax(0, l.x * l.x + l.y * l.y));
    case SHAPE_HULL: {
        double best = -1e300;
        for (int i = 0; i < 8; i++)
            best = fmax(best, l.x * hull_points[i][0] + l.y * hull_points[i][1] + l.z * hull_points[i][2]);
        return c + best;
    }
    default: return 0;
    }
}

static double gap(const shape *s, xform x, vec3 u)
{
    double top = fmax(v3_dot(u, tri[0]), fmax(v3_dot(u, tri[1]), v3_dot(u, tri[2])));
    return -support(s, x, v3_neg(u)) - top;
}

static vec3 face_normal(void)
{
    return v3_normalize(v3_cross(v3_sub(tri[1], tri[0]), v3_sub(tri[2], tri[0])));
}

/* Distance from p to the segment a..b. */
static double segment_distance(vec3 p, vec3 a, vec3 b)
{
    vec3 ab = v3_sub(b, a);
    double t = fmax(0, fmin(1, v3_dot(v3_sub(p, a), ab) / v3_len2(ab)));
    return v3_len(v3_sub(p, v3_madd(a, t, ab)));
}

/* Distance from p to the solid shape at x (0 inside). */
static double point_distance(const shape *s, xform x, vec3 p)
{
    vec3 l = xf_inv_point(x, p);
    switch (s->type) {
    case SHAPE_SPHERE: return fmax(0, v3_len(l) - s->radius);
    case SHAPE_CAPSULE: return fmax(0, segment_distance(l, v3(0, 0, -s->half_height), v3(0, 0, s->half_height)) - s->radius);
    case SHAPE_BOX: {
        vec3 h = s->half_extents;
        return v3_len(v3(fmax(fabs(l.x) - h.x, 0), fmax(fabs(l.y) - h.y, 0), fmax(fabs(l.z) - h.z, 0)));
    }
    case SHAPE_CYLINDER: {
        double rr = fmax(sqrt(l.x * l.x + l.y * l.y) - s->radius, 0), zz = fmax(fabs(l.z) - s->half_height, 0);
        return sqrt(rr * rr + zz * zz);
    }
    case SHAPE_HULL: {
        /* outside: the nearest point lies on a face whose plane p is beyond */
        const hull *h = s->hull;
        double best = 1e300;
        int inside = 1;
        for (int f = 0; f < h->face_count; f++) {
            const hull_face *hf = &h->faces[f];
            double above = v3_dot(hf->normal, l) - hf->offset;
            if (above <= 0) continue;
            inside = 0;
            int over = 1;
            double edge = 1e300;
            for (int k = 0; k < hf->count; k++) {
                vec3 a = h->vertices[h->face_vertices[hf->first + k]];
                vec3 b = h->vertices[h->face_vertices[hf->first + (k + 1) % hf->count]];
                if (v3_dot(v3_cross(v3_sub(b, a), hf->normal), v3_sub(l, a)) > 0) over = 0;
                edge = fmin(edge, segment_distance(l, a, b));
            }
            best = fmin(best, over ? above : edge);
        }
        return inside ? 0 : best;
    }
    default: return 0;
    }
}

static vec3 bary(double u, double w)
{
    return v3_add(tri[0], v3_add(v3_scale(v3_sub(tri[1], tri[0]), u), v3_scale(v3_sub(tri[2], tri[0]), w)));
}

/* Smallest distance over the triangle from the shape (0 when they touch or
 * overlap), and the triangle's nearest point. */
static double triangle_distance(const shape *s, xform x, vec3 *closest)
{
    double best = 1e300, bu = 0, bv = 0;
    const int n = 16;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            double d = point_distance(s, x, bary((double)i / n, (double)j / n));
            if (d < best) { best = d; bu = (double)i / n; bv = (double)j / n; }
        }
    static const double du[8] = {1, -1, 0, 0, 1, -1, 1, -1}, dv[8] = {0, 0, 1, -1, -1, 1, 1, -1};
    for (double step = 1.0 / n; step > 1e-12; step *= 0.5) {
        int moved = 1;
        while (moved) {
            moved = 0;
            for (int k = 0; k < 8; k++) {
                double u = bu + step * du[k], w = bv + step * dv[k];
                if (u < 0 || w < 0 || u + w > 1) continue;
                double d = point_distance(s, x, bary(u, w));
                if (d < best - 1e-15) { best = d; bu = u; bv = w; moved = 1; }
            }
        }
    }
    *closest = bary(bu, bv);
    return best;
}

/* The signed distance of a sphere or capsule whose core is in front of the
 * triangle's plane: the core's distance from the triangle minus the radius. */
static double core_signed_distance(const shape *s, xform x, vec3 *closest)
{
    shape core = *s;
    core.radius = 0;
    return triangle_distance(&core, x, closest) - s->radius;
}

/* The shape's lowest point along -n (a support point from its parameters). */
static vec3 lowest_point(const shape *s, xform x, vec3 n)
{
    vec3 l = q_inv_rotate(x.q, v3_neg(n)), p;
    switch (s->type) {
    case SHAPE_SPHERE: p = v3_scale(l, s->radius); break;
    case SHAPE_CAPSULE: p = v3_madd(v3(0, 0, l.z >= 0 ? s->half_height : -s->half_height), s->radius, l); break;
    case SHAPE_BOX: {
        vec3 h = s->half_extents;
        p = v3(l.x >= 0 ? h.x : -h.x, l.y >= 0 ? h.y : -h.y, l.z >= 0 ? h.z : -h.z);
        break;
    }
    case SHAPE_CYLINDER: {
        double r = sqrt(l.x * l.x + l.y * l.y);
        p = v3(r > 0 ? s->radius * l.x / r : 0, r > 0 ? s->radius * l.y / r : 0, l.z >= 0 ? s->half_height : -s->half_height);
        break;
    }
    default: {
        int best = 0;
        for (int i = 1; i < 8; i++)
            if (l.x * hull_points[i][0] + l.y * hull_points[i][1] + l.z * hull_points[i][2] >
                l.x * hull_points[best][0] + l.y * hull_points[best][1] + l.z * hull_points[best][2])
                best = i;
        p = v3(hull_points[best][0], hull_points[best][1], hull_points[best][2]);
    }
    }
    return xf_point(x, p);
}

/* Where a point's projection onto the triangle's plane lies: over the
 * face, beyond one edge only, or beyond a vertex (two edges). */
enum { REGION_FACE, REGION_EDGE, REGION_VERTEX };

static int region_of(vec3 p)
{
    vec3 n = face_normal();
    int out = 0;
    for (int k = 0; k < 3; k++)
        out += v3_dot(v3_cross(v3_sub(tri[(k + 1) % 3], tri[k]), n), v3_sub(p, tri[k])) > 1e-9;
    return out == 0 ? REGION_FACE : out == 1 ? REGION_EDGE : REGION_VERTEX;
}

static const char *type_name(int t)
{
    static const char *names[] = {"sphere", "box", "capsule", "cylinder", "hull"};
    return t >= 0 && t <= SHAPE_HULL ? names[t] : "?";
}

typedef struct pair_stats {
    int seen[3][3];          /* region (face, edge, vertex) x (apart, touching, deep) */
    int checked, exact, internal_checked, missed_beside;
    double worst_extra;      /* most room claimed beyond the distance, apart */
    int poor_normal;         /* apart, gap() along the contact's normal 1 mm short of its separation */
} pair_stats;

/* One pose: the brute force, then every check. */
static void check_pose(const shape *s, xform x, double tol, int trial, pair_stats *st)
{
    vec3 n = face_normal();
    int round = s->type == SHAPE_SPHERE || s->type == SHAPE_CAPSULE;
    vec3 low = lowest_point(s, x, n), near;
    double depth_low = v3_dot(n, v3_sub(low, tri[0]));
    /* d: spheres and capsules, the signed distance; the others, the distance
     * when apart (0: the triangle cuts the shape, they overlap) */
    double d = round ? core_signed_distance(s, x, &near) : triangle_distance(s, x, &near);
    int known = round || d > 0; /* d is the signed distance */
    if (!known && region_of(low) == REGION_FACE) { d = depth_low; }
    int region = region_of(d > 0 ? near : low);
    if (d > 0 && region == REGION_FACE) region = region_of(low);
    int depth = !known && depth_low < 0 ? 2 : d > 1e-4 ? 0 : d > -1e-4 ? 1 : 2;
    manifold m;
    collide_triangle(tri, 7u, 0, s, x, SPEC, &m);
    if (d < SPEC - 1e-6 && m.count == 0) {
        /* beside the triangle the nearest features can be a vertex and an
         * edge or two vertices, axes the separating-axis test does not try:
         * then the closest points give the look-ahead contact (before: 1
         * box, 5 cylinder, 4 hull poses of 400 had none) */
        if (!round && d > 0 && region != REGION_FACE) st->missed_beside++;
        printf("  %s trial %d: no contact at distance %.6f (region %d, lowest point %.4f above)\n", type_name(s->type),
               trial, d, region, depth_low);
        assert_true(m.count > 0);
    }
    if (m.count > 0) {
        st->seen[region][depth]++;
        double sep = 1e300;
        for (int i = 0; i < m.count; i++) sep = fmin(sep, m.points[i].separation);
        assert_true(fabs(v3_len(m.normal) - 1) < 1e-9);
        assert_true(v3_dot(m.normal, n) > -1e-9); /* the front side only */
        if (known) {
            /* never more room than the distance */
            if (sep > d + tol) printf("  %s trial %d: separation %.7f beyond the distance %.7f\n", type_name(s->type), trial, sep, d);
            assert_true(sep <= d + tol);
        } else {
            /* overlapping: no room claimed */
            if (sep > tol) printf("  %s trial %d: overlapping, separation %.7f (region %d, lowest point %.4f above, normal %.3f %.3f %.3f, id %x)\n", type_name(s->type), trial, sep, region, depth_low, m.normal.x, m.normal.y, m.normal.z, m.points[0].id);
            assert_true(sep <= tol);
        }
        if (known && d > 0) {
            /* nor along its own normal: moved that far towards the triangle it does not reach it */
            xform moved = {v3_madd(x.p, -(sep - tol), m.normal), x.q};
            vec3 unused;
            if (sep > tol && !(triangle_distance(s, moved, &unused) > 0))
                printf("  %s trial %d: moved %.7f along the normal, it overlaps\n", type_name(s->type), trial, sep);
            assert_true(sep <= tol || triangle_distance(s, moved, &unused) > 0);
            st->worst_extra = fmax(st->worst_extra, sep - d);
            /* informative: the room the normal itself shows */
            if (gap(s, x, m.normal) < sep - 1e-3) st->poor_normal++;
        }
        st->checked++;
        if (known && fabs(sep - d) <= 1e-6) st->exact++;
        if (round) {
            if (fabs(sep - d) > 1e-7) printf("  %s trial %d: separation %.9f, signed distance %.9f\n", type_name(s->type), trial, sep, d);
            assert_true(fabs(sep - d) <= 1e-7);
        }
    }
    /* every edge internal: the face normal, no point deeper than the
     * shape's lowest point along it */
    collide_triangle(tri, 0u, 0, s, x, SPEC, &m);
    if (m.count > 0) {
        assert_true(v3_len(v3_sub(m.normal, n)) < 1e-12);
        double lowest_gap = gap(s, x, n);
        for (int i = 0; i < m.count; i++) {
            if (m.points[i].separation < lowest_gap - tol)
                printf("  %s trial %d internal: point %d separation %.7f below the lowest point's %.7f\n",
                       type_name(s->type), trial, i, m.points[i].separation, lowest_gap);
            assert_true(m.points[i].separation >= lowest_gap - tol);
        }
        /* over the face the lowest point is the contact */
        if (region_of(low) == REGION_FACE && depth_low < SPEC - 1e-6) {
            double sep = 1e300;
            for (int i = 0; i < m.count; i++) sep = fmin(sep, m.points[i].separation);
            assert_true(sep <= lowest_gap + tol);
        }
        st->internal_checked++;
    }
}

/* Along the direction from the shape's nearest point to the triangle's
 * (the gradient of the point's distance to the shape). */
static vec3 towards_triangle(const shape *s, xform x, vec3 near)
{
    const double h = 1e-7;
    vec3 g = v3((point_distance(s, x, v3_add(near, v3(h, 0, 0))) - point_distance(s, x, v3_sub(near, v3(h, 0, 0)))) / (2 * h),
                (point_distance(s, x, v3_add(near, v3(0, h, 0))) - point_distance(s, x, v3_sub(near, v3(0, h, 0)))) / (2 * h),
                (point_distance(s, x, v3_add(near, v3(0, 0, h))) - point_distance(s, x, v3_sub(near, v3(0, 0, h)))) / (2 * h));
    return v3_normalize(g);
}

static void check_shape(int type)
{
    shape s = make_shape(type);
    vec3 n = face_normal();
    const double tol = 1e-7;
    unsigned seed = 17u + (unsigned)type;
    pair_stats st;
    memset(&st, 0, sizeof st);
    for (int trial = 0; trial < 400; trial++) {
        /* centre somewhere over or around the triangle, lifted so the lowest
         * point along -n lies between 6 cm deep and 8 cm above the plane */
        xform x = {v3(3.4 * lcg(&seed) - 1.7, 3.4 * lcg(&seed) - 1.6, 0), random_quat(&seed)};
        if (trial % 2 == 0) {
            /* around a vertex: out along the bisector of its corner */
            int k = (trial / 2) % 3;
            vec3 c = v3_scale(v3_add(tri[0], v3_add(tri[1], tri[2])), 1.0 / 3.0);
            vec3 out = v3_normalize(v3_sub(tri[k], c));
            x.p = v3_madd(tri[k], 0.6 * lcg(&seed) - 0.1, out);
            x.p = v3_add(x.p, v3(0.3 * lcg(&seed) - 0.15, 0.3 * lcg(&seed) - 0.15, 0));
        }
        double lift = -support(&s, x, v3_neg(n)) - v3_dot(n, tri[0]);
        /* around vertices deeper: overlapping there is rarer */
        x.p = v3_madd(x.p, -lift + 0.14 * lcg(&seed) - (trial % 2 == 0 ? 0.1 : 0.06), n);
        vec3 near;
        double d = triangle_distance(&s, x, &near);
        if (d > 0.1) continue;
        check_pose(&s, x, tol, trial, &st);
        if (d > 1e-4) {
            /* touching: moved towards the triangle until 1 um apart */
            vec3 w = towards_triangle(&s, x, near);
            xform xt = {v3_madd(x.p, d - 1e-6, w), x.q};
            check_pose(&s, xt, tol, 1000 + trial, &st);
        }
    }
    printf("  %s: %d contacts (%d at the signed distance within 1 um, most room beyond the distance %.2g m, "
           "%d apart with a normal that shows 1 mm less room), "
           "%d with internal edges, %d look-ahead misses beside the triangle; face/edge/vertex x apart/touching/deep: "
           "%d %d %d / %d %d %d / %d %d %d\n",
           type_name(type), st.checked, st.exact, st.worst_extra, st.poor_normal, st.internal_checked, st.missed_beside,
           st.seen[0][0], st.seen[0][1], st.seen[0][2], st.seen[1][0], st.seen[1][1], st.seen[1][2], st.seen[2][0],
           st.seen[2][1], st.seen[2][2]);
    /* the true cylinder: at the distance itself mostly (the prism: 63 of 244) */
    if (type == SHAPE_CYLINDER) assert_true(2 * st.exact > st.checked);
    /* each region apart, touching and deep */
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) assert_true(st.seen[r][k] >= 1);
    shape_free_data(&s);
}

static void test_sphere_against_triangle(void **state) { (void)state; check_shape(SHAPE_SPHERE); }
static void test_capsule_against_triangle(void **state) { (void)state; check_shape(SHAPE_CAPSULE); }
static void test_box_against_triangle(void **state) { (void)state; check_shape(SHAPE_BOX); }
static void test_cylinder_against_triangle(void **state) { (void)state; check_shape(SHAPE_CYLINDER); }
static void test_hull_against_triangle(void **state) { (void)state; check_shape(SHAPE_HULL); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_against_triangle),
        cmocka_unit_test(test_capsule_against_triangle),
        cmocka_unit_test(test_box_against_triangle),
        cmocka_unit_test(test_cylinder_against_triangle),
        cmocka_unit_test(test_hull_against_triangle),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
