/* triangle_contact.h - contacts of convex shapes against triangles, and so
 * against meshes and height fields (triangle_contact.c). */
#ifndef CAROM_TRIANGLE_CONTACT_H
#define CAROM_TRIANGLE_CONTACT_H

#include "narrowphase.h"

/* A mesh or height field (either of a, b) against a convex shape: the
 * triangles' contacts grouped by normal into up to `max` manifolds (normal
 * from a to b), written to out; returns how many. */
int collide_composite(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *out, int max);
/* One triangle (world vertices, counter-clockwise seen from the front) against
 * a convex shape; active: bit k set when edge v[k] -> v[k+1] is active (see
 * mesh.h). The normal points from the triangle to the shape. */
int collide_triangle(const vec3 v[3], unsigned active, int two_sided, const shape *s, xform xs, double speculative,
                     manifold *m);

/* Keeps only the corners of the points' outline seen along normal (at most
 * 64 points; collinear and inner points dropped, order along the outline);
 * returns the new count. */
int manifold_outline(manifold_point *pts, int n, vec3 normal);
/* manifold_reduce for an outline's corners: the fourth point is the one
 * that adds the most area outside the first three's triangle. */
int manifold_reduce_outline(manifold_point *pts, int n, vec3 normal);

#endif
