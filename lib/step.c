/* step.c - the step context's settings, and the soft contact coefficients. */
#include <string.h>
#include "step.h"

#define TWO_PI 6.283185307179586

softness make_softness(double hertz, double zeta, double h)
{
    softness s = {0.0, 1.0, 0.0};
    if (hertz <= 0) return s;
    double omega = TWO_PI * hertz;
    double a1 = 2.0 * zeta + h * omega;
    double a2 = h * omega * a1;
    double a3 = 1.0 / (1.0 + a2);
    s.bias_rate = omega / a1;
    s.mass_scale = a2 * a3;
    s.impulse_scale = a3;
    return s;
}

void step_context_init(step_context *ctx, const carom_world_def *def, double dt)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->dt = dt;
    ctx->substeps = def->substeps;
    ctx->h = dt / def->substeps;
    ctx->inv_h = 1.0 / ctx->h;
    /* a spring stiffer than a quarter of the sub-step rate is not resolved */
    ctx->contact_hertz = dmin(def->contact_hertz, 0.25 / ctx->h);
    ctx->contact_damping_ratio = def->contact_damping_ratio;
    ctx->soft = make_softness(ctx->contact_hertz, def->contact_damping_ratio, ctx->h);
    /* against a fixed body twice as stiff; without relax passes (fast) never
     * past the same quarter either */
    double static_hertz = 2.0 * ctx->contact_hertz;
    if (def->relax_iterations == 0) static_hertz = dmin(static_hertz, 0.25 / ctx->h);
    ctx->static_soft = make_softness(static_hertz, def->contact_damping_ratio, ctx->h);
    ctx->correction = def->position_correction;
    ctx->push_max = def->contact_push_max_velocity;
    ctx->slop = def->linear_slop;
    ctx->baumgarte_rate = def->baumgarte * ctx->inv_h;
    ctx->iterations = def->iterations;
    ctx->relax_iterations = def->relax_iterations;
    ctx->warm_starting = def->warm_starting;
    ctx->friction = def->enable_friction;
    ctx->restitution = def->enable_restitution;
    ctx->shock_propagation = def->shock_propagation;
    ctx->restitution_threshold = def->restitution_threshold;
    ctx->hit_event_threshold = def->hit_event_threshold;
    ctx->penalty = def->contact_model == CAROM_CONTACT_PENALTY;
    ctx->penalty_implicit = def->penalty_implicit;
    ctx->penalty_stiffness = def->penalty_stiffness;
    ctx->penalty_damping = def->penalty_damping;
    ctx->gravity = v3(def->gravity.x, def->gravity.y, def->gravity.z);
    ctx->gravity_length = v3_len(ctx->gravity);
    ctx->tasks = def;
}
