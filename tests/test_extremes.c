/* test_extremes.c - numerical stability at the edges of the envelope (fast
 * versions; bench/extremes runs the long ones): mass ratios, speeds, sizes,
 * distance from the origin, time steps, and a soak. The state must stay
 * finite everywhere, and accurate where the README says carom holds. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "helpers.h"


static carom_world *ground_world(carom_world_def d)
{
    d.enable_sleep = 0;
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    return w;
}

static carom_body_id box_at(carom_world *w, double x, double y, double z, double he, double mass)
{
    carom_body_def d = carom_body_def_default();
    d.position = vec(x, y, z);
    d.shape = carom_shape_box(he, he, he);
    d.mass = mass;
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    return id;
}

static void assert_world_finite(carom_world *w)
{
    double ke, pe;
    carom_vec3 p, l;
    assert_int_equal(carom_world_get_energy(w, &ke, &pe), CAROM_OK);
    assert_int_equal(carom_world_get_momentum(w, &p, &l), CAROM_OK);
    assert_true(isfinite(ke) && isfinite(pe));
    assert_true(isfinite(p.x) && isfinite(p.y) && isfinite(p.z) && isfinite(l.x) && isfinite(l.y) && isfinite(l.z));
}

static void run(carom_world *w, int n, double dt)
{
    for (int i = 0; i < n; i++) assert_int_equal(carom_world_step(w, dt), CAROM_OK);
}

/* 1000:1 holds; 1e6:1 stays finite and upright-ish (the light box is not squeezed out). */
static void test_mass_ratios(void **state)
{
    (void)state;
    double ratios[2] = {1e3, 1e6};
    for (int i = 0; i < 2; i++) {
        carom_world *w = ground_world(carom_world_def_default());
        carom_body_id light = box_at(w, 0, 0, 0.5, 0.5, 1.0);
        carom_body_id heavy = box_at(w, 0, 0, 1.5, 0.5, ratios[i]);
        run(w, 300, 1.0 / 60);
        assert_world_finite(w);
        carom_vec3 ph = pos(w, heavy), pl = pos(w, light);
        double tol = i == 0 ? 0.01 : 0.05;
        if (!(fabs(ph.z - 1.5) < tol && fabs(pl.z - 0.5) < tol)) {
            print_error("ratio %g: heavy z %.4f light z %.4f\n", ratios[i], ph.z, pl.z);
            fail();
        }
        carom_world_destroy(w);
    }
}

/* Projectiles up to 1000 m/s against a 5 cm wall never pass through. */
static void test_speeds(void **state)
{
    (void)state;
    double speeds[4] = {10, 100, 500, 1000};
    for (int i = 0; i < 4; i++) {
        carom_world_def d = carom_world_def_default();
        carom_world *w = carom_world_create(&d);
        carom_body_def wall = carom_body_def_default();
        wall.type = CAROM_BODY_STATIC;
        wall.position = vec(1.025, 0, 2);
        wall.shape = carom_shape_box(0.025, 2, 2);
        carom_body_create(w, &wall);
        carom_body_def s = carom_body_def_default();
        s.position = vec(0, 0, 2);
        s.shape = carom_shape_sphere(0.01);
        s.mass = 0.01;
        s.linear_velocity = vec(speeds[i], 0, 0);
        carom_body_id b = carom_body_create(w, &s);
        for (int k = 0; k < 60; k++) {
            run(w, 1, 1.0 / 60);
            if (!(pos(w, b).x < 1.0)) {
                print_error("speed %g m/s: x = %.4f after step %d\n", speeds[i], pos(w, b).x, k);
                fail();
            }
        }
        assert_world_finite(w);
        carom_world_destroy(w);
    }
}

/* A box resting on the ground stays put from 1 mm to 1 km. */
static void test_sizes(void **state)
{
    (void)state;
    double sizes[4] = {0.001, 0.01, 100.0, 1000.0};
    for (int i = 0; i < 4; i++) {
        carom_world *w = ground_world(carom_world_def_default());
        double he = 0.5 * sizes[i];
        carom_body_id b = box_at(w, 0, 0, he, he, 1000.0 * sizes[i] * sizes[i] * sizes[i]);
        run(w, 120, 1.0 / 60);
        assert_world_finite(w);
        carom_vec3 p = pos(w, b);
        /* within 1 % of its size, or the 5 mm slop, whichever is larger */
        double tol = fmax(0.01 * sizes[i], 0.006);
        if (!(fabs(p.z - he) < tol && fabs(p.x) < tol && fabs(p.y) < tol)) {
            print_error("size %g m: rest at (%.6f %.6f %.6f), expected z %.6f\n", sizes[i], p.x, p.y, p.z, he);
            fail();
        }
        carom_world_destroy(w);
    }
}

/* A five-box stack 1e5 m from the origin stands as it does at the origin. */
static void test_far_from_origin(void **state)
{
    (void)state;
    carom_world *w = ground_world(carom_world_def_default());
    const double X = 1e5, Y = -1e5;
    carom_body_id top = box_at(w, X, Y, 0.5, 0.5, 1);
    for (int i = 1; i < 5; i++) top = box_at(w, X, Y, 0.5 + i, 0.5, 1);
    run(w, 300, 1.0 / 60);
    assert_world_finite(w);
    carom_vec3 p = pos(w, top);
    double moved = sqrt(pow(p.x - X, 2) + pow(p.y - Y, 2) + pow(p.z - 4.5, 2));
    if (!(moved < 0.01)) { print_error("far stack top moved %.4f m\n", moved); fail(); }
    carom_world_destroy(w);
}

/* Time steps from 1/1000 to 1/15 s: a stack of five stands at each. */
static void test_time_steps(void **state)
{
    (void)state;
    double dts[4] = {1.0 / 1000, 1.0 / 120, 1.0 / 30, 1.0 / 15};
    for (int i = 0; i < 4; i++) {
        carom_world *w = ground_world(carom_world_def_default());
        carom_body_id top = box_at(w, 0, 0, 0.5, 0.5, 1);
        for (int k = 1; k < 5; k++) top = box_at(w, 0, 0, 0.5 + k, 0.5, 1);
        int steps = (int)(3.0 / dts[i]);
        run(w, steps, dts[i]);
        assert_world_finite(w);
        carom_vec3 p = pos(w, top);
        double moved = sqrt(p.x * p.x + p.y * p.y + pow(p.z - 4.5, 2));
        /* accurate to 3 cm at 60 Hz and finer; still standing (the peers' 0.1 m) at 30 and 15 Hz */
        double tol = dts[i] <= 1.0 / 60 ? 0.03 : 0.1;
        print_message("dt %.4f: top moved %.4f m\n", dts[i], moved);
        if (!(moved < tol)) { print_error("dt %g: stack top moved %.4f m\n", dts[i], moved); fail(); }
        carom_world_destroy(w);
    }
}

/* A short soak: a box and a ball bouncing around a closed room stay finite and inside. */
/* Finite but absurd velocities are refused by the setters (above the world's
 * speed limits), leaving the body as it was; velocities a later, lower limit
 * leaves too fast are clamped before they are integrated: no pose overflows,
 * no NaN reaches the narrowphase or the time-of-impact sweep. */
static void test_huge_velocities(void **state)
{
    (void)state;
    const carom_shape_def shapes[] = {carom_shape_capsule(0.1, 0.3), carom_shape_sphere(0.2), carom_shape_box(0.2, 0.2, 0.2)};
    for (int k = 0; k < 3; k++) {
        carom_world_def d = carom_world_def_default();
        d.max_angular_speed = 1000.0; /* an explicit cap (the default, 0, is automatic) */
        carom_world *w = ground_world(d);
        carom_body_def sb = carom_body_def_default();
        sb.type = CAROM_BODY_STATIC;
        sb.shape = carom_shape_box(2, 2, 0.5);
        sb.position = vec(0, 0, 0.5);
        carom_body_create(w, &sb);
        carom_body_def bd = carom_body_def_default();
        bd.shape = shapes[k];
        bd.position = vec(0, 0, 1.6);
        carom_body_id spin = carom_body_create(w, &bd);
        bd.position = vec(0.5, 0, 1.6);
        carom_body_id fly = carom_body_create(w, &bd);
        assert_int_equal(carom_body_set_angular_velocity(w, spin, vec(0, -1e308, 0)), CAROM_ERROR_INVALID_ARGUMENT);
        assert_int_equal(carom_body_set_linear_velocity(w, fly, vec(-1e308, 1e308, -1e308)), CAROM_ERROR_INVALID_ARGUMENT);
        carom_vec3 unchanged;
        assert_int_equal(carom_body_get_linear_velocity(w, fly, &unchanged), CAROM_OK);
        assert_true(unchanged.x == 0 && unchanged.y == 0 && unchanged.z == 0);
        assert_int_equal(carom_body_set_angular_velocity(w, spin, vec(0, -d.max_angular_speed, 0)), CAROM_OK);
        double c = d.max_linear_speed / sqrt(3.0) * (1 - 1e-12);
        assert_int_equal(carom_body_set_linear_velocity(w, fly, vec(-c, c, -c)), CAROM_OK);
        carom_world_def lower = d;
        lower.enable_sleep = 0;
        lower.max_linear_speed = d.max_linear_speed / 1e3;
        lower.max_angular_speed = d.max_angular_speed / 1e3;
        assert_int_equal(carom_world_set_def(w, &lower), CAROM_OK);
        d = lower;
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
        assert_true(st.clamped >= 2);
        assert_int_equal(st.non_finite, 0);
        carom_vec3 wv, v;
        assert_int_equal(carom_body_get_angular_velocity(w, spin, &wv), CAROM_OK);
        assert_true(sqrt(wv.x * wv.x + wv.y * wv.y + wv.z * wv.z) <= d.max_angular_speed * (1 + 1e-12));
        assert_int_equal(carom_body_get_linear_velocity(w, fly, &v), CAROM_OK);
        assert_true(sqrt(v.x * v.x + v.y * v.y + v.z * v.z) <= d.max_linear_speed * (1 + 1e-12));
        run(w, 120, 1.0 / 60);
        assert_world_finite(w);
        carom_vec3 p = pos(w, spin);
        assert_true(isfinite(p.x) && isfinite(p.y) && isfinite(p.z));
        carom_world_destroy(w);
    }
}

/* A 1 cm box on the ground with every manifold recomputed every step (no
 * reuse): it stays where it was put, flat (its eight corners are all within
 * the 2 cm look-ahead; the manifold must still be the bottom face's). */
static void test_small_box_rests_without_reuse(void **state)
{
    (void)state;
    carom_world_def d = carom_world_def_default();
    d.contact_reuse_distance = 0.0;
    carom_world *w = ground_world(d);
    carom_body_id id = box_at(w, 0, 0, 0.005, 0.005, 1e-3);
    run(w, 600, 1.0 / 60);
    carom_vec3 p = pos(w, id);
    carom_quat q;
    assert_int_equal(carom_body_get_orientation(w, id, &q), CAROM_OK);
    double drift = sqrt(p.x * p.x + p.y * p.y), tilt = 2.0 * acos(fmin(1.0, fabs(q.w)));
    print_message("1 cm box: drift %.3g m, sank %.3g m, tilt %.3g rad\n", drift, 0.005 - p.z, tilt);
    assert_true(drift < 1e-4);
    assert_true(fabs(p.z - 0.005) < 5e-4);
    assert_true(tilt < 0.01);
    carom_world_destroy(w);
}

/* Everything at once through the wide passes, under the sanitizers in make
 * check: 160 bodies of every shape falling into a walled bin (heavy ones
 * among them, so shock propagation runs between wide passes), kinematic
 * paddles sweeping through, plane-locked bodies, sleeping on. Nothing may go
 * non-finite, fall through the floor or leave the bin. */
static void test_mixed_bin_stress(void **state)
{
    (void)state;
    carom_world_def d = carom_world_def_default();
    d.enable_sleep = 1;
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    const double walls[5][4] = {{0, 0, 1, 0}, {1, 0, 0, -4}, {-1, 0, 0, -4}, {0, 1, 0, -4}, {0, -1, 0, -4}};
    for (int i = 0; i < 5; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(walls[i][0], walls[i][1], walls[i][2], walls[i][3]);
        carom_body_create(w, &g);
    }
    const double pts[15] = {0.3, 0, 0, -0.2, 0.25, 0, -0.2, -0.25, 0, 0, 0, 0.4, 0, 0, -0.3};
    carom_body_id ids[160];
    uint64_t r = 0xB1A5EDULL;
    for (int i = 0; i < 160; i++) {
        carom_body_def b = carom_body_def_default();
        b.position = vec(-3.0 + 0.75 * (i % 8), -3.0 + 0.75 * ((i / 8) % 8), 0.5 + 0.8 * (i / 64));
        switch (i % 6) {
        case 0: b.shape = carom_shape_box(0.3, 0.2, 0.25); break;
        case 1: b.shape = carom_shape_sphere(0.3); break;
        case 2: b.shape = carom_shape_capsule(0.15, 0.2); break;
        case 3: b.shape = carom_shape_cylinder(0.25, 0.2); break;
        case 4: b.shape = carom_shape_hull(pts, 5); break;
        default: b.shape = carom_shape_box(0.35, 0.35, 0.1); break;
        }
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        if (i % 17 == 0) b.mass = 1000.0; /* heavy */
        if (i % 23 == 5) { b.lock_to_plane = 1; b.plane_normal = vec(0, 1, 0); }
        if (i % 31 == 7) b.lock_rotation = 1;
        b.restitution = (double)(r >> 40 & 0xff) / 512.0;
        b.friction = 0.2 + (double)(r >> 48 & 0xff) / 512.0;
        b.angular_velocity = vec((double)(r >> 20 & 0xff) / 64.0 - 2, 0, (double)(r >> 28 & 0xff) / 64.0 - 2);
        ids[i] = carom_body_create(w, &b);
        assert_false(carom_body_id_is_null(ids[i]));
    }
    carom_body_id paddles[2];
    for (int k = 0; k < 2; k++) {
        carom_body_def p = carom_body_def_default();
        p.type = CAROM_BODY_KINEMATIC;
        p.shape = carom_shape_box(1.5, 0.1, 0.3);
        p.position = vec(0, k ? 2.0 : -2.0, 0.3);
        p.angular_velocity = vec(0, 0, k ? 1.0 : -1.5);
        paddles[k] = carom_body_create(w, &p);
    }
    int most = 0;
    for (int s = 0; s < 600; s++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
        assert_int_equal(st.non_finite, 0);
        if (st.contacts > most) most = st.contacts;
    }
    assert_true(most >= 64); /* the wide passes ran */
    assert_world_finite(w);
    for (int i = 0; i < 160; i++) {
        carom_vec3 p = pos(w, ids[i]);
        if (!(p.z > -0.05 && fabs(p.x) < 4.0 && fabs(p.y) < 4.0)) {
            print_error("body %d left the bin: (%.3f %.3f %.3f)\n", i, p.x, p.y, p.z);
            fail();
        }
    }
    (void)paddles;
    carom_world_destroy(w);
}

static void test_soak(void **state)
{
    (void)state;
    carom_world_def d = carom_world_def_default();
    d.enable_sleep = 0;
    carom_world *w = carom_world_create(&d);
    double walls[6][4] = {{0, 0, 1, 0}, {0, 0, -1, -6}, {1, 0, 0, -3}, {-1, 0, 0, -3}, {0, 1, 0, -3}, {0, -1, 0, -3}};
    for (int i = 0; i < 6; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(walls[i][0], walls[i][1], walls[i][2], walls[i][3]);
        g.restitution = 0.9;
        carom_body_create(w, &g);
    }
    carom_body_def b = carom_body_def_default();
    b.position = vec(0, 0, 2);
    b.shape = carom_shape_box(0.3, 0.2, 0.1);
    b.linear_velocity = vec(7, -3, 5);
    b.angular_velocity = vec(4, 9, -2);
    b.restitution = 0.9;
    carom_body_id box = carom_body_create(w, &b);
    b.shape = carom_shape_sphere(0.2);
    b.position = vec(1, 1, 3);
    carom_body_id ball = carom_body_create(w, &b);
    for (int i = 0; i < 20000; i++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        if (i % 1000 == 0) assert_world_finite(w);
    }
    carom_vec3 p = pos(w, box), q = pos(w, ball);
    assert_true(fabs(p.x) < 3 && fabs(p.y) < 3 && p.z > 0 && p.z < 6);
    assert_true(fabs(q.x) < 3 && fabs(q.y) < 3 && q.z > 0 && q.z < 6);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mass_ratios),
        cmocka_unit_test(test_speeds),
        cmocka_unit_test(test_sizes),
        cmocka_unit_test(test_far_from_origin),
        cmocka_unit_test(test_time_steps),
        cmocka_unit_test(test_huge_velocities),
        cmocka_unit_test(test_small_box_rests_without_reuse),
        cmocka_unit_test(test_mixed_bin_stress),
        cmocka_unit_test(test_soak),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
