/* contact_solver.h - the scalar passes over one manifold at a time: the
 * overflow path beside the wide batches (solver_wide.h), with the same
 * verbs. They read the step context and the solver bodies, never the world. */
#ifndef CAROM_CONTACT_SOLVER_H
#define CAROM_CONTACT_SOLVER_H

#include "constraint.h"

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
/* Shock propagation's pass: the lower body (lower_is_a: a) held immovable. */
void contact_solve_shock(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces, int lower_is_a);

#endif
