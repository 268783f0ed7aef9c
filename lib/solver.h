/* solver.h - contact constraints shared by the impulse solver (solver.c) and
 * the penalty model (penalty.c). */
#ifndef CAROM_SOLVER_H
#define CAROM_SOLVER_H

#include "world.h"

typedef struct softness {
    double bias_rate, mass_scale, impulse_scale;
} softness;

/* Hot fields first, in the order the solve pass reads them: the normal row,
 * then the friction rows; what only preparation, restitution or the shock
 * and penalty paths read comes last. */
typedef struct constraint_point {
    double base_separation;
    double normal_mass, normal_impulse;
    double total_normal_impulse, max_normal_impulse;
    vec3 ra_n, rb_n;             /* ra x n, rb x n */
    vec3 ia_n, ib_n;             /* IA^-1 (ra x n), IB^-1 (rb x n) */
    double tangent_mass[2], tangent_impulse[2];
    vec3 ra_t[2], rb_t[2];       /* ra x t_k, rb x t_k (friction rows) */
    vec3 ia_t[2], ib_t[2];       /* IA^-1 (ra x t_k), IB^-1 (rb x t_k) */
    vec3 ra, rb;                 /* anchors from each centre (world, fixed over the step) */
    double relative_velocity;    /* normal velocity before solving (restitution) */
    double penalty_k, penalty_c; /* penalty model spring and damper */
    double shock_normal;         /* shock pass impulse: this pass only, never warm-started */
} constraint_point;

typedef struct contact_constraint {
    int a, b;                    /* solver bodies (0 = the shared static body) */
    int contact;                 /* index in the contact set */
    int count;
    int level;                   /* shock propagation: lower of the two body levels */
    vec3 n, t1, t2;
    double friction, restitution;
    softness soft;
    constraint_point *p;         /* count points in the step's packed point array */
    int wide_batch, wide_lane;   /* solver_wide.c's batch and lane, or -1: scalar passes */
    /* what preparing the points reads */
    const manifold *m;
    const contact_point_state *warm; /* last step's impulses, matched by feature */
    vec3 center_a, center_b;     /* centres of mass */
    double gravity_closing;      /* normal acceleration of b relative to a from gravity and forces */
} contact_constraint;

softness make_softness(double hertz, double damping_ratio, double h);

/* What one solve pass reads besides the constraints. */
typedef struct solve_context {
    impulse_body *bodies;
    vec3 *dp, *dq;               /* per solver body: motion since the step began */
    double inv_h;
    double push_max, slop, baumgarte;
    carom_position_correction correction;
    int friction;
    /* the step's last relax pass: speculative rows of manifolds with
     * restitution add no impulse (they would stop an approach that meets its
     * contact next step; the next step's impact phase meets it there) */
    int hold_bounces;
} solve_context;

/* The scalar pass over one manifold (solver.c): normal rows, then friction;
 * use_bias selects the solve pass over the relax pass. */
void solve_constraint(contact_constraint *c, const solve_context *sc, int use_bias);
/* Applies one manifold's accumulated impulses (warm start). */
void warm_start_constraint(contact_constraint *c, impulse_body *bodies);

/* Wide passes (solver_wide.c): constraints coloured so that none in a colour
 * shares a moving body, packed four to a batch. */
typedef struct wide_set wide_set;
/* Colours the constraints and lays out the batches in *mem (grown as
 * needed), setting each constraint's wide_batch and wide_lane (-1: scalar)
 * and filling the batch headers; NULL on out of memory. */
wide_set *wide_plan(void **mem, size_t *capacity, contact_constraint *cc, int ncon, int nb);
/* Prepares every wide manifold's points four lanes at a time, as solver.c
 * prepares a scalar one (warm: 1 to warm-start, 0 not); the scalar points
 * get what restitution and the events read. Returns the deepest overlap. */
double wide_prepare(wide_set *ws, contact_constraint *cc, const impulse_body *bodies, double warm);
void wide_warm_start(wide_set *ws, contact_constraint *cc, impulse_body *bodies);
void wide_solve(wide_set *ws, contact_constraint *cc, const solve_context *sc, int use_bias);
/* Copies a wide constraint's current impulses to its scalar points (the shock
 * pass reads them between wide passes). */
void wide_read_impulses(const wide_set *ws, contact_constraint *c);
/* Writes the batches' impulses back to the constraints' points. */
void wide_store(const wide_set *ws, contact_constraint *cc);

/* Coulomb's cone: scales the friction impulse (t1, t2) back to |t| <= limit. */
static inline void coulomb_clamp(double *t1, double *t2, double limit)
{
    double mag2 = *t1 * *t1 + *t2 * *t2;
    if (mag2 > limit * limit) {
        double f = limit / sqrt(mag2);
        *t1 *= f;
        *t2 *= f;
    }
}
/* Penalty springs: one sub-step of spring forces (penalty.c). */
void penalty_solve(carom_world *w, contact_constraint *cc, int n, double h);
/* (h^2 k + 2 h c) / (4 m): below 1 an explicit spring-damper is stable at sub-step h. */
double penalty_explicit_stability(double k, double c, double mass, double h);
/* 0 (with the world's error set) when an explicit spring cannot be integrated at h. */
int penalty_check(carom_world *w, const contact_constraint *cc, int n, double h);

#endif
