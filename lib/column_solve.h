/* column_solve.h - the normal rows of a column of stacked manifolds (each
 * body between two of them touches nothing else) solved together, directly:
 * a block-tridiagonal LDL^T of their 4-row blocks (column_solve.c). */
#ifndef CAROM_COLUMN_SOLVE_H
#define CAROM_COLUMN_SOLVE_H

#include "constraint.h"

/* One manifold of a column, in the column's order. */
typedef struct column_link {
    double B[4][4];              /* its rows' coupling to the next manifold's (through the shared body) */
    double S[2][4][4];           /* LDL^T of the Schur complement, [1] soft rows, [0] rigid rows */
    double SiB[2][4][4];         /* S^-1 B */
    double z[4], acc[4];         /* a pass's substitution and the rows' totals before it */
    double ek[2][4];             /* the rows' compliance e K_ii per kind */
    contact_constraint *c;       /* this step's constraint con */
    int con;                     /* constraint index */
    int shared;                  /* solver body shared with the next manifold (last: -1) */
    /* the column's, in its first link: factored[kind] 0 not yet, 1 made, -1
     * failed; every manifold has a block; some has restitution */
    int factored[2], valid, bouncy;
} column_link;

/* The step's columns; kept between steps for its memory only. */
typedef struct column_memory {
    void *links;                 /* column_link */
    int links_capacity;
    void *start;                 /* int: column k is links start[k] .. start[k + 1] - 1 */
    int start_capacity;
    void *scratch;               /* int, per body and per constraint, while the columns are found */
    int scratch_capacity;
    int count;
} column_memory;

void column_memory_free(column_memory *m);

/* Two bodies whose masses differ by this factor or more are a heavy body on
 * a light one (solver.c's shock pass takes such pairs). */
#define SHOCK_MASS_RATIO 4.0
/* A column of at least COLUMN_MIN_HEAVY manifolds with a heavy-on-light
 * one is solved directly whatever its sag, and the shock pass leaves it
 * alone (contact_block.heavy_column: COLUMN_HEAVY; COLUMN_VERY_HEAVY where
 * some pair's masses differ by COLUMN_VERY_HEAVY_RATIO or more). */
#define COLUMN_MIN_HEAVY 3
#define COLUMN_VERY_HEAVY_RATIO 50.0
enum { COLUMN_HEAVY = 1, COLUMN_VERY_HEAVY = 2 };

/* Finds the step's columns among the manifolds the scalar passes take
 * (scalar: their indices, NULL for all) and marks their blocks
 * (contact_block.column, heavy_column) before contact_prepare reads the
 * marks; heavy_on_light: some manifold of the step is heavy-on-light. 0 on
 * out of memory. */
int column_find(column_memory *m, const step_context *ctx, const int *scalar, int scalar_count, int heavy_on_light);
/* Before the wide passes are planned, in a step with a heavy-on-light
 * manifold: marks the manifolds of every heavy column among all of them
 * (contact_constraint.keep_scalar), so that the scalar passes take them and
 * column_find finds them again; the blocks' marks are cleared after. 0 on
 * out of memory. */
int column_keep_heavy_scalar(column_memory *m, const step_context *ctx);
/* After contact_prepare: the couplings; a column with a manifold that has
 * no block is left to the manifolds' own solves. Returns how many stiff
 * manifolds (contact_block.stiff) the columns hold. */
int column_prepare(column_memory *m, const step_context *ctx);
/* Solves every column's normal rows (before the pass's manifold solves,
 * which then skip them: contact_block.column_done); a column whose rows mix
 * soft and rigid, or whose solution pulls, is left to them this pass.
 * Returns how many stiff manifolds were left so. */
int column_solve_pass(column_memory *m, const step_context *ctx, int use_bias, int hold_bounces);
/* The columns' manifolds, every column in turn: how many, and the
 * constraint index of the i-th. */
int column_manifold_count(const column_memory *m);
int column_manifold(const column_memory *m, int i);

#endif
