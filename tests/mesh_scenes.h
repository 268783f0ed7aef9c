/* mesh_scenes.h - level geometry for the mesh tests and the bench: flat and
 * inclined triangle grids, height fields, floors of separate tiles. */
#ifndef CAROM_MESH_SCENES_H
#define CAROM_MESH_SCENES_H

#include <stdlib.h>
#include "carom/carom.h"

/* A flat n x n grid of cells of size `cell` centred on the origin at height
 * z, two triangles per cell; `flip_seed` != 0 picks each cell's diagonal at
 * random (so edges run in three directions). Arrays are malloc'ed. */
static inline void scene_grid(int n, double cell, double z, unsigned flip_seed, double **vertices, int *vertex_count,
                              int **triangles, int *triangle_count)
{
    int nv = (n + 1) * (n + 1), nt = 2 * n * n;
    double *v = malloc(sizeof *v * 3 * (size_t)nv);
    int *t = malloc(sizeof *t * 3 * (size_t)nt);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double *p = v + 3 * (j * (n + 1) + i);
            p[0] = (i - 0.5 * n) * cell;
            p[1] = (j - 0.5 * n) * cell;
            p[2] = z;
        }
    unsigned s = flip_seed;
    int k = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            s = s * 1103515245u + 12345u;
            int flip = flip_seed && ((s >> 16) & 1);
            if (!flip) {
                int q[6] = {a, b, c, a, c, d};
                for (int m = 0; m < 6; m++) t[k + m] = q[m];
            } else {
                int q[6] = {a, b, d, b, c, d};
                for (int m = 0; m < 6; m++) t[k + m] = q[m];
            }
            k += 6;
        }
    *vertices = v; *vertex_count = nv; *triangles = t; *triangle_count = nt;
}

static inline carom_body_id scene_add_mesh(carom_world *w, const double *v, int nv, const int *t, int nt,
                                           carom_vec3 position, carom_quat orientation)
{
    carom_mesh_def md = carom_mesh_def_default();
    md.vertices = v; md.vertex_count = nv; md.triangles = t; md.triangle_count = nt;
    carom_body_def bd = carom_body_def_default();
    bd.type = CAROM_BODY_STATIC;
    bd.shape.type = CAROM_SHAPE_MESH;
    bd.mesh = &md;
    bd.position = position;
    bd.orientation = orientation;
    return carom_body_create(w, &bd);
}

/* A flat height field of rows x columns points at height z. */
static inline carom_body_id scene_add_flat_field(carom_world *w, int rows, int columns, double cell, double z,
                                                 carom_vec3 position)
{
    double *h = malloc(sizeof *h * (size_t)rows * (size_t)columns);
    for (int i = 0; i < rows * columns; i++) h[i] = z;
    carom_heightfield_def hd = carom_heightfield_def_default();
    hd.heights = h; hd.rows = rows; hd.columns = columns; hd.cell_x = cell; hd.cell_y = cell;
    carom_body_def bd = carom_body_def_default();
    bd.type = CAROM_BODY_STATIC;
    bd.shape.type = CAROM_SHAPE_HEIGHTFIELD;
    bd.heightfield = &hd;
    bd.position = position;
    carom_body_id id = carom_body_create(w, &bd);
    free(h);
    return id;
}

#endif
