/* query.h - the exact shape tests the world queries use, for the other
 * stages that need one (sensors). */
#ifndef CAROM_QUERY_H
#define CAROM_QUERY_H

#include "shape.h"

/* 1 when the shapes at these poses overlap or touch (not both planes or
 * triangle sets: then 0). */
int query_shapes_overlap(const shape *a, xform xa, const shape *b, xform xb);

#endif
