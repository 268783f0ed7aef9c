/* toi.h - continuous collision (toi.c): a fast or bullet body moved back to
 * its time of impact. */
#ifndef CAROM_TOI_H
#define CAROM_TOI_H

#include "step.h"
#include "shape.h"

int world_continuous(carom_world *w, const step_context *ctx); /* 0 on out of memory */

/* Farther than TOI_NEAR (1 cm) apart: 1, and a lower bound *d (at most range)
 * of the distance between shapes a and b, with the normal it holds along
 * (from a to b). Nearer, overlapping, or a pair it does not measure (planes,
 * level geometry against level geometry): 0, and continuous collision asks
 * the full contact collision instead. */
int toi_far_separation(const shape *a, xform xa, const shape *b, xform xb, double range, double *d, vec3 *normal);

#endif
