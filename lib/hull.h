/* hull.h - convex hulls (hull.c): polygon faces, unique edges, mass
 * properties; built from a point cloud. */
#ifndef CAROM_HULL_H
#define CAROM_HULL_H

#include "vecmath.h"

/* Limits of a hull (the narrowphase's polytope buffers are sized by them). */
#define HULL_MAX_VERTICES 256
#define HULL_MAX_FACES 256
#define HULL_MAX_FACE_VERTICES 1024

/* A hull face: a convex polygon, vertices counter-clockwise seen from outside. */
typedef struct hull_face {
    vec3 normal;        /* outward unit normal */
    double offset;      /* dot(normal, x) = offset on the face plane */
    int first;          /* index into hull.face_vertices */
    int count;          /* number of vertices of this face */
} hull_face;

typedef struct hull {
    int vertex_count;
    vec3 *vertices;        /* the hull's extreme points only */
    int face_count;
    hull_face *faces;      /* coplanar triangles merged into polygons */
    int *face_vertices;    /* indices into vertices, per face in order */
    int edge_count;
    int (*edges)[2];       /* unique edges as vertex index pairs (for SAT) */
    vec3 centroid;         /* volume centroid in the body frame */
    double volume;
    mat3 unit_inertia;     /* inertia about the centroid for density 1 */
    int shares;            /* owners besides the first (hull_share); hull_free frees the hull
                              only when it has none. A hull is never changed once built, so
                              bodies may share one (a restored snapshot's bodies share their
                              class's) */
} hull;

/* Builds a hull from points (xyz triples). Returns NULL and writes a message to
 * err when the points are degenerate (fewer than 4, coplanar, non-finite). */
hull *hull_build(const double *points, int count, char *err, int err_size);
hull *hull_make_box(vec3 half_extents);
/* Gives up one owner's hold: frees the hull when no other owner shares it. */
void hull_free(hull *h);
hull *hull_clone(const hull *h);
/* h, with one more owner (each owner calls hull_free once). */
hull *hull_share(hull *h);

#endif
