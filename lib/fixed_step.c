/* fixed_step.c - carom_fixed_step: a fixed-step clock for hosts that step
 * by frame time (the Lua binding's world:advance). Pure arithmetic on the
 * caller's accumulator; no world is involved. */
#include <math.h>
#include <stdio.h>
#include "carom/carom.h"

CAROM_API carom_status carom_fixed_step(double dt, int max_steps, double frame_time, double *accumulator, int *steps,
                                        char *msg, size_t msg_size)
{
    char local[8];
    if (!msg || msg_size == 0) { msg = local; msg_size = sizeof local; }
    msg[0] = '\0';
#define REFUSE(...) return snprintf(msg, msg_size, __VA_ARGS__), CAROM_ERROR_INVALID_ARGUMENT
    if (!(dt > 0 && dt <= 1)) REFUSE("dt must be in (0, 1] seconds (got %g)", dt);
    if (!(max_steps >= 1 && max_steps <= CAROM_FIXED_STEP_MAX_STEPS))
        REFUSE("max_steps must be in 1..%d (got %d)", CAROM_FIXED_STEP_MAX_STEPS, max_steps);
    if (!(isfinite(frame_time) && frame_time >= 0))
        REFUSE("frame time must not be negative or non-finite (got %g)", frame_time);
    if (!accumulator || !steps) REFUSE("accumulator and steps must not be NULL");
    if (!(isfinite(*accumulator) && *accumulator >= 0))
        REFUSE("the accumulator must not be negative or non-finite (got %g)", *accumulator);
#undef REFUSE
    double acc = *accumulator + frame_time;
    int n = 0;
    while (acc >= dt && n < max_steps) { /* one subtraction per step: the remainder a stepping loop would keep */
        acc -= dt;
        n++;
    }
    if (acc >= dt) acc = fmod(acc, dt); /* the backlog beyond max_steps is dropped */
    *accumulator = acc;
    *steps = n;
    return CAROM_OK;
}
