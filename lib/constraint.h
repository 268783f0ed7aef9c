/* constraint.h - a contact constraint (one touching manifold) and its points,
 * as every pass reads them, and the formulas the passes share: written once
 * here for the scalar passes (contact_solver.c, one manifold a call), the
 * wide passes (solver_wide.c, four a call), the shock pass and the penalty
 * springs. */
#ifndef CAROM_CONSTRAINT_H
#define CAROM_CONSTRAINT_H

#include "contact.h"
#include "step.h"

/* A point as every manifold has it: what the stages after the passes read
 * (impacts, impulse storage, hit and force events): normal_impulse,
 * tangent_impulse, total_normal_impulse, relative_velocity. It is the
 * contact's own point state (contact.h): the impulses a step starts from
 * are last step's (warm), which prepare reads before it writes them. Its
 * anchors are in constraint_anchor, the rows the scalar passes solve in
 * constraint_rows; a wide-solved manifold's anchors and rows live only in
 * its batch's lanes (solver_wide.c), and its anchors also here when the
 * shock pass runs. */
typedef contact_point_state constraint_point;

/* A point's separation and anchors: the scalar passes' and the shock pass's. */
typedef struct constraint_anchor {
    double base_separation;
    vec3 ra, rb;                 /* anchors from each centre (world, fixed over the step) */
} constraint_anchor;

/* A scalar-solved point's rows (contact_solver.c, penalty.c), hot fields
 * first in the order the solve pass reads them: the normal row, then the
 * friction rows. */
typedef struct constraint_rows {
    double normal_mass;
    vec3 ra_n, rb_n;             /* ra x n, rb x n */
    vec3 ia_n, ib_n;             /* IA^-1 (ra x n), IB^-1 (rb x n) */
    double tangent_mass[2];
    vec3 ra_t[2], rb_t[2];       /* ra x t_k, rb x t_k (friction rows) */
    vec3 ia_t[2], ib_t[2];       /* IA^-1 (ra x t_k), IB^-1 (rb x t_k) */
} constraint_rows;

/* The penalty model's spring and damper of a point (penalty.c only). */
typedef struct penalty_spring {
    double k, c;
} penalty_spring;

/* What only plane-locked or rolling manifolds need (the rest have none). */
typedef struct constraint_extra {
    /* plane-locked bodies (lock_to_plane): the plane normals, zero for a free body */
    vec3 lock_a, lock_b;
    /* rolling resistance (material.c): an angular row per tangent axis,
     * capped at rolling * rolling_radius * normal impulse */
    double rolling_radius;
    double rolling_mass[2], rolling_impulse[2];
} constraint_extra;

typedef struct contact_constraint {
    int a, b;                    /* solver bodies (0 = the shared static body) */
    int contact;                 /* index in the contact set */
    int count;
    int level;                   /* shock propagation: lower of the two body levels */
    int wide_batch, wide_lane;   /* solver_wide.c's batch and lane, or -1: scalar passes */
    /* plane-locked bodies (1: a, 2: b): every pass keeps the locked bodies'
     * velocities in their planes after each row (the wide ones in batches of
     * their own) */
    int locked;
    int spinless;                /* neither body can turn (static or rotation-locked): no angular terms */
    int keep_scalar;             /* in a heavy column (column_solve.c): the scalar passes take it */
    vec3 n, t1, t2;
    double friction, restitution;
    double rolling;              /* rolling resistance (0: no rolling rows, the manifold may go wide) */
    softness soft;
    constraint_point *p;         /* its count points: the contact's point states, holding last step's
                                    impulses (matched by feature) until prepare scales them in place */
    constraint_anchor *an;       /* their anchors: scalar passes, and every manifold when the shock pass runs; else NULL */
    constraint_rows *r;          /* their rows: scalar passes only (NULL for a wide-solved manifold) */
    penalty_spring *spring;      /* their springs: penalty model only, else NULL */
    constraint_extra *x;         /* locked or rolling manifolds only, else NULL */
    /* what preparing the points reads */
    const manifold *m;
    vec3 center_a, center_b;     /* centres of mass */
    double gravity_closing;      /* normal acceleration of b relative to a from gravity and forces */
} contact_constraint;

/* The plane normals of a manifold's bodies (zero for a free body). */
static inline vec3 constraint_lock_a(const contact_constraint *c) { return c->x ? c->x->lock_a : v3_zero(); }
static inline vec3 constraint_lock_b(const contact_constraint *c) { return c->x ? c->x->lock_b : v3_zero(); }

/* ---- the shared formulas ------------------------------------------------ */

/* Push-out bias of a penetrating row (separation s <= 0; a speculative row,
 * s > 0, takes CONTACT_SPECULATIVE_BIAS instead). `soft` selects the soft
 * spring's rate over Baumgarte's beta / h; both act on the overlap past the
 * slop only (linear_slop means the same in every mode) and are capped at
 * the push-out speed (neg_push = -push_max). Written over any number type:
 * the scalar passes give dmax/dmin, the wide passes the lanes' max/min. */
#define CONTACT_PUSH_BIAS(soft, s, bias_rate, baumgarte_rate, slop, neg_push, zero, MAX, MIN) \
    ((soft) ? MAX((bias_rate) * MIN((s) + (slop), (zero)), (neg_push))                       \
            : MAX((baumgarte_rate) * MIN((s) + (slop), (zero)), (neg_push)))
/* A speculative row (s > 0) arrives exactly at contact within the sub-step. */
#define CONTACT_SPECULATIVE_BIAS(s, inv_h) ((s) * (inv_h))

/* The normal velocity restitution answers: a gap that closes under gravity
 * (gravity_closing < 0) before the impact arrives faster than it started,
 * v^2 = v0^2 + 2 |a| gap. */
static inline double contact_approach_velocity(double vn, double gravity_closing, double separation)
{
    if (vn < 0.0 && separation > 0.0 && gravity_closing < 0.0)
        return -sqrt(vn * vn - 2.0 * gravity_closing * separation);
    return vn;
}

/* A body's share 1/m of the inverse effective mass along unit direction d,
 * when the body moves only in the plane with unit normal l (l = 0: free):
 * its linear response to an impulse along d is (1/m)(d - (d.l) l). */
static inline double locked_inv_mass(double inv_mass, vec3 d, vec3 l)
{
    double dl = v3_dot(d, l);
    return inv_mass * (1.0 - dl * dl);
}

/* A row the locks leave with under ROW_BLOCKED_SHARE of the bodies' free 1/m
 * (the sum of their unlocked inverse masses) is blocked and gets no impulse:
 * its 1/k would be over 1e6 times the free response (RANGE_IMPULSE_MAX's
 * margin), from a lock normal within 0.06 deg of the row. A contact normal
 * along a locked direction leaves only rounding, about 1e-32 of the free 1/m,
 * and 1/k of that stored a warm-start impulse of 1.2e33 N s that no snapshot
 * could restore. Without locks k >= the free 1/m: no row is blocked. */
#define ROW_BLOCKED_SHARE 1e-6
static inline double row_mass(double k, double free_inv_mass)
{
    return k > ROW_BLOCKED_SHARE * free_inv_mass ? 1.0 / k : 0.0;
}

/* A plane-locked body's velocity kept in its plane (l = 0: unchanged). */
static inline vec3 keep_in_plane(vec3 v, vec3 l) { return v3_madd(v, -v3_dot(v, l), l); }

/* Coulomb's cone: the factor that scales a friction impulse of squared
 * length mag2 back to |t| <= limit (1 inside the cone). */
static inline double coulomb_factor(double mag2, double limit)
{
    return mag2 > limit * limit ? limit / sqrt(mag2) : 1.0;
}

/* A friction point over the cone: (t1, t2) holds the trial o - M v (last
 * impulse o, slip v, the rows' own masses M = diag(m1, m2)), to be scaled
 * back to the cone. Where the point slides, Coulomb's friction is mu N
 * against the slip, but the trial points against M v, not v, wherever
 * m1 != m2 (a spinning box's corners in a basis turned from its edges: its
 * torsional friction came out 1.4 % short). Where the slip is far beyond
 * what any impulse inside the cone could stop, m |v| > 10 (2 limit) with m
 * the smaller row mass, the point slides for certain: then the trial
 * o - m v, with one mass for both rows, settles exactly against the slip.
 * Nearer sticking the rows' own trial is kept: one mass there let a stack of
 * five sway 0.2 m at dt 1/15 (0.04 m with the rows' own; 0.08 m with the
 * switch at 2 limit, 0.04 m at 10 and above). */
static inline void coulomb_over_cone(double *t1, double *t2, double o1, double o2, double v1, double v2, double m1,
                                     double m2, double limit)
{
    double m = m1 < m2 ? m1 : m2;
    if (m * m * (v1 * v1 + v2 * v2) > 400.0 * limit * limit) {
        *t1 = o1 - m * v1;
        *t2 = o2 - m * v2;
    }
    double f = coulomb_factor(*t1 * *t1 + *t2 * *t2, limit);
    *t1 *= f;
    *t2 *= f;
}

/* Coulomb's cone on (t1, t2). */
static inline void coulomb_clamp(double *t1, double *t2, double limit)
{
    double f = coulomb_factor(*t1 * *t1 + *t2 * *t2, limit);
    *t1 *= f;
    *t2 *= f;
}

#endif
