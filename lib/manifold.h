/* manifold.h - helpers for building manifolds (clipping, reduction). */
#ifndef CAROM_MANIFOLD_H
#define CAROM_MANIFOLD_H

#include "narrowphase.h"

#define CLIP_MAX 64

/* Reduces up to n candidate points to at most 4 (deepest first, then the
 * largest area), in place; returns the new count. */
int manifold_reduce(manifold_point *pts, int n, vec3 normal);

typedef struct clip_vertex {
    vec3 p;
    uint32_t id;     /* low 8 bits: incident vertex; bit 7: made by clipping; >> 8: clip plane tag */
} clip_vertex;

/* Clips polygon in[0..n) to dot(plane_n, p) <= plane_d; out needs n + 1 slots. */
int clip_polygon(const clip_vertex *in, int n, vec3 plane_n, double plane_d, uint32_t edge_tag, clip_vertex *out);

#endif
