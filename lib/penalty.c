/* penalty.c - the seed's alternative contact model: a stiff temporary spring
 * (and damper) between overlapping bodies pushes them apart. Explicit springs
 * are what the text describes (and what goes unstable when stiff); implicit
 * springs evaluate the force at the end of the sub-step and stay stable. */
#include "solver.h"

void penalty_solve(carom_world *w, contact_constraint *cc, int n, double h)
{
    impulse_body *bodies = w->scratch.bodies;
    const vec3 *dp = w->scratch.delta_position, *dq = w->scratch.delta_rotation;
    int implicit = w->def.penalty_implicit;
    int friction_on = w->def.enable_friction;
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
            double impulse;
            if (implicit) {
                /* P = h F(t+h) with s(t+h) = s + h vn', vn' = vn + P / m_eff */
                double inv_m = 1.0 / p->normal_mass;
                impulse = -(h * kk * s + h * (h * kk + cd) * vn) / (1.0 + h * inv_m * (h * kk + cd));
            } else {
                impulse = -h * (kk * s + cd * vn);
            }
            if (impulse <= 0.0) continue; /* springs push, never pull */
            p->total_normal_impulse += impulse;
            if (impulse > p->max_normal_impulse) p->max_normal_impulse = impulse;
            p->normal_impulse = impulse;
            impulse_apply(B, A, p->rb, p->ra, v3_scale(c->n, impulse));
            if (!friction_on || c->friction <= 0.0) continue;
            /* Coulomb friction on this sub-step's spring impulse */
            vec3 vp = v3_sub(impulse_point_velocity(B, p->rb), impulse_point_velocity(A, p->ra));
            double l1 = -p->tangent_mass[0] * v3_dot(vp, c->t1);
            double l2 = -p->tangent_mass[1] * v3_dot(vp, c->t2);
            coulomb_clamp(&l1, &l2, c->friction * impulse);
            p->tangent_impulse[0] = l1;
            p->tangent_impulse[1] = l2;
            impulse_apply(B, A, p->rb, p->ra, v3_add(v3_scale(c->t1, l1), v3_scale(c->t2, l2)));
        }
    }
}
