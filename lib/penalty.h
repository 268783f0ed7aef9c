/* penalty.h - the penalty contact model (penalty.c). */
#ifndef CAROM_PENALTY_H
#define CAROM_PENALTY_H

#include "constraint.h"

/* The spring and damper *sp of point p (its rows' normal_mass set), and its
 * starting impulses: an explicit spring starts from none, an implicit one
 * from the last step's (warm start). */
void penalty_prepare_point(constraint_point *p, const constraint_rows *r, penalty_spring *sp, const step_context *ctx);
/* One sub-step of spring (and damper) impulses over ctx's constraints. */
void penalty_solve(const step_context *ctx);
/* (h^2 k + 2 h c) / (4 m): below 1 an explicit spring-damper is stable at sub-step h. */
double penalty_explicit_stability(double k, double c, double mass, double h);
/* 0, with why in msg, when an explicit spring of ctx's constraints cannot be
 * integrated at the sub-step. */
int penalty_check(const step_context *ctx, char *msg, size_t msg_size);

#endif
