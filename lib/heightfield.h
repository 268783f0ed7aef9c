/* heightfield.h - height fields (heightfield.c): a grid of heights seen as
 * triangles, two per cell, queried and ray cast like a mesh (mesh.h holds the
 * height_field type and the triangle visitor). */
#ifndef CAROM_HEIGHTFIELD_H
#define CAROM_HEIGHTFIELD_H

#include "mesh.h"

/* 1 if the input is a valid height field, else 0 with err saying which
 * field is wrong. */
int heightfield_check(const double *heights, int rows, int columns, double cell_x, double cell_y, const int *holes,
                      int hole_count, char *err, int err_size);
/* Copies and validates the input (heightfield_check; err says which field is wrong). */
height_field *heightfield_build(const double *heights, int rows, int columns, double cell_x, double cell_y,
                                const int *holes, int hole_count, char *err, int err_size);
void heightfield_free(height_field *h);
aabb heightfield_bounds(const height_field *h);
void heightfield_query(const height_field *h, aabb box, tri_visit_fn *visit, void *ctx);
int heightfield_ray_cast(const height_field *h, vec3 o, vec3 d, double max_t, double *t, vec3 *normal,
                         uint32_t *index);

#endif
