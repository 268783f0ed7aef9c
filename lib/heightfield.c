/* heightfield.c - a grid of heights as a shape: the two triangles of a cell
 * and their active edges are made when a query reaches the cell, so no
 * triangle list is kept. The grid is centred on the body origin in x and y;
 * heights are along +z; row r lies at y = (r - (rows - 1) / 2) cell_y. A
 * cell (c, r) splits along its diagonal from (c, r) to (c + 1, r + 1). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mesh.h"
#include "ranges.h"
#include "heightfield.h"

void heightfield_free(height_field *h)
{
    if (!h) return;
    free(h->heights);
    free(h->hole);
    free(h);
}

int heightfield_check(const double *heights, int rows, int columns, double cell_x, double cell_y, const int *holes,
                      int hole_count, char *err, int err_size)
{
#define HF_CHECK_FAIL(...) do { if (err && err_size > 0) snprintf(err, (size_t)err_size, __VA_ARGS__); return 0; } while (0)
    if (rows < 2 || columns < 2) HF_CHECK_FAIL("heightfield rows and columns: need at least 2 each (got %d x %d)", rows, columns);
    if ((double)rows * columns > 1e8) HF_CHECK_FAIL("heightfield: too large (%d x %d)", rows, columns);
    if (!heights) HF_CHECK_FAIL("heightfield heights: NULL");
    if (!(cell_x >= RANGE_LENGTH_MIN && cell_x <= RANGE_LENGTH_MAX && cell_y >= RANGE_LENGTH_MIN && cell_y <= RANGE_LENGTH_MAX))
        HF_CHECK_FAIL("heightfield cell: sizes must be in [1e-6, 1e6] m (got %g, %g)", cell_x, cell_y);
    if ((columns - 1) * cell_x > RANGE_LENGTH_MAX || (rows - 1) * cell_y > RANGE_LENGTH_MAX)
        HF_CHECK_FAIL("heightfield: wider than 1e6 m (%g x %g)", (columns - 1) * cell_x, (rows - 1) * cell_y);
    for (int i = 0; i < rows * columns; i++)
        if (!isfinite(heights[i]) || fabs(heights[i]) > RANGE_LENGTH_MAX)
            HF_CHECK_FAIL("heightfield heights[%d]: must be finite (within 1e6 m; height %d counting from 1)", i, i + 1);
    int cells = (rows - 1) * (columns - 1);
    if (hole_count < 0 || (hole_count > 0 && !holes)) HF_CHECK_FAIL("heightfield holes: bad list (count %d)", hole_count);
    for (int i = 0; i < hole_count; i++)
        if (holes[i] < 0 || holes[i] >= cells) HF_CHECK_FAIL("heightfield holes[%d]: cell %d out of range 0..%d", i, holes[i], cells - 1);
    /* a field whose every cell is a hole has no ground at all, as a mesh of
     * zero-area triangles only has none: refused the same way (the list may
     * repeat cells, so they are counted once each) */
    if (hole_count >= cells) {
        unsigned char *seen = calloc((size_t)cells, 1);
        int distinct = 0;
        if (seen) {
            for (int i = 0; i < hole_count; i++) distinct += !seen[holes[i]], seen[holes[i]] = 1;
            free(seen);
        }
        if (distinct == cells) HF_CHECK_FAIL("heightfield holes: all %d cells are holes (no ground left)", cells);
    }
    return 1;
#undef HF_CHECK_FAIL
}

height_field *heightfield_build(const double *heights, int rows, int columns, double cell_x, double cell_y,
                                const int *holes, int hole_count, char *err, int err_size)
{
#define HF_FAIL(...) do { if (err && err_size > 0) snprintf(err, (size_t)err_size, __VA_ARGS__); return NULL; } while (0)
    if (!heightfield_check(heights, rows, columns, cell_x, cell_y, holes, hole_count, err, err_size)) return NULL;
    int cells = (rows - 1) * (columns - 1);
    height_field *h = calloc(1, sizeof *h);
    if (!h) HF_FAIL("heightfield: out of memory");
    h->rows = rows;
    h->columns = columns;
    h->cell_x = cell_x;
    h->cell_y = cell_y;
    h->heights = malloc(sizeof *h->heights * (size_t)rows * (size_t)columns);
    h->hole = calloc((size_t)cells, 1);
    if (!h->heights || !h->hole) { heightfield_free(h); HF_FAIL("heightfield: out of memory"); }
    memcpy(h->heights, heights, sizeof *h->heights * (size_t)rows * (size_t)columns);
    for (int i = 0; i < hole_count; i++) h->hole[holes[i]] = 1;
    h->min_height = h->max_height = heights[0];
    for (int i = 1; i < rows * columns; i++) {
        h->min_height = dmin(h->min_height, heights[i]);
        h->max_height = dmax(h->max_height, heights[i]);
    }
    return h;
#undef HF_FAIL
}

aabb heightfield_bounds(const height_field *h)
{
    double hx = 0.5 * (h->columns - 1) * h->cell_x, hy = 0.5 * (h->rows - 1) * h->cell_y;
    aabb b = {{-hx, -hy, h->min_height}, {hx, hy, h->max_height}};
    return b;
}

static vec3 grid_point(const height_field *h, int c, int r)
{
    return v3((c - 0.5 * (h->columns - 1)) * h->cell_x, (r - 0.5 * (h->rows - 1)) * h->cell_y,
              h->heights[r * h->columns + c]);
}

/* Whether cell (c, r) exists and is solid. */
static int solid(const height_field *h, int c, int r)
{
    return c >= 0 && r >= 0 && c < h->columns - 1 && r < h->rows - 1 && !h->hole[r * (h->columns - 1) + c];
}

/* Triangle `half` (0 or 1) of cell (c, r) and its active edges. */
static unsigned cell_triangle(const height_field *h, int c, int r, int half, vec3 v[3])
{
    /* neighbour across each edge: its cell and the grid point opposite the edge */
    int nc[3], nr[3], wc[3], wr[3];
    if (half == 0) {
        v[0] = grid_point(h, c, r); v[1] = grid_point(h, c + 1, r); v[2] = grid_point(h, c + 1, r + 1);
        nc[0] = c; nr[0] = r - 1; wc[0] = c; wr[0] = r - 1;             /* bottom edge: upper half of the cell below */
        nc[1] = c + 1; nr[1] = r; wc[1] = c + 2; wr[1] = r + 1;         /* right edge: upper half of the cell to the right */
        nc[2] = c; nr[2] = r; wc[2] = c; wr[2] = r + 1;                 /* diagonal: this cell's upper half */
    } else {
        v[0] = grid_point(h, c, r); v[1] = grid_point(h, c + 1, r + 1); v[2] = grid_point(h, c, r + 1);
        nc[0] = c; nr[0] = r; wc[0] = c + 1; wr[0] = r;                 /* diagonal: this cell's lower half */
        nc[1] = c; nr[1] = r + 1; wc[1] = c + 1; wr[1] = r + 2;         /* top edge: lower half of the cell above */
        nc[2] = c - 1; nr[2] = r; wc[2] = c - 1; wr[2] = r;             /* left edge: lower half of the cell to the left */
    }
    vec3 n = v3_normalize(v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0])));
    unsigned active = 0;
    for (int k = 0; k < 3; k++) {
        if (!solid(h, nc[k], nr[k])) { active |= 1u << k; continue; }
        if (mesh_edge_active(n, v[k], v[(k + 1) % 3], grid_point(h, wc[k], wr[k]), 0)) active |= 1u << k;
    }
    return active;
}

/* Cell range [c0, c1] x [r0, r1] covering the box in x and y; 0 when empty. */
static int cell_range(const height_field *h, aabb box, int *c0, int *c1, int *r0, int *r1)
{
    double ox = -0.5 * (h->columns - 1) * h->cell_x, oy = -0.5 * (h->rows - 1) * h->cell_y;
    double fx0 = floor((box.lo.x - ox) / h->cell_x), fx1 = floor((box.hi.x - ox) / h->cell_x);
    double fy0 = floor((box.lo.y - oy) / h->cell_y), fy1 = floor((box.hi.y - oy) / h->cell_y);
    if (!(fx1 >= 0 && fy1 >= 0 && fx0 <= h->columns - 2 && fy0 <= h->rows - 2)) return 0;
    *c0 = fx0 < 0 ? 0 : (int)fx0;
    *r0 = fy0 < 0 ? 0 : (int)fy0;
    *c1 = fx1 > h->columns - 2 ? h->columns - 2 : (int)fx1;
    *r1 = fy1 > h->rows - 2 ? h->rows - 2 : (int)fy1;
    return 1;
}

void heightfield_query(const height_field *h, aabb box, tri_visit_fn *visit, void *ctx)
{
    if (box.hi.z < h->min_height || box.lo.z > h->max_height) return;
    int c0, c1, r0, r1;
    if (!cell_range(h, box, &c0, &c1, &r0, &r1)) return;
    for (int r = r0; r <= r1; r++)
        for (int c = c0; c <= c1; c++) {
            if (h->hole[r * (h->columns - 1) + c]) continue;
            double z00 = h->heights[r * h->columns + c], z10 = h->heights[r * h->columns + c + 1];
            double z01 = h->heights[(r + 1) * h->columns + c], z11 = h->heights[(r + 1) * h->columns + c + 1];
            if (dmax(dmax(z00, z10), dmax(z01, z11)) < box.lo.z || dmin(dmin(z00, z10), dmin(z01, z11)) > box.hi.z) continue;
            for (int half = 0; half < 2; half++) {
                vec3 v[3];
                unsigned active = cell_triangle(h, c, r, half, v);
                uint32_t index = (uint32_t)(2 * (r * (h->columns - 1) + c) + half);
                if (!visit(ctx, v, active, index)) return;
            }
        }
}

int heightfield_ray_cast(const height_field *h, vec3 o, vec3 d, double max_t, double *t, vec3 *normal,
                         uint32_t *index)
{
    /* the cells under the ray's bounds (clipped to the grid): rays are short
     * or the grid is modest; a long diagonal ray visits its bounding rectangle */
    vec3 e = v3_madd(o, max_t, d);
    aabb box = {v3_min(o, e), v3_max(o, e)};
    aabb gb = heightfield_bounds(h);
    if (!aabb_overlap(box, gb)) return 0;
    int c0, c1, r0, r1;
    if (!cell_range(h, box, &c0, &c1, &r0, &r1)) return 0;
    double best = max_t;
    int found = 0;
    for (int r = r0; r <= r1; r++)
        for (int c = c0; c <= c1; c++) {
            if (h->hole[r * (h->columns - 1) + c]) continue;
            for (int half = 0; half < 2; half++) {
                vec3 v[3];
                cell_triangle(h, c, r, half, v);
                double tt;
                if (ray_triangle(o, d, v, 0, best, &tt) && (!found || tt < best)) {
                    best = tt;
                    found = 1;
                    *normal = v3_normalize(v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0])));
                    if (index) *index = (uint32_t)(2 * (r * (h->columns - 1) + c) + half);
                }
            }
        }
    if (found) *t = best;
    return found;
}
