/* collide_analytic.h - closed-form contact manifolds for the pairs of round
 * shapes, boxes and planes (box-box, hulls and cylinders live elsewhere).
 *
 * Every function has the collide() contract of narrowphase.h for exactly the
 * listed type order (the dispatcher swaps the shapes and flips the normal for
 * the other order; a plane is always b): the normal is unit and points from a
 * to b, points are world points midway between the two surfaces, separation is
 * < 0 when overlapping, only points with separation < speculative are kept,
 * and results are always finite (coincident centres give a fixed axis). The
 * normal is set even when no point is returned. Returns m->count.
 *
 * Feature ids (stable while the same features touch):
 *   single closest-point contacts: 0
 *   sphere_plane: 0; capsule_plane: 0 = the -z end, 1 = the +z end
 *   box_plane: the corner index, bit 0/1/2 set for the +x/+y/+z corner
 *   capsule_capsule, parallel: 1 = the low end of the overlap, 2 = the high end
 *   capsule_box: box face f (0..5 = -x,+x,-y,+y,-z,+z) with slot e (0 the low
 *     end of the segment clipped to the face, 1 the high end, 2 the segment's
 *     closest point when it lies beside the face): 1 + 3 f + e; box edge along
 *     axis k with corner sign bits c (the other two axes, lower axis first):
 *     32 + 4 k + c */
#ifndef CAROM_COLLIDE_ANALYTIC_H
#define CAROM_COLLIDE_ANALYTIC_H

#include "narrowphase.h"

int collide_sphere_sphere(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_sphere_plane(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_sphere_box(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_sphere_capsule(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_capsule_capsule(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_capsule_plane(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_capsule_box(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);
int collide_box_plane(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m);

/* Closest points of segments p1q1 and p2q2: returns the squared distance and
 * the parameters (0..1) of the closest points p1 + s (q1 - p1), p2 + t (q2 - p2).
 * Degenerate (zero-length) segments are points; parallel ones give one of the
 * closest pairs. */
double segment_segment_closest(vec3 p1, vec3 q1, vec3 p2, vec3 q2, double *s, double *t);

#endif
