/* mesh.h - level geometry: triangle meshes (own bounding-volume tree) and
 * height fields (a grid of heights, no triangle list). Both hand out
 * triangles overlapping a box, each with flags saying which of its edges are
 * active: an edge shared with a neighbour at (nearly) the same slope, or
 * folded concavely, is inactive, and contacts found on it are turned to the
 * triangle's face normal (internal edges do not catch). */
#ifndef CAROM_MESH_H
#define CAROM_MESH_H

#include <stdint.h>
#include "vecmath.h"

/* An edge is active when its two triangles' normals differ by more than this
 * angle (cosine) and it is convex seen from the front (or the mesh is two-sided). */
#define MESH_ACTIVE_EDGE_COS 0.99619469809174555 /* cos(5 degrees) */

typedef struct mesh_node {
    aabb box;
    int first;       /* leaf: first triangle (in tree order); inner: left child (right = first + 1) */
    int count;       /* leaf: triangle count; inner: 0 */
} mesh_node;

typedef struct tri_mesh {
    int vertex_count, triangle_count;  /* triangle_count: non-degenerate triangles kept */
    vec3 *vertices;
    int (*triangles)[3];               /* in tree order */
    int *source_index;                 /* tree order -> index in the caller's triangle list */
    uint8_t *active;                   /* per triangle: bit k = edge v[k] -> v[k+1] active */
    int node_count;
    mesh_node *nodes;                  /* node 0 is the root */
    int two_sided;
} tri_mesh;

typedef struct height_field {
    int rows, columns;                 /* grid points along y, along x */
    double cell_x, cell_y;
    double *heights;                   /* rows * columns, row 0 at the lowest y */
    uint8_t *hole;                     /* (rows - 1) * (columns - 1) cells, 1 = hole */
    double min_height, max_height;
} height_field;

/* Called for each triangle overlapping the query box (vertices in the shape's
 * frame, counter-clockwise seen from the front); index identifies it for
 * feature ids and ray hits. Return 0 to stop. */
typedef int tri_visit_fn(void *ctx, const vec3 v[3], unsigned active_edges, uint32_t index);

/* 1 if the input is a valid mesh (vertices finite within 1e6 m, indices in
 * range, no triangle repeating a vertex), else 0 with err saying which field
 * is wrong. Zero-area triangles are valid here (mesh_build drops them). */
int mesh_check(const double *vertices, int vertex_count, const int *triangles, int triangle_count, char *err,
               int err_size);
/* Copies and validates the input (mesh_check; err says which field is wrong); drops
 * zero-area triangles; builds the tree by the surface-area heuristic. */
tri_mesh *mesh_build(const double *vertices, int vertex_count, const int *triangles, int triangle_count,
                     int two_sided, char *err, int err_size);
void mesh_free(tri_mesh *m);
aabb mesh_bounds(const tri_mesh *m);
void mesh_query(const tri_mesh *m, aabb box, tri_visit_fn *visit, void *ctx);
/* Nearest front-face hit (both faces when two-sided) of o + t d, t in [0, max_t]. */
int mesh_ray_cast(const tri_mesh *m, vec3 o, vec3 d, double max_t, double *t, vec3 *normal, uint32_t *index);

/* Whether the edge p -> q of a triangle with unit normal n is active, given
 * the opposite vertex w of the neighbour across it. */
int mesh_edge_active(vec3 n, vec3 p, vec3 q, vec3 w, int two_sided);
/* Ray against one triangle: 1 and t when o + t d crosses it within [0, max_t]
 * from the front (either side when two_sided). */
int ray_triangle(vec3 o, vec3 d, const vec3 v[3], int two_sided, double max_t, double *t);

#endif
