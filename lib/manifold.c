/* manifold.c - building contact manifolds: polygon clipping against a
 * reference face and reduction to at most four points (deepest first, then
 * the largest area). */
#include "manifold.h"

int clip_polygon(const clip_vertex *in, int n, vec3 plane_n, double plane_d, uint32_t edge_tag, clip_vertex *out)
{
    /* Sutherland-Hodgman against one plane: keep dot(plane_n, p) <= plane_d */
    int m = 0;
    if (n == 0) return 0;
    /* each vertex's distance once: it is b's for one edge and a's for the next */
    double d0 = v3_dot(plane_n, in[0].p) - plane_d, da = d0;
    for (int i = 0; i < n; i++) {
        int last = i + 1 == n;
        const clip_vertex *a = &in[i], *b = last ? &in[0] : &in[i + 1];
        double db = last ? d0 : v3_dot(plane_n, b->p) - plane_d;
        if (da <= 0) out[m++] = *a;
        if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
            double t = da / (da - db);
            out[m].p = v3_lerp(a->p, b->p, t);
            /* a new point: its id names the incident edge (a's id) and the clip plane */
            out[m].id = (a->id & 0xffu) | 0x80u | (edge_tag << 8);
            m++;
        }
        da = db;
    }
    return m;
}

static double area2(vec3 a, vec3 b, vec3 c, vec3 n)
{
    return fabs(v3_dot(v3_cross(v3_sub(b, a), v3_sub(c, a)), n));
}

int manifold_reduce(manifold_point *pts, int n, vec3 normal)
{
    if (n <= MANIFOLD_MAX_POINTS) return n;
    manifold_point out[MANIFOLD_MAX_POINTS];
    int used[64] = {0};
    if (n > 64) n = 64;
    /* 1: deepest */
    int i0 = 0;
    for (int i = 1; i < n; i++)
        if (pts[i].separation < pts[i0].separation) i0 = i;
    used[i0] = 1;
    /* 2: farthest from it (in the contact plane) */
    int i1 = -1;
    double best = -1;
    for (int i = 0; i < n; i++) {
        if (used[i]) continue;
        vec3 d = v3_sub(pts[i].point, pts[i0].point);
        d = v3_madd(d, -v3_dot(d, normal), normal);
        if (v3_len2(d) > best) { best = v3_len2(d); i1 = i; }
    }
    used[i1] = 1;
    /* 3: largest triangle */
    int i2 = -1;
    best = -1;
    for (int i = 0; i < n; i++) {
        if (used[i]) continue;
        double a = area2(pts[i0].point, pts[i1].point, pts[i].point, normal);
        if (a > best) { best = a; i2 = i; }
    }
    used[i2] = 1;
    /* 4: the point that adds the most area to the triangle */
    int i3 = -1;
    best = -1;
    for (int i = 0; i < n; i++) {
        if (used[i]) continue;
        double a = dmax(area2(pts[i0].point, pts[i1].point, pts[i].point, normal),
                        dmax(area2(pts[i1].point, pts[i2].point, pts[i].point, normal),
                             area2(pts[i2].point, pts[i0].point, pts[i].point, normal)));
        if (a > best) { best = a; i3 = i; }
    }
    out[0] = pts[i0];
    out[1] = pts[i1];
    out[2] = pts[i2];
    out[3] = pts[i3];
    for (int i = 0; i < 4; i++) pts[i] = out[i];
    return 4;
}
