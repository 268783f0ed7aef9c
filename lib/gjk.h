/* gjk.h - closest points between two convex shapes (GJK distance) and the
 * first time of impact of one swept along a translation (conservative
 * advancement on that distance). Used by the world queries: shape casts,
 * exact overlaps, closest distances. Shapes with a radius (sphere, capsule)
 * run GJK on their core (point, segment) and add the radius afterwards, which
 * is exact and converges in a few iterations. */
#ifndef CAROM_GJK_H
#define CAROM_GJK_H

#include "shape.h"

/* A convex shape placed in a frame local to the query (the caller subtracts a
 * reference point from every position first, so far from the world origin
 * no precision is lost to large coordinates). */
typedef struct gjk_proxy {
    const shape *s;      /* a convex shape (not a plane, mesh or height field), or NULL: */
    const vec3 *points;  /* the convex hull of these (a mesh's triangle), in the frame x */
    int point_count;
    xform x;
} gjk_proxy;

typedef struct gjk_result {
    double distance;     /* between the surfaces; 0 when they overlap */
    vec3 point_a, point_b; /* closest points (query frame); equal-ish when overlapping */
    vec3 normal;         /* unit, from A towards B (zero when overlapping) */
    double lower_bound;  /* proven: the surfaces are at least this far apart, */
    vec3 lower_normal;   /* by the plane of this normal (A towards B); equal to
                            distance and normal once converged (curved pairs,
                            e.g. cylinders, converge slowly: ~1e-6 relative) */
    int overlap;         /* 1: the shapes intersect (touching within tolerance counts) */
    int iterations;
} gjk_result;

/* Radius a proxy adds around its GJK core (sphere, capsule; 0 otherwise). */
double gjk_core_radius(const gjk_proxy *p);
/* Support point of the core of p's shape in the query frame. */
vec3 gjk_core_support(const gjk_proxy *p, vec3 dir);

/* Closest points of A and B (neither a plane). */
gjk_result gjk_distance(const gjk_proxy *a, const gjk_proxy *b);

typedef struct gjk_cast_result {
    int hit;
    double fraction;     /* of the translation, 0..1; 0 when they overlap at the start */
    vec3 point;          /* on B's surface at the time of impact (query frame) */
    vec3 normal;         /* B's surface normal there, against the cast; -unit(translation)
                            when they overlap at the start */
} gjk_cast_result;

/* First contact of A moved by translation (A's pose + t translation, t in
 * [0, 1]) with B. */
gjk_cast_result gjk_shape_cast(const gjk_proxy *a, vec3 translation, const gjk_proxy *b);

#endif
