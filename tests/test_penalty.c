/* test_penalty.c - the penalty contact model: a column of ten unit boxes
 * holds at its default settings (every preset), and an explicit spring the
 * step cannot integrate is refused with a clear error, leaving the bodies
 * where they were; the automatic explicit spring stays stable. */
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

static carom_world *penalty_world(const char *preset, int implicit, double k)
{
    carom_world_def wd = preset_def(preset);
    wd.contact_model = CAROM_CONTACT_PENALTY;
    wd.penalty_implicit = implicit;
    wd.penalty_stiffness = k;
    carom_world *w = world_with(wd, 0, 0.0, 0.0);
    add_ground(w);
    return w;
}

static carom_body_id add_unit_box(carom_world *w, double z)
{
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_box(0.5, 0.5, 0.5);
    d.mass = 1.0;
    d.position = vec(0, 0, z);
    return add_body(w, &d);
}

static carom_body_id add_box_at(carom_world *w, carom_vec3 at, double mass)
{
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_box(0.5, 0.5, 0.5);
    d.mass = mass;
    d.position = at;
    return add_body(w, &d);
}

typedef struct column_result {
    double worst;    /* largest distance of the top box from where it started */
    double sideways; /* largest horizontal distance */
    double final_dz; /* top box's height change at the end */
} column_result;

/* A column of n unit boxes of the given mass, sleep off (nothing may rest on
 * sleeping), built bottom-up or top-down, at the world position at (the
 * ground plane through at.z), for seconds at dt. */
static column_result run_column(carom_world_def wd, int n, double mass, carom_vec3 at, int top_down, double dt,
                                double seconds)
{
    wd.contact_model = CAROM_CONTACT_PENALTY;
    wd.enable_sleep = 0;
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, at.z);
    assert_false(carom_body_id_is_null(carom_body_create(w, &g)));
    carom_body_id box[16];
    for (int k = 0; k < n; k++) {
        int i = top_down ? n - 1 - k : k;
        box[i] = add_box_at(w, vec(at.x, at.y, at.z + 0.5 + i), mass);
    }
    column_result r = {0, 0, 0};
    int steps = (int)(seconds / dt + 0.5);
    for (int s = 0; s < steps; s++) {
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        carom_vec3 t;
        assert_int_equal(carom_body_get_position(w, box[n - 1], &t), CAROM_OK);
        double dx = t.x - at.x, dy = t.y - at.y, dz = t.z - (at.z + n - 0.5);
        double side = sqrt(dx * dx + dy * dy), moved = sqrt(side * side + dz * dz);
        if (moved > r.worst) r.worst = moved;
        if (side > r.sideways) r.sideways = side;
        r.final_dz = dz;
    }
    carom_world_destroy(w);
    return r;
}

static const char *PRESETS[3] = {"fast", "default", "accurate"};

/* Ten unit boxes (1 kg) stacked on the ground, sleep off: the top moves
 * < 5 cm at any moment of 10 s (it settles by the springs' sag) and stays
 * straight (< 1 mm sideways), at every preset, dt 1/30..1/1000, masses
 * 0.1..100 kg, built either way up, far from the origin. */
static void test_penalty_stack_of_ten(void **state)
{
    (void)state;
    const double dts[4] = {1.0 / 30, 1.0 / 60, 1.0 / 240, 1.0 / 1000};
    const double masses[3] = {0.1, 1.0, 100.0};
    const carom_vec3 places[2] = {{0, 0, 0}, {3e4, -2e4, 1e3}};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 4; k++) {
            int v = p + k; /* the variations in turn, not all combinations */
            carom_world_def wd = preset_def(PRESETS[p]);
            double seconds = dts[k] < 0.002 ? 3.0 : 10.0; /* dt 1/1000: 3 s keeps make check fast */
            column_result r = run_column(wd, 10, masses[v % 3], places[v % 2], v % 2, dts[k], seconds);
            print_message("%s dt 1/%.0f mass %g at x %g %s: top moved at most %.4f m, sideways %.2e m, "
                          "ends %.4f m lower\n",
                          PRESETS[p], 1 / dts[k], masses[v % 3], places[v % 2].x, v % 2 ? "top-down" : "bottom-up",
                          r.worst, r.sideways, -r.final_dz);
            assert_true(r.worst < 0.05);
            assert_true(r.sideways < 1e-3);
        }
}

/* With a given spring k per contact point (four corners per face) a column
 * of n boxes of mass m settles by its static sag: interface j from the top
 * carries j m g on 4 springs, so the top sinks m g n (n + 1) / (8 k). */
static void test_penalty_column_sag(void **state)
{
    (void)state;
    const double ks[2] = {5e3, 2e4}; /* h omega up to 1.7 at h = 1/240 (0.125 kg per corner) */
    for (int p = 0; p < 3; p++)
        for (int i = 0; i < 2; i++) {
            int n = 10;
            double m = 1.0;
            carom_world_def wd = preset_def(PRESETS[p]);
            wd.penalty_stiffness = ks[i];
            wd.gravity = vec(0, 0, -9.81);
            column_result r = run_column(wd, n, m, vec(0, 0, 0), 0, 1.0 / 60, 10.0);
            double want = m * 9.81 * n * (n + 1) / (8.0 * ks[i]);
            print_message("%s k %g: sag %.6f m (static %.6f m)\n", PRESETS[p], ks[i], -r.final_dz, want);
            assert_true(fabs(-r.final_dz / want - 1) < 0.01);
            assert_true(r.sideways < 1e-3);
        }
}

/* k = 1e7 N/m on a 1 kg box at h = 1/240 s: h^2 k/m = 174 >> 4. The step is
 * refused naming the setting; the box has not moved; a softer explicit spring
 * (1e4 N/m, with its automatic damper) is accepted and holds the box. */
static void test_unstable_explicit_spring_refused(void **state)
{
    (void)state;
    carom_world *w = penalty_world("default", 0, 1e7);
    carom_body_id box = add_unit_box(w, 0.49);
    carom_vec3 before, after;
    assert_int_equal(carom_body_get_position(w, box, &before), CAROM_OK);
    assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_ERROR_INVALID_ARGUMENT);
    print_message("refused: %s\n", carom_world_last_error(w));
    assert_non_null(strstr(carom_world_last_error(w), "penalty_stiffness"));
    assert_non_null(strstr(carom_world_last_error(w), "substeps"));
    assert_non_null(strstr(carom_world_last_error(w), "penalty_implicit"));
    assert_int_equal(carom_body_get_position(w, box, &after), CAROM_OK);
    assert_true(after.x == before.x && after.y == before.y && after.z == before.z);
    carom_world_def d = carom_world_def_default();
    assert_int_equal(carom_world_get_def(w, &d), CAROM_OK);
    d.penalty_stiffness = 1e4;
    assert_int_equal(carom_world_set_def(w, &d), CAROM_OK);
    for (int i = 0; i < 300; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    assert_int_equal(carom_body_get_position(w, box, &after), CAROM_OK);
    /* static deflection m g / (4 k) per corner spring, 0.25 mm: it rests near z = 0.5 */
    print_message("k 1e4 explicit: box at z %.5f\n", after.z);
    assert_true(fabs(after.z - 0.5) < 0.01);
    carom_world_destroy(w);
}

/* The automatic explicit spring at large steps (dt 1/15..1/60, where 30 Hz
 * at one sub-step would be unstable): a dropped box comes to rest, never
 * higher than it started. */
static void test_automatic_explicit_spring_stable(void **state)
{
    (void)state;
    const double dts[3] = {1.0 / 15, 1.0 / 30, 1.0 / 60};
    for (int k = 0; k < 3; k++) {
        carom_world_def wd = carom_world_def_default();
        wd.contact_model = CAROM_CONTACT_PENALTY;
        wd.penalty_implicit = 0;
        wd.substeps = 1;
        carom_world *w = carom_world_create(&wd);
        assert_non_null(w);
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(0, 0, 1, 0);
        carom_body_create(w, &g);
        carom_body_id box = add_unit_box(w, 0.8);
        double highest = 0;
        carom_vec3 p;
        for (int i = 0; i < (int)(5.0 / dts[k]); i++) {
            assert_int_equal(carom_world_step(w, dts[k]), CAROM_OK);
            assert_int_equal(carom_body_get_position(w, box, &p), CAROM_OK);
            if (p.z > highest) highest = p.z;
        }
        print_message("dt 1/%.0f: rests at z %.4f, highest %.4f\n", 1 / dts[k], p.z, highest);
        assert_true(highest <= 0.8);
        assert_true(fabs(p.z - 0.5) < 0.05);
        carom_world_destroy(w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_penalty_stack_of_ten),
        cmocka_unit_test(test_penalty_column_sag),
        cmocka_unit_test(test_unstable_explicit_spring_refused),
        cmocka_unit_test(test_automatic_explicit_spring_stable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
