/* test_toi.c - continuous collision (lib/toi.c): a 750 m/s bullet does not
 * tunnel through a wall with continuous collision, and does without it; thin
 * plates and boxes that turn during the step, a spinning rod, fast dynamic
 * bodies meeting each other, and the exact rotation of a kinematic body. */
#define _POSIX_C_SOURCE 200809L /* setenv */
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
#include "world.h"

#include "helpers.h"

/* The peers' bullet: 1 cm, 10 g sphere at 750 m/s against a 5 cm wall. */
static void test_bullet_does_not_tunnel(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.5, 0.0);
    carom_body_def wall = carom_body_def_default();
    wall.type = CAROM_BODY_STATIC;
    wall.position = vec(1.025, 0, 2.0);
    wall.shape = carom_shape_box(0.025, 2.0, 2.0);
    wall.friction = 0.5;
    carom_body_create(w, &wall);
    carom_body_def d = carom_body_def_default();
    d.position = vec(0, 0, 2.0);
    d.shape = carom_shape_sphere(0.01);
    d.mass = 0.01;
    d.friction = 0.5;
    d.linear_velocity = vec(750, 0, 0);
    d.bullet = 1;
    carom_body_id b = carom_body_create(w, &d);
    int hits = 0;
    for (int i = 0; i < 60; i++) {
        step_n(w, 1, DT);
        const carom_contact_event *ev;
        int n = carom_world_get_events(w, &ev);
        for (int j = 0; j < n; j++)
            if (ev[j].type == CAROM_EVENT_HIT) {
                hits++;
                /* the wall stops it: J = m v, average force J / dt */
                EXPECT_NEAR(ev[j].normal_impulse, 0.01 * 750.0, 0.01 * 7.5, "bullet impulse");
                EXPECT_NEAR(ev[j].average_force, ev[j].normal_impulse / DT, 1e-9, "average force");
            }
        assert_true(pos(w, b).x < 1.0);
    }
    assert_int_equal(hits, 1);
    carom_world_destroy(w);
}

/* The same without continuous collision: the fast path must be what saves it. */
static void test_bullet_tunnels_without_ccd(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.enable_continuous = 0;
    carom_world *w = world_with(wd, 0, 0.5, 0.0);
    carom_body_def wall = carom_body_def_default();
    wall.type = CAROM_BODY_STATIC;
    wall.position = vec(1.025, 0, 2.0);
    wall.shape = carom_shape_box(0.025, 2.0, 2.0);
    carom_body_create(w, &wall);
    carom_body_def d = carom_body_def_default();
    d.position = vec(-20, 0, 2.0);
    d.shape = carom_shape_sphere(0.01);
    d.mass = 0.01;
    d.linear_velocity = vec(750, 0, 0);
    carom_body_id b = carom_body_create(w, &d);
    step_n(w, 60, DT);
    assert_true(pos(w, b).x > 1.05);
    carom_world_destroy(w);
}

/* ---- continuous collision against the scene's geometry (was test_continuous.c) ---- */

/* continuous collision against the geometry of the
 * scene: thin plates and boxes that turn during the step, a spinning rod,
 * fast dynamic bodies meeting each other, and the exact rotation of a
 * kinematic body. Depths are measured by the narrowphase at the poses each
 * step ends with (carom_world_measure_max_penetration). */

static const char *const presets[] = {"fast", "default", "accurate"};

static carom_quat about_x(double angle)
{
    carom_quat q = {cos(0.5 * angle), sin(0.5 * angle), 0, 0};
    return q;
}

static double speculative_distance(const carom_world *w)
{
    carom_world_def d = carom_world_def_default();
    assert_int_equal(carom_world_get_def(w, &d), CAROM_OK);
    return d.speculative_distance;
}

static carom_body_id add_moving(carom_world *w, carom_shape_def shape, carom_vec3 p, carom_quat q, carom_vec3 v, carom_vec3 av)
{
    carom_body_def d = carom_body_def_default();
    d.shape = shape;
    d.position = p;
    d.orientation = q;
    d.linear_velocity = v;
    d.angular_velocity = av;
    d.mass = 1.0;
    return add_body(w, &d);
}

/* Steps n times; returns the deepest overlap seen after any step. */
static double run_deepest(carom_world *w, int n, double dt)
{
    double deepest = 0;
    for (int i = 0; i < n; i++) {
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        double pen = carom_world_measure_max_penetration(w);
        if (pen > deepest) deepest = pen;
    }
    return deepest;
}

/* A 1 x 1 m plate 1 cm thick, tilted 30 degrees, falling at 200 and 2000 m/s
 * onto the floor, and at a 5 cm wall; and a 1 cm box spinning at 100 rad/s
 * while falling at 500 m/s: never deeper than the speculative distance, at
 * every preset, near the origin and 1e4 m from it. */
static void test_thin_turning_bodies_stop_at_the_surface(void **state)
{
    (void)state;
    const double speeds[] = {200, 2000};
    const double offsets[] = {0, 1e4};
    for (int p = 0; p < 3; p++)
        for (int o = 0; o < 2; o++) {
            double x0 = offsets[o];
            for (int k = 0; k < 2; k++) {
                /* floor */
                carom_world *w = world_preset(presets[p], 1);
                add_static(w, carom_shape_box(50, 50, 0.5), vec(x0, 0, -0.5));
                carom_body_id plate = add_moving(w, carom_shape_box(0.5, 0.5, 0.005), vec(x0, 0, 3), about_x(PI_ / 6),
                                               vec(0, 0, -speeds[k]), vec(0, 0, 0));
                double deepest = run_deepest(w, 60, 1.0 / 60);
                print_message("%s x0 %g plate at %g m/s onto the floor: deepest %.5f m, z %.4f\n", presets[p], x0,
                              speeds[k], deepest, pos(w, plate).z);
                assert_true(deepest <= speculative_distance(w));
                assert_true(pos(w, plate).z > -0.005);
                carom_world_destroy(w);
                /* 5 cm wall, plate flying sideways */
                w = world_preset(presets[p], 0);
                add_static(w, carom_shape_box(0.025, 5, 5), vec(x0 + 5, 0, 0));
                plate = add_moving(w, carom_shape_box(0.005, 0.5, 0.5), vec(x0, 0, 0), about_x(PI_ / 6),
                                 vec(speeds[k], 0, 0), vec(0, 0, 0));
                deepest = run_deepest(w, 30, 1.0 / 60);
                print_message("%s x0 %g plate at %g m/s into the wall: deepest %.5f m, x %.4f\n", presets[p], x0,
                              speeds[k], deepest, pos(w, plate).x - x0);
                assert_true(deepest <= speculative_distance(w));
                assert_true(pos(w, plate).x - x0 < 5.0);
                carom_world_destroy(w);
            }
            carom_world *w = world_preset(presets[p], 1);
            add_static(w, carom_shape_plane(0, 0, 1, 0), vec(x0, 0, 0));
            carom_body_id tile = add_moving(w, carom_shape_box(0.25, 0.25, 0.005), vec(x0, 0, 5), about_x(0.3),
                                          vec(0, 0, -500), vec(100, 0, 0));
            double deepest = run_deepest(w, 60, 1.0 / 60);
            print_message("%s x0 %g spinning tile at 500 m/s: deepest %.5f m, z %.4f\n", presets[p], x0, deepest,
                          pos(w, tile).z);
            assert_true(deepest <= speculative_distance(w));
            assert_true(pos(w, tile).z > -0.005);
            carom_world_destroy(w);
        }
}

/* A 1 m rod (capsule and box) spinning end over end at 500 rad/s just above
 * the floor, and spinning about its own axis: never deeper than the
 * speculative distance at any preset and step. Spinning about its own axis
 * it is not held up by continuous collision (its shape does not change):
 * it falls as freely as a body at rest would. */
static void test_spinning_rod_stays_above_the_floor(void **state)
{
    (void)state;
    const double rates[] = {30, 60, 240};
    for (int p = 0; p < 3; p++)
        for (int r = 0; r < 3; r++)
            for (int kind = 0; kind < 2; kind++) {
                carom_shape_def rod = kind ? carom_shape_box(0.02, 0.5, 0.02) : carom_shape_capsule(0.02, 0.5);
                carom_quat q = kind ? about_x(0) : about_x(PI_ / 2); /* both along y */
                carom_world *w = world_preset(presets[p], 1);
                add_static(w, carom_shape_plane(0, 0, 1, 0), vec(0, 0, 0));
                add_moving(w, rod, vec(0, 0, 0.03), q, vec(0, 0, 0), vec(500, 0, 0));
                double deepest = run_deepest(w, (int)(rates[r] / 2), 1.0 / rates[r]);
                print_message("%s dt 1/%g %s end over end: deepest %.5f\n", presets[p], rates[r],
                              kind ? "box" : "capsule", deepest);
                assert_true(deepest <= speculative_distance(w));
                carom_world_destroy(w);
            }
    for (int p = 0; p < 3; p++) {
        carom_world *w = world_preset(presets[p], 1);
        carom_body_id id = add_moving(w, carom_shape_capsule(0.02, 0.5), vec(0, 0, 10), about_x(PI_ / 2), vec(0, 0, 0),
                                    vec(0, 500, 0));
        for (int i = 0; i < 30; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        double t = 0.5, drop = 10 - pos(w, id).z;
        print_message("%s capsule spinning about its axis: dropped %.5f in %g s (g t^2/2 = %.5f)\n", presets[p], drop,
                      t, 0.5 * 9.81 * t * t);
        assert_true(fabs(drop - 0.5 * 9.81 * t * t) < 9.81 * t / 60);
        carom_world_destroy(w);
    }
}

/* Two dynamic bodies fired at each other meet (continuous collision between
 * moving bodies, not only against statics): 2 cm bullets at 500 m/s each
 * stop where they meet, at the midpoint (equal masses, no restitution),
 * and never pass each other; a 1 cm sphere at 1000 m/s meets a 5 cm box
 * coming the other way at 200 m/s. Zero gravity; any preset, dt and gap. */
static void test_fast_dynamic_bodies_meet(void **state)
{
    (void)state;
    const double rates[] = {15, 60, 1000};
    const double gaps[] = {3, 10, 40};
    for (int p = 0; p < 3; p++)
        for (int r = 0; r < 3; r++)
            for (int g = 0; g < 3; g++) {
                double dt = 1.0 / rates[r], half = 0.5 * gaps[g];
                carom_world *w = world_preset(presets[p], 0);
                carom_body_id a = add_moving(w, carom_shape_sphere(0.01), vec(-half, 0, 0), about_x(0), vec(500, 0, 0),
                                           vec(0, 0, 0));
                carom_body_id b = add_moving(w, carom_shape_sphere(0.01), vec(half, 0, 0), about_x(0), vec(-500, 0, 0),
                                           vec(0, 0, 0));
                int n = (int)ceil(2.0 * gaps[g] / 1000.0 / dt) + 4;
                for (int i = 0; i < n; i++) {
                    assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                    assert_true(pos(w, a).x < pos(w, b).x);
                }
                print_message("%s dt 1/%g gap %g: bullets at %.5f and %.5f\n", presets[p], rates[r], gaps[g],
                              pos(w, a).x, pos(w, b).x);
                /* they met and stopped where they met: the midpoint */
                assert_true(fabs(pos(w, a).x + 0.01) < 0.01 && fabs(pos(w, b).x - 0.01) < 0.01);
                carom_world_destroy(w);

                w = world_preset(presets[p], 0);
                carom_body_id s = add_moving(w, carom_shape_sphere(0.01), vec(-half, 0, 0), about_x(0), vec(1000, 0, 0),
                                           vec(0, 0, 0));
                carom_body_id box = add_moving(w, carom_shape_box(0.025, 0.5, 0.5), vec(half, 0, 0), about_x(0),
                                             vec(-200, 0, 0), vec(0, 0, 0));
                int met = 0;
                for (int i = 0; i < n; i++) {
                    assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                    assert_true(pos(w, s).x < pos(w, box).x);
                    carom_vec3 v;
                    assert_int_equal(carom_body_get_linear_velocity(w, s, &v), CAROM_OK);
                    if (v.x < 1000 - 1e-6) met = 1;
                }
                assert_true(met);
                carom_world_destroy(w);
            }
}

/* A kinematic body with constant w follows the exact rotation: after T
 * seconds its angle is w T to 1e-12 rad per second of motion, at any dt. */
static void test_kinematic_rotation_is_exact(void **state)
{
    (void)state;
    const double rates[] = {15, 60, 240, 1000};
    const double speeds[] = {PI_ / 2, 10.0, 300.0};
    for (int r = 0; r < 4; r++)
        for (int k = 0; k < 3; k++)
            for (int p = 0; p < 3; p++) {
                carom_world *w = world_preset(presets[p], 1);
                carom_body_def d = carom_body_def_default();
                d.type = CAROM_BODY_KINEMATIC;
                d.shape = carom_shape_box(0.5, 0.2, 0.1);
                d.angular_velocity = vec(0, 0, speeds[k]);
                carom_body_id id = carom_body_create(w, &d);
                int n = (int)rates[r];
                for (int i = 0; i < n; i++) assert_int_equal(carom_world_step(w, 1.0 / rates[r]), CAROM_OK);
                carom_quat q;
                assert_int_equal(carom_body_get_orientation(w, id, &q), CAROM_OK);
                /* expected quaternion: (cos(wT/2), 0, 0, sin(wT/2)); compare
                 * the relative rotation angle */
                double half = 0.5 * speeds[k] * n / rates[r];
                double c = cos(half) * q.w + sin(half) * q.z; /* <q_expected, q> */
                double s = sqrt(q.x * q.x + q.y * q.y + pow(cos(half) * q.z - sin(half) * q.w, 2));
                double err = 2.0 * atan2(s, fabs(c));
                print_message("%s dt 1/%g w %g: angle error %.3e rad after 1 s\n", presets[p], rates[r], speeds[k], err);
                assert_true(err <= 1e-12);
                carom_world_destroy(w);
            }
}

/* Issue 17, finding 6: a body resting on a static plane or box and struck
 * straight down (100 to 4000 m/s), or sent sliding along it at the speed
 * clamp, must not end inside it: a pair already touching gets no sweep of
 * its own, so the contact must stop it. Spheres of 1e-6 to 0.1 m and a small
 * capsule, every preset; depth after each step within the 5 mm a touching
 * pair may sink before its sweep stops it (toi.c's TOI_SINK). */
static void test_issue17_finding6_struck_resting_body_stays_out(void **state)
{
    (void)state;
    const double radii[] = {1e-6, 1e-3, 0.1};
    const double speeds[] = {100, 1000, 4000};
    for (int p = 0; p < 3; p++)
        for (int floor = 0; floor < 2; floor++)
            for (int r = 0; r < 3; r++)
                for (int kind = 0; kind < 2; kind++)
                    for (int k = 0; k < 4; k++) {
                        carom_world *w = world_preset(presets[p], 1);
                        carom_world_def d = carom_world_def_default();
                        assert_int_equal(carom_world_get_def(w, &d), CAROM_OK);
                        if (floor) add_static(w, carom_shape_box(1e3, 1e3, 0.5), vec(0, 0, -0.5));
                        else add_static(w, carom_shape_plane(0, 0, 1, 0), vec(0, 0, 0));
                        double rad = radii[r];
                        carom_shape_def shape = kind ? carom_shape_capsule(rad, 2 * rad) : carom_shape_sphere(rad);
                        carom_quat lying = about_x(PI_ / 2);
                        carom_body_id id = add_moving(w, shape, vec(0, 0, rad), kind ? lying : about_x(0), vec(0, 0, 0),
                                                    vec(0, 0, 0));
                        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
                        /* k < 3: struck down; k = 3: sliding at the clamp */
                        carom_vec3 v = k < 3 ? vec(0, 0, -speeds[k]) : vec(d.max_linear_speed, 0, 0);
                        assert_int_equal(carom_body_set_linear_velocity(w, id, v), CAROM_OK);
                        double deepest = run_deepest(w, 3, 1.0 / 60);
                        if (deepest > 0.005) {
                            print_error("%s %s %s r %g %s: %.5f m deep\n", presets[p], floor ? "box" : "plane",
                                        kind ? "capsule" : "sphere", rad,
                                        k < 3 ? "struck down" : "sliding", deepest);
                            fail();
                        }
                        /* and it is not below the surface by more than that either */
                        assert_true(pos(w, id).z - rad > -0.005);
                        carom_world_destroy(w);
                    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bullet_does_not_tunnel),
        cmocka_unit_test(test_bullet_tunnels_without_ccd),
        cmocka_unit_test(test_thin_turning_bodies_stop_at_the_surface),
        cmocka_unit_test(test_spinning_rod_stays_above_the_floor),
        cmocka_unit_test(test_fast_dynamic_bodies_meet),
        cmocka_unit_test(test_kinematic_rotation_is_exact),
        cmocka_unit_test(test_issue17_finding6_struck_resting_body_stays_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
