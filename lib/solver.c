/* solver.c - the soft-step sequential impulse solver. Per step: gather the
 * awake bodies contiguously, build constraints from touching manifolds, then
 * per sub-step integrate velocities, warm start, solve (biased), integrate
 * positions, relax (unbiased); after the sub-steps apply restitution from the
 * normal velocity stored before solving, and store impulses for next step. */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "solver.h"
#include "rotation.h"
#include "impact.h"

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

/* Normal then friction rows of one manifold; use_bias selects the solve pass
 * (position error fed back) over the relax pass (velocity only). */
void solve_constraint(contact_constraint *c, const solve_context *sc, int use_bias)
{
    impulse_body *A = &sc->bodies[c->a], *B = &sc->bodies[c->b];
    vec3 vA = A->v, wA = A->w, vB = B->v, wB = B->w;
    double mA = A->inv_mass, mB = B->inv_mass;
    vec3 n = c->n;
    vec3 dpab = v3_sub(sc->dp[c->b], sc->dp[c->a]);
    vec3 dqa = sc->dq[c->a], dqb = sc->dq[c->b];
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        /* current separation: small-angle update of the anchors */
        double s = p->base_separation + v3_dot(n, dpab) + v3_dot(dqb, p->rb_n) - v3_dot(dqa, p->ra_n);
        double bias = 0.0, mass_scale = 1.0, impulse_scale = 0.0;
        if (s > 0.0) {
            bias = s * sc->inv_h; /* speculative: arrive exactly at contact */
        } else if (use_bias) {
            if (sc->correction == CAROM_CORRECTION_SOFT) {
                bias = c->soft.bias_rate * s;
                if (bias < -sc->push_max) bias = -sc->push_max;
                mass_scale = c->soft.mass_scale;
                impulse_scale = c->soft.impulse_scale;
            } else if (sc->correction == CAROM_CORRECTION_BAUMGARTE) {
                bias = dmax(sc->baumgarte * sc->inv_h * dmin(s + sc->slop, 0.0), -sc->push_max);
            }
        }
        double vn = v3_dot(n, v3_sub(vB, vA)) + v3_dot(wB, p->rb_n) - v3_dot(wA, p->ra_n);
        double lambda = -p->normal_mass * mass_scale * (vn + bias) - impulse_scale * p->normal_impulse;
        double total = p->normal_impulse + lambda;
        if (total < 0.0) total = 0.0;
        if (sc->hold_bounces && s > 0.0 && c->restitution > 0.0 && total > p->normal_impulse) total = p->normal_impulse;
        lambda = total - p->normal_impulse;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        if (total > p->max_normal_impulse) p->max_normal_impulse = total;
        vA = v3_madd(vA, -mA * lambda, n);
        wA = v3_madd(wA, -lambda, p->ia_n);
        vB = v3_madd(vB, mB * lambda, n);
        wB = v3_madd(wB, lambda, p->ib_n);
    }
    if (sc->friction && c->friction > 0) {
        vec3 dv = v3_sub(vB, vA);
        for (int i = 0; i < c->count; i++) {
            constraint_point *p = &c->p[i];
            double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
            double v1 = v3_dot(dv, c->t1) + v3_dot(wB, p->rb_t[0]) - v3_dot(wA, p->ra_t[0]);
            double v2 = v3_dot(dv, c->t2) + v3_dot(wB, p->rb_t[1]) - v3_dot(wA, p->ra_t[1]);
            double n1 = o1 - p->tangent_mass[0] * v1;
            double n2 = o2 - p->tangent_mass[1] * v2;
            coulomb_clamp(&n1, &n2, c->friction * p->normal_impulse);
            p->tangent_impulse[0] = n1;
            p->tangent_impulse[1] = n2;
            double d1 = n1 - o1, d2 = n2 - o2;
            vec3 P = v3_add(v3_scale(c->t1, d1), v3_scale(c->t2, d2));
            vA = v3_madd(vA, -mA, P);
            vB = v3_madd(vB, mB, P);
            wA = v3_sub(wA, v3_add(v3_scale(p->ia_t[0], d1), v3_scale(p->ia_t[1], d2)));
            wB = v3_add(wB, v3_add(v3_scale(p->ib_t[0], d1), v3_scale(p->ib_t[1], d2)));
            dv = v3_sub(vB, vA);
        }
    }
    A->v = vA; A->w = wA;
    B->v = vB; B->w = wB;
}

/* Shock propagation (Guendelman et al. 2003): the body nearer the ground is
 * treated as immovable, so a heavy body is held by the light body under it
 * instead of slowly crushing it (an iterative solver converges at a rate set
 * by the mass ratio). Constraints arrive sorted bottom-up. */
static void solve_constraint_shock(contact_constraint *c, const solve_context *sc, int use_bias, int lower_is_a)
{
    impulse_body *A = &sc->bodies[c->a], *B = &sc->bodies[c->b];
    /* fa, fb scale each body's response: the lower body gets 0 */
    double fa = lower_is_a ? 0.0 : 1.0, fb = lower_is_a ? 1.0 : 0.0;
    vec3 n = c->n;
    vec3 dpab = v3_sub(sc->dp[c->b], sc->dp[c->a]);
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        /* rows from the anchors: a wide-solved point keeps only those */
        vec3 ra_n = v3_cross(p->ra, n), rb_n = v3_cross(p->rb, n);
        vec3 ia_n = m3_mulv(A->inv_inertia, ra_n), ib_n = m3_mulv(B->inv_inertia, rb_n);
        double s = p->base_separation + v3_dot(n, dpab) + v3_dot(sc->dq[c->b], rb_n) - v3_dot(sc->dq[c->a], ra_n);
        double k = fa * (A->inv_mass + v3_dot(ra_n, ia_n)) + fb * (B->inv_mass + v3_dot(rb_n, ib_n));
        p->shock_normal = 0.0;
        if (k <= 0) continue;
        /* rigid against an immovable lower body, with the soft push-out rate */
        double bias = 0.0;
        if (s > 0.0) bias = s * sc->inv_h;
        else if (use_bias && sc->correction == CAROM_CORRECTION_SOFT) bias = dmax(c->soft.bias_rate * s, -sc->push_max);
        else if (use_bias && sc->correction == CAROM_CORRECTION_BAUMGARTE)
            bias = dmax(sc->baumgarte * sc->inv_h * dmin(s + sc->slop, 0.0), -sc->push_max);
        double vn = v3_dot(n, v3_sub(B->v, A->v)) + v3_dot(B->w, rb_n) - v3_dot(A->w, ra_n);
        /* the pass may pull back at most what the regular solve pushed */
        double lambda = dmax(-(vn + bias) / k, -p->normal_impulse);
        if (sc->hold_bounces && s > 0.0 && c->restitution > 0.0 && lambda > 0.0) lambda = 0.0;
        p->shock_normal = lambda;
        p->total_normal_impulse += lambda;
        A->v = v3_madd(A->v, -fa * A->inv_mass * lambda, n);
        A->w = v3_madd(A->w, -fa * lambda, ia_n);
        B->v = v3_madd(B->v, fb * B->inv_mass * lambda, n);
        B->w = v3_madd(B->w, fb * lambda, ib_n);
    }
    if (!sc->friction || c->friction <= 0) return;
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        vec3 vp = v3_sub(v3_add(B->v, v3_cross(B->w, p->rb)), v3_add(A->v, v3_cross(A->w, p->ra)));
        vec3 t[2] = {c->t1, c->t2};
        double nw[2];
        for (int j = 0; j < 2; j++) {
            vec3 rat = v3_cross(p->ra, t[j]), rbt = v3_cross(p->rb, t[j]);
            double k = fa * (A->inv_mass + v3_dot(rat, m3_mulv(A->inv_inertia, rat))) +
                       fb * (B->inv_mass + v3_dot(rbt, m3_mulv(B->inv_inertia, rbt)));
            nw[j] = k > 0 ? -v3_dot(vp, t[j]) / k : 0.0;
        }
        /* Coulomb on the total: what the regular pass used plus this pass */
        double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
        double t1 = o1 + nw[0], t2 = o2 + nw[1];
        coulomb_clamp(&t1, &t2, c->friction * dmax(p->normal_impulse + p->shock_normal, 0.0));
        vec3 P = v3_add(v3_scale(t[0], t1 - o1), v3_scale(t[1], t2 - o2));
        A->v = v3_madd(A->v, -fa * A->inv_mass, P);
        A->w = v3_sub(A->w, v3_scale(m3_mulv(A->inv_inertia, v3_cross(p->ra, P)), fa));
        B->v = v3_madd(B->v, fb * B->inv_mass, P);
        B->w = v3_add(B->w, v3_scale(m3_mulv(B->inv_inertia, v3_cross(p->rb, P)), fb));
    }
}

void warm_start_constraint(contact_constraint *c, impulse_body *bodies)
{
    impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        vec3 P = v3_add(v3_scale(c->n, p->normal_impulse),
                        v3_add(v3_scale(c->t1, p->tangent_impulse[0]), v3_scale(c->t2, p->tangent_impulse[1])));
        p->total_normal_impulse += p->normal_impulse;
        /* seed convention: body 1 = B receives +P (n points from A to B) */
        impulse_apply(B, A, p->rb, p->ra, P);
    }
}

static void warm_start(contact_constraint *cc, int n, impulse_body *bodies)
{
    for (int k = 0; k < n; k++) warm_start_constraint(&cc[k], bodies);
}

/* Keeps plane-locked bodies in their plane: in-plane velocity, spin about the normal. */
static void project_planar(carom_world *w, int nb)
{
    step_scratch *s = &w->scratch;
    body_store *bs = &w->bodies;
    for (int k = 1; k < nb; k++) {
        int slot = s->body_slot[k];
        if (!(bs->flags[slot] & BODY_LOCK_PLANE)) continue;
        vec3 nrm = bs->plane_normal[slot];
        impulse_body *b = &s->bodies[k];
        b->v = v3_madd(b->v, -v3_dot(b->v, nrm), nrm);
        b->w = v3_scale(nrm, v3_dot(b->w, nrm));
    }
}

/* Scales v back to length max (counting it); overflow-safe for huge finite v. */
static vec3 clamp_length(vec3 v, double max, int *clamped)
{
    double m = dmax(fabs(v.x), dmax(fabs(v.y), fabs(v.z)));
    if (!(m > max / 2)) return v; /* |v| <= sqrt(3) m, and NaN passes to the guard */
    vec3 u = v3_scale(v, 1.0 / m); /* no overflow in the length */
    double len = m * v3_len(u);
    if (len <= max) return v;
    (*clamped)++;
    return v3_scale(u, max / v3_len(u));
}

/* Below this many manifolds the wide passes gain nothing (mostly empty
 * lanes), and the scalar order converges faster on a small stack: colours
 * interleave its contacts (red-black), so support climbs two boxes per sweep
 * instead of the whole stack. */
#define WIDE_MIN_CONSTRAINTS 64
#define SHOCK_MASS_RATIO 4.0

/* Levels above the ground (static/kinematic = 0) by repeated relaxation over
 * the contact graph; bodies not resting on anything stay at INT_MAX / 2. */
static int compute_levels(contact_constraint *cc, int n, const impulse_body *bodies, int *level, int nb, int *order,
                          int *count_buf)
{
    const int far = 1 << 29;
    level[0] = 0;
    for (int k = 1; k < nb; k++) level[k] = far;
    int changed = 1;
    for (int pass = 0; changed && pass < nb + 1; pass++) {
        changed = 0;
        for (int k = 0; k < n; k++) {
            int a = cc[k].a, b = cc[k].b;
            if (level[a] + 1 < level[b]) { level[b] = level[a] + 1; changed = 1; }
            if (level[b] + 1 < level[a]) { level[a] = level[b] + 1; changed = 1; }
        }
    }
    /* only contacts where the upper body outweighs the lower one take part
     * (and contacts with the ground, which carry the load down): equal masses
     * are solved well by the soft solver, and a rigid pass would fight it */
    int max_level = 0;
    for (int k = 0; k < n; k++) {
        contact_constraint *c = &cc[k];
        int la = level[c->a], lb = level[c->b];
        double inv_lower = la < lb ? bodies[c->a].inv_mass : bodies[c->b].inv_mass;
        double inv_upper = la < lb ? bodies[c->b].inv_mass : bodies[c->a].inv_mass;
        int eligible = la != lb && inv_upper > 0.0 && (inv_lower == 0.0 || inv_lower >= SHOCK_MASS_RATIO * inv_upper);
        int l = la < lb ? la : lb;
        if (l > nb) l = nb;
        c->level = eligible ? l : -1;
        if (l > max_level) max_level = l;
    }
    int count = 0;
    for (int l = 0; l <= max_level + 1; l++) count_buf[l] = 0;
    for (int k = 0; k < n; k++)
        if (cc[k].level >= 0) count_buf[cc[k].level + 1]++;
    for (int l = 1; l <= max_level + 1; l++) count_buf[l] += count_buf[l - 1];
    for (int k = 0; k < n; k++)
        if (cc[k].level >= 0) { order[count_buf[cc[k].level]++] = k; count++; }
    return count;
}

int world_solve(carom_world *w, double dt)
{
    body_store *bs = &w->bodies;
    step_scratch *s = &w->scratch;
    contact_set *cs = &w->contacts;
    const carom_world_def *def = &w->def;
    int substeps = def->substeps;
    double h = dt / substeps;

    /* gather awake bodies: index 0 is the shared immovable body */
    int nb = 1, clamped = 0;
    for (int i = 0; i < bs->count; i++) bs->solver_index[i] = 0;
    if (!array_reserve((void **)&s->body_slot, &s->body_capacity, bs->count + 1, sizeof *s->body_slot)) return 0;
    {
        int cap = s->body_capacity;
        /* the per-body scratch arrays share one capacity */
        void *p1 = realloc(s->bodies, sizeof *s->bodies * (size_t)cap);
        if (!p1) return 0;
        s->bodies = p1;
        void *p2 = realloc(s->delta_position, sizeof *s->delta_position * (size_t)cap);
        if (!p2) return 0;
        s->delta_position = p2;
        void *p3 = realloc(s->delta_rotation, sizeof *s->delta_rotation * (size_t)cap);
        if (!p3) return 0;
        s->delta_rotation = p3;
    }
    impulse_body *bodies = s->bodies;
    memset(&bodies[0], 0, sizeof bodies[0]);
    s->delta_position[0] = v3_zero();
    s->delta_rotation[0] = v3_zero();
    s->body_slot[0] = -1;
    for (int i = 0; i < bs->count; i++) {
        if (bs->type[i] == CAROM_BODY_STATIC || !(bs->flags[i] & BODY_AWAKE)) continue;
        int k = nb++;
        bs->solver_index[i] = k;
        s->body_slot[k] = i;
        /* clamp before integrating: a finite but huge velocity set by the user
         * would otherwise overflow the pose to inf/NaN within the step */
        bodies[k].v = clamp_length(bs->velocity[i], def->max_linear_speed, &clamped);
        bodies[k].w = clamp_length(bs->angular_velocity[i], def->max_angular_speed, &clamped);
        bodies[k].inv_mass = bs->inv_mass[i];
        bodies[k].inv_inertia = bs->inv_inertia_world[i];
        s->delta_position[k] = v3_zero();
        s->delta_rotation[k] = v3_zero();
    }

    /* constraints from touching manifolds */
    /* the collision stage listed them: no scan over every pair */
    int ncon = s->touching_count, npoints = 0;
    for (int c = 0; c < ncon; c++) npoints += cs->data[s->touching[c]].m.count;
    /* one block: constraints, then their points packed (most pairs of round
     * shapes have one point, so a fixed 4 per constraint would waste cache) */
    size_t con_bytes = sizeof(contact_constraint) * (size_t)ncon + sizeof(constraint_point) * (size_t)npoints +
                       sizeof(int) * (size_t)(3 * ncon + 3 * nb + 4);
    if (!array_reserve(&s->constraints, &s->constraint_capacity, (int)con_bytes, 1)) return 0;
    contact_constraint *cc = s->constraints;
    constraint_point *point_pool = (constraint_point *)(cc + ncon);
    int *order = (int *)(point_pool + npoints);
    int *level = order + ncon;
    int *count_buf = level + nb + 1;
    int *in_contact = count_buf + nb + 3; /* per solver body: in some manifold this step */

    double contact_hertz = dmin(def->contact_hertz, 0.25 / h);
    softness soft = make_softness(contact_hertz, def->contact_damping_ratio, h);
    softness static_soft = make_softness(2.0 * contact_hertz, def->contact_damping_ratio, h);
    double ws = def->warm_starting ? 1.0 : 0.0;
    int friction_on = def->enable_friction;
    int penalty = def->contact_model == CAROM_CONTACT_PENALTY;
    double max_pen = 0.0;
    int contacts_touching = 0, points = 0;

    /* constraint headers first: the colouring needs only the bodies */
    for (int k = 0; k < ncon; k++) {
        int i = s->touching[k];
        contact *ct = &cs->items[i];
        contact_data *cd = &cs->data[i];
        int sa = bs->ids[ct->id_a].slot, sb = bs->ids[ct->id_b].slot;
        contact_constraint *c = &cc[k];
        c->a = bs->solver_index[sa];
        c->b = bs->solver_index[sb];
        c->contact = i;
        c->count = cd->m.count;
        c->p = point_pool;
        point_pool += c->count;
        c->n = cd->m.normal;
        /* keep the friction basis stable across steps while the normal holds still */
        vec3 t1 = v3_sub(cd->tangent1, v3_scale(c->n, v3_dot(cd->tangent1, c->n)));
        if (v3_len2(t1) < 0.25) { vec3 t2; v3_basis(c->n, &t1, &t2); }
        t1 = v3_normalize(t1);
        cd->tangent1 = t1;
        c->t1 = t1;
        c->t2 = v3_cross(c->n, t1);
        c->friction = cd->friction;
        c->restitution = def->enable_restitution ? cd->restitution : 0.0;
        c->soft = (bodies[c->a].inv_mass == 0.0 || bodies[c->b].inv_mass == 0.0) ? static_soft : soft;
        c->wide_batch = -1;
        c->m = &cd->m;
        c->warm = cd->state;
        c->center_a = bs->center[sa];
        c->center_b = bs->center[sb];
        /* every force acting over the step, not only gravity: b's acceleration relative to a along n */
        vec3 grav = v3(def->gravity.x, def->gravity.y, def->gravity.z);
        vec3 acc_a = bodies[c->a].inv_mass > 0.0
                         ? v3_madd(v3_scale(grav, bs->gravity_scale[sa]), bodies[c->a].inv_mass, bs->force[sa]) : v3_zero();
        vec3 acc_b = bodies[c->b].inv_mass > 0.0
                         ? v3_madd(v3_scale(grav, bs->gravity_scale[sb]), bodies[c->b].inv_mass, bs->force[sb]) : v3_zero();
        c->gravity_closing = v3_dot(c->n, v3_sub(acc_b, acc_a));
        contacts_touching++;
    }
    for (int b = 0; b < nb; b++) in_contact[b] = 0;
    for (int k = 0; k < ncon; k++) in_contact[cc[k].a] = in_contact[cc[k].b] = 1;
    int shock = 0;
    if (def->shock_propagation && !penalty) {
        /* cheap test first: scenes without a heavy-on-light contact pay nothing */
        for (int c = 0; c < ncon && !shock; c++) {
            double ia = bodies[cc[c].a].inv_mass, ib = bodies[cc[c].b].inv_mass;
            shock = (ia > 0 && ib >= SHOCK_MASS_RATIO * ia) || (ib > 0 && ia >= SHOCK_MASS_RATIO * ib);
        }
        if (shock) shock = compute_levels(cc, ncon, bodies, level, nb, order, count_buf);
    }

    /* the wide passes (penalty springs keep the scalar loop; the shock pass
     * runs scalar between wide passes, reading the impulses from the lanes) */
    wide_set *wide = NULL;
    if (!penalty && ncon >= WIDE_MIN_CONSTRAINTS) {
        wide = wide_plan(&s->wide, &s->wide_capacity, cc, ncon, nb);
        if (!wide) return 0;
    }

    /* the points: a wide-solved manifold's rows go straight to its lane, and
     * its scalar point keeps what restitution and the events read */
    if (wide) {
        max_pen = wide_prepare(wide, cc, bodies, ws);
        points = npoints;
    }
    for (int k = 0; k < ncon; k++) {
        contact_constraint *c = &cc[k];
        if (c->wide_batch >= 0) continue; /* prepared above */
        impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
        vec3 ca = c->center_a, cb = c->center_b;
        double an = c->gravity_closing;
        for (int j = 0; j < c->count; j++) {
            const manifold_point *mp = &c->m->points[j];
            constraint_point *p = &c->p[j];
            p->ra = v3_sub(mp->point, ca);
            p->rb = v3_sub(mp->point, cb);
            p->ra_n = v3_cross(p->ra, c->n);
            p->rb_n = v3_cross(p->rb, c->n);
            p->ia_n = m3_mulv(A->inv_inertia, p->ra_n);
            p->ib_n = m3_mulv(B->inv_inertia, p->rb_n);
            p->ra_t[0] = v3_cross(p->ra, c->t1);
            p->rb_t[0] = v3_cross(p->rb, c->t1);
            p->ra_t[1] = v3_cross(p->ra, c->t2);
            p->rb_t[1] = v3_cross(p->rb, c->t2);
            for (int q = 0; q < 2; q++) {
                p->ia_t[q] = m3_mulv(A->inv_inertia, p->ra_t[q]);
                p->ib_t[q] = m3_mulv(B->inv_inertia, p->rb_t[q]);
            }
            /* the seed's denominator 1/m1 + 1/m2 + n.((I1^-1 (r1 x n)) x r1) + ..., from the
             * rows above: n.((I^-1 (r x n)) x r) = (I^-1 (r x n)).(r x n) */
            double kn = A->inv_mass + B->inv_mass + v3_dot(p->ia_n, p->ra_n) + v3_dot(p->ib_n, p->rb_n);
            double k1 = A->inv_mass + B->inv_mass + v3_dot(p->ia_t[0], p->ra_t[0]) + v3_dot(p->ib_t[0], p->rb_t[0]);
            double k2 = A->inv_mass + B->inv_mass + v3_dot(p->ia_t[1], p->ra_t[1]) + v3_dot(p->ib_t[1], p->rb_t[1]);
            p->normal_mass = kn > 0 ? 1.0 / kn : 0.0;
            p->tangent_mass[0] = k1 > 0 ? 1.0 / k1 : 0.0;
            p->tangent_mass[1] = k2 > 0 ? 1.0 / k2 : 0.0;
            p->base_separation = mp->separation;
            p->relative_velocity = impulse_relative_normal_velocity(B, A, p->rb, p->ra, c->n);
            if (p->relative_velocity < 0.0 && mp->separation > 0.0 && an < 0.0) {
                /* the gap closes under gravity before impact: restitution needs the
                 * approach speed at impact, v^2 = v0^2 + 2 |a| gap */
                p->relative_velocity = -sqrt(p->relative_velocity * p->relative_velocity - 2.0 * an * mp->separation);
            }
            p->normal_impulse = ws * c->warm[j].normal_impulse;
            p->tangent_impulse[0] = ws * c->warm[j].tangent_impulse[0];
            p->tangent_impulse[1] = ws * c->warm[j].tangent_impulse[1];
            p->total_normal_impulse = 0.0;
            p->max_normal_impulse = 0.0;
            if (penalty) {
                double omega = TWO_PI * contact_hertz;
                /* the automatic explicit spring (critically damped) stays stable:
                 * h^2 w^2 + 4 h w < 4 * 0.8 at h w <= 0.6 */
                if (!def->penalty_implicit && omega * h > 0.6) omega = 0.6 / h;
                p->penalty_k = def->penalty_stiffness > 0 ? def->penalty_stiffness : p->normal_mass * omega * omega;
                p->penalty_c = def->penalty_damping > 0 ? def->penalty_damping : 2.0 * p->normal_mass * omega;
                p->normal_impulse = 0.0;
                p->tangent_impulse[0] = p->tangent_impulse[1] = 0.0;
            }
            if (-mp->separation > max_pen) max_pen = -mp->separation;
            if (!wide) points++;
        }
    }

    if (penalty && !penalty_check(w, cc, ncon, h)) return -1; /* before any body moved */

    /* impacts first, at the geometry of the moment of contact (impact.c) */
    int impacts = !penalty && def->enable_restitution;
    if (impacts && !impact_resolve(w, cc, ncon, nb, dt)) return 0;

    solve_context sc = {bodies, s->delta_position, s->delta_rotation, 1.0 / h,
                        def->contact_push_max_velocity, def->linear_slop, def->baumgarte,
                        def->position_correction, friction_on, 0};
    solve_context sc_last = sc;
    sc_last.hold_bounces = impacts;
    vec3 g = v3(def->gravity.x, def->gravity.y, def->gravity.z);

    for (int step = 0; step < substeps; step++) {
        /* integrate velocities */
        for (int b = 1; b < nb; b++) {
            int slot = s->body_slot[b];
            impulse_body *B = &bodies[b];
            if (B->inv_mass == 0.0) continue; /* kinematic */
            vec3 acc = v3_madd(v3_scale(g, bs->gravity_scale[slot]), B->inv_mass, bs->force[slot]);
            B->v = v3_madd(B->v, h, acc);
            if (bs->linear_damping[slot] > 0) B->v = v3_scale(B->v, 1.0 / (1.0 + h * bs->linear_damping[slot]));
            if (bs->angular_damping[slot] > 0) B->w = v3_scale(B->w, 1.0 / (1.0 + h * bs->angular_damping[slot]));
        }
        project_planar(w, nb);
        if (penalty) {
            penalty_solve(w, cc, ncon, h);
        } else {
            if (def->warm_starting) {
                if (wide) wide_warm_start(wide, cc, bodies);
                else warm_start(cc, ncon, bodies);
            }
            for (int it = 0; it < def->iterations; it++) {
                if (wide) wide_solve(wide, cc, &sc, 1);
                else for (int c = 0; c < ncon; c++) solve_constraint(&cc[c], &sc, 1);
            }
            for (int o = 0; o < shock; o++) {
                contact_constraint *c = &cc[order[o]];
                if (c->wide_batch >= 0) wide_read_impulses(wide, c);
                solve_constraint_shock(c, &sc, 1, level[c->a] < level[c->b]);
            }
        }
        project_planar(w, nb);
        /* integrate positions */
        for (int b = 1; b < nb; b++) {
            int slot = s->body_slot[b];
            impulse_body *B = &bodies[b];
            vec3 dx = v3_scale(B->v, h);
            if (!in_contact[b] && B->inv_mass > 0.0 && !(bs->linear_damping[slot] > 0)) {
                /* in free flight the acceleration is constant over the sub-step: x += v0 h + a h^2 / 2
                 * exactly (v = v0 + a h here), where semi-implicit Euler's v h flies an arc low by v h / 2 */
                vec3 acc = v3_madd(v3_scale(g, bs->gravity_scale[slot]), B->inv_mass, bs->force[slot]);
                dx = v3_madd(dx, -0.5 * h * h, acc);
            }
            bs->center[slot] = v3_add(bs->center[slot], dx);
            s->delta_position[b] = v3_add(s->delta_position[b], dx);
            if (B->w.x != 0.0 || B->w.y != 0.0 || B->w.z != 0.0) {
                vec3 wr = B->w;
                if (B->inv_mass > 0.0 && !(bs->flags[slot] & (BODY_LOCK_PLANE | BODY_LOCK_ROTATION))) {
                    /* between impulses L = I w is what holds: rotate with the
                     * midpoint w of Euler's equations (rotation.c), the solver
                     * keeps w = I_start^-1 L for the step's impulses */
                    vec3 L = m3_mulv(m3_inverse(B->inv_inertia), B->w);
                    bs->rotation[slot] = rotation_free_step(bs->rotation[slot], bs->inertia_local[slot],
                                                            bs->inv_inertia_local[slot], L, h, &wr);
                } else {
                    bs->rotation[slot] = q_integrate(bs->rotation[slot], wr, h);
                }
                s->delta_rotation[b] = v3_madd(s->delta_rotation[b], h, wr);
            }
        }
        if (!penalty) {
            const solve_context *rc = step == substeps - 1 ? &sc_last : &sc;
            for (int it = 0; it < def->relax_iterations; it++) {
                if (wide) wide_solve(wide, cc, rc, 0);
                else for (int c = 0; c < ncon; c++) solve_constraint(&cc[c], rc, 0);
            }
            if (def->relax_iterations > 0)
                for (int o = 0; o < shock; o++) {
                    contact_constraint *c = &cc[order[o]];
                    if (c->wide_batch >= 0) wide_read_impulses(wide, c);
                    solve_constraint_shock(c, rc, 0, level[c->a] < level[c->b]);
                }
            project_planar(w, nb);
        }
    }
    if (wide) wide_store(wide, cc);
    if (impacts) impact_finish(w, nb);

    /* store impulses for warm starting, raise hit events */
    for (int c = 0; c < ncon; c++) {
        contact_constraint *con = &cc[c];
        contact *ct = &cs->items[con->contact];
        contact_data *cd = &cs->data[con->contact];
        double approach = 0.0, total = 0.0, tangent = 0.0;
        int deepest = 0;
        for (int j = 0; j < con->count; j++) {
            constraint_point *p = &con->p[j];
            cd->state[j].normal_impulse = p->normal_impulse;
            cd->state[j].tangent_impulse[0] = p->tangent_impulse[0];
            cd->state[j].tangent_impulse[1] = p->tangent_impulse[1];
            total += p->total_normal_impulse;
            if (-p->relative_velocity > approach) { approach = -p->relative_velocity; deepest = j; }
        }
        if (approach > def->hit_event_threshold && total > 0.0) {
            for (int j = 0; j < con->count; j++) {
                const constraint_point *p = &con->p[j];
                tangent += sqrt(p->tangent_impulse[0] * p->tangent_impulse[0] + p->tangent_impulse[1] * p->tangent_impulse[1]) * substeps;
            }
            carom_contact_event e;
            memset(&e, 0, sizeof e);
            e.type = CAROM_EVENT_HIT;
            e.a = world_make_id(w, ct->id_a);
            e.b = world_make_id(w, ct->id_b);
            vec3 pt = cd->m.points[deepest].point;
            e.point.x = pt.x; e.point.y = pt.y; e.point.z = pt.z;
            e.normal.x = con->n.x; e.normal.y = con->n.y; e.normal.z = con->n.z;
            e.normal_impulse = total;
            e.tangent_impulse = tangent;
            e.approach_speed = approach;
            e.average_force = impulse_average_force(total, dt);
            if (world_push_event(w, &e)) world_set_last_event_contact(w, con->contact);
        }
    }

    /* write velocities back; clamp and guard */
    int awake = 0;
    double vmax = def->max_linear_speed, wmax = def->max_angular_speed;
    for (int b = 1; b < nb; b++) {
        int slot = s->body_slot[b];
        vec3 v = bodies[b].v, av = bodies[b].w;
        v = clamp_length(v, vmax, &clamped);
        int angular_clamped = 0;
        av = clamp_length(av, wmax, &angular_clamped);
        quat q = bs->rotation[slot];
        if (!v3_is_finite(v) || !v3_is_finite(av) || !v3_is_finite(bs->center[slot]) ||
            !(isfinite(q.w) && isfinite(q.x) && isfinite(q.y) && isfinite(q.z))) {
            /* never propagate NaN: undo this step's motion and stop the body */
            bs->center[slot] = v3_sub(bs->center[slot], s->delta_position[b]);
            if (!v3_is_finite(bs->center[slot])) bs->center[slot] = v3_zero();
            s->delta_position[b] = v3_zero(); /* nothing for continuous collision to sweep */
            bs->rotation[slot] = q_normalize(q); /* identity if it overflowed */
            v = v3_zero();
            av = v3_zero();
            w->stats.non_finite++;
        }
        bs->velocity[slot] = v;
        bs->angular_velocity[slot] = av;
        if (bs->flags[slot] & BODY_LOCK_PLANE) {
            vec3 nrm = bs->plane_normal[slot];
            bs->center[slot] = v3_madd(bs->center[slot], bs->plane_offset[slot] - v3_dot(nrm, bs->center[slot]), nrm);
        }
        if (bs->flags[slot] & BODY_HAS_FORCE) {
            bs->force[slot] = v3_zero();
            bs->flags[slot] &= ~(uint32_t)BODY_HAS_FORCE;
        }
        if (!(bs->flags[slot] & BODY_LOCK_ROTATION) && bodies[b].inv_mass > 0.0 &&
            (av.x != 0.0 || av.y != 0.0 || av.z != 0.0)) {
            /* the solver worked with the step's starting inertia; carry its angular
             * momentum L = I_start w to the new orientation (w = I_end^-1 L), so a
             * freely tumbling body conserves L rather than w */
            vec3 L = m3_mulv(m3_inverse(bodies[b].inv_inertia), av);
            body_update_inertia(bs, slot);
            av = m3_mulv(bs->inv_inertia_world[slot], L);
            if (bs->flags[slot] & BODY_LOCK_PLANE) av = v3_scale(bs->plane_normal[slot], v3_dot(av, bs->plane_normal[slot]));
            /* at the new inertia a clamped spin can read faster again */
            if (angular_clamped) av = clamp_length(av, wmax, &angular_clamped);
            if (!v3_is_finite(av)) { /* the ranges keep this finite; never let NaN through if not */
                av = v3_zero();
                w->stats.non_finite++;
            }
            bs->angular_velocity[slot] = av;
        } else {
            body_update_inertia(bs, slot);
        }
        clamped += angular_clamped > 0;
        awake++;
    }
    w->stats.clamped += clamped;
    w->stats.awake_bodies = awake;
    w->stats.contacts = contacts_touching;
    w->stats.contact_points = points;
    w->stats.pairs = cs->count;
    w->stats.max_penetration = max_pen;
    return 1;
}
