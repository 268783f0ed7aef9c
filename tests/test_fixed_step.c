/* test_fixed_step.c - carom_fixed_step, the fixed-step clock (lib/fixed_step.c):
 * the steps it asks for and the time it keeps against the arithmetic of
 * real time (whole steps of dt in the accumulated frame time, at most
 * max_steps, the backlog beyond them dropped), and its refusals, which
 * change nothing. */
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

/* Frames of a steady rate against a step of another: after any number of
 * frames no time is lost or made (steps taken x dt + the time kept = the
 * elapsed time, to rounding), the steps taken are floor(elapsed / dt) (one
 * fewer where elapsed / dt is an integer to rounding: that step comes with
 * the next frame), and alpha stays in [0, 1). */
static void test_steps_follow_real_time(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 60, 1.0 / 120, 1.0 / 15, 0.25, 1.0};
    const double frames[] = {1.0 / 144, 1.0 / 60, 1.0 / 30, 0.1, 0.0};
    for (size_t a = 0; a < sizeof dts / sizeof dts[0]; a++)
        for (size_t b = 0; b < sizeof frames / sizeof frames[0]; b++) {
            double dt = dts[a], frame = frames[b], acc = 0;
            long total = 0;
            for (int f = 1; f <= 600; f++) {
                int steps = -1;
                assert_int_equal(carom_fixed_step(dt, 1000, frame, &acc, &steps, NULL, 0), CAROM_OK);
                total += steps;
                double elapsed = f * frame, exact = elapsed / dt;
                long want = (long)floor(exact);
                int at_edge = fabs(exact - floor(exact + 0.5)) < 1e-9;
                if (at_edge) want = (long)floor(exact + 0.5);
                if (!(total == want || (at_edge && total == want - 1)))
                    fail_msg("dt %g frame %g after %d frames: %ld steps, want %ld", dt, frame, f, total, want);
                if (!(fabs((double)total * dt + acc - elapsed) <= 1e-9))
                    fail_msg("dt %g frame %g after %d frames: %.17g s taken + %.17g kept != %.17g elapsed", dt, frame, f,
                             (double)total * dt, acc, elapsed);
                assert_true(acc >= 0 && acc / dt < 1);
            }
        }
}

/* A frame longer than max_steps steps: exactly max_steps run, and the
 * clock keeps only the fraction of a step (the backlog is dropped). */
static void test_backlog_is_dropped(void **state)
{
    (void)state;
    double acc = 0;
    int steps = 0;
    assert_int_equal(carom_fixed_step(0.01, 5, 1.0, &acc, &steps, NULL, 0), CAROM_OK);
    assert_int_equal(steps, 5);
    EXPECT_NEAR(acc, fmod(1.0 - 5 * 0.01, 0.01), 1e-12, "fraction kept");
    assert_true(acc < 0.01);
    /* at the cap exactly: nothing dropped */
    acc = 0;
    assert_int_equal(carom_fixed_step(0.25, 4, 1.0, &acc, &steps, NULL, 0), CAROM_OK);
    assert_int_equal(steps, 4);
    assert_true(acc == 0.0);
    acc = 0.125;
    assert_int_equal(carom_fixed_step(0.25, 4, 0.0, &acc, &steps, NULL, 0), CAROM_OK);
    assert_int_equal(steps, 0);
    assert_true(acc == 0.125);
}

static void test_refusals_change_nothing(void **state)
{
    (void)state;
    struct { double dt; int max_steps; double frame, acc; const char *words; } bad[] = {
        {0.0, 8, 0.1, 0, "dt must be in (0, 1] seconds"},
        {1.5, 8, 0.1, 0, "dt must be in (0, 1] seconds"},
        {NAN, 8, 0.1, 0, "dt must be in (0, 1] seconds"},
        {0.01, 0, 0.1, 0, "max_steps must be in 1..100000"},
        {0.01, CAROM_FIXED_STEP_MAX_STEPS + 1, 0.1, 0, "max_steps must be in 1..100000"},
        {0.01, 8, -1e-3, 0, "frame time must not be negative"},
        {0.01, 8, INFINITY, 0, "frame time must not be negative or non-finite"},
        {0.01, 8, 0.1, -1, "accumulator must not be negative"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        double acc = bad[i].acc;
        int steps = 77;
        char msg[128];
        assert_int_equal(carom_fixed_step(bad[i].dt, bad[i].max_steps, bad[i].frame, &acc, &steps, msg, sizeof msg),
                         CAROM_ERROR_INVALID_ARGUMENT);
        if (!strstr(msg, bad[i].words)) fail_msg("case %d: '%s' lacks '%s'", (int)i, msg, bad[i].words);
        assert_true(acc == bad[i].acc);
        assert_int_equal(steps, 77);
    }
    double acc = 0;
    assert_int_equal(carom_fixed_step(0.01, 8, 0.1, NULL, &(int){0}, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_fixed_step(0.01, 8, 0.1, &acc, NULL, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
    /* the edges themselves are accepted */
    int steps;
    assert_int_equal(carom_fixed_step(1.0, CAROM_FIXED_STEP_MAX_STEPS, 0, &acc, &steps, NULL, 0), CAROM_OK);
    assert_int_equal(carom_fixed_step(1e-300, 1, 0, &acc, &steps, NULL, 0), CAROM_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_steps_follow_real_time),
        cmocka_unit_test(test_backlog_is_dropped),
        cmocka_unit_test(test_refusals_change_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
