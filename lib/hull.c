/* hull.c - convex hull construction: quickhull with exact orientation
 * tests, then coplanar triangles merged into convex polygon faces; the
 * hull's mass properties, copies and the box hull. */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "hull.h"

/* Quickhull over triangles. Which faces a new point sees is decided by an
 * exact orientation test, so the triangles always form a consistent convex
 * surface, however nearly coplanar or duplicated the input. A tolerance
 * relative to the cloud's size decides the rest: points within it of the
 * hull are not added, and neighbouring triangles within it of a common plane
 * are merged into one polygon face. Merging follows the triangle adjacency,
 * so the polygons share their edges exactly. */

/* The tolerance, relative to the cloud's diagonal (1e-7 of a 1 m hull is 0.1
 * micrometre). A triangle's plane measures distances with an error of about
 * DBL_EPSILON * size^2 / height, so much below sqrt(DBL_EPSILON) most thin
 * triangles could no longer tell points within it from points outside. */
#define HULL_REL_TOLERANCE 1e-7

typedef struct qh_face {
    int v[3];          /* counter-clockwise seen from outside */
    int adj[3];        /* adj[k] lies across the edge v[k] -> v[k+1] */
    vec3 n;            /* outward unit normal */
    double d;          /* plane offset */
    int outside;       /* head of this face's outside-point list, -1 when empty */
    int far_point;     /* the outside point farthest above the face */
    double far_dist;
    int tested;        /* the eye stamp this face was last found hidden from */
    int visible;
    int alive;
    int sliver;        /* too thin for its plane to measure distances with */
} qh_face;

/* A horizon edge a -> b of the visible patch; the face outside it, and
 * which of its edges this is. */
typedef struct qh_edge { int a, b, outer, outer_edge; } qh_edge;

typedef struct quickhull {
    const vec3 *p;     /* points relative to the cloud's centre */
    int n;
    double eps;        /* distance below which a point counts as on a plane */
    double min_height; /* thinner triangles (height over the longest edge) are slivers */
    qh_face *f;
    int nf, fcap;
    int *next_out;     /* per point: next point of the same outside list */
    int *edge_from;    /* per point: horizon edge starting there, -1 */
    int *vis;          /* visible faces of the current eye */
    qh_edge *horizon, *loop;
    int *cone;         /* the faces made for the current eye */
    int *dead;         /* slots of removed faces, reused for new ones */
    int *pending;      /* queue of faces that may still have outside points */
    int vcap, hcap, lcap, ccap, dcap, pcap, ndead, npending, next_pending;
    int stamp;
} quickhull;

static void hull_fail(char *err, int n, const char *msg)
{
    if (err && n > 0) snprintf(err, (size_t)n, "%s", msg);
}

/* Unit normal of triangle abc (counter-clockwise), from its two shortest
 * edges, which meet at the vertex opposite the longest: the best conditioned. */
static vec3 tri_normal(vec3 a, vec3 b, vec3 c)
{
    vec3 ab = v3_sub(b, a), bc = v3_sub(c, b), ca = v3_sub(a, c);
    double lab = v3_len2(ab), lbc = v3_len2(bc), lca = v3_len2(ca);
    vec3 n;
    if (lab >= lbc && lab >= lca) n = v3_cross(bc, ca);       /* longest ab: edges at c */
    else if (lbc >= lca) n = v3_cross(ca, ab);                /* longest bc: edges at a */
    else n = v3_cross(ab, bc);                                /* longest ca: edges at b */
    return v3_normalize(n);
}

/* Exact orientation: the sign of ((b - a) x (c - a)) . (p - a), positive
 * when p is above the counter-clockwise triangle abc. The hull's topology
 * rests on these signs alone, so it is always a consistent convex surface
 * however nearly coplanar the points are; tolerances only decide which
 * points are worth adding and which faces are merged. */
static void two_sum(double a, double b, double *sum, double *err)
{
    double s = a + b, bv = s - a, av = s - bv;
    *sum = s;
    *err = (a - av) + (b - bv);
}

/* Adds b to the nonoverlapping expansion e[0..n) (components in increasing
 * magnitude, zeros dropped); returns its new length. */
static int expansion_add(double *e, int n, double b)
{
    int m = 0;
    double q = b;
    for (int i = 0; i < n; i++) {
        double sum, err;
        two_sum(q, e[i], &sum, &err);
        if (err != 0) e[m++] = err;
        q = sum;
    }
    if (q != 0) e[m++] = q;
    return m;
}

/* e += sign * u . (v x w), exactly: each product of three doubles is four
 * doubles exactly (fma gives a product's rounding error). */
static int expansion_add_det3(double *e, int n, vec3 u, vec3 v, vec3 w, double sign)
{
    const double t[6][3] = {{u.x, v.y, w.z}, {u.x, -v.z, w.y}, {u.y, v.z, w.x},
                            {u.y, -v.x, w.z}, {u.z, v.x, w.y}, {u.z, -v.y, w.x}};
    for (int k = 0; k < 6; k++) {
        double xy = t[k][0] * t[k][1], xy_err = fma(t[k][0], t[k][1], -xy);
        double hi = xy * t[k][2], lo = xy_err * t[k][2];
        n = expansion_add(e, n, sign * hi);
        n = expansion_add(e, n, sign * fma(xy, t[k][2], -hi));
        n = expansion_add(e, n, sign * lo);
        n = expansion_add(e, n, sign * fma(xy_err, t[k][2], -lo));
    }
    return n;
}

static int orient_sign(vec3 a, vec3 b, vec3 c, vec3 p)
{
    vec3 ab = v3_sub(b, a), ac = v3_sub(c, a), ap = v3_sub(p, a);
    double m0 = ac.y * ap.z - ac.z * ap.y, m1 = ac.z * ap.x - ac.x * ap.z, m2 = ac.x * ap.y - ac.y * ap.x;
    double det = ab.x * m0 + ab.y * m1 + ab.z * m2;
    double permanent = fabs(ab.x) * (fabs(ac.y * ap.z) + fabs(ac.z * ap.y)) +
                       fabs(ab.y) * (fabs(ac.z * ap.x) + fabs(ac.x * ap.z)) +
                       fabs(ab.z) * (fabs(ac.x * ap.y) + fabs(ac.y * ap.x));
    /* the rounding error of the line above is below 7 * 2^-53 * permanent (Shewchuk) */
    double bound = 8.0 * DBL_EPSILON * permanent;
    if (det > bound) return 1;
    if (det < -bound) return -1;
    /* exactly: ((b-a) x (c-a)).(p-a) = [b,c,p] - [a,c,p] + [a,b,p] - [a,b,c] */
    double e[100];
    int n = 0;
    n = expansion_add_det3(e, n, b, c, p, 1.0);
    n = expansion_add_det3(e, n, a, c, p, -1.0);
    n = expansion_add_det3(e, n, a, b, p, 1.0);
    n = expansion_add_det3(e, n, a, b, c, -1.0);
    return n == 0 ? 0 : (e[n - 1] > 0 ? 1 : -1);
}

static int qh_sees(const quickhull *q, int face, int point)
{
    const qh_face *f = &q->f[face];
    return orient_sign(q->p[f->v[0]], q->p[f->v[1]], q->p[f->v[2]], q->p[point]) > 0;
}

static void qh_plane(quickhull *q, qh_face *f)
{
    vec3 a = q->p[f->v[0]], b = q->p[f->v[1]], c = q->p[f->v[2]];
    f->n = tri_normal(a, b, c);
    f->d = (v3_dot(f->n, a) + v3_dot(f->n, b) + v3_dot(f->n, c)) / 3.0;
    double longest = sqrt(dmax(v3_len2(v3_sub(b, a)), dmax(v3_len2(v3_sub(c, b)), v3_len2(v3_sub(a, c)))));
    f->sliver = !(v3_len(v3_cross(v3_sub(b, a), v3_sub(c, a))) > q->min_height * longest);
}

static double qh_dist(const quickhull *q, int face, int point)
{
    return v3_dot(q->f[face].n, q->p[point]) - q->f[face].d;
}

static int qh_new_face(quickhull *q, int a, int b, int c)
{
    int slot;
    if (q->ndead > 0) {
        slot = q->dead[--q->ndead];
    } else {
        if (!array_reserve((void **)&q->f, &q->fcap, q->nf + 1, sizeof *q->f)) return -1;
        slot = q->nf++;
    }
    qh_face *f = &q->f[slot];
    memset(f, 0, sizeof *f);
    f->v[0] = a; f->v[1] = b; f->v[2] = c;
    f->adj[0] = f->adj[1] = f->adj[2] = -1;
    f->outside = f->far_point = -1;
    f->tested = -1;
    f->alive = 1;
    qh_plane(q, f);
    return slot;
}

/* Puts point i in the outside list of the face it lies farthest above among
 * faces[0..count) and the outer faces of the horizon edges given (within the
 * tolerance, a point can end up above a face next to a new cone without
 * being above the cone); drops it when it is above none (it is inside the
 * hull). Returns 0 when out of memory. */
static int qh_assign(quickhull *q, int i, const int *faces, int count, const qh_edge *horizon, int nh)
{
    int best = -1;
    double bd = q->eps;
    for (int k = 0; k < count + nh; k++) {
        int f = k < count ? faces[k] : horizon[k - count].outer;
        if (q->f[f].sliver) continue; /* its neighbours see such points just as well */
        double d = qh_dist(q, f, i);
        if (d > bd) { bd = d; best = f; }
    }
    if (best < 0) return 1;
    qh_face *f = &q->f[best];
    if (f->outside < 0) {
        if (!array_reserve((void **)&q->pending, &q->pcap, q->npending + 1, sizeof *q->pending)) return 0;
        q->pending[q->npending++] = best;
    }
    q->next_out[i] = f->outside;
    f->outside = i;
    if (f->far_point < 0 || bd > f->far_dist) { f->far_point = i; f->far_dist = bd; }
    return 1;
}

/* Takes point out of face's outside list and finds the list's new farthest. */
static void qh_drop_point(quickhull *q, int face, int point)
{
    qh_face *f = &q->f[face];
    int *link = &f->outside;
    while (*link >= 0 && *link != point) link = &q->next_out[*link];
    if (*link == point) *link = q->next_out[point];
    f->far_point = -1;
    for (int i = f->outside; i >= 0; i = q->next_out[i]) {
        double d = qh_dist(q, face, i);
        if (f->far_point < 0 || d > f->far_dist) { f->far_point = i; f->far_dist = d; }
    }
}

/* Adds the farthest outside point of face fi: removes the faces it sees and
 * closes the hole with a cone of triangles from the horizon to the point.
 * Returns 0 when out of memory. */
static int qh_add_point(quickhull *q, int fi)
{
    int eye = q->f[fi].far_point;
    int stamp = ++q->stamp;
    if (!array_reserve((void **)&q->vis, &q->vcap, q->nf, sizeof *q->vis)) return 0;
    if (!qh_sees(q, fi, eye)) {
        /* its distance above a nearly flat triangle was rounding */
        qh_drop_point(q, fi, eye);
        return 1;
    }
    /* the faces the eye sees form a connected patch around fi */
    int nvis = 0;
    q->vis[nvis++] = fi;
    q->f[fi].visible = 1;
    for (int i = 0; i < nvis; i++) {
        const qh_face *g = &q->f[q->vis[i]];
        for (int k = 0; k < 3; k++) {
            int h = g->adj[k];
            if (q->f[h].visible || q->f[h].tested == stamp) continue;
            if (qh_sees(q, h, eye)) {
                q->f[h].visible = 1;
                q->vis[nvis++] = h;
            } else {
                q->f[h].tested = stamp;
            }
        }
    }
    /* horizon edges, then chained into one loop */
    if (!array_reserve((void **)&q->horizon, &q->hcap, 3 * nvis, sizeof *q->horizon) ||
        !array_reserve((void **)&q->loop, &q->lcap, 3 * nvis, sizeof *q->loop))
        return 0;
    int nh = 0;
    for (int i = 0; i < nvis; i++) {
        const qh_face *g = &q->f[q->vis[i]];
        for (int k = 0; k < 3; k++) {
            int h = g->adj[k];
            if (q->f[h].visible) continue;
            qh_edge e = {g->v[k], g->v[(k + 1) % 3], h, 0};
            while (q->f[h].adj[e.outer_edge] != q->vis[i]) e.outer_edge++;
            q->horizon[nh++] = e;
        }
    }
    int simple = nh >= 3;
    for (int i = 0; i < nh; i++) {
        if (q->edge_from[q->horizon[i].a] >= 0) simple = 0;
        q->edge_from[q->horizon[i].a] = i;
    }
    int cur = 0;
    for (int i = 0; i < nh && simple; i++) {
        if (cur < 0 || (i > 0 && cur == 0)) { simple = 0; break; }
        q->loop[i] = q->horizon[cur];
        cur = q->edge_from[q->horizon[cur].b];
    }
    if (cur != 0) simple = 0;
    for (int i = 0; i < nh; i++) q->edge_from[q->horizon[i].a] = -1;
    if (!simple) {
        /* cannot happen with exact signs (the visible faces of a convex
         * surface form a disc); kept so that nothing can corrupt the hull */
        for (int i = 0; i < nvis; i++) q->f[q->vis[i]].visible = 0;
        qh_drop_point(q, fi, eye);
        return 1;
    }
    /* the cone (in slots of faces removed before: the visible ones still
     * hold their outside points) */
    if (!array_reserve((void **)&q->cone, &q->ccap, nh, sizeof *q->cone) ||
        !array_reserve((void **)&q->dead, &q->dcap, q->ndead + nvis, sizeof *q->dead))
        return 0;
    for (int i = 0; i < nh; i++)
        if ((q->cone[i] = qh_new_face(q, q->loop[i].a, q->loop[i].b, eye)) < 0) return 0;
    for (int i = 0; i < nh; i++) {
        qh_face *f = &q->f[q->cone[i]];
        f->adj[0] = q->loop[i].outer;
        f->adj[1] = q->cone[(i + 1) % nh];
        f->adj[2] = q->cone[(i + nh - 1) % nh];
        q->f[q->loop[i].outer].adj[q->loop[i].outer_edge] = q->cone[i];
    }
    /* the points the removed faces had outside go to the new faces */
    for (int i = 0; i < nvis; i++) {
        qh_face *g = &q->f[q->vis[i]];
        int pt = g->outside;
        g->alive = 0;
        g->visible = 0;
        g->outside = -1;
        q->dead[q->ndead++] = q->vis[i];
        while (pt >= 0) {
            int next = q->next_out[pt];
            if (pt != eye && !qh_assign(q, pt, q->cone, nh, q->loop, nh)) return 0;
            pt = next;
        }
    }
    return 1;
}

/* Polygon faces from the triangles: groups of coplanar neighbours, the
 * boundary loop of each group, and vertices lying on just two faces (on an
 * edge, not a corner) dropped. */
typedef struct merge_state {
    int nt;
    int *tri;          /* alive face index per compact triangle */
    int *compact;      /* face index -> compact triangle, -1 dead */
    int *group;
    int *single;       /* triangles that must stay alone (their group failed) */
    int *order, *queue;
    int *seed;         /* per group: the triangle whose plane it follows */
    int ngroups;
    int *loop_first, *loop_count, *loop_v; /* boundary loops per group */
} merge_state;

typedef struct area_index { double area; int index; } area_index;

static int area_desc(const void *x, const void *y)
{
    const area_index *a = x, *b = y;
    if (a->area != b->area) return a->area > b->area ? -1 : 1;
    return (a->index > b->index) - (a->index < b->index);
}

/* Groups neighbouring triangles whose corners lie within tol of the group's
 * seed plane, and finds each group's boundary loop. Returns 1 when every
 * group is a convex disc, 0 when some triangles had to be marked single (call
 * again), -1 when out of memory. */
static int merge_groups(quickhull *q, merge_state *m, double tol)
{
    int nt = m->nt;
    for (int t = 0; t < nt; t++) m->group[t] = -1;
    m->ngroups = 0;
    for (int s = 0; s < nt; s++) {
        int seed = m->order[s];
        if (m->group[seed] >= 0) continue;
        int g = m->ngroups++;
        m->group[seed] = g;
        m->seed[g] = seed;
        if (m->single[seed]) continue;
        const qh_face *sf = &q->f[m->tri[seed]];
        int head = 0, tail = 0;
        m->queue[tail++] = seed;
        while (head < tail) {
            const qh_face *f = &q->f[m->tri[m->queue[head++]]];
            for (int k = 0; k < 3; k++) {
                int u = m->compact[f->adj[k]];
                if (m->group[u] >= 0 || m->single[u]) continue;
                const qh_face *uf = &q->f[m->tri[u]];
                int flat = 1;
                for (int j = 0; j < 3; j++)
                    if (fabs(v3_dot(sf->n, q->p[uf->v[j]]) - sf->d) > tol) flat = 0;
                if (!flat) continue;
                m->group[u] = g;
                m->queue[tail++] = u;
            }
        }
    }
    /* boundary half-edges per group, by counting sort */
    int ng = m->ngroups;
    int *cnt = calloc((size_t)ng + 1, sizeof *cnt);
    int *he = malloc(sizeof *he * (size_t)(3 * nt) * 2);
    free(m->loop_first); free(m->loop_count); free(m->loop_v);
    m->loop_first = malloc(sizeof *m->loop_first * (size_t)ng);
    m->loop_count = malloc(sizeof *m->loop_count * (size_t)ng);
    m->loop_v = malloc(sizeof *m->loop_v * (size_t)(3 * nt));
    if (!cnt || !he || !m->loop_first || !m->loop_count || !m->loop_v) { free(cnt); free(he); return -1; }
    for (int t = 0; t < nt; t++) {
        const qh_face *f = &q->f[m->tri[t]];
        for (int k = 0; k < 3; k++)
            if (m->group[m->compact[f->adj[k]]] != m->group[t]) cnt[m->group[t] + 1]++;
    }
    for (int g = 0; g < ng; g++) cnt[g + 1] += cnt[g];
    for (int g = 0; g < ng; g++) { m->loop_first[g] = cnt[g]; m->loop_count[g] = 0; }
    for (int t = 0; t < nt; t++) {
        const qh_face *f = &q->f[m->tri[t]];
        int g = m->group[t];
        for (int k = 0; k < 3; k++)
            if (m->group[m->compact[f->adj[k]]] != g) {
                int at = m->loop_first[g] + m->loop_count[g]++;
                he[2 * at] = f->v[k];
                he[2 * at + 1] = f->v[(k + 1) % 3];
            }
    }
    int ok = 1;
    for (int g = 0; g < ng; g++) {
        int first = m->loop_first[g], count = m->loop_count[g], disc = count >= 3;
        for (int i = first; i < first + count; i++) {
            if (q->edge_from[he[2 * i]] >= 0) disc = 0;
            q->edge_from[he[2 * i]] = i;
        }
        int cur = first;
        for (int i = 0; i < count && disc; i++) {
            if (cur < 0 || (i > 0 && cur == first)) { disc = 0; break; }
            m->loop_v[first + i] = he[2 * cur];
            cur = q->edge_from[he[2 * cur + 1]];
        }
        if (cur != first) disc = 0;
        for (int i = first; i < first + count; i++) q->edge_from[he[2 * i]] = -1;
        if (!disc) {
            /* not a disc (never seen): every triangle of the group stays alone */
            ok = 0;
            for (int t = 0; t < nt; t++) if (m->group[t] == g) m->single[t] = 1;
            continue;
        }
        /* The polygon must be convex: no corner farther than the tolerance
         * inside the line through its neighbours. A notch means a slightly
         * tilted neighbour reaches into the plane; the group's triangles at
         * that corner then stay alone. */
        vec3 n = q->f[m->tri[m->seed[g]]].n;
        for (int i = 0; i < count; i++) {
            int corner = m->loop_v[first + i];
            vec3 a = q->p[m->loop_v[first + (i + count - 1) % count]], b = q->p[corner];
            vec3 c = q->p[m->loop_v[first + (i + 1) % count]];
            if (v3_dot(v3_cross(v3_sub(b, a), v3_sub(c, b)), n) >= -tol * v3_len(v3_sub(c, a))) continue;
            ok = 0;
            for (int t = 0; t < nt; t++) {
                const int *v = q->f[m->tri[t]].v;
                if (m->group[t] == g && (v[0] == corner || v[1] == corner || v[2] == corner)) m->single[t] = 1;
            }
        }
    }
    free(cnt);
    free(he);
    return ok;
}

/* Volume, centroid and inertia about the centroid (density 1) of the closed
 * polyhedron, by tetrahedra from an interior reference point to a fan of
 * each face. */
static void hull_mass(hull *h)
{
    vec3 ref = v3_zero();
    for (int i = 0; i < h->vertex_count; i++) ref = v3_add(ref, h->vertices[i]);
    ref = v3_scale(ref, 1.0 / h->vertex_count);
    double vol = 0, cov[3][3] = {{0}};
    vec3 cen = v3_zero();
    for (int f = 0; f < h->face_count; f++) {
        const hull_face *F = &h->faces[f];
        vec3 a = v3_sub(h->vertices[h->face_vertices[F->first]], ref);
        for (int k = 1; k + 1 < F->count; k++) {
            vec3 b = v3_sub(h->vertices[h->face_vertices[F->first + k]], ref);
            vec3 c = v3_sub(h->vertices[h->face_vertices[F->first + k + 1]], ref);
            double det = v3_dot(a, v3_cross(b, c)); /* six times the signed volume */
            vec3 s = v3_add(v3_add(a, b), c);
            vol += det / 6.0;
            cen = v3_madd(cen, det / 24.0, s);
            /* second moment of tetrahedron (0, a, b, c):
             * det/120 * (s s^T + a a^T + b b^T + c c^T) */
            double S[3] = {s.x, s.y, s.z}, A[3] = {a.x, a.y, a.z}, B[3] = {b.x, b.y, b.z}, C[3] = {c.x, c.y, c.z};
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    cov[i][j] += det / 120.0 * (S[i] * S[j] + A[i] * A[j] + B[i] * B[j] + C[i] * C[j]);
        }
    }
    vec3 com = v3_scale(cen, 1.0 / vol);
    double c3[3] = {com.x, com.y, com.z};
    /* second moment about the centroid, then I = tr(C) 1 - C */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) cov[i][j] -= vol * c3[i] * c3[j];
    double tr = cov[0][0] + cov[1][1] + cov[2][2];
    h->unit_inertia = m3_cols(v3(tr - cov[0][0], -cov[1][0], -cov[2][0]), v3(-cov[0][1], tr - cov[1][1], -cov[2][1]),
                              v3(-cov[0][2], -cov[1][2], tr - cov[2][2]));
    h->volume = vol;
    h->centroid = v3_add(ref, com);
}

/* Builds the hull's arrays from the merged loops; orig are the caller's
 * points. A loop vertex is a corner of the hull when it lies on three or
 * more faces. On just two it lies on their common edge and is left out,
 * unless the two faces are coplanar (where a group had to be split): then it
 * is a corner of both. */
static hull *hull_from_loops(const quickhull *q, const merge_state *m, const vec3 *orig, double tol, char *err, int err_size)
{
    int ng = m->ngroups, n = q->n;
    int *faces_at = calloc((size_t)n, sizeof *faces_at), *newidx = malloc(sizeof *newidx * (size_t)n);
    char *corner = calloc((size_t)n, 1);
    hull *h = calloc(1, sizeof *h);
    if (!faces_at || !newidx || !corner || !h) goto oom;
    for (int g = 0; g < ng; g++)
        for (int i = 0; i < m->loop_count[g]; i++) faces_at[m->loop_v[m->loop_first[g] + i]]++;
    for (int g = 0; g < ng; g++) {
        const int *lv = &m->loop_v[m->loop_first[g]];
        int count = m->loop_count[g];
        for (int i = 0; i < count; i++) {
            vec3 a = q->p[lv[(i + count - 1) % count]], b = q->p[lv[i]], c = q->p[lv[(i + 1) % count]];
            if (faces_at[lv[i]] > 2 || v3_len(v3_cross(v3_sub(b, a), v3_sub(c, a))) > tol * v3_len(v3_sub(c, a)))
                corner[lv[i]] = 1;
        }
    }
    /* A face thinner than the tolerance keeps only two corners: it is left
     * out, and its neighbours on either side meet along those two. */
    int total = 0;
    for (int g = 0; g < ng; g++) {
        int kept = 0;
        for (int i = 0; i < m->loop_count[g]; i++) kept += corner[m->loop_v[m->loop_first[g] + i]];
        if (kept == 1) {
            hull_fail(err, err_size, "hull points are numerically degenerate (a face with one corner)");
            goto fail;
        }
        total += kept > 2 ? kept : 0;
    }
    h->faces = malloc(sizeof *h->faces * (size_t)ng);
    h->face_vertices = malloc(sizeof *h->face_vertices * (size_t)total);
    h->edges = malloc(sizeof *h->edges * (size_t)total);
    if (!h->faces || !h->face_vertices || !h->edges) goto oom;
    for (int i = 0; i < n; i++) newidx[i] = -1;
    int nv = 0, fv = 0, nf = 0;
    for (int g = 0; g < ng; g++) {
        int kept = 0;
        for (int i = 0; i < m->loop_count[g]; i++) kept += corner[m->loop_v[m->loop_first[g] + i]];
        if (kept < 3) continue;
        hull_face *F = &h->faces[nf++];
        F->first = fv;
        for (int i = 0; i < m->loop_count[g]; i++) {
            int v = m->loop_v[m->loop_first[g] + i];
            if (!corner[v]) continue;
            if (newidx[v] < 0) newidx[v] = nv++;
            h->face_vertices[fv++] = newidx[v];
        }
        F->count = fv - F->first;
    }
    h->face_count = nf;
    h->vertex_count = nv;
    h->vertices = malloc(sizeof *h->vertices * (size_t)nv);
    if (!h->vertices) goto oom;
    for (int i = 0; i < n; i++)
        if (newidx[i] >= 0) h->vertices[newidx[i]] = orig[i];
    /* planes: Newell's normal of each polygon (about its centre, where
     * rounding is smallest), offset as the mean over its corners */
    for (int g = 0; g < nf; g++) {
        hull_face *F = &h->faces[g];
        vec3 c = v3_zero(), nn = v3_zero();
        int *idx = &h->face_vertices[F->first];
        for (int i = 0; i < F->count; i++) c = v3_add(c, h->vertices[idx[i]]);
        c = v3_scale(c, 1.0 / F->count);
        for (int i = 0; i < F->count; i++) {
            vec3 a = v3_sub(h->vertices[idx[i]], c), b = v3_sub(h->vertices[idx[(i + 1) % F->count]], c);
            nn = v3_add(nn, v3_cross(a, b));
        }
        F->normal = v3_normalize(nn);
        double d = 0;
        for (int i = 0; i < F->count; i++) d += v3_dot(F->normal, h->vertices[idx[i]]);
        F->offset = d / F->count;
        for (int i = 0; i < F->count; i++) {
            int a = idx[i], b = idx[(i + 1) % F->count];
            if (a < b) { h->edges[h->edge_count][0] = a; h->edges[h->edge_count][1] = b; h->edge_count++; }
        }
    }
    free(faces_at);
    free(newidx);
    free(corner);
    hull_mass(h);
    if (!(h->volume > 0) || !v3_is_finite(h->centroid)) {
        hull_fail(err, err_size, "hull has no volume");
        hull_free(h);
        return NULL;
    }
    return h;
oom:
    hull_fail(err, err_size, "out of memory");
fail:
    free(faces_at);
    free(newidx);
    free(corner);
    hull_free(h);
    return NULL;
}

static void quickhull_free(quickhull *q)
{
    free(q->f);
    free(q->next_out);
    free(q->edge_from);
    free(q->vis);
    free(q->horizon);
    free(q->loop);
    free(q->cone);
    free(q->dead);
    free(q->pending);
}

static void merge_free(merge_state *m)
{
    free(m->tri); free(m->compact); free(m->group); free(m->single);
    free(m->order); free(m->queue); free(m->seed);
    free(m->loop_first); free(m->loop_count); free(m->loop_v);
}

/* The first tetrahedron: the farthest pair among the axis extremes, the
 * point farthest from their line, the point farthest from that plane.
 * Returns 1, 0 for degenerate points (message in err), -1 out of memory. */
static int qh_start(quickhull *q, char *err, int err_size)
{
    const vec3 *p = q->p;
    int ext[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 1; i < q->n; i++)
        for (int a = 0; a < 3; a++) {
            if (v3_get(p[i], a) < v3_get(p[ext[2 * a]], a)) ext[2 * a] = i;
            if (v3_get(p[i], a) > v3_get(p[ext[2 * a + 1]], a)) ext[2 * a + 1] = i;
        }
    int i0 = ext[0], i1 = ext[1];
    double best = -1;
    for (int a = 0; a < 6; a++)
        for (int b = a + 1; b < 6; b++) {
            double d = v3_len2(v3_sub(p[ext[a]], p[ext[b]]));
            if (d > best) { best = d; i0 = ext[a]; i1 = ext[b]; }
        }
    if (sqrt(best) <= q->eps) return hull_fail(err, err_size, "hull points are all the same point (duplicates only)"), 0;
    vec3 axis = v3_normalize(v3_sub(p[i1], p[i0]));
    int i2 = 0;
    best = -1;
    for (int i = 0; i < q->n; i++) {
        double d = v3_len(v3_cross(axis, v3_sub(p[i], p[i0])));
        if (d > best) { best = d; i2 = i; }
    }
    if (best <= q->eps) return hull_fail(err, err_size, "hull points are collinear (no area, no volume)"), 0;
    vec3 normal = tri_normal(p[i0], p[i1], p[i2]);
    int i3 = 0;
    best = -1;
    for (int i = 0; i < q->n; i++) {
        double d = fabs(v3_dot(normal, v3_sub(p[i], p[i0])));
        if (d > best) { best = d; i3 = i; }
    }
    if (best <= q->eps) return hull_fail(err, err_size, "hull points are coplanar (no volume)"), 0;
    /* base (a, b, c) faces away from the apex d; the sides run each base edge backwards */
    int up = orient_sign(p[i0], p[i1], p[i2], p[i3]) > 0;
    int a = i0, b = up ? i2 : i1, c = up ? i1 : i2, d = i3;
    int tet[4][3] = {{a, b, c}, {b, a, d}, {c, b, d}, {a, c, d}};
    for (int f = 0; f < 4; f++)
        if (qh_new_face(q, tet[f][0], tet[f][1], tet[f][2]) < 0) return -1;
    for (int f = 0; f < 4; f++)
        for (int k = 0; k < 3; k++)
            for (int g = 0; g < 4; g++)
                for (int j = 0; j < 3; j++)
                    if (q->f[g].v[j] == q->f[f].v[(k + 1) % 3] && q->f[g].v[(j + 1) % 3] == q->f[f].v[k]) q->f[f].adj[k] = g;
    const int first4[4] = {0, 1, 2, 3};
    for (int i = 0; i < q->n; i++)
        if (i != a && i != b && i != c && i != d && !qh_assign(q, i, first4, 4, NULL, 0)) return -1;
    return 1;
}

/* Compact triangle numbering for merging, largest first so that the seed
 * planes are the best conditioned. Returns 0 when out of memory. */
static int merge_init(merge_state *m, const quickhull *q)
{
    int nt = 0;
    for (int f = 0; f < q->nf; f++) nt += q->f[f].alive;
    m->nt = nt;
    m->tri = malloc(sizeof *m->tri * (size_t)nt);
    m->compact = malloc(sizeof *m->compact * (size_t)q->nf);
    m->group = malloc(sizeof *m->group * (size_t)nt);
    m->single = calloc((size_t)nt, sizeof *m->single);
    m->order = malloc(sizeof *m->order * (size_t)nt);
    m->queue = malloc(sizeof *m->queue * (size_t)nt);
    m->seed = malloc(sizeof *m->seed * (size_t)nt);
    area_index *ai = malloc(sizeof *ai * (size_t)nt);
    if (!m->tri || !m->compact || !m->group || !m->single || !m->order || !m->queue || !m->seed || !ai) {
        free(ai);
        return 0;
    }
    nt = 0;
    for (int f = 0; f < q->nf; f++) {
        m->compact[f] = q->f[f].alive ? nt : -1;
        if (!q->f[f].alive) continue;
        const int *v = q->f[f].v;
        ai[nt].area = v3_len(v3_cross(v3_sub(q->p[v[1]], q->p[v[0]]), v3_sub(q->p[v[2]], q->p[v[0]])));
        ai[nt].index = nt;
        m->tri[nt++] = f;
    }
    qsort(ai, (size_t)nt, sizeof *ai, area_desc);
    for (int t = 0; t < nt; t++) m->order[t] = ai[t].index;
    free(ai);
    return 1;
}

hull *hull_build(const double *points, int count, char *err, int err_size)
{
    if (!points || count < 4) { hull_fail(err, err_size, "a hull needs at least 4 points"); return NULL; }
    for (size_t i = 0; i < 3 * (size_t)count; i++)
        if (!isfinite(points[i])) { hull_fail(err, err_size, "hull points must be finite (NaN or infinity given)"); return NULL; }
    vec3 *orig = malloc(sizeof *orig * (size_t)count), *p = malloc(sizeof *p * (size_t)count);
    quickhull q;
    merge_state m;
    memset(&q, 0, sizeof q);
    memset(&m, 0, sizeof m);
    hull *h = NULL;
    int started, merged;
    if (!orig || !p) goto oom;
    vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < count; i++) {
        orig[i] = v3(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
        lo = v3_min(lo, orig[i]);
        hi = v3_max(hi, orig[i]);
    }
    double size = v3_len(v3_sub(hi, lo)), far = v3_len(v3_max(v3_abs(lo), v3_abs(hi)));
    /* keeps the exact predicate's products of three coordinates clear of
     * overflow and underflow */
    if (far > 1e50) { hull_fail(err, err_size, "hull points must lie within 1e50 of the origin"); goto done; }
    if (size < 1e-50) { hull_fail(err, err_size, "hull points are all the same point (duplicates only)"); goto done; }
    /* work relative to the centre of the bounds: far from the origin, plane
     * offsets would otherwise lose the digits that tell points apart */
    vec3 centre = v3_scale(v3_add(lo, hi), 0.5);
    for (int i = 0; i < count; i++) {
        p[i] = v3_sub(orig[i], centre);
        double noise = 1e-30 * size; /* exactly zero below this */
        if (fabs(p[i].x) < noise) p[i].x = 0;
        if (fabs(p[i].y) < noise) p[i].y = 0;
        if (fabs(p[i].z) < noise) p[i].z = 0;
    }
    q.p = p;
    q.n = count;
    q.eps = HULL_REL_TOLERANCE * size + 16.0 * DBL_EPSILON * far;
    /* a triangle's normal is good to about DBL_EPSILON * size / height; from
     * this height on, its distances over the cloud are good to within eps */
    q.min_height = 8.0 * DBL_EPSILON * size * size / q.eps;
    q.next_out = malloc(sizeof *q.next_out * (size_t)count);
    q.edge_from = malloc(sizeof *q.edge_from * (size_t)count);
    if (!q.next_out || !q.edge_from) goto oom;
    for (int i = 0; i < count; i++) q.edge_from[i] = -1;
    started = qh_start(&q, err, err_size);
    if (started < 0) goto oom;
    if (started == 0) goto done;
    /* first come, first served: the hull grows evenly (much faster than
     * depth first on large clouds) */
    while (q.next_pending < q.npending) {
        int fi = q.pending[q.next_pending++];
        while (q.f[fi].alive && q.f[fi].outside >= 0)
            if (!qh_add_point(&q, fi)) goto oom;
    }
    if (!merge_init(&m, &q)) goto oom;
    while ((merged = merge_groups(&q, &m, 2.0 * q.eps)) == 0) {}
    if (merged < 0) goto oom;
    h = hull_from_loops(&q, &m, orig, 2.0 * q.eps, err, err_size);
    goto done;
oom:
    hull_fail(err, err_size, "out of memory");
done:
    quickhull_free(&q);
    merge_free(&m);
    free(orig);
    free(p);
    return h;
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
    if (h->shares > 0) {
        h->shares--;
        return;
    }
    free(h->vertices);
    free(h->faces);
    free(h->face_vertices);
    free(h->edges);
    free(h);
}

hull *hull_share(hull *h)
{
    h->shares++;
    return h;
}

hull *hull_clone(const hull *h)
{
    if (!h) return NULL;
    hull *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    int nfv = 0;
    for (int f = 0; f < h->face_count; f++)
        if (h->faces[f].first + h->faces[f].count > nfv) nfv = h->faces[f].first + h->faces[f].count;
    c->vertices = malloc(sizeof *c->vertices * (size_t)(h->vertex_count > 0 ? h->vertex_count : 1));
    c->faces = malloc(sizeof *c->faces * (size_t)(h->face_count > 0 ? h->face_count : 1));
    c->face_vertices = malloc(sizeof *c->face_vertices * (size_t)(nfv > 0 ? nfv : 1));
    c->edges = malloc(sizeof *c->edges * (size_t)(h->edge_count > 0 ? h->edge_count : 1));
    if (!c->vertices || !c->faces || !c->face_vertices || !c->edges) { hull_free(c); return NULL; }
    memcpy(c->vertices, h->vertices, sizeof *c->vertices * (size_t)h->vertex_count);
    memcpy(c->faces, h->faces, sizeof *c->faces * (size_t)h->face_count);
    memcpy(c->face_vertices, h->face_vertices, sizeof *c->face_vertices * (size_t)nfv);
    memcpy(c->edges, h->edges, sizeof *c->edges * (size_t)h->edge_count);
    c->vertex_count = h->vertex_count;
    c->face_count = h->face_count;
    c->edge_count = h->edge_count;
    c->centroid = h->centroid;
    c->volume = h->volume;
    c->unit_inertia = h->unit_inertia;
    return c;
}
