/* query.h - the exact shape tests the world queries use, for the other
 * stages that need one (sensors). */
#ifndef CAROM_QUERY_H
#define CAROM_QUERY_H

#include "shape.h"

/* 1 when the shapes at these poses overlap or touch (not both planes or
 * triangle sets: then 0). */
int query_shapes_overlap(const shape *a, xform xa, const shape *b, xform xb);
/* The triangle of mesh or height field s at x (its index as a ray cast
 * names it) nearest the world point p among those within reach of it along
 * each axis; the lower index on a tie; -1 when none is, or s is another shape. */
int query_triangle_near(const shape *s, xform x, vec3 p, double reach);

#endif
