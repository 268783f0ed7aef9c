/* test_material.c - named materials: every combine mode against its
 * formula (read from the contact the pair makes), the mode priority,
 * friction and restitution through the motion they cause (a box sliding
 * slows at mu g, a ball bounces back at e v), rolling resistance against
 * c g at several c, radii and dt (and 0: a rolling ball keeps its speed),
 * and refused materials naming the field. */
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
#include "world.h"

static carom_material material(double mu, double e, double roll, carom_combine_mode mode)
{
    carom_material m = carom_material_default();
    m.friction = mu;
    m.restitution = e;
    m.rolling_resistance = roll;
    m.combine = mode;
    return m;
}

static double combined(carom_combine_mode mode, int which, double a, double b)
{
    switch (mode) {
    case CAROM_COMBINE_AVERAGE: return (a + b) / 2;
    case CAROM_COMBINE_GEOMETRIC_MEAN: return sqrt(a * b);
    case CAROM_COMBINE_MIN: return a < b ? a : b;
    case CAROM_COMBINE_MULTIPLY: return a * b;
    case CAROM_COMBINE_MAX: return a > b ? a : b;
    default: return which == 0 ? sqrt(a * b) : (a > b ? a : b);
    }
}

/* Two boxes touching, each with its own material: the contact's mixed
 * values follow the higher of the two modes. */
static void test_combine_modes(void **state)
{
    (void)state;
    for (int ma = 0; ma <= CAROM_COMBINE_MAX; ma++)
        for (int mb = 0; mb <= CAROM_COMBINE_MAX; mb++) {
            carom_world *w = world_with(carom_world_def_default(), 0, 0, 0);
            carom_material A = material(0.8, 0.3, 0.05, (carom_combine_mode)ma);
            carom_material B = material(0.2, 0.6, 0.2, (carom_combine_mode)mb);
            carom_body_def d = carom_body_def_default();
            d.shape = carom_shape_box(0.5, 0.5, 0.5);
            d.type = CAROM_BODY_STATIC;
            d.material = &A;
            carom_body_id a = carom_body_create(w, &d);
            d.type = CAROM_BODY_DYNAMIC;
            d.position = vec(0, 0, 1.0);
            d.material = &B;
            carom_body_id b = carom_body_create(w, &d);
            assert_false(carom_body_id_is_null(a) || carom_body_id_is_null(b));
            step_n(w, 1, DT);
            assert_int_equal(w->contacts.count, 1);
            const contact_data *cd = CONTACT_DATA(&w->contacts, 0);
            carom_combine_mode mode = (carom_combine_mode)(ma > mb ? ma : mb);
            assert_true(fabs(cd->friction - combined(mode, 0, 0.8, 0.2)) < 1e-15);
            assert_true(fabs(cd->restitution - combined(mode, 1, 0.3, 0.6)) < 1e-15);
            assert_true(fabs(cd->rolling_resistance - combined(mode, 2, 0.05, 0.2)) < 1e-15);
            /* set_material re-mixes the pair now */
            carom_material C = material(0.4, 0.1, 0.0, CAROM_COMBINE_MIN);
            assert_int_equal(carom_body_set_material(w, b, &C), CAROM_OK);
            mode = (carom_combine_mode)(ma > CAROM_COMBINE_MIN ? ma : CAROM_COMBINE_MIN);
            assert_true(fabs(cd->friction - combined(mode, 0, 0.8, 0.4)) < 1e-15);
            carom_material got = carom_material_default();
            assert_int_equal(carom_body_get_material(w, b, &got), CAROM_OK);
            assert_true(got.friction == 0.4 && got.restitution == 0.1 && got.combine == CAROM_COMBINE_MIN);
            carom_world_destroy(w);
        }
}

/* A compound child's material is that child's alone. */
static void test_child_material(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 1, 0.5, 0);
    carom_material ice = material(0.02, 0.0, 0.0, CAROM_COMBINE_MIN);
    carom_compound_child ch[2] = {carom_compound_child_default(carom_shape_box(0.25, 0.25, 0.25)),
                                  carom_compound_child_default(carom_shape_box(0.25, 0.25, 0.25))};
    ch[0].position = vec(-0.5, 0, 0);
    ch[1].position = vec(0.5, 0, 0);
    ch[1].material = &ice;
    carom_body_def d = carom_body_def_default();
    d.shape.type = CAROM_SHAPE_COMPOUND;
    d.children = ch;
    d.child_count = 2;
    d.position = vec(0, 0, 0.25);
    carom_body_id b = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(b));
    step_n(w, 2, DT);
    int seen = 0;
    for (int k = 0; k < w->contacts.count; k++) {
        const contact_data *cd = CONTACT_DATA(&w->contacts, k);
        if (cd->m.count == 0) continue;
        double x = cd->m.points[0].point.x;
        double want = x > 0 ? 0.02 : sqrt(0.5 * 0.6);
        assert_true(fabs(cd->friction - want) < 1e-15);
        seen++;
    }
    assert_int_equal(seen, 2);
    carom_world_destroy(w);
}

/* Friction through motion: a box launched along the floor slows at mu g
 * with mu = the MULTIPLY mix; restitution: a ball dropped on the floor
 * leaves at e v with e = the MIN mix. */
static void test_friction_and_restitution_in_motion(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    carom_material floor_m = material(0.5, 0.9, 0, CAROM_COMBINE_MULTIPLY);
    carom_material box_m = material(0.6, 0.5, 0, CAROM_COMBINE_DEFAULT);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    g.material = &floor_m;
    carom_body_create(w, &g);
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_box(0.25, 0.25, 0.25);
    d.position = vec(0, 0, 0.25);
    d.linear_velocity = vec(4, 0, 0);
    d.material = &box_m;
    d.enable_sleep = 0;
    carom_body_id b = carom_body_create(w, &d);
    step_n(w, 6, DT);
    double v1 = vel(w, b).x;
    step_n(w, 30, DT);
    double v2 = vel(w, b).x;
    double mu = 0.5 * 0.6;
    EXPECT_NEAR((v1 - v2) / (30 * DT), mu * G, 0.01 * mu * G, "sliding deceleration = mu_a mu_b g (MULTIPLY)");
    carom_world_destroy(w);

    w = carom_world_create(&wd);
    carom_material floor_e = material(0.5, 0.9, 0, CAROM_COMBINE_MIN);
    g.material = &floor_e;
    carom_body_create(w, &g);
    carom_body_def s = carom_body_def_default();
    s.shape = carom_shape_sphere(0.2);
    s.position = vec(0, 0, 0.2 + 1e-3);
    s.linear_velocity = vec(0, 0, -5);
    s.gravity_scale = 0;
    carom_material ball = material(0.5, 0.7, 0, CAROM_COMBINE_DEFAULT);
    s.material = &ball;
    carom_body_id sb = carom_body_create(w, &s);
    step_n(w, 10, DT);
    EXPECT_NEAR(vel(w, sb).z, 0.7 * 5, 0.01 * 3.5, "bounce speed = min(e_a, e_b) v (MIN)");
    carom_world_destroy(w);
}

/* A ball rolling on a flat floor with rolling resistance c slows at c g,
 * at several c, radii and dt; with c = 0 it keeps its speed. */
static void test_rolling_resistance(void **state)
{
    (void)state;
    const double cs[] = {0.02, 0.1, 0.3};
    const double radii[] = {0.05, 0.5, 2.0};
    const double dts[] = {1.0 / 30, 1.0 / 60, 1.0 / 240};
    double worst = 0;
    for (int ci = 0; ci < 3; ci++)
        for (int ri = 0; ri < 3; ri++)
            for (int k = 0; k < 3; k++) {
                double c = cs[ci], r = radii[ri], dt = dts[k];
                carom_world_def wd = carom_world_def_default();
                carom_world *w = carom_world_create(&wd);
                carom_material floor_m = material(1.0, 0, c, CAROM_COMBINE_DEFAULT);
                carom_body_def g = carom_body_def_default();
                g.type = CAROM_BODY_STATIC;
                g.shape = carom_shape_plane(0, 0, 1, 0);
                g.material = &floor_m;
                carom_body_create(w, &g);
                carom_material ball_m = material(1.0, 0, 0, CAROM_COMBINE_DEFAULT);
                carom_body_def d = carom_body_def_default();
                d.shape = carom_shape_sphere(r);
                d.position = vec(0, 0, r);
                double v0 = 4.0;
                d.linear_velocity = vec(v0, 0, 0);
                d.angular_velocity = vec(0, v0 / r, 0); /* rolling: the contact point is still */
                d.material = &ball_m;
                d.enable_sleep = 0;
                carom_body_id b = carom_body_create(w, &d);
                /* long enough to measure, short enough not to stop: v0 / (c g) */
                double t_stop = v0 / (c * G);
                int n1 = (int)lround(0.1 * t_stop / dt) + 2, n2 = (int)lround(0.6 * t_stop / dt) + 2;
                step_n(w, n1, dt);
                double v1 = vel(w, b).x;
                step_n(w, n2 - n1, dt);
                double v2 = vel(w, b).x;
                double decel = (v1 - v2) / ((n2 - n1) * dt);
                double err = fabs(decel - c * G) / (c * G);
                if (err > worst) worst = err;
                if (err > 0.01)
                    fail_msg("c %g r %g dt %.4f: slows at %.5g m/s^2, c g = %.5g", c, r, dt, decel, c * G);
                /* still rolling, not sliding */
                carom_vec3 av;
                carom_body_get_angular_velocity(w, b, &av);
                assert_true(fabs(av.y * r - v2) < 1e-3 * v0);
                carom_world_destroy(w);
            }
    print_message("rolling resistance: worst |a - c g| / c g = %.3g over 27 cases\n", worst);
    /* c = 0 (the default): the textbook ball rolls on unslowed */
    carom_world *w = world_with(carom_world_def_default(), 1, 1.0, 0);
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(0.5);
    d.position = vec(0, 0, 0.5);
    d.linear_velocity = vec(4, 0, 0);
    d.angular_velocity = vec(0, 8, 0);
    d.enable_sleep = 0;
    carom_body_id b = carom_body_create(w, &d);
    step_n(w, 120, DT);
    /* (the soft contact costs it 2e-5 of its speed over 2 s, rolling resistance or not) */
    EXPECT_NEAR(vel(w, b).x, 4.0, 1e-4, "no rolling resistance: speed kept");
    carom_world_destroy(w);
}

/* Rolling resistance stops a rolling ball after v^2 / (2 c g) and holds it
 * there (the clamp never pushes it backwards). */
static void test_rolling_resistance_stops(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    carom_material floor_m = material(1.0, 0, 0.1, CAROM_COMBINE_DEFAULT);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    g.material = &floor_m;
    carom_body_create(w, &g);
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(0.3);
    d.position = vec(0, 0, 0.3);
    d.linear_velocity = vec(0.5, 0, 0);
    d.angular_velocity = vec(0, 0.5 / 0.3, 0);
    d.enable_sleep = 0;
    carom_body_id b = carom_body_create(w, &d);
    step_n(w, 120, DT); /* stops after 0.5 / (0.1 g) = 0.51 s */
    carom_vec3 v = vel(w, b), av;
    carom_body_get_angular_velocity(w, b, &av);
    assert_true(fabs(v.x) < 1e-6 && fabs(av.y) < 1e-5);
    EXPECT_NEAR(pos(w, b).x, 0.5 * 0.5 / (2 * 0.1 * G), 0.01 * 0.5 * 0.5 / (2 * 0.1 * G), "stopping distance v^2 / (2 c g)");
    carom_world_destroy(w);
}

static void test_bad_materials(void **state)
{
    (void)state;
    char msg[160];
    carom_material m = carom_material_default();
    assert_int_equal(carom_material_check(&m, msg, sizeof msg), CAROM_OK);
    m.friction = NAN;
    assert_int_equal(carom_material_check(&m, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "friction"));
    m = carom_material_default();
    m.restitution = 1.5;
    assert_int_equal(carom_material_check(&m, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "restitution"));
    m = carom_material_default();
    m.rolling_resistance = -0.1;
    assert_int_equal(carom_material_check(&m, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "rolling_resistance"));
    m = carom_material_default();
    m.combine = (carom_combine_mode)17;
    assert_int_equal(carom_material_check(&m, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "combine"));
    assert_int_equal(carom_material_check(NULL, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);

    carom_world *w = world_with(carom_world_def_default(), 0, 0, 0);
    carom_body_def d = carom_body_def_default();
    d.material = &m;
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    assert_non_null(strstr(carom_world_last_error(w), "combine"));
    assert_int_equal(carom_world_body_count(w), 0);
    d.material = NULL;
    d.friction = 0.3;
    carom_body_id b = carom_body_create(w, &d);
    assert_int_equal(carom_body_set_material(w, b, &m), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_material(w, b, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    double mu;
    carom_body_get_friction(w, b, &mu);
    assert_true(mu == 0.3); /* unchanged */
    carom_compound_child ch = carom_compound_child_default(carom_shape_sphere(0.2));
    ch.material = &m;
    d.shape.type = CAROM_SHAPE_COMPOUND;
    d.children = &ch;
    d.child_count = 1;
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    assert_non_null(strstr(carom_world_last_error(w), "children[0]"));
    carom_body_destroy(w, b);
    carom_material ok = carom_material_default();
    assert_int_equal(carom_body_set_material(w, b, &ok), CAROM_ERROR_STALE_ID);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_combine_modes),
        cmocka_unit_test(test_child_material),
        cmocka_unit_test(test_friction_and_restitution_in_motion),
        cmocka_unit_test(test_rolling_resistance),
        cmocka_unit_test(test_rolling_resistance_stops),
        cmocka_unit_test(test_bad_materials),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
