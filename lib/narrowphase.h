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
    int feature;         /* last reference feature (box-box / hull SAT axis), -1 none */
    unsigned char has_normal; /* 0 or 1 (bytes: the cache is 32 bytes and a contact 128) */
    unsigned char flip;  /* last reference face belonged to B (0 or 1) */
} collide_cache;

/* Contacts between two convex shapes (sphere, box, capsule, cylinder, hull;
 * plane against those), a at xa and b at xb, including speculative points
 * whose separation is below `speculative` (>= 0). Any order of types works
 * (the normal always points from a to b). Returns m->count. Results are
 * always finite. Any pair at all: collide (compound.c). */
int collide_convex(const shape *a, xform xa, const shape *b, xform xb, double speculative,
                   collide_cache *cache, manifold *m);

/* Most manifolds a convex shape gets against one mesh or height field. */
#define COMPOSITE_MAX_MANIFOLDS 4

/* Most manifolds one pair gets (compound children, each against a mesh in
 * up to COMPOSITE_MAX_MANIFOLDS). */
#define PAIR_MAX_MANIFOLDS 64

#define POLY_MAX_V HULL_MAX_VERTICES
#define POLY_MAX_F HULL_MAX_FACES
#define POLY_MAX_FV HULL_MAX_FACE_VERTICES
#define CYL_SIDES 16

/* A convex polytope in world space (narrowphase.c builds them from shapes). */
typedef struct poly {
    int nv, nf, ne;
    vec3 v[POLY_MAX_V];
    vec3 fn[POLY_MAX_F];
    double fd[POLY_MAX_F];
    int ffirst[POLY_MAX_F], fcount[POLY_MAX_F];
    int fv[POLY_MAX_FV];
    int e[POLY_MAX_FV / 2][2];
    int ef[POLY_MAX_FV / 2][2];      /* the two faces beside each edge (Gauss-map arcs) */
    vec3 center;
} poly;

/* The polytope helpers, shared with the triangle contacts. */
int poly_from_shape(poly *p, const shape *s, xform x);   /* box, hull, cylinder (a prism); 0 otherwise */
void poly_finish(poly *p);                               /* centre and face offsets from v, fn, fv */
void poly_edge_faces(poly *p);                           /* ef from the faces */
/* Incident face of inc clipped against reference face rf of ref (see narrowphase.c). */
void poly_face_contact(const poly *ref, int rf, const poly *inc, const shape *inc_cyl, xform inc_x, int flip,
                       double spec, uint32_t tag, manifold *m);
void closest_segments(vec3 p1, vec3 q1, vec3 p2, vec3 q2, vec3 *c1, vec3 *c2);
void capsule_segment(const shape *s, xform x, vec3 *p0, vec3 *p1);

#endif
