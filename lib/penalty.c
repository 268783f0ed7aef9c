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
#include <math.h>
#include "penalty.h"

/* sweeps of the implicit springs per sub-step. Started cold (from zero
 * impulses every sub-step, what this did first) a 10-box column at default
 * settings, sleep off, rocked sideways 14-19 cm within 10 s at 16 sweeps
 * (4.5 cm at 64): each sub-step re-solved the whole column's load and the
 * unconverged remainder was uneven between corners. Warm started from the
 * previous sub-step's impulses the sweeps only correct the change, and stop
 * when it is below PENALTY_TOLERANCE: the column stays straight (sideways
 * 2e-5 m at dt 1/60, 4e-5 m at 1/30, where 16 sweeps at most left 1.5 mm). */
#define PENALTY_MAX_SWEEPS 64
/* the sweeps stop early once no point's impulse changes by more than this
 * fraction of the largest */
#define PENALTY_TOLERANCE 1e-9
/* automatic implicit spring: twice the contact frequency (four times the
 * stiffness) of the setting, capped at a quarter of the sub-step rate before
 * doubling (h omega <= pi). The column's sag is N^2 g / omega^2 (2.8 cm for
 * ten boxes at 30 Hz, 0.7 cm at 60, settling from 4.5 and 1.2 cm); four
 * times the frequency (h omega up to 2 pi at dt 1/15) no longer converges
 * in the sweeps and the column blows apart. */
#define PENALTY_IMPLICIT_HERTZ_SCALE 2.0
#define PENALTY_TWO_PI 6.283185307179586
/* explicit (symplectic Euler) spring-damper x'' = -(k x + c x') / m is stable
 * iff h^2 k/m + 2 h c/m < 4; points coupled through a body stiffen it, so
 * refuse from this fraction of the bound */
#define PENALTY_EXPLICIT_MARGIN 0.8

void penalty_prepare_point(constraint_point *p, const constraint_rows *r, penalty_spring *sp, const step_context *ctx)
{
    double omega = PENALTY_TWO_PI * ctx->contact_hertz;
    if (ctx->penalty_implicit) omega *= PENALTY_IMPLICIT_HERTZ_SCALE;
    /* the automatic explicit spring (critically damped) stays stable:
     * h^2 w^2 + 4 h w < 4 * 0.8 at h w <= 0.6 */
    else if (omega * ctx->h > 0.6) omega = 0.6 / ctx->h;
    sp->k = ctx->penalty_stiffness > 0 ? ctx->penalty_stiffness : r->normal_mass * omega * omega;
    sp->c = ctx->penalty_damping > 0 ? ctx->penalty_damping : 2.0 * r->normal_mass * omega;
    if (!ctx->penalty_implicit) {
        p->normal_impulse = 0.0;
        p->tangent_impulse[0] = p->tangent_impulse[1] = 0.0;
    }
}

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
            const constraint_rows *rows = &cc[k].r[i];
            const penalty_spring *sp = &cc[k].spring[i];
            double r = penalty_explicit_stability(sp->k, sp->c, rows->normal_mass, h);
            if (r >= PENALTY_EXPLICIT_MARGIN) {
                snprintf(msg, msg_size,
                           "explicit penalty spring k %g N/m, c %g N s/m on effective mass %g kg is "
                           "unstable at sub-step %g s (h^2 k/m + 2 h c/m = %.3g >= %.3g): use penalty_implicit = 1, "
                           "a smaller penalty_stiffness or more substeps",
                           sp->k, sp->c, rows->normal_mass, h, 4.0 * r, 4.0 * PENALTY_EXPLICIT_MARGIN);
                return 0;
            }
        }
    return 1;
}

static void friction_rows(impulse_body *A, impulse_body *B, contact_constraint *c, constraint_point *p,
                          const constraint_anchor *q, const constraint_rows *r)
{
    vec3 vp = v3_sub(impulse_point_velocity(B, q->rb), impulse_point_velocity(A, q->ra));
    double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
    double l1 = o1 - r->tangent_mass[0] * v3_dot(vp, c->t1);
    double l2 = o2 - r->tangent_mass[1] * v3_dot(vp, c->t2);
    coulomb_clamp(&l1, &l2, c->friction * p->normal_impulse);
    p->tangent_impulse[0] = l1;
    p->tangent_impulse[1] = l2;
    impulse_apply(B, A, q->rb, q->ra, v3_add(v3_scale(c->t1, l1 - o1), v3_scale(c->t2, l2 - o2)));
}

/* a point whose spring let go keeps no friction impulse either */
static void drop_friction(impulse_body *A, impulse_body *B, contact_constraint *c, constraint_point *p,
                          const constraint_anchor *q)
{
    double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
    if (o1 == 0.0 && o2 == 0.0) return;
    p->tangent_impulse[0] = p->tangent_impulse[1] = 0.0;
    impulse_apply(B, A, q->rb, q->ra, v3_add(v3_scale(c->t1, -o1), v3_scale(c->t2, -o2)));
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
    for (int k = 0; k < n; k++) {
        contact_constraint *c = &cc[k];
        for (int i = 0; i < c->count; i++) {
            constraint_point *p = &c->p[i];
            if (!implicit) {
                p->normal_impulse = 0.0;
                p->tangent_impulse[0] = p->tangent_impulse[1] = 0.0;
                continue;
            }
            /* warm start: the previous sub-step's (or step's) spring impulses
             * applied first, so the sweeps only correct the change */
            vec3 P = v3_add(v3_scale(c->n, p->normal_impulse),
                            v3_add(v3_scale(c->t1, p->tangent_impulse[0]), v3_scale(c->t2, p->tangent_impulse[1])));
            p->total_normal_impulse += p->normal_impulse;
            impulse_apply(&bodies[c->b], &bodies[c->a], c->an[i].rb, c->an[i].ra, P);
        }
    }
    int sweeps = implicit ? PENALTY_MAX_SWEEPS : 1;
    for (int sweep = 0; sweep < sweeps; sweep++) {
        double largest = 0.0, change = 0.0; /* this sweep's largest impulse and correction */
        for (int k = 0; k < n; k++) {
            contact_constraint *c = &cc[k];
            impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
            vec3 dpab = v3_sub(dp[c->b], dp[c->a]);
            for (int i = 0; i < c->count; i++) {
                constraint_point *p = &c->p[i];
                const constraint_rows *r = &c->r[i];
                const constraint_anchor *q = &c->an[i];
                if (r->normal_mass <= 0.0) continue;
                double s = q->base_separation + v3_dot(c->n, dpab) + v3_dot(dq[c->b], r->rb_n) - v3_dot(dq[c->a], r->ra_n);
                double total = 0.0; /* apart: no spring (a warm impulse is taken back) */
                if (s < 0.0) {
                    double vn = impulse_relative_normal_velocity(B, A, q->rb, q->ra, c->n);
                    double kk = c->spring[i].k, cd = c->spring[i].c;
                    if (implicit) {
                        /* P = -h (k (s + h vn') + c vn') with vn' = vn + dP / m_eff: the
                         * correction dP of this point's accumulated impulse */
                        double inv_m = 1.0 / r->normal_mass, g = h * (h * kk + cd);
                        double residual = p->normal_impulse + h * kk * s + g * vn;
                        total = p->normal_impulse - residual / (1.0 + g * inv_m);
                    } else {
                        total = -h * (kk * s + cd * vn);
                    }
                    if (total < 0.0) total = 0.0; /* springs push, never pull */
                }
                double d = total - p->normal_impulse;
                if (d == 0.0 && total == 0.0 && p->tangent_impulse[0] == 0.0 && p->tangent_impulse[1] == 0.0) continue;
                p->normal_impulse = total;
                p->total_normal_impulse += d;
                impulse_apply(B, A, q->rb, q->ra, v3_scale(c->n, d));
                /* Coulomb friction on this sub-step's spring impulse */
                if (friction_on && c->friction > 0.0) friction_rows(A, B, c, p, q, r);
                else if (total == 0.0) drop_friction(A, B, c, p, q);
                if (total > largest) largest = total;
                if (fabs(d) > change) change = fabs(d);
            }
        }
        if (change <= PENALTY_TOLERANCE * largest) break;
    }
}
