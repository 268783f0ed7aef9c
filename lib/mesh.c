/* mesh.c - triangle meshes: validation, edge adjacency (which edges are
 * active), a bounding-volume tree built once by the binned surface-area
 * heuristic, box queries and ray casts. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mesh.h"
#include "ranges.h"

#define LEAF_SIZE 4
#define SAH_BINS 16

static void fail(char *err, int n, const char *fmt, int a, int b)
{
    if (err && n > 0) snprintf(err, (size_t)n, fmt, a, b);
}

static vec3 tri_normal_raw(vec3 a, vec3 b, vec3 c) { return v3_cross(v3_sub(b, a), v3_sub(c, a)); }

int mesh_edge_active(vec3 n, vec3 p, vec3 q, vec3 w, int two_sided)
{
    vec3 n2 = tri_normal_raw(q, p, w);
    double l = v3_len(n2);
    if (!(l > 0)) return 1;
    n2 = v3_scale(n2, 1.0 / l);
    if (v3_dot(n, n2) >= MESH_ACTIVE_EDGE_COS) return 0; /* flat enough: internal */
    if (two_sided) return 1;
    /* concave seen from the front (the neighbour rises above this plane): the
     * two faces hold any contact there, an edge normal would only snag */
    double rise = v3_dot(n, v3_sub(w, p));
    return rise < 0;
}

int ray_triangle(vec3 o, vec3 d, const vec3 v[3], int two_sided, double max_t, double *t)
{
    /* Moller-Trumbore */
    vec3 e1 = v3_sub(v[1], v[0]), e2 = v3_sub(v[2], v[0]);
    vec3 pv = v3_cross(d, e2);
    double det = v3_dot(e1, pv);
    /* det = -d . (e1 x e2) > 0: the ray meets the front face */
    if (!two_sided && !(det > 0)) return 0;
    if (det == 0 || !isfinite(det)) return 0;
    double inv = 1.0 / det;
    vec3 tv = v3_sub(o, v[0]);
    double u = v3_dot(tv, pv) * inv;
    if (u < 0 || u > 1) return 0;
    vec3 qv = v3_cross(tv, e1);
    double w = v3_dot(d, qv) * inv;
    if (w < 0 || u + w > 1) return 0;
    double tt = v3_dot(e2, qv) * inv;
    if (!(tt >= 0 && tt <= max_t)) return 0;
    *t = tt;
    return 1;
}

/* ---- edge adjacency ---------------------------------------------------------- */

typedef struct edge_rec { int lo, hi, tri, k; } edge_rec;

static int edge_cmp(const void *x, const void *y)
{
    const edge_rec *a = x, *b = y;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->tri < b->tri ? -1 : (a->tri > b->tri);
}

/* Marks the active edges: boundary and non-manifold edges are active, an edge
 * between two triangles is active when folded (see mesh_edge_active). */
static int compute_active_edges(tri_mesh *m)
{
    int n = m->triangle_count;
    edge_rec *e = malloc(sizeof *e * (size_t)n * 3);
    if (!e) return 0;
    for (int t = 0; t < n; t++)
        for (int k = 0; k < 3; k++) {
            int a = m->triangles[t][k], b = m->triangles[t][(k + 1) % 3];
            edge_rec r = {a < b ? a : b, a < b ? b : a, t, k};
            e[3 * t + k] = r;
        }
    qsort(e, (size_t)n * 3, sizeof *e, edge_cmp);
    for (int t = 0; t < n; t++) m->active[t] = 7;
    for (int i = 0; i < 3 * n;) {
        int j = i + 1;
        while (j < 3 * n && e[j].lo == e[i].lo && e[j].hi == e[i].hi) j++;
        if (j - i == 2) {
            for (int s = 0; s < 2; s++) {
                const edge_rec *me = &e[i + s], *other = &e[i + 1 - s];
                const int *tv = m->triangles[me->tri], *ov = m->triangles[other->tri];
                vec3 p = m->vertices[tv[me->k]], q = m->vertices[tv[(me->k + 1) % 3]];
                vec3 w = m->vertices[ov[(other->k + 2) % 3]];
                vec3 nn = v3_normalize(tri_normal_raw(m->vertices[tv[0]], m->vertices[tv[1]], m->vertices[tv[2]]));
                if (!mesh_edge_active(nn, p, q, w, m->two_sided))
                    m->active[me->tri] &= (uint8_t)~(1u << me->k);
            }
        }
        i = j;
    }
    free(e);
    return 1;
}

/* ---- tree -------------------------------------------------------------------- */

typedef struct build_state {
    tri_mesh *m;
    aabb *tri_box;
    vec3 *centroid;
    int *order;        /* triangle indices being partitioned */
    int node_capacity;
} build_state;

static aabb box_of(const build_state *b, int from, int to)
{
    aabb r = b->tri_box[b->order[from]];
    for (int i = from + 1; i < to; i++) r = aabb_union(r, b->tri_box[b->order[i]]);
    return r;
}

/* Builds the subtree of order[from, to) into node `ni`. */
static void build_node(build_state *b, int ni, int from, int to, int depth)
{
    mesh_node *nodes = b->m->nodes;
    nodes[ni].box = box_of(b, from, to);
    int n = to - from;
    if (n <= LEAF_SIZE) {
        nodes[ni].first = from;
        nodes[ni].count = n;
        return;
    }
    /* centroid bounds, then the cheapest of the binned splits on every axis */
    vec3 clo = b->centroid[b->order[from]], chi = clo;
    for (int i = from + 1; i < to; i++) {
        clo = v3_min(clo, b->centroid[b->order[i]]);
        chi = v3_max(chi, b->centroid[b->order[i]]);
    }
    double best_cost = 1e300;
    int best_axis = -1, best_bin = 0;
    for (int axis = 0; axis < 3; axis++) {
        double lo = v3_get(clo, axis), ext = v3_get(chi, axis) - lo;
        if (!(ext > 0)) continue;
        int count[SAH_BINS] = {0};
        aabb bins[SAH_BINS];
        for (int i = from; i < to; i++) {
            int t = b->order[i];
            int k = (int)((v3_get(b->centroid[t], axis) - lo) / ext * SAH_BINS);
            if (k >= SAH_BINS) k = SAH_BINS - 1;
            bins[k] = count[k] ? aabb_union(bins[k], b->tri_box[t]) : b->tri_box[t];
            count[k]++;
        }
        /* sweep: area of the left part times its count plus the right's */
        double right_area[SAH_BINS];
        int right_count[SAH_BINS];
        aabb acc = {{0, 0, 0}, {0, 0, 0}};
        int c = 0;
        for (int k = SAH_BINS - 1; k > 0; k--) {
            if (count[k]) { acc = c ? aabb_union(acc, bins[k]) : bins[k]; c += count[k]; }
            right_area[k] = c ? aabb_area(acc) : 0;
            right_count[k] = c;
        }
        c = 0;
        for (int k = 0; k < SAH_BINS - 1; k++) {
            if (count[k]) { acc = c ? aabb_union(acc, bins[k]) : bins[k]; c += count[k]; }
            if (!c || !right_count[k + 1]) continue;
            double cost = aabb_area(acc) * c + right_area[k + 1] * right_count[k + 1];
            if (cost < best_cost) { best_cost = cost; best_axis = axis; best_bin = k; }
        }
    }
    int mid;
    if (best_axis < 0 || depth > 40) {
        mid = from + n / 2; /* every centroid in one point (or a lopsided tree): split the list */
    } else {
        double lo = v3_get(clo, best_axis), ext = v3_get(chi, best_axis) - lo;
        int i = from, j = to - 1;
        while (i <= j) {
            int k = (int)((v3_get(b->centroid[b->order[i]], best_axis) - lo) / ext * SAH_BINS);
            if (k >= SAH_BINS) k = SAH_BINS - 1;
            if (k <= best_bin) i++;
            else { int t = b->order[i]; b->order[i] = b->order[j]; b->order[j] = t; j--; }
        }
        mid = i;
        if (mid == from || mid == to) mid = from + n / 2;
    }
    int left = b->m->node_count;
    b->m->node_count += 2;
    nodes[ni].first = left;
    nodes[ni].count = 0;
    build_node(b, left, from, mid, depth + 1);
    build_node(b, left + 1, mid, to, depth + 1);
}

static int build_tree(tri_mesh *m)
{
    int n = m->triangle_count;
    build_state b;
    b.m = m;
    b.tri_box = malloc(sizeof *b.tri_box * (size_t)n);
    b.centroid = malloc(sizeof *b.centroid * (size_t)n);
    b.order = malloc(sizeof *b.order * (size_t)n);
    m->nodes = malloc(sizeof *m->nodes * (size_t)(2 * n));
    int (*tris)[3] = malloc(sizeof *tris * (size_t)n);
    int *src = malloc(sizeof *src * (size_t)n);
    uint8_t *act = malloc((size_t)n);
    if (!b.tri_box || !b.centroid || !b.order || !m->nodes || !tris || !src || !act) {
        free(b.tri_box); free(b.centroid); free(b.order); free(tris); free(src); free(act);
        return 0;
    }
    for (int t = 0; t < n; t++) {
        vec3 a = m->vertices[m->triangles[t][0]], c = m->vertices[m->triangles[t][1]], d = m->vertices[m->triangles[t][2]];
        b.tri_box[t].lo = v3_min(a, v3_min(c, d));
        b.tri_box[t].hi = v3_max(a, v3_max(c, d));
        b.centroid[t] = v3_scale(v3_add(a, v3_add(c, d)), 1.0 / 3.0);
        b.order[t] = t;
    }
    m->node_count = 1;
    build_node(&b, 0, 0, n, 0);
    /* store the triangles in leaf order: a leaf's triangles are contiguous */
    for (int i = 0; i < n; i++) {
        int t = b.order[i];
        memcpy(tris[i], m->triangles[t], sizeof tris[i]);
        src[i] = m->source_index[t];
        act[i] = m->active[t];
    }
    free(m->triangles); free(m->source_index); free(m->active);
    m->triangles = tris;
    m->source_index = src;
    m->active = act;
    free(b.tri_box); free(b.centroid); free(b.order);
    return 1;
}

/* ---- building ---------------------------------------------------------------- */

void mesh_free(tri_mesh *m)
{
    if (!m) return;
    free(m->vertices); free(m->triangles); free(m->source_index); free(m->active); free(m->nodes);
    free(m);
}

int mesh_check(const double *vertices, int vertex_count, const int *triangles, int triangle_count, char *err,
               int err_size)
{
    if (vertex_count < 3) { fail(err, err_size, "mesh vertices: need at least 3 (got %d)", vertex_count, 0); return 0; }
    if (!vertices) { fail(err, err_size, "mesh vertices: NULL (vertex_count %d)", vertex_count, 0); return 0; }
    if (triangle_count < 1) { fail(err, err_size, "mesh triangles: need at least 1 (got %d)", triangle_count, 0); return 0; }
    if (!triangles) { fail(err, err_size, "mesh triangles: NULL (triangle_count %d)", triangle_count, 0); return 0; }
    if (vertex_count > 100000000 || triangle_count > 100000000) { fail(err, err_size, "mesh: too large (%d vertices, %d triangles)", vertex_count, triangle_count); return 0; }
    for (int i = 0; i < 3 * vertex_count; i++)
        if (!isfinite(vertices[i]) || fabs(vertices[i]) > RANGE_LENGTH_MAX) {
            fail(err, err_size, "mesh vertices[%d]: coordinates must be finite (within 1e6 m; vertex %d counting from 1)", i / 3,
                 i / 3 + 1);
            return 0;
        }
    for (int t = 0; t < triangle_count; t++) {
        const int *v = triangles + 3 * t;
        for (int k = 0; k < 3; k++)
            if (v[k] < 0 || v[k] >= vertex_count) {
                fail(err, err_size, "mesh triangles[%d]: vertex index %d out of range", t, v[k]);
                return 0;
            }
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
            int repeated = v[0] == v[1] || v[0] == v[2] ? v[0] : v[1];
            if (err && err_size > 0)
                snprintf(err, (size_t)err_size, "mesh triangles[%d]: repeats vertex %d (triangle %d, vertex %d counting from 1)",
                         t, repeated, t + 1, repeated + 1);
            return 0;
        }
    }
    return 1;
}

tri_mesh *mesh_build(const double *vertices, int vertex_count, const int *triangles, int triangle_count,
                     int two_sided, char *err, int err_size)
{
    if (!mesh_check(vertices, vertex_count, triangles, triangle_count, err, err_size)) return NULL;
    tri_mesh *m = calloc(1, sizeof *m);
    if (!m) { fail(err, err_size, "mesh: out of memory", 0, 0); return NULL; }
    m->two_sided = two_sided != 0;
    m->vertex_count = vertex_count;
    m->vertices = malloc(sizeof *m->vertices * (size_t)vertex_count);
    m->triangles = malloc(sizeof *m->triangles * (size_t)triangle_count);
    m->source_index = malloc(sizeof *m->source_index * (size_t)triangle_count);
    m->active = malloc((size_t)triangle_count);
    if (!m->vertices || !m->triangles || !m->source_index || !m->active) {
        mesh_free(m);
        fail(err, err_size, "mesh: out of memory", 0, 0);
        return NULL;
    }
    for (int i = 0; i < vertex_count; i++) m->vertices[i] = v3(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
    /* zero-area triangles have no face to collide with: dropped (their
     * neighbours then see an open edge there, which is active) */
    double extent = 0;
    for (int i = 0; i < vertex_count; i++) extent = dmax(extent, v3_len(v3_sub(m->vertices[i], m->vertices[0])));
    int kept = 0;
    for (int t = 0; t < triangle_count; t++) {
        const int *v = triangles + 3 * t;
        vec3 n = tri_normal_raw(m->vertices[v[0]], m->vertices[v[1]], m->vertices[v[2]]);
        if (!(v3_len(n) > 1e-24 * extent * extent) || !(v3_len(n) > 0)) continue;
        memcpy(m->triangles[kept], v, sizeof m->triangles[kept]);
        m->source_index[kept] = t;
        kept++;
    }
    if (kept == 0) {
        mesh_free(m);
        fail(err, err_size, "mesh triangles: all %d have zero area", triangle_count, 0);
        return NULL;
    }
    m->triangle_count = kept;
    if (!compute_active_edges(m) || !build_tree(m)) {
        mesh_free(m);
        fail(err, err_size, "mesh: out of memory", 0, 0);
        return NULL;
    }
    return m;
}

aabb mesh_bounds(const tri_mesh *m) { return m->nodes[0].box; }

/* ---- queries ----------------------------------------------------------------- */

#define STACK_MAX 128

void mesh_query(const tri_mesh *m, aabb box, tri_visit_fn *visit, void *ctx)
{
    int stack[STACK_MAX], top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const mesh_node *nd = &m->nodes[stack[--top]];
        if (!aabb_overlap(nd->box, box)) continue;
        if (nd->count == 0) {
            if (top + 2 > STACK_MAX) continue; /* deeper than any SAH tree of 100M triangles */
            stack[top++] = nd->first + 1;
            stack[top++] = nd->first;
            continue;
        }
        for (int i = nd->first; i < nd->first + nd->count; i++) {
            vec3 v[3] = {m->vertices[m->triangles[i][0]], m->vertices[m->triangles[i][1]], m->vertices[m->triangles[i][2]]};
            aabb tb = {v3_min(v[0], v3_min(v[1], v[2])), v3_max(v[0], v3_max(v[1], v[2]))};
            if (!aabb_overlap(tb, box)) continue;
            if (!visit(ctx, v, m->active[i], (uint32_t)m->source_index[i])) return;
        }
    }
}

/* Entry distance of the ray into a box, or a value > max_t when it misses. */
static double ray_box(vec3 o, vec3 inv_d, aabb b, double max_t)
{
    double t0 = 0, t1 = max_t;
    double oo[3] = {o.x, o.y, o.z}, id[3] = {inv_d.x, inv_d.y, inv_d.z};
    double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    for (int i = 0; i < 3; i++) {
        double a = (lo[i] - oo[i]) * id[i], c = (hi[i] - oo[i]) * id[i];
        if (isnan(a) || isnan(c)) { if (oo[i] < lo[i] || oo[i] > hi[i]) return 2 * max_t + 1; continue; }
        if (a > c) { double t = a; a = c; c = t; }
        t0 = dmax(t0, a);
        t1 = dmin(t1, c);
        if (t0 > t1) return 2 * max_t + 1;
    }
    return t0;
}

int mesh_ray_cast(const tri_mesh *m, vec3 o, vec3 d, double max_t, double *t, vec3 *normal, uint32_t *index)
{
    vec3 inv = v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    int stack[STACK_MAX], top = 0, hit = -1;
    double best = max_t;
    stack[top++] = 0;
    while (top > 0) {
        const mesh_node *nd = &m->nodes[stack[--top]];
        if (ray_box(o, inv, nd->box, best) > best) continue;
        if (nd->count == 0) {
            if (top + 2 > STACK_MAX) continue;
            stack[top++] = nd->first + 1;
            stack[top++] = nd->first;
            continue;
        }
        for (int i = nd->first; i < nd->first + nd->count; i++) {
            vec3 v[3] = {m->vertices[m->triangles[i][0]], m->vertices[m->triangles[i][1]], m->vertices[m->triangles[i][2]]};
            double tt;
            if (ray_triangle(o, d, v, m->two_sided, best, &tt) && (hit < 0 || tt < best)) { best = tt; hit = i; }
        }
    }
    if (hit < 0) return 0;
    const int *tv = m->triangles[hit];
    vec3 n = v3_normalize(tri_normal_raw(m->vertices[tv[0]], m->vertices[tv[1]], m->vertices[tv[2]]));
    if (v3_dot(n, d) > 0) n = v3_neg(n); /* two-sided, hit from behind */
    *t = best;
    *normal = n;
    if (index) *index = (uint32_t)m->source_index[hit];
    return 1;
}
