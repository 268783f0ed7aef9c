/* toi.c - continuous collision. Speculative contacts catch ordinary motion;
 * a body whose surface moved farther than its own thickness this step (or
 * any bullet) is swept over the step against everything near its path -
 * static, kinematic, sleeping and moving dynamic bodies - and it and the
 * body it meets are stopped at the first time of impact, so the next step's
 * speculative contact lands them on each other instead of tunnelling or
 * being pushed out softly.
 *
 * Motion over the step, fraction t in [0, 1]: the centre of mass moves on
 * the straight line from its start to its end, the orientation turns by the
 * step's accumulated rotation vector (exp(t dtheta) q0, the true path of a
 * body spinning about a fixed axis, however many turns). Each pair's time
 * of impact is found by conservative advancement (Mirtich's bound, as
 * Bullet's continuous convex collision uses it): at the current time, the
 * separation d cannot close faster than the relative motion along the
 * contact normal plus each body's rotation angle times its reach from the
 * centre of mass, so advancing t by d / that bound never passes contact.
 *
 * A pair already touching at the start is swept too (a resting body struck
 * downwards at 4000 m/s would otherwise end half a metre inside the floor):
 * it may sink at most TOI_SINK (5 mm) below where it started. A body stopped at
 * fraction f stays stopped there for later pairs; passes repeat until no
 * fraction changes (a box stopped by one body must stop the one behind it).
 *
 * A body thicker than its step's travel is swept too where it ends more
 * than TOI_SINK deep in a static or kinematic body after moving otherwise
 * than its contacts looked ahead for (struck, or set turning, within the
 * step) or after touching one whose contacts did not hold it (end_state):
 * against the static and kinematic bodies alone, from its start pose, so it
 * stops where it met the ground. */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "filter.h"
#include "compound.h"
#include "gjk.h"
#include "mesh.h"
#include "heightfield.h"
#include "world.h"
#include "toi.h"
#include "collision.h"

#define TOI_MAX_ITERATIONS 64
/* how far a touching pair may sink within a step before its sweep stops it
 * (the contact solve removes that overlap; linear_slop's default once) */
#define TOI_SINK 0.005
#define TOI_MAX_PASSES 32
/* farther apart than this, a pair's separation is its distance (GJK's
 * proven lower bound); nearer, the contacts the next step will see */
#define TOI_NEAR 0.01
/* the look-ahead of a near pair's contacts against a mesh or height field */
#define TOI_NEAR_REACH (4 * TOI_NEAR)

/* How fast the shape's surface can approach anything per radian of turn
 * about the unit axis u (body frame) through the centre of mass com: the
 * largest distance from that axis of the points that carry its geometry
 * (a box's or hull's vertices, a capsule's segment ends; a sphere turning
 * about its centre does not change the space it fills, and a cylinder's
 * rim only moves with the tilt of its axis). */
static double turn_reach(const shape *s, vec3 com, vec3 u)
{
    double m = 0.0;
    switch (s->type) {
    case SHAPE_SPHERE: return v3_len(v3_cross(com, u));
    case SHAPE_CAPSULE: case SHAPE_CYLINDER: {
        for (int k = -1; k <= 1; k += 2)
            m = dmax(m, v3_len(v3_cross(v3_sub(v3(0, 0, k * s->half_height), com), u)));
        if (s->type == SHAPE_CYLINDER) m += s->radius * v3_len(v3_cross(v3(0, 0, 1), u));
        return m;
    }
    case SHAPE_BOX:
        for (int k = 0; k < 8; k++) {
            vec3 h = s->half_extents;
            vec3 p = v3(k & 1 ? h.x : -h.x, k & 2 ? h.y : -h.y, k & 4 ? h.z : -h.z);
            m = dmax(m, v3_len(v3_cross(v3_sub(p, com), u)));
        }
        return m;
    case SHAPE_HULL:
        for (int k = 0; k < s->hull->vertex_count; k++)
            m = dmax(m, v3_len(v3_cross(v3_sub(s->hull->vertices[k], com), u)));
        return m;
    case SHAPE_COMPOUND:
        /* each child about the same axis, in its own frame: a dumbbell rolling
         * on its spheres turns about the line through their centres and moves
         * no surface by it (its bounding reach, 0.55 m at 28 rad/s, made each
         * step's advancement creep 9 mm at a time until the iterations ran
         * out: at dt 1/30 it stopped it 45 % into the step, 20 % short after
         * 2 s down a slope) */
        for (int i = 0; i < s->compound->count; i++) {
            xform p = s->compound->poses[i];
            m = dmax(m, turn_reach(&s->compound->children[i], q_inv_rotate(p.q, v3_sub(com, p.p)), q_inv_rotate(p.q, u)));
        }
        return m;
    default: return shape_bounding_radius(s) + v3_len(com);
    }
}

/* A body's motion over the step (see the header). */
typedef struct sweep {
    vec3 c0, dc;          /* centre of mass at the start, and its travel */
    quat q0;
    vec3 dtheta;          /* rotation vector over the step */
    double reach;         /* farthest surface point from the centre of mass */
    double turn;          /* |dtheta| times the reach from the turning axis (turn_reach) */
    int moving;           /* 0: at rest all step (static, sleeping) */
    int at_rest_only;     /* swept only against static and kinematic bodies (see world_continuous) */
} sweep;

/* A body the sweeps read: its motion and where it stops (1 = its end pose). */
typedef struct toi_body {
    sweep sw;
    double fraction;
} toi_body;

/* The bodies a step's sweeps read are the fast ones and those near their
 * paths, a few of the world's: each gets its toi_body when first read (the
 * same sweep at any time: nothing the sweep reads changes before the
 * bodies are moved back), found through the slot's index (one int a slot
 * instead of a sweep and a fraction: 6.8 MB at 50,000 bodies with one of
 * them fast). */
typedef struct toi_context {
    carom_world *w;
    const step_context *step;
    int *index;           /* per store slot: its toi_body + 1, 0: none yet */
    toi_body *bodies;     /* step_scratch.toi_bodies */
    int slot;             /* the body being swept */
    double target, slop;  /* separation to stop at, allowed extra sinking of a touching pair */
    int changed;
    int *near, near_count; /* the slots the swept body's query found (step_scratch.toi_near) */
    int failed;           /* out of memory */
} toi_context;

static toi_body *toi_of(const toi_context *ctx, int slot) { return &ctx->bodies[ctx->index[slot] - 1]; }

static xform pose_at(const carom_world *w, const sweep *sw, double f, int slot, double t)
{
    const body_store *s = &w->bodies;
    if (!sw->moving || t >= f) t = f;
    if (!sw->moving || t >= 1.0) return body_xform(s, slot);
    quat q = q_normalize(q_mul(q_exp(v3_scale(sw->dtheta, t)), sw->q0));
    vec3 c = v3_madd(sw->c0, t, sw->dc);
    xform x = {v3_sub(c, q_rotate(q, s->local_center[slot])), q};
    return x;
}

/* ---- separation far from contact: distance only ------------------------------
 * Conservative advancement needs only a lower bound of the distance and the
 * direction it holds along while the pair is apart; building contact
 * manifolds for it (every triangle of a mesh within the step's reach, each
 * clipped and grouped) cost the terrain most of its continuous collision.
 * Farther than TOI_NEAR, GJK's proven lower bound and its separating plane's
 * normal serve (for a mesh or height field: the least over the triangles,
 * each first bounded by its plane); nearer, or overlapping, the full contact
 * collision decides as before, so where a body stops is judged by the same
 * contacts the solver will see. */

typedef struct far_query {
    const shape *s;       /* the convex shape, at xs */
    xform xs, xm;         /* and the mesh's frame */
    int two_sided;
    double best;          /* least lower bound so far (starts at the range) */
    vec3 normal;          /* its normal, from the triangle to the shape */
    int near;             /* 1: a triangle within TOI_NEAR: the full collision decides */
} far_query;

static int far_triangle(void *ctx, const vec3 v[3], unsigned active, uint32_t index)
{
    far_query *q = ctx;
    (void)active;
    (void)index;
    /* positions relative to the shape (precision far from the origin) */
    vec3 t[3];
    for (int k = 0; k < 3; k++) t[k] = v3_sub(xf_point(q->xm, v[k]), q->xs.p);
    vec3 n = v3_cross(v3_sub(t[1], t[0]), v3_sub(t[2], t[0]));
    double len = v3_len(n);
    if (!(len > 0) || !isfinite(len)) return 1; /* degenerate: no contact either */
    n = v3_scale(n, 1.0 / len);
    /* the shape's extent along the face normal bounds its distance from the triangle */
    vec3 lo = q_rotate(q->xs.q, shape_support_local(q->s, q_inv_rotate(q->xs.q, v3_neg(n))));
    vec3 hi = q_rotate(q->xs.q, shape_support_local(q->s, q_inv_rotate(q->xs.q, n)));
    double below = v3_dot(n, v3_sub(lo, t[0])), above = v3_dot(n, v3_sub(hi, t[0]));
    if (!q->two_sided && above < 0) return 1; /* wholly behind a one-sided face: it never collides */
    double bound = q->two_sided ? dmax(below, -above) : below;
    if (bound >= q->best) return 1;
    gjk_proxy pt = {NULL, t, 3, {v3_zero(), q_identity()}};
    gjk_proxy ps = {q->s, NULL, 0, {v3_zero(), q->xs.q}};
    gjk_result r = gjk_distance(&pt, &ps);
    if (r.overlap || !(r.lower_bound > TOI_NEAR)) { q->near = 1; return 0; }
    if (r.lower_bound < q->best) { q->best = r.lower_bound; q->normal = r.lower_normal; }
    return 1;
}

/* Radius of a ball about the shape's origin inside it (0 when not known). */
static double inner_radius(const shape *s)
{
    switch (s->type) {
    case SHAPE_SPHERE: case SHAPE_CAPSULE: case SHAPE_BOX: case SHAPE_CYLINDER: return shape_thickness(s);
    default: return 0.0;
    }
}

static xform xf_mul(xform a, xform b)
{
    xform r = {xf_point(a, b.p), q_mul(a.q, b.q)};
    return r;
}

/* (toi.h) */
int toi_far_separation(const shape *a, xform xa, const shape *b, xform xb, double range, double *d, vec3 *normal)
{
    if (a->type == SHAPE_PLANE || b->type == SHAPE_PLANE) return 0;
    if (a->type == SHAPE_COMPOUND || b->type == SHAPE_COMPOUND) { /* the nearest child */
        int on_a = a->type == SHAPE_COMPOUND;
        const compound *c = on_a ? a->compound : b->compound;
        double best = range;
        vec3 bn = v3(0, 0, 1);
        for (int i = 0; i < c->count; i++) {
            double di;
            vec3 ni;
            int ok = on_a ? toi_far_separation(&c->children[i], xf_mul(xa, c->poses[i]), b, xb, best, &di, &ni)
                          : toi_far_separation(a, xa, &c->children[i], xf_mul(xb, c->poses[i]), best, &di, &ni);
            if (!ok) return 0;
            if (di < best) { best = di; bn = ni; }
        }
        *d = best;
        *normal = bn;
        return 1;
    }
    if (shape_is_composite(a) || shape_is_composite(b)) {
        if (shape_is_composite(a) && shape_is_composite(b)) return 0;
        int mesh_first = shape_is_composite(a);
        const shape *ms = mesh_first ? a : b, *cs = mesh_first ? b : a;
        far_query q;
        q.s = cs;
        q.xs = mesh_first ? xb : xa;
        q.xm = mesh_first ? xa : xb;
        q.two_sided = ms->type == SHAPE_MESH && ms->mesh->two_sided;
        q.best = range;
        q.normal = v3(0, 0, 1);
        q.near = 0;
        xform rel = {xf_inv_point(q.xm, q.xs.p), q_mul(q_conj(q.xm.q), q.xs.q)};
        aabb box = aabb_fatten(shape_aabb(cs, rel), range);
        if (ms->type == SHAPE_MESH) mesh_query(ms->mesh, box, far_triangle, &q);
        else heightfield_query(ms->field, box, far_triangle, &q);
        if (q.near) return 0;
        *d = q.best;
        *normal = mesh_first ? q.normal : v3_neg(q.normal);
        return 1;
    }
    /* a ball inside each (about its origin) bounds the distance from above:
     * a pair resting on each other is near without asking GJK */
    double ia = inner_radius(a), ib = inner_radius(b);
    if (v3_len(v3_sub(xb.p, xa.p)) - ia - ib <= TOI_NEAR) return 0;
    gjk_proxy pa = {a, NULL, 0, {v3_zero(), xa.q}};
    gjk_proxy pb = {b, NULL, 0, {v3_sub(xb.p, xa.p), xb.q}};
    gjk_result r = gjk_distance(&pa, &pb);
    if (r.overlap || !(r.lower_bound > TOI_NEAR)) return 0;
    *d = dmin(r.lower_bound, range);
    *normal = r.lower_normal;
    return 1;
}

/* Separation of bodies a and b at time t (large when beyond range), and the
 * contact normal from a to b. */
static double separation_at(const toi_context *ctx, int a, int b, double t, double range, int *try_far, vec3 *normal)
{
    const carom_world *w = ctx->w;
    const body_store *s = &w->bodies;
    const toi_body *ta = toi_of(ctx, a), *tb = toi_of(ctx, b);
    xform xa = pose_at(w, &ta->sw, ta->fraction, a, t);
    xform xb = pose_at(w, &tb->sw, tb->fraction, b, t);
    double far;
    if (*try_far) {
        if (toi_far_separation(&s->shapes[a], xa, &s->shapes[b], xb, range, &far, normal)) return far;
        *try_far = 0; /* within TOI_NEAR: the advancement only closes in from here */
    }
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    /* a mesh or height field: only the triangles within TOI_NEAR_REACH (the
     * query box grows with the look-ahead; the step's whole reach took in
     * every triangle a fast body could touch, each clipped and grouped, to
     * find the one deepest point); none that near: that much room at least,
     * and the distance test may answer again */
    double spec = range;
    int composite = shape_is_composite(&s->shapes[a]) || shape_is_composite(&s->shapes[b]);
    if (composite && spec > TOI_NEAR_REACH) spec = TOI_NEAR_REACH;
    collide(&s->shapes[a], xa, &s->shapes[b], xb, spec, &cache, &m);
    *normal = m.normal;
    if (m.count == 0) {
        if (spec < range) *try_far = 1;
        return spec;
    }
    double d = m.points[0].separation;
    for (int i = 1; i < m.count; i++) d = dmin(d, m.points[i].separation);
    return d;
}

/* Earliest time before `limit` at which a and b come within the stop
 * separation, or limit when they do not. */
static double pair_toi(const toi_context *ctx, int a, int b, double limit)
{
    const toi_body *ta = toi_of(ctx, a), *tb = toi_of(ctx, b);
    const sweep *sa = &ta->sw, *sb = &tb->sw;
    double ra = sa->moving ? sa->turn : 0.0;
    double rb = sb->moving ? sb->turn : 0.0;
    double la = sa->moving ? v3_len(sa->dc) : 0.0, lb = sb->moving ? v3_len(sb->dc) : 0.0;
    double range = la + lb + ra + rb + ctx->target;
    if (!(range > ctx->target) || !isfinite(range)) return limit;
    vec3 n;
    int try_far = 1;
    double d0 = separation_at(ctx, a, b, 0.0, range, &try_far, &n);
    /* already touching: may sink a little deeper, no more */
    double tolerance = 0.25 * ctx->target;
    double stop = d0 > ctx->target + tolerance ? ctx->target : d0 - ctx->slop + tolerance;
    double t = 0.0, d = d0;
    for (int it = 0; it < TOI_MAX_ITERATIONS; it++) {
        if (d <= stop + tolerance) return t;
        vec3 dca = sa->moving && t < ta->fraction ? sa->dc : v3_zero();
        vec3 dcb = sb->moving && t < tb->fraction ? sb->dc : v3_zero();
        double bound = v3_dot(v3_sub(dca, dcb), n);
        bound = dmax(bound, 0.0) + (t < ta->fraction ? ra : 0.0) + (t < tb->fraction ? rb : 0.0);
        /* the bound holds until one of them stops (if either does) */
        double next = limit;
        if (t < ta->fraction && ta->fraction < next) next = ta->fraction;
        if (t < tb->fraction && tb->fraction < next) next = tb->fraction;
        double step = bound > 0.0 ? (d - stop) / bound : INFINITY;
        if (!(t + step < next)) {
            if (next >= limit) return limit; /* nothing closes the gap in time */
            t = next;
        } else {
            t += step;
        }
        d = separation_at(ctx, a, b, t, range, &try_far, &n);
    }
    return t; /* not converged: stop where the advancement got (never past contact) */
}

/* The swept body's query collects the bodies near its path; they are swept
 * against after it, in rank order (sweep_against). */
static int collect_near(void *user, int id_index)
{
    toi_context *ctx = user;
    int other = ctx->w->bodies.ids[id_index].slot;
    if (other < 0 || other == ctx->slot) return 1;
    step_scratch *sc = &ctx->w->scratch;
    /* with the merge space of the sort after them */
    if (!array_reserve_near((void **)&sc->toi_near, &sc->toi_near_capacity, 2 * (ctx->near_count + 1),
                            sizeof *sc->toi_near)) {
        ctx->failed = 1;
        return 0;
    }
    ctx->near = sc->toi_near;
    ctx->near[ctx->near_count++] = other;
    return 1;
}

static sweep make_sweep(const carom_world *w, const step_context *step, int slot);

/* Gives the slot its toi_body (its sweep, not stopped) if it has none; 0 on out of memory. */
static inline int toi_add(toi_context *ctx, int slot)
{
    if (ctx->index[slot]) return 1;
    step_scratch *sc = &ctx->w->scratch;
    if (!array_reserve_near((void **)&sc->toi_bodies, &sc->toi_body_capacity, sc->toi_body_count + 1,
                            sizeof *sc->toi_bodies))
        return 0;
    ctx->bodies = sc->toi_bodies;
    toi_body *tb = &ctx->bodies[sc->toi_body_count++];
    tb->sw = make_sweep(ctx->w, ctx->step, slot);
    tb->fraction = 1.0;
    ctx->index[slot] = sc->toi_body_count;
    return 1;
}

static void sweep_against(toi_context *ctx, int other)
{
    const body_store *s = &ctx->w->bodies;
    int self = ctx->slot;
    if ((s->flags[other] | s->flags[self]) & BODY_SENSOR) return; /* sensors never stop a body */
    if (toi_of(ctx, self)->sw.at_rest_only && s->type[other] == CAROM_BODY_DYNAMIC) return;
    if (!filter_pair_allowed(ctx->w, self, other)) return; /* the bits and the world's pair filter */
    if (!toi_add(ctx, other)) { ctx->failed = 1; return; }
    toi_body *ts = toi_of(ctx, self), *to = toi_of(ctx, other);
    double limit = ts->fraction;
    /* a moving dynamic body can be stopped too: meeting sooner binds it */
    int other_stops = s->type[other] == CAROM_BODY_DYNAMIC && to->sw.moving;
    if (other_stops) limit = dmax(limit, to->fraction);
    if (!(limit > 0.0)) return;
    double t = pair_toi(ctx, self, other, limit);
    if (t < ts->fraction) { ts->fraction = t; ctx->changed = 1; }
    if (other_stops && t < to->fraction) { to->fraction = t; ctx->changed = 1; }
}

static sweep make_sweep(const carom_world *w, const step_context *step, int slot)
{
    const body_store *s = &w->bodies;
    const step_scratch *sc = &w->scratch;
    sweep sw;
    memset(&sw, 0, sizeof sw);
    sw.q0 = s->rotation[slot];
    sw.c0 = s->center[slot];
    int k = s->solver_index[slot];
    if (s->type[slot] == CAROM_BODY_STATIC || !(s->flags[slot] & BODY_AWAKE) || k <= 0) return sw;
    /* the start pose the collision stage read */
    xform x0 = sc->pose[slot];
    sw.q0 = x0.q;
    sw.c0 = v3_add(x0.p, q_rotate(x0.q, s->local_center[slot]));
    sw.dc = v3_sub(s->center[slot], sw.c0);
    sw.dtheta = step->dq[k];
    if (!v3_is_finite(sw.dc) || !v3_is_finite(sw.dtheta)) return sw;
    sw.reach = shape_bounding_radius(&s->shapes[slot]) + v3_len(s->local_center[slot]);
    double angle = v3_len(sw.dtheta);
    if (angle > 0.0) {
        vec3 axis = q_inv_rotate(sw.q0, v3_scale(sw.dtheta, 1.0 / angle));
        sw.turn = angle * dmin(turn_reach(&s->shapes[slot], s->local_center[slot], axis), sw.reach);
    }
    sw.moving = 1;
    return sw;
}

/* Whether a body whose surface moved at most `bound` this step moved
 * otherwise than its contacts looked ahead for: farther than its look-ahead
 * against a body at rest, or kicked (its centre's travel off the one its
 * start velocity and gravity predicted, or its turn beyond its start spin's)
 * by more than TOI_SINK. Speculative contacts hold what they foresaw; such
 * a body may have had none where it went (a hull at rest, struck from
 * above, turned 32 rad/s and ended 4.3 cm inside a plane). */
static int unforeseen(const carom_world *w, const step_context *step, int slot, double bound)
{
    const body_store *s = &w->bodies;
    if (!(bound > TOI_SINK)) return 0;
    if (bound > world_look_ahead_at_rest(w, step, slot) + TOI_SINK) return 1;
    const look_ahead *la = &w->scratch.ahead[slot];
    int k = s->solver_index[slot];
    const xform *x0 = &w->scratch.pose[slot];
    vec3 c0 = v3_add(x0->p, q_rotate(x0->q, s->local_center[slot]));
    vec3 off = v3_sub(v3_sub(s->center[slot], c0), v3_scale(la->velocity, step->dt));
    double reach = shape_bounding_radius(&s->shapes[slot]) + v3_len(s->local_center[slot]);
    double spin = v3_len(step->dq[k]) * reach - la->turn;
    return v3_len(off) + dmax(spin, 0.0) > TOI_SINK;
}

/* An upper bound of how far a body's surface moved over the step (the
 * centre's travel plus the turn at its bounding reach, which make_sweep's
 * turn never exceeds): 1 when the body may need a sweep (fast or a
 * bullet), 2 when it moved more than TOI_SINK (its end pose may need a
 * check, see end_state), else 0. A resting scene's bodies are all ruled
 * out by it before any sweep is built. */
static int may_need_sweep(const carom_world *w, const step_context *step, int slot)
{
    const body_store *s = &w->bodies;
    int k = s->solver_index[slot];
    if (s->type[slot] != CAROM_BODY_DYNAMIC || !(s->flags[slot] & BODY_AWAKE) || k <= 0) return 0;
    if (s->flags[slot] & BODY_BULLET) return 1;
    const xform *x0 = &w->scratch.pose[slot];
    vec3 lc = s->local_center[slot];
    const shape *sh = &s->shapes[slot];
    double bound;
    if (lc.x == 0.0 && lc.y == 0.0 && lc.z == 0.0) {
        /* the centre of mass at the origin (every primitive): c0 is the
         * start pose's origin, the same length as make_sweep's dc (a zero
         * offset turns to zeros; a non-finite start pose makes no sweep) */
        bound = v3_len(v3_sub(s->center[slot], x0->p)) + v3_len(step->dq[k]) * shape_bounding_radius(sh);
    } else {
        vec3 c0 = v3_add(x0->p, q_rotate(x0->q, lc));
        double reach = shape_bounding_radius(sh) + v3_len(lc);
        bound = v3_len(v3_sub(s->center[slot], c0)) + v3_len(step->dq[k]) * reach;
    }
    if (!(bound <= shape_thickness(sh))) return 1; /* NaN: let the sweep decide */
    return bound > TOI_SINK ? 2 : 0;
}

/* The surface travel bound of may_need_sweep (for the bodies it passed with 2). */
static double travel_bound(const carom_world *w, const step_context *step, int slot)
{
    const body_store *s = &w->bodies;
    int k = s->solver_index[slot];
    const xform *x0 = &w->scratch.pose[slot];
    vec3 lc = s->local_center[slot];
    vec3 c0 = v3_add(x0->p, q_rotate(x0->q, lc));
    double reach = shape_bounding_radius(&s->shapes[slot]) + v3_len(lc);
    return v3_len(v3_sub(s->center[slot], c0)) + v3_len(step->dq[k]) * reach;
}

/* Whether the body in `slot` ends the step deeper than TOI_SINK in a static
 * or kinematic body its filters let it touch (the deepest manifold of each,
 * as the next step's contacts will see it). */
typedef struct end_query {
    carom_world *w;             /* (the pair filter is the user's, called with the world) */
    int slot;
    int deep;
} end_query;

static int end_visit(void *user, int id_index)
{
    end_query *q = user;
    const body_store *s = &q->w->bodies;
    int other = s->ids[id_index].slot;
    if (other < 0 || other == q->slot || s->type[other] == CAROM_BODY_DYNAMIC) return 1;
    if ((s->flags[other] | s->flags[q->slot]) & BODY_SENSOR) return 1;
    if (!filter_pair_allowed(q->w, q->slot, other)) return 1;
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(&s->shapes[other], body_xform(s, other), &s->shapes[q->slot], body_xform(s, q->slot), 0.0, &cache, &m);
    for (int i = 0; i < m.count; i++)
        if (m.points[i].separation < -TOI_SINK) q->deep = 1;
    return !q->deep;
}

static int ends_deep(carom_world *w, int slot)
{
    const body_store *s = &w->bodies;
    end_query q = {w, slot, 0};
    bp_query(w->bp, shape_aabb(&s->shapes[slot], body_xform(s, slot)), end_visit, &q);
    return q.deep;
}

/* Per slot, what is known of a body that is no fast one (bits of the state
 * bytes): it touched a static or kinematic body this step; its end pose was
 * checked and found clear, or deep. */
enum { END_TOUCHED = 1, END_CLEAR = 2, END_DEEP = 4 };

/* Whether a dynamic body that moved more than TOI_SINK ends deep in a
 * static or kinematic body, where it may have: it had a contact with one
 * (the solve may not have held it: a capsule between the mesh and a heavy
 * box landing on it at 6 m/s took 357 N s in one step, and its far end, 9 cm
 * above the mesh with a speculative point there, ended 6 cm inside; a
 * capsule tipping over on a flat mesh at dt 1/30 took its far end from a
 * speculative point 17 cm above to 5 cm inside), or it moved otherwise than
 * its contacts looked ahead for (unforeseen: then it may have had none). A
 * body falling free, which has neither, is not checked. The answer is kept
 * in state[slot]. */
static int end_state(carom_world *w, const step_context *step, int slot, unsigned char *state)
{
    if (!(state[slot] & (END_CLEAR | END_DEEP))) {
        int deep = ((state[slot] & END_TOUCHED) || unforeseen(w, step, slot, travel_bound(w, step, slot))) &&
                   ends_deep(w, slot);
        state[slot] |= deep ? END_DEEP : END_CLEAR;
    }
    return (state[slot] & END_DEEP) != 0;
}

int world_continuous(carom_world *w, const step_context *step)
{
    body_store *s = &w->bodies;
    step_scratch *sc = &w->scratch;
    int n = s->count;
    int first = 0; /* the first slot that may need a sweep or a check of its end pose */
    while (first < n && !may_need_sweep(w, step, first)) first++;
    if (first == n) return 1;
    /* per slot: its toi_body's index, then its end state (a byte); then the
     * fast bodies, with the merge space of their sort */
    size_t need = (sizeof(int) + 1) * (size_t)(n > 0 ? n : 1);
    if (sc->toi_capacity < need) {
        void *p = realloc(sc->toi, need);
        if (!p) return 0;
        sc->toi = p;
        sc->toi_capacity = need;
    }
    toi_context ctx = {w, step, sc->toi, sc->toi_bodies, -1, 0.5 * TOI_SINK, TOI_SINK, 1, sc->toi_near, 0, 0};
    memset(ctx.index, 0, sizeof *ctx.index * (size_t)n);
    unsigned char *state = (unsigned char *)(ctx.index + n);
    memset(state, 0, (size_t)n);
    for (int t = 0; t < sc->touching_count; t++) {
        const contact *c = &w->contacts.items[sc->touching[t]];
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        if ((s->type[a] == CAROM_BODY_DYNAMIC) == (s->type[b] == CAROM_BODY_DYNAMIC)) continue;
        state[s->type[a] == CAROM_BODY_DYNAMIC ? a : b] |= END_TOUCHED;
    }
    sc->toi_body_count = 0;
    int fast_count = 0;
    /* the fast bodies: only those may_need_sweep's bound leaves can have
     * travelled farther than their thickness (a bullet always may); and
     * those thick enough not to pass through anything, but that moved and
     * end deep in a static or kinematic body where they may have (end_state):
     * those are swept against the static and kinematic bodies alone (a
     * landing made on the contacts is left as it is: a sweep would stop it
     * short, at the stop separation) */
    for (int i = first; i < n; i++) {
        int need_sweep = may_need_sweep(w, step, i);
        if (!need_sweep) continue;
        if (need_sweep == 2 && !end_state(w, step, i, state)) continue;
        if (!toi_add(&ctx, i)) return 0;
        sweep *sw = &toi_of(&ctx, i)->sw;
        if (!sw->moving) continue;
        /* how far any surface point moved: the centre's travel plus the turn at the reach */
        double travel = v3_len(sw->dc) + sw->turn;
        int bullet = (s->flags[i] & BODY_BULLET) != 0;
        if (!(travel > 0) || !isfinite(travel)) continue;
        if (!bullet && travel <= shape_thickness(&s->shapes[i])) {
            if (!(travel > TOI_SINK) || !end_state(w, step, i, state)) continue;
            sw->at_rest_only = 1;
        }
        if (!array_reserve_near((void **)&sc->toi_fast, &sc->toi_fast_capacity, 2 * (fast_count + 1),
                                sizeof *sc->toi_fast))
            return 0;
        sc->toi_fast[fast_count++] = i;
    }
    if (fast_count == 0) return 1;
    int *fast = sc->toi_fast;
    /* swept in rank order (collision.c), not by slot, and each against the
     * bodies near its path in rank order, not the tree's: a body stopped by
     * one pair is stopped sooner for later ones, so the order must not
     * follow creation (docs/physics.md, "Creation order") */
    world_rank_sort(s, fast, fast + fast_count, fast_count);
    for (int pass = 0; pass < TOI_MAX_PASSES && ctx.changed; pass++) {
        ctx.changed = 0;
        for (int k = 0; k < fast_count; k++) {
            int i = fast[k];
            const sweep *sw = &toi_of(&ctx, i)->sw;
            ctx.slot = i;
            /* everything the body's surface can reach along its path */
            vec3 c1 = v3_add(sw->c0, sw->dc);
            double r = sw->reach + ctx.target;
            aabb box = {v3_sub(v3_min(sw->c0, c1), v3(r, r, r)), v3_add(v3_max(sw->c0, c1), v3(r, r, r))};
            ctx.near_count = 0;
            bp_query(w->bp, box, collect_near, &ctx);
            if (ctx.failed) return 0;
            if (ctx.near_count > 1) world_rank_sort(s, ctx.near, ctx.near + ctx.near_count, ctx.near_count); /* (none near: ctx.near may be NULL) */
            for (int j = 0; j < ctx.near_count; j++) sweep_against(&ctx, ctx.near[j]);
            if (ctx.failed) return 0;
        }
    }
    for (int i = 0; i < n; i++) {
        if (!ctx.index[i]) continue;
        const toi_body *tb = toi_of(&ctx, i);
        if (!(tb->fraction < 1.0)) continue;
        xform x = pose_at(w, &tb->sw, tb->fraction, i, tb->fraction);
        s->rotation[i] = x.q;
        s->center[i] = v3_add(x.p, q_rotate(x.q, s->local_center[i]));
        body_update_inertia(s, i);
        w->stats.toi_events++;
        aabb fat = aabb_fatten(shape_aabb(&s->shapes[i], body_xform(s, i)), WORLD_AABB_MARGIN + w->def.speculative_distance);
        s->fat_box[i] = fat;
        bp_move_proxy(w->bp, s->proxy[i], fat);
    }
    return 1;
}
