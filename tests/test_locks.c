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
#include "helpers.h"

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

/* A box kept in the plane z = its start, sunk 2 % of its size into the
 * ground (contact normal = plane normal): it cannot move along the normal,
 * so nothing can push it out; its effective
 * mass there is infinite, the contact gets no normal impulse and friction
 * (mu N = 0) leaves its free spin exactly as it was: w_z = 2.5 after every
 * step, for sizes, masses, time steps, presets and far from the origin. */
static void test_plane_lock_contact_normal_along_lock(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    const double sizes[] = {0.1, 0.5, 2.0}, masses[] = {1.0, 50.0}, dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 1000};
    const double offsets[] = {0, 1e5};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 3; k++)
            for (int o = 0; o < 2; o++) {
                double he = sizes[k], mass = masses[(p + k) % 2], dt = dts[(p + 2 * k + o) % 3], x0 = offsets[o];
                carom_world_def wd = carom_world_def_default();
                assert_int_equal(carom_world_def_apply_preset(&wd, presets[p]), CAROM_OK);
                wd.enable_sleep = 0;
                carom_world *w = carom_world_create(&wd);
                assert_non_null(w);
                carom_body_def g = carom_body_def_default();
                g.type = CAROM_BODY_STATIC;
                g.shape = carom_shape_box(4.0 * he, 4.0 * he, he);
                g.position = vec(x0, 0, -he);
                g.friction = 0.6;
                assert_false(carom_body_id_is_null(carom_body_create(w, &g)));
                carom_body_def d = carom_body_def_default();
                d.shape = carom_shape_box(he, he, he);
                d.mass = mass;
                d.friction = 0.6;
                double z0 = 0.98 * he;
                d.position = vec(x0, 0, z0);
                d.angular_velocity = vec(0, 0, 2.5);
                d.lock_to_plane = 1;
                d.plane_normal = vec(0, 0, 1);
                carom_body_id id = carom_body_create(w, &d);
                assert_false(carom_body_id_is_null(id));
                for (int st = 0; st < 30; st++) {
                    assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                    carom_vec3 av, v, c;
                    assert_int_equal(carom_body_get_angular_velocity(w, id, &av), CAROM_OK);
                    assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
                    assert_int_equal(carom_body_get_center_of_mass(w, id, &c), CAROM_OK);
                    carom_contact_info info[4];
                    int nc = carom_body_get_contacts(w, id, info, 4);
                    assert_true(nc >= 0);
                    double impulse = 0.0;
                    for (int i = 0; i < nc && i < 4; i++) impulse += info[i].normal_impulse;
                    if (st == 0 || st == 29)
                        print_message("%s he %g m %g dt 1/%.0f x0 %g step %d: w_z %.15f, v_z %g, normal impulse %g (%d contacts)\n",
                                      presets[p], he, mass, 1.0 / dt, x0, st + 1, av.z, v.z, impulse, nc);
                    assert_true(nc >= 1); /* it is touching the ground... */
                    assert_true(impulse == 0.0); /* ...which pushes it nowhere */
                    assert_true(av.z == 2.5);
                    assert_true(av.x == 0.0 && av.y == 0.0 && v.z == 0.0);
                    assert_true(c.z == z0);
                }
                carom_world_destroy(w);
            }
}

/* A ball kept in a tilted plane (unit normal l = (0, sin b, cos b)) lands on
 * the ground (normal z) at e = 0 and mu = 0. Across the plane it cannot move,
 * so an impulse J z changes its normal velocity by J (1 - cos^2 b) / m: the
 * locked body's effective mass along z is m / sin^2 b (its arm r = -R z gives
 * no turning). One rigid row at that mass stops the approach exactly: after
 * each step with a relax pass (default, accurate) the normal velocity is 0 to
 * rounding, and at every preset the velocity along l is 0; with the free
 * mass m one row removes only sin^2 b of the approach. */
static void test_plane_lock_effective_mass_in_contact(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    const double tilts[] = {20.0, 45.0, 70.0}, dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 1000};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 3; k++)
            for (int o = 0; o < 2; o++) {
                double b = tilts[k] * 3.14159265358979323846 / 180.0, dt = dts[(p + k) % 3], x0 = o ? 1e5 : 0.0;
                double mass = 3.0, radius = 0.25, v0 = 1.0, g = 9.81;
                carom_vec3 l = vec(0, sin(b), cos(b));
                carom_world_def wd = carom_world_def_default();
                assert_int_equal(carom_world_def_apply_preset(&wd, presets[p]), CAROM_OK);
                wd.enable_sleep = 0;
                carom_world *w = carom_world_create(&wd);
                assert_non_null(w);
                carom_body_def gd = carom_body_def_default();
                gd.type = CAROM_BODY_STATIC;
                gd.shape = carom_shape_box(5, 5, 1);
                gd.position = vec(x0, 0, -1);
                gd.friction = 0.0;
                assert_false(carom_body_id_is_null(carom_body_create(w, &gd)));
                carom_body_def d = carom_body_def_default();
                d.shape = carom_shape_sphere(radius);
                d.mass = mass;
                d.friction = 0.0;
                d.restitution = 0.0;
                d.position = vec(x0, 0, radius);
                /* down the plane: the in-plane part of -z, at speed v0 */
                carom_vec3 down = vec(0, l.z * l.y, -(1.0 - l.z * l.z));
                double dl = sqrt(dot(down, down));
                d.linear_velocity = vec(0, v0 * down.y / dl, v0 * down.z / dl);
                d.lock_to_plane = 1;
                d.plane_normal = l;
                carom_body_id id = carom_body_create(w, &d);
                assert_false(carom_body_id_is_null(id));
                double sin2 = 1.0 - l.z * l.z;
                for (int st = 0; st < 5; st++) {
                    carom_vec3 v;
                    assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
                    /* the approach it brings into the step, gravity's in-plane pull added */
                    double vn_in = v.z - g * sin2 * dt;
                    assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                    assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
                    print_message("%s tilt %g dt 1/%.0f x0 %g step %d: v_n %.2e (in %.3f), v.l %.1e\n",
                                  presets[p], tilts[k], 1.0 / dt, x0, st + 1, v.z, vn_in, dot(v, l));
                    if (p > 0) assert_true(fabs(v.z) <= 1e-12); /* fast: no relax pass, the push-out stays */
                    assert_true(fabs(dot(v, l)) <= 1e-15);
                }
                carom_world_destroy(w);
            }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_lock_reduced_response),
        cmocka_unit_test(test_plane_lock_contact_normal_along_lock),
        cmocka_unit_test(test_plane_lock_effective_mass_in_contact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
