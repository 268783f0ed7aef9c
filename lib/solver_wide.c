/* solver_wide.c - the point preparation and the warm-start, solve and relax
 * passes over batches of four independent manifolds, one vector instruction
 * doing the work of four scalar ones (the passes are bound by arithmetic:
 * interleaving four manifolds in scalar code made the solve pass about 1.3x
 * faster, AVX2 vectors about 2.4x). Greedy graph colouring puts manifolds
 * that share no moving body in one colour; within a colour, manifolds with
 * the same number of points are packed four to a batch, field by field. Each
 * manifold is still solved point by point exactly as in solver.c; only the
 * order between manifolds becomes colour by colour. Manifolds take batches
 * of their own kind (a switch that removes work saves it): with a
 * plane-locked body beside a free one (the locked velocities kept in their
 * planes after every row), with every body static or locked to a plane
 * (three degrees of freedom a body: the planar rows), and with no body that
 * can turn (static or rotation-locked: the linear rows). Manifolds beyond
 * the last colour, or with rolling resistance, keep the scalar passes
 * (contact_solver.c). The AVX2 and SSE2 builds
 * of the passes come from one source (WIDE_PASSES below), each for two row
 * layouts: the precomputed rows (wide_point) and, for large worlds, the
 * compact ones (wide_cpoint), recomputed from the anchors in each pass. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "solver_wide.h"
#include "tasks.h"
#include "pages.h"

#define LANES 4

/* Four lanes: a GNU C vector where the compiler has them (SSE2 pairs, or one
 * AVX register in the AVX2 build of the kernels below), else an array. Both
 * are indexed as x[lane]. */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__aarch64__))
#define WIDE_VECTORS 1
typedef double lane_t __attribute__((vector_size(LANES * sizeof(double))));
typedef long long lane_mask __attribute__((vector_size(LANES * sizeof(double))));
#define WIDE_COLORS 32 /* one bit each in a body's mask */
#if defined(__x86_64__)
#define WIDE_AVX2 1
#endif
#else
/* no vectors: every manifold takes the scalar passes */
#define WIDE_VECTORS 0
#define WIDE_COLORS 1
typedef double lane_t[LANES];
#endif
#ifndef WIDE_AVX2
#define WIDE_AVX2 0
#endif

/* One point slot of a batch: lane l holds point i of the batch's l-th manifold. */
typedef struct wide_point {
    lane_t base_separation, normal_mass, normal_impulse;
    lane_t total_normal_impulse;
    lane_t ra_n[3], rb_n[3], ia_n[3], ib_n[3];
    lane_t tangent_mass[2], tangent_impulse[2];
    lane_t ra_t[2][3], rb_t[2][3], ia_t[2][3], ib_t[2][3];
} wide_point;

/* The compact point of a large world's batches (wide_plan: at least
 * WIDE_COMPACT_POINTS points), 88 bytes a point instead of 352: a's
 * anchor in the batch's contact basis (n, t1, t2) instead of the nine arms
 * and their nine responses through the inertias. In that basis an arm
 * r x e is three coordinates of r, and the inertias' responses come from
 * the batch's two basis-projected inverse inertias (wide_inertia), so every
 * row is recomputed in each pass, in double, from 11 lanes a point and 15 a
 * manifold (b's anchor from a's and the centres' offset). The same rows as wide_point's, to rounding; the velocities are
 * solved in the basis too (wide normal and friction rows then read one or
 * two coordinates), turned into it when a batch is gathered and back when
 * it is scattered. A small world's rows fit the caches and the precomputed
 * ones take fewer instructions; a large world's stream from memory in every
 * pass, and there the bytes cost more than the arithmetic. */
typedef struct wide_cpoint {
    lane_t base_separation, normal_mass, normal_impulse;
    lane_t total_normal_impulse;
    lane_t tangent_mass[2], tangent_impulse[2];
    lane_t ra[3];                /* anchor from a's centre, in the basis: (r.n, r.t1, r.t2); b's is
                                    ra - d (wide_inertia: both arms reach the same point) */
} wide_cpoint;

/* The point of a batch whose bodies cannot turn (each static or
 * rotation-locked: zero inverse inertia and no spin), 64 bytes a point: the
 * rows of wide_point without its 36 lanes of arms and their responses,
 * which would only multiply zeros (the same bits, but for the sign of a
 * zero). Both layouts take it for such batches: their rows are the same. */
typedef struct wide_lpoint {
    lane_t base_separation, normal_mass, normal_impulse;
    lane_t total_normal_impulse;
    lane_t tangent_mass[2], tangent_impulse[2];
} wide_lpoint;

/* The point of a planar batch (WIDE_KIND_PLANAR), 112 bytes a point: a body
 * locked to a plane with normal l moves in it and turns about l only, so
 * each row's angular part is one number per body, the arm's (r x d).l, and
 * its response through the inverse inertia (k l l^T, body.c) is k times it
 * about l. The static body has l = 0: no angular part. */
typedef struct wide_ppoint {
    lane_t base_separation, normal_mass, normal_impulse;
    lane_t total_normal_impulse;
    lane_t tangent_mass[2], tangent_impulse[2];
    lane_t ja_n, jb_n, ja_t[2], jb_t[2]; /* (r x d).l for d = n, t1, t2 */
} wide_ppoint;

/* A planar batch's bodies per lane: the plane normals (zero: the static
 * body), each row direction's part in each body's plane, d - (d.l) l (what
 * an impulse along d moves the body by, per unit of 1/m: its velocity stays
 * in the plane without a projection after each row), and each body's
 * inverse moment about its normal. */
typedef struct wide_plane {
    lane_t la[3], lb[3];
    lane_t na[3], nb[3], t1a[3], t1b[3], t2a[3], t2b[3];
    lane_t ka, kb;
} wide_plane;

/* A compact batch's inverse inertias in its basis e = (n, t1, t2), e_i.I^-1 e_j:
 * the upper triangle 00 01 02 11 12 22; and b's centre less a's in the
 * basis, d: both arms reach the same contact point, rb = ra - d, so a point
 * keeps one anchor (3 lanes) and the batch these 3 (at 4 points a manifold,
 * 72 bytes a manifold less; the same rows to rounding). */
typedef struct wide_inertia {
    lane_t ka[6], kb[6];
    lane_t d[3];
} wide_inertia;

/* Points from here on a batch take the compact rows (wide_cpoint): 16,384
 * points of wide_point are 5.8 MB, past a core's share of the last-level
 * cache of the machines this was measured on. */
#define WIDE_COMPACT_POINTS 16384

/* A locked batch's plane normals per lane (zero: a free body), solver.c's
 * constraint_extra lock_a and lock_b; a compact batch's in its basis. */
typedef struct wide_lock {
    lane_t a[3], b[3];
} wide_lock;

/* A batch's kind, from its manifolds' bodies: whether a body is locked to a
 * plane (the passes keep its velocity there) and whether none can turn (the
 * rows are linear only: wide_lpoint). Each kind has its own batches within
 * a colour and its own build of the warm-start and solve passes. */
enum {
    WIDE_KIND_LOCKED = 1,        /* a body is locked to a plane */
    WIDE_KIND_SPINLESS = 2,      /* every body static or rotation-locked */
    /* every body static or locked to a plane, and some can turn: the three
     * planar degrees of freedom (wide_ppoint; not a bit: it has neither of the above's rows) */
    WIDE_KIND_PLANAR = 4,
    WIDE_KINDS = 5
};

typedef struct wide_batch {
    lane_t n[3], t1[3], t2[3];
    lane_t friction, bias_rate, mass_scale, impulse_scale;
    lane_t restitution;
    int a[LANES], b[LANES];      /* solver bodies; an empty lane uses the static body 0 */
    int con[LANES];              /* constraint index per lane */
    int count;                   /* points per manifold, the same in every lane */
    int lanes;                   /* lanes in use */
    int first;                   /* first of `count` wide points */
    int lock;                    /* its manifolds' plane normals in the set's locks, or -1: no body locked */
    int kind;                    /* WIDE_KIND_* bits, or WIDE_KIND_PLANAR (its lock indexes the set's planes) */
} wide_batch;

struct wide_set {
    wide_batch *batches;
    wide_point *points;
    wide_cpoint *cpoints;        /* the same block, compact: one or the other is used */
    wide_lpoint *lpoints;        /* the spinless batches' points (either layout) */
    wide_ppoint *ppoints;        /* the planar batches' points (either layout) */
    wide_plane *planes;          /* the planar batches' bodies (wb->lock indexes them) */
    wide_inertia *inertia;       /* compact: per batch */
    int compact;                 /* the batches take the compact rows */
    wide_lock *locks;            /* locked batches' plane normals */
    int *overflow;               /* constraints with no colour: scalar passes */
    double *deepest;             /* per batch: its deepest overlap (prepare) */
    int batch_count, overflow_count;
    int color_first[WIDE_COLORS + 1]; /* colour c's batches: color_first[c] .. color_first[c + 1] - 1 */
    /* colour c's batches of kind k: kind_first[c][k] .. the next kind's first - 1 (the last kind's: color_first[c + 1] - 1) */
    int kind_first[WIDE_COLORS][WIDE_KINDS];
    int avx2;                    /* run the AVX2 build of the passes */
    int free_only;               /* every batch is of the free kind (the passes skip the kinds' spans) */
};

/* One build of the passes over the batches first .. last - 1 (WIDE_PASSES). */
typedef struct wide_passes {
    /* friction 0: no tangent rows are prepared or warm-started (their impulses stay zero) */
    void (*prepare)(const wide_set *ws, contact_constraint *cc, const impulse_body *bodies, double warm, int friction,
                    int first, int last);
    /* per batch kind (WIDE_KIND_*) */
    void (*warm[WIDE_KINDS])(const wide_set *ws, impulse_body *bodies, int friction, int first, int last);
    void (*solve[WIDE_KINDS])(const wide_set *ws, const step_context *ctx, int use_bias, int hold_bounces, int first,
                              int last);
} wide_passes;

/* Both row layouts' builds of the passes. */
typedef struct wide_kernels {
    wide_passes full, compact;
} wide_kernels;

static size_t align_up(size_t n) { return (n + 63) & ~(size_t)63; }

/* A lane's batch header: the manifold's bodies, basis and material. */
static void fill_header(const wide_set *ws, wide_batch *wb, int l, int ci, const contact_constraint *c)
{
    wb->a[l] = c->a;
    wb->b[l] = c->b;
    wb->con[l] = ci;
    for (int d = 0; d < 3; d++) {
        wb->n[d][l] = v3_get(c->n, d);
        wb->t1[d][l] = v3_get(c->t1, d);
        wb->t2[d][l] = v3_get(c->t2, d);
    }
    if (wb->lock < 0) {
        /* no body locked to a plane */
    } else if (wb->kind == WIDE_KIND_PLANAR || wb->kind == (WIDE_KIND_SPINLESS | WIDE_KIND_LOCKED)) {
        wide_plane *pl = &ws->planes[wb->lock];
        vec3 la = constraint_lock_a(c), lb = constraint_lock_b(c);
        for (int d = 0; d < 3; d++) {
            pl->la[d][l] = v3_get(la, d);
            pl->lb[d][l] = v3_get(lb, d);
        }
    } else {
        wide_lock *lk = &ws->locks[wb->lock];
        vec3 la = constraint_lock_a(c), lb = constraint_lock_b(c);
        if (ws->compact) { /* in the basis */
            la = v3(v3_dot(la, c->n), v3_dot(la, c->t1), v3_dot(la, c->t2));
            lb = v3(v3_dot(lb, c->n), v3_dot(lb, c->t1), v3_dot(lb, c->t2));
        }
        for (int d = 0; d < 3; d++) {
            lk->a[d][l] = v3_get(la, d);
            lk->b[d][l] = v3_get(lb, d);
        }
    }
    wb->friction[l] = c->friction;
    wb->restitution[l] = c->restitution;
    wb->bias_rate[l] = c->soft.bias_rate;
    wb->mass_scale[l] = c->soft.mass_scale;
    wb->impulse_scale[l] = c->soft.impulse_scale;
}

/* A manifold's batch kind (WIDE_KIND_*). */
static int kind_of(const contact_constraint *c)
{
    if (c->spinless) return WIDE_KIND_SPINLESS | (c->locked != 0 ? WIDE_KIND_LOCKED : 0);
    if (!c->locked) return 0;
    /* planar: each moving body is a locked one (c->locked has a bit for every plane-locked moving body) */
    return (c->a == 0 || (c->locked & 1)) && (c->b == 0 || (c->locked & 2)) ? WIDE_KIND_PLANAR : WIDE_KIND_LOCKED;
}

/* Per colour, kind and point count: manifolds counted, then lanes filled,
 * and the first batch. A bucket's flat index is BUCKET(c, kind, n). */
#define BUCKET(c, kind, n) (((c) * WIDE_KINDS + (kind)) * (MANIFOLD_MAX_POINTS + 1) + (n))
typedef struct plan_buckets {
    int count[WIDE_COLORS * WIDE_KINDS * (MANIFOLD_MAX_POINTS + 1)];
    int start[WIDE_COLORS * WIDE_KINDS * (MANIFOLD_MAX_POINTS + 1)];
} plan_buckets;

/* How many manifolds and points each kind has (wide_plan's first scan). */
typedef struct plan_counts {
    int manifolds[WIDE_KINDS], points[WIDE_KINDS];
} plan_counts;

/* The set, its batches and points and the planner's scratch in one block
 * (grown, never shrunk), 64-byte aligned. */
static wide_set *reserve_set(void **mem, size_t *capacity, const plan_counts *pc, int compact, int ncon, int nb,
                             int **color, uint32_t **used)
{
    /* upper bounds: every (colour, kind, point count) bucket may end in a part-full batch */
    size_t point_size = compact ? sizeof(wide_cpoint) : sizeof(wide_point);
    int kinds = 0, turning_kinds = 0, spinless_kinds = 0, nturning = 0, nspinless = 0, nlocked = 0, locked_kinds = 0;
    for (int k = 0; k < WIDE_KINDS; k++) {
        if (!pc->manifolds[k] || k == WIDE_KIND_PLANAR) continue;
        kinds++;
        if (k & WIDE_KIND_SPINLESS) { spinless_kinds++; nspinless += pc->points[k]; }
        else { turning_kinds++; nturning += pc->points[k]; }
        if (k == WIDE_KIND_LOCKED) { locked_kinds++; nlocked += pc->manifolds[k]; }
    }
    int nplanar = pc->manifolds[WIDE_KIND_PLANAR], nplanar_points = pc->points[WIDE_KIND_PLANAR];
    int nplaned = nplanar + pc->manifolds[WIDE_KIND_SPINLESS | WIDE_KIND_LOCKED]; /* batches with planes */
    kinds += nplanar > 0;
    int max_planes = nplaned ? nplaned / LANES + 2 * WIDE_COLORS * MANIFOLD_MAX_POINTS + 1 : 0;
    int max_ppoints = nplanar ? nplanar_points / LANES + WIDE_COLORS * (1 + 2 + 3 + 4) + 1 : 0;
    int max_batches = ncon / LANES + kinds * WIDE_COLORS * MANIFOLD_MAX_POINTS + 1;
    int max_locks = nlocked ? nlocked / LANES + locked_kinds * WIDE_COLORS * MANIFOLD_MAX_POINTS + 1 : 0;
    int max_wide_points = nturning / LANES + turning_kinds * WIDE_COLORS * (1 + 2 + 3 + 4) + 1;
    int max_lpoints = nspinless ? nspinless / LANES + spinless_kinds * WIDE_COLORS * (1 + 2 + 3 + 4) + 1 : 0;
    size_t inertia_bytes = compact ? align_up(sizeof(wide_inertia) * (size_t)max_batches) : 0;
    size_t bytes = align_up(sizeof(struct wide_set)) + align_up(sizeof(wide_batch) * (size_t)max_batches) +
                   align_up(point_size * (size_t)max_wide_points) + align_up(sizeof(wide_lpoint) * (size_t)max_lpoints) +
                   align_up(sizeof(wide_lock) * (size_t)max_locks) + inertia_bytes +
                   align_up(sizeof(wide_ppoint) * (size_t)max_ppoints) + align_up(sizeof(wide_plane) * (size_t)max_planes) +
                   align_up(sizeof(int) * (size_t)ncon) * 2 +
                   align_up(sizeof(uint32_t) * (size_t)nb) + align_up(sizeof(double) * (size_t)max_batches);
    if (bytes > *capacity) {
        size_t cap = *capacity ? *capacity : 4096;
        while (cap < bytes) cap *= 2;
        void *p = realloc(*mem, cap + 63);
        if (!p) return NULL;
        pages_hint_huge(p, cap + 63);
        *mem = p;
        *capacity = cap;
    }
    char *base = (char *)(((uintptr_t)*mem + 63) & ~(uintptr_t)63);
    wide_set *ws = (wide_set *)base;
    ws->compact = compact;
    base += align_up(sizeof *ws);
    ws->batches = (wide_batch *)base;
    base += align_up(sizeof(wide_batch) * (size_t)max_batches);
    ws->points = (wide_point *)base;
    ws->cpoints = (wide_cpoint *)base;
    base += align_up(point_size * (size_t)max_wide_points);
    ws->lpoints = (wide_lpoint *)base;
    base += align_up(sizeof(wide_lpoint) * (size_t)max_lpoints);
    ws->ppoints = (wide_ppoint *)base;
    base += align_up(sizeof(wide_ppoint) * (size_t)max_ppoints);
    ws->planes = (wide_plane *)base;
    base += align_up(sizeof(wide_plane) * (size_t)max_planes);
    ws->inertia = compact ? (wide_inertia *)base : NULL;
    base += inertia_bytes;
    ws->locks = (wide_lock *)base;
    base += align_up(sizeof(wide_lock) * (size_t)max_locks);
    ws->overflow = (int *)base;
    base += align_up(sizeof(int) * (size_t)ncon);
    ws->deepest = (double *)base;
    base += align_up(sizeof(double) * (size_t)max_batches);
    *color = (int *)base;
    base += align_up(sizeof(int) * (size_t)ncon);
    *used = (uint32_t *)base;
    memset(*used, 0, sizeof **used * (size_t)nb);
    return ws;
}

/* Greedy colouring; the static body 0 never blocks (it does not move).
 * bucket[k]: constraint k's bucket (BUCKET), or -1: the scalar passes; a
 * coloured constraint's wide_lane holds its place in its bucket until
 * fill_lanes, which then needs no count of its own (and runs in ranges). */
static void color_manifolds(wide_set *ws, contact_constraint *cc, int ncon, int kinds, int *bucket, uint32_t *used,
                            plan_buckets *pb)
{
    memset(pb->count, 0, sizeof pb->count);
    ws->overflow_count = 0;
    for (int k = 0; k < ncon; k++) {
        int a = cc[k].a, b = cc[k].b;
        uint32_t taken = (a ? used[a] : 0) | (b ? used[b] : 0);
        int c = 0;
        while (c < WIDE_COLORS && (taken >> c & 1u)) c++;
        cc[k].wide_batch = cc[k].wide_lane = -1;
        if (!WIDE_VECTORS || c == WIDE_COLORS || cc[k].count < 1 || cc[k].rolling > 0.0 || cc[k].keep_scalar) {
            bucket[k] = -1;
            ws->overflow[ws->overflow_count++] = k;
            continue;
        }
        if (a) used[a] |= 1u << c;
        if (b) used[b] |= 1u << c;
        bucket[k] = BUCKET(c, kinds ? kind_of(&cc[k]) : 0, cc[k].count);
        cc[k].wide_lane = pb->count[bucket[k]]++;
    }
}

/* Batches in colour order; inside a colour, by kind, then point count. */
static void lay_out_batches(wide_set *ws, plan_buckets *pb, const plan_counts *pc)
{
    int nbatch = 0, nwide = 0, nlin = 0, nlock = 0, nplan = 0, nplane = 0;
    for (int c = 0; c < WIDE_COLORS; c++) {
        ws->color_first[c] = nbatch;
        for (int kind = 0; kind < WIDE_KINDS; kind++) {
            ws->kind_first[c][kind] = nbatch;
            if (!pc->manifolds[kind]) continue; /* no bucket of this kind has any */
            int spinless = (kind & WIDE_KIND_SPINLESS) != 0, planar = kind == WIDE_KIND_PLANAR;
            for (int n = 1; n <= MANIFOLD_MAX_POINTS; n++) {
                int bk = BUCKET(c, kind, n);
                pb->start[bk] = nbatch;
                int batches = (pb->count[bk] + LANES - 1) / LANES;
                int next = spinless ? nlin : planar ? nplan : nwide;
                for (int i = 0; i < batches; i++) {
                    wide_batch *wb = &ws->batches[nbatch + i];
                    int first = next + i * n;
                    if (i == batches - 1 && pb->count[bk] % LANES) {
                        /* the part-full batch: empty lanes stay zero (no mass, no effect) */
                        memset(wb, 0, sizeof *wb);
                        if (spinless) {
                            memset(&ws->lpoints[first], 0, sizeof(wide_lpoint) * (size_t)n);
                        } else if (planar) {
                            memset(&ws->ppoints[first], 0, sizeof(wide_ppoint) * (size_t)n);
                        } else if (ws->compact) {
                            memset(&ws->cpoints[first], 0, sizeof(wide_cpoint) * (size_t)n);
                            memset(&ws->inertia[nbatch + i], 0, sizeof(wide_inertia));
                        } else {
                            memset(&ws->points[first], 0, sizeof(wide_point) * (size_t)n);
                        }
                    }
                    wb->count = n;
                    wb->lanes = i < batches - 1 || pb->count[bk] % LANES == 0 ? LANES : pb->count[bk] % LANES;
                    wb->first = first;
                    wb->kind = kind;
                    wb->lock = -1;
                    if (kind == WIDE_KIND_LOCKED) {
                        wb->lock = nlock;
                        memset(&ws->locks[nlock++], 0, sizeof(wide_lock));
                    } else if (planar || kind == (WIDE_KIND_SPINLESS | WIDE_KIND_LOCKED)) {
                        wb->lock = nplane;
                        memset(&ws->planes[nplane++], 0, sizeof(wide_plane));
                    }
                }
                nbatch += batches;
                if (spinless) nlin += batches * n;
                else if (planar) nplan += batches * n;
                else nwide += batches * n;
            }
        }
    }
    ws->color_first[WIDE_COLORS] = nbatch;
    ws->batch_count = nbatch;
}

/* Each coloured manifold into its lane (its place in its bucket, from
 * color_manifolds): the manifolds write only their own lanes, so in ranges. */
typedef struct lanes_job {
    wide_set *ws;
    contact_constraint *cc;
    const int *bucket;
    const plan_buckets *pb;
} lanes_job;

static void fill_lanes_range(int begin, int end, int worker, void *p)
{
    const lanes_job *j = p;
    (void)worker;
    for (int k = begin; k < end; k++) {
        int bk = j->bucket[k];
        if (bk < 0) continue;
        contact_constraint *c = &j->cc[k];
        int slot = c->wide_lane, batch = j->pb->start[bk] + slot / LANES;
        fill_header(j->ws, &j->ws->batches[batch], slot % LANES, k, c);
        c->wide_batch = batch;
        c->wide_lane = slot % LANES;
    }
}

/* Manifolds per range of fill_lanes. */
#define LANES_MIN_RANGE 256

static void fill_lanes(wide_set *ws, contact_constraint *cc, int ncon, const int *bucket, const plan_buckets *pb,
                       const carom_world_def *tasks)
{
    lanes_job j = {ws, cc, bucket, pb};
    tasks_run(tasks, ncon, LANES_MIN_RANGE, fill_lanes_range, &j);
}

int wide_read_env(void)
{
    const char *layout = getenv("CAROM_WIDE_COMPACT");
    int env = WIDE_ENV_READ | (getenv("CAROM_NO_AVX2") ? WIDE_ENV_NO_AVX2 : 0);
    if (layout && *layout) env |= *layout != '0' ? WIDE_ENV_COMPACT : WIDE_ENV_FULL;
    return env;
}

wide_set *wide_plan(void **mem, size_t *capacity, contact_constraint *cc, int ncon, int kinds, int nb, int env,
                    const carom_world_def *tasks)
{
    int *color;
    uint32_t *used;
    int npoints = 0;
    plan_counts pc;
    memset(&pc, 0, sizeof pc);
    if (kinds) {
        for (int k = 0; k < ncon; k++) {
            int kind = kind_of(&cc[k]);
            pc.manifolds[kind]++;
            pc.points[kind] += cc[k].count;
        }
        for (int kind = 0; kind < WIDE_KINDS; kind++) npoints += pc.points[kind];
    } else {
        for (int k = 0; k < ncon; k++) npoints += cc[k].count;
        pc.manifolds[0] = ncon;
        pc.points[0] = npoints;
    }
    int compact = env & WIDE_ENV_COMPACT ? 1 : env & WIDE_ENV_FULL ? 0 : npoints >= WIDE_COMPACT_POINTS;
    wide_set *ws = reserve_set(mem, capacity, &pc, compact, ncon, nb, &color, &used);
    if (!ws) return NULL;
    plan_buckets pb;
    color_manifolds(ws, cc, ncon, kinds, color, used, &pb);
    lay_out_batches(ws, &pb, &pc);
    ws->free_only = 1;
    for (int kind = 1; kind < WIDE_KINDS; kind++) ws->free_only &= pc.manifolds[kind] == 0;
    fill_lanes(ws, cc, ncon, color, &pb, tasks);
#if WIDE_AVX2
    /* CAROM_NO_AVX2 set: the SSE2 build (tests compare the two bit for bit) */
    ws->avx2 = __builtin_cpu_supports("avx2") != 0 && !(env & WIDE_ENV_NO_AVX2);
#else
    (void)env;
    ws->avx2 = 0;
#endif
    return ws;
}

#if WIDE_VECTORS
/* Lane helpers are macros: a function taking or returning a 32-byte vector
 * would draw GCC's note on the AVX calling convention. Arguments are plain
 * variables (each is evaluated twice). */
#define LANE_INLINE static inline __attribute__((always_inline)) /* also into the AVX2 copies below */
#define SPLAT(x) ((lane_t){(x), (x), (x), (x)})
#define SELECT_LANES(m, a, b) ((lane_t)(((m) & (lane_mask)(a)) | (~(m) & (lane_mask)(b))))
#define LANE_MAX(a, b) SELECT_LANES((a) > (b), a, b)
#define LANE_MIN(a, b) SELECT_LANES((a) < (b), a, b)
#define DOT3(a, b) ((a)[0] * (b)[0] + (a)[1] * (b)[1] + (a)[2] * (b)[2])
/* keep_in_plane (constraint.h) per lane: v -= (v.l) l, l = 0 for a free body */
#define KEEP_IN_PLANE(v, l)                                                    \
    do {                                                                       \
        lane_t neg_ = -DOT3(v, l);                                             \
        for (int k_ = 0; k_ < 3; k_++) (v)[k_] = (v)[k_] + neg_ * (l)[k_];     \
    } while (0)
/* d's part in the plane with normal l: d - (d.l) l (d itself for l = 0). */
#define IN_PLANE(out, d, l)                                                   \
    do {                                                                      \
        lane_t dl_ = DOT3(d, l);                                              \
        for (int k_ = 0; k_ < 3; k_++) (out)[k_] = (d)[k_] - dl_ * (l)[k_];   \
    } while (0)

#define SET_LANES(dst, P0, P1, P2, P3, field)                                    \
    do {                                                                         \
        const double lanes_[LANES] = {(P0)->field, (P1)->field, (P2)->field, (P3)->field}; \
        memcpy(&(dst), lanes_, sizeof(dst));                                     \
    } while (0)

/* The lanes' body velocities, gathered and scattered around each batch. */
typedef struct lane_bodies {
    lane_t va[3], wa[3], vb[3], wb[3];
    lane_t ma, mb;
} lane_bodies;

LANE_INLINE void gather(const wide_batch *wb, const impulse_body *bodies, lane_bodies *lb)
{
    /* whole vectors from their four lanes through memcpy (element inserts, or
     * a braced vector, draw GCC's maybe-uninitialized false positive) */
    const impulse_body *A0 = &bodies[wb->a[0]], *A1 = &bodies[wb->a[1]], *A2 = &bodies[wb->a[2]], *A3 = &bodies[wb->a[3]];
    const impulse_body *B0 = &bodies[wb->b[0]], *B1 = &bodies[wb->b[1]], *B2 = &bodies[wb->b[2]], *B3 = &bodies[wb->b[3]];
    SET_LANES(lb->va[0], A0, A1, A2, A3, v.x);
    SET_LANES(lb->va[1], A0, A1, A2, A3, v.y);
    SET_LANES(lb->va[2], A0, A1, A2, A3, v.z);
    SET_LANES(lb->wa[0], A0, A1, A2, A3, w.x);
    SET_LANES(lb->wa[1], A0, A1, A2, A3, w.y);
    SET_LANES(lb->wa[2], A0, A1, A2, A3, w.z);
    SET_LANES(lb->vb[0], B0, B1, B2, B3, v.x);
    SET_LANES(lb->vb[1], B0, B1, B2, B3, v.y);
    SET_LANES(lb->vb[2], B0, B1, B2, B3, v.z);
    SET_LANES(lb->wb[0], B0, B1, B2, B3, w.x);
    SET_LANES(lb->wb[1], B0, B1, B2, B3, w.y);
    SET_LANES(lb->wb[2], B0, B1, B2, B3, w.z);
    SET_LANES(lb->ma, A0, A1, A2, A3, inv_mass);
    SET_LANES(lb->mb, B0, B1, B2, B3, inv_mass);
}

LANE_INLINE void scatter(const wide_batch *wb, impulse_body *bodies, const lane_bodies *lb)
{
    /* never the static body 0 (it does not move): a store to it would make the
     * next batch's gather wait for this batch to finish */
    for (int l = 0; l < LANES; l++) {
        if (wb->a[l]) {
            impulse_body *A = &bodies[wb->a[l]];
            A->v = v3(lb->va[0][l], lb->va[1][l], lb->va[2][l]);
            A->w = v3(lb->wa[0][l], lb->wa[1][l], lb->wa[2][l]);
        }
        if (wb->b[l]) {
            impulse_body *B = &bodies[wb->b[l]];
            B->v = v3(lb->vb[0][l], lb->vb[1][l], lb->vb[2][l]);
            B->w = v3(lb->wb[0][l], lb->wb[1][l], lb->wb[2][l]);
        }
    }
}

/* `locked` (a constant in each inlined copy): the batch's manifolds have
 * plane-locked bodies (lk their normals), whose velocities are kept in their
 * planes after every row, as the scalar passes do. */
/* friction 0: the tangent impulses are zero and their rows were not
 * prepared (the terms they would add are zeros). */
LANE_INLINE void warm_batch(const wide_batch *wb, wide_point *pts, impulse_body *bodies, const wide_lock *lk,
                            const int locked, const int friction)
{
    lane_bodies lb;
    gather(wb, bodies, &lb);
    for (int i = 0; i < wb->count; i++) {
        wide_point *p = &pts[i];
        lane_t ni = p->normal_impulse, t1 = p->tangent_impulse[0], t2 = p->tangent_impulse[1];
        p->total_normal_impulse += ni;
        if (friction) {
            for (int d = 0; d < 3; d++) {
                lane_t P = wb->n[d] * ni + wb->t1[d] * t1 + wb->t2[d] * t2;
                lb.va[d] -= lb.ma * P;
                lb.vb[d] += lb.mb * P;
                lb.wa[d] -= p->ia_n[d] * ni + p->ia_t[0][d] * t1 + p->ia_t[1][d] * t2;
                lb.wb[d] += p->ib_n[d] * ni + p->ib_t[0][d] * t1 + p->ib_t[1][d] * t2;
            }
        } else {
            for (int d = 0; d < 3; d++) {
                lane_t P = wb->n[d] * ni;
                lb.va[d] -= lb.ma * P;
                lb.vb[d] += lb.mb * P;
                lb.wa[d] -= p->ia_n[d] * ni;
                lb.wb[d] += p->ib_n[d] * ni;
            }
        }
        if (locked) {
            KEEP_IN_PLANE(lb.va, lk->a);
            KEEP_IN_PLANE(lb.vb, lk->b);
        }
    }
    scatter(wb, bodies, &lb);
}

/* The lanes' position and rotation changes since the sub-steps began: dp the
 * relative translation (B minus A), dqa and dqb each body's rotation. */
LANE_INLINE void gather_motion(const wide_batch *wb, const step_context *ctx, lane_t dp[3], lane_t dqa[3],
                               lane_t dqb[3])
{
    const vec3 *pa0 = &ctx->dp[wb->a[0]], *pa1 = &ctx->dp[wb->a[1]], *pa2 = &ctx->dp[wb->a[2]], *pa3 = &ctx->dp[wb->a[3]];
    const vec3 *pb0 = &ctx->dp[wb->b[0]], *pb1 = &ctx->dp[wb->b[1]], *pb2 = &ctx->dp[wb->b[2]], *pb3 = &ctx->dp[wb->b[3]];
    const vec3 *qa0 = &ctx->dq[wb->a[0]], *qa1 = &ctx->dq[wb->a[1]], *qa2 = &ctx->dq[wb->a[2]], *qa3 = &ctx->dq[wb->a[3]];
    const vec3 *qb0 = &ctx->dq[wb->b[0]], *qb1 = &ctx->dq[wb->b[1]], *qb2 = &ctx->dq[wb->b[2]], *qb3 = &ctx->dq[wb->b[3]];
    lane_t dpa[3];
    SET_LANES(dpa[0], pa0, pa1, pa2, pa3, x);
    SET_LANES(dpa[1], pa0, pa1, pa2, pa3, y);
    SET_LANES(dpa[2], pa0, pa1, pa2, pa3, z);
    SET_LANES(dp[0], pb0, pb1, pb2, pb3, x);
    SET_LANES(dp[1], pb0, pb1, pb2, pb3, y);
    SET_LANES(dp[2], pb0, pb1, pb2, pb3, z);
    for (int d = 0; d < 3; d++) dp[d] -= dpa[d];
    SET_LANES(dqa[0], qa0, qa1, qa2, qa3, x);
    SET_LANES(dqa[1], qa0, qa1, qa2, qa3, y);
    SET_LANES(dqa[2], qa0, qa1, qa2, qa3, z);
    SET_LANES(dqb[0], qb0, qb1, qb2, qb3, x);
    SET_LANES(dqb[1], qb0, qb1, qb2, qb3, y);
    SET_LANES(dqb[2], qb0, qb1, qb2, qb3, z);
}

/* The normal rows of every point of a batch (contact_solve's first loop). */
LANE_INLINE void solve_normal_rows(const wide_batch *wb, wide_point *pts, const step_context *ctx, lane_bodies *lb,
                                   int use_bias, int hold_bounces, const wide_lock *lk, const int locked)
{
    lane_t dp[3], dqa[3], dqb[3];
    gather_motion(wb, ctx, dp, dqa, dqb);
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0), inv_h = SPLAT(ctx->inv_h), push = SPLAT(-ctx->push_max);
    /* bias, mass and impulse scales of a penetrating point (speculative ones differ per lane below) */
    lane_t pen_mass_scale = one, pen_impulse_scale = zero;
    int soft = use_bias && ctx->correction == CAROM_CORRECTION_SOFT;
    int baumgarte = use_bias && ctx->correction == CAROM_CORRECTION_BAUMGARTE;
    if (soft) {
        pen_mass_scale = wb->mass_scale;
        pen_impulse_scale = wb->impulse_scale;
    }
    const lane_t baum_rate = SPLAT(ctx->baumgarte_rate), slop = SPLAT(ctx->slop);
    for (int i = 0; i < wb->count; i++) {
        wide_point *p = &pts[i];
        /* current separation: small-angle update of the anchors */
        lane_t s = p->base_separation + DOT3(wb->n, dp) + DOT3(dqb, p->rb_n) - DOT3(dqa, p->ra_n);
        lane_t pen_bias = zero;
        if (soft || baumgarte) {
            lane_t rate = wb->bias_rate;
            pen_bias = CONTACT_PUSH_BIAS(soft, s, rate, baum_rate, slop, push, zero, LANE_MAX, LANE_MIN);
        }
        /* speculative (s > 0): arrive exactly at contact, rigidly */
        lane_mask ahead = s > zero;
        lane_t spec = CONTACT_SPECULATIVE_BIAS(s, inv_h);
        lane_t bias = SELECT_LANES(ahead, spec, pen_bias);
        lane_t mass_scale = SELECT_LANES(ahead, one, pen_mass_scale);
        lane_t impulse_scale = SELECT_LANES(ahead, zero, pen_impulse_scale);
        lane_t vn = wb->n[0] * (lb->vb[0] - lb->va[0]) + wb->n[1] * (lb->vb[1] - lb->va[1]) +
                    wb->n[2] * (lb->vb[2] - lb->va[2]) + DOT3(lb->wb, p->rb_n) - DOT3(lb->wa, p->ra_n);
        lane_t old = p->normal_impulse;
        lane_t total = old - p->normal_mass * mass_scale * (vn + bias) - impulse_scale * old;
        total = LANE_MAX(total, zero);
        if (hold_bounces) {
            lane_mask hold = ahead & (wb->restitution > zero);
            total = SELECT_LANES(hold, LANE_MIN(total, old), total);
        }
        lane_t lambda = total - old;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        lane_t la = lb->ma * lambda, lbm = lb->mb * lambda;
        for (int d = 0; d < 3; d++) {
            lb->va[d] -= la * wb->n[d];
            lb->wa[d] -= lambda * p->ia_n[d];
            lb->vb[d] += lbm * wb->n[d];
            lb->wb[d] += lambda * p->ib_n[d];
        }
        if (locked) {
            KEEP_IN_PLANE(lb->va, lk->a);
            KEEP_IN_PLANE(lb->vb, lk->b);
        }
    }
}

/* One point's two friction rows in every lane: the accumulated impulses take
 * the unclamped step, then lanes outside Coulomb's cone (|t| <= mu * normal)
 * are brought back by coulomb_over_cone; *d1, *d2 are the impulses applied.
 * Every kernel kind (full, spinless, planar, compact) shares it. */
LANE_INLINE void friction_lanes(lane_t impulse[2], const lane_t mass[2], const lane_t *normal_impulse,
                                const lane_t *friction, const lane_t *vel1, const lane_t *vel2, lane_t *d1, lane_t *d2)
{
    /* vectors by pointer: by value they would change the ABI between the SSE2 and AVX2 builds */
    lane_t v1 = *vel1, v2 = *vel2;
    lane_t o1 = impulse[0], o2 = impulse[1];
    lane_t n1 = o1 - mass[0] * v1, n2 = o2 - mass[1] * v2;
    lane_t limit = *friction * *normal_impulse;
    lane_t mag2 = n1 * n1 + n2 * n2;
    lane_mask over = mag2 > limit * limit;
    if (over[0] | over[1] | over[2] | over[3]) { /* resting contacts are inside the cone */
        for (int l = 0; l < LANES; l++) {
            if (!over[l]) continue;
            double s1 = n1[l], s2 = n2[l];
            coulomb_over_cone(&s1, &s2, o1[l], o2[l], v1[l], v2[l], mass[0][l], mass[1][l], limit[l]);
            n1[l] = s1;
            n2[l] = s2;
        }
    }
    impulse[0] = n1;
    impulse[1] = n2;
    *d1 = n1 - o1;
    *d2 = n2 - o2;
}

/* The friction rows of every point of a batch (contact_solve's second loop). */
LANE_INLINE void solve_friction_rows(const wide_batch *wb, wide_point *pts, lane_bodies *lb, const wide_lock *lk,
                                     const int locked)
{
    for (int i = 0; i < wb->count; i++) {
        wide_point *p = &pts[i];
        lane_t dv[3] = {lb->vb[0] - lb->va[0], lb->vb[1] - lb->va[1], lb->vb[2] - lb->va[2]};
        lane_t v1 = DOT3(dv, wb->t1) + DOT3(lb->wb, p->rb_t[0]) - DOT3(lb->wa, p->ra_t[0]);
        lane_t v2 = DOT3(dv, wb->t2) + DOT3(lb->wb, p->rb_t[1]) - DOT3(lb->wa, p->ra_t[1]);
        lane_t d1, d2;
        friction_lanes(p->tangent_impulse, p->tangent_mass, &p->normal_impulse, &wb->friction, &v1, &v2, &d1, &d2);
        for (int d = 0; d < 3; d++) {
            lane_t P = wb->t1[d] * d1 + wb->t2[d] * d2;
            lb->va[d] -= lb->ma * P;
            lb->vb[d] += lb->mb * P;
            lb->wa[d] -= p->ia_t[0][d] * d1 + p->ia_t[1][d] * d2;
            lb->wb[d] += p->ib_t[0][d] * d1 + p->ib_t[1][d] * d2;
        }
        if (locked) {
            KEEP_IN_PLANE(lb->va, lk->a);
            KEEP_IN_PLANE(lb->vb, lk->b);
        }
    }
}

/* The scalar contact_solve (contact_solver.c), four manifolds at a time. */
LANE_INLINE void solve_batch(const wide_batch *wb, wide_point *pts, const step_context *ctx, int use_bias,
                             int hold_bounces, const wide_lock *lk, const int locked)
{
    lane_bodies lb;
    gather(wb, ctx->bodies, &lb);
    solve_normal_rows(wb, pts, ctx, &lb, use_bias, hold_bounces, lk, locked);
    if (ctx->friction) solve_friction_rows(wb, pts, &lb, lk, locked);
    scatter(wb, ctx->bodies, &lb);
}

/* ---- the spinless rows (wide_lpoint) --------------------------------------
 * A batch whose bodies cannot turn: the rows above with every angular term
 * dropped. Each was a product with a zero inverse inertia, angular velocity
 * or rotation (a rotation-locked body keeps w = 0 and dq = 0, the static
 * body 0 has both zero), so the results are the same bits but for the sign
 * of a zero, and only the linear velocities are gathered and scattered. */

/* The lanes' linear velocities and inverse masses. */
typedef struct lane_lbodies {
    lane_t va[3], vb[3];
    lane_t ma, mb;
} lane_lbodies;

LANE_INLINE void gather_l(const wide_batch *wb, const impulse_body *bodies, lane_lbodies *lb)
{
    const impulse_body *A0 = &bodies[wb->a[0]], *A1 = &bodies[wb->a[1]], *A2 = &bodies[wb->a[2]], *A3 = &bodies[wb->a[3]];
    const impulse_body *B0 = &bodies[wb->b[0]], *B1 = &bodies[wb->b[1]], *B2 = &bodies[wb->b[2]], *B3 = &bodies[wb->b[3]];
    SET_LANES(lb->va[0], A0, A1, A2, A3, v.x);
    SET_LANES(lb->va[1], A0, A1, A2, A3, v.y);
    SET_LANES(lb->va[2], A0, A1, A2, A3, v.z);
    SET_LANES(lb->vb[0], B0, B1, B2, B3, v.x);
    SET_LANES(lb->vb[1], B0, B1, B2, B3, v.y);
    SET_LANES(lb->vb[2], B0, B1, B2, B3, v.z);
    SET_LANES(lb->ma, A0, A1, A2, A3, inv_mass);
    SET_LANES(lb->mb, B0, B1, B2, B3, inv_mass);
}

LANE_INLINE void scatter_l(const wide_batch *wb, impulse_body *bodies, const lane_lbodies *lb)
{
    for (int l = 0; l < LANES; l++) {
        if (wb->a[l]) bodies[wb->a[l]].v = v3(lb->va[0][l], lb->va[1][l], lb->va[2][l]);
        if (wb->b[l]) bodies[wb->b[l]].v = v3(lb->vb[0][l], lb->vb[1][l], lb->vb[2][l]);
    }
}

/* `locked` (a constant in each inlined copy): some body is locked to a
 * plane (pl: the batch's planes), and each is pushed along the rows'
 * directions in its plane, so its velocity stays there. */
LANE_INLINE void warm_batch_l(const wide_batch *wb, wide_lpoint *pts, impulse_body *bodies, const wide_plane *pl,
                              const int locked, const int friction)
{
    lane_lbodies lb;
    gather_l(wb, bodies, &lb);
    for (int i = 0; i < wb->count; i++) {
        wide_lpoint *p = &pts[i];
        lane_t ni = p->normal_impulse, t1 = p->tangent_impulse[0], t2 = p->tangent_impulse[1];
        p->total_normal_impulse += ni;
        for (int d = 0; d < 3; d++) {
            if (locked) {
                lane_t Pa = friction ? pl->na[d] * ni + pl->t1a[d] * t1 + pl->t2a[d] * t2 : pl->na[d] * ni;
                lane_t Pb = friction ? pl->nb[d] * ni + pl->t1b[d] * t1 + pl->t2b[d] * t2 : pl->nb[d] * ni;
                lb.va[d] -= lb.ma * Pa;
                lb.vb[d] += lb.mb * Pb;
            } else {
                lane_t P = friction ? wb->n[d] * ni + wb->t1[d] * t1 + wb->t2[d] * t2 : wb->n[d] * ni;
                lb.va[d] -= lb.ma * P;
                lb.vb[d] += lb.mb * P;
            }
        }
    }
    scatter_l(wb, bodies, &lb);
}

/* The lanes' relative translation since the sub-steps began (B minus A). */
LANE_INLINE void gather_translation(const wide_batch *wb, const step_context *ctx, lane_t dp[3])
{
    const vec3 *pa0 = &ctx->dp[wb->a[0]], *pa1 = &ctx->dp[wb->a[1]], *pa2 = &ctx->dp[wb->a[2]], *pa3 = &ctx->dp[wb->a[3]];
    const vec3 *pb0 = &ctx->dp[wb->b[0]], *pb1 = &ctx->dp[wb->b[1]], *pb2 = &ctx->dp[wb->b[2]], *pb3 = &ctx->dp[wb->b[3]];
    lane_t dpa[3];
    SET_LANES(dpa[0], pa0, pa1, pa2, pa3, x);
    SET_LANES(dpa[1], pa0, pa1, pa2, pa3, y);
    SET_LANES(dpa[2], pa0, pa1, pa2, pa3, z);
    SET_LANES(dp[0], pb0, pb1, pb2, pb3, x);
    SET_LANES(dp[1], pb0, pb1, pb2, pb3, y);
    SET_LANES(dp[2], pb0, pb1, pb2, pb3, z);
    for (int d = 0; d < 3; d++) dp[d] -= dpa[d];
}

LANE_INLINE void solve_normal_rows_l(const wide_batch *wb, wide_lpoint *pts, const step_context *ctx,
                                     lane_lbodies *lb, int use_bias, int hold_bounces, const wide_plane *pl,
                                     const int locked)
{
    lane_t dp[3];
    gather_translation(wb, ctx, dp);
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0), inv_h = SPLAT(ctx->inv_h), push = SPLAT(-ctx->push_max);
    lane_t pen_mass_scale = one, pen_impulse_scale = zero;
    int soft = use_bias && ctx->correction == CAROM_CORRECTION_SOFT;
    int baumgarte = use_bias && ctx->correction == CAROM_CORRECTION_BAUMGARTE;
    if (soft) {
        pen_mass_scale = wb->mass_scale;
        pen_impulse_scale = wb->impulse_scale;
    }
    const lane_t baum_rate = SPLAT(ctx->baumgarte_rate), slop = SPLAT(ctx->slop);
    lane_t dpn = DOT3(wb->n, dp); /* the same for every point: nothing turns */
    for (int i = 0; i < wb->count; i++) {
        wide_lpoint *p = &pts[i];
        lane_t s = p->base_separation + dpn;
        lane_t pen_bias = zero;
        if (soft || baumgarte) {
            lane_t rate = wb->bias_rate;
            pen_bias = CONTACT_PUSH_BIAS(soft, s, rate, baum_rate, slop, push, zero, LANE_MAX, LANE_MIN);
        }
        lane_mask ahead = s > zero;
        lane_t spec = CONTACT_SPECULATIVE_BIAS(s, inv_h);
        lane_t bias = SELECT_LANES(ahead, spec, pen_bias);
        lane_t mass_scale = SELECT_LANES(ahead, one, pen_mass_scale);
        lane_t impulse_scale = SELECT_LANES(ahead, zero, pen_impulse_scale);
        lane_t vn = wb->n[0] * (lb->vb[0] - lb->va[0]) + wb->n[1] * (lb->vb[1] - lb->va[1]) +
                    wb->n[2] * (lb->vb[2] - lb->va[2]);
        lane_t old = p->normal_impulse;
        lane_t total = old - p->normal_mass * mass_scale * (vn + bias) - impulse_scale * old;
        total = LANE_MAX(total, zero);
        if (hold_bounces) {
            lane_mask hold = ahead & (wb->restitution > zero);
            total = SELECT_LANES(hold, LANE_MIN(total, old), total);
        }
        lane_t lambda = total - old;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        lane_t la = lb->ma * lambda, lbm = lb->mb * lambda;
        for (int d = 0; d < 3; d++) {
            lb->va[d] -= la * (locked ? pl->na[d] : wb->n[d]);
            lb->vb[d] += lbm * (locked ? pl->nb[d] : wb->n[d]);
        }
    }
}

LANE_INLINE void solve_friction_rows_l(const wide_batch *wb, wide_lpoint *pts, lane_lbodies *lb, const wide_plane *pl,
                                       const int locked)
{
    for (int i = 0; i < wb->count; i++) {
        wide_lpoint *p = &pts[i];
        lane_t dv[3] = {lb->vb[0] - lb->va[0], lb->vb[1] - lb->va[1], lb->vb[2] - lb->va[2]};
        lane_t v1 = DOT3(dv, wb->t1);
        lane_t v2 = DOT3(dv, wb->t2);
        lane_t d1, d2;
        friction_lanes(p->tangent_impulse, p->tangent_mass, &p->normal_impulse, &wb->friction, &v1, &v2, &d1, &d2);
        for (int d = 0; d < 3; d++) {
            if (locked) {
                lb->va[d] -= lb->ma * (pl->t1a[d] * d1 + pl->t2a[d] * d2);
                lb->vb[d] += lb->mb * (pl->t1b[d] * d1 + pl->t2b[d] * d2);
            } else {
                lane_t P = wb->t1[d] * d1 + wb->t2[d] * d2;
                lb->va[d] -= lb->ma * P;
                lb->vb[d] += lb->mb * P;
            }
        }
    }
}

LANE_INLINE void solve_batch_l(const wide_batch *wb, wide_lpoint *pts, const step_context *ctx, int use_bias,
                               int hold_bounces, const wide_plane *pl, const int locked)
{
    lane_lbodies lb;
    gather_l(wb, ctx->bodies, &lb);
    solve_normal_rows_l(wb, pts, ctx, &lb, use_bias, hold_bounces, pl, locked);
    if (ctx->friction) solve_friction_rows_l(wb, pts, &lb, pl, locked);
    scatter_l(wb, ctx->bodies, &lb);
}

/* Lane l of a batch reads manifold l (an empty lane reads zeros: static body,
 * no point, no impulse, so every row it gets is zero). */
typedef struct lane_source {
    const contact_constraint *c[LANES];
} lane_source;

#define CROSS(r, a, b)                                  \
    do {                                                \
        (r)[0] = (a)[1] * (b)[2] - (a)[2] * (b)[1];     \
        (r)[1] = (a)[2] * (b)[0] - (a)[0] * (b)[2];     \
        (r)[2] = (a)[0] * (b)[1] - (a)[1] * (b)[0];     \
    } while (0)
/* column-major 3x3 times a vector, as m3_mulv */
#define MAT_VEC(r, m, v)                                                   \
    do {                                                                   \
        for (int d_ = 0; d_ < 3; d_++)                                     \
            (r)[d_] = (m)[0][d_] * (v)[0] + (m)[1][d_] * (v)[1] + (m)[2][d_] * (v)[2]; \
    } while (0)

LANE_INLINE void gather_inertia(lane_t out[3][3], const impulse_body *b0, const impulse_body *b1,
                                const impulse_body *b2, const impulse_body *b3)
{
    SET_LANES(out[0][0], b0, b1, b2, b3, inv_inertia.c0.x);
    SET_LANES(out[0][1], b0, b1, b2, b3, inv_inertia.c0.y);
    SET_LANES(out[0][2], b0, b1, b2, b3, inv_inertia.c0.z);
    SET_LANES(out[1][0], b0, b1, b2, b3, inv_inertia.c1.x);
    SET_LANES(out[1][1], b0, b1, b2, b3, inv_inertia.c1.y);
    SET_LANES(out[1][2], b0, b1, b2, b3, inv_inertia.c1.z);
    SET_LANES(out[2][0], b0, b1, b2, b3, inv_inertia.c2.x);
    SET_LANES(out[2][1], b0, b1, b2, b3, inv_inertia.c2.y);
    SET_LANES(out[2][2], b0, b1, b2, b3, inv_inertia.c2.z);
}

LANE_INLINE void gather_vec(lane_t out[3], vec3 v0, vec3 v1, vec3 v2, vec3 v3_)
{
    const double x[LANES] = {v0.x, v1.x, v2.x, v3_.x}, y[LANES] = {v0.y, v1.y, v2.y, v3_.y},
                 z[LANES] = {v0.z, v1.z, v2.z, v3_.z};
    memcpy(&out[0], x, sizeof out[0]);
    memcpy(&out[1], y, sizeof out[1]);
    memcpy(&out[2], z, sizeof out[2]);
}

/* What every point of a batch's manifolds shares: the lanes' constraints,
 * bodies (inverse masses and inertias, velocities) and centres of mass. */
typedef struct lane_manifolds {
    contact_constraint *c[LANES];
    lane_t ia[3][3], ib[3][3], va[3], wa[3], vb[3], wb[3], ma, mb, center_a[3], center_b[3];
} lane_manifolds;

/* spin 0 (a spinless batch): the inertias and angular velocities are not gathered (not read). */
LANE_INLINE void gather_manifolds(const wide_batch *wb, contact_constraint *cc, const impulse_body *bodies,
                                  lane_manifolds *lm, const int spin)
{
    const impulse_body *A[LANES], *B[LANES];
    vec3 ca[LANES], cb[LANES];
    for (int l = 0; l < LANES; l++) {
        lm->c[l] = l < wb->lanes ? &cc[wb->con[l]] : NULL;
        A[l] = &bodies[wb->a[l]];
        B[l] = &bodies[wb->b[l]];
        ca[l] = lm->c[l] ? lm->c[l]->center_a : v3_zero();
        cb[l] = lm->c[l] ? lm->c[l]->center_b : v3_zero();
    }
    if (spin) {
        gather_inertia(lm->ia, A[0], A[1], A[2], A[3]);
        gather_inertia(lm->ib, B[0], B[1], B[2], B[3]);
        gather_vec(lm->wa, A[0]->w, A[1]->w, A[2]->w, A[3]->w);
        gather_vec(lm->wb, B[0]->w, B[1]->w, B[2]->w, B[3]->w);
    }
    gather_vec(lm->va, A[0]->v, A[1]->v, A[2]->v, A[3]->v);
    gather_vec(lm->vb, B[0]->v, B[1]->v, B[2]->v, B[3]->v);
    SET_LANES(lm->ma, A[0], A[1], A[2], A[3], inv_mass);
    SET_LANES(lm->mb, B[0], B[1], B[2], B[3], inv_mass);
    gather_vec(lm->center_a, ca[0], ca[1], ca[2], ca[3]);
    gather_vec(lm->center_b, cb[0], cb[1], cb[2], cb[3]);
}

/* A point's rows: the arms crossed with the basis, those through the inverse
 * inertias, and the effective masses as solver.c:
 * 1 / (1/mA + 1/mB + (IA^-1 (rA x n)).(rA x n) + ...) */
/* Point i of the four lanes' manifolds: its warm-start state, its arms from
 * each body's centre and its separation (an empty lane reads a zero point). */
LANE_INLINE void gather_point(const lane_manifolds *lm, int i, const contact_point_state *st[LANES], lane_t ra[3],
                              lane_t rb[3], lane_t *sep)
{
    static const manifold_point no_point = {{0, 0, 0}, 0, 0};
    static const contact_point_state no_state = {.normal_impulse = 0.0};
    const manifold_point *mp[LANES];
    for (int l = 0; l < LANES; l++) {
        mp[l] = lm->c[l] ? &lm->c[l]->m->points[i] : &no_point;
        st[l] = lm->c[l] ? &lm->c[l]->p[i] : &no_state;
    }
    lane_t point[3];
    gather_vec(point, mp[0]->point, mp[1]->point, mp[2]->point, mp[3]->point);
    SET_LANES(*sep, mp[0], mp[1], mp[2], mp[3], separation);
    for (int d = 0; d < 3; d++) {
        ra[d] = point[d] - lm->center_a[d];
        rb[d] = point[d] - lm->center_b[d];
    }
}

LANE_INLINE void prepare_rows(const wide_batch *wb, const lane_manifolds *lm, wide_point *p, const lane_t ra[3],
                              const lane_t rb[3], const lane_t lin[3], const lane_t *blocked, int friction)
{
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0), floor = *blocked;
    CROSS(p->ra_n, ra, wb->n);
    CROSS(p->rb_n, rb, wb->n);
    MAT_VEC(p->ia_n, lm->ia, p->ra_n);
    MAT_VEC(p->ib_n, lm->ib, p->rb_n);
    if (!friction) { /* no tangent rows: only the normal's mass */
        lane_t kn = lin[0] + DOT3(p->ia_n, p->ra_n) + DOT3(p->ib_n, p->rb_n);
        lane_t ikn = one / SELECT_LANES(kn > floor, kn, one);
        p->normal_mass = SELECT_LANES(kn > floor, ikn, zero);
        return;
    }
    CROSS(p->ra_t[0], ra, wb->t1);
    CROSS(p->rb_t[0], rb, wb->t1);
    CROSS(p->ra_t[1], ra, wb->t2);
    CROSS(p->rb_t[1], rb, wb->t2);
    for (int q = 0; q < 2; q++) {
        MAT_VEC(p->ia_t[q], lm->ia, p->ra_t[q]);
        MAT_VEC(p->ib_t[q], lm->ib, p->rb_t[q]);
    }
    lane_t kn = lin[0] + DOT3(p->ia_n, p->ra_n) + DOT3(p->ib_n, p->rb_n);
    lane_t k1 = lin[1] + DOT3(p->ia_t[0], p->ra_t[0]) + DOT3(p->ib_t[0], p->rb_t[0]);
    lane_t k2 = lin[2] + DOT3(p->ia_t[1], p->ra_t[1]) + DOT3(p->ib_t[1], p->rb_t[1]);
    lane_t ikn = one / SELECT_LANES(kn > floor, kn, one), ik1 = one / SELECT_LANES(k1 > floor, k1, one),
           ik2 = one / SELECT_LANES(k2 > floor, k2, one);
    p->normal_mass = SELECT_LANES(kn > floor, ikn, zero);
    p->tangent_mass[0] = SELECT_LANES(k1 > floor, ik1, zero);
    p->tangent_mass[1] = SELECT_LANES(k2 > floor, ik2, zero);
}

/* Point i's warm-start impulses, scaled by warm (empty lanes read zeros). */
/* Written over the three point types (their impulse fields share names):
 * friction 0 starts the tangent impulses at zero (a world whose friction was
 * switched off no longer pushes with last step's). */
#define WARM_POINT(p, st, warm, friction)                                           \
    do {                                                                            \
        const lane_t zero_ = SPLAT(0.0), warm_scale_ = SPLAT(warm);                 \
        lane_t ni_;                                                                 \
        SET_LANES(ni_, st[0], st[1], st[2], st[3], normal_impulse);                 \
        (p)->normal_impulse = warm_scale_ * ni_;                                    \
        (p)->total_normal_impulse = zero_;                                          \
        if (friction) {                                                             \
            lane_t t1_, t2_;                                                        \
            SET_LANES(t1_, st[0], st[1], st[2], st[3], tangent_impulse[0]);         \
            SET_LANES(t2_, st[0], st[1], st[2], st[3], tangent_impulse[1]);         \
            (p)->tangent_impulse[0] = warm_scale_ * t1_;                            \
            (p)->tangent_impulse[1] = warm_scale_ * t2_;                            \
        } else {                                                                    \
            (p)->tangent_impulse[0] = (p)->tangent_impulse[1] = zero_;              \
        }                                                                           \
    } while (0)

/* What the stages around the passes read of point i in each lane's
 * constraint (the shock pass, restitution, the events); returns the deepest
 * penetration. */
LANE_INLINE double store_point(const wide_batch *wb, const lane_manifolds *lm, int i,
                               const lane_t ra[3], const lane_t rb[3], const lane_t *sep, const lane_t *vn,
                               double deepest)
{
    for (int l = 0; l < wb->lanes; l++) {
        const contact_constraint *c = lm->c[l];
        constraint_point *cold = &c->p[i];
        double s = (*sep)[l];
        cold->relative_velocity = contact_approach_velocity((*vn)[l], c->gravity_closing, s);
        cold->total_normal_impulse = 0.0;
        if (c->an) { /* the shock pass runs */
            constraint_anchor *q = &c->an[i];
            q->base_separation = s;
            q->ra = v3(ra[0][l], ra[1][l], ra[2][l]);
            q->rb = v3(rb[0][l], rb[1][l], rb[2][l]);
        }
        if (-s > deepest) deepest = -s;
    }
    return deepest;
}

/* A plane-locked body's 1/m counts only the row's part in its plane
 * (locked_inv_mass, constraint.h): (1/m)(1 - (d.l)^2) per lane. */
#define LOCKED_INV_MASS(m, d, l) ((m) * (one - DOT3(d, l) * DOT3(d, l)))

LANE_INLINE double prepare_batch(const wide_batch *wb, wide_point *pts, contact_constraint *cc,
                                 const impulse_body *bodies, double warm, const wide_lock *lk, int friction)
{
    lane_manifolds lm;
    gather_manifolds(wb, cc, bodies, &lm, 1);
    /* the linear share of each row's inverse effective mass (n, t1, t2) */
    lane_t lin[3], floor = SPLAT(0.0); /* rows blocked at or below floor (row_mass, constraint.h) */
    lin[0] = lin[1] = lin[2] = lm.ma + lm.mb;
    if (lk) {
        const lane_t one = SPLAT(1.0);
        lin[0] = LOCKED_INV_MASS(lm.ma, wb->n, lk->a) + LOCKED_INV_MASS(lm.mb, wb->n, lk->b);
        lin[1] = LOCKED_INV_MASS(lm.ma, wb->t1, lk->a) + LOCKED_INV_MASS(lm.mb, wb->t1, lk->b);
        lin[2] = LOCKED_INV_MASS(lm.ma, wb->t2, lk->a) + LOCKED_INV_MASS(lm.mb, wb->t2, lk->b);
        floor = SPLAT(ROW_BLOCKED_SHARE) * (lm.ma + lm.mb);
    }
    double deepest = 0.0;
    for (int i = 0; i < wb->count; i++) {
        wide_point *p = &pts[i];
        const contact_point_state *st[LANES];
        lane_t ra[3], rb[3], sep;
        gather_point(&lm, i, st, ra, rb, &sep);
        prepare_rows(wb, &lm, p, ra, rb, lin, &floor, friction);
        p->base_separation = sep;
        /* normal velocity before solving: n . ((vB + wB x rB) - (vA + wA x rA)) */
        lane_t wxa[3], wxb[3];
        CROSS(wxa, lm.wa, ra);
        CROSS(wxb, lm.wb, rb);
        lane_t vrel[3];
        for (int d = 0; d < 3; d++) vrel[d] = (lm.vb[d] + wxb[d]) - (lm.va[d] + wxa[d]);
        lane_t vn = DOT3(vrel, wb->n);
        WARM_POINT(p, st, warm, friction);
        deepest = store_point(wb, &lm, i, ra, rb, &sep, &vn, deepest);
    }
    return deepest;
}

/* The effective mass 1 / k of a row, 0 where k is not above floor: zero,
 * or with a body locked to a plane the share of the free 1/m below which
 * the row is blocked (row_mass, constraint.h). */
#define ROW_MASS_ABOVE(k, floor) SELECT_LANES((k) > (floor), one / SELECT_LANES((k) > (floor), (k), one), zero)
#define ROW_MASS(k) ROW_MASS_ABOVE(k, zero)

/* A spinless batch's points: each row's mass is its linear share alone
 * (the angular ones were zeros), the same at every point of a manifold. */
LANE_INLINE double prepare_batch_l(const wide_batch *wb, wide_lpoint *pts, contact_constraint *cc,
                                   const impulse_body *bodies, double warm, wide_plane *pl, int friction)
{
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0);
    lane_manifolds lm;
    gather_manifolds(wb, cc, bodies, &lm, 0);
    lane_t lin[3], floor = zero;
    lin[0] = lin[1] = lin[2] = lm.ma + lm.mb;
    if (pl) { /* some body locked to a plane: the rows' directions in each plane */
        IN_PLANE(pl->na, wb->n, pl->la);
        IN_PLANE(pl->nb, wb->n, pl->lb);
        IN_PLANE(pl->t1a, wb->t1, pl->la);
        IN_PLANE(pl->t1b, wb->t1, pl->lb);
        IN_PLANE(pl->t2a, wb->t2, pl->la);
        IN_PLANE(pl->t2b, wb->t2, pl->lb);
        lin[0] = LOCKED_INV_MASS(lm.ma, wb->n, pl->la) + LOCKED_INV_MASS(lm.mb, wb->n, pl->lb);
        lin[1] = LOCKED_INV_MASS(lm.ma, wb->t1, pl->la) + LOCKED_INV_MASS(lm.mb, wb->t1, pl->lb);
        lin[2] = LOCKED_INV_MASS(lm.ma, wb->t2, pl->la) + LOCKED_INV_MASS(lm.mb, wb->t2, pl->lb);
        floor = SPLAT(ROW_BLOCKED_SHARE) * (lm.ma + lm.mb);
    }
    lane_t normal_mass = ROW_MASS_ABOVE(lin[0], floor), tangent_mass[2] = {zero, zero};
    if (friction) {
        tangent_mass[0] = ROW_MASS_ABOVE(lin[1], floor);
        tangent_mass[1] = ROW_MASS_ABOVE(lin[2], floor);
    }
    lane_t dv[3];
    for (int d = 0; d < 3; d++) dv[d] = lm.vb[d] - lm.va[d];
    lane_t vn = DOT3(dv, wb->n); /* normal velocity before solving, at every point */
    double deepest = 0.0;
    for (int i = 0; i < wb->count; i++) {
        wide_lpoint *p = &pts[i];
        const contact_point_state *st[LANES];
        lane_t ra[3], rb[3], sep;
        gather_point(&lm, i, st, ra, rb, &sep);
        p->normal_mass = normal_mass;
        p->tangent_mass[0] = tangent_mass[0];
        p->tangent_mass[1] = tangent_mass[1];
        p->base_separation = sep;
        WARM_POINT(p, st, warm, friction);
        deepest = store_point(wb, &lm, i, ra, rb, &sep, &vn, deepest);
    }
    return deepest;
}

/* ---- the planar rows (wide_ppoint, wide_plane) ---------------------------
 * Every body of the batch static or locked to a plane, and some can turn:
 * a body's velocities are its linear velocity, kept in its plane by
 * pushing it only along the rows' in-plane directions, and its spin about
 * its plane normal, w = omega l (what project_planar keeps). Each row reads
 * and writes those three degrees of freedom per body instead of six, with
 * no projection after each row. */

/* The lanes' linear velocities and spins about their plane normals. */
typedef struct lane_pbodies {
    lane_t va[3], vb[3];
    lane_t oa, ob;               /* w.l */
    lane_t ma, mb;
} lane_pbodies;

LANE_INLINE void gather_p(const wide_batch *wb, const wide_plane *pl, const impulse_body *bodies, lane_pbodies *lb)
{
    const impulse_body *A0 = &bodies[wb->a[0]], *A1 = &bodies[wb->a[1]], *A2 = &bodies[wb->a[2]], *A3 = &bodies[wb->a[3]];
    const impulse_body *B0 = &bodies[wb->b[0]], *B1 = &bodies[wb->b[1]], *B2 = &bodies[wb->b[2]], *B3 = &bodies[wb->b[3]];
    lane_t wa[3], wb_[3];
    SET_LANES(lb->va[0], A0, A1, A2, A3, v.x);
    SET_LANES(lb->va[1], A0, A1, A2, A3, v.y);
    SET_LANES(lb->va[2], A0, A1, A2, A3, v.z);
    SET_LANES(lb->vb[0], B0, B1, B2, B3, v.x);
    SET_LANES(lb->vb[1], B0, B1, B2, B3, v.y);
    SET_LANES(lb->vb[2], B0, B1, B2, B3, v.z);
    SET_LANES(wa[0], A0, A1, A2, A3, w.x);
    SET_LANES(wa[1], A0, A1, A2, A3, w.y);
    SET_LANES(wa[2], A0, A1, A2, A3, w.z);
    SET_LANES(wb_[0], B0, B1, B2, B3, w.x);
    SET_LANES(wb_[1], B0, B1, B2, B3, w.y);
    SET_LANES(wb_[2], B0, B1, B2, B3, w.z);
    SET_LANES(lb->ma, A0, A1, A2, A3, inv_mass);
    SET_LANES(lb->mb, B0, B1, B2, B3, inv_mass);
    lb->oa = DOT3(wa, pl->la);
    lb->ob = DOT3(wb_, pl->lb);
}

LANE_INLINE void scatter_p(const wide_batch *wb, const wide_plane *pl, impulse_body *bodies, const lane_pbodies *lb)
{
    lane_t wa[3], wb_[3];
    for (int d = 0; d < 3; d++) {
        wa[d] = pl->la[d] * lb->oa;
        wb_[d] = pl->lb[d] * lb->ob;
    }
    for (int l = 0; l < LANES; l++) {
        if (wb->a[l]) {
            impulse_body *A = &bodies[wb->a[l]];
            A->v = v3(lb->va[0][l], lb->va[1][l], lb->va[2][l]);
            A->w = v3(wa[0][l], wa[1][l], wa[2][l]);
        }
        if (wb->b[l]) {
            impulse_body *B = &bodies[wb->b[l]];
            B->v = v3(lb->vb[0][l], lb->vb[1][l], lb->vb[2][l]);
            B->w = v3(wb_[0][l], wb_[1][l], wb_[2][l]);
        }
    }
}

LANE_INLINE void warm_batch_p(const wide_batch *wb, const wide_plane *pl, wide_ppoint *pts, impulse_body *bodies,
                              const int friction)
{
    lane_pbodies lb;
    gather_p(wb, pl, bodies, &lb);
    for (int i = 0; i < wb->count; i++) {
        wide_ppoint *p = &pts[i];
        lane_t ni = p->normal_impulse, t1 = p->tangent_impulse[0], t2 = p->tangent_impulse[1];
        p->total_normal_impulse += ni;
        if (friction) {
            for (int d = 0; d < 3; d++) {
                lb.va[d] -= lb.ma * (pl->na[d] * ni + pl->t1a[d] * t1 + pl->t2a[d] * t2);
                lb.vb[d] += lb.mb * (pl->nb[d] * ni + pl->t1b[d] * t1 + pl->t2b[d] * t2);
            }
            lb.oa -= pl->ka * (p->ja_n * ni + p->ja_t[0] * t1 + p->ja_t[1] * t2);
            lb.ob += pl->kb * (p->jb_n * ni + p->jb_t[0] * t1 + p->jb_t[1] * t2);
        } else {
            for (int d = 0; d < 3; d++) {
                lb.va[d] -= lb.ma * (pl->na[d] * ni);
                lb.vb[d] += lb.mb * (pl->nb[d] * ni);
            }
            lb.oa -= pl->ka * (p->ja_n * ni);
            lb.ob += pl->kb * (p->jb_n * ni);
        }
    }
    scatter_p(wb, pl, bodies, &lb);
}

LANE_INLINE void solve_normal_rows_p(const wide_batch *wb, const wide_plane *pl, wide_ppoint *pts,
                                     const step_context *ctx, lane_pbodies *lb, int use_bias, int hold_bounces)
{
    lane_t dp[3], dqa[3], dqb[3];
    gather_motion(wb, ctx, dp, dqa, dqb);
    /* each body's rotation since the sub-steps began is about its plane normal */
    lane_t qa = DOT3(dqa, pl->la), qb = DOT3(dqb, pl->lb), dpn = DOT3(wb->n, dp);
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0), inv_h = SPLAT(ctx->inv_h), push = SPLAT(-ctx->push_max);
    lane_t pen_mass_scale = one, pen_impulse_scale = zero;
    int soft = use_bias && ctx->correction == CAROM_CORRECTION_SOFT;
    int baumgarte = use_bias && ctx->correction == CAROM_CORRECTION_BAUMGARTE;
    if (soft) {
        pen_mass_scale = wb->mass_scale;
        pen_impulse_scale = wb->impulse_scale;
    }
    const lane_t baum_rate = SPLAT(ctx->baumgarte_rate), slop = SPLAT(ctx->slop);
    for (int i = 0; i < wb->count; i++) {
        wide_ppoint *p = &pts[i];
        lane_t s = p->base_separation + dpn + qb * p->jb_n - qa * p->ja_n;
        lane_t pen_bias = zero;
        if (soft || baumgarte) {
            lane_t rate = wb->bias_rate;
            pen_bias = CONTACT_PUSH_BIAS(soft, s, rate, baum_rate, slop, push, zero, LANE_MAX, LANE_MIN);
        }
        lane_mask ahead = s > zero;
        lane_t spec = CONTACT_SPECULATIVE_BIAS(s, inv_h);
        lane_t bias = SELECT_LANES(ahead, spec, pen_bias);
        lane_t mass_scale = SELECT_LANES(ahead, one, pen_mass_scale);
        lane_t impulse_scale = SELECT_LANES(ahead, zero, pen_impulse_scale);
        lane_t vn = wb->n[0] * (lb->vb[0] - lb->va[0]) + wb->n[1] * (lb->vb[1] - lb->va[1]) +
                    wb->n[2] * (lb->vb[2] - lb->va[2]) + lb->ob * p->jb_n - lb->oa * p->ja_n;
        lane_t old = p->normal_impulse;
        lane_t total = old - p->normal_mass * mass_scale * (vn + bias) - impulse_scale * old;
        total = LANE_MAX(total, zero);
        if (hold_bounces) {
            lane_mask hold = ahead & (wb->restitution > zero);
            total = SELECT_LANES(hold, LANE_MIN(total, old), total);
        }
        lane_t lambda = total - old;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        lane_t la = lb->ma * lambda, lbm = lb->mb * lambda;
        for (int d = 0; d < 3; d++) {
            lb->va[d] -= la * pl->na[d];
            lb->vb[d] += lbm * pl->nb[d];
        }
        lb->oa -= pl->ka * (p->ja_n * lambda);
        lb->ob += pl->kb * (p->jb_n * lambda);
    }
}

LANE_INLINE void solve_friction_rows_p(const wide_batch *wb, const wide_plane *pl, wide_ppoint *pts, lane_pbodies *lb)
{
    for (int i = 0; i < wb->count; i++) {
        wide_ppoint *p = &pts[i];
        lane_t dv[3] = {lb->vb[0] - lb->va[0], lb->vb[1] - lb->va[1], lb->vb[2] - lb->va[2]};
        lane_t v1 = DOT3(dv, wb->t1) + lb->ob * p->jb_t[0] - lb->oa * p->ja_t[0];
        lane_t v2 = DOT3(dv, wb->t2) + lb->ob * p->jb_t[1] - lb->oa * p->ja_t[1];
        lane_t d1, d2;
        friction_lanes(p->tangent_impulse, p->tangent_mass, &p->normal_impulse, &wb->friction, &v1, &v2, &d1, &d2);
        for (int d = 0; d < 3; d++) {
            lb->va[d] -= lb->ma * (pl->t1a[d] * d1 + pl->t2a[d] * d2);
            lb->vb[d] += lb->mb * (pl->t1b[d] * d1 + pl->t2b[d] * d2);
        }
        lb->oa -= pl->ka * (p->ja_t[0] * d1 + p->ja_t[1] * d2);
        lb->ob += pl->kb * (p->jb_t[0] * d1 + p->jb_t[1] * d2);
    }
}

LANE_INLINE void solve_batch_p(const wide_batch *wb, const wide_plane *pl, wide_ppoint *pts, const step_context *ctx,
                               int use_bias, int hold_bounces)
{
    lane_pbodies lb;
    gather_p(wb, pl, ctx->bodies, &lb);
    solve_normal_rows_p(wb, pl, pts, ctx, &lb, use_bias, hold_bounces);
    if (ctx->friction) solve_friction_rows_p(wb, pl, pts, &lb);
    scatter_p(wb, pl, ctx->bodies, &lb);
}

/* A planar batch's points: the rows' directions in each body's plane and
 * the moments about the normals (k = l.(I^-1 l) for I^-1 = k l l^T; 0 for
 * the static body), then per point the arms' components about the normals
 * and the masses 1 / (1/mA (1 - (d.lA)^2) + kA ((rA x d).lA)^2 + ...). */
LANE_INLINE double prepare_batch_p(const wide_batch *wb, wide_plane *pl, wide_ppoint *pts, contact_constraint *cc,
                                   const impulse_body *bodies, double warm, int friction)
{
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0);
    lane_manifolds lm;
    gather_manifolds(wb, cc, bodies, &lm, 1);
    IN_PLANE(pl->na, wb->n, pl->la);
    IN_PLANE(pl->nb, wb->n, pl->lb);
    IN_PLANE(pl->t1a, wb->t1, pl->la);
    IN_PLANE(pl->t1b, wb->t1, pl->lb);
    IN_PLANE(pl->t2a, wb->t2, pl->la);
    IN_PLANE(pl->t2b, wb->t2, pl->lb);
    lane_t ila[3], ilb[3];
    MAT_VEC(ila, lm.ia, pl->la);
    MAT_VEC(ilb, lm.ib, pl->lb);
    pl->ka = DOT3(pl->la, ila);
    pl->kb = DOT3(pl->lb, ilb);
    lane_t lin[3], floor = SPLAT(ROW_BLOCKED_SHARE) * (lm.ma + lm.mb);
    lin[0] = LOCKED_INV_MASS(lm.ma, wb->n, pl->la) + LOCKED_INV_MASS(lm.mb, wb->n, pl->lb);
    lin[1] = LOCKED_INV_MASS(lm.ma, wb->t1, pl->la) + LOCKED_INV_MASS(lm.mb, wb->t1, pl->lb);
    lin[2] = LOCKED_INV_MASS(lm.ma, wb->t2, pl->la) + LOCKED_INV_MASS(lm.mb, wb->t2, pl->lb);
    double deepest = 0.0;
    for (int i = 0; i < wb->count; i++) {
        wide_ppoint *p = &pts[i];
        const contact_point_state *st[LANES];
        lane_t ra[3], rb[3], sep;
        gather_point(&lm, i, st, ra, rb, &sep);
        lane_t xa[3], xb[3];
        CROSS(xa, ra, wb->n);
        CROSS(xb, rb, wb->n);
        p->ja_n = DOT3(xa, pl->la);
        p->jb_n = DOT3(xb, pl->lb);
        lane_t kn = lin[0] + pl->ka * p->ja_n * p->ja_n + pl->kb * p->jb_n * p->jb_n;
        p->normal_mass = ROW_MASS_ABOVE(kn, floor);
        if (friction) {
            CROSS(xa, ra, wb->t1);
            CROSS(xb, rb, wb->t1);
            p->ja_t[0] = DOT3(xa, pl->la);
            p->jb_t[0] = DOT3(xb, pl->lb);
            CROSS(xa, ra, wb->t2);
            CROSS(xb, rb, wb->t2);
            p->ja_t[1] = DOT3(xa, pl->la);
            p->jb_t[1] = DOT3(xb, pl->lb);
            lane_t k1 = lin[1] + pl->ka * p->ja_t[0] * p->ja_t[0] + pl->kb * p->jb_t[0] * p->jb_t[0];
            lane_t k2 = lin[2] + pl->ka * p->ja_t[1] * p->ja_t[1] + pl->kb * p->jb_t[1] * p->jb_t[1];
            p->tangent_mass[0] = ROW_MASS_ABOVE(k1, floor);
            p->tangent_mass[1] = ROW_MASS_ABOVE(k2, floor);
        }
        p->base_separation = sep;
        lane_t wxa[3], wxb[3];
        CROSS(wxa, lm.wa, ra);
        CROSS(wxb, lm.wb, rb);
        lane_t vrel[3];
        for (int d = 0; d < 3; d++) vrel[d] = (lm.vb[d] + wxb[d]) - (lm.va[d] + wxa[d]);
        lane_t vn = DOT3(vrel, wb->n);
        WARM_POINT(p, st, warm, friction);
        deepest = store_point(wb, &lm, i, ra, rb, &sep, &vn, deepest);
    }
    return deepest;
}

/* ---- the compact rows (wide_cpoint) --------------------------------------
 * The same rows as above with every arm in the batch's basis e = (n, t1,
 * t2): an anchor r = (r0, r1, r2) there has the arms r x n = (0, r2, -r1),
 * r x t1 = (-r2, 0, r0) and r x t2 = (r1, -r0, 0), and a body's velocities
 * in the basis meet the normal row in their first coordinate and the
 * friction rows in the other two. */

/* K x for the upper triangle K of a symmetric matrix (wide_inertia). */
#define SYM_MUL(u, K, x)                                              \
    do {                                                              \
        (u)[0] = (K)[0] * (x)[0] + (K)[1] * (x)[1] + (K)[2] * (x)[2]; \
        (u)[1] = (K)[1] * (x)[0] + (K)[3] * (x)[1] + (K)[4] * (x)[2]; \
        (u)[2] = (K)[2] * (x)[0] + (K)[4] * (x)[1] + (K)[5] * (x)[2]; \
    } while (0)
/* a world vector's coordinates in the batch's basis */
#define TO_BASIS(dst, wb_, src)                 \
    do {                                        \
        (dst)[0] = DOT3((wb_)->n, src);         \
        (dst)[1] = DOT3((wb_)->t1, src);        \
        (dst)[2] = DOT3((wb_)->t2, src);        \
    } while (0)

/* b's anchor in the basis from a's (wide_inertia's d) */
#define ARM_B(rb_, ra_, d_)                                     \
    do {                                                        \
        for (int k_ = 0; k_ < 3; k_++) (rb_)[k_] = (ra_)[k_] - (d_)[k_]; \
    } while (0)

/* The lanes' bodies as gathered (world) and in the basis, solved there. */
typedef struct lane_cbodies {
    lane_bodies world;
    lane_t va[3], wa[3], vb[3], wb[3];         /* solved */
    lane_t va0[3], wa0[3], vb0[3], wb0[3];     /* as gathered */
    lane_t ma, mb;
} lane_cbodies;

LANE_INLINE void gather_c(const wide_batch *wb, const impulse_body *bodies, lane_cbodies *lb)
{
    gather(wb, bodies, &lb->world);
    TO_BASIS(lb->va0, wb, lb->world.va);
    TO_BASIS(lb->wa0, wb, lb->world.wa);
    TO_BASIS(lb->vb0, wb, lb->world.vb);
    TO_BASIS(lb->wb0, wb, lb->world.wb);
    for (int d = 0; d < 3; d++) {
        lb->va[d] = lb->va0[d];
        lb->wa[d] = lb->wa0[d];
        lb->vb[d] = lb->vb0[d];
        lb->wb[d] = lb->wb0[d];
    }
    lb->ma = lb->world.ma;
    lb->mb = lb->world.mb;
}

/* world += the change made in the basis (a body no row pushed keeps its bits) */
#define ADD_FROM_BASIS(w_, wb_, now, was)                                                  \
    do {                                                                                   \
        lane_t c0_ = (now)[0] - (was)[0], c1_ = (now)[1] - (was)[1], c2_ = (now)[2] - (was)[2]; \
        for (int k_ = 0; k_ < 3; k_++)                                                     \
            (w_)[k_] = (w_)[k_] + (c0_ * (wb_)->n[k_] + c1_ * (wb_)->t1[k_] + c2_ * (wb_)->t2[k_]); \
    } while (0)

LANE_INLINE void scatter_c(const wide_batch *wb, impulse_body *bodies, lane_cbodies *lb)
{
    ADD_FROM_BASIS(lb->world.va, wb, lb->va, lb->va0);
    ADD_FROM_BASIS(lb->world.wa, wb, lb->wa, lb->wa0);
    ADD_FROM_BASIS(lb->world.vb, wb, lb->vb, lb->vb0);
    ADD_FROM_BASIS(lb->world.wb, wb, lb->wb, lb->wb0);
    scatter(wb, bodies, &lb->world);
}

/* A body's angular change -K (r x P) (a) or +K (r x P) (b), P = (p0, p1, p2) in the basis. */
#define PUSH_ANGULAR(w_, sign, K, r, p0, p1, p2)                                                         \
    do {                                                                                                \
        lane_t x_[3] = {(r)[1] * (p2) - (r)[2] * (p1), (r)[2] * (p0) - (r)[0] * (p2), (r)[0] * (p1) - (r)[1] * (p0)}; \
        lane_t u_[3];                                                                                   \
        SYM_MUL(u_, K, x_);                                                                             \
        for (int k_ = 0; k_ < 3; k_++) (w_)[k_] = (w_)[k_] sign u_[k_];                                  \
    } while (0)

LANE_INLINE void warm_batch_c(const wide_batch *wb, const wide_inertia *in, wide_cpoint *pts, impulse_body *bodies,
                              const wide_lock *lk, const int locked, const int friction)
{
    lane_cbodies lb;
    const lane_t zero = SPLAT(0.0);
    gather_c(wb, bodies, &lb);
    for (int i = 0; i < wb->count; i++) {
        wide_cpoint *p = &pts[i];
        lane_t ni = p->normal_impulse, t1 = p->tangent_impulse[0], t2 = p->tangent_impulse[1];
        lane_t rb[3];
        ARM_B(rb, p->ra, in->d);
        p->total_normal_impulse += ni;
        lb.va[0] -= lb.ma * ni;
        lb.vb[0] += lb.mb * ni;
        if (friction) {
            lb.va[1] -= lb.ma * t1;
            lb.va[2] -= lb.ma * t2;
            lb.vb[1] += lb.mb * t1;
            lb.vb[2] += lb.mb * t2;
            PUSH_ANGULAR(lb.wa, -, in->ka, p->ra, ni, t1, t2);
            PUSH_ANGULAR(lb.wb, +, in->kb, rb, ni, t1, t2);
        } else {
            PUSH_ANGULAR(lb.wa, -, in->ka, p->ra, ni, zero, zero);
            PUSH_ANGULAR(lb.wb, +, in->kb, rb, ni, zero, zero);
        }
        if (locked) {
            KEEP_IN_PLANE(lb.va, lk->a);
            KEEP_IN_PLANE(lb.vb, lk->b);
        }
    }
    scatter_c(wb, bodies, &lb);
}

LANE_INLINE void solve_normal_rows_c(const wide_batch *wb, const wide_inertia *in, wide_cpoint *pts,
                                     const step_context *ctx, lane_cbodies *lb, int use_bias, int hold_bounces,
                                     const wide_lock *lk, const int locked)
{
    lane_t dp[3], dqa[3], dqb[3];
    gather_motion(wb, ctx, dp, dqa, dqb);
    /* the motion in the basis: what the separations read of it */
    lane_t dpn = DOT3(wb->n, dp), qa1 = DOT3(wb->t1, dqa), qa2 = DOT3(wb->t2, dqa), qb1 = DOT3(wb->t1, dqb),
           qb2 = DOT3(wb->t2, dqb);
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0), inv_h = SPLAT(ctx->inv_h), push = SPLAT(-ctx->push_max);
    lane_t pen_mass_scale = one, pen_impulse_scale = zero;
    int soft = use_bias && ctx->correction == CAROM_CORRECTION_SOFT;
    int baumgarte = use_bias && ctx->correction == CAROM_CORRECTION_BAUMGARTE;
    if (soft) {
        pen_mass_scale = wb->mass_scale;
        pen_impulse_scale = wb->impulse_scale;
    }
    const lane_t baum_rate = SPLAT(ctx->baumgarte_rate), slop = SPLAT(ctx->slop);
    for (int i = 0; i < wb->count; i++) {
        wide_cpoint *p = &pts[i];
        const lane_t *a = p->ra;
        lane_t b[3];
        ARM_B(b, a, in->d);
        lane_t s = p->base_separation + dpn + (b[2] * qb1 - b[1] * qb2) - (a[2] * qa1 - a[1] * qa2);
        lane_t pen_bias = zero;
        if (soft || baumgarte) {
            lane_t rate = wb->bias_rate;
            pen_bias = CONTACT_PUSH_BIAS(soft, s, rate, baum_rate, slop, push, zero, LANE_MAX, LANE_MIN);
        }
        lane_mask ahead = s > zero;
        lane_t spec = CONTACT_SPECULATIVE_BIAS(s, inv_h);
        lane_t bias = SELECT_LANES(ahead, spec, pen_bias);
        lane_t mass_scale = SELECT_LANES(ahead, one, pen_mass_scale);
        lane_t impulse_scale = SELECT_LANES(ahead, zero, pen_impulse_scale);
        lane_t vn = (lb->vb[0] - lb->va[0]) + (b[2] * lb->wb[1] - b[1] * lb->wb[2]) -
                    (a[2] * lb->wa[1] - a[1] * lb->wa[2]);
        lane_t old = p->normal_impulse;
        lane_t total = old - p->normal_mass * mass_scale * (vn + bias) - impulse_scale * old;
        total = LANE_MAX(total, zero);
        if (hold_bounces) {
            lane_mask hold = ahead & (wb->restitution > zero);
            total = SELECT_LANES(hold, LANE_MIN(total, old), total);
        }
        lane_t lambda = total - old;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        lb->va[0] -= lb->ma * lambda;
        lb->vb[0] += lb->mb * lambda;
        PUSH_ANGULAR(lb->wa, -, in->ka, a, lambda, zero, zero);
        PUSH_ANGULAR(lb->wb, +, in->kb, b, lambda, zero, zero);
        if (locked) {
            KEEP_IN_PLANE(lb->va, lk->a);
            KEEP_IN_PLANE(lb->vb, lk->b);
        }
    }
}

LANE_INLINE void solve_friction_rows_c(const wide_batch *wb, const wide_inertia *in, wide_cpoint *pts,
                                       lane_cbodies *lb, const wide_lock *lk, const int locked)
{
    const lane_t zero = SPLAT(0.0);
    for (int i = 0; i < wb->count; i++) {
        wide_cpoint *p = &pts[i];
        const lane_t *a = p->ra;
        lane_t b[3];
        ARM_B(b, a, in->d);
        lane_t v1 = (lb->vb[1] - lb->va[1]) + (b[0] * lb->wb[2] - b[2] * lb->wb[0]) -
                    (a[0] * lb->wa[2] - a[2] * lb->wa[0]);
        lane_t v2 = (lb->vb[2] - lb->va[2]) + (b[1] * lb->wb[0] - b[0] * lb->wb[1]) -
                    (a[1] * lb->wa[0] - a[0] * lb->wa[1]);
        lane_t d1, d2;
        friction_lanes(p->tangent_impulse, p->tangent_mass, &p->normal_impulse, &wb->friction, &v1, &v2, &d1, &d2);
        lb->va[1] -= lb->ma * d1;
        lb->va[2] -= lb->ma * d2;
        lb->vb[1] += lb->mb * d1;
        lb->vb[2] += lb->mb * d2;
        PUSH_ANGULAR(lb->wa, -, in->ka, a, zero, d1, d2);
        PUSH_ANGULAR(lb->wb, +, in->kb, b, zero, d1, d2);
        if (locked) {
            KEEP_IN_PLANE(lb->va, lk->a);
            KEEP_IN_PLANE(lb->vb, lk->b);
        }
    }
}

LANE_INLINE void solve_batch_c(const wide_batch *wb, const wide_inertia *in, wide_cpoint *pts,
                               const step_context *ctx, int use_bias, int hold_bounces, const wide_lock *lk,
                               const int locked)
{
    lane_cbodies lb;
    gather_c(wb, ctx->bodies, &lb);
    solve_normal_rows_c(wb, in, pts, ctx, &lb, use_bias, hold_bounces, lk, locked);
    if (ctx->friction) solve_friction_rows_c(wb, in, pts, &lb, lk, locked);
    scatter_c(wb, ctx->bodies, &lb);
}

/* out += r.(K r) for an arm r */
#define ADD_QUAD(out, K, x)          \
    do {                             \
        lane_t u_[3];                \
        SYM_MUL(u_, K, x);           \
        (out) = (out) + DOT3(x, u_); \
    } while (0)

/* The basis-projected inverse inertia of one side's lanes. */
LANE_INLINE void project_inertia(lane_t k[6], const wide_batch *wb, lane_t ia[3][3])
{
    lane_t in_[3], it1[3], it2[3];
    MAT_VEC(in_, ia, wb->n);
    MAT_VEC(it1, ia, wb->t1);
    MAT_VEC(it2, ia, wb->t2);
    k[0] = DOT3(wb->n, in_);
    k[1] = DOT3(wb->n, it1);
    k[2] = DOT3(wb->n, it2);
    k[3] = DOT3(wb->t1, it1);
    k[4] = DOT3(wb->t1, it2);
    k[5] = DOT3(wb->t2, it2);
}


LANE_INLINE double prepare_batch_c(const wide_batch *wb, wide_inertia *in, wide_cpoint *pts, contact_constraint *cc,
                                   const impulse_body *bodies, double warm, const wide_lock *lk, int friction)
{
    const lane_t zero = SPLAT(0.0), one = SPLAT(1.0);
    lane_manifolds lm;
    gather_manifolds(wb, cc, bodies, &lm, 1);
    project_inertia(in->ka, wb, lm.ia);
    project_inertia(in->kb, wb, lm.ib);
    lane_t dc[3];
    for (int d = 0; d < 3; d++) dc[d] = lm.center_b[d] - lm.center_a[d];
    TO_BASIS(in->d, wb, dc);
    /* the linear share of each row's inverse effective mass (n, t1, t2);
     * a locked body's plane normal is in the basis here */
    lane_t lin[3];
    lin[0] = lin[1] = lin[2] = lm.ma + lm.mb;
    if (lk) {
        for (int d = 0; d < 3; d++)
            lin[d] = lm.ma * (one - lk->a[d] * lk->a[d]) + lm.mb * (one - lk->b[d] * lk->b[d]);
    }
    double deepest = 0.0;
    for (int i = 0; i < wb->count; i++) {
        wide_cpoint *p = &pts[i];
        const contact_point_state *st[LANES];
        lane_t ra[3], rb[3], sep;
        gather_point(&lm, i, st, ra, rb, &sep);
        TO_BASIS(p->ra, wb, ra);
        const lane_t *a = p->ra;
        lane_t b[3];
        ARM_B(b, a, in->d);
        /* the arms r x n, r x t1, r x t2 in the basis, and their masses */
        lane_t jan[3] = {zero, a[2], -a[1]}, jbn[3] = {zero, b[2], -b[1]};
        lane_t ja1[3] = {-a[2], zero, a[0]}, jb1[3] = {-b[2], zero, b[0]};
        lane_t ja2[3] = {a[1], -a[0], zero}, jb2[3] = {b[1], -b[0], zero};
        lane_t kn = lin[0];
        ADD_QUAD(kn, in->ka, jan);
        ADD_QUAD(kn, in->kb, jbn);
        p->normal_mass = ROW_MASS(kn);
        if (friction) {
            lane_t k1 = lin[1], k2 = lin[2];
            ADD_QUAD(k1, in->ka, ja1);
            ADD_QUAD(k1, in->kb, jb1);
            ADD_QUAD(k2, in->ka, ja2);
            ADD_QUAD(k2, in->kb, jb2);
            p->tangent_mass[0] = ROW_MASS(k1);
            p->tangent_mass[1] = ROW_MASS(k2);
        }
        p->base_separation = sep;
        lane_t wxa[3], wxb[3];
        CROSS(wxa, lm.wa, ra);
        CROSS(wxb, lm.wb, rb);
        lane_t vrel[3];
        for (int d = 0; d < 3; d++) vrel[d] = (lm.vb[d] + wxb[d]) - (lm.va[d] + wxa[d]);
        lane_t vn = DOT3(vrel, wb->n);
        WARM_POINT(p, st, warm, friction);
        deepest = store_point(wb, &lm, i, ra, rb, &sep, &vn, deepest);
    }
    return deepest;
}

/* A large world's batches (the compact rows) reach their bodies in no
 * order the caches can follow: a pass fetches the bodies of the batch
 * WIDE_PREFETCH ahead (and, solving, their motion since the step began)
 * while it solves this one. Reading that batch's body indices is itself a
 * miss in a large world (the headers stream past the caches, and the
 * hardware's prefetch did not keep ahead of them: a third of the solve
 * pass's samples at 50k bodies sat on that read), so the header twice as
 * far ahead is fetched too, each of its cache lines. Hints only: no result
 * depends on them. */
#define WIDE_PREFETCH 4
LANE_INLINE void prefetch_batch(const wide_set *ws, const impulse_body *bodies, const step_context *ctx, int k,
                                int last)
{
    if (k + 2 * WIDE_PREFETCH < last) {
        const char *header = (const char *)&ws->batches[k + 2 * WIDE_PREFETCH];
        for (size_t at = 0; at < sizeof(wide_batch); at += 64) __builtin_prefetch(header + at);
    }
    if (k + WIDE_PREFETCH >= last) return;
    const wide_batch *wb = &ws->batches[k + WIDE_PREFETCH];
    for (int l = 0; l < LANES; l++) {
        __builtin_prefetch(&bodies[wb->a[l]]);
        __builtin_prefetch(&bodies[wb->b[l]]);
        if (ctx) {
            __builtin_prefetch(&ctx->dp[wb->a[l]]);
            __builtin_prefetch(&ctx->dp[wb->b[l]]);
            __builtin_prefetch(&ctx->dq[wb->a[l]]);
            __builtin_prefetch(&ctx->dq[wb->b[l]]);
        }
    }
}

/* The passes over every batch, written once and built twice: for the base
 * target (SSE2 on x86-64) and, chosen at run time, for AVX2 (one register per
 * four lanes instead of two, and twice the registers). No FMA: rounding stays
 * the same in both builds, so results do not depend on the machine. */
#define WIDE_PASSES(SUFFIX, TARGET)                                                                     \
    TARGET static void prepare_batches##SUFFIX(const wide_set *ws, contact_constraint *cc,               \
                                               const impulse_body *bodies, double warm, int friction,    \
                                               int first, int last)                                      \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            const wide_lock *lk = wb->kind == WIDE_KIND_LOCKED ? &ws->locks[wb->lock] : NULL;          \
            if (wb->kind & WIDE_KIND_SPINLESS)                                                           \
                ws->deepest[k] = prepare_batch_l(wb, &ws->lpoints[wb->first], cc, bodies, warm,          \
                                                 wb->lock >= 0 ? &ws->planes[wb->lock] : NULL, friction); \
            else if (wb->kind == WIDE_KIND_PLANAR)                                                       \
                ws->deepest[k] = prepare_batch_p(wb, &ws->planes[wb->lock], &ws->ppoints[wb->first], cc, bodies, \
                                                 warm, friction);                                        \
            else                                                                                         \
                ws->deepest[k] = prepare_batch(wb, &ws->points[wb->first], cc, bodies, warm, lk, friction); \
        }                                                                                                \
    }                                                                                                    \
    /* the other kinds' copies out of line: the free batches' loops stay as without them */             \
    TARGET __attribute__((noinline)) static void warm_locked##SUFFIX(const wide_set *ws, impulse_body *bodies, \
                                                                    int friction, int first, int last)   \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            if (friction) warm_batch(wb, &ws->points[wb->first], bodies, &ws->locks[wb->lock], 1, 1);\
            else warm_batch(wb, &ws->points[wb->first], bodies, &ws->locks[wb->lock], 1, 0);         \
        }                                                                                                \
    }                                                                                                    \
    TARGET static void warm_batches##SUFFIX(const wide_set *ws, impulse_body *bodies, int friction, int first, \
                                            int last)                                                    \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            if (friction) warm_batch(wb, &ws->points[wb->first], bodies, NULL, 0, 1);                \
            else warm_batch(wb, &ws->points[wb->first], bodies, NULL, 0, 0);                         \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void warm_spinless##SUFFIX(const wide_set *ws, impulse_body *bodies, \
                                                                      int friction, int first, int last) \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            if (friction) warm_batch_l(wb, &ws->lpoints[wb->first], bodies, NULL, 0, 1);             \
            else warm_batch_l(wb, &ws->lpoints[wb->first], bodies, NULL, 0, 0);                      \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void warm_spinless_locked##SUFFIX(const wide_set *ws,        \
                                                                             impulse_body *bodies,       \
                                                                             int friction, int first,    \
                                                                             int last)                   \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            if (friction) warm_batch_l(wb, &ws->lpoints[wb->first], bodies, &ws->planes[wb->lock], 1, 1); \
            else warm_batch_l(wb, &ws->lpoints[wb->first], bodies, &ws->planes[wb->lock], 1, 0);     \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void warm_planar##SUFFIX(const wide_set *ws, impulse_body *bodies, \
                                                                    int friction, int first, int last)   \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            if (friction) warm_batch_p(wb, &ws->planes[wb->lock], &ws->ppoints[wb->first], bodies, 1);   \
            else warm_batch_p(wb, &ws->planes[wb->lock], &ws->ppoints[wb->first], bodies, 0);            \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void solve_planar##SUFFIX(const wide_set *ws, const step_context *ctx, \
                                                                     int use_bias, int hold_bounces, int first, \
                                                                     int last)                           \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            solve_batch_p(wb, &ws->planes[wb->lock], &ws->ppoints[wb->first], ctx, use_bias, hold_bounces); \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void solve_locked##SUFFIX(const wide_set *ws, const step_context *ctx, \
                                                                     int use_bias, int hold_bounces, int first, \
                                                                     int last)                           \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            solve_batch(wb, &ws->points[wb->first], ctx, use_bias, hold_bounces, &ws->locks[wb->lock], 1); \
        }                                                                                                \
    }                                                                                                    \
    TARGET static void solve_batches##SUFFIX(const wide_set *ws, const step_context *ctx, int use_bias,  \
                                             int hold_bounces, int first, int last)                      \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            solve_batch(wb, &ws->points[wb->first], ctx, use_bias, hold_bounces, NULL, 0);               \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void solve_spinless##SUFFIX(const wide_set *ws,              \
                                                                       const step_context *ctx, int use_bias, \
                                                                       int hold_bounces, int first, int last) \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            solve_batch_l(wb, &ws->lpoints[wb->first], ctx, use_bias, hold_bounces, NULL, 0);            \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void solve_spinless_locked##SUFFIX(const wide_set *ws,       \
                                                                              const step_context *ctx,   \
                                                                              int use_bias,              \
                                                                              int hold_bounces, int first, \
                                                                              int last)                  \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            solve_batch_l(wb, &ws->lpoints[wb->first], ctx, use_bias, hold_bounces, &ws->planes[wb->lock], 1); \
        }                                                                                                \
    }                                                                                                    \
    TARGET static void prepare_batches_c##SUFFIX(const wide_set *ws, contact_constraint *cc,             \
                                                 const impulse_body *bodies, double warm, int friction,  \
                                                 int first, int last)                                    \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            const wide_lock *lk = wb->kind == WIDE_KIND_LOCKED ? &ws->locks[wb->lock] : NULL;          \
            if (wb->kind & WIDE_KIND_SPINLESS)                                                           \
                ws->deepest[k] = prepare_batch_l(wb, &ws->lpoints[wb->first], cc, bodies, warm,          \
                                                 wb->lock >= 0 ? &ws->planes[wb->lock] : NULL, friction); \
            else if (wb->kind == WIDE_KIND_PLANAR)                                                       \
                ws->deepest[k] = prepare_batch_p(wb, &ws->planes[wb->lock], &ws->ppoints[wb->first], cc, bodies, \
                                                 warm, friction);                                        \
            else                                                                                         \
                ws->deepest[k] = prepare_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], cc, bodies, warm, \
                                                 lk, friction);                                          \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void warm_locked_c##SUFFIX(const wide_set *ws, impulse_body *bodies, \
                                                                      int friction, int first, int last) \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            if (friction) warm_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], bodies, &ws->locks[wb->lock], 1, 1);\
            else warm_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], bodies, &ws->locks[wb->lock], 1, 0);\
        }                                                                                                \
    }                                                                                                    \
    TARGET static void warm_batches_c##SUFFIX(const wide_set *ws, impulse_body *bodies, int friction, int first, \
                                              int last)                                                  \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            prefetch_batch(ws, bodies, NULL, k, last);                                                   \
            if (friction) warm_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], bodies, NULL, 0, 1);\
            else warm_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], bodies, NULL, 0, 0);     \
        }                                                                                                \
    }                                                                                                    \
    TARGET __attribute__((noinline)) static void solve_locked_c##SUFFIX(const wide_set *ws, const step_context *ctx, \
                                                                       int use_bias, int hold_bounces, int first, \
                                                                       int last)                         \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            solve_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], ctx, use_bias, hold_bounces,     \
                          &ws->locks[wb->lock], 1);                                                      \
        }                                                                                                \
    }                                                                                                    \
    TARGET static void solve_batches_c##SUFFIX(const wide_set *ws, const step_context *ctx, int use_bias, \
                                               int hold_bounces, int first, int last)                    \
    {                                                                                                    \
        for (int k = first; k < last; k++) {                                                             \
            const wide_batch *wb = &ws->batches[k];                                                      \
            prefetch_batch(ws, ctx->bodies, ctx, k, last);                                               \
            solve_batch_c(wb, &ws->inertia[k], &ws->cpoints[wb->first], ctx, use_bias, hold_bounces, NULL, 0); \
        }                                                                                                \
    }                                                                                                    \
    /* indexed by kind: free, locked, spinless, spinless and locked, planar (both layouts share the spinless and planar rows) */ \
    static const wide_kernels passes##SUFFIX = {                                                         \
        {prepare_batches##SUFFIX,                                                                        \
         {warm_batches##SUFFIX, warm_locked##SUFFIX, warm_spinless##SUFFIX, warm_spinless_locked##SUFFIX,    \
          warm_planar##SUFFIX},                                                                          \
         {solve_batches##SUFFIX, solve_locked##SUFFIX, solve_spinless##SUFFIX, solve_spinless_locked##SUFFIX, \
          solve_planar##SUFFIX}},                                                                        \
        {prepare_batches_c##SUFFIX,                                                                      \
         {warm_batches_c##SUFFIX, warm_locked_c##SUFFIX, warm_spinless##SUFFIX, warm_spinless_locked##SUFFIX, \
          warm_planar##SUFFIX},                                                                          \
         {solve_batches_c##SUFFIX, solve_locked_c##SUFFIX, solve_spinless##SUFFIX, solve_spinless_locked##SUFFIX, \
          solve_planar##SUFFIX}}};

WIDE_PASSES(_base, )
#if WIDE_AVX2
WIDE_PASSES(_avx2, __attribute__((target("avx2"))))
#endif


/* The build of the passes this set runs, for its row layout. */
static const wide_passes *passes_for(const wide_set *ws)
{
    const wide_kernels *k = &passes_base;
#if WIDE_AVX2
    if (ws->avx2) k = &passes_avx2;
#endif
    return ws->compact ? &k->compact : &k->full;
}

/* Batches per range handed to the task hooks: a range of a solve pass is a
 * few microseconds of work, well above the cost of handing it over. */
#define WIDE_MIN_RANGE 32

/* One pass's job: the batches of the colour (or of all colours) in hand
 * start at `offset`. */
typedef struct wide_job {
    const wide_set *ws;
    const wide_passes *passes;
    const step_context *ctx;
    contact_constraint *cc;
    int offset, use_bias, hold_bounces;
    int color;                   /* the colour in hand (warm start and solve) */
} wide_job;

static void prepare_range(int begin, int end, int worker, void *p)
{
    const wide_job *j = p;
    (void)worker;
    j->passes->prepare(j->ws, j->cc, j->ctx->bodies, j->ctx->warm_starting ? 1.0 : 0.0, j->ctx->friction,
                       j->offset + begin, j->offset + end);
}

/* The part of [first, last) that holds kind k's batches of the colour in hand. */
static int kind_span(const wide_job *j, int k, int first, int last, int *from, int *to)
{
    const wide_set *ws = j->ws;
    int lo = ws->kind_first[j->color][k];
    int hi = k + 1 < WIDE_KINDS ? ws->kind_first[j->color][k + 1] : ws->color_first[j->color + 1];
    *from = lo > first ? lo : first;
    *to = hi < last ? hi : last;
    return *from < *to;
}

static void warm_range(int begin, int end, int worker, void *p)
{
    const wide_job *j = p;
    (void)worker;
    int first = j->offset + begin, last = j->offset + end, from, to;
    if (j->ws->free_only) {
        j->passes->warm[0](j->ws, j->ctx->bodies, j->ctx->friction, first, last);
        return;
    }
    for (int k = 0; k < WIDE_KINDS; k++)
        if (kind_span(j, k, first, last, &from, &to)) j->passes->warm[k](j->ws, j->ctx->bodies, j->ctx->friction, from, to);
}

static void solve_range(int begin, int end, int worker, void *p)
{
    const wide_job *j = p;
    (void)worker;
    int first = j->offset + begin, last = j->offset + end, from, to;
    if (j->ws->free_only) {
        j->passes->solve[0](j->ws, j->ctx, j->use_bias, j->hold_bounces, first, last);
        return;
    }
    for (int k = 0; k < WIDE_KINDS; k++)
        if (kind_span(j, k, first, last, &from, &to))
            j->passes->solve[k](j->ws, j->ctx, j->use_bias, j->hold_bounces, from, to);
}

/* Prepare reads the bodies and writes only its own batches: every batch at
 * once. The deepest overlap is taken over the batches in order afterwards. */
double wide_prepare(const wide_set *ws, contact_constraint *cc, const step_context *ctx)
{
    wide_job j = {ws, passes_for(ws), ctx, cc, 0, 0, 0, 0};
    tasks_run(ctx->tasks, ws->batch_count, WIDE_MIN_RANGE, prepare_range, &j);
    double deepest = 0.0;
    for (int k = 0; k < ws->batch_count; k++) deepest = dmax(deepest, ws->deepest[k]);
    return deepest;
}

/* Warm start and solve write the bodies: colour by colour (no two batches of
 * a colour share a moving body, so a colour's batches run in any order and
 * at once with the same result as one after another). */
void wide_warm_start(const wide_set *ws, const step_context *ctx)
{
    wide_job j = {ws, passes_for(ws), ctx, NULL, 0, 0, 0, 0};
    for (int c = 0; c < WIDE_COLORS; c++) {
        j.offset = ws->color_first[c];
        j.color = c;
        tasks_run(ctx->tasks, ws->color_first[c + 1] - j.offset, WIDE_MIN_RANGE, warm_range, &j);
    }
}

void wide_solve(const wide_set *ws, const step_context *ctx, int use_bias, int hold_bounces)
{
    wide_job j = {ws, passes_for(ws), ctx, NULL, 0, use_bias, hold_bounces, 0};
    for (int c = 0; c < WIDE_COLORS; c++) {
        j.offset = ws->color_first[c];
        j.color = c;
        tasks_run(ctx->tasks, ws->color_first[c + 1] - j.offset, WIDE_MIN_RANGE, solve_range, &j);
    }
}
#else
/* no vectors: no batches, every manifold is in the overflow */
double wide_prepare(const wide_set *ws, contact_constraint *cc, const step_context *ctx)
{
    (void)ws; (void)cc; (void)ctx;
    return 0.0;
}
void wide_warm_start(const wide_set *ws, const step_context *ctx) { (void)ws; (void)ctx; }
void wide_solve(const wide_set *ws, const step_context *ctx, int use_bias, int hold_bounces)
{
    (void)ws; (void)ctx; (void)use_bias; (void)hold_bounces;
}
#endif

int wide_overflow(const wide_set *ws, const int **list)
{
    *list = ws->overflow;
    return ws->overflow_count;
}

/* A batched constraint's impulses from whichever layout its batch has. */
#define READ_IMPULSES(PTS)                                                \
    for (int i = 0; i < c->count; i++) {                                  \
        const PTS *q = &(PTS##_array)[wb->first + i];                     \
        c->p[i].normal_impulse = q->normal_impulse[l];                    \
        c->p[i].tangent_impulse[0] = q->tangent_impulse[0][l];            \
        c->p[i].tangent_impulse[1] = q->tangent_impulse[1][l];            \
    }

void wide_read_impulses(const wide_set *ws, contact_constraint *c)
{
    const wide_batch *wb = &ws->batches[c->wide_batch];
    int l = c->wide_lane;
    if (wb->kind & WIDE_KIND_SPINLESS) {
        const wide_lpoint *wide_lpoint_array = ws->lpoints;
        READ_IMPULSES(wide_lpoint)
    } else if (wb->kind == WIDE_KIND_PLANAR) {
        const wide_ppoint *wide_ppoint_array = ws->ppoints;
        READ_IMPULSES(wide_ppoint)
    } else if (ws->compact) {
        const wide_cpoint *wide_cpoint_array = ws->cpoints;
        READ_IMPULSES(wide_cpoint)
    } else {
        const wide_point *wide_point_array = ws->points;
        READ_IMPULSES(wide_point)
    }
}

/* Batches per range of the store: a batch's store is some 20 scattered
 * writes, far less than a solve pass's work on it. */
#define WIDE_STORE_MIN_RANGE 128

/* One batch's points of either layout back to its constraints' points. */
#define STORE_POINTS(PTS)                                                                          \
    for (int l = 0; l < wb->lanes; l++) {                                                          \
        contact_constraint *c = &cc[wb->con[l]];                                                   \
        for (int i = 0; i < wb->count; i++) {                                                      \
            const PTS *q = &(PTS##_array)[wb->first + i];                                          \
            constraint_point *p = &c->p[i];                                                        \
            p->normal_impulse = q->normal_impulse[l];                                              \
            p->total_normal_impulse += q->total_normal_impulse[l]; /* plus any shock pass's */     \
            p->tangent_impulse[0] = q->tangent_impulse[0][l];                                      \
            p->tangent_impulse[1] = q->tangent_impulse[1][l];                                      \
        }                                                                                          \
    }

typedef struct store_job {
    const wide_set *ws;
    contact_constraint *cc;
} store_job;

/* Each batch writes only its own constraints' points: every batch at once. */
static void store_range(int begin, int end, int worker, void *p)
{
    const store_job *j = p;
    const wide_set *ws = j->ws;
    contact_constraint *cc = j->cc;
    const wide_point *wide_point_array = ws->points;
    const wide_cpoint *wide_cpoint_array = ws->cpoints;
    const wide_lpoint *wide_lpoint_array = ws->lpoints;
    const wide_ppoint *wide_ppoint_array = ws->ppoints;
    (void)worker;
    for (int k = begin; k < end; k++) {
        const wide_batch *wb = &ws->batches[k];
        if (wb->kind & WIDE_KIND_SPINLESS) {
            STORE_POINTS(wide_lpoint)
        } else if (wb->kind == WIDE_KIND_PLANAR) {
            STORE_POINTS(wide_ppoint)
        } else if (ws->compact) {
            STORE_POINTS(wide_cpoint)
        } else {
            STORE_POINTS(wide_point)
        }
    }
}

void wide_store(const wide_set *ws, contact_constraint *cc, const step_context *ctx)
{
    store_job j = {ws, cc};
    tasks_run(ctx->tasks, ws->batch_count, WIDE_STORE_MIN_RANGE, store_range, &j);
}
