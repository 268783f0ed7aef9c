/* test_shape.c - shapes against closed forms: mass properties of every
 * shape, hull construction (topology, rejection of degenerate input), bounds
 * that contain and touch the shape, support points, and ray casts. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "shape.h"

#define PI 3.14159265358979323846

static void close_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want) + 1e-15)) {
        print_error("%s: got %.15g expected %.15g\n", what, got, want);
        fail();
    }
}

static shape make(int type)
{
    shape s;
    memset(&s, 0, sizeof s);
    s.type = type;
    return s;
}

static double rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static void test_capsule_and_cylinder_mass(void **state)
{
    (void)state;
    shape c = make(SHAPE_CAPSULE);
    c.radius = 0.3;
    c.half_height = 0.5;
    double r = 0.3, h = 1.0, m = 2.0;
    mass_props mp = shape_mass_from_mass(&c, m);
    /* cylinder part and two hemispheres, by volume share */
    double vc = PI * r * r * h, vs = 4.0 / 3.0 * PI * r * r * r, mc = m * vc / (vc + vs), ms = m * vs / (vc + vs);
    close_rel(mp.inertia.c2.z, mc * r * r / 2 + 2.0 / 5.0 * ms * r * r, 1e-12, "capsule Izz");
    double ixx = mc * (3 * r * r + h * h) / 12 + ms * (2.0 / 5.0 * r * r + h * h / 4 + 3.0 * h * r / 8);
    close_rel(mp.inertia.c0.x, ixx, 1e-12, "capsule Ixx (hemispheres by the parallel axis theorem)");
    close_rel(shape_volume(&c), vc + vs, 1e-14, "capsule volume");
    shape y = make(SHAPE_CYLINDER);
    y.radius = 0.5;
    y.half_height = 0.25;
    mass_props my = shape_mass_from_density(&y, 1000);
    close_rel(my.mass, 1000 * PI * 0.25 * 0.5, 1e-14, "cylinder mass from density");
    close_rel(my.inertia.c0.x, my.mass * (3 * 0.25 + 0.25) / 12, 1e-12, "cylinder Ixx");
}

static void test_hull_of_cube_and_tetrahedron(void **state)
{
    (void)state;
    double cube[24];
    for (int i = 0; i < 8; i++) {
        cube[3 * i] = (i & 1) ? 1 : -1;
        cube[3 * i + 1] = (i & 2) ? 1 : -1;
        cube[3 * i + 2] = (i & 4) ? 1 : -1;
    }
    hull *h = hull_build(cube, 8, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 8);
    assert_int_equal(h->face_count, 6); /* coplanar triangles merged into quads */
    assert_int_equal(h->edge_count, 12);
    close_rel(h->volume, 8, 1e-14, "cube volume");
    assert_true(v3_len(h->centroid) < 1e-14);
    close_rel(h->unit_inertia.c0.x, 8 * (4 + 4) / 12.0, 1e-12, "cube inertia");
    for (int f = 0; f < h->face_count; f++) assert_int_equal(h->faces[f].count, 4);
    hull_free(h);
    /* interior points and duplicates change nothing */
    double many[3 * 108];
    memcpy(many, cube, sizeof cube);
    uint64_t s = 3;
    for (int i = 8; i < 108; i++)
        for (int c = 0; c < 3; c++) many[3 * i + c] = i < 100 ? 1.98 * rnd(&s) - 0.99 : cube[3 * (i - 100) + c];
    h = hull_build(many, 108, NULL, 0);
    assert_non_null(h);
    assert_int_equal(h->vertex_count, 8);
    close_rel(h->volume, 8, 1e-12, "cube with interior points");
    hull_free(h);
    /* a corner tetrahedron: volume 1/6, centroid (1/4, 1/4, 1/4) */
    double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    h = hull_build(tet, 4, NULL, 0);
    assert_non_null(h);
    close_rel(h->volume, 1.0 / 6.0, 1e-14, "tetrahedron volume");
    close_rel(h->centroid.x, 0.25, 1e-14, "tetrahedron centroid");
    /* about the corner: int x^2 dV = 1/60, int x y dV = 1/120 (unit legs, density 1),
     * so Ixx = 1/30 and Ixy = -1/120; moved to the centroid by the parallel axis theorem */
    double m = 1.0 / 6.0;
    close_rel(h->unit_inertia.c0.x, 1.0 / 30.0 - m * (0.0625 + 0.0625), 1e-12, "tetrahedron Ixx about its centroid");
    close_rel(h->unit_inertia.c1.x, -(1.0 / 120.0 - m * 0.0625), 1e-12, "tetrahedron product of inertia");
    /* Euler: V - E + F = 2 */
    assert_int_equal(h->vertex_count - h->edge_count + h->face_count, 2);
    hull_free(h);
}

static void test_hull_of_sphere_points(void **state)
{
    (void)state;
    enum { N = 400 };
    double pts[3 * N];
    uint64_t s = 11;
    for (int i = 0; i < N; i++) {
        vec3 d = v3_normalize(v3(rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5));
        pts[3 * i] = d.x; pts[3 * i + 1] = d.y; pts[3 * i + 2] = d.z;
    }
    hull *h = hull_build(pts, N, NULL, 0);
    assert_non_null(h);
    assert_true(h->volume < 4.0 / 3.0 * PI && h->volume > 0.95 * 4.0 / 3.0 * PI);
    assert_int_equal(h->vertex_count - h->edge_count + h->face_count, 2);
    /* every input point lies inside every face plane */
    for (int f = 0; f < h->face_count; f++)
        for (int i = 0; i < N; i++)
            assert_true(v3_dot(h->faces[f].normal, v3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2])) <= h->faces[f].offset + 1e-9);
    hull_free(h);
}

static void test_degenerate_hulls_rejected(void **state)
{
    (void)state;
    char err[128];
    double flat[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.5, 0};
    assert_null(hull_build(flat, 5, err, sizeof err));
    assert_non_null(strstr(err, "coplanar"));
    double line[12] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
    assert_null(hull_build(line, 4, err, sizeof err));
    assert_non_null(strstr(err, "collinear"));
    double same[12] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    assert_null(hull_build(same, 4, err, sizeof err));
    double bad[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN};
    assert_null(hull_build(bad, 4, err, sizeof err));
    assert_non_null(strstr(err, "finite"));
    assert_null(hull_build(flat, 3, err, sizeof err));
}

/* Bounds contain random support points and each side is touched by one. */
static void test_bounds_and_support(void **state)
{
    (void)state;
    double pts[18] = {0.3, 0, 0, -0.3, 0.1, 0, 0, 0.3, 0, 0, -0.3, 0.05, 0, 0, 0.4, 0.1, 0, -0.4};
    shape shapes[5] = {make(SHAPE_SPHERE), make(SHAPE_BOX), make(SHAPE_CAPSULE), make(SHAPE_CYLINDER), make(SHAPE_HULL)};
    shapes[0].radius = 0.4;
    shapes[1].half_extents = v3(0.2, 0.3, 0.5);
    shapes[2].radius = 0.2; shapes[2].half_height = 0.4;
    shapes[3].radius = 0.35; shapes[3].half_height = 0.3;
    shapes[4].hull = hull_build(pts, 6, NULL, 0);
    uint64_t s = 17;
    for (int k = 0; k < 5; k++)
        for (int t = 0; t < 200; t++) {
            xform x = {v3(rnd(&s), rnd(&s), rnd(&s)), q_normalize((quat){rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5})};
            aabb b = shape_aabb(&shapes[k], x);
            double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
            for (int axis = 0; axis < 3; axis++)
                for (int sgn = -1; sgn <= 1; sgn += 2) {
                    vec3 d = v3(axis == 0 ? sgn : 0, axis == 1 ? sgn : 0, axis == 2 ? sgn : 0);
                    vec3 p = xf_point(x, shape_support_local(&shapes[k], q_inv_rotate(x.q, d)));
                    double c = v3_get(p, axis);
                    /* the support along each axis lies on that side of the box: tight */
                    assert_true(fabs(c - (sgn > 0 ? hi[axis] : lo[axis])) < 1e-9);
                }
            for (int i = 0; i < 20; i++) {
                vec3 d = v3(rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5);
                vec3 p = xf_point(x, shape_support_local(&shapes[k], d));
                assert_true(p.x >= b.lo.x - 1e-9 && p.x <= b.hi.x + 1e-9 && p.y >= b.lo.y - 1e-9 &&
                            p.y <= b.hi.y + 1e-9 && p.z >= b.lo.z - 1e-9 && p.z <= b.hi.z + 1e-9);
            }
        }
    hull_free(shapes[4].hull);
}

static void test_ray_casts(void **state)
{
    (void)state;
    double t;
    vec3 n;
    shape s = make(SHAPE_SPHERE);
    s.radius = 1;
    assert_true(shape_ray_cast_local(&s, v3(-3, 0, 0), v3(1, 0, 0), 10, &t, &n));
    close_rel(t, 2, 1e-14, "sphere t");
    assert_true(n.x == -1);
    assert_false(shape_ray_cast_local(&s, v3(0, 0, 0), v3(1, 0, 0), 10, &t, &n)); /* from inside */
    assert_false(shape_ray_cast_local(&s, v3(-3, 2, 0), v3(1, 0, 0), 10, &t, &n)); /* miss */
    shape b = make(SHAPE_BOX);
    b.half_extents = v3(1, 2, 3);
    assert_true(shape_ray_cast_local(&b, v3(0, 0, 10), v3(0, 0, -1), 100, &t, &n));
    close_rel(t, 7, 1e-14, "box t");
    assert_true(n.z == 1);
    shape c = make(SHAPE_CAPSULE);
    c.radius = 0.5; c.half_height = 1;
    assert_true(shape_ray_cast_local(&c, v3(0, 0, 5), v3(0, 0, -1), 100, &t, &n));
    close_rel(t, 3.5, 1e-14, "capsule cap t");
    assert_true(shape_ray_cast_local(&c, v3(3, 0, 0.5), v3(-1, 0, 0), 100, &t, &n));
    close_rel(t, 2.5, 1e-14, "capsule side t");
    shape y = make(SHAPE_CYLINDER);
    y.radius = 0.5; y.half_height = 1;
    assert_true(shape_ray_cast_local(&y, v3(0.2, 0, 5), v3(0, 0, -1), 100, &t, &n));
    close_rel(t, 4, 1e-14, "cylinder cap t");
    assert_true(n.z == 1);
    double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    shape h = make(SHAPE_HULL);
    h.hull = hull_build(tet, 4, NULL, 0);
    assert_true(shape_ray_cast_local(&h, v3(1, 1, 1), v3(-1, -1, -1), 10, &t, &n));
    close_rel(t, 2.0 / 3.0, 1e-12, "hull slanted face t");
    close_rel(n.x, 1 / sqrt(3.0), 1e-12, "hull face normal");
    hull_free(h.hull);
    shape p = make(SHAPE_PLANE);
    p.plane_normal = v3(0, 0, 1);
    assert_true(shape_ray_cast_local(&p, v3(0, 0, 2), v3(0, 0, -1), 10, &t, &n));
    close_rel(t, 2, 1e-14, "plane t");
    assert_false(shape_ray_cast_local(&p, v3(0, 0, 2), v3(0, 0, 1), 10, &t, &n));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_capsule_and_cylinder_mass),
        cmocka_unit_test(test_hull_of_cube_and_tetrahedron),
        cmocka_unit_test(test_hull_of_sphere_points),
        cmocka_unit_test(test_degenerate_hulls_rejected),
        cmocka_unit_test(test_bounds_and_support),
        cmocka_unit_test(test_ray_casts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
