/* penalty.c - the seed's alternative contact model: a stiff temporary spring
 * (and damper) between overlapping bodies pushes them apart. Explicit springs
 * are what the text describes (and what goes unstable when stiff); implicit
 * springs evaluate the force at the end of the sub-step and stay stable.
 *
 * Implicit springs are solved together: each sweep corrects a point's
 * accumulated impulse P towards P = -h (k s' + c vn') (s', vn' at the end of
 * the sub-step, with every other point's impulse applied), so a body on four
 * corners, or a column of ten boxes, gets the implicit step of the coupled
 * springs. One sweep of independent per-point updates (what this did first)
 * overshoots where points share a body: a 10-box stack rocked and fell over
 * within 3 s (top moved 9.8 m). */
#include <stdio.h>
#include "penalty.h"

/* sweeps of the implicit springs per sub-step: a 10-box column at default
 * settings (sleep off) drifts sideways 15 cm in 10 s at 8 sweeps, 2-11 cm at
 * 16 (sleeping stops it at 1 mm); 1 sweep topples it within 3 s */
#define PENALTY_SWEEPS 16
/* explicit (symplectic Euler) spring-damper x'' = -(k x + c x') / m is stable
 * iff h^2 k/m + 2 h c/m < 4; points coupled through a body stiffen it, so
 * refuse from this fraction of the bound */
#define PENALTY_EXPLICIT_MARGIN 0.8

double penalty_explicit_stability(double k, double c, double mass, double h)
{
    return mass > 0.0 ? (h * h * k + 2.0 * h * c) / (4.0 * mass) : 0.0;
}

int penalty_check(const step_context *ctx, char *msg, size_t msg_size)
{
    const contact_constraint *cc = ctx->constraints;
    int n = ctx->constraint_count;
    double h = ctx->h;
    if (ctx->penalty_implicit) return 1;
    for (int k = 0; k < n; k++)
        for (int i = 0; i < cc[k].count; i++) {
            const constraint_point *p = &cc[k].p[i];
            double r = penalty_explicit_stability(p->penalty_k, p->penalty_c, p->normal_mass, h);
            if (r >= PENALTY_EXPLICIT_MARGIN) {
                snprintf(msg, msg_size,
                           "step: explicit penalty spring k %g N/m, c %g N s/m on effective mass %g kg is "
                           "unstable at sub-step %g s (h^2 k/m + 2 h c/m = %.3g >= %.3g): use penalty_implicit = 1, "
                           "a smaller penalty_stiffness or more substeps",
                           p->penalty_k, p->penalty_c, p->normal_mass, h, 4.0 * r, 4.0 * PENALTY_EXPLICIT_MARGIN);
                return 0;
            }
        }
    return 1;
}

static void friction_rows(impulse_body *A, impulse_body *B, contact_constraint *c, constraint_point *p)
{
    vec3 vp = v3_sub(impulse_point_velocity(B, p->rb), impulse_point_velocity(A, p->ra));
    double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
    double l1 = o1 - p->tangent_mass[0] * v3_dot(vp, c->t1);
    double l2 = o2 - p->tangent_mass[1] * v3_dot(vp, c->t2);
    coulomb_clamp(&l1, &l2, c->friction * p->normal_impulse);
    p->tangent_impulse[0] = l1;
    p->tangent_impulse[1] = l2;
    impulse_apply(B, A, p->rb, p->ra, v3_add(v3_scale(c->t1, l1 - o1), v3_scale(c->t2, l2 - o2)));
}

void penalty_solve(const step_context *ctx)
{
    impulse_body *bodies = ctx->bodies;
    const vec3 *dp = ctx->dp, *dq = ctx->dq;
    contact_constraint *cc = ctx->constraints;
    int n = ctx->constraint_count;
    double h = ctx->h;
    int implicit = ctx->penalty_implicit;
    int friction_on = ctx->friction;
    for (int k = 0; k < n; k++)
        for (int i = 0; i < cc[k].count; i++) {
            cc[k].p[i].normal_impulse = 0.0;
            cc[k].p[i].tangent_impulse[0] = cc[k].p[i].tangent_impulse[1] = 0.0;
        }
    int sweeps = implicit ? PENALTY_SWEEPS : 1;
    for (int sweep = 0; sweep < sweeps; sweep++)
        for (int k = 0; k < n; k++) {
            contact_constraint *c = &cc[k];
            impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
            vec3 dpab = v3_sub(dp[c->b], dp[c->a]);
            for (int i = 0; i < c->count; i++) {
                constraint_point *p = &c->p[i];
                double s = p->base_separation + v3_dot(c->n, dpab) + v3_dot(dq[c->b], p->rb_n) - v3_dot(dq[c->a], p->ra_n);
                if (s >= 0.0 || p->normal_mass <= 0.0) continue;
                double vn = impulse_relative_normal_velocity(B, A, p->rb, p->ra, c->n);
                double kk = p->penalty_k, cd = p->penalty_c;
                double total;
                if (implicit) {
                    /* P = -h (k (s + h vn') + c vn') with vn' = vn + dP / m_eff: the
                     * correction dP of this point's accumulated impulse */
                    double inv_m = 1.0 / p->normal_mass, g = h * (h * kk + cd);
                    double residual = p->normal_impulse + h * kk * s + g * vn;
                    total = p->normal_impulse - residual / (1.0 + g * inv_m);
                } else {
                    total = -h * (kk * s + cd * vn);
                }
                if (total < 0.0) total = 0.0; /* springs push, never pull */
                double d = total - p->normal_impulse;
                p->normal_impulse = total;
                p->total_normal_impulse += d;
                if (total > p->max_normal_impulse) p->max_normal_impulse = total;
                impulse_apply(B, A, p->rb, p->ra, v3_scale(c->n, d));
                /* Coulomb friction on this sub-step's spring impulse */
                if (friction_on && c->friction > 0.0) friction_rows(A, B, c, p);
            }
        }
}
