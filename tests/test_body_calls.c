/* test_body_calls.c - angular impulses against I^-1 L, damping set later
 * against exp(-c t), frame conversions, the shape back as a def, previous
 * poses for interpolation, and velocity changes from inside an event
 * callback applied exactly once after it. */
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

static carom_body_id add_oriented_box(carom_world *w, double hx, double hy, double hz, double mass, carom_quat q)
{
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_box(hx, hy, hz);
    d.mass = mass;
    d.orientation = q;
    d.enable_sleep = 0;
    return add_body(w, &d);
}

/* A box's principal moments m (b^2 + c^2) / 3 with half extents: the
 * impulse along each body axis changes the spin by L / I about it. */
static void test_angular_impulse(void **state)
{
    (void)state;
    carom_world *w = world_no_gravity();
    double hx = 0.5, hy = 0.25, hz = 0.1, m = 3.0;
    double I[3] = {m * (hy * hy + hz * hz) / 3, m * (hx * hx + hz * hz) / 3, m * (hx * hx + hy * hy) / 3};
    double c = cos(0.35), s = sin(0.35);
    carom_quat q = {c, 0, 0, s}; /* 0.7 rad about z */
    carom_body_id b = add_oriented_box(w, hx, hy, hz, m, q);
    /* along the body's x axis, in world terms */
    double ca = cos(0.7), sa = sin(0.7);
    carom_vec3 L = {2.0 * ca, 2.0 * sa, 0};
    assert_int_equal(carom_body_apply_angular_impulse(w, b, L), CAROM_OK);
    carom_vec3 av;
    carom_body_get_angular_velocity(w, b, &av);
    assert_true(fabs(av.x - 2.0 / I[0] * ca) < 1e-12 && fabs(av.y - 2.0 / I[0] * sa) < 1e-12 && fabs(av.z) < 1e-12);
    carom_vec3 Lz = {0, 0, 0.5}, zero = {0, 0, 0};
    carom_body_set_angular_velocity(w, b, zero);
    assert_int_equal(carom_body_apply_angular_impulse(w, b, Lz), CAROM_OK);
    carom_body_get_angular_velocity(w, b, &av);
    assert_true(fabs(av.z - 0.5 / I[2]) < 1e-12);
    /* a static body and a rotation-locked one: no effect, no error */
    carom_body_def sd = carom_body_def_default();
    sd.type = CAROM_BODY_STATIC;
    sd.position.x = 5;
    carom_body_id st = carom_body_create(w, &sd);
    assert_int_equal(carom_body_apply_angular_impulse(w, st, L), CAROM_OK);
    carom_vec3 nan3 = {NAN, 0, 0};
    assert_int_equal(carom_body_apply_angular_impulse(w, b, nan3), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(carom_world_last_error(w), "impulse"));
    carom_vec3 huge = {0, 0, 1e12};
    assert_int_equal(carom_body_apply_angular_impulse(w, b, huge), CAROM_ERROR_INVALID_ARGUMENT);
    carom_body_get_angular_velocity(w, b, &av);
    assert_true(fabs(av.z - 0.5 / I[2]) < 1e-12); /* unchanged by the refused calls */
    carom_world_destroy(w);
}

/* Damping set after creation: a free body slows as exp(-c t), to the
 * integrator's first-order error, at dt 1/15 .. 1/1000. */
static void test_damping_after_creation(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 1000};
    for (int k = 0; k < 3; k++) {
        carom_world *w = world_no_gravity();
        carom_quat id = {1, 0, 0, 0};
        carom_body_id b = add_oriented_box(w, 0.5, 0.5, 0.5, 1.0, id);
        carom_vec3 v = {2, 0, 0}, av = {0, 0, 3};
        carom_body_set_linear_velocity(w, b, v);
        carom_body_set_angular_velocity(w, b, av);
        assert_int_equal(carom_body_set_damping(w, b, 1.0, 0.5), CAROM_OK);
        double lin, ang;
        assert_int_equal(carom_body_get_damping(w, b, &lin, &ang), CAROM_OK);
        assert_true(lin == 1.0 && ang == 0.5);
        int steps = (int)lround(1.0 / dts[k]);
        for (int i = 0; i < steps; i++) carom_world_step(w, dts[k]);
        carom_vec3 vv, ww;
        carom_body_get_linear_velocity(w, b, &vv);
        carom_body_get_angular_velocity(w, b, &ww);
        /* implicit Euler on v' = -c v over 4 sub-steps of h = dt / 4: relative
         * error about c^2 h t / 2 (the first term of the series) */
        double want_v = 2 * exp(-1.0), want_w = 3 * exp(-0.5), h = dts[k] / 4;
        double tol_v = 1.0 * h / 2 * 1.1 + 1e-4, tol_w = 0.25 * h / 2 * 1.1 + 1e-4;
        if (fabs(vv.x / want_v - 1) > tol_v || fabs(ww.z / want_w - 1) > tol_w)
            fail_msg("dt %g: v %.6f (want %.6f), w %.6f (want %.6f)", dts[k], vv.x, want_v, ww.z, want_w);
        assert_int_equal(carom_body_set_damping(w, b, -1, 0), CAROM_ERROR_INVALID_ARGUMENT);
        assert_int_equal(carom_body_set_damping(w, b, 0, NAN), CAROM_ERROR_INVALID_ARGUMENT);
        assert_non_null(strstr(carom_world_last_error(w), "angular damping"));
        assert_int_equal(carom_body_get_damping(w, b, &lin, &ang), CAROM_OK);
        assert_true(lin == 1.0 && ang == 0.5);
        carom_world_destroy(w);
    }
}

static void test_frame_conversions(void **state)
{
    (void)state;
    carom_world *w = world_no_gravity();
    double h = sqrt(0.5);
    carom_body_def d = carom_body_def_default();
    d.position.x = 1e6; d.position.y = 2; d.position.z = 3;
    d.orientation.w = h; d.orientation.z = h; /* 90 degrees about z */
    carom_body_id b = carom_body_create(w, &d);
    carom_vec3 lx = {1, 0, 0}, out, back;
    assert_int_equal(carom_body_get_world_point(w, b, lx, &out), CAROM_OK);
    assert_true(fabs(out.x - 1e6) < 1e-9 && fabs(out.y - 3) < 1e-12 && fabs(out.z - 3) < 1e-12);
    assert_int_equal(carom_body_get_local_point(w, b, out, &back), CAROM_OK);
    assert_true(fabs(back.x - 1) < 1e-9 && fabs(back.y) < 1e-9 && fabs(back.z) < 1e-12);
    assert_int_equal(carom_body_get_world_vector(w, b, lx, &out), CAROM_OK);
    assert_true(fabs(out.x) < 1e-15 && fabs(out.y - 1) < 1e-15);
    assert_int_equal(carom_body_get_local_vector(w, b, out, &back), CAROM_OK);
    assert_true(fabs(back.x - 1) < 1e-15 && fabs(back.y) < 1e-15);
    carom_vec3 nan3 = {0, NAN, 0};
    assert_int_equal(carom_body_get_world_point(w, b, nan3, &out), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_get_world_point(w, b, lx, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    carom_body_destroy(w, b);
    assert_int_equal(carom_body_get_local_vector(w, b, lx, &out), CAROM_ERROR_STALE_ID);
    carom_world_destroy(w);
}

/* The shape comes back as a def that builds the same body (same mass). */
static void test_shape_round_trip(void **state)
{
    (void)state;
    static const double pts[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 0.2, 0.2};
    carom_shape_def defs[] = {carom_shape_sphere(0.3), carom_shape_box(0.1, 0.2, 0.3), carom_shape_capsule(0.2, 0.5),
                              carom_shape_cylinder(0.4, 0.1), carom_shape_hull(pts, 5), carom_shape_plane(0, 0, 2, 1)};
    carom_world *w = world_no_gravity();
    for (int i = 0; i < 6; i++) {
        carom_body_def d = carom_body_def_default();
        d.shape = defs[i];
        if (i == 5) d.type = CAROM_BODY_STATIC;
        carom_body_id b = carom_body_create(w, &d);
        carom_shape_def got;
        assert_int_equal(carom_body_get_shape(w, b, &got), CAROM_OK);
        assert_int_equal(got.type, defs[i].type);
        if (i == 4) assert_int_equal(got.point_count, 4); /* the interior point is not a vertex */
        if (i == 5) assert_true(fabs(got.normal.z - 1) < 1e-15 && fabs(got.offset - 0.5) < 1e-15);
        d.shape = got;
        d.position.x = 3;
        carom_body_id c = carom_body_create(w, &d);
        assert_false(carom_body_id_is_null(c));
        double ma, mb;
        carom_body_get_mass(w, b, &ma);
        carom_body_get_mass(w, c, &mb);
        assert_true(fabs(ma - mb) <= 1e-12 * ma);
    }
    assert_int_equal(carom_body_get_shape(w, carom_null_body(), NULL), CAROM_ERROR_STALE_ID);
    carom_world_destroy(w);
}

/* Previous poses: the pose at the start of the last step. */
static void test_previous_pose(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    carom_body_def d = carom_body_def_default();
    d.position.z = 10;
    d.angular_velocity.z = 2;
    carom_body_id b = carom_body_create(w, &d);
    carom_vec3 p0, p1, prev;
    carom_quat q0, q1, qprev;
    carom_body_get_position(w, b, &p0);
    carom_body_get_orientation(w, b, &q0);
    assert_int_equal(carom_body_get_previous_position(w, b, &prev), CAROM_OK);
    assert_true(prev.z == p0.z); /* a new body: its pose */
    carom_world_step(w, 1.0 / 60);
    carom_body_get_position(w, b, &p1);
    carom_body_get_orientation(w, b, &q1);
    carom_body_get_previous_position(w, b, &prev);
    carom_body_get_previous_orientation(w, b, &qprev);
    assert_true(prev.z == p0.z && p1.z < p0.z);
    assert_true(qprev.w == q0.w && qprev.z == q0.z && q1.z != q0.z);
    carom_world_step(w, 1.0 / 60);
    carom_body_get_previous_position(w, b, &prev);
    assert_true(prev.z == p1.z);
    /* a teleport leaves nothing to interpolate across */
    carom_vec3 there = {5, 5, 5};
    carom_body_set_position(w, b, there);
    carom_body_get_previous_position(w, b, &prev);
    assert_true(prev.x == 5 && prev.y == 5 && prev.z == 5);
    assert_int_equal(carom_body_get_previous_orientation(w, b, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    carom_world_destroy(w);
}

/* Velocity changes from a callback: queued, applied once after it. Two
 * identical worlds, one with the callback: the difference is the impulse
 * over the mass, exactly once. */
typedef struct kick { carom_world *w; carom_body_id target, bystander; int calls; carom_status st[6]; } kick;

static void on_event(void *ctx, const carom_contact_event *e)
{
    kick *k = ctx;
    if (e->type != CAROM_EVENT_BEGIN) return;
    carom_vec3 j = {0, 2.0, 0}, up = {0, 0, 1}, nan3 = {NAN, 0, 0}, spin = {0, 0, 3};
    k->st[0] = carom_body_apply_impulse(k->w, k->target, j, NULL);
    k->st[1] = carom_body_apply_impulse(k->w, k->bystander, j, NULL);
    k->st[2] = carom_body_apply_angular_impulse(k->w, k->bystander, up);
    k->st[3] = carom_body_apply_impulse(k->w, k->bystander, nan3, NULL); /* refused at once */
    k->st[4] = carom_body_set_damping(k->w, k->bystander, 1, 1);         /* not deferred: refused */
    k->st[5] = carom_body_set_angular_velocity(k->w, k->target, spin);
    k->calls++;
}

static void build(carom_world **w, carom_body_id *a, carom_body_id *b, carom_body_id *by, kick *k)
{
    carom_world_def wd = carom_world_def_default();
    wd.gravity.z = 0;
    if (k) { wd.event_callback = on_event; wd.event_context = k; }
    *w = carom_world_create(&wd);
    carom_body_def d = carom_body_def_default();
    d.enable_sleep = 0;
    d.linear_velocity.x = 1;
    d.position.x = -0.55;
    *a = carom_body_create(*w, &d);
    d.linear_velocity.x = -1;
    d.position.x = 0.55;
    *b = carom_body_create(*w, &d);
    d.linear_velocity.x = 0;
    d.position.x = 0;
    d.position.y = 10;
    *by = carom_body_create(*w, &d);
    if (k) { k->w = *w; k->target = *a; k->bystander = *by; }
}

static void test_impulses_in_callbacks_apply_once(void **state)
{
    (void)state;
    carom_world *w1, *w2;
    carom_body_id a1, b1, by1, a2, b2, by2;
    kick k;
    memset(&k, 0, sizeof k);
    build(&w1, &a1, &b1, &by1, &k);
    build(&w2, &a2, &b2, &by2, NULL);
    double m;
    carom_body_get_mass(w1, a1, &m);
    int step_of_kick = -1;
    for (int i = 0; i < 30; i++) {
        carom_world_step(w1, 1.0 / 60);
        carom_world_step(w2, 1.0 / 60);
        if (k.calls && step_of_kick < 0) {
            step_of_kick = i;
            carom_vec3 v1, v2, vb, wb;
            carom_body_get_linear_velocity(w1, a1, &v1);
            carom_body_get_linear_velocity(w2, a2, &v2);
            assert_true(fabs((v1.y - v2.y) - 2.0 / m) < 1e-12);
            carom_body_get_linear_velocity(w1, by1, &vb);
            assert_true(fabs(vb.y - 2.0 / m) < 1e-15);
            carom_body_get_angular_velocity(w1, by1, &wb);
            double I = 0.4 * m * 0.25; /* solid sphere 2/5 m r^2, r = 0.5 */
            assert_true(fabs(wb.z - 1.0 / I) < 1e-9);
            carom_vec3 wa;
            carom_body_get_angular_velocity(w1, a1, &wa);
            assert_true(fabs(wa.z - 3) < 1e-12); /* set after the impulse, in call order */
        }
    }
    assert_int_equal(k.calls, 1);
    assert_true(step_of_kick >= 0);
    assert_int_equal(k.st[0], CAROM_OK);
    assert_int_equal(k.st[1], CAROM_OK);
    assert_int_equal(k.st[2], CAROM_OK);
    assert_int_equal(k.st[3], CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(k.st[4], CAROM_ERROR_LOCKED);
    assert_int_equal(k.st[5], CAROM_OK);
    /* the bystander keeps exactly the one kick */
    carom_vec3 vb;
    carom_body_get_linear_velocity(w1, by1, &vb);
    assert_true(fabs(vb.y - 2.0 / m) < 1e-15);
    carom_world_destroy(w1);
    carom_world_destroy(w2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_angular_impulse),
        cmocka_unit_test(test_damping_after_creation),
        cmocka_unit_test(test_frame_conversions),
        cmocka_unit_test(test_shape_round_trip),
        cmocka_unit_test(test_previous_pose),
        cmocka_unit_test(test_impulses_in_callbacks_apply_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
