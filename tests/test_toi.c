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
#include "toi.h"
#include "mesh.h"
#include "heightfield.h"
#include "compound.h"
#include "mesh_scenes.h"

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

/* ---- the distance-only separation far from contact (toi_far_separation) ----
 * Against an independent brute force: every triangle of a wavy mesh and a
 * height field sampled on a barycentric grid, each sample's exact distance
 * to the convex shape (closed forms per type, in the shape's frame). The
 * least sampled distance is at least the true distance and at most h more
 * (h: the farthest any triangle point is from its nearest sample; distance
 * is 1-Lipschitz). The bound must never exceed the true distance, must be
 * within h + 1e-6 of it, and must say "near" (0) only within TOI_NEAR + h.
 * Also a sphere against each convex type (exact: the centre's distance
 * minus the radius), and a compound of two of them. */

#define FAR_SUB 48

static double point_shape_distance(const shape *s, xform x, vec3 pw)
{
    vec3 p = xf_inv_point(x, pw);
    switch (s->type) {
    case SHAPE_SPHERE: return v3_len(p) - s->radius;
    case SHAPE_BOX: {
        vec3 q = v3(fabs(p.x) - s->half_extents.x, fabs(p.y) - s->half_extents.y, fabs(p.z) - s->half_extents.z);
        vec3 o = v3(dmax(q.x, 0), dmax(q.y, 0), dmax(q.z, 0));
        return v3_len(o) > 0 ? v3_len(o) : dmax(q.x, dmax(q.y, q.z));
    }
    case SHAPE_CAPSULE: {
        double z = dmax(-s->half_height, dmin(s->half_height, p.z));
        return v3_len(v3(p.x, p.y, p.z - z)) - s->radius;
    }
    case SHAPE_CYLINDER: {
        double dr = sqrt(p.x * p.x + p.y * p.y) - s->radius, dz = fabs(p.z) - s->half_height;
        double ox = dmax(dr, 0), oz = dmax(dz, 0);
        return ox > 0 || oz > 0 ? sqrt(ox * ox + oz * oz) : dmax(dr, dz);
    }
    default: fail(); return 0;
    }
}

typedef struct far_brute { const shape *s; xform xs, xm; double best, h; } far_brute;

static int far_brute_triangle(void *ctx, const vec3 v[3], unsigned active, uint32_t index)
{
    (void)active;
    (void)index;
    far_brute *b = ctx;
    vec3 w[3] = {xf_point(b->xm, v[0]), xf_point(b->xm, v[1]), xf_point(b->xm, v[2])};
    double longest = dmax(v3_len(v3_sub(w[1], w[0])), dmax(v3_len(v3_sub(w[2], w[1])), v3_len(v3_sub(w[0], w[2]))));
    b->h = dmax(b->h, longest / FAR_SUB);
    for (int i = 0; i <= FAR_SUB; i++)
        for (int j = 0; i + j <= FAR_SUB; j++) {
            double u = (double)i / FAR_SUB, t = (double)j / FAR_SUB;
            vec3 p = v3_add(v3_scale(w[0], 1 - u - t), v3_add(v3_scale(w[1], u), v3_scale(w[2], t)));
            b->best = dmin(b->best, point_shape_distance(b->s, b->xs, p));
        }
    return 1;
}

static void check_far(const char *what, const shape *a, xform xa, const shape *b, xform xb, double truth, double h,
                      int *far_count)
{
    double d = -1;
    vec3 n = v3_zero();
    int far = toi_far_separation(a, xa, b, xb, 10.0, &d, &n);
    if (far) {
        (*far_count)++;
        if (!(d <= truth + 1e-9 && d >= truth - h - 1e-6 && fabs(v3_len(n) - 1) < 1e-9)) {
            print_error("%s: bound %.9f against brute force %.9f (h %.4f)\n", what, d, truth, h);
            fail();
        }
    } else if (truth > 0.01 + h + 1e-6) {
        print_error("%s: said near at brute-force distance %.6f\n", what, truth);
        fail();
    }
}

static void test_far_separation_against_brute_force(void **state)
{
    (void)state;
    /* a wavy 6 x 6 grid of 0.25 m cells, as a one-sided mesh and as a height field */
    enum { N = 6 };
    double v[(N + 1) * (N + 1) * 3], heights[(N + 1) * (N + 1)];
    int t[N * N * 6];
    for (int j = 0; j <= N; j++)
        for (int i = 0; i <= N; i++) {
            double x = (i - 0.5 * N) * 0.25, y = (j - 0.5 * N) * 0.25, z = 0.2 * sin(2.1 * x) * cos(1.7 * y);
            int k = j * (N + 1) + i;
            v[3 * k] = x; v[3 * k + 1] = y; v[3 * k + 2] = z;
            heights[k] = z;
        }
    for (int j = 0, q = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            int a = j * (N + 1) + i, b = a + 1, c = a + N + 1, d = c + 1;
            t[q++] = a; t[q++] = b; t[q++] = d;
            t[q++] = a; t[q++] = d; t[q++] = c;
        }
    char err[128];
    shape level[2];
    memset(level, 0, sizeof level);
    level[0].type = SHAPE_MESH;
    level[0].mesh = mesh_build(v, (N + 1) * (N + 1), t, 2 * N * N, 0, err, (int)sizeof err);
    level[1].type = SHAPE_HEIGHTFIELD;
    level[1].field = heightfield_build(heights, N + 1, N + 1, 0.25, 0.25, NULL, 0, err, (int)sizeof err);
    assert_non_null(level[0].mesh);
    assert_non_null(level[1].field);
    shape convex[4];
    memset(convex, 0, sizeof convex);
    convex[0].type = SHAPE_SPHERE; convex[0].radius = 0.15;
    convex[1].type = SHAPE_BOX; convex[1].half_extents = v3(0.2, 0.1, 0.15);
    convex[2].type = SHAPE_CAPSULE; convex[2].radius = 0.08; convex[2].half_height = 0.2;
    convex[3].type = SHAPE_CYLINDER; convex[3].radius = 0.18; convex[3].half_height = 0.1;
    uint64_t seed = 0x70F4A25EEDull;
    int far_count = 0, cases = 0;
    for (int l = 0; l < 2; l++)
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 24; k++) {
                /* the level placed far from the origin and turned; the shape above it */
                xform xm = {v3(1000.0 + k, -2000.0, 50.0), q_normalize(q_axis_angle(v3(0.3, -0.2, 1), 0.4 * k))};
                double lift = 0.003 + 0.6 * rnd(&seed) * rnd(&seed);
                vec3 local = v3(0.9 * (rnd(&seed) - 0.5), 0.9 * (rnd(&seed) - 0.5), 0.3 + lift);
                quat q = q_normalize(q_axis_angle(v3(rnd(&seed) - 0.5, rnd(&seed) - 0.5, rnd(&seed) - 0.5), 6.3 * rnd(&seed)));
                xform xs = {xf_point(xm, local), q_mul(xm.q, q)};
                far_brute bf = {&convex[c], xs, xm, 1e300, 0};
                aabb all = {v3(-10, -10, -10), v3(10, 10, 10)};
                if (l == 0) mesh_query(level[0].mesh, all, far_brute_triangle, &bf);
                else heightfield_query(level[1].field, all, far_brute_triangle, &bf);
                if (bf.best <= 0) continue; /* overlapping: the full collision's */
                char what[64];
                snprintf(what, sizeof what, "%s type %d case %d", l ? "field" : "mesh", c, k);
                check_far(what, &level[l], xm, &convex[c], xs, bf.best, bf.h, &far_count);
                /* either order: the normal turns, the bound does not */
                check_far(what, &convex[c], xs, &level[l], xm, bf.best, bf.h, &far_count);
                cases++;
            }
    /* a sphere against each convex type, and a compound of a box and a cylinder */
    for (int c = 0; c < 4; c++)
        for (int k = 0; k < 50; k++) {
            xform xb = {v3(-300.0, 40.0, 7.0), q_normalize(q_axis_angle(v3(rnd(&seed), rnd(&seed), 1), 6.3 * rnd(&seed)))};
            vec3 dir = v3_normalize(v3(rnd(&seed) - 0.5, rnd(&seed) - 0.5, rnd(&seed) - 0.5));
            xform xa = {v3_madd(xb.p, 0.2 + 0.5 * rnd(&seed), dir), q_identity()};
            double truth = point_shape_distance(&convex[c], xb, xa.p) - convex[0].radius;
            if (truth <= 0) continue;
            check_far("sphere pair", &convex[0], xa, &convex[c], xb, truth, 0.0, &far_count);
            cases++;
        }
    shape comp;
    memset(&comp, 0, sizeof comp);
    comp.type = SHAPE_COMPOUND;
    comp.compound = compound_alloc(2);
    assert_non_null(comp.compound);
    comp.compound->count = 2;
    comp.compound->children[0] = convex[1];
    comp.compound->children[1] = convex[3];
    comp.compound->poses[0] = (xform){v3(0.3, 0, 0), q_identity()};
    comp.compound->poses[1] = (xform){v3(-0.3, 0.1, 0), q_axis_angle(v3(1, 0, 0), 1.0)};
    for (int k = 0; k < 50; k++) {
        xform xb = {v3(5.0, 5.0, 5.0), q_normalize(q_axis_angle(v3(rnd(&seed), 1, rnd(&seed)), 6.3 * rnd(&seed)))};
        vec3 dir = v3_normalize(v3(rnd(&seed) - 0.5, rnd(&seed) - 0.5, rnd(&seed) - 0.5));
        xform xa = {v3_madd(xb.p, 0.3 + 0.6 * rnd(&seed), dir), q_identity()};
        double truth = 1e300;
        for (int i = 0; i < 2; i++) {
            xform xc = {xf_point(xb, comp.compound->poses[i].p), q_mul(xb.q, comp.compound->poses[i].q)};
            truth = dmin(truth, point_shape_distance(&comp.compound->children[i], xc, xa.p) - convex[0].radius);
        }
        if (truth <= 0) continue;
        check_far("sphere-compound", &convex[0], xa, &comp, xb, truth, 0.0, &far_count);
        cases++;
    }
    /* the far path answered most of them (the rest lie within TOI_NEAR) */
    print_message("far separation: %d of %d answered far\n", far_count, 2 * cases);
    assert_true(far_count > cases);
    shape_free_data(&comp);
    mesh_free(level[0].mesh);
    heightfield_free(level[1].field);
}


/* ---- motion the contacts did not look ahead for (issue 18, the terrain's landing) ----
 * A body spinning onto the ground, or one resting there and struck by a
 * heavy body landing on its end, moves its corners farther in a step than
 * its travel alone says. Against a plane, a box floor, 1 m tiles, a flat
 * mesh and a flat height field, at every preset and dt 1/30..1/240: after
 * every step no body is deeper in the ground than the speculative distance
 * (the depth measured afresh by the narrowphase at the step's end poses). */

enum { GROUND_PLANE, GROUND_BOX, GROUND_TILES, GROUND_MESH, GROUND_FIELD, GROUND_KINDS };
static const char *const ground_names[] = {"plane", "box", "tiles", "mesh", "field"};

/* the ground's bodies (up to 100 tiles); returns how many */
static int add_landing_ground(carom_world *w, int kind, carom_body_id *out)
{
    switch (kind) {
    case GROUND_PLANE: out[0] = add_static(w, carom_shape_plane(0, 0, 1, 0), vec(0, 0, 0)); return 1;
    case GROUND_BOX: out[0] = add_static(w, carom_shape_box(20, 20, 0.5), vec(0, 0, -0.5)); return 1;
    case GROUND_TILES: {
        int n = 0;
        for (int i = 0; i < 10; i++)
            for (int j = 0; j < 10; j++) out[n++] = add_static(w, carom_shape_box(0.5, 0.5, 0.5), vec(i - 4.5, j - 4.5, -0.5));
        return n;
    }
    case GROUND_MESH: {
        double *v;
        int *t, nv, nt;
        scene_grid(20, 0.5, 0.0, 7u, &v, &nv, &t, &nt);
        out[0] = scene_add_mesh(w, v, nv, t, nt, vec(0, 0, 0), about_x(0));
        free(v);
        free(t);
        return 1;
    }
    default: out[0] = scene_add_flat_field(w, 41, 41, 0.25, 0.0, vec(0, 0, 0)); return 1;
    }
}

/* deepest overlap of body b with any of the ground's bodies at the current poses */
static double ground_depth(carom_world *w, const carom_body_id *ground, int n, carom_body_id b)
{
    const body_store *s = &w->bodies;
    int sb = s->ids[b.index1 - 1].slot;
    double deepest = 0;
    for (int i = 0; i < n; i++) {
        int sg = s->ids[ground[i].index1 - 1].slot;
        collide_cache cache;
        memset(&cache, 0, sizeof cache);
        cache.feature = -1;
        manifold m;
        collide(&s->shapes[sg], body_xform(s, sg), &s->shapes[sb], body_xform(s, sb), 0.0, &cache, &m);
        for (int k = 0; k < m.count; k++) deepest = dmax(deepest, -m.points[k].separation);
    }
    return deepest;
}

static carom_shape_def landing_shape(int k)
{
    static const double hull_pts[24] = {0.25, 0, 0, -0.2, 0.1, 0, 0, 0.25, 0.05, 0, -0.22, 0.02,
                                        0.05, 0.05, 0.2, -0.05, 0, -0.2, 0.12, -0.1, 0.1, -0.1, -0.12, -0.1};
    switch (k) {
    case 0: return carom_shape_capsule(0.15, 0.2);
    case 1: return carom_shape_box(0.25, 0.2, 0.15);
    case 2: return carom_shape_cylinder(0.2, 0.15);
    default: return carom_shape_hull(hull_pts, 8);
    }
}

static void test_spun_and_struck_bodies_stay_out_of_the_ground(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 30, 1.0 / 60, 1.0 / 240};
    double worst[2] = {0, 0};
    int deep_cases = 0;
    for (int p = 0; p < 3; p++)
        for (int g = 0; g < GROUND_KINDS; g++)
            for (int k = 0; k < 4; k++)
                for (int d = 0; d < 3; d++)
                    for (int struck = 0; struck < 2; struck++) {
                        double dt = dts[d];
                        carom_world *w = world_preset(presets[p], 1);
                        carom_body_id ground[100];
                        int ng = add_landing_ground(w, g, ground);
                        carom_body_id b;
                        if (!struck) {
                            /* falling at 3 m/s, spinning at 25 rad/s about a level axis */
                            b = add_moving(w, landing_shape(k), vec(0.3, 0.2, 0.6), about_x(0.3), vec(0.5, 0, -3),
                                           vec(0, 25, 0));
                        } else {
                            /* lying at rest; a 100 kg box lands on its end at 6 m/s */
                            carom_quat lying = about_x(PI_ / 2);
                            b = add_moving(w, landing_shape(k), vec(0.3, 0.2, k == 0 ? 0.15 : k == 2 ? 0.2 : 0.25),
                                           k == 0 ? lying : about_x(0), vec(0, 0, 0), vec(0, 0, 0));
                            carom_body_def h = carom_body_def_default();
                            h.shape = carom_shape_box(0.3, 0.3, 0.3);
                            h.mass = 100.0;
                            h.position = vec(0.3, 0.2 + 0.25, 1.2);
                            h.linear_velocity = vec(0, 0, -6);
                            add_body(w, &h);
                        }
                        double deepest = 0;
                        int steps = (int)(1.0 / dt);
                        for (int i = 0; i < steps; i++) {
                            assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                            deepest = dmax(deepest, ground_depth(w, ground, ng, b));
                        }
                        worst[struck] = dmax(worst[struck], deepest);
                        if (deepest > speculative_distance(w)) {
                            deep_cases++;
                            print_error("%s %s shape %d dt 1/%.0f %s: %.4f m deep (speculative %.3f)\n", presets[p],
                                        ground_names[g], k, 1.0 / dt, struck ? "struck" : "spun", deepest,
                                        speculative_distance(w));
                        }
                        carom_world_destroy(w);
                    }
    print_message("deepest in the ground: spun %.4f m, struck %.4f m\n", worst[0], worst[1]);
    assert_int_equal(deep_cases, 0);
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
        cmocka_unit_test(test_far_separation_against_brute_force),
        cmocka_unit_test(test_spun_and_struck_bodies_stay_out_of_the_ground),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
