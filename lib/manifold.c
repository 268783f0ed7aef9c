/* manifold.c - building contact manifolds: polygon clipping against a
 * reference face and reduction to at most four points (deepest first, or on
 * a flat face the farthest from its centre, then the largest area). */
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

/* Within a relative MANIFOLD_TIE two scores tie and the earlier point (in
 * the clipper's order, which follows the features) stays: a symmetric face
 * (two concentric squares, one turned: eight points the same distance from
 * the centre) has candidates whose scores differ by rounding, or by the
 * micrometres a rock shifts the face, and the pick must not follow them
 * from step to step (at 1e-6 a 1e-5 rad rock still swapped them). */
#define MANIFOLD_TIE 1e-3
static int better_pick(double v, double best) { return v > best * (1.0 + MANIFOLD_TIE); }

/* A face whose points' depths spread less than MANIFOLD_FLAT times its size
 * (tilted by less than a milliradian) starts from its point farthest from
 * the centre in the contact plane, not from its deepest: the depths there
 * are the bodies' rocking, micrometres, and two turned faces (8 points, two
 * near each corner) swapped their kept points with every rock; a column of
 * 10 boxes offset up to 2 mm and turned up to 1.1 degrees swayed and walked
 * (the top box's mean sideways walk after 10 s, 64 seeds, fast / default /
 * accurate: 4.70 / 5.35 / 0.96 cm; with this 4.32 / 3.25 / 0.30). A face
 * tilted more keeps its deepest point (test_narrowphase checks it has the
 * separating axis' depth). Every later pick is in the plane alone. */
#define MANIFOLD_FLAT 1e-3

int manifold_reduce(manifold_point *pts, int n, vec3 normal)
{
    if (n <= MANIFOLD_MAX_POINTS) return n;
    manifold_point out[MANIFOLD_MAX_POINTS];
    int used[64] = {0};
    if (n > 64) n = 64;
    /* 1: deepest, or on a flat face the farthest from the centre */
    int i0 = 0;
    double shallow = pts[0].separation;
    vec3 c = v3_zero();
    for (int i = 0; i < n; i++) {
        if (pts[i].separation < pts[i0].separation) i0 = i;
        shallow = dmax(shallow, pts[i].separation);
        c = v3_add(c, pts[i].point);
    }
    c = v3_scale(c, 1.0 / n);
    double r2[64], size2 = 0.0;
    for (int i = 0; i < n; i++) {
        vec3 d = v3_sub(pts[i].point, c);
        d = v3_madd(d, -v3_dot(d, normal), normal);
        r2[i] = v3_len2(d);
        size2 = dmax(size2, r2[i]);
    }
    double spread = shallow - pts[i0].separation;
    if (spread * spread <= MANIFOLD_FLAT * MANIFOLD_FLAT * size2) {
        /* the first point within MANIFOLD_TIE of the farthest */
        for (i0 = 0; r2[i0] < size2 * (1.0 - MANIFOLD_TIE); i0++) {}
    }
    used[i0] = 1;
    /* 2: farthest from it (in the contact plane) */
    int i1 = -1;
    double best = -1;
    for (int i = 0; i < n; i++) {
        if (used[i]) continue;
        vec3 d = v3_sub(pts[i].point, pts[i0].point);
        d = v3_madd(d, -v3_dot(d, normal), normal);
        if (i1 < 0 || better_pick(v3_len2(d), best)) { best = v3_len2(d); i1 = i; }
    }
    used[i1] = 1;
    /* 3: largest triangle */
    int i2 = -1;
    best = -1;
    for (int i = 0; i < n; i++) {
        if (used[i]) continue;
        double a = area2(pts[i0].point, pts[i1].point, pts[i].point, normal);
        if (i2 < 0 || better_pick(a, best)) { best = a; i2 = i; }
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
        if (i3 < 0 || better_pick(a, best)) { best = a; i3 = i; }
    }
    out[0] = pts[i0];
    out[1] = pts[i1];
    out[2] = pts[i2];
    out[3] = pts[i3];
    for (int i = 0; i < 4; i++) pts[i] = out[i];
    return 4;
}
