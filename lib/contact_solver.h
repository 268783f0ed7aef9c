/* contact_solver.h - the scalar passes over one manifold at a time: the
 * overflow path beside the wide batches (solver_wide.h), with the same
 * verbs. They read the step context and the solver bodies, never the world. */
#ifndef CAROM_CONTACT_SOLVER_H
#define CAROM_CONTACT_SOLVER_H

#include "constraint.h"

/* A manifold's normal rows solved as one block (contact_solver.c): built
 * once a step for an unlocked manifold of 2-4 points, one per constraint
 * in the step's block (step_context.blocks, indexed as the constraints). */
typedef struct contact_block {
    double K[4][4];              /* J M^-1 J^T of the normal rows */
    double inv[2][4][4];         /* LDL^T of K + E (every row rigid) and K + C + E (every row soft), once made */
    double shock_K[4][4], shock_inv[4][4]; /* the shock pass's, built at its first call */
    int ready;                   /* 0: sweep the rows one by one */
    int factored[2];             /* inv[k]: 1 made, -1 failed, 0 not yet */
    int shock_ready;
    int stiff;                   /* springs past a quarter of the sub-step rate: swept again (contact_solve_normals) */
    int column;                  /* in a column solved directly (column_solve.c; set before prepare) */
    int heavy_column;            /* that column holds a heavy-on-light manifold: COLUMN_HEAVY, or
                                    COLUMN_VERY_HEAVY (column_solve.h); 0 otherwise */
    int column_done;             /* this pass's normal rows already solved by its column */
    int friction_first;          /* every point warm-started pressed and sticking: friction rows first (solve_manifold) */
} contact_block;

/* The soft rows' compliance factor gamma: c_i = gamma K_ii (0: rigid rows). */
static inline double contact_block_gamma(const contact_constraint *c, const step_context *ctx)
{
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    return soft && c->soft.mass_scale > 0.0 ? c->soft.impulse_scale / c->soft.mass_scale : 0.0;
}

/* Anchors, rows, effective masses, warm impulses and the approach velocity
 * of one manifold's points; returns its deepest overlap. */
double contact_prepare(contact_constraint *c, const step_context *ctx);
/* Applies the manifold's accumulated impulses. */
void contact_warm_start(contact_constraint *c, impulse_body *bodies);
/* Normal rows, then friction; use_bias selects the solve pass (position
 * error fed back) over the relax pass (velocity only). hold_bounces (the
 * step's last relax pass, with the impact phase on): speculative rows of
 * manifolds with restitution add no impulse; they would stop an approach
 * that meets its contact next step, where the impact phase meets it. */
void contact_solve(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces);
/* The normal rows alone of a block-solved manifold, solved again: the
 * extra sweeps over the stiff manifolds (contact_block.stiff) after a pass. */
void contact_solve_normals(contact_constraint *c, const step_context *ctx, int use_bias);
/* Shock propagation's pass: the lower body (lower_is_a: a) held immovable. */
void contact_solve_shock(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces, int lower_is_a);

#endif
