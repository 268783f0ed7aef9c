/* test_forces.c - torques and forces at a point against the impulse they
 * deliver (L grows by tau t, p by F t), contact force events against the
 * weight they carry (a resting box m g; the bottom contact of a stack the
 * weight of all above it), and refused input leaving the body unchanged. */
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

static carom_world *zero_g(double dt_hint)
{
    (void)dt_hint;
    carom_world_def d = carom_world_def_default();
    d.gravity.z = 0;
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    return w;
}

static carom_body_id free_body(carom_world *w, carom_shape_def shape, double mass, carom_quat q)
{
    carom_body_def d = carom_body_def_default();
    d.shape = shape;
    d.mass = mass;
    d.orientation = q;
    d.enable_sleep = 0;
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    return id;
}

/* Angular momentum of a world about the origin (r x p + I w). */
static carom_vec3 world_L(carom_world *w)
{
    carom_vec3 p, L;
    assert_int_equal(carom_world_get_momentum(w, &p, &L), CAROM_OK);
    return L;
}

/* A constant torque on a sphere: w = tau t / I, every dt; and on a tumbling
 * box (no symmetry) the angular momentum is still tau t exactly. */
static void test_constant_torque(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 1000};
    carom_quat id = {1, 0, 0, 0};
    for (int k = 0; k < 3; k++) {
        double dt = dts[k], r = 0.3, m = 2.0, I = 0.4 * m * r * r;
        carom_world *w = zero_g(dt);
        carom_body_id s = free_body(w, carom_shape_sphere(r), m, id);
        carom_vec3 tau = {0.3, -0.2, 0.5};
        int n = (int)lround(1.0 / dt);
        for (int i = 0; i < n; i++) {
            assert_int_equal(carom_body_apply_torque(w, s, tau), CAROM_OK);
            step_n(w, 1, dt);
        }
        double t = n * dt;
        carom_vec3 av;
        carom_body_get_angular_velocity(w, s, &av);
        char what[64];
        snprintf(what, sizeof what, "sphere w.x at dt %.4f", dt);
        EXPECT_NEAR(av.x, tau.x * t / I, 1e-9 * fabs(tau.x * t / I), what);
        EXPECT_NEAR(av.y, tau.y * t / I, 1e-9 * fabs(tau.y * t / I), "sphere w.y");
        EXPECT_NEAR(av.z, tau.z * t / I, 1e-9 * fabs(tau.z * t / I), "sphere w.z");
        carom_vec3 v = vel(w, s);
        assert_true(v.x == 0 && v.y == 0 && v.z == 0); /* a pure torque moves nothing */

        double c = cos(0.4), sn = sin(0.4);
        carom_quat q = {c, sn * 0.6, 0, sn * 0.8};
        carom_world_destroy(w);
        w = zero_g(dt); /* alone: the box turns about its centre at the origin, p = 0 */
        carom_body_id b = free_body(w, carom_shape_box(0.5, 0.2, 0.1), 3.0, q);
        for (int i = 0; i < n; i++) {
            assert_int_equal(carom_body_apply_torque(w, b, tau), CAROM_OK);
            step_n(w, 1, dt);
        }
        carom_vec3 L = world_L(w);
        EXPECT_NEAR(L.x, tau.x * t, 1e-7, "box L.x = tau.x t");
        EXPECT_NEAR(L.y, tau.y * t, 1e-7, "box L.y = tau.y t");
        EXPECT_NEAR(L.z, tau.z * t, 1e-7, "box L.z = tau.z t");
        carom_world_destroy(w);
    }
}

/* A force at a point off the centre of mass, for one step: the momentum
 * grows by F dt and the spin momentum by (p - c) x F dt. Over many steps
 * the same force at the centre only accelerates: v = F t / m. */
static void test_force_at_point(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 240};
    carom_quat id = {1, 0, 0, 0};
    for (int k = 0; k < 3; k++) {
        double dt = dts[k], m = 4.0;
        carom_world *w = zero_g(dt);
        carom_body_id b = free_body(w, carom_shape_box(0.5, 0.3, 0.2), m, id);
        carom_vec3 c = pos(w, b), F = {0, 10, 2}, arm = {0.5, 0.1, -0.2};
        carom_vec3 p = {c.x + arm.x, c.y + arm.y, c.z + arm.z};
        assert_int_equal(carom_body_apply_force_at_point(w, b, F, p), CAROM_OK);
        carom_vec3 f, t;
        assert_int_equal(carom_body_get_applied_force(w, b, &f, &t), CAROM_OK);
        carom_vec3 want_t = {arm.y * F.z - arm.z * F.y, arm.z * F.x - arm.x * F.z, arm.x * F.y - arm.y * F.x};
        assert_true(f.x == F.x && f.y == F.y && f.z == F.z);
        EXPECT_NEAR(t.x, want_t.x, 1e-12, "accumulated torque x");
        step_n(w, 1, dt);
        carom_vec3 v = vel(w, b), L = world_L(w); /* the centre is at the origin: r x p = 0 at the start */
        EXPECT_NEAR(v.y, F.y * dt / m, 1e-12, "v.y = F.y dt / m");
        EXPECT_NEAR(v.z, F.z * dt / m, 1e-12, "v.z = F.z dt / m");
        EXPECT_NEAR(L.x, want_t.x * dt, 1e-9, "L.x = ((p - c) x F).x dt");
        EXPECT_NEAR(L.y, want_t.y * dt, 1e-9, "L.y");
        EXPECT_NEAR(L.z, want_t.z * dt, 1e-9, "L.z");
        /* the force is for one step only */
        assert_int_equal(carom_body_get_applied_force(w, b, &f, &t), CAROM_OK);
        assert_true(f.x == 0 && f.y == 0 && f.z == 0 && t.x == 0 && t.y == 0 && t.z == 0);
        carom_world_destroy(w);
    }
}

/* Static, kinematic and rotation-locked bodies take no torque; refused input
 * (NaN, stale id) changes nothing and names the argument. */
static void test_refused_torque(void **state)
{
    (void)state;
    carom_world *w = zero_g(DT);
    carom_quat id = {1, 0, 0, 0};
    carom_body_id b = free_body(w, carom_shape_sphere(0.5), 1.0, id);
    carom_vec3 nan3 = {NAN, 0, 0}, ok = {1, 0, 0}, f, t;
    assert_int_equal(carom_body_apply_torque(w, b, nan3), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(carom_world_last_error(w), "torque"));
    assert_int_equal(carom_body_apply_force_at_point(w, b, ok, nan3), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(carom_world_last_error(w), "point"));
    assert_int_equal(carom_body_apply_force_at_point(w, b, nan3, ok), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(carom_world_last_error(w), "force"));
    carom_vec3 huge = {1e300, 0, 0}, far = {0, 1e300, 0};
    assert_int_equal(carom_body_apply_force_at_point(w, b, huge, far), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_apply_torque(w, b, huge), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_get_applied_force(w, b, &f, &t), CAROM_OK);
    assert_true(f.x == 0 && t.x == 0 && t.y == 0 && t.z == 0); /* nothing kept from the refused calls */
    assert_int_equal(carom_body_set_force_threshold(w, b, -1), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(carom_world_last_error(w), "threshold"));
    assert_int_equal(carom_body_set_force_threshold(w, b, NAN), CAROM_ERROR_INVALID_ARGUMENT);
    double th = -1;
    assert_int_equal(carom_body_get_force_threshold(w, b, &th), CAROM_OK);
    assert_true(th == 0);

    carom_body_def ld = carom_body_def_default();
    ld.lock_rotation = 1;
    ld.position.x = 3;
    carom_body_id locked = carom_body_create(w, &ld);
    assert_int_equal(carom_body_apply_torque(w, locked, ok), CAROM_OK);
    carom_body_def sd = carom_body_def_default();
    sd.type = CAROM_BODY_KINEMATIC;
    sd.position.x = -3;
    carom_body_id kin = carom_body_create(w, &sd);
    assert_int_equal(carom_body_apply_torque(w, kin, ok), CAROM_OK);
    step_n(w, 1, DT);
    carom_vec3 av;
    carom_body_get_angular_velocity(w, locked, &av);
    assert_true(av.x == 0 && av.y == 0 && av.z == 0);
    carom_body_get_angular_velocity(w, kin, &av);
    assert_true(av.x == 0 && av.y == 0 && av.z == 0);

    carom_body_destroy(w, b);
    assert_int_equal(carom_body_apply_torque(w, b, ok), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_apply_force_at_point(w, b, ok, ok), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_set_force_threshold(w, b, 1), CAROM_ERROR_STALE_ID);
    carom_body_def bad = carom_body_def_default();
    bad.force_threshold = NAN;
    assert_true(carom_body_id_is_null(carom_body_create(w, &bad)));
    assert_non_null(strstr(carom_world_last_error(w), "force_threshold"));
    carom_world_destroy(w);
}

/* ---- force events ---------------------------------------------------------- */

typedef struct force_log {
    int count;
    carom_contact_event last[8];
} force_log;

static void collect_forces(carom_world *w, force_log *log)
{
    const carom_contact_event *ev;
    int n = carom_world_get_events(w, &ev);
    log->count = 0;
    for (int i = 0; i < n; i++)
        if (ev[i].type == CAROM_EVENT_FORCE && log->count < 8) log->last[log->count++] = ev[i];
}

static carom_body_id stack_box(carom_world *w, double z, double he, double mass, double threshold)
{
    carom_body_def d = carom_body_def_default();
    d.position = vec(0, 0, z);
    d.shape = carom_shape_box(he, he, he);
    d.mass = mass;
    d.enable_sleep = 0;
    d.force_threshold = threshold;
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    return id;
}

/* A box at rest on the ground: one force event a step, equal to m g within
 * 1 %, at masses 0.5..200 kg, dt 1/15..1/1000 and every preset; none when
 * the threshold is above m g or no body asks. */
static void test_resting_box_force(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    const double dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 240, 1.0 / 1000};
    const double masses[] = {0.5, 10.0, 200.0};
    double worst = 0;
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 4; k++)
            for (int mi = 0; mi < 3; mi++) {
                carom_world_def wd = carom_world_def_default();
                assert_int_equal(carom_world_def_apply_preset(&wd, presets[p]), CAROM_OK);
                carom_world *w = world_with(wd, 1, 0.6, 0);
                double m = masses[mi], he = 0.25, dt = dts[k];
                carom_body_id b = stack_box(w, he, he, m, 0.5 * m * G);
                step_n(w, (int)lround(1.0 / dt), dt); /* a second to settle */
                force_log log;
                step_n(w, 1, dt);
                collect_forces(w, &log);
                if (log.count != 1)
                    fail_msg("%s dt %.4f m %g: %d force events, expected 1", presets[p], dt, m, log.count);
                const carom_contact_event *e = &log.last[0];
                assert_true(carom_body_id_equal(e->a, b) || carom_body_id_equal(e->b, b));
                double err = fabs(e->average_force - m * G) / (m * G);
                if (err > worst) worst = err;
                if (err > 0.01)
                    fail_msg("%s dt %.4f m %g: force %.6g N, m g = %.6g N", presets[p], dt, m, e->average_force, m * G);
                assert_true(fabs(e->normal_impulse - e->average_force * dt) <= 1e-9 * m * G * dt);
                assert_true(fabs(fabs(e->normal.z) - 1.0) < 1e-9);
                if (!(fabs(e->point.x) < 1e-3 && fabs(e->point.y) < 1e-3 && fabs(e->point.z) < 0.01))
                    fail_msg("centre of pressure (%g, %g, %g), not under the box's centre", e->point.x, e->point.y,
                             e->point.z);
                /* above the weight: no event */
                assert_int_equal(carom_body_set_force_threshold(w, b, 1.02 * m * G), CAROM_OK);
                step_n(w, 1, dt);
                collect_forces(w, &log);
                assert_int_equal(log.count, 0);
                assert_int_equal(carom_body_set_force_threshold(w, b, 0), CAROM_OK);
                step_n(w, 1, dt);
                collect_forces(w, &log);
                assert_int_equal(log.count, 0);
                carom_world_destroy(w);
            }
    print_message("resting box force events: worst |F - m g| / m g = %.3g over 36 cases\n", worst);
}

/* A stack of three boxes of different masses: each contact carries the
 * weight of everything above it, the bottom one the sum, within 1 %. */
static void test_stack_forces(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++) {
        carom_world_def wd = carom_world_def_default();
        assert_int_equal(carom_world_def_apply_preset(&wd, presets[p]), CAROM_OK);
        carom_world *w = world_with(wd, 1, 0.6, 0);
        double he = 0.25, m[3] = {3.0, 1.0, 2.0};
        carom_body_id b[3];
        for (int i = 0; i < 3; i++) b[i] = stack_box(w, he + 2 * he * i, he, m[i], 0.01);
        step_n(w, 120, DT);
        step_n(w, 1, DT);
        force_log log;
        collect_forces(w, &log);
        assert_int_equal(log.count, 3);
        for (int i = 0; i < 3; i++) {
            double carried = 0;
            for (int j = i; j < 3; j++) carried += m[j] * G;
            int found = 0;
            for (int e = 0; e < log.count; e++) {
                const carom_contact_event *ev = &log.last[e];
                int lower = i == 0 ? -1 : i - 1;
                int has_i = carom_body_id_equal(ev->a, b[i]) || carom_body_id_equal(ev->b, b[i]);
                int has_lower = lower < 0 ? !(carom_body_id_equal(ev->a, b[1]) || carom_body_id_equal(ev->b, b[1]) ||
                                              carom_body_id_equal(ev->a, b[2]) || carom_body_id_equal(ev->b, b[2]))
                                          : (carom_body_id_equal(ev->a, b[lower]) || carom_body_id_equal(ev->b, b[lower]));
                if (!(has_i && has_lower)) continue;
                found = 1;
                char what[80];
                snprintf(what, sizeof what, "%s: contact under box %d carries (N)", presets[p], i);
                EXPECT_NEAR(ev->average_force, carried, 0.01 * carried, what);
            }
            assert_true(found);
        }
        carom_world_destroy(w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant_torque),
        cmocka_unit_test(test_force_at_point),
        cmocka_unit_test(test_refused_torque),
        cmocka_unit_test(test_resting_box_force),
        cmocka_unit_test(test_stack_forces),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
