/* manifold.h - helpers for building manifolds (clipping, reduction). */
#ifndef CAROM_MANIFOLD_H
#define CAROM_MANIFOLD_H

#include "narrowphase.h"

#define CLIP_MAX 64
#define POLY_MAX_V HULL_MAX_VERTICES
#define POLY_MAX_F HULL_MAX_FACES
#define POLY_MAX_FV HULL_MAX_FACE_VERTICES
#define CYL_SIDES 16

/* Reduces up to n candidate points to at most 4 (deepest first, then the
 * largest area), in place; returns the new count. */
int manifold_reduce(manifold_point *pts, int n, vec3 normal);

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

typedef struct clip_vertex {
    vec3 p;
    uint32_t id;     /* low 8 bits: incident vertex; bit 7: made by clipping; >> 8: clip plane tag */
} clip_vertex;

/* Clips polygon in[0..n) to dot(plane_n, p) <= plane_d; out needs n + 1 slots. */
int clip_polygon(const clip_vertex *in, int n, vec3 plane_n, double plane_d, uint32_t edge_tag, clip_vertex *out);

/* Keeps only the corners of the points' outline seen along normal (at most
 * 64 points; collinear and inner points dropped, order along the outline);
 * returns the new count. triangle_contact.c. */
int manifold_outline(manifold_point *pts, int n, vec3 normal);

/* narrowphase.c's polytope helpers, shared with the triangle contacts. */
int poly_from_shape(poly *p, const shape *s, xform x);   /* box, hull, cylinder (a prism); 0 otherwise */
void poly_finish(poly *p);                               /* centre and face offsets from v, fn, fv */
void poly_edge_faces(poly *p);                           /* ef from the faces */
/* Incident face of inc clipped against reference face rf of ref (see narrowphase.c). */
void poly_face_contact(const poly *ref, int rf, const poly *inc, const shape *inc_cyl, xform inc_x, int flip,
                       double spec, uint32_t tag, manifold *m);
void closest_segments(vec3 p1, vec3 q1, vec3 p2, vec3 q2, vec3 *c1, vec3 *c2);
void capsule_segment(const shape *s, xform x, vec3 *p0, vec3 *p1);

#endif
