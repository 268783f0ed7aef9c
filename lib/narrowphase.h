/* narrowphase.h - contact manifolds for a pair of shapes: analytic pairs,
 * box-box by separating axes and face clipping, libccd for hulls and
 * cylinders. At most 4 points per manifold. */
#ifndef CAROM_NARROWPHASE_H
#define CAROM_NARROWPHASE_H

#include <stdint.h>
#include "shape.h"

#define MANIFOLD_MAX_POINTS 4

typedef struct manifold_point {
    vec3 point;          /* world point, midway between the two surfaces */
    double separation;   /* signed gap along the normal: < 0 overlapping */
    uint32_t id;         /* feature id: unchanged while the same features touch */
} manifold_point;

typedef struct manifold {
    vec3 normal;         /* unit, world frame, pointing from shape A to shape B */
    int count;           /* 0 .. MANIFOLD_MAX_POINTS */
    manifold_point points[MANIFOLD_MAX_POINTS];
} manifold;

/* Per-pair memory kept by the contact cache between steps. Zero it for a new pair. */
typedef struct collide_cache {
    vec3 normal;         /* last normal (A to B), valid when has_normal */
    int has_normal;
    int feature;         /* last reference feature (box-box / hull SAT axis), -1 none */
    int flip;            /* last reference face belonged to B */
} collide_cache;

/* Contacts between shape a at xa and shape b at xb, including speculative
 * points whose separation is below `speculative` (>= 0). Any order of types
 * works (the normal always points from a to b). Returns m->count. Results are
 * always finite. A mesh or height field gives its deepest manifold only (the
 * contact stage asks collide_composite for all of them). */
int collide(const shape *a, xform xa, const shape *b, xform xb, double speculative,
            collide_cache *cache, manifold *m);

/* Most manifolds a convex shape gets against one mesh or height field. */
#define COMPOSITE_MAX_MANIFOLDS 4

/* A mesh or height field (either of a, b) against a convex shape: the
 * triangles' contacts grouped by normal into up to `max` manifolds (normal
 * from a to b), written to out; returns how many. triangle_contact.c. */
int collide_composite(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *out, int max);
/* One triangle (world vertices, counter-clockwise seen from the front) against
 * a convex shape; active: bit k set when edge v[k] -> v[k+1] is active (see
 * mesh.h). The normal points from the triangle to the shape. */
int collide_triangle(const vec3 v[3], unsigned active, int two_sided, const shape *s, xform xs, double speculative,
                     manifold *m);

/* Most manifolds one pair gets (compound children, each against a mesh in
 * up to COMPOSITE_MAX_MANIFOLDS). */
#define PAIR_MAX_MANIFOLDS 64
/* Any pair with a mesh, height field or compound on either side: its
 * manifolds (normal a to b) and for each the base of its contact numbers
 * (a multiple of COMPOSITE_MAX_MANIFOLDS naming the child pair); returns how
 * many. compound.c. */
int collide_multi(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *out,
                  uint32_t *base, int max);
/* The compound children a contact number `sub` of the pair belongs to (-1: not a compound). */
void compound_sub_children(const shape *a, const shape *b, uint32_t sub, int *child_a, int *child_b);

#endif
