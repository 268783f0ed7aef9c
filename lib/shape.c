/* shape.c - mass properties, bounds, support mapping and ray casts of the
 * shapes, and convex hull construction (incremental, with coplanar triangles
 * merged into polygon faces). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "shape.h"

#define PI 3.14159265358979323846
#define PLANE_EXTENT 1e18

/* ---- mass properties --------------------------------------------------------- */

double shape_volume(const shape *s)
{
    double r = s->radius, h = 2.0 * s->half_height;
    switch (s->type) {
    case SHAPE_SPHERE: return 4.0 / 3.0 * PI * r * r * r;
    case SHAPE_BOX: return 8.0 * s->half_extents.x * s->half_extents.y * s->half_extents.z;
    case SHAPE_CAPSULE: return PI * r * r * h + 4.0 / 3.0 * PI * r * r * r;
    case SHAPE_CYLINDER: return PI * r * r * h;
    case SHAPE_HULL: return s->hull->volume;
    default: return 0.0;
    }
}

/* Inertia about the centre of mass for unit density (so mass = volume). */
static mat3 unit_density_inertia(const shape *s, vec3 *center)
{
    double r = s->radius, r2 = r * r, hh = s->half_height, h = 2.0 * hh;
    *center = v3_zero();
    switch (s->type) {
    case SHAPE_SPHERE: {
        double m = shape_volume(s), i = 0.4 * m * r2;
        return m3_diag(v3(i, i, i));
    }
    case SHAPE_BOX: {
        vec3 e = v3_scale(s->half_extents, 2.0);
        double m = shape_volume(s);
        return m3_diag(v3(m * (e.y * e.y + e.z * e.z) / 12.0, m * (e.x * e.x + e.z * e.z) / 12.0,
                          m * (e.x * e.x + e.y * e.y) / 12.0));
    }
    case SHAPE_CYLINDER: {
        double m = PI * r2 * h;
        double ixx = m * (3.0 * r2 + h * h) / 12.0;
        return m3_diag(v3(ixx, ixx, 0.5 * m * r2));
    }
    case SHAPE_CAPSULE: {
        /* cylinder plus two hemispheres whose centroids sit 3r/8 beyond the segment ends */
        double mc = PI * r2 * h, ms = 4.0 / 3.0 * PI * r2 * r; /* both hemispheres together */
        double izz = 0.5 * mc * r2 + 0.4 * ms * r2;
        double d = hh + 3.0 * r / 8.0;
        /* each hemisphere about its own centroid: (2/5 - 9/64) m r^2 about a transverse axis */
        double ihemi = (0.4 - 9.0 / 64.0) * ms * r2 + ms * d * d;
        double ixx = mc * (3.0 * r2 + h * h) / 12.0 + ihemi;
        return m3_diag(v3(ixx, ixx, izz));
    }
    case SHAPE_HULL:
        *center = s->hull->centroid;
        return s->hull->unit_inertia;
    default:
        return m3_zero();
    }
}

mass_props shape_mass_from_density(const shape *s, double density)
{
    mass_props mp;
    mat3 unit = unit_density_inertia(s, &mp.center);
    mp.mass = density * shape_volume(s);
    mp.inertia = m3_scale(unit, density);
    return mp;
}

mass_props shape_mass_from_mass(const shape *s, double mass)
{
    double v = shape_volume(s);
    return shape_mass_from_density(s, v > 0 ? mass / v : 0.0);
}

/* ---- bounds and support ------------------------------------------------------ */

aabb shape_aabb(const shape *s, xform t)
{
    aabb b;
    switch (s->type) {
    case SHAPE_SPHERE: {
        vec3 r = v3(s->radius, s->radius, s->radius);
        b.lo = v3_sub(t.p, r);
        b.hi = v3_add(t.p, r);
        return b;
    }
    case SHAPE_BOX: {
        mat3 m = m3_from_quat(t.q);
        vec3 he = s->half_extents;
        vec3 e = v3_add(v3_add(v3_scale(v3_abs(m.c0), he.x), v3_scale(v3_abs(m.c1), he.y)), v3_scale(v3_abs(m.c2), he.z));
        b.lo = v3_sub(t.p, e);
        b.hi = v3_add(t.p, e);
        return b;
    }
    case SHAPE_CAPSULE: {
        vec3 axis = q_rotate(t.q, v3(0, 0, s->half_height));
        vec3 r = v3(s->radius, s->radius, s->radius);
        vec3 a = v3_add(t.p, axis), c = v3_sub(t.p, axis);
        b.lo = v3_sub(v3_min(a, c), r);
        b.hi = v3_add(v3_max(a, c), r);
        return b;
    }
    case SHAPE_CYLINDER: {
        vec3 a = q_rotate(t.q, v3(0, 0, 1));
        double ex[3];
        for (int i = 0; i < 3; i++) {
            double ai = v3_get(a, i);
            ex[i] = s->half_height * fabs(ai) + s->radius * sqrt(fmax(0.0, 1.0 - ai * ai));
        }
        vec3 e = v3(ex[0], ex[1], ex[2]);
        b.lo = v3_sub(t.p, e);
        b.hi = v3_add(t.p, e);
        return b;
    }
    case SHAPE_HULL: {
        vec3 p = xf_point(t, s->hull->vertices[0]);
        b.lo = b.hi = p;
        for (int i = 1; i < s->hull->vertex_count; i++) {
            p = xf_point(t, s->hull->vertices[i]);
            b.lo = v3_min(b.lo, p);
            b.hi = v3_max(b.hi, p);
        }
        return b;
    }
    case SHAPE_PLANE: {
        vec3 n = q_rotate(t.q, s->plane_normal);
        double off = s->plane_offset + v3_dot(n, t.p);
        b.lo = v3(-PLANE_EXTENT, -PLANE_EXTENT, -PLANE_EXTENT);
        b.hi = v3(PLANE_EXTENT, PLANE_EXTENT, PLANE_EXTENT);
        /* axis-aligned planes get a tight side: the solid half-space */
        double c[3] = {n.x, n.y, n.z};
        for (int i = 0; i < 3; i++) {
            if (fabs(fabs(c[i]) - 1.0) > 1e-12) continue;
            double lim = off / c[i];
            if (c[i] > 0) { if (i == 0) b.hi.x = lim; else if (i == 1) b.hi.y = lim; else b.hi.z = lim; }
            else { if (i == 0) b.lo.x = lim; else if (i == 1) b.lo.y = lim; else b.lo.z = lim; }
        }
        return b;
    }
    default:
        b.lo = b.hi = t.p;
        return b;
    }
}

vec3 shape_support_local(const shape *s, vec3 d)
{
    switch (s->type) {
    case SHAPE_SPHERE: {
        vec3 n = v3_normalize(d);
        if (v3_len2(n) == 0) n = v3(0, 0, 1);
        return v3_scale(n, s->radius);
    }
    case SHAPE_BOX: {
        vec3 h = s->half_extents;
        return v3(d.x < 0 ? -h.x : h.x, d.y < 0 ? -h.y : h.y, d.z < 0 ? -h.z : h.z);
    }
    case SHAPE_CAPSULE: {
        vec3 n = v3_normalize(d);
        if (v3_len2(n) == 0) n = v3(0, 0, 1);
        return v3_add(v3(0, 0, d.z < 0 ? -s->half_height : s->half_height), v3_scale(n, s->radius));
    }
    case SHAPE_CYLINDER: {
        double l = sqrt(d.x * d.x + d.y * d.y);
        vec3 rim = l > 1e-300 ? v3(s->radius * d.x / l, s->radius * d.y / l, 0) : v3(s->radius, 0, 0);
        rim.z = d.z < 0 ? -s->half_height : s->half_height;
        return rim;
    }
    case SHAPE_HULL: {
        const hull *h = s->hull;
        int best = 0;
        double bd = v3_dot(h->vertices[0], d);
        for (int i = 1; i < h->vertex_count; i++) {
            double v = v3_dot(h->vertices[i], d);
            if (v > bd) { bd = v; best = i; }
        }
        return h->vertices[best];
    }
    default:
        return v3_zero();
    }
}

double shape_bounding_radius(const shape *s)
{
    switch (s->type) {
    case SHAPE_SPHERE: return s->radius;
    case SHAPE_BOX: return v3_len(s->half_extents);
    case SHAPE_CAPSULE: return s->half_height + s->radius;
    case SHAPE_CYLINDER: return sqrt(s->half_height * s->half_height + s->radius * s->radius);
    case SHAPE_HULL: {
        double m = 0;
        for (int i = 0; i < s->hull->vertex_count; i++) m = fmax(m, v3_len(s->hull->vertices[i]));
        return m;
    }
    default: return PLANE_EXTENT;
    }
}

/* ---- convex hulls ------------------------------------------------------------ */

typedef struct tri { int v[3]; vec3 n; double d; int alive; } tri;

static void tri_plane(tri *t, const vec3 *p)
{
    vec3 n = v3_cross(v3_sub(p[t->v[1]], p[t->v[0]]), v3_sub(p[t->v[2]], p[t->v[0]]));
    t->n = v3_normalize(n);
    t->d = v3_dot(t->n, p[t->v[0]]);
}

typedef struct edge_rec { int a, b; } edge_rec;

static int edge_cmp(const void *x, const void *y)
{
    const edge_rec *e = x, *f = y;
    int ea = e->a < e->b ? e->a : e->b, eb = e->a < e->b ? e->b : e->a;
    int fa = f->a < f->b ? f->a : f->b, fb = f->a < f->b ? f->b : f->a;
    if (ea != fa) return ea < fa ? -1 : 1;
    return (eb > fb) - (eb < fb);
}

static void hull_fail(char *err, int n, const char *msg)
{
    if (err && n > 0) snprintf(err, (size_t)n, "%s", msg);
}

/* Merges coplanar triangles into polygons, orders their vertices CCW, builds
 * edges, and computes volume, centroid and inertia. */
static hull *hull_finish(const vec3 *p, tri *tris, int ntri, double eps)
{
    hull *h = calloc(1, sizeof *h);
    int *group = malloc(sizeof *group * (size_t)ntri);
    int *vmap = malloc(sizeof *vmap * (size_t)(3 * ntri + 1));
    int *used = NULL;
    if (!h || !group || !vmap) goto oom;
    int nfaces = 0;
    for (int i = 0; i < ntri; i++) group[i] = -1;
    for (int i = 0; i < ntri; i++) {
        if (!tris[i].alive || group[i] >= 0) continue;
        group[i] = nfaces;
        for (int j = i + 1; j < ntri; j++)
            if (tris[j].alive && group[j] < 0 && v3_dot(tris[i].n, tris[j].n) > 1.0 - 1e-9 &&
                fabs(tris[i].d - tris[j].d) < eps)
                group[j] = nfaces;
        nfaces++;
    }
    /* collect distinct vertices per face */
    int max_pts = 0;
    for (int i = 0; i < ntri; i++)
        for (int k = 0; k < 3; k++)
            if (tris[i].alive && tris[i].v[k] + 1 > max_pts) max_pts = tris[i].v[k] + 1;
    used = calloc((size_t)max_pts, sizeof *used);
    h->faces = calloc((size_t)nfaces, sizeof *h->faces);
    h->face_vertices = malloc(sizeof *h->face_vertices * (size_t)(3 * ntri));
    if (!used || !h->faces || !h->face_vertices) goto oom;
    int fv = 0;
    for (int f = 0; f < nfaces; f++) {
        int first = fv;
        vec3 n = v3_zero();
        double d = 0;
        int cnt = 0;
        for (int i = 0; i < ntri; i++) {
            if (group[i] != f) continue;
            n = v3_add(n, tris[i].n);
            cnt++;
            for (int k = 0; k < 3; k++) {
                int v = tris[i].v[k], seen = 0;
                for (int q = first; q < fv; q++) if (h->face_vertices[q] == v) seen = 1;
                if (!seen) h->face_vertices[fv++] = v;
            }
        }
        n = v3_normalize(n);
        /* order CCW around the face centre, seen from outside */
        vec3 c = v3_zero();
        for (int q = first; q < fv; q++) c = v3_add(c, p[h->face_vertices[q]]);
        c = v3_scale(c, 1.0 / (fv - first));
        vec3 u, w;
        v3_basis(n, &u, &w);
        for (int a = first + 1; a < fv; a++) {
            int key = h->face_vertices[a];
            vec3 dk = v3_sub(p[key], c);
            double ak = atan2(v3_dot(dk, w), v3_dot(dk, u));
            int b = a - 1;
            while (b >= first) {
                vec3 db = v3_sub(p[h->face_vertices[b]], c);
                if (atan2(v3_dot(db, w), v3_dot(db, u)) <= ak) break;
                h->face_vertices[b + 1] = h->face_vertices[b];
                b--;
            }
            h->face_vertices[b + 1] = key;
        }
        for (int q = first; q < fv; q++) d += v3_dot(n, p[h->face_vertices[q]]);
        h->faces[f].normal = n;
        h->faces[f].offset = d / (fv - first);
        h->faces[f].first = first;
        h->faces[f].count = fv - first;
        (void)cnt;
    }
    h->face_count = nfaces;
    /* remove collinear points on face boundaries: keep only vertices that are corners */
    for (int f = 0; f < nfaces; f++) {
        hull_face *F = &h->faces[f];
        int out = F->first;
        for (int q = 0; q < F->count; q++) {
            int prev = h->face_vertices[F->first + (q + F->count - 1) % F->count];
            int cur = h->face_vertices[F->first + q];
            int next = h->face_vertices[F->first + (q + 1) % F->count];
            vec3 cr = v3_cross(v3_sub(p[cur], p[prev]), v3_sub(p[next], p[cur]));
            if (v3_dot(cr, F->normal) > eps * eps) h->face_vertices[out++] = cur;
        }
        /* compaction keeps faces in order; later faces start where they were */
        F->count = out - F->first;
    }
    /* vertices: every corner of a face, renumbered */
    for (int i = 0; i < max_pts; i++) used[i] = -1;
    int nv = 0;
    for (int f = 0; f < nfaces; f++)
        for (int q = 0; q < h->faces[f].count; q++) {
            int *v = &h->face_vertices[h->faces[f].first + q];
            if (used[*v] < 0) used[*v] = nv++;
            *v = used[*v];
        }
    h->vertices = malloc(sizeof *h->vertices * (size_t)nv);
    if (!h->vertices) goto oom;
    for (int i = 0; i < max_pts; i++)
        if (used[i] >= 0) h->vertices[used[i]] = p[i];
    h->vertex_count = nv;
    /* unique edges */
    int ne_max = 0;
    for (int f = 0; f < nfaces; f++) ne_max += h->faces[f].count;
    h->edges = malloc(sizeof *h->edges * (size_t)(ne_max > 0 ? ne_max : 1));
    if (!h->edges) goto oom;
    for (int f = 0; f < nfaces; f++) {
        const hull_face *F = &h->faces[f];
        for (int q = 0; q < F->count; q++) {
            int a = h->face_vertices[F->first + q], b = h->face_vertices[F->first + (q + 1) % F->count];
            if (a < b) { h->edges[h->edge_count][0] = a; h->edges[h->edge_count][1] = b; h->edge_count++; }
        }
    }
    /* volume, centroid, inertia by tetrahedra from an interior point */
    vec3 ref = v3_zero();
    for (int i = 0; i < nv; i++) ref = v3_add(ref, h->vertices[i]);
    ref = v3_scale(ref, 1.0 / nv);
    double vol = 0;
    vec3 cen = v3_zero();
    double cov[3][3] = {{0}};
    for (int f = 0; f < nfaces; f++) {
        const hull_face *F = &h->faces[f];
        vec3 a = v3_sub(h->vertices[h->face_vertices[F->first]], ref);
        for (int q = 1; q + 1 < F->count; q++) {
            vec3 b = v3_sub(h->vertices[h->face_vertices[F->first + q]], ref);
            vec3 c = v3_sub(h->vertices[h->face_vertices[F->first + q + 1]], ref);
            double det = v3_dot(a, v3_cross(b, c));
            vol += det / 6.0;
            cen = v3_add(cen, v3_scale(v3_add(v3_add(a, b), c), det / 24.0));
            /* covariance of the tetrahedron (0, a, b, c): det/120 * sum (1 + [i==j]) v_i v_j^T */
            vec3 s = v3_add(v3_add(a, b), c);
            double S[3] = {s.x, s.y, s.z}, A[3] = {a.x, a.y, a.z}, B[3] = {b.x, b.y, b.z}, C[3] = {c.x, c.y, c.z};
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    cov[i][j] += det / 120.0 * (S[i] * S[j] + A[i] * A[j] + B[i] * B[j] + C[i] * C[j]);
        }
    }
    vec3 com = v3_scale(cen, 1.0 / vol);
    double m[3] = {com.x, com.y, com.z};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) cov[i][j] -= vol * m[i] * m[j];
    double tr = cov[0][0] + cov[1][1] + cov[2][2];
    h->unit_inertia = m3_cols(v3(tr - cov[0][0], -cov[1][0], -cov[2][0]), v3(-cov[0][1], tr - cov[1][1], -cov[2][1]),
                              v3(-cov[0][2], -cov[1][2], tr - cov[2][2]));
    h->volume = vol;
    h->centroid = v3_add(ref, com);
    free(group);
    free(vmap);
    free(used);
    return h;
oom:
    free(group);
    free(vmap);
    free(used);
    hull_free(h);
    return NULL;
}

hull *hull_build(const double *points, int count, char *err, int err_size)
{
    if (!points || count < 4) { hull_fail(err, err_size, "a hull needs at least 4 points"); return NULL; }
    vec3 *p = malloc(sizeof *p * (size_t)count);
    if (!p) { hull_fail(err, err_size, "out of memory"); return NULL; }
    vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < count; i++) {
        p[i] = v3(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
        if (!v3_is_finite(p[i])) { free(p); hull_fail(err, err_size, "hull points must be finite"); return NULL; }
        lo = v3_min(lo, p[i]);
        hi = v3_max(hi, p[i]);
    }
    double scale = v3_len(v3_sub(hi, lo));
    double eps = 1e-9 * (scale > 0 ? scale : 1.0) + 1e-12 * v3_len(v3_max(v3_abs(lo), v3_abs(hi)));
    /* initial tetrahedron: extreme points */
    int i0 = 0, i1 = -1, i2 = -1, i3 = -1;
    for (int i = 1; i < count; i++) if (p[i].x < p[i0].x) i0 = i;
    double best = 0;
    for (int i = 0; i < count; i++) { double d = v3_len2(v3_sub(p[i], p[i0])); if (d > best) { best = d; i1 = i; } }
    if (i1 < 0 || sqrt(best) <= eps) { free(p); hull_fail(err, err_size, "hull points are all the same point"); return NULL; }
    best = 0;
    vec3 dir = v3_sub(p[i1], p[i0]);
    for (int i = 0; i < count; i++) {
        double d = v3_len(v3_cross(dir, v3_sub(p[i], p[i0]))) / v3_len(dir);
        if (d > best) { best = d; i2 = i; }
    }
    if (i2 < 0 || best <= eps) { free(p); hull_fail(err, err_size, "hull points are collinear"); return NULL; }
    vec3 nrm = v3_normalize(v3_cross(dir, v3_sub(p[i2], p[i0])));
    best = 0;
    for (int i = 0; i < count; i++) {
        double d = fabs(v3_dot(nrm, v3_sub(p[i], p[i0])));
        if (d > best) { best = d; i3 = i; }
    }
    if (i3 < 0 || best <= eps) { free(p); hull_fail(err, err_size, "hull points are coplanar (no volume)"); return NULL; }
    int cap = 64;
    tri *tris = malloc(sizeof *tris * (size_t)cap);
    edge_rec *edges = NULL;
    int ecap = 0, ntri = 0;
    if (!tris) { free(p); hull_fail(err, err_size, "out of memory"); return NULL; }
    int base[4][3] = {{i0, i1, i2}, {i0, i3, i1}, {i1, i3, i2}, {i2, i3, i0}};
    if (v3_dot(nrm, v3_sub(p[i3], p[i0])) > 0) {
        /* make every face point away from the fourth vertex */
        int flip[4][3] = {{i0, i2, i1}, {i0, i1, i3}, {i1, i2, i3}, {i2, i0, i3}};
        memcpy(base, flip, sizeof base);
    }
    for (int f = 0; f < 4; f++) {
        tris[ntri].v[0] = base[f][0]; tris[ntri].v[1] = base[f][1]; tris[ntri].v[2] = base[f][2];
        tris[ntri].alive = 1;
        tri_plane(&tris[ntri], p);
        ntri++;
    }
    for (int i = 0; i < count; i++) {
        if (i == i0 || i == i1 || i == i2 || i == i3) continue;
        int ne = 0, any = 0;
        for (int t = 0; t < ntri; t++) {
            if (!tris[t].alive || v3_dot(tris[t].n, p[i]) - tris[t].d <= eps) continue;
            any = 1;
            if (ne + 3 > ecap) {
                ecap = ecap ? ecap * 2 : 64;
                edge_rec *ne_ = realloc(edges, sizeof *edges * (size_t)ecap);
                if (!ne_) goto oom;
                edges = ne_;
            }
            for (int k = 0; k < 3; k++) { edges[ne].a = tris[t].v[k]; edges[ne].b = tris[t].v[(k + 1) % 3]; ne++; }
            tris[t].alive = 0;
        }
        if (!any) continue;
        /* horizon: edges of the visible region that appear once */
        qsort(edges, (size_t)ne, sizeof *edges, edge_cmp);
        for (int e = 0; e < ne; e++) {
            if ((e + 1 < ne && edge_cmp(&edges[e], &edges[e + 1]) == 0) || (e > 0 && edge_cmp(&edges[e], &edges[e - 1]) == 0))
                continue;
            if (ntri >= cap) {
                cap *= 2;
                tri *nt = realloc(tris, sizeof *tris * (size_t)cap);
                if (!nt) goto oom;
                tris = nt;
            }
            tris[ntri].v[0] = edges[e].a; tris[ntri].v[1] = edges[e].b; tris[ntri].v[2] = i;
            tris[ntri].alive = 1;
            tri_plane(&tris[ntri], p);
            ntri++;
        }
        /* compact dead triangles now and then so the scan stays short */
        if (ntri > 4 * count + 64) {
            int k = 0;
            for (int t = 0; t < ntri; t++) if (tris[t].alive) tris[k++] = tris[t];
            ntri = k;
        }
    }
    free(edges);
    edges = NULL;
    hull *h = hull_finish(p, tris, ntri, eps * 10);
    free(tris);
    free(p);
    if (!h) { hull_fail(err, err_size, "out of memory"); return NULL; }
    if (!(h->volume > 0)) { hull_free(h); hull_fail(err, err_size, "hull has no volume"); return NULL; }
    return h;
oom:
    free(edges);
    free(tris);
    free(p);
    hull_fail(err, err_size, "out of memory");
    return NULL;
}

hull *hull_make_box(vec3 he)
{
    double pts[24];
    for (int i = 0; i < 8; i++) {
        pts[3 * i] = (i & 1) ? he.x : -he.x;
        pts[3 * i + 1] = (i & 2) ? he.y : -he.y;
        pts[3 * i + 2] = (i & 4) ? he.z : -he.z;
    }
    return hull_build(pts, 8, NULL, 0);
}

void hull_free(hull *h)
{
    if (!h) return;
    free(h->vertices);
    free(h->faces);
    free(h->face_vertices);
    free(h->edges);
    free(h);
}

hull *hull_clone(const hull *h)
{
    if (!h) return NULL;
    hull *c = malloc(sizeof *c);
    if (!c) return NULL;
    *c = *h;
    int nfv = 0;
    for (int f = 0; f < h->face_count; f++) nfv = h->faces[f].first + h->faces[f].count > nfv ? h->faces[f].first + h->faces[f].count : nfv;
    c->vertices = malloc(sizeof *c->vertices * (size_t)h->vertex_count);
    c->faces = malloc(sizeof *c->faces * (size_t)h->face_count);
    c->face_vertices = malloc(sizeof *c->face_vertices * (size_t)(nfv > 0 ? nfv : 1));
    c->edges = malloc(sizeof *c->edges * (size_t)(h->edge_count > 0 ? h->edge_count : 1));
    if (!c->vertices || !c->faces || !c->face_vertices || !c->edges) { hull_free(c); return NULL; }
    memcpy(c->vertices, h->vertices, sizeof *c->vertices * (size_t)h->vertex_count);
    memcpy(c->faces, h->faces, sizeof *c->faces * (size_t)h->face_count);
    memcpy(c->face_vertices, h->face_vertices, sizeof *c->face_vertices * (size_t)nfv);
    memcpy(c->edges, h->edges, sizeof *c->edges * (size_t)h->edge_count);
    return c;
}

/* ---- ray casts --------------------------------------------------------------- */

/* Smallest t >= 0 with |o + t d|^2 = r^2 (ray from outside). */
static int ray_sphere(vec3 o, vec3 d, double r, double *t)
{
    double a = v3_dot(d, d), b = v3_dot(o, d), c = v3_dot(o, o) - r * r;
    if (c <= 0 || a <= 0) return 0; /* inside, or no direction */
    double disc = b * b - a * c;
    if (disc < 0 || b > 0) return 0;
    *t = (-b - sqrt(disc)) / a;
    return 1;
}

/* Ray against the infinite z-axis cylinder of radius r, limited to |z| <= hh. */
static int ray_cylinder_side(vec3 o, vec3 d, double r, double hh, double *t)
{
    double a = d.x * d.x + d.y * d.y, b = o.x * d.x + o.y * d.y, c = o.x * o.x + o.y * o.y - r * r;
    if (a <= 0 || c <= 0) return 0;
    double disc = b * b - a * c;
    if (disc < 0 || b > 0) return 0;
    double tt = (-b - sqrt(disc)) / a;
    if (fabs(o.z + tt * d.z) > hh) return 0;
    *t = tt;
    return 1;
}

/* Ray against the convex region {x: n_i . x <= d_i}: clip the parameter range. */
static int ray_planes(vec3 o, vec3 d, const vec3 *n, const double *off, int count, double max_t, double *t, vec3 *normal)
{
    double enter = 0.0, leave = max_t;
    int face = -1;
    for (int i = 0; i < count; i++) {
        double num = off[i] - v3_dot(n[i], o), den = v3_dot(n[i], d);
        if (den == 0) {
            if (num < 0) return 0;
            continue;
        }
        double s = num / den;
        if (den < 0) { if (s > enter) { enter = s; face = i; } }
        else if (s < leave) leave = s;
        if (enter > leave) return 0;
    }
    if (face < 0) return 0; /* started inside */
    *t = enter;
    *normal = n[face];
    return 1;
}

int shape_ray_cast_local(const shape *s, vec3 o, vec3 d, double max_t, double *t, vec3 *normal)
{
    double tt = 0;
    vec3 n = v3_zero();
    int hit = 0;
    switch (s->type) {
    case SHAPE_SPHERE:
        hit = ray_sphere(o, d, s->radius, &tt);
        if (hit) n = v3_normalize(v3_madd(o, tt, d));
        break;
    case SHAPE_BOX: {
        vec3 h = s->half_extents;
        vec3 ns[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        double off[6] = {h.x, h.x, h.y, h.y, h.z, h.z};
        hit = ray_planes(o, d, ns, off, 6, max_t, &tt, &n);
        break;
    }
    case SHAPE_CAPSULE: {
        double best = INFINITY, c;
        vec3 top = v3(0, 0, s->half_height), bot = v3(0, 0, -s->half_height);
        /* inside the capsule: no hit */
        double z = fmax(-s->half_height, fmin(s->half_height, o.z));
        if (v3_len2(v3_sub(o, v3(0, 0, z))) <= s->radius * s->radius) return 0;
        if (ray_cylinder_side(o, d, s->radius, s->half_height, &c) && c < best) {
            best = c;
            vec3 p = v3_madd(o, c, d);
            n = v3_normalize(v3(p.x, p.y, 0));
        }
        if (ray_sphere(v3_sub(o, top), d, s->radius, &c) && c < best) { best = c; n = v3_normalize(v3_sub(v3_madd(o, c, d), top)); }
        if (ray_sphere(v3_sub(o, bot), d, s->radius, &c) && c < best) { best = c; n = v3_normalize(v3_sub(v3_madd(o, c, d), bot)); }
        hit = best < INFINITY;
        tt = best;
        break;
    }
    case SHAPE_CYLINDER: {
        double best = INFINITY, c;
        if (fabs(o.z) <= s->half_height && o.x * o.x + o.y * o.y <= s->radius * s->radius) return 0;
        if (ray_cylinder_side(o, d, s->radius, s->half_height, &c) && c < best) {
            best = c;
            vec3 p = v3_madd(o, c, d);
            n = v3_normalize(v3(p.x, p.y, 0));
        }
        for (int side = -1; side <= 1; side += 2) {
            double hz = side * s->half_height;
            if (d.z == 0 || (o.z - hz) * side <= 0) continue;
            c = (hz - o.z) / d.z;
            vec3 p = v3_madd(o, c, d);
            if (c >= 0 && p.x * p.x + p.y * p.y <= s->radius * s->radius && c < best) { best = c; n = v3(0, 0, side); }
        }
        hit = best < INFINITY;
        tt = best;
        break;
    }
    case SHAPE_HULL: {
        const hull *h = s->hull;
        vec3 ns[256];
        double off[256];
        /* the face planes, in batches to bound stack use */
        if (h->face_count <= 256) {
            for (int i = 0; i < h->face_count; i++) { ns[i] = h->faces[i].normal; off[i] = h->faces[i].offset; }
            hit = ray_planes(o, d, ns, off, h->face_count, max_t, &tt, &n);
        } else {
            double enter = 0, leave = max_t;
            int face = -1;
            for (int i = 0; i < h->face_count; i++) {
                double num = h->faces[i].offset - v3_dot(h->faces[i].normal, o), den = v3_dot(h->faces[i].normal, d);
                if (den == 0) { if (num < 0) return 0; continue; }
                double sv = num / den;
                if (den < 0) { if (sv > enter) { enter = sv; face = i; } }
                else if (sv < leave) leave = sv;
                if (enter > leave) return 0;
            }
            if (face < 0) return 0;
            hit = 1;
            tt = enter;
            n = h->faces[face].normal;
        }
        break;
    }
    case SHAPE_PLANE: {
        double num = s->plane_offset - v3_dot(s->plane_normal, o), den = v3_dot(s->plane_normal, d);
        if (num >= 0 || den >= 0) return 0; /* starts inside the solid, or moves away */
        tt = num / den;
        n = s->plane_normal;
        hit = 1;
        break;
    }
    default:
        return 0;
    }
    if (!hit || tt < 0 || tt > max_t) return 0;
    *t = tt;
    *normal = n;
    return 1;
}
