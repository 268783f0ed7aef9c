/* impact.c - the collision phase of the step (impact.h).
 *
 * The contact solve treats every contact as a velocity constraint on the
 * geometry found at the start of the step, up to the look-ahead before the
 * bodies touch; restitution applied after it used that geometry (a lever arm
 * too long by the gap, a normal turned by the motion until contact), lost the
 * rest of the step after the bounce, and split impacts that arrive together
 * as if they were one plastic collision (a touching cradle's last ball left
 * at 0.22 of the impact speed at e = 1). Here, as in the seed's classical
 * method, each impact is a collision of two bodies at the moment they touch:
 *   1. time of contact tau from the gap s, the normal velocity vn and the
 *      closing acceleration a: s + vn t + a t^2 / 2 = 0;
 *   2. the manifold recomputed at both bodies' poses at tau (normal, points);
 *   3. the impulse at that geometry: vn+ = -e vn- at every point of the
 *      manifold (solved together, so a box landing flat stays flat), then
 *      Coulomb friction on that normal impulse, never more than stops the slip;
 *   4. impacts repeated pair by pair, earliest first, until no pair
 *      approaches: the propagation model of Guendelman, Bridson and Fedkiw
 *      (2003, "Nonconvex rigid bodies with stacking", collisions before
 *      contacts). Each pairwise impact at e = 1 without friction keeps energy
 *      and momentum exactly, so chains, racks and elastic gases keep theirs;
 *      a simultaneous (LCP-style) solve of all impacts at once, measured
 *      first, passes momentum only partly down a chain.
 * Impacts act on the step's starting velocities; each body then integrates
 * the whole step with its new velocity, and impact_finish moves it back by
 * what it would not have travelled: -dv tau dt. */
#include <stdlib.h>
#include <string.h>
#include "compound.h"
#include "world.h"
#include "impact.h"

#define IMPACT_MAX_PASSES 64
#define IMPACT_POINT_ITERATIONS 8
/* approach speeds below this are round-off, not impacts (m/s) */
#define IMPACT_SPEED_TOLERANCE 1e-9

typedef struct impact_body_state {
    vec3 shift_lin, shift_ang;  /* correction applied after the sub-steps */
    vec3 acc;                   /* acceleration over the step (gravity, forces) */
    double tau;                 /* fraction of the step of its latest impact */
} impact_body_state;

typedef struct impact_pair {
    int con, a, b, count;
    double tau, e, mu, threshold, closing;
    vec3 n;
    vec3 ra[MANIFOLD_MAX_POINTS], rb[MANIFOLD_MAX_POINTS];
    double normal_mass[MANIFOLD_MAX_POINTS];
    double impulse;             /* normal impulse over the phase (events) */
} impact_pair;

/* Earliest t in (0, dt] with s + vn t + a t^2 / 2 <= 0 for s > 0, or -1. */
static double time_of_contact(double s, double vn, double a, double dt)
{
    if (s <= 0.0) return 0.0;
    double disc = vn * vn - 2.0 * a * s;
    if (disc < 0.0) return -1.0;
    double den = -vn + sqrt(disc); /* 2 s / den is the smaller positive root */
    if (!(den > 0.0)) return -1.0;
    double t = 2.0 * s / den;
    return t <= dt ? t : -1.0;
}

static xform pose_at(const body_store *bs, int slot, const impulse_body *b, vec3 acc, double t)
{
    vec3 c = v3_add(bs->center[slot], v3_add(v3_scale(b->v, t), v3_scale(acc, 0.5 * t * t)));
    quat q = bs->rotation[slot];
    if (b->w.x != 0.0 || b->w.y != 0.0 || b->w.z != 0.0) q = q_integrate(q, b->w, t);
    xform x = {v3_sub(c, q_rotate(q, bs->local_center[slot])), q};
    return x;
}

/* Earliest time of contact of constraint c's points at the current
 * velocities (0: touching), or -1 when they do not meet within dt. */
static double pair_contact_time(const impulse_body *bodies, const impact_body_state *st, const contact_constraint *c,
                                double dt)
{
    const impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
    double an = v3_dot(c->n, v3_sub(st[c->b].acc, st[c->a].acc));
    double t = -1.0;
    for (int j = 0; j < c->m->count; j++) {
        const manifold_point *mp = &c->m->points[j];
        vec3 ra = v3_sub(mp->point, c->center_a), rb = v3_sub(mp->point, c->center_b);
        double vn = impulse_relative_normal_velocity(B, A, rb, ra, c->n);
        double tj = time_of_contact(mp->separation, vn, an, dt);
        if (tj >= 0.0 && (t < 0.0 || tj < t)) t = tj;
    }
    return t;
}

static void pair_init(carom_world *w, const contact_constraint *cc, int k, const impact_body_state *st, double dt,
                      impact_pair *ip)
{
    const contact_constraint *c = &cc[k];
    ip->con = k;
    ip->a = c->a;
    ip->b = c->b;
    ip->count = 0; /* geometry not built yet */
    ip->e = c->restitution;
    ip->mu = w->def.enable_friction ? c->friction : 0.0;
    ip->closing = v3_dot(c->n, v3_sub(st[c->b].acc, st[c->a].acc));
    ip->threshold = impact_threshold(w->def.restitution_threshold, ip->closing, dt);
    ip->impulse = 0.0;
    double t = pair_contact_time(w->scratch.bodies, st, c, dt);
    ip->tau = t < 0.0 ? 2.0 : t / dt; /* the order only: > 1 meets later (or never) */
}

/* The geometry of the moment of contact t (the manifold recomputed at both
 * bodies' poses then; the manifold as found when already touching). */
static void pair_geometry(carom_world *w, const contact_constraint *cc, const impact_body_state *st, impact_pair *ip,
                          double t, double dt)
{
    const body_store *bs = &w->bodies;
    const contact_constraint *c = &cc[ip->con];
    const impulse_body *A = &w->scratch.bodies[c->a], *B = &w->scratch.bodies[c->b];
    const contact *ct = &w->contacts.items[c->contact];
    int sa = bs->ids[ct->id_a].slot, sb = bs->ids[ct->id_b].slot;
    manifold m;
    vec3 ca = c->center_a, cb = c->center_b;
    m.count = 0;
    if (t > 0.0) {
        xform xa = pose_at(bs, sa, A, st[c->a].acc, t), xb = pose_at(bs, sb, B, st[c->b].acc, t);
        collide_cache cache = ct->cache;
        collide(&bs->shapes[sa], xa, &bs->shapes[sb], xb, w->def.speculative_distance, &cache, &m);
        ca = v3_add(xa.p, q_rotate(xa.q, bs->local_center[sa]));
        cb = v3_add(xb.p, q_rotate(xb.q, bs->local_center[sb]));
    }
    if (m.count == 0) {
        m = *c->m; /* touching already, or the recomputation missed */
        ca = c->center_a;
        cb = c->center_b;
    }
    ip->tau = t / dt;
    ip->n = m.normal;
    ip->count = m.count;
    for (int j = 0; j < m.count; j++) {
        ip->ra[j] = v3_sub(m.points[j].point, ca);
        ip->rb[j] = v3_sub(m.points[j].point, cb);
        /* a plane-locked body moves along the normal only by its part in the plane */
        double k = impulse_inverse_effective_mass(B, A, ip->rb[j], ip->ra[j], m.normal) -
                   (A->inv_mass - locked_inv_mass(A->inv_mass, m.normal, constraint_lock_a(c))) -
                   (B->inv_mass - locked_inv_mass(B->inv_mass, m.normal, constraint_lock_b(c)));
        ip->normal_mass[j] = row_mass(k, A->inv_mass + B->inv_mass);
    }
}

/* One collision of pair ip at the current velocities; returns 1 if it acted. */
static int pair_collide(carom_world *w, const contact_constraint *cc, impact_body_state *st, impact_pair *ip, double dt)
{
    impulse_body *bodies = w->scratch.bodies;
    impulse_body *A = &bodies[ip->a], *B = &bodies[ip->b];
    if (ip->count == 0) {
        /* not met yet: does it meet within the step at the velocities now? */
        double t = pair_contact_time(bodies, st, &cc[ip->con], dt);
        if (t < 0.0) return 0;
        pair_geometry(w, cc, st, ip, t, dt);
        if (ip->count == 0) return 0;
    }
    const contact_constraint *c = &cc[ip->con];
    double tau = dmax(ip->tau, dmax(st[ip->a].tau, st[ip->b].tau));
    /* normal velocity gained from the closing acceleration until the impact */
    double gained = ip->closing * tau * dt;
    double vn[MANIFOLD_MAX_POINTS], most = 0.0;
    for (int j = 0; j < ip->count; j++) {
        vn[j] = impulse_relative_normal_velocity(B, A, ip->rb[j], ip->ra[j], ip->n) + gained;
        if (vn[j] < most) most = vn[j];
    }
    if (!(-most > dmax(ip->threshold, IMPACT_SPEED_TOLERANCE))) return 0;
    impulse_body a0 = *A, b0 = *B;
    double target[MANIFOLD_MAX_POINTS], lambda[MANIFOLD_MAX_POINTS];
    for (int j = 0; j < ip->count; j++) {
        target[j] = vn[j] < 0.0 ? -ip->e * vn[j] : 0.0;
        lambda[j] = 0.0;
    }
    int iterations = ip->count == 1 ? 1 : IMPACT_POINT_ITERATIONS;
    for (int it = 0; it < iterations; it++)
        for (int j = 0; j < ip->count; j++) {
            double v = impulse_relative_normal_velocity(B, A, ip->rb[j], ip->ra[j], ip->n) + gained;
            double total = dmax(lambda[j] - ip->normal_mass[j] * (v - target[j]), 0.0);
            double d = total - lambda[j];
            lambda[j] = total;
            impulse_apply(B, A, ip->rb[j], ip->ra[j], v3_scale(ip->n, d));
            if (c->locked) {
                A->v = keep_in_plane(A->v, constraint_lock_a(c));
                B->v = keep_in_plane(B->v, constraint_lock_b(c));
            }
        }
    for (int j = 0; j < ip->count; j++) {
        ip->impulse += lambda[j];
        if (ip->mu > 0.0 && lambda[j] > 0.0)
            impulse_apply(B, A, ip->rb[j], ip->ra[j],
                          impulse_friction(B, A, ip->rb[j], ip->ra[j], ip->n, ip->mu, lambda[j], NULL));
        if (c->locked) { A->v = keep_in_plane(A->v, constraint_lock_a(c)); B->v = keep_in_plane(B->v, constraint_lock_b(c)); }
    }
    /* what each body would not have travelled before the impact */
    double back = tau * dt;
    if (ip->a > 0) {
        st[ip->a].shift_lin = v3_madd(st[ip->a].shift_lin, -back, v3_sub(A->v, a0.v));
        st[ip->a].shift_ang = v3_madd(st[ip->a].shift_ang, -back, v3_sub(A->w, a0.w));
        st[ip->a].tau = dmax(st[ip->a].tau, tau);
    }
    if (ip->b > 0) {
        st[ip->b].shift_lin = v3_madd(st[ip->b].shift_lin, -back, v3_sub(B->v, b0.v));
        st[ip->b].shift_ang = v3_madd(st[ip->b].shift_ang, -back, v3_sub(B->w, b0.w));
        st[ip->b].tau = dmax(st[ip->b].tau, tau);
    }
    return 1;
}

int impact_resolve(carom_world *w, contact_constraint *cc, int ncon, int nb, double dt)
{
    step_scratch *s = &w->scratch;
    const body_store *bs = &w->bodies;
    s->impact.bodies = 0;
    int candidates = 0;
    for (int k = 0; k < ncon; k++)
        if (cc[k].restitution > 0.0 && cc[k].count > 0) candidates++;
    if (candidates == 0) return 1;
    size_t need = sizeof(impact_body_state) * (size_t)nb + sizeof(impact_pair) * (size_t)candidates;
    if (need > s->impact.capacity) {
        void *p = realloc(s->impact.block, need);
        if (!p) return 0;
        s->impact.block = p;
        s->impact.capacity = need;
    }
    impact_body_state *st = s->impact.block;
    impact_pair *pairs = (impact_pair *)(st + nb);
    vec3 g = v3(w->def.gravity.x, w->def.gravity.y, w->def.gravity.z);
    memset(st, 0, sizeof *st * (size_t)nb);
    for (int b = 1; b < nb; b++) {
        int slot = s->body_slot[b];
        if (s->bodies[b].inv_mass > 0.0)
            st[b].acc = v3_madd(v3_scale(g, bs->gravity_scale[slot]), s->bodies[b].inv_mass, bs->force[slot]);
    }
    int np = 0;
    for (int k = 0; k < ncon; k++)
        if (cc[k].restitution > 0.0 && cc[k].count > 0) pair_init(w, cc, k, st, dt, &pairs[np++]);
    /* earliest first (insertion sort: stable, few pairs) */
    for (int i = 1; i < np; i++) {
        impact_pair t = pairs[i];
        int j = i - 1;
        while (j >= 0 && pairs[j].tau > t.tau) { pairs[j + 1] = pairs[j]; j--; }
        pairs[j + 1] = t;
    }
    for (int pass = 0; pass < IMPACT_MAX_PASSES; pass++) {
        int acted = 0;
        for (int i = 0; i < np; i++) acted += pair_collide(w, cc, st, &pairs[i], dt);
        if (!acted) break;
    }
    for (int i = 0; i < np; i++) {
        if (pairs[i].impulse <= 0.0) continue;
        constraint_point *p = &cc[pairs[i].con].p[0];
        p->total_normal_impulse += pairs[i].impulse;
    }
    s->impact.bodies = nb;
    return 1;
}

void impact_finish(carom_world *w, int nb)
{
    step_scratch *s = &w->scratch;
    body_store *bs = &w->bodies;
    if (s->impact.bodies != nb || nb == 0) return;
    const impact_body_state *st = s->impact.block;
    for (int b = 1; b < nb; b++) {
        if (st[b].tau <= 0.0) continue;
        int slot = s->body_slot[b];
        vec3 dx = st[b].shift_lin, dq = st[b].shift_ang;
        if (bs->flags[slot] & BODY_LOCK_PLANE) {
            vec3 nrm = bs->plane_normal[slot];
            dx = v3_madd(dx, -v3_dot(dx, nrm), nrm);
            dq = v3_scale(nrm, v3_dot(dq, nrm));
        }
        if (bs->flags[slot] & BODY_LOCK_ROTATION) dq = v3_zero();
        bs->center[slot] = v3_add(bs->center[slot], dx);
        s->delta_position[b] = v3_add(s->delta_position[b], dx);
        if (dq.x != 0.0 || dq.y != 0.0 || dq.z != 0.0) {
            bs->rotation[slot] = q_integrate(bs->rotation[slot], dq, 1.0);
            s->delta_rotation[b] = v3_add(s->delta_rotation[b], dq);
        }
    }
    s->impact.bodies = 0;
}

void impact_memory_free(impact_memory *m)
{
    free(m->block);
    m->block = NULL;
    m->capacity = 0;
}
