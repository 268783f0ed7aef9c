/* test_island.c - islands and sleeping: a resting island sleeps and wakes when touched. */
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

static void test_sleep_and_wake(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 1, 0.6, 0.0);
    carom_body_id box = add_box(w, 0, 0, 0.5, 0.5, 1.0, 0.6);
    step_n(w, 120, DT);
    assert_false(carom_body_is_awake(w, box));
    carom_world_stats st = carom_world_stats_init();
    carom_world_get_stats(w, &st);
    assert_int_equal(st.awake_bodies, 0);
    /* a falling box wakes it on impact */
    carom_body_id dropper = add_box(w, 0, 0, 3.0, 0.5, 1.0, 0.6);
    int woke = 0;
    for (int i = 0; i < 60; i++) {
        step_n(w, 1, DT);
        if (carom_body_is_awake(w, box)) woke = 1;
    }
    assert_true(woke);
    EXPECT_NEAR(pos(w, dropper).z, 1.5, 0.02, "dropped box rests on the first");
    /* setting a velocity wakes a sleeper */
    step_n(w, 120, DT);
    assert_false(carom_body_is_awake(w, dropper));
    carom_body_set_linear_velocity(w, dropper, vec(0, 0, 1));
    assert_true(carom_body_is_awake(w, dropper));
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sleep_and_wake),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
