/* solver.c - the soft-step sequential impulse solver: the stages that read
 * and write the world (bodies in and out, constraints from the contacts),
 * around the passes of contact_solver.c (one manifold a call), solver_wide.c
 * (four) and penalty.c. world_solve runs, in this order:
 *
 *   gather_bodies          awake bodies -> solver bodies (ctx->bodies)
 *   build_constraints      touching manifolds -> constraint headers (ctx->constraints)
 *   plan_shock             shock propagation: levels and the bottom-up order
 *   plan_wide              colours and batches for the wide passes (wide_plan)
 *   prepare_points         anchors, rows, effective masses, warm impulses
 *   check_penalty          explicit springs the sub-step cannot integrate refused
 *   resolve_impacts        impacts at the moment of contact (impact.c)
 *   per sub-step:
 *     integrate_velocities gravity, forces, torques, damping
 *     warm_start           last step's impulses
 *     solve                biased passes, then the shock pass (penalty: springs)
 *     integrate_positions  centres and orientations
 *     relax                unbiased passes, then the shock pass
 *   store_wide             the batches' impulses back to the points
 *   finish_impacts         bounced bodies keep the rest of the step (impact.c)
 *   store_impulses         the hit-event flags (the impulses are already the contacts'
 *                          point states: next step's warm start)
 *   raise_hit_events       impacts above the threshold
 *   events_raise_forces    pairs pressed above a body's force threshold (events.c)
 *   finish_bodies          velocities written back, clamps, NaN guard, inertia
 *
 * A new pass over the constraints plugs in as a stage here, with a scalar
 * verb in contact_solver.c and, if it is hot, a wide one in solver_wide.c. */
#define _POSIX_C_SOURCE 200809L /* posix_memalign */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "world.h"
#include "solver.h"
#include "contact_solver.h"
#include "column_solve.h"
#include "solver_wide.h"
#include "penalty.h"
#include "rotation.h"
#include "impact.h"
#include "events.h"
#include "tasks.h"

/* Below this many manifolds the wide passes gain nothing (mostly empty
 * lanes), and the scalar order converges faster on a small stack: colours
 * interleave its contacts (red-black), so support climbs two boxes per sweep
 * instead of the whole stack. */
#define WIDE_MIN_CONSTRAINTS 64

/* What the stages hand each other besides the step context. */
typedef struct solver_work {
    wide_set *wide;              /* NULL: every manifold takes the scalar passes */
    const int *scalar;           /* manifolds the scalar passes take (NULL: all) */
    int scalar_count;
    int *shock_order, *level, *level_count;
    int shock_count;             /* constraints in the shock pass, bottom-up */
    int *in_contact;             /* per solver body: in some manifold this step */
    int impacts;                 /* the impact phase runs (impulse model with restitution) */
    int clamped;                 /* velocities clamped this step */
    double max_penetration;
    int points;
    int locked;                  /* constraints with a plane-locked body */
    int heavy_on_light;          /* some constraint's bodies differ in mass by SHOCK_MASS_RATIO or more */
    int stiff;                   /* scalar manifolds marked stiff (contact_block.stiff) */
    column_memory *columns;      /* the columns solved directly (column_solve.c) */
} solver_work;

/* What the sub-steps read of a solver body, computed once per step from the
 * store (nothing in the step changes the forces, damping, flags or local
 * inertia it is made of): the same expressions the sub-steps evaluated
 * before, so the same bits. */
enum {
    STEP_TORQUE = 1,       /* BODY_HAS_FORCE: w += h I^-1 torque */
    STEP_LINEAR_DAMP = 2,  /* linear_damping > 0 */
    STEP_ANGULAR_DAMP = 4, /* angular_damping > 0 */
    STEP_FLIGHT = 8,       /* dynamic and undamped: free flight integrates the constant acceleration */
    STEP_FREE_SPIN = 16,   /* dynamic, unlocked, anisotropic: the midpoint rotation (rotation.c) */
    STEP_KINEMATIC = 32    /* inv_mass 0: turned by the exact exponential map */
};
enum { STEP_EXTRA = STEP_TORQUE | STEP_LINEAR_DAMP | STEP_ANGULAR_DAMP | STEP_FREE_SPIN };
typedef struct body_step {
    int flags;             /* the fields below are set only where a flag says they are read */
    int extra;             /* its body_step_extra in solver_memory.motion_extra; a STEP_EXTRA flag */
    vec3 acc;              /* gravity (scaled) and force over mass; not STEP_KINEMATIC */
} body_step;
/* What only some bodies' sub-steps read (most bodies have no torque, no
 * damping and an isotropic inertia: kept for every body, these were 112 B
 * a body, 5.6 MB at 50,000 bodies). */
typedef struct body_step_extra {
    mat3 inertia_start;    /* the step's starting world inertia, the inverse of B->inv_inertia: L = I w
                              (STEP_FREE_SPIN; finish_bodies computes the other bodies') */
    vec3 spin;             /* I^-1 torque at the step's inertia; STEP_TORQUE */
    double linear_keep;    /* 1 / (1 + h linear_damping); STEP_LINEAR_DAMP */
    double angular_keep;   /* 1 / (1 + h angular_damping); STEP_ANGULAR_DAMP */
} body_step_extra;

/* Keeps plane-locked bodies in their plane: in-plane velocity, spin about the normal. */
static void project_planar(const carom_world *w, const step_context *ctx)
{
    const body_store *bs = &w->bodies;
    if (!w->scratch.solver.planar) return; /* no awake body is locked to a plane (gather_bodies) */
    for (int k = 1; k < ctx->body_count; k++) {
        int slot = ctx->body_slot[k];
        if (!(bs->flags[slot] & BODY_LOCK_PLANE)) continue;
        vec3 nrm = bs->plane_normal[slot];
        impulse_body *b = &ctx->bodies[k];
        b->v = v3_madd(b->v, -v3_dot(b->v, nrm), nrm);
        b->w = v3_scale(nrm, v3_dot(b->w, nrm));
    }
}

/* Scales v back to length max (counting it); overflow-safe for huge finite v. */
static inline __attribute__((always_inline)) vec3 clamp_length(vec3 v, double max, int *clamped)
{
    double m = dmax(fabs(v.x), dmax(fabs(v.y), fabs(v.z)));
    if (!(m > max / 2)) return v; /* |v| <= sqrt(3) m, and NaN passes to the guard */
    vec3 u = v3_scale(v, 1.0 / m); /* no overflow in the length */
    double len = m * v3_len(u);
    if (len <= max) return v;
    (*clamped)++;
    return v3_scale(u, max / v3_len(u));
}

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


/* ---- the stages ---------------------------------------------------------- */

/* Fills m, and x when it returns 1: the body has a STEP_EXTRA flag. */
static int body_step_of(const body_store *bs, int i, const impulse_body *B, const step_context *ctx, body_step *m,
                        body_step_extra *x)
{
    if (B->inv_mass == 0.0) {
        m->flags = STEP_KINEMATIC;
        return 0;
    }
    double h = ctx->h;
    int flags = 0;
    m->acc = v3_madd(v3_scale(ctx->gravity, bs->gravity_scale[i]), B->inv_mass, bs->force[i]);
    uint32_t bf = bs->flags[i];
    if (bf & BODY_HAS_FORCE) {
        flags |= STEP_TORQUE;
        x->spin = m3_mulv(B->inv_inertia, bs->torque[i]);
    }
    double ld = bs->linear_damping[i], ad = bs->angular_damping[i];
    if (ld > 0) {
        flags |= STEP_LINEAR_DAMP;
        x->linear_keep = 1.0 / (1.0 + h * ld);
    } else {
        flags |= STEP_FLIGHT;
    }
    if (ad > 0) {
        flags |= STEP_ANGULAR_DAMP;
        x->angular_keep = 1.0 / (1.0 + h * ad);
    }
    if (!(bf & (BODY_LOCK_PLANE | BODY_LOCK_ROTATION)) && !rotation_is_isotropic(&bs->inv_inertia_local[i])) {
        flags |= STEP_FREE_SPIN;
        /* once per step, not per sub-step: integrate_rotation's L = I w */
        x->inertia_start = m3_inverse(B->inv_inertia);
    }
    m->flags = flags;
    return (flags & STEP_EXTRA) != 0;
}

/* Awake bodies, contiguous: index 0 is the shared immovable body. */
static int gather_bodies(carom_world *w, step_context *ctx, solver_work *work)
{
    body_store *bs = &w->bodies;
    step_scratch *s = &w->scratch;
    double wmax = world_spin_clamp(&w->def, ctx->h);
    for (int i = 0; i < bs->count; i++) bs->solver_index[i] = 0;
    if (!array_reserve_near((void **)&s->body_slot, &s->body_capacity, bs->count + 1, sizeof *s->body_slot)) return 0;
    /* the per-body scratch arrays share one capacity */
    int cap = s->body_capacity;
    if (cap > s->solver.bodies_capacity || !s->bodies) {
        /* 64-byte aligned (nothing in them outlives the step): a solver
         * body's velocities and inverse mass, what the passes read of it,
         * then lie in one cache line; realloc's large blocks begin 16 bytes
         * into a page, which split every one of them over two */
        void *p1 = NULL;
        if (posix_memalign(&p1, 64, sizeof *s->bodies * (size_t)cap) != 0) return 0;
        pages_hint_huge(p1, sizeof *s->bodies * (size_t)cap);
        free(s->bodies);
        s->bodies = p1;
        s->solver.bodies_capacity = cap;
    }
    void *p2 = realloc(s->delta_position, sizeof *s->delta_position * (size_t)cap);
    if (!p2) return 0;
    pages_hint_huge(p2, sizeof *s->delta_position * (size_t)cap);
    s->delta_position = p2;
    void *p3 = realloc(s->delta_rotation, sizeof *s->delta_rotation * (size_t)cap);
    if (!p3) return 0;
    pages_hint_huge(p3, sizeof *s->delta_rotation * (size_t)cap);
    s->delta_rotation = p3;
    if (!array_reserve_near(&s->solver.motion, &s->solver.motion_capacity, cap, sizeof(body_step))) return 0;
    body_step *motion = s->solver.motion;
    motion[0].flags = STEP_KINEMATIC;
    impulse_body *bodies = s->bodies;
    memset(&bodies[0], 0, sizeof bodies[0]);
    s->delta_position[0] = v3_zero();
    s->delta_rotation[0] = v3_zero();
    s->body_slot[0] = -1;
    int nb = 1, extra_count = 0;
    uint32_t any_flags = 0;
    for (int i = 0; i < bs->count; i++) {
        if (bs->type[i] == CAROM_BODY_STATIC || !(bs->flags[i] & BODY_AWAKE)) continue;
        int k = nb++;
        bs->solver_index[i] = k;
        s->body_slot[k] = i;
        /* clamp before integrating: a finite but huge velocity set by the user
         * would otherwise overflow the pose to inf/NaN within the step */
        bodies[k].v = clamp_length(bs->velocity[i], w->def.max_linear_speed, &work->clamped);
        bodies[k].w = clamp_length(bs->angular_velocity[i], wmax, &work->clamped);
        bodies[k].inv_mass = bs->inv_mass[i];
        bodies[k].inv_inertia = bs->inv_inertia_world[i];
        s->delta_position[k] = v3_zero();
        s->delta_rotation[k] = v3_zero();
        body_step_extra x;
        if (body_step_of(bs, i, &bodies[k], ctx, &motion[k], &x)) {
            if (!array_reserve_near(&s->solver.motion_extra, &s->solver.motion_extra_capacity, extra_count + 1,
                                    sizeof(body_step_extra)))
                return 0;
            motion[k].extra = extra_count;
            ((body_step_extra *)s->solver.motion_extra)[extra_count++] = x;
        }
        any_flags |= bs->flags[i];
    }
    s->solver.planar = (any_flags & BODY_LOCK_PLANE) != 0;
    s->solver.rotation_locked = (any_flags & BODY_LOCK_ROTATION) != 0;
    ctx->bodies = bodies;
    ctx->dp = s->delta_position;
    ctx->dq = s->delta_rotation;
    ctx->body_slot = s->body_slot;
    ctx->body_count = nb;
    return 1;
}

/* 1 when a point of the manifold already touches (separation <= 0) and the
 * bodies approach there faster than max_push before solving. */
static int touching_impact(const contact_constraint *c, const impulse_body *A, const impulse_body *B, vec3 ca, vec3 cb,
                           double max_push)
{
    /* a bound first (most pairs rest): at a point the normal speed is the
     * centres' n.(vb - va) to within |wa| |ra| + |wb| |rb| */
    double ra2 = -1.0, rb2 = 0.0;
    for (int j = 0; j < c->count; j++) {
        const manifold_point *mp = &c->m->points[j];
        if (mp->separation > 0.0) continue;
        ra2 = dmax(ra2, v3_len2(v3_sub(mp->point, ca)));
        rb2 = dmax(rb2, v3_len2(v3_sub(mp->point, cb)));
    }
    if (ra2 < 0.0) return 0; /* nothing touches */
    double centres = v3_dot(c->n, v3_sub(B->v, A->v));
    double turn = sqrt(v3_len2(A->w) * ra2) + sqrt(v3_len2(B->w) * rb2);
    if (centres - turn > -max_push + 1e-9 * (fabs(centres) + turn + max_push)) return 0;
    for (int j = 0; j < c->count; j++) {
        const manifold_point *mp = &c->m->points[j];
        if (mp->separation > 0.0) continue;
        vec3 ra = v3_sub(mp->point, ca), rb = v3_sub(mp->point, cb);
        if (impulse_relative_normal_velocity(B, A, rb, ra, c->n) < -max_push) return 1;
    }
    return 0;
}

/* A manifold's softness, stiffened by the load it carries. A soft contact
 * of frequency f on the pair's reduced mass m sags W / (m (2 pi f)^2) under
 * a steady load W, so a column's sag grows with the square of its height
 * (10 unit boxes at 30 Hz: 2.55 cm; 40: 43 cm) and so does the tilt the
 * sag allows, which topples tall towers. The spring is tuned to the mass it
 * holds up: the pair's reduced mass plus the load its last impulses carried
 * against gravity, m_load = sum(lambda) / (h g), f' = f sqrt(1 + m_load / m),
 * at most f sqrt(2) (twice the stiffness): with one Gauss-Seidel pass a
 * stiffer spring rocks a column sideways (cap 2 f: the 10-column at fast
 * walked 22 cm; no cap: every tower fell). A contact carrying at least its
 * own pair's weight rests at half the setting's sag; a fresh or unloaded
 * contact (landing, impact) keeps the setting's softness. Only with relax
 * passes: without them (fast) the biased pass's push-out speed stays in the
 * bodies, and the stiffer spring rocked the 10-column 7 cm sideways (2.55 cm
 * unstiffened). docs/physics.md section 5 has the measurements. */
#define LOAD_STIFFENING_MAX 1.4142135623730951

/* What loaded_softness reads that is the same for every manifold of the
 * step: whether it stiffens at all, and the softness at the cap (most
 * loaded contacts reach it), one for a pair with a fixed body, one without. */
typedef struct load_softness {
    int loaded;
    double load_scale;           /* h |g| */
    softness capped[2];          /* [fixed] */
} load_softness;

static double loaded_stiffness(const step_context *ctx, int fixed, double f)
{
    double hertz = (fixed ? 2.0 : 1.0) * ctx->contact_hertz;
    /* never past a quarter of the sub-step rate, the setting's own cap */
    return dmin(hertz * f, dmax(hertz, 0.25 * ctx->inv_h));
}

static void load_softness_init(load_softness *ls, const step_context *ctx)
{
    ls->loaded = ctx->relax_iterations > 0 && ctx->gravity_length > 0.0 && ctx->warm_starting;
    ls->load_scale = ctx->h * ctx->gravity_length;
    for (int fixed = 0; fixed < 2; fixed++)
        ls->capped[fixed] = make_softness(loaded_stiffness(ctx, fixed, LOAD_STIFFENING_MAX), ctx->contact_damping_ratio,
                                          ctx->h);
}

static softness loaded_softness(const step_context *ctx, const load_softness *ls, const impulse_body *A,
                                const impulse_body *B, const contact_point_state *warm, int count)
{
    int fixed = A->inv_mass == 0.0 || B->inv_mass == 0.0;
    double inv_m = A->inv_mass + B->inv_mass;
    if (!(ls->loaded && inv_m > 0.0)) return fixed ? ctx->static_soft : ctx->soft;
    double load = 0.0;
    for (int j = 0; j < count; j++) load += warm[j].normal_impulse;
    if (!(load > 0.0)) return fixed ? ctx->static_soft : ctx->soft;
    double ratio = load * inv_m / ls->load_scale;
    double f = dmin(sqrt(1.0 + ratio), LOAD_STIFFENING_MAX);
    if (f == LOAD_STIFFENING_MAX) return ls->capped[fixed];
    return make_softness(loaded_stiffness(ctx, fixed, f), ctx->contact_damping_ratio, ctx->h);
}

/* One header per manifold the collision stage listed as touching: bodies,
 * basis, material, softness; the points stay for prepare_points. */
static void fill_constraint(carom_world *w, const step_context *ctx, const load_softness *ls, contact_constraint *c,
                            int i)
{
    const body_store *bs = &w->bodies;
    contact *ct = &w->contacts.items[i];
    contact_data *cd = CONTACT_DATA(&w->contacts, i);
    const impulse_body *bodies = ctx->bodies;
    int sa = bs->ids[ct->id_a].slot, sb = bs->ids[ct->id_b].slot;
    c->a = bs->solver_index[sa];
    c->b = bs->solver_index[sb];
    c->contact = i;
    c->count = cd->m.count;
    c->n = cd->m.normal;
    /* keep the friction basis stable across steps while the normal holds still */
    vec3 t1 = v3_sub(cd->tangent1, v3_scale(c->n, v3_dot(cd->tangent1, c->n)));
    if (v3_len2(t1) < 0.25) { vec3 t2; v3_basis(c->n, &t1, &t2); }
    t1 = v3_normalize(t1);
    cd->tangent1 = t1;
    c->t1 = t1;
    c->t2 = v3_cross(c->n, t1);
    c->friction = cd->friction;
    c->restitution = ctx->restitution ? cd->restitution : 0.0;
    c->rolling = ctx->friction ? cd->rolling_resistance : 0.0;
    c->soft = loaded_softness(ctx, ls, &bodies[c->a], &bodies[c->b], cd->state, cd->m.count);
    c->wide_batch = -1;
    c->m = &cd->m;
    c->p = cd->state; /* solved in place: last step's impulses until prepare scales them */
    c->center_a = bs->center[sa];
    c->center_b = bs->center[sb];
    /* plane normals (attach_extras): a moving body's, when it is locked to a plane
     * (none where no awake body is: solver_memory.planar) */
    c->locked = !w->scratch.solver.planar ? 0 :
                (bodies[c->a].inv_mass > 0.0 && (bs->flags[sa] & BODY_LOCK_PLANE) && v3_len2(bs->plane_normal[sa]) > 0.0) |
                (bodies[c->b].inv_mass > 0.0 && (bs->flags[sb] & BODY_LOCK_PLANE) && v3_len2(bs->plane_normal[sb]) > 0.0) << 1;
    c->spinless = 0; /* mark_spinless, where some body is rotation-locked */
    c->keep_scalar = 0; /* plan_wide, where a heavy column would go wide */
    c->an = NULL;
    c->r = NULL;
    c->spring = NULL;
    c->x = NULL;
    if (touching_impact(c, &bodies[c->a], &bodies[c->b], c->center_a, c->center_b, ctx->push_max)) {
        /* a touching pair driven together faster than the soft contact may
         * push out is stopped rigidly, as a speculative contact would be: a
         * soft one lets a few per cent of the approach through each sub-step
         * (a resting 0.1 m sphere struck at 100 m/s sank 9.9 mm at fast) */
        c->soft.mass_scale = 1.0;
        c->soft.impulse_scale = 0.0;
    }
    /* every force acting over the step, not only gravity: b's acceleration relative to a along n */
    /* (body_step.acc, computed by gather_bodies; zero for an unmoved body) */
    const body_step *motion = w->scratch.solver.motion;
    vec3 acc_a = motion[c->a].flags & STEP_KINEMATIC ? v3_zero() : motion[c->a].acc;
    vec3 acc_b = motion[c->b].flags & STEP_KINEMATIC ? v3_zero() : motion[c->b].acc;
    c->gravity_closing = v3_dot(c->n, v3_sub(acc_b, acc_a));
}

/* Constraints per range handed to the task hooks. */
#define CONSTRAINT_MIN_RANGE 128

/* What the later stages count over the new constraints, taken while each
 * is in the cache: integer sums and an or, added per worker as a range
 * ends, so any split gives the same totals. */
typedef struct constraint_totals {
    int extras;  /* with a plane-locked body or rolling resistance (attach_extras) */
    int locked;  /* with a plane-locked body */
    int shock;   /* some heavy-on-light pair (plan_shock) */
} constraint_totals;

/* A per-constraint loop's job. */
typedef struct constraint_job {
    carom_world *w;
    const step_context *ctx;
    contact_constraint *cc;
    int *in_contact; /* per solver body, zeroed before: set for each constraint's bodies */
    constraint_totals totals[CAROM_MAX_WORKERS];
} constraint_job;

/* One body heavier than the other by SHOCK_MASS_RATIO or more. */
static int heavy_on_light(const impulse_body *bodies, const contact_constraint *c)
{
    double ia = bodies[c->a].inv_mass, ib = bodies[c->b].inv_mass;
    return (ia > 0 && ib >= SHOCK_MASS_RATIO * ia) || (ib > 0 && ia >= SHOCK_MASS_RATIO * ib);
}

/* Ranges running at once may mark one body: the same value, stored
 * atomically where the compiler allows (so no data race). */
static inline void mark_in_contact(int *flag)
{
#if defined(__GNUC__)
    __atomic_store_n(flag, 1, __ATOMIC_RELAXED);
#else
    *flag = 1;
#endif
}

/* What fill_constraint reads, fetched ahead in stages (the manifolds come
 * bottom-up, not in the contact set's or the bodies' order, so each of its
 * reads is a cache miss of its own, and one constraint's work is too long
 * for the processor to reach the next one's loads by itself): the contact
 * and its data PREFETCH_FAR constraints ahead, the bodies' id entries half
 * way, their slots' fields and solver bodies PREFETCH_NEAR ahead, each
 * stage reading only what an earlier one brought in. Hints only: no
 * result depends on them. */
#define PREFETCH_FAR 16
#define PREFETCH_MID 8
#define PREFETCH_NEAR 4
#if defined(__GNUC__)
#define PREFETCH(p) __builtin_prefetch(p)
/* inlined: GCC drops the prefetches of a helper it keeps out of line (a call with no effect) */
#define PREFETCH_INLINE static inline __attribute__((always_inline))
#else
#define PREFETCH(p) ((void)(p))
#define PREFETCH_INLINE static inline
#endif
PREFETCH_INLINE void prefetch_constraint_inputs(const carom_world *w, const step_context *ctx, const int *touching, int k,
                                                int end)
{
    const contact_set *cs = &w->contacts;
    const body_store *bs = &w->bodies;
    if (k + PREFETCH_FAR < end) {
        int i = touching[k + PREFETCH_FAR];
        PREFETCH(&cs->items[i]);
    }
    if (k + PREFETCH_MID < end) {
        const contact *ct = &cs->items[touching[k + PREFETCH_MID]];
        const char *cd = (const char *)&cs->data[ct->slot];
        for (size_t o = 0; o < sizeof(contact_data); o += 64) PREFETCH(cd + o);
        PREFETCH(&bs->ids[ct->id_a]);
        PREFETCH(&bs->ids[ct->id_b]);
    }
    if (k + PREFETCH_NEAR < end) {
        const contact *ct = &cs->items[touching[k + PREFETCH_NEAR]];
        int sa = bs->ids[ct->id_a].slot, sb = bs->ids[ct->id_b].slot;
        PREFETCH(&bs->solver_index[sa]);
        PREFETCH(&bs->solver_index[sb]);
        PREFETCH(&bs->center[sa]);
        PREFETCH(&bs->center[sb]);
    }
    if (k + 2 < end) {
        const contact *ct = &cs->items[touching[k + 2]];
        int a = bs->solver_index[bs->ids[ct->id_a].slot], b = bs->solver_index[bs->ids[ct->id_b].slot];
        const body_step *motion = w->scratch.solver.motion;
        PREFETCH(&ctx->bodies[a]);
        PREFETCH(&ctx->bodies[b]);
        PREFETCH(&motion[a]);
        PREFETCH(&motion[b]);
    }
}

/* From this many constraints on, their inputs are fetched ahead: below it
 * they stay in the caches between steps (the canonical scenes), and the
 * prefetches would be instructions for nothing. */
#define PREFETCH_MIN_CONSTRAINTS 8192

/* Each constraint from its own manifold (its points already placed). */
static void fill_constraints_range(int begin, int end, int worker, void *p)
{
    constraint_job *j = p;
    const int *touching = j->w->scratch.touching;
    const impulse_body *bodies = j->ctx->bodies;
    int *in_contact = j->in_contact;
    load_softness ls;
    load_softness_init(&ls, j->ctx);
    constraint_totals t = {0, 0, 0};
    /* one loop, one call: fill_constraint stays inlined as it was */
    int prefetch = j->w->scratch.touching_count >= PREFETCH_MIN_CONSTRAINTS;
    for (int k = begin; k < end; k++) {
        if (prefetch) prefetch_constraint_inputs(j->w, j->ctx, touching, k, end);
        contact_constraint *c = &j->cc[k];
        fill_constraint(j->w, j->ctx, &ls, c, touching[k]);
        t.extras += c->locked || c->rolling > 0.0;
        t.locked += c->locked != 0;
        t.shock |= heavy_on_light(bodies, c);
        mark_in_contact(&in_contact[c->a]);
        mark_in_contact(&in_contact[c->b]);
    }
    constraint_totals *sum = &j->totals[worker];
    sum->extras += t.extras;
    sum->locked += t.locked;
    sum->shock |= t.shock;
}

/* The solver block's bytes (build_constraints): ncon constraints (their
 * points are the contacts' own, contact_point_state), the shock and contact
 * lists over nb bodies, then from *block_at (64-byte aligned) the scalar passes'
 * blocks (contact_prepare fills those of the manifolds it prepares; the wide
 * ones' stay untouched, so their pages are never resident). */
static size_t solver_block_bytes(int ncon, int nb, size_t *block_at)
{
    size_t con_bytes = sizeof(contact_constraint) * (size_t)ncon + sizeof(int) * (size_t)(3 * ncon + 3 * nb + 4);
    size_t at = (con_bytes + 63) / 64 * 64;
    if (block_at) *block_at = at;
    return at + sizeof(contact_block) * (size_t)ncon;
}

/* The order the manifolds are solved in, from the geometry alone, so a scene
 * gives the same results whatever order its bodies were created in (the
 * contact set's order follows creation): bottom-up by the height of the
 * manifold's centroid against gravity, then along two fixed horizontal axes
 * (without gravity: along z, then x, y). Ties (two manifolds with one
 * centroid) keep the contact set's order. Bottom-up is also the faster
 * order for a stack: a reversed 10-box column at default ended 5.1 cm from
 * its start in the creation order, 2.7 cm bottom-up (top-down: 2.9-3.4).
 * This reorders step_scratch.touching in place: the seam pass (ghost.c) has
 * already read step_scratch.mixed, whose indices into it go stale here. */
typedef struct order_key { double k[3]; int contact, points; } order_key; /* points: in the padding */
static int by_order_key(const void *pa, const void *pb)
{
    const order_key *a = pa, *b = pb;
    for (int i = 0; i < 3; i++) {
        if (a->k[i] < b->k[i]) return -1;
        if (a->k[i] > b->k[i]) return 1;
    }
    return (a->contact > b->contact) - (a->contact < b->contact);
}

/* Sorts n keys by by_order_key (a total order over distinct contacts, so
 * the result is the one qsort gave): runs of 16 by insertion, then
 * bottom-up merges through tmp, skipping a merge whose halves are already
 * in order (last step's order mostly holds). Inline comparisons instead of
 * qsort's callback: on the 2000-body pile qsort was 2.2G instructions of
 * 20.9G. trim (keys without NaN, so the order is total and every merge has
 * one answer): a merge leaves in place the left run's head below the right
 * run's first key and the right run's tail above the left run's last, found
 * by bisection, and merges only what lies between (hinted keys: a few out
 * of place in long runs). from_width: SORT_RUN for the whole sort; a block
 * width when each block of that many keys is sorted already. */
enum { SORT_RUN = 16 };
static void sort_order_keys(order_key *a, order_key *tmp, int n, int trim, int from_width)
{
    enum { RUN = SORT_RUN };
    for (int lo = 0; from_width == RUN && lo < n; lo += RUN) {
        int hi = lo + RUN < n ? lo + RUN : n;
        for (int i = lo + 1; i < hi; i++) {
            if (by_order_key(&a[i - 1], &a[i]) <= 0) continue;
            order_key x = a[i];
            int j = i;
            while (j > lo && by_order_key(&a[j - 1], &x) > 0) { a[j] = a[j - 1]; j--; }
            a[j] = x;
        }
    }
    for (int width = from_width; width < n; width *= 2) {
        for (int lo = 0; lo + width < n; lo += 2 * width) {
            int mid = lo + width, hi = lo + 2 * width < n ? lo + 2 * width : n;
            if (by_order_key(&a[mid - 1], &a[mid]) <= 0) continue; /* already in order */
            int first = lo, last = hi;
            if (trim) {
                /* first: the left run's first key above a[mid]; last: the right run's first above a[mid - 1] */
                for (int top = mid; first < top;) {
                    int m = first + (top - first) / 2;
                    if (by_order_key(&a[mid], &a[m]) < 0) top = m; else first = m + 1;
                }
                last = mid;
                for (int top = hi; last < top;) {
                    int m = last + (top - last) / 2;
                    if (by_order_key(&a[mid - 1], &a[m]) < 0) top = m; else last = m + 1;
                }
            }
            int i = first, j = mid, k = first;
            while (i < mid && j < last) tmp[k++] = by_order_key(&a[j], &a[i]) < 0 ? a[j++] : a[i++];
            while (i < mid) tmp[k++] = a[i++];
            while (j < last) tmp[k++] = a[j++];
            memcpy(a + first, tmp + first, sizeof *a * (size_t)(last - first));
        }
    }
}

/* The sort in ranges: blocks of SORT_RUN 2^k keys, sorted each by itself
 * (the same runs and merges the whole sort makes below that width, each
 * inside one block), then the merges from the block width up on the
 * calling thread. The keys end in the same order, bit for bit, on any
 * number of workers. */
typedef struct sort_job {
    order_key *a, *tmp;
    int n, block, trim;
} sort_job;

static void sort_blocks_range(int begin, int end, int worker, void *p)
{
    const sort_job *j = p;
    (void)worker;
    for (int b = begin; b < end; b++) {
        int lo = b * j->block, count = j->n - lo < j->block ? j->n - lo : j->block;
        sort_order_keys(j->a + lo, j->tmp + lo, count, j->trim, SORT_RUN);
    }
}

/* Blocks per worker: enough that a worker finishing early takes another. */
#define SORT_BLOCKS_PER_WORKER 4

static void sort_order_keys_tasks(const carom_world_def *tasks, order_key *a, order_key *tmp, int n, int trim)
{
    int workers = tasks_workers(tasks), block = SORT_RUN;
    if (workers > 1)
        while (block < n && (n + block - 1) / block > SORT_BLOCKS_PER_WORKER * workers) block *= 2;
    if (workers <= 1 || block >= n) {
        sort_order_keys(a, tmp, n, trim, SORT_RUN);
        return;
    }
    sort_job job = {a, tmp, n, block, trim};
    tasks_run(tasks, (n + block - 1) / block, 1, sort_blocks_range, &job);
    sort_order_keys(a, tmp, n, trim, block);
}

/* Keys in the order of last step's solve order (the hint), the manifolds
 * new to it after them in the contact set's order: the merges then mostly
 * find their halves in order. Without NaN the keys' order is total (ties go
 * by contact index), so the sorted result does not depend on the order the
 * keys come in; keys holds them in the contact set's order, tmp receives
 * them. The hint may be stale (a removed contact's index reused): it only
 * changes the work. */
static void order_by_hint(solver_memory *sm, const order_key *keys, order_key *tmp, int n)
{
    int *mark = sm->mark, out = 0;
    for (int k = 0; k < n; k++) mark[keys[k].contact] = k + 1;
    for (int r = 0; r < sm->last_count; r++) {
        int c = sm->last_order[r];
        if (c < sm->mark_capacity && mark[c]) {
            tmp[out++] = keys[mark[c] - 1];
            mark[c] = 0;
        }
    }
    for (int k = 0; k < n; k++) {
        int c = keys[k].contact;
        if (mark[c]) {
            tmp[out++] = keys[k];
            mark[c] = 0;
        }
    }
}

/* Keeps the solve order as next step's hint (0 on out of memory: no hint). */
static void keep_hint(solver_memory *sm, const int *touching, int n, int contacts)
{
    sm->last_count = 0;
    int had = sm->mark_capacity;
    if (!array_reserve_near((void **)&sm->last_order, &sm->last_capacity, n, sizeof *sm->last_order) ||
        !array_reserve_near((void **)&sm->mark, &sm->mark_capacity, contacts, sizeof *sm->mark))
        return;
    if (sm->mark_capacity > had) memset(sm->mark + had, 0, sizeof *sm->mark * (size_t)(sm->mark_capacity - had));
    memcpy(sm->last_order, touching, sizeof *touching * (size_t)n);
    sm->last_count = n;
}

/* The touching manifolds' keys, each from its own manifold: in ranges (the
 * reads of every manifold's points were a fifth of world_solve's own time
 * at 50,000 bodies). */
typedef struct key_job {
    const carom_world *w;
    order_key *keys;
    vec3 up, e1, e2;
} key_job;

static void order_keys_range(int begin, int end, int worker, void *p)
{
    const key_job *j = p;
    /* locals: the stores to the keys could alias the job's fields */
    const contact_set *cs = &j->w->contacts;
    const int *touching = j->w->scratch.touching;
    order_key *keys = j->keys;
    const vec3 up = j->up, e1 = j->e1, e2 = j->e2;
    (void)worker;
    for (int k = begin; k < end; k++) {
        const manifold *m = &CONTACT_DATA(cs, touching[k])->m;
        vec3 c = v3_zero();
        for (int i = 0; i < m->count; i++) c = v3_add(c, m->points[i].point);
        c = v3_scale(c, 1.0 / m->count);
        keys[k].k[0] = v3_dot(c, up);
        keys[k].k[1] = v3_dot(c, e1);
        keys[k].k[2] = v3_dot(c, e2);
        keys[k].contact = touching[k];
        keys[k].points = m->count;
    }
}

/* Also leaves each manifold's point count in solve order in sm->points:
 * build_constraints reads them there, in sequence, instead of twice from
 * the contact data in the sorted order (a cache miss per manifold at 50,000
 * bodies: 24 % of world_solve's own time). */
static int sort_touching(carom_world *w, const step_context *ctx)
{
    step_scratch *s = &w->scratch;
    solver_memory *sm = &s->solver;
    int n = s->touching_count;
    if (!array_reserve_near((void **)&sm->points, &sm->points_capacity, n > 0 ? n : 1, sizeof *sm->points)) return 0;
    if (n < 2) {
        if (n == 1) sm->points[0] = CONTACT_DATA(&w->contacts, s->touching[0])->m.count;
        return 1;
    }
    /* keys, then merge space, then the hinted order: at the start of the
     * solver block, which build_constraints fills with the constraints once
     * the keys are dead, so the keys' pages are the constraints' (a block of
     * their own was 12 MB resident at 50,000 bodies, 250 B a body). The block
     * is reserved for the constraints too, so that build_constraints does not
     * move it. */
    size_t key_bytes = sizeof(order_key) * 3 * (size_t)n, block_bytes = solver_block_bytes(n, ctx->body_count, NULL);
    if (!array_reserve(&sm->block, &sm->block_capacity, (int)(key_bytes > block_bytes ? key_bytes : block_bytes), 1))
        return 0;
    order_key *keys = sm->block;
    key_job job;
    job.w = w;
    job.keys = keys;
    job.up = v3_len2(ctx->gravity) > 0.0 ? v3_normalize(v3_neg(ctx->gravity)) : v3(0, 0, 1);
    v3_basis(job.up, &job.e1, &job.e2);
    tasks_run(ctx->tasks, n, CONSTRAINT_MIN_RANGE, order_keys_range, &job);
    int sorted = 1, nan = 0;
    for (int k = 0; k < n; k++) {
        nan |= keys[k].k[0] != keys[k].k[0] || keys[k].k[1] != keys[k].k[1] || keys[k].k[2] != keys[k].k[2];
        if (k > 0 && sorted && by_order_key(&keys[k - 1], &keys[k]) > 0) sorted = 0;
    }
    if (!sorted) {
        order_key *a = keys;
        /* NaN makes the order partial, and the result would then depend on the
         * input order and the merges' comparisons: NaN keys take the contact
         * set's order and the full merges, as without a hint */
        if (!nan && sm->last_count > 0 && sm->mark_capacity >= w->contacts.count) {
            a = keys + 2 * n;
            order_by_hint(sm, keys, a, n);
        }
        sort_order_keys_tasks(ctx->tasks, a, keys + n, n, !nan);
        for (int k = 0; k < n; k++) {
            s->touching[k] = a[k].contact;
            sm->points[k] = a[k].points;
        }
    } else {
        for (int k = 0; k < n; k++) sm->points[k] = keys[k].points;
    }
    keep_hint(sm, s->touching, n, w->contacts.count);
    return 1;
}

/* Manifolds where neither body can turn (the static body 0, or
 * rotation-locked: zero inverse inertia, and w and dq stay zero): the wide
 * passes drop their angular terms, which would only multiply zeros. Only
 * where some awake body is rotation-locked (solver_memory.rotation_locked). */
static void mark_spinless(const carom_world *w, const step_context *ctx, contact_constraint *cc, int ncon)
{
    const uint32_t *flags = w->bodies.flags;
    for (int k = 0; k < ncon; k++) {
        contact_constraint *c = &cc[k];
        c->spinless = (c->a == 0 || (flags[ctx->body_slot[c->a]] & BODY_LOCK_ROTATION)) &&
                      (c->b == 0 || (flags[ctx->body_slot[c->b]] & BODY_LOCK_ROTATION));
    }
}

/* The few manifolds with a plane-locked body or rolling resistance (n of
 * them) get their extra fields (constraint_extra), in constraint order. */
static int attach_extras(carom_world *w, const step_context *ctx, contact_constraint *cc, int ncon, int n)
{
    solver_memory *sm = &w->scratch.solver;
    const body_store *bs = &w->bodies;
    if (n == 0) return 1;
    if (!array_reserve(&sm->extra, &sm->extra_capacity, n, sizeof(constraint_extra))) return 0;
    constraint_extra *x = sm->extra;
    for (int k = 0; k < ncon; k++) {
        contact_constraint *c = &cc[k];
        if (!c->locked && !(c->rolling > 0.0)) continue;
        memset(x, 0, sizeof *x);
        if (c->locked & 1) x->lock_a = bs->plane_normal[ctx->body_slot[c->a]];
        if (c->locked & 2) x->lock_b = bs->plane_normal[ctx->body_slot[c->b]];
        c->x = x++;
    }
    return 1;
}

static int build_constraints(carom_world *w, step_context *ctx, solver_work *work)
{
    step_scratch *s = &w->scratch;
    if (!sort_touching(w, ctx)) return 0;
    int ncon = s->touching_count, npoints = 0, nb = ctx->body_count;
    const int *points = s->solver.points;
    for (int c = 0; c < ncon; c++) npoints += points[c];
    size_t block_at, all_bytes = solver_block_bytes(ncon, nb, &block_at);
    if (!array_reserve(&s->solver.block, &s->solver.block_capacity, (int)all_bytes, 1)) return 0;
    contact_constraint *cc = s->solver.block;
    work->shock_order = (int *)(cc + ncon);
    work->level = work->shock_order + ncon;
    work->level_count = work->level + nb + 1;
    work->in_contact = work->level_count + nb + 3;
    for (int b = 0; b < nb; b++) work->in_contact[b] = 0;
    constraint_job job;
    job.w = w;
    job.ctx = ctx;
    job.cc = cc;
    job.in_contact = work->in_contact;
    int workers = tasks_workers(ctx->tasks);
    for (int k = 0; k < workers; k++) job.totals[k].extras = job.totals[k].locked = job.totals[k].shock = 0;
    tasks_run(ctx->tasks, ncon, CONSTRAINT_MIN_RANGE, fill_constraints_range, &job);
    int extras = 0;
    work->locked = work->heavy_on_light = 0;
    for (int k = 0; k < workers; k++) {
        extras += job.totals[k].extras;
        work->locked += job.totals[k].locked;
        work->heavy_on_light |= job.totals[k].shock;
    }
    if (s->solver.rotation_locked) mark_spinless(w, ctx, cc, ncon);
    if (!attach_extras(w, ctx, cc, ncon, extras)) return 0;
    ctx->constraints = cc;
    ctx->blocks = (contact_block *)((char *)s->solver.block + block_at);
    ctx->constraint_count = ncon;
    ctx->point_count = npoints;
    return 1;
}

static void plan_shock(const step_context *ctx, solver_work *work)
{
    work->shock_count = 0;
    /* scenes without a heavy-on-light contact (build_constraints looked) pay nothing */
    if (!ctx->shock_propagation || ctx->penalty || !work->heavy_on_light) return;
    work->shock_count = compute_levels(ctx->constraints, ctx->constraint_count, ctx->bodies, work->level,
                                       ctx->body_count, work->shock_order, work->level_count);
}

/* The wide passes (penalty springs keep the scalar loop; the shock pass runs
 * scalar between wide passes, reading the impulses from the lanes). */
static int plan_wide(carom_world *w, const step_context *ctx, solver_work *work)
{
    step_scratch *s = &w->scratch;
    work->wide = NULL;
    work->scalar = NULL;
    work->scalar_count = ctx->constraint_count;
    if (ctx->penalty || ctx->constraint_count < WIDE_MIN_CONSTRAINTS) return 1;
    /* towers under a heavy body stay scalar, so that column_find finds them
     * (a tower among 80 other boxes fell as it did without columns) */
    if (work->heavy_on_light && !column_keep_heavy_scalar(&s->solver.columns, ctx)) return 0;
    if (!s->solver.wide_env) s->solver.wide_env = wide_read_env(); /* once per world, not a getenv a step */
    work->wide = wide_plan(&s->solver.wide, &s->solver.wide_capacity, ctx->constraints, ctx->constraint_count,
                           work->locked > 0 || s->solver.rotation_locked, ctx->body_count, s->solver.wide_env,
                           ctx->tasks);
    if (!work->wide) return 0;
    work->scalar_count = wide_overflow(work->wide, &work->scalar);
    return 1;
}

/* The k-th manifold of the scalar passes. */
static contact_constraint *scalar_constraint(const step_context *ctx, const solver_work *work, int k)
{
    return &ctx->constraints[work->scalar ? work->scalar[k] : k];
}

/* The anchors and rows of the manifolds the scalar passes take (and the
 * penalty model's springs), packed in their order; a wide-solved manifold
 * has them in its lanes only, and its anchors also here when the shock pass
 * (which reads every manifold's) runs. */
static int attach_rows(carom_world *w, const step_context *ctx, solver_work *work)
{
    solver_memory *sm = &w->scratch.solver;
    int n = 0, anchors;
    for (int k = 0; k < work->scalar_count; k++) n += scalar_constraint(ctx, work, k)->count;
    anchors = work->shock_count > 0 ? ctx->point_count : n;
    if (anchors == 0) return 1;
    if (!array_reserve(&sm->anchors, &sm->anchors_capacity, anchors, sizeof(constraint_anchor))) return 0;
    if (n > 0 && !array_reserve(&sm->rows, &sm->rows_capacity, n, sizeof(constraint_rows))) return 0;
    if (ctx->penalty && !array_reserve(&sm->springs, &sm->springs_capacity, n, sizeof(penalty_spring))) return 0;
    constraint_anchor *q = sm->anchors;
    constraint_rows *r = sm->rows;
    penalty_spring *sp = sm->springs;
    if (work->shock_count > 0) {
        for (int k = 0; k < ctx->constraint_count; k++) {
            ctx->constraints[k].an = q;
            q += ctx->constraints[k].count;
        }
    }
    for (int k = 0; k < work->scalar_count; k++) {
        contact_constraint *c = scalar_constraint(ctx, work, k);
        if (!c->an) {
            c->an = q;
            q += c->count;
        }
        c->r = r;
        r += c->count;
        if (ctx->penalty) {
            c->spring = sp;
            sp += c->count;
        }
    }
    return 1;
}

/* A wide-solved manifold's rows go straight to its lane, and its scalar
 * point keeps what restitution and the events read. */
static void prepare_points(const step_context *ctx, solver_work *work)
{
    work->max_penetration = 0.0;
    work->points = 0;
    work->stiff = 0;
    if (work->wide) {
        work->max_penetration = wide_prepare(work->wide, ctx->constraints, ctx);
        work->points = ctx->point_count;
    }
    for (int k = 0; k < work->scalar_count; k++) {
        contact_constraint *c = scalar_constraint(ctx, work, k);
        work->max_penetration = dmax(work->max_penetration, contact_prepare(c, ctx));
        if (!work->wide) work->points += c->count;
        /* the penalty model prepares no blocks (contact_prepare) */
        if (ctx->blocks && !ctx->penalty) {
            contact_block *blk = &ctx->blocks[c - ctx->constraints];
            work->stiff += blk->stiff;
            /* friction rows last where a heavy body rests on a light one
             * (contact_solver.c, solve_manifold) */
            if (work->heavy_on_light) blk->friction_first = 0;
        }
    }
}

/* Solver bodies per range handed to the task hooks. */
#define BODY_MIN_RANGE 256

/* A per-body loop's job: solver bodies 1 + begin .. 1 + end - 1. */
typedef struct body_job {
    carom_world *w;
    const step_context *ctx;
    const solver_work *work;
} body_job;

static void integrate_velocities_range(int begin, int end, int worker, void *p)
{
    const body_job *j = p;
    const step_context *ctx = j->ctx;
    const body_step *motion = j->w->scratch.solver.motion;
    const body_step_extra *extra = j->w->scratch.solver.motion_extra;
    double h = ctx->h;
    (void)worker;
    for (int b = 1 + begin; b < 1 + end; b++) {
        const body_step *m = &motion[b];
        if (m->flags & STEP_KINEMATIC) continue;
        impulse_body *B = &ctx->bodies[b];
        B->v = v3_madd(B->v, h, m->acc);
        if (!(m->flags & (STEP_TORQUE | STEP_LINEAR_DAMP | STEP_ANGULAR_DAMP))) continue;
        const body_step_extra *x = &extra[m->extra];
        /* a torque adds tau h to the angular momentum: w = I_start^-1 L as the solver keeps it */
        if (m->flags & STEP_TORQUE) B->w = v3_madd(B->w, h, x->spin);
        if (m->flags & STEP_LINEAR_DAMP) B->v = v3_scale(B->v, x->linear_keep);
        if (m->flags & STEP_ANGULAR_DAMP) B->w = v3_scale(B->w, x->angular_keep);
    }
}

static void integrate_velocities(carom_world *w, const step_context *ctx)
{
    body_job j = {w, ctx, NULL};
    tasks_run(ctx->tasks, ctx->body_count - 1, BODY_MIN_RANGE, integrate_velocities_range, &j);
    project_planar(w, ctx);
}

static void warm_start(const step_context *ctx, const solver_work *work)
{
    if (ctx->penalty || !ctx->warm_starting) return;
    if (work->wide) wide_warm_start(work->wide, ctx);
    for (int k = 0; k < work->scalar_count; k++) contact_warm_start(scalar_constraint(ctx, work, k), ctx->bodies);
}

/* Sweeps of the stiff manifolds' normal rows after each pass. */
#define BLOCK_STIFF_SWEEPS 3

/* One pass over every manifold: the batches four at a time, the rest one at a time. */
static void solve_pass(const step_context *ctx, const solver_work *work, int use_bias, int hold_bounces)
{
    if (work->wide) wide_solve(work->wide, ctx, use_bias, hold_bounces);
    int stiff = work->stiff; /* stiff manifolds that no column solved this pass */
    if (work->columns->count > 0) stiff += column_solve_pass(work->columns, ctx, use_bias, hold_bounces);
    for (int k = 0; k < work->scalar_count; k++)
        contact_solve(scalar_constraint(ctx, work, k), ctx, use_bias, hold_bounces);
    /* the stiff manifolds' normal rows again (contact_solver.c, block_loaded_softness) */
    for (int e = 0; e < BLOCK_STIFF_SWEEPS && stiff > 0; e++) {
        for (int k = 0; k < work->scalar_count; k++) {
            contact_constraint *c = scalar_constraint(ctx, work, k);
            const contact_block *blk = &ctx->blocks[c - ctx->constraints];
            if (blk->stiff && !blk->column_done) contact_solve_normals(c, ctx, use_bias);
        }
    }
}

static void shock_pass(const step_context *ctx, const solver_work *work, int use_bias, int hold_bounces)
{
    for (int o = 0; o < work->shock_count; o++) {
        contact_constraint *c = &ctx->constraints[work->shock_order[o]];
        /* a heavy column's normal rows are solved exactly (column_solve.c):
         * held immovable, its light bodies' rocking would be fed into the
         * heavy one (a 100 kg box on two 1 kg boxes fell at every preset) */
        if (c->wide_batch < 0 && ctx->blocks && ctx->blocks[work->shock_order[o]].heavy_column) continue;
        if (c->wide_batch >= 0) wide_read_impulses(work->wide, c);
        contact_solve_shock(c, ctx, use_bias, hold_bounces, work->level[c->a] < work->level[c->b]);
    }
}

static void solve(carom_world *w, const step_context *ctx, const solver_work *work)
{
    if (ctx->penalty) {
        penalty_solve(ctx);
    } else {
        for (int it = 0; it < ctx->iterations; it++) solve_pass(ctx, work, 1, 0);
        shock_pass(ctx, work, 1, 0);
    }
    project_planar(w, ctx);
}

/* Rotation over one sub-step: between impulses L = I w is what holds, so a
 * free body rotates with the midpoint w of Euler's equations (rotation.c);
 * the solver keeps w = I_start^-1 L for the step's impulses (a sphere's or
 * a cube's w is constant between impulses: the plain update, which
 * integrate_positions_range does itself). Returns the angular velocity the
 * rotation used. */
static vec3 integrate_rotation(body_store *bs, int slot, const impulse_body *B, int flags, const mat3 *inertia_start,
                               double h)
{
    vec3 wr = B->w;
    if (flags & STEP_FREE_SPIN) {
        vec3 L = m3_mulv(*inertia_start, B->w);
        bs->rotation[slot] = rotation_free_step(bs->rotation[slot], &bs->inv_inertia_local[slot], L, h, &wr);
    } else {
        /* a kinematic body's w is constant: turn it by the exact exponential map */
        bs->rotation[slot] = q_normalize(q_mul(q_exp(v3_scale(wr, h)), bs->rotation[slot]));
    }
    return wr;
}

static void integrate_positions_range(int begin, int end, int worker, void *p)
{
    const body_job *j = p;
    body_store *bs = &j->w->bodies;
    const step_context *ctx = j->ctx;
    const body_step *motion = j->w->scratch.solver.motion;
    const body_step_extra *extra = j->w->scratch.solver.motion_extra;
    const int *in_contact = j->work->in_contact;
    double h = ctx->h;
    (void)worker;
    for (int b = 1 + begin; b < 1 + end; b++) {
        int slot = ctx->body_slot[b];
        const impulse_body *B = &ctx->bodies[b];
        const body_step *m = &motion[b];
        vec3 dx = v3_scale(B->v, h);
        if ((m->flags & STEP_FLIGHT) && !in_contact[b]) {
            /* in free flight the acceleration is constant over the sub-step: x += v0 h + a h^2 / 2
             * exactly (v = v0 + a h here), where semi-implicit Euler's v h flies an arc low by v h / 2 */
            dx = v3_madd(dx, -0.5 * h * h, m->acc);
        }
        bs->center[slot] = v3_add(bs->center[slot], dx);
        ctx->dp[b] = v3_add(ctx->dp[b], dx);
        if (B->w.x != 0.0 || B->w.y != 0.0 || B->w.z != 0.0) {
            vec3 wr = B->w;
            if (m->flags & (STEP_FREE_SPIN | STEP_KINEMATIC))
                wr = integrate_rotation(bs, slot, B, m->flags,
                                        m->flags & STEP_FREE_SPIN ? &extra[m->extra].inertia_start : NULL, h);
            else
                bs->rotation[slot] = q_integrate(bs->rotation[slot], wr, h);
            ctx->dq[b] = v3_madd(ctx->dq[b], h, wr);
        }
    }
}

static void integrate_positions(carom_world *w, const step_context *ctx, const solver_work *work)
{
    body_job j = {w, ctx, work};
    tasks_run(ctx->tasks, ctx->body_count - 1, BODY_MIN_RANGE, integrate_positions_range, &j);
}

/* Without relax passes (fast) the columns' manifolds still take one: the
 * columns' normal rows and then each manifold's own solve (its friction;
 * its normal rows too where its column left them, with the stiff sweeps
 * after), unbiased. Their stiffer springs (block_loaded_softness) leave the
 * biased pass's push-out speed in the bodies, and without this pass a tilt
 * mode of the column grows from rounding: the 11-tower at fast walked
 * 3.5 mm sideways in 60 s and the 40-tower fell after 45 s (relaxing only
 * the normal rows: 2.8-4.0 mm, the 40-tower 2.4 m aside); with it they
 * stand as at default (0.28 and 2.83 cm down, sideways < 1e-8 m). Columns
 * are towers of more than ten boxes (column_solve.c), so the canonical
 * scenes at fast pay nothing. */
static void relax_columns(const step_context *ctx, const solver_work *work, int hold)
{
    const column_memory *m = work->columns;
    if (m->count == 0) return;
    column_solve_pass(work->columns, ctx, 0, hold);
    int n = column_manifold_count(m), stiff = 0;
    for (int i = 0; i < n; i++) {
        contact_constraint *c = &ctx->constraints[column_manifold(m, i)];
        const contact_block *blk = &ctx->blocks[c - ctx->constraints];
        contact_solve(c, ctx, 0, hold);
        stiff += blk->stiff && !blk->column_done;
    }
    for (int e = 0; e < BLOCK_STIFF_SWEEPS && stiff > 0; e++)
        for (int i = 0; i < n; i++) {
            contact_constraint *c = &ctx->constraints[column_manifold(m, i)];
            const contact_block *blk = &ctx->blocks[c - ctx->constraints];
            if (blk->stiff && !blk->column_done) contact_solve_normals(c, ctx, 0);
        }
}

/* The step's last relax pass holds bounces (see contact_solve) where the
 * impact phase runs. The shock pass relaxes even without relax passes
 * (fast): the biased pass leaves a heavy body the push-out velocity the
 * light one under it could not hold, and a 1000:1 pair at fast slid 19 mm
 * in 10 s (1.1 mm with this pass; scenes without a heavy-on-light contact
 * have no shock pass and pay nothing). */
static void relax(carom_world *w, const step_context *ctx, const solver_work *work, int last)
{
    if (ctx->penalty) return;
    int hold = last && work->impacts;
    for (int it = 0; it < ctx->relax_iterations; it++) solve_pass(ctx, work, 0, hold);
    if (ctx->relax_iterations == 0) relax_columns(ctx, work, hold);
    shock_pass(ctx, work, 0, hold);
    project_planar(w, ctx);
}

static void store_wide(const step_context *ctx, const solver_work *work)
{
    if (work->wide) wide_store(work->wide, ctx->constraints, ctx);
}

/* Before any body moved: 0 (error set) when an explicit penalty spring
 * cannot be integrated at the sub-step. */
static int check_penalty(carom_world *w, const step_context *ctx)
{
    char msg[WORLD_ERROR_SIZE];
    if (!ctx->penalty || penalty_check(ctx, msg, sizeof msg)) return 1;
    world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "step: %s", msg);
    return 0;
}

/* Impacts first, at the geometry of the moment of contact (impact.c). */
static int resolve_impacts(carom_world *w, const step_context *ctx, solver_work *work)
{
    work->impacts = !ctx->penalty && ctx->restitution;
    return !work->impacts || impact_resolve(w, ctx->constraints, ctx->constraint_count, ctx->body_count, ctx->dt);
}

static void finish_impacts(carom_world *w, const step_context *ctx, const solver_work *work)
{
    if (work->impacts) impact_finish(w, ctx->body_count);
}

/* A manifold's hit-event test: the fastest approach at a point before
 * solving (its speed and point in *approach, *deepest) above the threshold,
 * and some normal impulse. */
static int hit_of(const contact_constraint *con, double threshold, double *approach, double *total, int *deepest)
{
    *approach = 0.0;
    *total = 0.0;
    *deepest = 0;
    for (int j = 0; j < con->count; j++) {
        const constraint_point *p = &con->p[j];
        *total += p->total_normal_impulse;
        if (-p->relative_velocity > *approach) { *approach = -p->relative_velocity; *deepest = j; }
    }
    return *approach > threshold && *total > 0.0;
}

typedef struct impulse_job {
    carom_world *w;
    const step_context *ctx;
    const contact_constraint *cc;
    unsigned char *hit;          /* per constraint: hit_of (NULL: raise_hit_events tests them itself) */
} impulse_job;

/* Which manifolds raise a hit event. (The impulses are already the
 * contacts': a manifold's points are its contact's point states.) */
static void store_impulses_range(int begin, int end, int worker, void *p)
{
    const impulse_job *job = p;
    /* locals: the byte stores to hit may alias anything */
    const contact_constraint *cc = job->cc;
    unsigned char *hit = job->hit;
    double threshold = job->ctx->hit_event_threshold;
    (void)worker;
    for (int c = begin; c < end; c++) {
        double approach, total;
        int deepest;
        hit[c] = (unsigned char)hit_of(&cc[c], threshold, &approach, &total, &deepest);
    }
}

/* Returns the hit flags per constraint, or NULL (out of memory: raise_hit_events tests every manifold). */
static const unsigned char *store_impulses(carom_world *w, const step_context *ctx)
{
    solver_memory *sm = &w->scratch.solver;
    int n = ctx->constraint_count;
    impulse_job job = {w, ctx, ctx->constraints, NULL};
    if (!array_reserve_near((void **)&sm->hit, &sm->hit_capacity, n > 0 ? n : 1, sizeof *sm->hit)) return NULL;
    job.hit = sm->hit;
    tasks_run(ctx->tasks, n, CONSTRAINT_MIN_RANGE, store_impulses_range, &job);
    return job.hit;
}

/* In constraint order (events are raised in it): the manifolds store_impulses flagged. */
static void raise_hit_events(carom_world *w, const step_context *ctx, const unsigned char *hit)
{
    for (int c = 0; c < ctx->constraint_count; c++) {
        if (hit && !hit[c]) continue;
        const contact_constraint *con = &ctx->constraints[c];
        double approach, total, tangent = 0.0;
        int deepest;
        if (!hit_of(con, ctx->hit_event_threshold, &approach, &total, &deepest)) continue;
        for (int j = 0; j < con->count; j++) {
            const constraint_point *p = &con->p[j];
            tangent += sqrt(p->tangent_impulse[0] * p->tangent_impulse[0] + p->tangent_impulse[1] * p->tangent_impulse[1]) *
                       ctx->substeps;
        }
        events_hit(w, con->contact, deepest, total, tangent, approach, ctx->dt);
    }
}

/* Never propagate NaN: undoes the body's motion this step and stops it. */
static void reset_non_finite(carom_world *w, const step_context *ctx, int b, vec3 *v, vec3 *av, int *non_finite)
{
    body_store *bs = &w->bodies;
    int slot = ctx->body_slot[b];
    bs->center[slot] = v3_sub(bs->center[slot], ctx->dp[b]);
    if (!v3_is_finite(bs->center[slot])) bs->center[slot] = v3_zero();
    ctx->dp[b] = v3_zero(); /* nothing for continuous collision to sweep */
    bs->rotation[slot] = q_normalize(bs->rotation[slot]); /* identity if it overflowed */
    *v = v3_zero();
    *av = v3_zero();
    (*non_finite)++;
}

/* What finish_bodies counts, per worker (integer sums: any order adds up the same). */
typedef struct finish_job {
    carom_world *w;
    const step_context *ctx;
    int clamped[CAROM_MAX_WORKERS], non_finite[CAROM_MAX_WORKERS];
} finish_job;

/* Velocities back to the store, clamped and guarded; the new orientation's
 * inertia. */
static void finish_bodies_range(int begin, int end, int worker, void *p)
{
    finish_job *job = p;
    carom_world *w = job->w;
    const step_context *ctx = job->ctx;
    /* counted here, added to the worker's as the range ends (the workers'
     * counts share a cache line) */
    int clamped_here = 0, non_finite_here = 0, *clamped = &clamped_here, *non_finite = &non_finite_here;
    body_store *bs = &w->bodies;
    double vmax = w->def.max_linear_speed, wmax = world_spin_clamp(&w->def, ctx->h);
    const body_step *motion = w->scratch.solver.motion;
    const body_step_extra *extra = w->scratch.solver.motion_extra;
    for (int b = 1 + begin; b < 1 + end; b++) {
        int slot = ctx->body_slot[b];
        const impulse_body *B = &ctx->bodies[b];
        int angular_clamped = 0;
        vec3 v = clamp_length(B->v, vmax, clamped), av = clamp_length(B->w, wmax, &angular_clamped);
        quat q = bs->rotation[slot];
        if (!v3_is_finite(v) || !v3_is_finite(av) || !v3_is_finite(bs->center[slot]) ||
            !(isfinite(q.w) && isfinite(q.x) && isfinite(q.y) && isfinite(q.z)))
            reset_non_finite(w, ctx, b, &v, &av, non_finite);
        bs->velocity[slot] = v;
        bs->angular_velocity[slot] = av;
        if (bs->flags[slot] & BODY_LOCK_PLANE) {
            vec3 nrm = bs->plane_normal[slot];
            bs->center[slot] = v3_madd(bs->center[slot], bs->plane_offset[slot] - v3_dot(nrm, bs->center[slot]), nrm);
        }
        if (bs->flags[slot] & BODY_HAS_FORCE) {
            bs->force[slot] = v3_zero();
            bs->torque[slot] = v3_zero();
            bs->flags[slot] &= ~(uint32_t)BODY_HAS_FORCE;
        }
        /* (a plane-locked body turns about the plane normal only, and n.I n is
         * the same in every orientation it reaches: its w needs no carrying) */
        if (!(bs->flags[slot] & (BODY_LOCK_ROTATION | BODY_LOCK_PLANE)) && B->inv_mass > 0.0 &&
            (av.x != 0.0 || av.y != 0.0 || av.z != 0.0)) {
            /* the solver worked with the step's starting inertia; carry its angular
             * momentum L = I_start w to the new orientation (w = I_end^-1 L), so a
             * freely tumbling body conserves L rather than w */
            const body_step *m = &motion[b];
            /* L = I_start w: the inverse of the step's starting B->inv_inertia, kept
             * by gather_bodies for the bodies whose sub-steps read it */
            mat3 inertia = m->flags & STEP_FREE_SPIN ? extra[m->extra].inertia_start
                                                     : m3_inverse(B->inv_inertia);
            vec3 L = m3_mulv(inertia, av);
            body_update_inertia(bs, slot);
            av = m3_mulv(bs->inv_inertia_world[slot], L);
            if (bs->flags[slot] & BODY_LOCK_PLANE) av = v3_scale(bs->plane_normal[slot], v3_dot(av, bs->plane_normal[slot]));
            /* at the new inertia a clamped spin can read faster again */
            if (angular_clamped) av = clamp_length(av, wmax, &angular_clamped);
            if (!v3_is_finite(av)) { /* the ranges keep this finite; never let NaN through if not */
                av = v3_zero();
                (*non_finite)++;
            }
            bs->angular_velocity[slot] = av;
        } else {
            body_update_inertia(bs, slot);
        }
        *clamped += angular_clamped > 0;
    }
    job->clamped[worker] += clamped_here;
    job->non_finite[worker] += non_finite_here;
}

static void finish_bodies(carom_world *w, const step_context *ctx, solver_work *work)
{
    finish_job job;
    job.w = w;
    job.ctx = ctx;
    int workers = tasks_workers(&w->def);
    for (int k = 0; k < workers; k++) job.clamped[k] = job.non_finite[k] = 0;
    tasks_run(ctx->tasks, ctx->body_count - 1, BODY_MIN_RANGE, finish_bodies_range, &job);
    for (int k = 0; k < workers; k++) {
        work->clamped += job.clamped[k];
        w->stats.non_finite += job.non_finite[k];
    }
    w->stats.clamped += work->clamped;
    w->stats.awake_bodies = ctx->body_count - 1;
    w->stats.contacts = ctx->constraint_count;
    w->stats.contact_points = work->points;
    w->stats.pairs = w->contacts.count;
    w->stats.max_penetration = work->max_penetration;
}

void solver_memory_free(solver_memory *m)
{
    free(m->block);
    free(m->anchors);
    free(m->rows);
    free(m->springs);
    free(m->extra);
    free(m->wide);
    free(m->points);
    free(m->hit);
    free(m->last_order);
    free(m->mark);
    free(m->motion);
    free(m->motion_extra);
    column_memory_free(&m->columns);
    memset(m, 0, sizeof *m);
}

int world_solve(carom_world *w, step_context *ctx)
{
    solver_work work;
    memset(&work, 0, sizeof work);
    if (!gather_bodies(w, ctx, &work) || !build_constraints(w, ctx, &work)) return 0;
    plan_shock(ctx, &work);
    if (!plan_wide(w, ctx, &work) || !attach_rows(w, ctx, &work)) return 0;
    work.columns = &w->scratch.solver.columns;
    if (!column_find(work.columns, ctx, work.scalar, work.scalar_count, work.heavy_on_light)) return 0;
    prepare_points(ctx, &work);
    work.stiff -= column_prepare(work.columns, ctx);
    if (!check_penalty(w, ctx)) return -1;
    if (!resolve_impacts(w, ctx, &work)) return 0;
    for (int step = 0; step < ctx->substeps; step++) {
        integrate_velocities(w, ctx);
        warm_start(ctx, &work);
        solve(w, ctx, &work);
        integrate_positions(w, ctx, &work);
        relax(w, ctx, &work, step == ctx->substeps - 1);
    }
    store_wide(ctx, &work);
    finish_impacts(w, ctx, &work);
    const unsigned char *hit = store_impulses(w, ctx);
    raise_hit_events(w, ctx, hit);
    events_raise_forces(w, ctx->constraints, ctx->constraint_count, ctx->dt);
    finish_bodies(w, ctx, &work);
    return 1;
}
