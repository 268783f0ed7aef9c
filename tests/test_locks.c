/* test_locks.c - plane-locked bodies respond as the reduced system: a body
 * kept in a plane with normal n turns about n only, so a torque impulse T
 * gives it w = n (n.T) / (n.I n) exactly (not the free response I^-1 T
 * projected onto n), and its motion across the plane and its spin about any
 * other axis stay exactly zero, step after step. */
#include <stdarg.h>
#include <stdlib.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"

static carom_vec3 vec(double x, double y, double z) { carom_vec3 v = {x, y, z}; return v; }
static double dot(carom_vec3 a, carom_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static carom_vec3 cross(carom_vec3 a, carom_vec3 b)
{
    return vec(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

/* Rotates v by unit quaternion q. */
static carom_vec3 rotate(carom_quat q, carom_vec3 v)
{
    carom_vec3 u = vec(q.x, q.y, q.z);
    carom_vec3 t = cross(u, v);
    t = vec(2 * t.x, 2 * t.y, 2 * t.z);
    carom_vec3 c = cross(u, t);
    return vec(v.x + q.w * t.x + c.x, v.y + q.w * t.y + c.y, v.z + q.w * t.z + c.z);
}

/* n.I n for a box of mass m and half extents h at orientation q:
 * I = diag(m/3 (hy^2 + hz^2), ...) in body axes. */
static double box_inertia_about(double m, carom_vec3 h, carom_quat q, carom_vec3 n)
{
    carom_quat qc = {q.w, -q.x, -q.y, -q.z};
    carom_vec3 b = rotate(qc, n);
    double ix = m / 3 * (h.y * h.y + h.z * h.z), iy = m / 3 * (h.x * h.x + h.z * h.z), iz = m / 3 * (h.x * h.x + h.y * h.y);
    return ix * b.x * b.x + iy * b.y * b.y + iz * b.z * b.z;
}

/* A box turned 20 degrees about (1,1,1), locked to a plane, given a couple
 * (two opposite impulses) of moment T: w = n (n.T)/(n.I n) to 1e-12, for
 * several planes and couples, far from the origin too; then 60 steps in
 * zero gravity keep the spin (free rotation about n) and zero motion across
 * the plane exactly. */
static void test_plane_lock_reduced_response(void **state)
{
    (void)state;
    const carom_vec3 normals[] = {{0, 1, 0}, {0, 0, 1}, {1, 2, 2}};
    const carom_vec3 moments[] = {{1, 0, 0}, {1, 1, 0}, {0.3, -2, 0.7}};
    const double offsets[] = {0, 1e5};
    double a = 20.0 * 3.14159265358979323846 / 180.0, s = sin(a / 2) / sqrt(3.0);
    carom_quat q = {cos(a / 2), s, s, s};
    carom_vec3 h = vec(0.5, 0.3, 0.2);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            for (int o = 0; o < 2; o++) {
                carom_world_def wd = carom_world_def_default();
                wd.gravity = vec(0, 0, 0);
                carom_world *w = carom_world_create(&wd);
                assert_non_null(w);
                carom_body_def d = carom_body_def_default();
                d.shape = carom_shape_box(h.x, h.y, h.z);
                d.mass = 2.0;
                d.orientation = q;
                d.position = vec(offsets[o], 0, 0);
                d.lock_to_plane = 1;
                d.plane_normal = normals[i];
                carom_body_id id = carom_body_create(w, &d);
                assert_false(carom_body_id_is_null(id));
                double len = sqrt(dot(normals[i], normals[i]));
                carom_vec3 n = vec(normals[i].x / len, normals[i].y / len, normals[i].z / len);
                /* a couple of moment T: impulses +j at c + r and -j at c - r with 2 r x j = T;
                 * take r along n x T's perpendicular: r = (T x u)/(2|u|^2)... simply pick
                 * r perpendicular to T and j = (T x r)/(2 |r|^2) */
                carom_vec3 T = moments[k];
                carom_vec3 r = cross(T, vec(0.3, 0.5, 0.7));
                double rl = sqrt(dot(r, r));
                r = vec(0.1 * r.x / rl, 0.1 * r.y / rl, 0.1 * r.z / rl);
                carom_vec3 j = cross(r, T);
                double f = 1.0 / (2.0 * dot(r, r));
                j = vec(-j.x * f, -j.y * f, -j.z * f); /* 2 r x j = T */
                carom_vec3 c;
                assert_int_equal(carom_body_get_center_of_mass(w, id, &c), CAROM_OK);
                carom_vec3 p1 = vec(c.x + r.x, c.y + r.y, c.z + r.z), p2 = vec(c.x - r.x, c.y - r.y, c.z - r.z);
                carom_vec3 mj = vec(-j.x, -j.y, -j.z);
                assert_int_equal(carom_body_apply_impulse(w, id, j, &p1), CAROM_OK);
                assert_int_equal(carom_body_apply_impulse(w, id, mj, &p2), CAROM_OK);
                double want = dot(n, T) / box_inertia_about(2.0, h, q, n);
                carom_vec3 av, v;
                assert_int_equal(carom_body_get_angular_velocity(w, id, &av), CAROM_OK);
                assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
                double got = dot(av, n);
                carom_vec3 off = vec(av.x - got * n.x, av.y - got * n.y, av.z - got * n.z);
                print_message("n %d T %d: w.n %.15f (closed form %.15f), off-axis %.1e\n", i, k, got, want,
                              sqrt(dot(off, off)));
                /* the application points c +- r themselves carry rounding |c| eps: the
                 * couple is known to |c| eps / |r| relative */
                double tol = (1e-12 + 4.0 * 2.2e-16 * (1.0 + fabs(offsets[o])) / 0.1) * (1 + fabs(want));
                assert_true(fabs(got - want) <= tol);
                assert_true(sqrt(dot(off, off)) <= 1e-15 * (1 + fabs(want)));
                assert_true(fabs(dot(v, n)) <= 1e-15);
                double plane = dot(n, c);
                for (int st = 0; st < 60; st++) {
                    assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
                    assert_int_equal(carom_body_get_angular_velocity(w, id, &av), CAROM_OK);
                    assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
                    assert_int_equal(carom_body_get_center_of_mass(w, id, &c), CAROM_OK);
                    double spin = dot(av, n);
                    off = vec(av.x - spin * n.x, av.y - spin * n.y, av.z - spin * n.z);
                    assert_true(sqrt(dot(off, off)) <= 1e-15 * (1 + fabs(want)));
                    assert_true(fabs(dot(v, n)) <= 1e-12);
                    assert_true(fabs(dot(n, c) - plane) <= 1e-9 * (1 + fabs(plane)));
                    /* free rotation about n: the spin is kept */
                    assert_true(fabs(spin - want) <= tol);
                }
                carom_world_destroy(w);
            }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_lock_reduced_response),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
