/* solver.h - the solver stage of the step (solver.c): contact constraints
 * from the touching manifolds, solved over the sub-steps; bodies integrated. */
#ifndef CAROM_SOLVER_H
#define CAROM_SOLVER_H

#include "step.h"
#include "column_solve.h"

/* The solver's memory, kept between steps in the world's scratch. */
typedef struct solver_memory {
    void *block;                 /* constraints, their points, shock and contact lists (before them in
                                    the step: sort_touching's keys) */
    int block_capacity;
    void *anchors;               /* the scalar and shock passes' anchors (constraint_anchor) */
    int anchors_capacity;
    void *rows;                  /* the scalar passes' rows (constraint_rows) */
    int rows_capacity;
    void *springs;               /* the penalty model's springs (penalty_spring) */
    int springs_capacity;
    void *extra;                 /* locked and rolling manifolds' constraint_extra */
    int extra_capacity;
    void *wide;                  /* solver_wide.c's batches */
    size_t wide_capacity;
    int wide_env;                /* wide_read_env's switches (0: not read yet) */
    int *points;                 /* this step: each touching manifold's point count, in solve order */
    int points_capacity;
    unsigned char *hit;          /* this step: per constraint, 1 when it raises a hit event (store_impulses) */
    int hit_capacity;
    /* sort_touching's hint: last step's solve order (contact indices) and a
     * zeroed per-contact mark; only the work of the sort depends on them */
    int *last_order, *mark;
    int last_count, last_capacity, mark_capacity;
    void *motion;                /* per solver body: what its sub-steps read of it (body_step, solver.c) */
    int motion_capacity;
    void *motion_extra;          /* what only some bodies' sub-steps read (body_step_extra, solver.c) */
    int motion_extra_capacity;
    int bodies_capacity;         /* step_scratch.bodies' (gather_bodies) */
    int planar;                  /* this step: some awake body is locked to a plane */
    int rotation_locked;         /* this step: some awake body is rotation-locked (spinless manifolds may exist) */
    column_memory columns;       /* this step's columns solved directly (column_solve.c) */
} solver_memory;
void solver_memory_free(solver_memory *m);

/* Fills ctx's solver bodies and constraints, solves, writes the bodies back
 * and raises hit events. 0 on out of memory; -1 when the settings cannot be
 * integrated (the world's error says why; no body moved). */
int world_solve(carom_world *w, step_context *ctx);

#endif
