/* contact_solver.c - the scalar passes over one manifold: prepare, warm
 * start, solve / relax and the shock pass. The wide passes
 * (solver_wide.c) do the same four manifolds at a time; the formulas they
 * share are in constraint.h. */
#include "contact_solver.h"
#include "penalty.h"


/* Rolling resistance c: a torque against the bodies' relative rolling,
 * capped at c R N. A body of mass m and inertia I_t about the rolling axis,
 * its centre r above the contact, rolling on still ground slows at
 * T r / (I_t + m r^2) under a torque T: R = r + I_t / (m r) makes that c g,
 * as a block sliding with friction c would (the larger R of two bodies). */
static void prepare_rolling(contact_constraint *c, const impulse_body *A, const impulse_body *B)
{
    constraint_extra *x = c->x;
    if (!x) return; /* no rolling rows (every reader checks c->rolling first) */
    x->rolling_impulse[0] = x->rolling_impulse[1] = 0.0;
    x->rolling_mass[0] = x->rolling_mass[1] = 0.0;
    x->rolling_radius = 0.0;
    if (!(c->rolling > 0.0) || c->count < 1) return;
    vec3 t[2] = {c->t1, c->t2};
    for (int q = 0; q < 2; q++) {
        double k = v3_dot(t[q], m3_mulv(A->inv_inertia, t[q])) + v3_dot(t[q], m3_mulv(B->inv_inertia, t[q]));
        x->rolling_mass[q] = k > 0.0 ? 1.0 / k : 0.0;
    }
    vec3 mid = v3_zero();
    for (int j = 0; j < c->count; j++) mid = v3_add(mid, c->m->points[j].point);
    mid = v3_scale(mid, 1.0 / c->count);
    const impulse_body *body[2] = {A, B};
    vec3 centre[2] = {c->center_a, c->center_b};
    for (int i = 0; i < 2; i++) {
        const impulse_body *X = body[i];
        double r = fabs(v3_dot(c->n, v3_sub(mid, centre[i])));
        double inv_it = 0.5 * (v3_dot(t[0], m3_mulv(X->inv_inertia, t[0])) + v3_dot(t[1], m3_mulv(X->inv_inertia, t[1])));
        if (!(X->inv_mass > 0.0 && inv_it > 0.0 && r > 0.0)) continue;
        x->rolling_radius = dmax(x->rolling_radius, r + X->inv_mass / (inv_it * r));
    }
}

static void solve_rolling(contact_constraint *c, vec3 *wA, vec3 *wB, const impulse_body *A, const impulse_body *B)
{
    double normal = 0.0;
    for (int j = 0; j < c->count; j++) normal += c->p[j].normal_impulse;
    constraint_extra *x = c->x;
    vec3 rel = v3_sub(*wB, *wA);
    double o1 = x->rolling_impulse[0], o2 = x->rolling_impulse[1];
    double n1 = o1 - x->rolling_mass[0] * v3_dot(c->t1, rel);
    double n2 = o2 - x->rolling_mass[1] * v3_dot(c->t2, rel);
    coulomb_clamp(&n1, &n2, c->rolling * x->rolling_radius * normal);
    x->rolling_impulse[0] = n1;
    x->rolling_impulse[1] = n2;
    vec3 L = v3_add(v3_scale(c->t1, n1 - o1), v3_scale(c->t2, n2 - o2));
    *wA = v3_sub(*wA, m3_mulv(A->inv_inertia, L));
    *wB = v3_add(*wB, m3_mulv(B->inv_inertia, L));
}

double contact_prepare(contact_constraint *c, const step_context *ctx)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    vec3 ca = c->center_a, cb = c->center_b;
    double ws = ctx->warm_starting ? 1.0 : 0.0;
    double deepest = 0.0;
    /* the linear share of each row's inverse effective mass: a plane-locked
     * body's 1/m counts only the row's part in its plane (its inverse inertia
     * is already the reduced n n^T / (n.I n)) */
    double lin_n = A->inv_mass + B->inv_mass, lin_1 = lin_n, lin_2 = lin_n;
    if (c->locked) {
        vec3 la = constraint_lock_a(c), lb = constraint_lock_b(c);
        lin_n = locked_inv_mass(A->inv_mass, c->n, la) + locked_inv_mass(B->inv_mass, c->n, lb);
        lin_1 = locked_inv_mass(A->inv_mass, c->t1, la) + locked_inv_mass(B->inv_mass, c->t1, lb);
        lin_2 = locked_inv_mass(A->inv_mass, c->t2, la) + locked_inv_mass(B->inv_mass, c->t2, lb);
    }
    for (int j = 0; j < c->count; j++) {
        const manifold_point *mp = &c->m->points[j];
        constraint_point *p = &c->p[j];
        constraint_anchor *q = &c->an[j];
        constraint_rows *r = &c->r[j];
        q->ra = v3_sub(mp->point, ca);
        q->rb = v3_sub(mp->point, cb);
        r->ra_n = v3_cross(q->ra, c->n);
        r->rb_n = v3_cross(q->rb, c->n);
        r->ia_n = m3_mulv(A->inv_inertia, r->ra_n);
        r->ib_n = m3_mulv(B->inv_inertia, r->rb_n);
        r->ra_t[0] = v3_cross(q->ra, c->t1);
        r->rb_t[0] = v3_cross(q->rb, c->t1);
        r->ra_t[1] = v3_cross(q->ra, c->t2);
        r->rb_t[1] = v3_cross(q->rb, c->t2);
        for (int q = 0; q < 2; q++) {
            r->ia_t[q] = m3_mulv(A->inv_inertia, r->ra_t[q]);
            r->ib_t[q] = m3_mulv(B->inv_inertia, r->rb_t[q]);
        }
        /* the seed's denominator 1/m1 + 1/m2 + n.((I1^-1 (r1 x n)) x r1) + ..., from the
         * rows above: n.((I^-1 (r x n)) x r) = (I^-1 (r x n)).(r x n) */
        double kn = lin_n + v3_dot(r->ia_n, r->ra_n) + v3_dot(r->ib_n, r->rb_n);
        double k1 = lin_1 + v3_dot(r->ia_t[0], r->ra_t[0]) + v3_dot(r->ib_t[0], r->rb_t[0]);
        double k2 = lin_2 + v3_dot(r->ia_t[1], r->ra_t[1]) + v3_dot(r->ib_t[1], r->rb_t[1]);
        r->normal_mass = kn > 0 ? 1.0 / kn : 0.0;
        r->tangent_mass[0] = k1 > 0 ? 1.0 / k1 : 0.0;
        r->tangent_mass[1] = k2 > 0 ? 1.0 / k2 : 0.0;
        q->base_separation = mp->separation;
        p->relative_velocity = contact_approach_velocity(impulse_relative_normal_velocity(B, A, q->rb, q->ra, c->n),
                                                         c->gravity_closing, mp->separation);
        p->normal_impulse = ws * c->warm[j].normal_impulse;
        p->tangent_impulse[0] = ws * c->warm[j].tangent_impulse[0];
        p->tangent_impulse[1] = ws * c->warm[j].tangent_impulse[1];
        p->total_normal_impulse = 0.0;
        if (ctx->penalty) penalty_prepare_point(p, r, &c->spring[j], ctx);
        if (-mp->separation > deepest) deepest = -mp->separation;
    }
    prepare_rolling(c, A, B);
    return deepest;
}

void contact_warm_start(contact_constraint *c, impulse_body *bodies)
{
    impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        vec3 P = v3_add(v3_scale(c->n, p->normal_impulse),
                        v3_add(v3_scale(c->t1, p->tangent_impulse[0]), v3_scale(c->t2, p->tangent_impulse[1])));
        p->total_normal_impulse += p->normal_impulse;
        /* seed convention: body 1 = B receives +P (n points from A to B) */
        impulse_apply(B, A, c->an[i].rb, c->an[i].ra, P);
        if (c->locked) {
            A->v = keep_in_plane(A->v, constraint_lock_a(c));
            B->v = keep_in_plane(B->v, constraint_lock_b(c));
        }
    }
    if (c->rolling > 0.0) {
        vec3 L = v3_add(v3_scale(c->t1, c->x->rolling_impulse[0]), v3_scale(c->t2, c->x->rolling_impulse[1]));
        A->w = v3_sub(A->w, m3_mulv(A->inv_inertia, L));
        B->w = v3_add(B->w, m3_mulv(B->inv_inertia, L));
    }
}

/* Normal then friction rows of one manifold; use_bias selects the solve pass
 * (position error fed back) over the relax pass (velocity only). */
#if defined(__GNUC__)
#define SOLVE_INLINE static inline __attribute__((always_inline))
#else
#define SOLVE_INLINE static inline
#endif

/* contact_solve's body, built twice: `locked` (a constant in each build)
 * keeps plane-locked bodies' velocities in their planes after every row; the
 * build for free bodies carries none of it. */
SOLVE_INLINE void solve_manifold(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces,
                                 const int locked)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    vec3 vA = A->v, wA = A->w, vB = B->v, wB = B->w;
    double mA = A->inv_mass, mB = B->inv_mass;
    vec3 n = c->n;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    vec3 dqa = ctx->dq[c->a], dqb = ctx->dq[c->b];
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    const int count = c->count;
    vec3 lock_a = v3_zero(), lock_b = v3_zero();
    if (locked) { lock_a = c->x->lock_a; lock_b = c->x->lock_b; }
    for (int i = 0; i < count; i++) {
        constraint_point *p = &c->p[i];
        const constraint_rows *r = &c->r[i];
        /* current separation: small-angle update of the anchors */
        double s = c->an[i].base_separation + v3_dot(n, dpab) + v3_dot(dqb, r->rb_n) - v3_dot(dqa, r->ra_n);
        double bias = 0.0, mass_scale = 1.0, impulse_scale = 0.0;
        if (s > 0.0) {
            bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        } else if (push) {
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
            if (soft) {
                mass_scale = c->soft.mass_scale;
                impulse_scale = c->soft.impulse_scale;
            }
        }
        double vn = v3_dot(n, v3_sub(vB, vA)) + v3_dot(wB, r->rb_n) - v3_dot(wA, r->ra_n);
        double lambda = -r->normal_mass * mass_scale * (vn + bias) - impulse_scale * p->normal_impulse;
        double total = p->normal_impulse + lambda;
        if (total < 0.0) total = 0.0;
        if (hold_bounces && s > 0.0 && c->restitution > 0.0 && total > p->normal_impulse) total = p->normal_impulse;
        lambda = total - p->normal_impulse;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        vA = v3_madd(vA, -mA * lambda, n);
        wA = v3_madd(wA, -lambda, r->ia_n);
        vB = v3_madd(vB, mB * lambda, n);
        wB = v3_madd(wB, lambda, r->ib_n);
        if (locked) { vA = keep_in_plane(vA, lock_a); vB = keep_in_plane(vB, lock_b); }
    }
    if (ctx->friction && c->friction > 0) {
        vec3 dv = v3_sub(vB, vA);
        for (int i = 0; i < count; i++) {
            constraint_point *p = &c->p[i];
            const constraint_rows *r = &c->r[i];
            double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
            double v1 = v3_dot(dv, c->t1) + v3_dot(wB, r->rb_t[0]) - v3_dot(wA, r->ra_t[0]);
            double v2 = v3_dot(dv, c->t2) + v3_dot(wB, r->rb_t[1]) - v3_dot(wA, r->ra_t[1]);
            double n1 = o1 - r->tangent_mass[0] * v1;
            double n2 = o2 - r->tangent_mass[1] * v2;
            double limit = c->friction * p->normal_impulse;
            if (n1 * n1 + n2 * n2 > limit * limit)
                coulomb_over_cone(&n1, &n2, o1, o2, v1, v2, r->tangent_mass[0], r->tangent_mass[1], limit);
            p->tangent_impulse[0] = n1;
            p->tangent_impulse[1] = n2;
            double d1 = n1 - o1, d2 = n2 - o2;
            vec3 P = v3_add(v3_scale(c->t1, d1), v3_scale(c->t2, d2));
            vA = v3_madd(vA, -mA, P);
            vB = v3_madd(vB, mB, P);
            wA = v3_sub(wA, v3_add(v3_scale(r->ia_t[0], d1), v3_scale(r->ia_t[1], d2)));
            wB = v3_add(wB, v3_add(v3_scale(r->ib_t[0], d1), v3_scale(r->ib_t[1], d2)));
            if (locked) { vA = keep_in_plane(vA, lock_a); vB = keep_in_plane(vB, lock_b); }
            dv = v3_sub(vB, vA);
        }
    }
    if (c->rolling > 0.0) solve_rolling(c, &wA, &wB, A, B);
    A->v = vA; A->w = wA;
    B->v = vB; B->w = wB;
}

void contact_solve(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces)
{
    if (c->locked) solve_manifold(c, ctx, use_bias, hold_bounces, 1);
    else solve_manifold(c, ctx, use_bias, hold_bounces, 0);
}

/* Shock propagation (Guendelman et al. 2003): the body nearer the ground is
 * treated as immovable, so a heavy body is held by the light body under it
 * instead of slowly crushing it (an iterative solver converges at a rate set
 * by the mass ratio). Constraints arrive sorted bottom-up. */
void contact_solve_shock(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces, int lower_is_a)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    /* fa, fb scale each body's response: the lower body gets 0 */
    double fa = lower_is_a ? 0.0 : 1.0, fb = lower_is_a ? 1.0 : 0.0;
    vec3 n = c->n;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    vec3 lock_a = constraint_lock_a(c), lock_b = constraint_lock_b(c);
    double shock_normal[MANIFOLD_MAX_POINTS]; /* this pass's normal impulses, never warm-started */
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        const constraint_anchor *q = &c->an[i];
        /* rows from the anchors: a wide-solved point keeps only those */
        vec3 ra_n = v3_cross(q->ra, n), rb_n = v3_cross(q->rb, n);
        vec3 ia_n = m3_mulv(A->inv_inertia, ra_n), ib_n = m3_mulv(B->inv_inertia, rb_n);
        double s = q->base_separation + v3_dot(n, dpab) + v3_dot(ctx->dq[c->b], rb_n) - v3_dot(ctx->dq[c->a], ra_n);
        double k = fa * (locked_inv_mass(A->inv_mass, n, lock_a) + v3_dot(ra_n, ia_n)) +
                   fb * (locked_inv_mass(B->inv_mass, n, lock_b) + v3_dot(rb_n, ib_n));
        shock_normal[i] = 0.0;
        if (k <= 0) continue;
        /* rigid against an immovable lower body, with the soft push-out rate */
        double bias = 0.0;
        if (s > 0.0) bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        else if (push)
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
        double vn = v3_dot(n, v3_sub(B->v, A->v)) + v3_dot(B->w, rb_n) - v3_dot(A->w, ra_n);
        /* the pass may pull back at most what the regular solve pushed */
        double lambda = dmax(-(vn + bias) / k, -p->normal_impulse);
        if (hold_bounces && s > 0.0 && c->restitution > 0.0 && lambda > 0.0) lambda = 0.0;
        shock_normal[i] = lambda;
        p->total_normal_impulse += lambda;
        A->v = v3_madd(A->v, -fa * A->inv_mass * lambda, n);
        A->w = v3_madd(A->w, -fa * lambda, ia_n);
        B->v = v3_madd(B->v, fb * B->inv_mass * lambda, n);
        B->w = v3_madd(B->w, fb * lambda, ib_n);
        if (c->locked) { A->v = keep_in_plane(A->v, lock_a); B->v = keep_in_plane(B->v, lock_b); }
    }
    if (!ctx->friction || c->friction <= 0) return;
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        const constraint_anchor *q = &c->an[i];
        vec3 vp = v3_sub(v3_add(B->v, v3_cross(B->w, q->rb)), v3_add(A->v, v3_cross(A->w, q->ra)));
        vec3 t[2] = {c->t1, c->t2};
        double nw[2];
        for (int j = 0; j < 2; j++) {
            vec3 rat = v3_cross(q->ra, t[j]), rbt = v3_cross(q->rb, t[j]);
            double k = fa * (locked_inv_mass(A->inv_mass, t[j], lock_a) + v3_dot(rat, m3_mulv(A->inv_inertia, rat))) +
                       fb * (locked_inv_mass(B->inv_mass, t[j], lock_b) + v3_dot(rbt, m3_mulv(B->inv_inertia, rbt)));
            nw[j] = k > 0 ? -v3_dot(vp, t[j]) / k : 0.0;
        }
        /* Coulomb on the total: what the regular pass used plus this pass */
        double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
        double t1 = o1 + nw[0], t2 = o2 + nw[1];
        coulomb_clamp(&t1, &t2, c->friction * dmax(p->normal_impulse + shock_normal[i], 0.0));
        vec3 P = v3_add(v3_scale(t[0], t1 - o1), v3_scale(t[1], t2 - o2));
        A->v = v3_madd(A->v, -fa * A->inv_mass, P);
        A->w = v3_sub(A->w, v3_scale(m3_mulv(A->inv_inertia, v3_cross(q->ra, P)), fa));
        B->v = v3_madd(B->v, fb * B->inv_mass, P);
        B->w = v3_add(B->w, v3_scale(m3_mulv(B->inv_inertia, v3_cross(q->rb, P)), fb));
        if (c->locked) { A->v = keep_in_plane(A->v, lock_a); B->v = keep_in_plane(B->v, lock_b); }
    }
}
