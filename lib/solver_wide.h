/* solver_wide.h - the wide passes: constraints coloured so that none in a
 * colour shares a moving body, packed four to a batch and solved four at a
 * time. The manifolds no colour takes (the overflow) are left to the scalar
 * passes (contact_solver.h), which the caller runs after each wide pass. */
#ifndef CAROM_SOLVER_WIDE_H
#define CAROM_SOLVER_WIDE_H

#include "constraint.h"

typedef struct wide_set wide_set;
/* The test switches the wide passes read from the environment, once per
 * world (wide_read_env): the SSE2 build over AVX2 (CAROM_NO_AVX2), a row
 * layout forced (CAROM_WIDE_COMPACT=0 or 1; tests compare them). */
enum { WIDE_ENV_READ = 1, WIDE_ENV_NO_AVX2 = 2, WIDE_ENV_FULL = 4, WIDE_ENV_COMPACT = 8 };
int wide_read_env(void);
/* Colours the constraints and lays out the batches in *mem (grown as
 * needed), setting each constraint's wide_batch and wide_lane (-1: scalar)
 * and filling the batch headers; manifolds with a plane-locked body
 * (locked) or with no body that can turn (spinless) get batches of their
 * own (kinds 0: the caller knows there are none); env: wide_read_env's;
 * tasks: the hooks the headers are filled through. NULL on out of memory. */
wide_set *wide_plan(void **mem, size_t *capacity, contact_constraint *cc, int ncon, int kinds, int nb, int env,
                    const carom_world_def *tasks);
/* The constraints left to the scalar passes, in order. */
int wide_overflow(const wide_set *ws, const int **list);
/* Prepares every batched manifold's points four lanes at a time, as
 * contact_prepare does one; their scalar points get what the shock pass,
 * restitution and the events read. Returns the deepest overlap. */
double wide_prepare(const wide_set *ws, contact_constraint *cc, const step_context *ctx);
void wide_warm_start(const wide_set *ws, const step_context *ctx);
/* use_bias: the solve pass, else relax; hold_bounces: see contact_solve. */
void wide_solve(const wide_set *ws, const step_context *ctx, int use_bias, int hold_bounces);
/* Copies a batched constraint's current impulses to its scalar points (the
 * shock pass reads them between wide passes). */
void wide_read_impulses(const wide_set *ws, contact_constraint *c);
/* Writes the batches' impulses back to the constraints' points (in ranges
 * of batches through the task hooks: a constraint is in one batch). */
void wide_store(const wide_set *ws, contact_constraint *cc, const step_context *ctx);

#endif
