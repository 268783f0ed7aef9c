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

/* Ten unit boxes (1 kg) stacked on the ground: the top moves < 5 cm in 10 s. */
static void test_penalty_stack_of_ten(void **state)
{
    (void)state;
    static const char *presets[3] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++) {
        carom_world *w = penalty_world(presets[p], 1, 0.0);
        carom_body_id box[10];
        for (int i = 0; i < 10; i++) box[i] = add_unit_box(w, 0.5 + i);
        for (int i = 0; i < 600; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_vec3 top;
        assert_int_equal(carom_body_get_position(w, box[9], &top), CAROM_OK);
        double moved = sqrt(top.x * top.x + top.y * top.y + (top.z - 9.5) * (top.z - 9.5));
        print_message("%s: top box moved %.4f m in 10 s\n", presets[p], moved);
        assert_true(moved < 0.05);
        carom_world_destroy(w);
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
        cmocka_unit_test(test_unstable_explicit_spring_refused),
        cmocka_unit_test(test_automatic_explicit_spring_stable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
