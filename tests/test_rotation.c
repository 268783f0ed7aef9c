/* test_rotation.c - free rotation against Euler's equations: a torque-free
 * body keeps its world angular momentum and its kinetic energy, a spin about
 * the major or minor axis stays there, a spin about the intermediate axis
 * flips with the half-period 2 K(k) / lambda of the elliptic-function
 * solution, and a fast slender rod keeps its spin. Through the pure step
 * (lib/rotation.c) and through the world at every preset and dt 1/15..1/1000. */
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
#include "rotation.h"


/* The box: half extents 0.5, 0.25, 0.1 m, 1 kg. */
static const double HX = 0.5, HY = 0.25, HZ = 0.1;

static vec3 box_inertia(double m, double hx, double hy, double hz)
{
    return v3(m * (hy * hy + hz * hz) / 3, m * (hx * hx + hz * hz) / 3, m * (hx * hx + hy * hy) / 3);
}

/* Complete elliptic integral of the first kind K(k), by the arithmetic-geometric mean. */
static double elliptic_k(double k)
{
    double a = 1.0, b = sqrt(1.0 - k * k);
    for (int i = 0; i < 40 && fabs(a - b) > 1e-16 * a; i++) {
        double an = 0.5 * (a + b);
        b = sqrt(a * b);
        a = an;
    }
    return PI_ / (2.0 * a);
}

/* Time between successive sign changes of the intermediate-axis rate w2 of a
 * free body with principal moments i1 < i2 < i3 started at body rate w:
 * w2 = a sn(lambda t, k), so 2 K(k) / lambda (Landau and Lifshitz, section 37). */
static double flip_half_period(vec3 i, vec3 w)
{
    double L2 = i.x * i.x * w.x * w.x + i.y * i.y * w.y * w.y + i.z * i.z * w.z * w.z;
    double E2 = i.x * w.x * w.x + i.y * w.y * w.y + i.z * w.z * w.z;
    double lambda, k2;
    if (L2 > E2 * i.y) { /* circulates about the major axis */
        lambda = sqrt((i.z - i.y) * (L2 - E2 * i.x) / (i.x * i.y * i.z));
        k2 = (i.y - i.x) * (E2 * i.z - L2) / ((i.z - i.y) * (L2 - E2 * i.x));
    } else {             /* about the minor axis */
        lambda = sqrt((i.y - i.x) * (E2 * i.z - L2) / (i.x * i.y * i.z));
        k2 = (i.z - i.y) * (L2 - E2 * i.x) / ((i.y - i.x) * (E2 * i.z - L2));
    }
    return 2.0 * elliptic_k(sqrt(k2)) / lambda;
}

/* ---- the pure step ---------------------------------------------------------- */

static void test_midpoint_step_keeps_invariants(void **state)
{
    (void)state;
    vec3 I = box_inertia(1.0, HX, HY, HZ);
    mat3 Ibi = m3_diag(v3(1 / I.x, 1 / I.y, 1 / I.z));
    const double hs[3] = {1.0 / 60, 1.0 / 240, 1.0 / 8000};
    for (int k = 0; k < 3; k++) {
        /* tilted start: every axis moves */
        quat q = q_normalize((quat){0.9, 0.2, -0.3, 0.1});
        vec3 L = v3(0.3, -1.1, 0.7);
        vec3 lb = q_inv_rotate(q, L);
        double e0 = 0.5 * v3_dot(lb, m3_mulv(Ibi, lb));
        int n = (int)(5.0 / hs[k]);
        for (int i = 0; i < n; i++) q = rotation_free_step(q, &Ibi, L, hs[k], NULL);
        lb = q_inv_rotate(q, L);
        double e = 0.5 * v3_dot(lb, m3_mulv(Ibi, lb));
        print_message("h %g: energy drift %.3e over 5 s\n", hs[k], e / e0 - 1);
        assert_true(fabs(e / e0 - 1) < 1e-10);
    }
}

/* A body turning many radians in one sub-step (an impulse mid-step can
 * give it that: the clamp acts only at the step's ends), where Newton from
 * the starting momentum used to run off to inf (two fuzz findings): the step
 * stays a unit quaternion, the energy is kept to 1e-9 and the rate it
 * reports is no faster than the body turns (|w_mid| <= |w| for any root,
 * up to the halving's averaging). The box, tilted, 8..2000 rad. */
static void test_midpoint_step_fast_turns(void **state)
{
    (void)state;
    vec3 I = box_inertia(0.0116, 0.047, 0.69, 0.18);
    mat3 Ibi = m3_diag(v3(1 / I.x, 1 / I.y, 1 / I.z));
    const double turns[5] = {8.3, 52.6, 157.4, 800.0, 2000.0};
    for (int k = 0; k < 5; k++) {
        quat q = q_normalize((quat){0.9, 0.2, -0.3, 0.1});
        vec3 wb = v3_normalize(v3(1.0, 0.7, -0.4)); /* body-frame direction of the rate */
        double h = 0.188;
        wb = v3_scale(wb, turns[k] / h);
        vec3 L = q_rotate(q, v3_mul(I, wb));
        vec3 lb = q_inv_rotate(q, L);
        double e0 = 0.5 * v3_dot(lb, m3_mulv(Ibi, lb)), wmax = v3_len(m3_mulv(Ibi, lb));
        for (int i = 0; i < 4; i++) {
            vec3 wm;
            q = rotation_free_step(q, &Ibi, L, h, &wm);
            assert_true(isfinite(wm.x) && isfinite(wm.y) && isfinite(wm.z));
            /* |w_mid| = |I^-1 y| with |y| <= |y0|: no faster than the fastest rate of that |L| */
            double fastest = v3_len(L) / fmin(I.x, fmin(I.y, I.z));
            assert_true(v3_len(wm) <= fastest * (1 + 1e-9));
        }
        double qn = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
        lb = q_inv_rotate(q, L);
        double e = 0.5 * v3_dot(lb, m3_mulv(Ibi, lb));
        print_message("%.1f rad per step (|w| %.0f rad/s): |q| - 1 = %.1e, energy drift %.2e\n", turns[k], wmax,
                      qn - 1, e / e0 - 1);
        assert_true(fabs(qn - 1) < 1e-12);
        assert_true(fabs(e / e0 - 1) < 1e-9);
    }
}

/* Pure step, intermediate axis: the flip time between sign changes of w2. */
static double measured_half_period(double h, double seconds, int *flips)
{
    vec3 I = box_inertia(1.0, HX, HY, HZ);
    mat3 Ibi = m3_diag(v3(1 / I.x, 1 / I.y, 1 / I.z));
    vec3 w0 = v3(0.01, 10, 0.01);
    vec3 L = v3_mul(I, w0);
    quat q = q_identity();
    double prev = w0.y, t = 0, first = -1, last = -1;
    int n = 0;
    for (int i = 0; i < (int)(seconds / h + 0.5); i++) {
        q = rotation_free_step(q, &Ibi, L, h, NULL);
        t += h;
        double w2 = m3_mulv(Ibi, q_inv_rotate(q, L)).y;
        if ((w2 < 0) != (prev < 0)) {
            double tc = t - h * w2 / (w2 - prev); /* linear interpolation of the crossing */
            if (first < 0) first = tc;
            last = tc;
            n++;
        }
        prev = w2;
    }
    *flips = n;
    return n >= 2 ? (last - first) / (n - 1) : -1;
}

static void test_midpoint_step_flip_period(void **state)
{
    (void)state;
    double want = flip_half_period(box_inertia(1.0, HX, HY, HZ), v3(0.01, 10, 0.01));
    const double hs[3] = {1.0 / 60, 1.0 / 240, 1.0 / 1000};
    for (int k = 0; k < 3; k++) {
        int flips;
        double got = measured_half_period(hs[k], 20.0, &flips);
        print_message("h %g: %d flips, half-period %.4f s (Euler %.4f s)\n", hs[k], flips, got, want);
        assert_true(flips >= 2);
        assert_true(fabs(got / want - 1) < 0.02);
    }
}

/* ---- through the world ------------------------------------------------------ */

typedef struct spin_result {
    double energy_drift, momentum_drift, max_tilt_deg, half_period;
    int flips;
} spin_result;

static carom_vec3 cv(double x, double y, double z) { carom_vec3 v = {x, y, z}; return v; }

/* Spins a body (box or rod) about body axis `axis` at rate w, zero gravity,
 * for `seconds`; reports the drifts, the largest tilt of that body axis from
 * its start direction, and the intermediate-axis flip half-period. */
static spin_result spin_run(const char *preset, double dt, double seconds, carom_shape_def shape, double mass,
                            int axis, double rate, double wobble, carom_vec3 at)
{
    carom_world_def wd = carom_world_def_default();
    assert_int_equal(carom_world_def_apply_preset(&wd, preset), CAROM_OK);
    wd.gravity = cv(0, 0, 0);
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def d = carom_body_def_default();
    d.shape = shape;
    d.mass = mass;
    d.position = at;
    d.angular_velocity = cv(axis == 0 ? rate : wobble, axis == 1 ? rate : wobble, axis == 2 ? rate : wobble);
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    double e0, pe, e;
    carom_vec3 p0, L0, p, L;
    assert_int_equal(carom_world_get_energy(w, &e0, &pe), CAROM_OK);
    assert_int_equal(carom_world_get_momentum(w, &p0, &L0), CAROM_OK);
    spin_result r = {0, 0, 0, -1, 0};
    double prev = rate, t = 0, first = -1, last = -1;
    int n = (int)(seconds / dt + 0.5);
    for (int i = 0; i < n; i++) {
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        t += dt;
        carom_quat cq;
        carom_vec3 wv;
        carom_body_get_orientation(w, id, &cq);
        carom_body_get_angular_velocity(w, id, &wv);
        quat q = {cq.w, cq.x, cq.y, cq.z};
        vec3 e_axis = q_rotate(q, v3(axis == 0, axis == 1, axis == 2));
        double c = fabs(v3_get(e_axis, axis));
        double tilt = acos(c > 1 ? 1 : c) * 180.0 / PI_;
        if (tilt > r.max_tilt_deg) r.max_tilt_deg = tilt;
        double wb = v3_get(q_inv_rotate(q, v3(wv.x, wv.y, wv.z)), axis);
        if ((wb < 0) != (prev < 0)) {
            double tc = t - dt * wb / (wb - prev);
            if (first < 0) first = tc;
            last = tc;
            r.flips++;
        }
        prev = wb;
        assert_int_equal(carom_world_get_energy(w, &e, &pe), CAROM_OK);
        assert_int_equal(carom_world_get_momentum(w, &p, &L), CAROM_OK);
        double de = fabs(e / e0 - 1);
        double dl = sqrt((L.x - L0.x) * (L.x - L0.x) + (L.y - L0.y) * (L.y - L0.y) + (L.z - L0.z) * (L.z - L0.z)) /
                    sqrt(L0.x * L0.x + L0.y * L0.y + L0.z * L0.z);
        if (de > r.energy_drift) r.energy_drift = de;
        if (dl > r.momentum_drift) r.momentum_drift = dl;
    }
    if (r.flips >= 2) r.half_period = (last - first) / (r.flips - 1);
    carom_world_destroy(w);
    return r;
}

static const char *PRESETS[3] = {"fast", "default", "accurate"};

/* Major (z) and minor (x) axis spins at 10 rad/s: L to 1e-9, energy to 0.1 %,
 * within 1 degree of the axis for 20 s. */
static void test_box_stable_axes(void **state)
{
    (void)state;
    const double dts[3] = {1.0 / 15, 1.0 / 60, 1.0 / 1000};
    const carom_vec3 places[2] = {{0, 0, 0}, {1e4, -2e4, 5e3}};
    for (int pr = 0; pr < 3; pr++)
        for (int k = 0; k < 3; k++)
            for (int ax = 0; ax < 3; ax += 2) {
                carom_vec3 at = places[(pr + k + ax) % 2];
                double seconds = dts[k] < 0.01 ? 5.0 : 20.0; /* dt 1/1000: 5 s keeps make check fast */
                spin_result r = spin_run(PRESETS[pr], dts[k], seconds, carom_shape_box(HX, HY, HZ), 1.0, ax, 10.0, 0.01, at);
                print_message("%s dt 1/%.0f axis %c at x %.0f: energy %.2e, L %.2e, tilt %.3f deg\n", PRESETS[pr],
                              1 / dts[k], "xyz"[ax], at.x, r.energy_drift, r.momentum_drift, r.max_tilt_deg);
                assert_true(r.momentum_drift < 1e-9);
                assert_true(r.energy_drift < 1e-3);
                assert_true(r.max_tilt_deg < 1.0);
            }
}

/* Intermediate axis (y): flips with Euler's half-period within 2 %. */
static void test_box_intermediate_axis_flips(void **state)
{
    (void)state;
    double want = flip_half_period(box_inertia(1.0, HX, HY, HZ), v3(0.01, 10, 0.01));
    const double dts[3] = {1.0 / 15, 1.0 / 60, 1.0 / 240};
    for (int pr = 0; pr < 3; pr++)
        for (int k = 0; k < 3; k++) {
            spin_result r = spin_run(PRESETS[pr], dts[k], 20.0, carom_shape_box(HX, HY, HZ), 1.0, 1, 10.0, 0.01, cv(0, 0, 0));
            print_message("%s dt 1/%.0f: %d flips, half-period %.4f s (Euler %.4f), energy %.2e, L %.2e\n",
                          PRESETS[pr], 1 / dts[k], r.flips, r.half_period, want, r.energy_drift, r.momentum_drift);
            assert_true(r.flips >= 2);
            assert_true(fabs(r.half_period / want - 1) < 0.02);
            assert_true(r.momentum_drift < 1e-9);
            assert_true(r.energy_drift < 1e-3);
        }
}

/* The same box scaled (x0.1 and x10, mass 0.01 and 1000 kg) and spun faster:
 * the flip period scales as 1/w, the invariants hold. */
static void test_box_sizes_and_rates(void **state)
{
    (void)state;
    const double scales[2] = {0.1, 10.0}, masses[2] = {0.01, 1000.0}, rates[2] = {30.0, 3.0};
    for (int k = 0; k < 2; k++) {
        double s = scales[k];
        vec3 I = box_inertia(masses[k], HX * s, HY * s, HZ * s);
        double want = flip_half_period(I, v3(0.01, rates[k], 0.01));
        spin_result r = spin_run("default", 1.0 / 60, 20.0, carom_shape_box(HX * s, HY * s, HZ * s), masses[k], 1,
                                 rates[k], 0.01, cv(0, 0, 0));
        print_message("scale %g, %g rad/s: %d flips, half-period %.4f (Euler %.4f), energy %.2e, L %.2e\n", s,
                      rates[k], r.flips, r.half_period, want, r.energy_drift, r.momentum_drift);
        assert_true(r.flips >= 2);
        assert_true(fabs(r.half_period / want - 1) < 0.02);
        assert_true(r.momentum_drift < 1e-9);
        assert_true(r.energy_drift < 1e-3);
    }
}

/* A 1 m x 1 cm rod spun at 900 rad/s about its long axis (1 rad/s off it)
 * keeps L and energy within 1 % over 5 s (more than half a turn per sub-step: the clamp at
 * 1000 rad/s must not cut in, and nothing may blow up). */
static void test_fast_rod(void **state)
{
    (void)state;
    for (int pr = 0; pr < 3; pr++) {
        spin_result r = spin_run(PRESETS[pr], 1.0 / 60, 5.0, carom_shape_box(0.5, 0.005, 0.005), 1.0, 0, 900.0,
                                 1.0, cv(0, 0, 0));
        print_message("%s rod: energy %.2e, L %.2e, tilt %.3f deg\n", PRESETS[pr], r.energy_drift, r.momentum_drift,
                      r.max_tilt_deg);
        assert_true(r.energy_drift < 0.01);
        assert_true(r.momentum_drift < 0.01);
    }
}

/* The quarter-turn rule: at the default (automatic) max_angular_speed the
 * clamp never alters a body turning less than a quarter turn per sub-step,
 * at every preset and dt 1/15..1/1000; above both that and 1000 rad/s it
 * clamps to exactly the larger of the two; an explicit cap is honoured even
 * where it clamps a slow body. A sphere (|w| constant when free) and the
 * issue's box about its major axis (|w| constant to the integrator's
 * round-off). */
static double spin_after(carom_world *w, carom_body_id id, int steps, double dt, long *clamped)
{
    *clamped = 0;
    for (int i = 0; i < steps; i++) { /* stats.clamped counts the last step's */
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
        *clamped += st.clamped;
    }
    carom_vec3 wv;
    assert_int_equal(carom_body_get_angular_velocity(w, id, &wv), CAROM_OK);
    return sqrt(wv.x * wv.x + wv.y * wv.y + wv.z * wv.z);
}

static void test_quarter_turn_rule(void **state)
{
    (void)state;
    const double dts[5] = {1.0 / 15, 1.0 / 30, 1.0 / 60, 1.0 / 240, 1.0 / 1000};
    for (int pr = 0; pr < 3; pr++)
        for (int k = 0; k < 5; k++)
            for (int shape = 0; shape < 2; shape++) {
                carom_world_def d = carom_world_def_default();
                assert_int_equal(carom_world_def_apply_preset(&d, PRESETS[pr]), CAROM_OK);
                d.gravity = cv(0, 0, 0);
                double h = dts[k] / d.substeps, quarter = 0.5 * PI_ / h;
                double clamp = quarter > 1000.0 ? quarter : 1000.0;
                double rates[2] = {0.999 * quarter, 1.5 * clamp};
                for (int r = 0; r < 2; r++) {
                    carom_world *w = carom_world_create(&d);
                    assert_non_null(w);
                    carom_body_def b = carom_body_def_default();
                    b.shape = shape ? carom_shape_box(HX, HY, HZ) : carom_shape_sphere(0.3);
                    b.mass = 1.0;
                    b.angular_velocity = cv(0, 0, rates[r]);
                    carom_body_id id = carom_body_create(w, &b);
                    assert_false(carom_body_id_is_null(id));
                    long clamped;
                    double got = spin_after(w, id, 3, dts[k], &clamped);
                    print_message("%s dt 1/%.0f %s at %.0f rad/s (quarter turn %.0f): %.6f rad/s, clamped %ld\n",
                                  PRESETS[pr], 1 / dts[k], shape ? "box" : "sphere", rates[r], quarter, got, clamped);
                    if (r == 0) {
                        assert_int_equal(clamped, 0);
                        assert_true(fabs(got / rates[r] - 1) < 1e-9);
                    } else {
                        assert_true(clamped >= 1);
                        assert_true(fabs(got / clamp - 1) < 1e-9);
                    }
                    carom_world_destroy(w);
                }
                /* an explicit cap, lowered below the body's spin, is honoured */
                d.max_angular_speed = 0.5 * quarter;
                carom_world *w = carom_world_create(&d);
                carom_body_def b = carom_body_def_default();
                b.shape = carom_shape_sphere(0.3);
                b.angular_velocity = cv(0, 0, 0.4 * quarter);
                carom_body_id id = carom_body_create(w, &b);
                assert_false(carom_body_id_is_null(id));
                assert_int_equal(carom_body_set_angular_velocity(w, id, cv(0, 0, 0.6 * quarter)),
                                 CAROM_ERROR_INVALID_ARGUMENT);
                d.max_angular_speed = 0.1 * quarter;
                assert_int_equal(carom_world_set_def(w, &d), CAROM_OK);
                long clamped;
                double got = spin_after(w, id, 2, dts[k], &clamped);
                assert_true(clamped >= 1);
                assert_true(fabs(got / (0.1 * quarter) - 1) < 1e-9);
                carom_world_destroy(w);
            }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_midpoint_step_keeps_invariants),
        cmocka_unit_test(test_midpoint_step_fast_turns),
        cmocka_unit_test(test_midpoint_step_flip_period),
        cmocka_unit_test(test_box_stable_axes),
        cmocka_unit_test(test_box_intermediate_axis_flips),
        cmocka_unit_test(test_box_sizes_and_rates),
        cmocka_unit_test(test_fast_rod),
        cmocka_unit_test(test_quarter_turn_rule),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
