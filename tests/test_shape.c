/* test_shape.c - shapes against closed forms: volumes and mass properties of
 * every shape (sphere 2/5 m r^2, box, capsule and cylinder also by an exact
 * integral over their profile, hulls of cubes and tetrahedra), hull topology
 * on clean and degenerate point sets, rejection of bad input, bounds that
 * contain and touch the shape, support points against brute force, and ray
 * casts against hand-computed hits. */
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
#include "shape.h"
#include "helpers.h"


/* ---- helpers ------------------------------------------------------------------ */

static int close_to(double got, double want, double tol, const char *what, int item)
{
    if (fabs(got - want) <= tol) return 1;
    print_error("%s (case %d): got %.17g expected %.17g (tolerance %g)\n", what, item, got, want, tol);
    return 0;
}

#define CHECK_CLOSE(got, want, tol, what, item) assert_true(close_to((got), (want), (tol), (what), (item)))

static void check_mat(mat3 got, mat3 want, double tol, const char *what, int item)
{
    double g[9] = {got.c0.x, got.c0.y, got.c0.z, got.c1.x, got.c1.y, got.c1.z, got.c2.x, got.c2.y, got.c2.z};
    double w[9] = {want.c0.x, want.c0.y, want.c0.z, want.c1.x, want.c1.y, want.c1.z, want.c2.x, want.c2.y, want.c2.z};
    for (int i = 0; i < 9; i++) CHECK_CLOSE(g[i], w[i], tol, what, item);
}

static void check_vec(vec3 got, vec3 want, double tol, const char *what, int item)
{
    CHECK_CLOSE(got.x, want.x, tol, what, item);
    CHECK_CLOSE(got.y, want.y, tol, what, item);
    CHECK_CLOSE(got.z, want.z, tol, what, item);
}

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
static shape hull_shape(hull *h) { shape s = make(SHAPE_HULL); s.hull = h; return s; }

static vec3 rnd_unit(uint64_t *s)
{
    for (;;) {
        vec3 v = v3(2 * rnd(s) - 1, 2 * rnd(s) - 1, 2 * rnd(s) - 1);
        double l = v3_len(v);
        if (l > 0.1 && l <= 1) return v3_scale(v, 1 / l);
    }
}

static quat rnd_quat(uint64_t *s)
{
    quat q = {rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5};
    return q_normalize(q);
}

/* n points spread evenly over the unit sphere (Fibonacci lattice) */
static void fibonacci_sphere(double *pts, int n)
{
    double golden = PI_ * (3 - sqrt(5.0));
    for (int i = 0; i < n; i++) {
        double z = 1 - (2 * i + 1.0) / n, r = sqrt(1 - z * z), a = golden * i;
        pts[3 * i] = r * cos(a);
        pts[3 * i + 1] = r * sin(a);
        pts[3 * i + 2] = z;
    }
}

static void box_corners(double *pts, vec3 he)
{
    for (int i = 0; i < 8; i++) {
        pts[3 * i] = (i & 1) ? he.x : -he.x;
        pts[3 * i + 1] = (i & 2) ? he.y : -he.y;
        pts[3 * i + 2] = (i & 4) ? he.z : -he.z;
    }
}

static vec3 pt(const double *pts, int i) { return v3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]); }

/* Every structural promise of a hull, checked against the input points:
 * Euler V - E + F = 2; each directed edge used once and its reverse once
 * (closed, consistently oriented); the edge list is exactly the undirected
 * face edges; faces have at least 3 corners, lie on their plane, are convex
 * and counter-clockwise seen from outside (their polygon's area vector
 * points along the unit normal); every vertex is an input point on at least
 * three faces; every input point lies inside every face plane. */
static void check_hull(const hull *h, const double *pts, int n, int item)
{
    vec3 lo = pt(pts, 0), hi = lo;
    for (int i = 1; i < n; i++) { lo = v3_min(lo, pt(pts, i)); hi = v3_max(hi, pt(pts, i)); }
    double size = v3_len(v3_sub(hi, lo)), tol = 1e-6 * size;
    int V = h->vertex_count, F = h->face_count, E = h->edge_count;
    if (V - E + F != 2) print_error("case %d: V %d E %d F %d\n", item, V, E, F);
    assert_int_equal(V - E + F, 2);
    int *uses = calloc((size_t)V * (size_t)V, sizeof *uses), *faces_at = calloc((size_t)V, sizeof *faces_at);
    assert_non_null(uses);
    assert_non_null(faces_at);
    for (int f = 0; f < F; f++) {
        const hull_face *fc = &h->faces[f];
        const int *idx = &h->face_vertices[fc->first];
        assert_true(fc->count >= 3);
        CHECK_CLOSE(v3_len(fc->normal), 1.0, 1e-12, "face normal is unit", item);
        vec3 area = v3_zero();
        for (int k = 0; k < fc->count; k++) {
            int a = idx[k], b = idx[(k + 1) % fc->count], c = idx[(k + 2) % fc->count];
            assert_true(a >= 0 && a < V);
            uses[a * V + b]++;
            faces_at[a]++;
            CHECK_CLOSE(v3_dot(fc->normal, h->vertices[a]), fc->offset, tol, "face vertex on its plane", item);
            vec3 turn = v3_cross(v3_sub(h->vertices[b], h->vertices[a]), v3_sub(h->vertices[c], h->vertices[b]));
            assert_true(v3_dot(turn, fc->normal) > 0); /* convex, counter-clockwise */
            area = v3_add(area, v3_cross(h->vertices[a], h->vertices[b]));
        }
        assert_true(v3_dot(area, fc->normal) > 0.999 * v3_len(area));
    }
    int half_edges = 0;
    for (int a = 0; a < V; a++) {
        assert_true(faces_at[a] >= 3);
        for (int b = 0; b < V; b++) {
            assert_true(uses[a * V + b] <= 1);
            assert_int_equal(uses[a * V + b], uses[b * V + a]);
            half_edges += uses[a * V + b];
        }
    }
    assert_int_equal(2 * E, half_edges);
    for (int e = 0; e < E; e++) {
        int a = h->edges[e][0], b = h->edges[e][1];
        assert_int_equal(uses[a * V + b], 1);
        for (int g = e + 1; g < E; g++)
            assert_false((h->edges[g][0] == a && h->edges[g][1] == b) || (h->edges[g][0] == b && h->edges[g][1] == a));
    }
    for (int v = 0; v < V; v++) {
        int found = 0;
        for (int i = 0; i < n && !found; i++) found = v3_len(v3_sub(h->vertices[v], pt(pts, i))) == 0;
        assert_true(found);
    }
    for (int f = 0; f < F; f++)
        for (int i = 0; i < n; i++)
            if (v3_dot(h->faces[f].normal, pt(pts, i)) > h->faces[f].offset + tol) {
                print_error("case %d: point %d outside face %d by %g\n", item, i, f,
                            v3_dot(h->faces[f].normal, pt(pts, i)) - h->faces[f].offset);
                fail();
            }
    free(uses);
    free(faces_at);
}

/* Volume and inertia of a solid of revolution about z with radius R(z), by
 * 5-point Gauss-Legendre on each piece where R^2 is a polynomial: exact for
 * the capsule's and cylinder's integrands (degree <= 4). Density 1. */
typedef struct revolution { double volume, ixx, izz; } revolution;

static double capsule_radius2(double z, double r, double hh)
{
    double e = fabs(z) - hh;
    return e <= 0 ? r * r : r * r - e * e;
}

static revolution revolve(double r, double hh, int caps)
{
    static const double x[5] = {0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
    static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891, 0.2369268850561891};
    double ends[4] = {-hh - r, -hh, hh, hh + r};
    revolution out = {0, 0, 0};
    for (int piece = caps ? 0 : 1; piece < (caps ? 3 : 2); piece++) {
        double a = ends[piece], b = ends[piece + 1];
        for (int k = 0; k < 5; k++) {
            double z = 0.5 * (a + b) + 0.5 * (b - a) * x[k], dz = 0.5 * (b - a) * w[k];
            double r2 = capsule_radius2(z, r, hh);
            /* a disc of radius R at height z: area pi R^2, about x: R^2/4 + z^2 per unit mass */
            out.volume += PI_ * r2 * dz;
            out.ixx += PI_ * r2 * (r2 / 4 + z * z) * dz;
            out.izz += PI_ * r2 * r2 / 2 * dz;
        }
    }
    return out;
}

/* ---- mass properties ------------------------------------------------------------ */

static void test_sphere_and_box_mass(void **state)
{
    (void)state;
    shape s = sphere(0.3);
    CHECK_CLOSE(shape_volume(&s), 4.0 / 3.0 * PI_ * 0.027, 1e-15, "sphere volume", 0);
    mass_props mp = shape_mass_from_density(&s, 7800);
    double m = 7800 * 4.0 / 3.0 * PI_ * 0.027, i = 0.4 * m * 0.09;
    CHECK_CLOSE(mp.mass, m, 1e-12 * m, "sphere mass from density", 0);
    check_mat(mp.inertia, m3_diag(v3(i, i, i)), 1e-12 * i, "sphere 2/5 m r^2", 0);
    check_vec(mp.center, v3_zero(), 0, "sphere centre", 0);
    mp = shape_mass_from_mass(&s, 2.5);
    CHECK_CLOSE(mp.mass, 2.5, 1e-15, "sphere given mass", 0);
    check_mat(mp.inertia, m3_diag(v3(0.4 * 2.5 * 0.09, 0.4 * 2.5 * 0.09, 0.4 * 2.5 * 0.09)), 1e-15, "sphere 2/5 m r^2 (mass)", 0);

    /* box with full extents a, b, c: Ixx = m (b^2 + c^2) / 12 and so on */
    shape b = box(0.5, 1.0, 1.5);
    double a = 1.0, bb = 2.0, c = 3.0;
    CHECK_CLOSE(shape_volume(&b), a * bb * c, 1e-15, "box volume", 0);
    mp = shape_mass_from_mass(&b, 12.0);
    check_mat(mp.inertia, m3_diag(v3(bb * bb + c * c, a * a + c * c, a * a + bb * bb)), 1e-13, "box inertia", 0);
    mp = shape_mass_from_density(&b, 2.0);
    CHECK_CLOSE(mp.mass, 12.0, 1e-15, "box mass from density", 0);
    check_vec(mp.center, v3_zero(), 0, "box centre", 0);
}

static void test_capsule_and_cylinder_mass(void **state)
{
    (void)state;
    double r = 0.3, hh = 0.5, h = 2 * hh, m = 2.0;
    shape c = capsule(r, hh);
    double vc = PI_ * r * r * h, vs = 4.0 / 3.0 * PI_ * r * r * r;
    CHECK_CLOSE(shape_volume(&c), vc + vs, 1e-15, "capsule volume", 0);
    mass_props mp = shape_mass_from_mass(&c, m);
    /* cylinder part plus two hemispheres: a hemisphere's centroid sits 3r/8
     * from its flat face, its own transverse moment is (2/5 - 9/64) m r^2,
     * carried to the body centre by the parallel axis theorem */
    double mc = m * vc / (vc + vs), ms = m * vs / (vc + vs), d = hh + 3 * r / 8;
    double izz = mc * r * r / 2 + 0.4 * ms * r * r;
    double ixx = mc * (3 * r * r + h * h) / 12 + ms * ((0.4 - 9.0 / 64.0) * r * r + d * d);
    check_mat(mp.inertia, m3_diag(v3(ixx, ixx, izz)), 1e-14, "capsule inertia", 0);
    /* the same again, as a plain expansion: 2/5 r^2 + h^2/4 + 3 h r/8 per unit hemisphere mass */
    CHECK_CLOSE(ixx, mc * (3 * r * r + h * h) / 12 + ms * (0.4 * r * r + h * h / 4 + 3 * h * r / 8), 1e-15, "capsule Ixx expanded", 0);
    /* and by integrating discs along the axis */
    revolution rv = revolve(r, hh, 1);
    CHECK_CLOSE(shape_volume(&c), rv.volume, 1e-14, "capsule volume (integral)", 0);
    mp = shape_mass_from_density(&c, 1.0);
    CHECK_CLOSE(mp.inertia.c0.x, rv.ixx, 1e-14, "capsule Ixx (integral)", 0);
    CHECK_CLOSE(mp.inertia.c1.y, rv.ixx, 1e-14, "capsule Iyy (integral)", 0);
    CHECK_CLOSE(mp.inertia.c2.z, rv.izz, 1e-14, "capsule Izz (integral)", 0);

    /* cylinder along z, full height h: Izz = m r^2 / 2, Ixx = Iyy = m (3 r^2 + h^2) / 12 */
    r = 0.5;
    hh = 0.25;
    h = 0.5;
    shape y = cylinder(r, hh);
    mass_props my = shape_mass_from_density(&y, 1000);
    double mass = 1000 * PI_ * r * r * h;
    CHECK_CLOSE(my.mass, mass, 1e-12, "cylinder mass from density", 0);
    check_mat(my.inertia, m3_diag(v3(mass * (3 * r * r + h * h) / 12, mass * (3 * r * r + h * h) / 12, mass * r * r / 2)),
              1e-12, "cylinder inertia", 0);
    rv = revolve(r, hh, 0);
    my = shape_mass_from_density(&y, 1.0);
    CHECK_CLOSE(my.inertia.c0.x, rv.ixx, 1e-15, "cylinder Ixx (integral)", 0);
    CHECK_CLOSE(my.inertia.c2.z, rv.izz, 1e-15, "cylinder Izz (integral)", 0);
    my = shape_mass_from_mass(&y, 3.0);
    CHECK_CLOSE(my.mass, 3.0, 1e-15, "cylinder given mass", 0);
    CHECK_CLOSE(my.inertia.c2.z, 3.0 * r * r / 2, 1e-15, "cylinder Izz from mass", 0);
}

static void test_plane_has_no_mass(void **state)
{
    (void)state;
    shape p = make(SHAPE_PLANE);
    p.plane_normal = v3(0, 0, 1);
    CHECK_CLOSE(shape_volume(&p), 0, 0, "plane volume", 0);
    mass_props a = shape_mass_from_density(&p, 1000), b = shape_mass_from_mass(&p, 5);
    assert_true(a.mass == 0 && b.mass == 0);
    check_mat(a.inertia, m3_zero(), 0, "plane tensor", 0);
    check_mat(b.inertia, m3_zero(), 0, "plane tensor (mass)", 0);
}

/* The hull of a box's corners is the box: same mass, centre and tensor. */
static void check_hull_is_box(const hull *h, vec3 he, int item)
{
    shape hs = hull_shape((hull *)h), bs = box(he.x, he.y, he.z);
    double vol = 8 * he.x * he.y * he.z;
    assert_int_equal(h->vertex_count, 8);
    assert_int_equal(h->face_count, 6); /* coplanar triangles merged into quads */
    assert_int_equal(h->edge_count, 12);
    for (int f = 0; f < 6; f++) {
        assert_int_equal(h->faces[f].count, 4);
        vec3 n = v3_abs(h->faces[f].normal);
        assert_true(fabs(fmax(n.x, fmax(n.y, n.z)) - 1) < 1e-15);
    }
    CHECK_CLOSE(h->volume, vol, 1e-12 * vol, "hull box volume", item);
    mass_props a = shape_mass_from_mass(&hs, 3.0), b = shape_mass_from_mass(&bs, 3.0);
    CHECK_CLOSE(a.mass, b.mass, 1e-12, "hull box mass", item);
    check_vec(a.center, b.center, 1e-12 * v3_len(he), "hull box centre", item);
    check_mat(a.inertia, b.inertia, 1e-12 * b.inertia.c0.x, "hull box inertia", item);
}

static void test_hull_of_box_corners_is_the_box(void **state)
{
    (void)state;
    vec3 he = v3(0.3, 0.7, 1.1);
    double pts[3 * 608];
    box_corners(pts, he);
    hull *h = hull_build(pts, 8, NULL, 0);
    assert_non_null(h);
    check_hull_is_box(h, he, 0);
    check_hull(h, pts, 8, 0);
    hull_free(h);
    /* corners plus random points inside, on the faces and on the edges, shuffled */
    uint64_t seed = 3;
    for (int trial = 0; trial < 4; trial++) {
        int n = 608;
        box_corners(pts, he);
        for (int i = 8; i < n; i++) {
            vec3 u = v3(2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1);
            int kind = i % 3, axis = (int)(3 * rnd(&seed));
            double side = rnd(&seed) < 0.5 ? -1 : 1;
            if (kind >= 1) u = v3(axis == 0 ? side : u.x, axis == 1 ? side : u.y, axis == 2 ? side : u.z); /* a face */
            if (kind == 2) u = v3(axis == 1 ? side : u.x, axis == 2 ? side : u.y, axis == 0 ? side : u.z); /* an edge */
            vec3 p = v3_mul(u, he);
            pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
        }
        for (int i = n - 1; i > 0; i--) {
            int j = (int)(rnd(&seed) * (i + 1));
            for (int c = 0; c < 3; c++) { double t = pts[3 * i + c]; pts[3 * i + c] = pts[3 * j + c]; pts[3 * j + c] = t; }
        }
        h = hull_build(pts, n, NULL, 0);
        assert_non_null(h);
        check_hull_is_box(h, he, 1 + trial);
        check_hull(h, pts, n, 1 + trial);
        hull_free(h);
    }
    /* corners repeated with 1e-13 jitter: still the box */
    int n = 0;
    for (int r = 0; r < 10; r++)
        for (int i = 0; i < 8; i++, n++) {
            pts[3 * n] = ((i & 1) ? he.x : -he.x) + 1e-13 * (rnd(&seed) - 0.5);
            pts[3 * n + 1] = ((i & 2) ? he.y : -he.y) + 1e-13 * (rnd(&seed) - 0.5);
            pts[3 * n + 2] = ((i & 4) ? he.z : -he.z) + 1e-13 * (rnd(&seed) - 0.5);
        }
    h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 8);
    assert_int_equal(h->face_count, 6);
    CHECK_CLOSE(h->volume, 8 * he.x * he.y * he.z, 1e-11, "near-duplicate corners", 0);
    check_hull(h, pts, n, 9);
    hull_free(h);
    h = hull_make_box(he);
    assert_non_null(h);
    check_hull_is_box(h, he, 10);
    hull_free(h);
}

/* A box turned and moved: centroid at the offset, tensor R D R^T about it. */
static void test_offset_rotated_hull(void **state)
{
    (void)state;
    uint64_t seed = 5;
    for (int trial = 0; trial < 8; trial++) {
        vec3 he = v3(0.2 + rnd(&seed), 0.2 + rnd(&seed), 0.2 + rnd(&seed));
        vec3 offset = v3(10 * rnd(&seed) - 5, 10 * rnd(&seed) - 5, 10 * rnd(&seed) - 5);
        quat q = rnd_quat(&seed);
        double pts[24];
        box_corners(pts, he);
        for (int i = 0; i < 8; i++) {
            vec3 p = v3_add(offset, q_rotate(q, pt(pts, i)));
            pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
        }
        hull *h = hull_build(pts, 8, NULL, 0);
        assert_non_null(h);
        assert_int_equal(h->face_count, 6);
        check_hull(h, pts, 8, trial);
        shape hs = hull_shape(h), bs = box(he.x, he.y, he.z);
        mass_props a = shape_mass_from_density(&hs, 2.0), b = shape_mass_from_density(&bs, 2.0);
        CHECK_CLOSE(a.mass, b.mass, 1e-12 * b.mass, "rotated hull mass", trial);
        check_vec(a.center, offset, 1e-12 * v3_len(offset), "offset hull centroid", trial);
        check_mat(a.inertia, m3_rotate_tensor(m3_from_quat(q), b.inertia), 1e-11 * b.inertia.c0.x, "rotated hull tensor", trial);
        hull_free(h);
    }
}

static void test_hull_of_tetrahedra(void **state)
{
    (void)state;
    /* regular tetrahedron of edge a: V = a^3 / (6 sqrt 2), and about its
     * centroid the tensor is m a^2 / 20 times the identity */
    uint64_t seed = 7;
    for (int trial = 0; trial < 4; trial++) {
        double scale = 0.1 + rnd(&seed), a = 2 * sqrt(2.0) * scale;
        quat q = rnd_quat(&seed);
        vec3 offset = v3(rnd(&seed), rnd(&seed), rnd(&seed));
        double corners[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, pts[12];
        for (int i = 0; i < 4; i++) {
            vec3 p = v3_add(offset, q_rotate(q, v3_scale(v3(corners[i][0], corners[i][1], corners[i][2]), scale)));
            pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
        }
        hull *h = hull_build(pts, 4, NULL, 0);
        assert_non_null(h);
        assert_int_equal(h->vertex_count, 4);
        assert_int_equal(h->face_count, 4);
        assert_int_equal(h->edge_count, 6);
        check_hull(h, pts, 4, trial);
        double vol = a * a * a / (6 * sqrt(2.0)), i = vol * a * a / 20;
        CHECK_CLOSE(h->volume, vol, 1e-13 * vol, "regular tetrahedron volume", trial);
        check_vec(h->centroid, offset, 1e-13, "regular tetrahedron centroid", trial);
        check_mat(h->unit_inertia, m3_diag(v3(i, i, i)), 1e-12 * i, "regular tetrahedron m a^2 / 20", trial);
        hull_free(h);
    }
    /* the corner tetrahedron (unit legs): V = 1/6, centroid (1/4, 1/4, 1/4);
     * about the origin int x^2 dV = 1/60 and int x y dV = 1/120, so
     * Ixx = 1/30 and Ixy = -1/120 there; moved to the centroid by the
     * parallel axis theorem */
    double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    hull *h = hull_build(tet, 4, NULL, 0);
    assert_non_null(h);
    double m = 1.0 / 6.0, ixx = 1.0 / 30.0 - m * (1.0 / 16 + 1.0 / 16), ixy = -(1.0 / 120.0 - m / 16);
    CHECK_CLOSE(h->volume, m, 1e-15, "corner tetrahedron volume", 0);
    check_vec(h->centroid, v3(0.25, 0.25, 0.25), 1e-15, "corner tetrahedron centroid", 0);
    check_mat(h->unit_inertia, m3_cols(v3(ixx, ixy, ixy), v3(ixy, ixx, ixy), v3(ixy, ixy, ixx)), 1e-15,
              "corner tetrahedron tensor", 0);
    hull_free(h);
}

/* A square pyramid, base side a and height h, turned and moved: its
 * centroid (h/4 above the base) is not the mean of its corners (h/5), so
 * this checks that the tensor is taken about the centroid:
 * Izz = m a^2 / 10 and Ixx = Iyy = m (a^2 / 20 + 3 h^2 / 80). */
static void test_hull_of_square_pyramid(void **state)
{
    (void)state;
    uint64_t seed = 37;
    for (int trial = 0; trial < 4; trial++) {
        double a = 0.5 + rnd(&seed), h = 0.5 + 2 * rnd(&seed);
        quat q = rnd_quat(&seed);
        vec3 offset = v3(4 * rnd(&seed) - 2, 4 * rnd(&seed) - 2, 4 * rnd(&seed) - 2);
        vec3 local[5] = {v3(-a / 2, -a / 2, 0), v3(a / 2, -a / 2, 0), v3(a / 2, a / 2, 0), v3(-a / 2, a / 2, 0), v3(0, 0, h)};
        double pts[15];
        for (int i = 0; i < 5; i++) {
            vec3 p = v3_add(offset, q_rotate(q, local[i]));
            pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
        }
        hull *hl = hull_build(pts, 5, NULL, 0);
        assert_non_null(hl);
        assert_int_equal(hl->vertex_count, 5);
        assert_int_equal(hl->face_count, 5);
        assert_int_equal(hl->edge_count, 8);
        check_hull(hl, pts, 5, trial);
        shape s = hull_shape(hl);
        mass_props mp = shape_mass_from_mass(&s, 2.0);
        CHECK_CLOSE(hl->volume, a * a * h / 3, 1e-13, "pyramid volume", trial);
        check_vec(mp.center, v3_add(offset, q_rotate(q, v3(0, 0, h / 4))), 1e-13, "pyramid centroid", trial);
        double ixx = 2.0 * (a * a / 20 + 3 * h * h / 80), izz = 2.0 * a * a / 10;
        check_mat(mp.inertia, m3_rotate_tensor(m3_from_quat(q), m3_diag(v3(ixx, ixx, izz))), 1e-12, "pyramid tensor", trial);
        hull_free(hl);
    }
}

/* Points on a sphere: the inscribed hull's volume approaches 4/3 pi from
 * below, and its tensor approaches 2/5 m r^2. */
static void test_hull_of_sphere_points(void **state)
{
    (void)state;
    static double pts[3 * 3000];
    double sphere_volume = 4.0 / 3.0 * PI_, last_gap = 1;
    int sizes[3] = {100, 600, 3000};
    for (int k = 0; k < 3; k++) {
        int n = sizes[k];
        fibonacci_sphere(pts, n);
        hull *h = hull_build(pts, n, NULL, 0);
        assert_non_null(h);
        assert_int_equal(h->vertex_count, n); /* every point is extreme */
        double gap = 1 - h->volume / sphere_volume;
        /* 2n nearly equilateral faces of area A = 4 pi / 2n and circumradius
         * rho^2 = 4 A / (3 sqrt 3). Such a face lies (rho^2 - s^2) / 2 below
         * the sphere at distance s from its centre, and s^2 averages rho^2 / 4
         * over it: a mean depth 3 rho^2 / 8, and a shell 3 times as thick in
         * volume, 9 rho^2 / 8 of the sphere */
        double rho2 = 4 * PI_ / (2 * n) * 4 / (3 * sqrt(3.0)), expect = 9 * rho2 / 8;
        if (!(gap > 0.9 * expect && gap < 1.25 * expect)) {
            print_error("n = %d: volume gap %g, expected about %g\n", n, gap, expect);
            fail();
        }
        assert_true(gap < last_gap / 4); /* shrinks like 1/n */
        last_gap = gap;
        check_vec(h->centroid, v3_zero(), 1e-3, "sphere cloud centroid", k);
        shape s = hull_shape(h);
        mass_props mp = shape_mass_from_mass(&s, 1.0);
        CHECK_CLOSE(mp.inertia.c0.x, 0.4, 0.4 * 2 * gap, "sphere cloud 2/5 m r^2", k);
        if (n <= 600) check_hull(h, pts, n, k);
        hull_free(h);
    }
}

/* Symmetric and positive definite, for every shape and random hulls; the
 * principal moments obey the triangle inequality. */
static void check_spd(mat3 m, int item)
{
    double tr = m.c0.x + m.c1.y + m.c2.z;
    CHECK_CLOSE(m.c0.y, m.c1.x, 1e-14 * tr, "symmetric xy", item);
    CHECK_CLOSE(m.c0.z, m.c2.x, 1e-14 * tr, "symmetric xz", item);
    CHECK_CLOSE(m.c1.z, m.c2.y, 1e-14 * tr, "symmetric yz", item);
    assert_true(m.c0.x > 0);
    assert_true(m.c0.x * m.c1.y - m.c0.y * m.c1.x > 0);
    assert_true(m3_det(m) > 0);
    assert_true(m.c0.x + m.c1.y >= m.c2.z && m.c1.y + m.c2.z >= m.c0.x && m.c2.z + m.c0.x >= m.c1.y);
}

static void test_inertia_symmetric_positive_definite(void **state)
{
    (void)state;
    shape shapes[4] = {sphere(0.2), box(0.1, 0.5, 2.0), capsule(0.1, 3.0), cylinder(2.0, 0.01)};
    for (int k = 0; k < 4; k++) check_spd(shape_mass_from_density(&shapes[k], 10).inertia, k);
    uint64_t seed = 11;
    double pts[3 * 44];
    for (int trial = 0; trial < 20; trial++) {
        int n = 4 + trial * 2;
        vec3 stretch = v3(0.1 + rnd(&seed), 0.1 + rnd(&seed), 0.1 + rnd(&seed));
        for (int i = 0; i < n; i++) {
            vec3 p = v3_add(v3(3, -1, 2), v3_mul(stretch, v3(rnd(&seed), rnd(&seed), rnd(&seed))));
            pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
        }
        hull *h = hull_build(pts, n, NULL, 0);
        assert_non_null(h);
        check_hull(h, pts, n, 100 + trial);
        shape s = hull_shape(h);
        check_spd(shape_mass_from_density(&s, 1).inertia, 100 + trial);
        hull_free(h);
    }
}

/* ---- hull topology and rejections ------------------------------------------------ */

static void test_hull_topology_of_known_solids(void **state)
{
    (void)state;
    static double pts[3 * 1200];
    uint64_t seed = 13;
    /* dodecahedron (pentagons from merged triangles) and icosahedron */
    double phi = (1 + sqrt(5.0)) / 2;
    int n = 0;
    for (int i = 0; i < 8; i++, n++) {
        pts[3 * n] = (i & 1) ? 1 : -1; pts[3 * n + 1] = (i & 2) ? 1 : -1; pts[3 * n + 2] = (i & 4) ? 1 : -1;
    }
    for (int i = 0; i < 4; i++) {
        double a = (i & 1) ? 1 / phi : -1 / phi, b = (i & 2) ? phi : -phi;
        double v[3][3] = {{0, a, b}, {a, b, 0}, {b, 0, a}};
        for (int k = 0; k < 3; k++, n++) memcpy(&pts[3 * n], v[k], sizeof v[k]);
    }
    hull *h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 20);
    assert_int_equal(h->face_count, 12);
    assert_int_equal(h->edge_count, 30);
    for (int f = 0; f < 12; f++) assert_int_equal(h->faces[f].count, 5);
    /* edge 2/phi: V = (15 + 7 sqrt 5) / 4 a^3 */
    double a = 2 / phi;
    CHECK_CLOSE(h->volume, (15 + 7 * sqrt(5.0)) / 4 * a * a * a, 1e-12, "dodecahedron volume", 0);
    check_hull(h, pts, n, 0);
    /* again with points sampled on its faces, edges and inside */
    int base = n;
    for (int i = 0; i < 600; i++, n++) {
        const hull_face *f = &h->faces[(int)(rnd(&seed) * h->face_count)];
        vec3 p = v3_zero();
        double wsum = 0;
        for (int k = 0; k < f->count; k++) {
            double w = i % 3 == 0 && k > 1 ? 0 : rnd(&seed); /* a third of them on an edge */
            p = v3_madd(p, w, h->vertices[h->face_vertices[f->first + k]]);
            wsum += w;
        }
        p = v3_scale(p, 1 / wsum);
        if (i % 5 == 0) p = v3_scale(p, rnd(&seed));
        pts[3 * n] = p.x; pts[3 * n + 1] = p.y; pts[3 * n + 2] = p.z;
    }
    double vol = h->volume;
    hull_free(h);
    h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 20);
    assert_int_equal(h->face_count, 12);
    CHECK_CLOSE(h->volume, vol, 1e-12, "dodecahedron with samples", 0);
    check_hull(h, pts, n, 1);
    hull_free(h);
    /* turned at random, its faces are coplanar only to rounding: which side
     * of a face a sample lies on is then a question for the exact test */
    for (int trial = 0; trial < 6; trial++) {
        quat q = rnd_quat(&seed);
        static double turned[3 * 1200];
        for (int i = 0; i < n; i++) {
            vec3 p = q_rotate(q, pt(pts, i));
            turned[3 * i] = p.x; turned[3 * i + 1] = p.y; turned[3 * i + 2] = p.z;
        }
        h = hull_build(turned, n, NULL, 0);
        assert_non_null(h);
        assert_int_equal(h->vertex_count, 20);
        assert_int_equal(h->face_count, 12);
        CHECK_CLOSE(h->volume, vol, 1e-12, "turned dodecahedron with samples", trial);
        check_hull(h, turned, n, 10 + trial);
        hull_free(h);
    }
    (void)base;
    /* icosahedron */
    double ico[12][3] = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
                         {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
    h = hull_build(&ico[0][0], 12, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 12);
    assert_int_equal(h->face_count, 20);
    assert_int_equal(h->edge_count, 30);
    CHECK_CLOSE(h->volume, 5.0 / 12.0 * (3 + sqrt(5.0)) * 8, 1e-12, "icosahedron volume (edge 2)", 0);
    check_hull(h, &ico[0][0], 12, 2);
    hull_free(h);
    /* a 12-sided prism whose rims carry extra collinear and coplanar points */
    n = 0;
    for (int i = 0; i < 48; i++)
        for (int z = -1; z <= 1; z += 2, n++) {
            int corner = i / 4;
            double t = (i % 4) / 4.0, a0 = 2 * PI_ * corner / 12, a1 = 2 * PI_ * (corner + 1) / 12;
            pts[3 * n] = (1 - t) * cos(a0) + t * cos(a1);
            pts[3 * n + 1] = (1 - t) * sin(a0) + t * sin(a1);
            pts[3 * n + 2] = 0.5 * z;
        }
    h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 24);
    assert_int_equal(h->face_count, 14);
    assert_int_equal(h->edge_count, 36);
    CHECK_CLOSE(h->volume, 0.5 * 12 * sin(2 * PI_ / 12) * 1.0, 1e-12, "prism volume", 0);
    check_hull(h, pts, n, 3);
    hull_free(h);
    /* a cube's edge points listed before its corners: the edge points are
     * taken first and must drop out once the corners make them collinear */
    n = 0;
    for (int e = 0; e < 12; e++)
        for (int k = 1; k < 8; k++, n++) {
            int axis = e / 4;
            double q3[3];
            q3[axis] = -1 + 2.0 * k / 8;
            q3[(axis + 1) % 3] = (e & 1) ? 1 : -1;
            q3[(axis + 2) % 3] = (e & 2) ? 1 : -1;
            memcpy(&pts[3 * n], q3, sizeof q3);
        }
    for (int i = 0; i < 8; i++, n++) {
        pts[3 * n] = (i & 1) ? 1 : -1; pts[3 * n + 1] = (i & 2) ? 1 : -1; pts[3 * n + 2] = (i & 4) ? 1 : -1;
    }
    h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 8);
    assert_int_equal(h->face_count, 6);
    CHECK_CLOSE(h->volume, 8, 1e-12, "cube from edge points", 0);
    check_hull(h, pts, n, 6);
    hull_free(h);
    /* a 6x6x6 lattice: all but the 8 corners lie on faces or edges */
    n = 0;
    for (int i = 0; i < 216; i++, n++) { pts[3 * n] = i % 6; pts[3 * n + 1] = (i / 6) % 6; pts[3 * n + 2] = i / 36; }
    h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 8);
    assert_int_equal(h->face_count, 6);
    CHECK_CLOSE(h->volume, 125, 1e-12, "lattice volume", 0);
    check_hull(h, pts, n, 4);
    hull_free(h);
    /* far from the origin: a small sphere cloud at 1e6 */
    n = 300;
    fibonacci_sphere(pts, n);
    for (int i = 0; i < n; i++) {
        pts[3 * i] = 1e6 + 0.01 * pts[3 * i];
        pts[3 * i + 1] *= 0.01;
        pts[3 * i + 2] *= 0.01;
    }
    h = hull_build(pts, n, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, n);
    check_hull(h, pts, n, 5);
    hull_free(h);
}

/* A turned solid sampled on its edges, on its faces and inside: the hull of
 * it all is the solid again. Turned, its faces are coplanar only to
 * rounding, so which side of a face a sample lies on is a question for the
 * exact orientation test, and thin triangles along the edges must not
 * capture points with their rounded planes. */
static void test_hull_of_sampled_solids(void **state)
{
    (void)state;
    static double pts[3 * 1520];
    double phi = (1 + sqrt(5.0)) / 2;
    vec3 solid[2][20];
    int corners[2] = {8, 20};
    for (int i = 0; i < 8; i++) solid[0][i] = v3((i & 1) ? 1 : -1, (i & 2) ? 0.5 : -0.5, (i & 4) ? 2 : -2);
    for (int i = 0; i < 8; i++) solid[1][i] = v3((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    for (int i = 0; i < 4; i++) {
        double a = (i & 1) ? 1 / phi : -1 / phi, b = (i & 2) ? phi : -phi;
        solid[1][8 + 3 * i] = v3(0, a, b);
        solid[1][9 + 3 * i] = v3(a, b, 0);
        solid[1][10 + 3 * i] = v3(b, 0, a);
    }
    uint64_t seed = 41;
    for (int trial = 0; trial < 24; trial++) {
        int kind = trial % 2, nb = corners[kind], n = 0;
        quat q = rnd_quat(&seed);
        for (int i = 0; i < nb; i++, n++) {
            vec3 p = q_rotate(q, solid[kind][i]);
            pts[3 * n] = p.x; pts[3 * n + 1] = p.y; pts[3 * n + 2] = p.z;
        }
        hull *h0 = hull_build(pts, nb, NULL, 0);
        assert_non_null(h0);
        for (int k = 0; k < 1500; k++, n++) {
            const hull_face *f = &h0->faces[(int)(rnd(&seed) * h0->face_count)];
            const int *idx = &h0->face_vertices[f->first];
            vec3 p = v3_zero();
            if (k % 3 == 0) { /* on an edge */
                int e = (int)(rnd(&seed) * f->count);
                p = v3_lerp(h0->vertices[idx[e]], h0->vertices[idx[(e + 1) % f->count]], rnd(&seed));
            } else { /* on a face, then a third of those moved inside */
                double wsum = 0;
                for (int v = 0; v < f->count; v++) {
                    double w = rnd(&seed);
                    p = v3_madd(p, w * w * w, h0->vertices[idx[v]]);
                    wsum += w * w * w;
                }
                p = v3_scale(p, 1 / wsum);
                if (k % 3 == 2) p = v3_lerp(p, h0->centroid, rnd(&seed));
            }
            pts[3 * n] = p.x; pts[3 * n + 1] = p.y; pts[3 * n + 2] = p.z;
        }
        for (int i = n - 1; i > 0; i--) {
            int j = (int)(rnd(&seed) * (i + 1));
            for (int c = 0; c < 3; c++) { double t = pts[3 * i + c]; pts[3 * i + c] = pts[3 * j + c]; pts[3 * j + c] = t; }
        }
        hull *h = hull_build(pts, n, NULL, 0);
        assert_non_null(h);
        if (h->vertex_count != nb || h->face_count != h0->face_count)
            print_error("trial %d: %d vertices %d faces, expected %d and %d\n", trial, h->vertex_count, h->face_count, nb, h0->face_count);
        assert_int_equal(h->vertex_count, nb);
        assert_int_equal(h->face_count, h0->face_count);
        CHECK_CLOSE(h->volume, h0->volume, 1e-12 * h0->volume, "sampled solid volume", trial);
        check_hull(h, pts, n, trial);
        hull_free(h);
        hull_free(h0);
    }
}

/* Many small turned boxes given by their corners and points on their edges:
 * the edge points are collinear only to rounding, so now and then three of
 * them make a triangle too thin for its rounded plane to measure distances
 * with; such a triangle must not capture (and lose) the corners. */
static void test_hull_of_boxes_with_edge_points(void **state)
{
    (void)state;
    uint64_t seed = 41;
    double pts[3 * 38];
    for (int trial = 0; trial < 2000; trial++) {
        quat q = rnd_quat(&seed);
        vec3 c[8];
        for (int i = 0; i < 8; i++) c[i] = q_rotate(q, v3((i & 1) ? 1 : -1, (i & 2) ? 0.5 : -0.5, (i & 4) ? 2 : -2));
        int n = 0;
        for (int i = 0; i < 8; i++, n++) { pts[3 * n] = c[i].x; pts[3 * n + 1] = c[i].y; pts[3 * n + 2] = c[i].z; }
        for (; n < 38; n++) {
            /* edge e runs along axis e / 4 from the corner whose other two bits are e % 4 */
            int e = (int)(rnd(&seed) * 12), axis = e / 4, u = (axis + 1) % 3, w = (axis + 2) % 3;
            int from = ((e & 1) << u) | (((e & 2) >> 1) << w);
            vec3 p = v3_lerp(c[from], c[from | (1 << axis)], rnd(&seed));
            pts[3 * n] = p.x; pts[3 * n + 1] = p.y; pts[3 * n + 2] = p.z;
        }
        for (int i = n - 1; i > 0; i--) {
            int j = (int)(rnd(&seed) * (i + 1));
            for (int k = 0; k < 3; k++) { double t = pts[3 * i + k]; pts[3 * i + k] = pts[3 * j + k]; pts[3 * j + k] = t; }
        }
        hull *h = hull_build(pts, n, NULL, 0);
        assert_non_null(h);
        if (h->vertex_count != 8 || h->face_count != 6 || fabs(h->volume - 8) > 1e-12) {
            print_error("trial %d: %d vertices, %d faces, volume %.17g\n", trial, h->vertex_count, h->face_count, h->volume);
            fail();
        }
        hull_free(h);
    }
}

/* Random clouds, some flattened to near-coplanar (thickness 1e-12 on top of
 * a thin slab): always a valid hull, never a corrupted one. */
static void test_hull_random_and_nearly_degenerate(void **state)
{
    (void)state;
    static double pts[3 * 400];
    uint64_t seed = 17;
    for (int trial = 0; trial < 30; trial++) {
        int n = 20 + (int)(rnd(&seed) * 380);
        quat q = rnd_quat(&seed);
        for (int i = 0; i < n; i++) {
            vec3 p = v3(rnd(&seed), rnd(&seed), rnd(&seed));
            if (trial % 3 == 1) p.z = (i % 2) ? 0.1 : 0.1 + 1e-12 * rnd(&seed); /* a slab: top noisy below tolerance */
            if (trial % 3 == 2) p = v3_normalize(v3_sub(p, v3(0.5, 0.5, 0.5)));
            p = q_rotate(q, p);
            pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
        }
        if (trial % 3 == 1) { pts[2] = 0.0; } /* the slab's bottom point */
        char err[128] = "";
        hull *h = hull_build(pts, n, err, sizeof err);
        if (!h) print_error("trial %d: %s\n", trial, err);
        assert_non_null(h);
        check_hull(h, pts, n, trial);
        hull_free(h);
    }
}

static void test_degenerate_hulls_rejected(void **state)
{
    (void)state;
    char err[128];
    double flat[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.5, 0};
    assert_null(hull_build(flat, 5, err, sizeof err));
    assert_non_null(strstr(err, "coplanar"));
    /* off the plane by far less than the tolerance: still coplanar */
    double nearly[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.5, 1e-12};
    assert_null(hull_build(nearly, 5, err, sizeof err));
    assert_non_null(strstr(err, "coplanar"));
    double line[15] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, -1, -1, -1};
    assert_null(hull_build(line, 5, err, sizeof err));
    assert_non_null(strstr(err, "collinear"));
    double same[12] = {1, 2, 3, 1, 2, 3, 1, 2, 3, 1, 2, 3};
    assert_null(hull_build(same, 4, err, sizeof err));
    assert_non_null(strstr(err, "same point"));
    double bad[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN};
    assert_null(hull_build(bad, 4, err, sizeof err));
    assert_non_null(strstr(err, "finite"));
    bad[11] = INFINITY;
    assert_null(hull_build(bad, 4, err, sizeof err));
    assert_non_null(strstr(err, "finite"));
    assert_null(hull_build(flat, 3, err, sizeof err));
    assert_non_null(strstr(err, "at least 4"));
    assert_null(hull_build(NULL, 8, err, sizeof err));
    assert_non_null(strstr(err, "at least 4"));
    double huge[12] = {0, 0, 0, 1e60, 0, 0, 0, 1e60, 0, 0, 0, 1e60};
    assert_null(hull_build(huge, 4, err, sizeof err));
    assert_null(hull_build(flat, 5, NULL, 0)); /* no message buffer: still safe */
    hull_free(NULL);
    assert_null(hull_clone(NULL));
}

static void test_hull_clone(void **state)
{
    (void)state;
    double tet[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 0.2, 0.2};
    hull *h = hull_build(tet, 5, NULL, 0);
    assert_non_null(h);
    hull *c = hull_clone(h);
    assert_non_null(c);
    assert_true(c->vertices != h->vertices && c->faces != h->faces);
    assert_int_equal(c->vertex_count, h->vertex_count);
    assert_int_equal(c->face_count, h->face_count);
    assert_int_equal(c->edge_count, h->edge_count);
    assert_memory_equal(c->vertices, h->vertices, sizeof *h->vertices * (size_t)h->vertex_count);
    assert_memory_equal(c->faces, h->faces, sizeof *h->faces * (size_t)h->face_count);
    assert_memory_equal(c->edges, h->edges, sizeof *h->edges * (size_t)h->edge_count);
    int nfv = 0;
    for (int f = 0; f < h->face_count; f++) nfv += h->faces[f].count;
    assert_memory_equal(c->face_vertices, h->face_vertices, sizeof *h->face_vertices * (size_t)nfv);
    assert_true(c->volume == h->volume);
    hull_free(h);
    check_hull(c, tet, 5, 0); /* the copy stands alone */
    hull_free(c);
}

/* ---- bounds and support -------------------------------------------------------- */

/* A point of the shape (within tol)? */
static int inside(const shape *s, vec3 p, double tol)
{
    switch (s->type) {
    case SHAPE_SPHERE: return v3_len(p) <= s->radius + tol;
    case SHAPE_BOX:
        return fabs(p.x) <= s->half_extents.x + tol && fabs(p.y) <= s->half_extents.y + tol &&
               fabs(p.z) <= s->half_extents.z + tol;
    case SHAPE_CAPSULE: {
        double z = fmax(-s->half_height, fmin(s->half_height, p.z));
        return v3_len(v3_sub(p, v3(0, 0, z))) <= s->radius + tol;
    }
    case SHAPE_CYLINDER: return sqrt(p.x * p.x + p.y * p.y) <= s->radius + tol && fabs(p.z) <= s->half_height + tol;
    case SHAPE_HULL:
        for (int f = 0; f < s->hull->face_count; f++)
            if (v3_dot(s->hull->faces[f].normal, p) > s->hull->faces[f].offset + tol) return 0;
        return 1;
    default: return 0;
    }
}

/* Dense samples of each shape's surface, where its support points lie. */
static int surface_samples(const shape *s, vec3 *out, int max)
{
    int n = 0;
    switch (s->type) {
    case SHAPE_SPHERE:
    case SHAPE_CAPSULE: {
        static double dirs[3 * 4000];
        fibonacci_sphere(dirs, 4000);
        for (int i = 0; i < 4000 && n < max; i++) {
            vec3 d = pt(dirs, i);
            double zc = s->type == SHAPE_CAPSULE ? (d.z >= 0 ? s->half_height : -s->half_height) : 0;
            out[n++] = v3_add(v3(0, 0, zc), v3_scale(d, s->radius));
        }
        break;
    }
    case SHAPE_BOX:
        for (int i = 0; i < 8; i++)
            out[n++] = v3((i & 1) ? s->half_extents.x : -s->half_extents.x, (i & 2) ? s->half_extents.y : -s->half_extents.y,
                          (i & 4) ? s->half_extents.z : -s->half_extents.z);
        break;
    case SHAPE_CYLINDER:
        for (int i = 0; i < 2000 && n + 2 <= max; i++) {
            double a = 2 * PI_ * i / 2000;
            out[n++] = v3(s->radius * cos(a), s->radius * sin(a), s->half_height);
            out[n++] = v3(s->radius * cos(a), s->radius * sin(a), -s->half_height);
        }
        break;
    case SHAPE_HULL:
        for (int i = 0; i < s->hull->vertex_count; i++) out[n++] = s->hull->vertices[i];
        break;
    default: break;
    }
    return n;
}

static void test_support_against_brute_force(void **state)
{
    (void)state;
    static vec3 samples[4000];
    double ico_pts[3 * 60];
    fibonacci_sphere(ico_pts, 60);
    hull *h = hull_build(ico_pts, 60, NULL, 0);
    assert_non_null(h);
    shape shapes[5] = {sphere(0.4), box(0.2, 0.3, 0.5), capsule(0.2, 0.4), cylinder(0.35, 0.3), hull_shape(h)};
    uint64_t seed = 19;
    for (int k = 0; k < 5; k++) {
        const shape *s = &shapes[k];
        int n = surface_samples(s, samples, 4000);
        /* samples are a few thousand per sphere: the best of them falls short of the support by ~1e-3 r */
        double gap = (s->type == SHAPE_BOX || s->type == SHAPE_HULL) ? 1e-15 : 2e-3 * s->radius;
        for (int t = 0; t < 300; t++) {
            vec3 d = v3_scale(rnd_unit(&seed), 0.01 + 10 * rnd(&seed)); /* not unit */
            vec3 p = shape_support_local(s, d);
            assert_true(inside(s, p, 1e-12));
            double best = -INFINITY, got = v3_dot(p, d) / v3_len(d);
            for (int i = 0; i < n; i++) best = fmax(best, v3_dot(samples[i], d) / v3_len(d));
            if (!(got >= best - 1e-12 && got <= best + gap)) {
                print_error("shape %d direction %d: support %.17g brute force %.17g\n", k, t, got, best);
                fail();
            }
            /* the direction's length does not matter */
            check_vec(shape_support_local(s, v3_scale(d, 3.7)), p, 1e-15, "support scale invariant", k);
        }
        /* a zero direction still gives a point of the shape */
        vec3 z = shape_support_local(s, v3_zero());
        assert_true(v3_is_finite(z) && inside(s, z, 1e-12));
    }
    /* the box answers with a corner, the cylinder with a point on a rim */
    vec3 c = shape_support_local(&shapes[1], v3(1, -2, 0.5));
    check_vec(c, v3(0.2, -0.3, 0.5), 0, "box corner", 0);
    c = shape_support_local(&shapes[3], v3(3, 4, -1));
    check_vec(c, v3(0.35 * 0.6, 0.35 * 0.8, -0.3), 1e-15, "cylinder rim", 0);
    c = shape_support_local(&shapes[2], v3(0, 0, 5));
    check_vec(c, v3(0, 0, 0.6), 1e-15, "capsule tip", 0);
    hull_free(h);
}

static void test_bounds_contain_and_touch(void **state)
{
    (void)state;
    static vec3 samples[4000];
    double pts[18] = {0.3, 0, 0, -0.3, 0.1, 0, 0, 0.3, 0, 0, -0.3, 0.05, 0, 0, 0.4, 0.1, 0, -0.4};
    hull *h = hull_build(pts, 6, NULL, 0);
    assert_non_null(h);
    shape shapes[5] = {sphere(0.4), box(0.2, 0.3, 0.5), capsule(0.2, 0.4), cylinder(0.35, 0.3), hull_shape(h)};
    uint64_t seed = 23;
    for (int k = 0; k < 5; k++) {
        int n = surface_samples(&shapes[k], samples, 4000);
        for (int t = 0; t < 40; t++) {
            xform x = {v3(10 * rnd(&seed) - 5, 10 * rnd(&seed) - 5, 10 * rnd(&seed) - 5), rnd_quat(&seed)};
            if (t == 0) x.q = q_identity();
            aabb b = shape_aabb(&shapes[k], x);
            /* tight: the support along each world axis lies on that side of the box */
            for (int axis = 0; axis < 3; axis++)
                for (int sgn = -1; sgn <= 1; sgn += 2) {
                    vec3 d = v3(axis == 0 ? sgn : 0, axis == 1 ? sgn : 0, axis == 2 ? sgn : 0);
                    vec3 p = xf_point(x, shape_support_local(&shapes[k], q_inv_rotate(x.q, d)));
                    CHECK_CLOSE(v3_get(p, axis), v3_get(sgn > 0 ? b.hi : b.lo, axis), 1e-12, "bound touches the shape", k);
                }
            /* contains every surface sample */
            for (int i = 0; i < n; i++) {
                vec3 p = xf_point(x, samples[i]);
                assert_true(p.x >= b.lo.x - 1e-12 && p.x <= b.hi.x + 1e-12 && p.y >= b.lo.y - 1e-12 &&
                            p.y <= b.hi.y + 1e-12 && p.z >= b.lo.z - 1e-12 && p.z <= b.hi.z + 1e-12);
            }
        }
    }
    hull_free(h);
    /* cylinder standing up: exactly r sideways and h/2 up and down; lying along x: the reverse */
    shape cy = cylinder(0.5, 2.0);
    xform up = {v3(1, 2, 3), q_identity()};
    aabb b = shape_aabb(&cy, up);
    check_vec(b.lo, v3(0.5, 1.5, 1.0), 1e-15, "upright cylinder lo", 0);
    check_vec(b.hi, v3(1.5, 2.5, 5.0), 1e-15, "upright cylinder hi", 0);
    xform lying = {v3_zero(), q_axis_angle(v3(0, 1, 0), PI_ / 2)};
    b = shape_aabb(&cy, lying);
    check_vec(b.hi, v3(2.0, 0.5, 0.5), 1e-15, "lying cylinder hi", 0);
    /* a plane: huge, except on the solid side of an axis-aligned normal */
    shape ground = make(SHAPE_PLANE);
    ground.plane_normal = v3(0, 0, 1);
    b = shape_aabb(&ground, (xform){v3_zero(), q_identity()});
    check_vec(b.lo, v3(-1e18, -1e18, -1e18), 0, "plane lo", 0);
    check_vec(b.hi, v3(1e18, 1e18, 0), 0, "plane hi", 0);
    ground.plane_offset = 2;
    b = shape_aabb(&ground, (xform){v3(0, 0, 1), q_identity()});
    CHECK_CLOSE(b.hi.z, 3, 0, "raised plane", 0);
    /* turned a quarter about x, the normal points along -y: solid where y > -offset */
    b = shape_aabb(&ground, (xform){v3_zero(), q_axis_angle(v3(1, 0, 0), PI_ / 2)});
    CHECK_CLOSE(b.lo.y, -2, 1e-12, "turned plane", 0);
    assert_true(b.hi.y == 1e18 && b.hi.z == 1e18 && b.lo.z == -1e18);
    ground.plane_normal = v3_normalize(v3(1, 1, 1));
    b = shape_aabb(&ground, (xform){v3_zero(), q_identity()});
    check_vec(b.hi, v3(1e18, 1e18, 1e18), 0, "slanted plane", 0);
}

static void test_bounding_radius(void **state)
{
    (void)state;
    shape s = sphere(0.7), b = box(1, 2, 2), c = capsule(0.5, 1), y = cylinder(3, 4);
    CHECK_CLOSE(shape_bounding_radius(&s), 0.7, 0, "sphere", 0);
    CHECK_CLOSE(shape_bounding_radius(&b), 3, 1e-15, "box", 0);
    CHECK_CLOSE(shape_bounding_radius(&c), 1.5, 0, "capsule", 0);
    CHECK_CLOSE(shape_bounding_radius(&y), 5, 1e-15, "cylinder", 0);
    double tet[12] = {0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 1};
    hull *h = hull_build(tet, 4, NULL, 0);
    shape hs = hull_shape(h);
    CHECK_CLOSE(shape_bounding_radius(&hs), 3, 0, "hull", 0);
    hull_free(h);
}

/* ---- ray casts ------------------------------------------------------------------ */

static void check_hit(const shape *s, vec3 o, vec3 d, double max_t, double want_t, vec3 want_n, const char *what)
{
    double t = -1;
    vec3 n = v3_zero();
    if (!shape_ray_cast_local(s, o, d, max_t, &t, &n)) {
        print_error("%s: no hit\n", what);
        fail();
    }
    CHECK_CLOSE(t, want_t, 1e-12, what, 0);
    check_vec(n, want_n, 1e-12, what, 0);
}

static void check_miss(const shape *s, vec3 o, vec3 d, double max_t, const char *what)
{
    double t;
    vec3 n;
    if (shape_ray_cast_local(s, o, d, max_t, &t, &n)) {
        print_error("%s: unexpected hit at t = %g\n", what, t);
        fail();
    }
}

static void test_ray_casts(void **state)
{
    (void)state;
    shape s = sphere(1);
    check_hit(&s, v3(-3, 0, 0), v3(1, 0, 0), 10, 2, v3(-1, 0, 0), "sphere head on");
    check_hit(&s, v3(-3, 0, 0), v3(2, 0, 0), 10, 1, v3(-1, 0, 0), "sphere, direction not unit");
    check_hit(&s, v3(-3, 0.6, 0), v3(1, 0, 0), 10, 2.2, v3(-0.8, 0.6, 0), "sphere off centre");
    check_miss(&s, v3(0, 0, 0), v3(1, 0, 0), 10, "sphere from inside");
    check_miss(&s, v3(-0.5, 0, 0), v3(1, 0, 0), 10, "sphere from inside, towards the centre");
    check_miss(&s, v3(-3, 1.01, 0), v3(1, 0, 0), 10, "sphere passing by");
    check_miss(&s, v3(-3, 0, 0), v3(1, 0, 0), 1.9, "sphere beyond max_t");
    check_miss(&s, v3(-3, 0, 0), v3(-1, 0, 0), 10, "sphere behind");

    shape b = box(1, 2, 3);
    check_hit(&b, v3(0, 0, 10), v3(0, 0, -1), 100, 7, v3(0, 0, 1), "box top");
    check_hit(&b, v3(5, 1, 1), v3(-1, 0, 0), 100, 4, v3(1, 0, 0), "box side");
    check_hit(&b, v3(3, 3, 0), v3(-1, -1, 0), 100, 2, v3(1, 0, 0), "box slanted");
    check_hit(&b, v3(0, -6, 0), v3(0, 2, 0), 100, 2, v3(0, -1, 0), "box, direction not unit");
    check_miss(&b, v3(0, 0, 0), v3(1, 0, 0), 100, "box from inside");
    check_miss(&b, v3(5, 2.5, 0), v3(-1, 0, 0), 100, "box parallel, outside");
    check_miss(&b, v3(0, 0, 10), v3(0, 0, -1), 6.9, "box beyond max_t");

    shape c = capsule(0.5, 1);
    check_hit(&c, v3(0, 0, 5), v3(0, 0, -1), 100, 3.5, v3(0, 0, 1), "capsule tip");
    check_hit(&c, v3(3, 0, 0.5), v3(-1, 0, 0), 100, 2.5, v3(1, 0, 0), "capsule side");
    /* into the top hemisphere at x = 0.3: z = 1 + sqrt(0.25 - 0.09) = 1.4 */
    check_hit(&c, v3(0.3, 0, 5), v3(0, 0, -1), 100, 3.6, v3(0.6, 0, 0.8), "capsule cap off axis");
    check_hit(&c, v3(0, 0, -4), v3(0, 0, 1), 100, 2.5, v3(0, 0, -1), "capsule bottom");
    check_miss(&c, v3(0, 0.2, 1.2), v3(0, 0, 1), 100, "capsule from inside the cap");
    check_miss(&c, v3(0.51, 0, 5), v3(0, 0, -1), 100, "capsule passing by");

    shape y = cylinder(0.5, 1);
    check_hit(&y, v3(0.2, 0, 5), v3(0, 0, -1), 100, 4, v3(0, 0, 1), "cylinder cap");
    check_hit(&y, v3(0.2, 0, -5), v3(0, 0, 1), 100, 4, v3(0, 0, -1), "cylinder bottom cap");
    check_hit(&y, v3(3, 0, 0.5), v3(-1, 0, 0), 100, 2.5, v3(1, 0, 0), "cylinder side");
    /* x = 2 - t, z = 1.5 - t: passes the cap plane at x = 1.5 (off the cap), meets the side at t = 1.5 */
    check_hit(&y, v3(2, 0, 1.5), v3(-1, 0, -1), 100, 1.5, v3(1, 0, 0), "cylinder slanted onto the side");
    check_miss(&y, v3(0.6, 0, 5), v3(0, 0, -1), 100, "cylinder passing the rim");
    check_miss(&y, v3(0, 0, 0.9), v3(0, 0, 1), 100, "cylinder from inside");

    double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    shape h = hull_shape(hull_build(tet, 4, NULL, 0));
    double r3 = 1 / sqrt(3.0);
    /* (1,1,1) - t (1,1,1) meets x + y + z = 1 at t = 2/3 */
    check_hit(&h, v3(1, 1, 1), v3(-1, -1, -1), 10, 2.0 / 3.0, v3(r3, r3, r3), "hull slanted face");
    check_hit(&h, v3(0.2, 0.2, -1), v3(0, 0, 1), 10, 1, v3(0, 0, -1), "hull bottom face");
    check_miss(&h, v3(0.1, 0.1, 0.1), v3(1, 0, 0), 10, "hull from inside");
    check_miss(&h, v3(0.6, 0.6, -1), v3(0, 0, 1), 10, "hull passing by");
    hull_free(h.hull);
    /* a box hull and the box agree */
    shape bh = hull_shape(hull_make_box(v3(1, 2, 3)));
    uint64_t seed = 29;
    for (int i = 0; i < 200; i++) {
        vec3 o = v3_scale(rnd_unit(&seed), 6), d = v3_sub(v3(2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1), o);
        double t1 = -1, t2 = -2;
        vec3 n1, n2;
        int hit1 = shape_ray_cast_local(&b, o, d, 1, &t1, &n1), hit2 = shape_ray_cast_local(&bh, o, d, 1, &t2, &n2);
        assert_int_equal(hit1, hit2);
        if (hit1) {
            CHECK_CLOSE(t1, t2, 1e-12, "box hull t", i);
            check_vec(n1, n2, 1e-12, "box hull normal", i);
        }
    }
    hull_free(bh.hull);

    shape p = make(SHAPE_PLANE);
    p.plane_normal = v3(0, 0, 1);
    p.plane_offset = 2;
    check_hit(&p, v3(0, 0, 5), v3(0, 0, -2), 10, 1.5, v3(0, 0, 1), "plane");
    check_hit(&p, v3(1, 1, 3), v3(1, 0, -1), 10, 1, v3(0, 0, 1), "plane slanted");
    check_miss(&p, v3(0, 0, 1), v3(0, 0, -1), 10, "plane from inside the solid");
    check_miss(&p, v3(0, 0, 5), v3(0, 0, 1), 10, "plane moving away");
    check_miss(&p, v3(0, 0, 5), v3(1, 0, 0), 10, "plane parallel");
    check_miss(&p, v3(0, 0, 5), v3(0, 0, -1), 2.9, "plane beyond max_t");
}

/* ---- carom_shape_def_check: the rules body_create applies, alone ---------------- */

/* For each def and body type: the check agrees with carom_body_create, an
 * accepted def leaves msg empty, a refused one names the bad value. */
static void test_shape_def_check(void **state)
{
    (void)state;
    static const double tetra[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const double far_tetra[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 2e6};
    struct { carom_shape_def def; int ok_static, ok_dynamic; const char *text; } cases[] = {
        {carom_shape_sphere(0.5), 1, 1, ""},
        {carom_shape_sphere(-1), 0, 0, "sphere radius -1 is outside"},
        {carom_shape_sphere(0), 0, 0, "sphere radius 0 is outside"},
        {carom_shape_sphere(2e6), 0, 0, "sphere radius 2e+06 is outside"},
        {carom_shape_box(1, 1, 1), 1, 1, ""},
        {carom_shape_box(1, -1, 1), 0, 0, "box half extents (1, -1, 1)"},
        {carom_shape_capsule(0.5, -1), 0, 0, "capsule half_height -1"},
        {carom_shape_cylinder(0, 1), 0, 0, "cylinder radius 0"},
        {carom_shape_hull(tetra, 4), 1, 1, ""},
        {carom_shape_hull(tetra, 3), 0, 0, "a hull needs 4..100000 points (got 3)"},
        {carom_shape_hull(far_tetra, 4), 0, 0, "hull point 3 has coordinate 2e+06"},
        {carom_shape_plane(0, 0, 1, 0), 1, 0, "a plane can only be a static body"},
        {carom_shape_plane(0, 0, 0, 0), 0, 0, "plane normal must be finite"},
        {carom_shape_plane(0, 0, 1, 1e13), 0, 0, "plane offset 1e+13 is outside"},
    };
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        for (int dynamic = 0; dynamic < 2; dynamic++) {
            carom_body_type type = dynamic ? CAROM_BODY_DYNAMIC : CAROM_BODY_STATIC;
            int want = dynamic ? cases[i].ok_dynamic : cases[i].ok_static;
            char msg[256] = "untouched";
            carom_status st = carom_shape_def_check(&cases[i].def, type, msg, sizeof msg);
            assert_int_equal(st, want ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT);
            if (want) assert_string_equal(msg, "");
            else if (dynamic == cases[i].ok_static) assert_non_null(strstr(msg, cases[i].text)); /* the text: static's, or dynamic's where static is fine */
            /* body_create applies the same rules */
            carom_body_def bd = carom_body_def_default();
            bd.type = type;
            bd.shape = cases[i].def;
            carom_body_id id = carom_body_create(w, &bd);
            assert_int_equal(carom_body_is_valid(w, id), want);
        }
    }
    char msg[64];
    assert_int_equal(carom_shape_def_check(NULL, CAROM_BODY_STATIC, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "shape is NULL"));
    carom_shape_def s = carom_shape_sphere(1);
    assert_int_equal(carom_shape_def_check(&s, (carom_body_type)7, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_shape_def_check(&s, CAROM_BODY_KINEMATIC, NULL, 0), CAROM_OK);
    carom_world_destroy(w);
}

/* ---- carom_mesh_def_check, carom_heightfield_def_check, carom_compound_check ---- */

/* A static body with this data is created exactly when the check accepts it
 * (create_ok: what body_create says, for the one documented difference); a
 * refusal names the bad field. */
static void expect_data(carom_world *w, carom_status st, const char *msg, carom_body_def *bd, int check_ok, int create_ok,
                        const char *words)
{
    assert_int_equal(st, check_ok ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT);
    if (check_ok) assert_string_equal(msg, "");
    else if (!strstr(msg, words)) fail_msg("message '%s' lacks '%s'", msg, words);
    int before = carom_world_body_count(w);
    carom_body_id id = carom_body_create(w, bd);
    assert_int_equal(carom_body_is_valid(w, id), create_ok);
    assert_int_equal(carom_world_body_count(w), before + create_ok);
    if (!create_ok && !check_ok) assert_non_null(strstr(carom_world_last_error_reason(w), msg)); /* the same reason */
}

static void test_data_checks(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    char msg[256];
    /* meshes */
    double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0};
    double bad_v[] = {0, 0, 0, 1, 0, 0, 2e6, 1, 0};
    int ok_t[] = {0, 1, 2}, out_t[] = {0, 1, 3}, rep_t[] = {0, 2, 2}, flat_t[] = {0, 1, 3};
    struct { const double *v; int nv; const int *t; int nt; int check_ok, create_ok; const char *words; } meshes[] = {
        {v, 3, ok_t, 1, 1, 1, ""},
        {v, 2, ok_t, 1, 0, 0, "vertices: need at least 3"},
        {v, 3, ok_t, 0, 0, 0, "triangles: need at least 1"},
        {bad_v, 3, ok_t, 1, 0, 0, "vertices[2]: coordinates must be finite (within 1e6 m; vertex 3 counting from 1)"},
        {v, 3, out_t, 1, 0, 0, "vertex index 3 out of range"},
        {v, 3, rep_t, 1, 0, 0, "triangles[0]: repeats vertex 2 (triangle 1, vertex 3 counting from 1)"},
        {v, 4, flat_t, 1, 1, 0, ""}, /* only zero-area triangles: body_create refuses it */
    };
    for (size_t i = 0; i < sizeof meshes / sizeof meshes[0]; i++) {
        carom_mesh_def md = carom_mesh_def_default();
        md.vertices = meshes[i].v; md.vertex_count = meshes[i].nv;
        md.triangles = meshes[i].t; md.triangle_count = meshes[i].nt;
        carom_body_def bd = carom_body_def_default();
        bd.type = CAROM_BODY_STATIC;
        bd.shape.type = CAROM_SHAPE_MESH;
        bd.mesh = &md;
        strcpy(msg, "untouched");
        carom_status st = carom_mesh_def_check(&md, msg, sizeof msg);
        expect_data(w, st, msg, &bd, meshes[i].check_ok, meshes[i].create_ok, meshes[i].words);
    }
    assert_int_equal(carom_mesh_def_check(NULL, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "NULL"));
    carom_mesh_def small = carom_mesh_def_default();
    small.size = 8;
    assert_int_equal(carom_mesh_def_check(&small, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
    /* height fields */
    double h[] = {0, 0.5, 1, 0, 0, 0}, bad_h[] = {0, 0, 1.0 / 0.0, 0, 0, 0};
    int hole_ok[] = {1}, hole_out[] = {2};
    struct { const double *h; int rows, cols; double cx; const int *holes; int nh; int ok; const char *words; } fields[] = {
        {h, 2, 3, 1.0, NULL, 0, 1, ""},
        {h, 2, 3, 1.0, hole_ok, 1, 1, ""},
        {h, 1, 6, 1.0, NULL, 0, 0, "need at least 2 each (got 1 x 6)"},
        {h, 2, 3, 0.0, NULL, 0, 0, "cell: sizes must be in [1e-6, 1e6] m"},
        {bad_h, 2, 3, 1.0, NULL, 0, 0, "heights[2]: must be finite (within 1e6 m; height 3 counting from 1)"},
        {h, 2, 3, 1.0, hole_out, 1, 0, "holes[0]: cell 2 out of range 0..1"},
    };
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        carom_heightfield_def hd = carom_heightfield_def_default();
        hd.heights = fields[i].h; hd.rows = fields[i].rows; hd.columns = fields[i].cols;
        hd.cell_x = fields[i].cx; hd.holes = fields[i].holes; hd.hole_count = fields[i].nh;
        carom_body_def bd = carom_body_def_default();
        bd.type = CAROM_BODY_STATIC;
        bd.shape.type = CAROM_SHAPE_HEIGHTFIELD;
        bd.heightfield = &hd;
        strcpy(msg, "untouched");
        carom_status st = carom_heightfield_def_check(&hd, msg, sizeof msg);
        expect_data(w, st, msg, &bd, fields[i].ok, fields[i].ok, fields[i].words);
    }
    assert_int_equal(carom_heightfield_def_check(NULL, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
    /* compounds: the second child carries the fault, named by both numberings */
    struct { int field; double value; int ok; const char *words; } kids[] = {
        {0, 0, 1, ""},
        {1, -1, 0, "children[1].friction must be in [0, 1e3] (child 2 counting from 1)"},
        {2, 1.5, 0, "children[1].restitution must be in [0, 1]"},
        {3, 0, 0, "children[1].density must be in [1e-6, 1e9] kg/m^3"},
        {4, 2e6, 0, "children[1].position must be finite (within 1e6 m)"},
        {5, -1, 0, "children[1]: sphere radius -1 is outside"},
        {6, 0, 0, "children[1].shape must be convex"},
    };
    for (size_t i = 0; i < sizeof kids / sizeof kids[0]; i++) {
        carom_compound_child c[2] = {carom_compound_child_default(carom_shape_box(0.5, 0.5, 0.5)),
                                     carom_compound_child_default(carom_shape_sphere(0.25))};
        c[1].position = vec(1, 0, 0);
        switch (kids[i].field) {
        case 1: c[1].friction = kids[i].value; break;
        case 2: c[1].restitution = kids[i].value; break;
        case 3: c[1].density = kids[i].value; break;
        case 4: c[1].position.x = kids[i].value; break;
        case 5: c[1].shape = carom_shape_sphere(kids[i].value); break;
        case 6: c[1].shape = carom_shape_plane(0, 0, 1, 0); break;
        default: break;
        }
        carom_body_def bd = carom_body_def_default();
        bd.shape.type = CAROM_SHAPE_COMPOUND;
        bd.children = c;
        bd.child_count = 2;
        strcpy(msg, "untouched");
        carom_status st = carom_compound_check(c, 2, msg, sizeof msg);
        expect_data(w, st, msg, &bd, kids[i].ok, kids[i].ok, kids[i].words);
    }
    carom_compound_child one = carom_compound_child_default(carom_shape_sphere(1));
    assert_int_equal(carom_compound_check(&one, 0, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "a compound needs children (got 0)"));
    assert_int_equal(carom_compound_check(NULL, 1, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_and_box_mass),
        cmocka_unit_test(test_capsule_and_cylinder_mass),
        cmocka_unit_test(test_plane_has_no_mass),
        cmocka_unit_test(test_hull_of_box_corners_is_the_box),
        cmocka_unit_test(test_offset_rotated_hull),
        cmocka_unit_test(test_hull_of_tetrahedra),
        cmocka_unit_test(test_hull_of_square_pyramid),
        cmocka_unit_test(test_hull_of_sphere_points),
        cmocka_unit_test(test_inertia_symmetric_positive_definite),
        cmocka_unit_test(test_hull_topology_of_known_solids),
        cmocka_unit_test(test_hull_of_sampled_solids),
        cmocka_unit_test(test_hull_of_boxes_with_edge_points),
        cmocka_unit_test(test_hull_random_and_nearly_degenerate),
        cmocka_unit_test(test_degenerate_hulls_rejected),
        cmocka_unit_test(test_hull_clone),
        cmocka_unit_test(test_support_against_brute_force),
        cmocka_unit_test(test_bounds_contain_and_touch),
        cmocka_unit_test(test_bounding_radius),
        cmocka_unit_test(test_ray_casts),
        cmocka_unit_test(test_shape_def_check),
        cmocka_unit_test(test_data_checks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
