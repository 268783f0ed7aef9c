/* gjk.c - GJK distance (closest point of the Minkowski difference A - B to the
 * origin, sub-simplex by Voronoi regions) and a shape cast by conservative
 * advancement on it. See gjk.h. */
#include "gjk.h"

#define GJK_MAX_ITERATIONS 96
#define CAST_MAX_ITERATIONS 64
/* relative gap between the upper (|v|) and lower (v.w / |v|) bound on the
 * distance at which GJK stops: far below what any caller can notice */
#define GJK_RELATIVE_TOLERANCE 1e-12
#define GJK_MAX_RESTARTS 4
#define GJK_RESTART_GAP 1e-9

typedef struct simplex_vertex {
    vec3 a, b, w; /* support points of A and B, and w = a - b */
} simplex_vertex;

typedef struct simplex {
    simplex_vertex v[4];
    double bary[4];
    int count;
} simplex;

double gjk_core_radius(const gjk_proxy *p)
{
    if (!p->s) return 0.0;
    return p->s->type == SHAPE_SPHERE || p->s->type == SHAPE_CAPSULE ? p->s->radius : 0.0;
}

/* Bounding radius of a proxy about its frame's origin. */
static double proxy_radius(const gjk_proxy *p)
{
    if (p->s) return shape_bounding_radius(p->s);
    double r2 = 0;
    for (int i = 0; i < p->point_count; i++) r2 = dmax(r2, v3_len2(p->points[i]));
    return sqrt(r2);
}

static vec3 core_support_local(const shape *s, vec3 d)
{
    switch (s->type) {
    case SHAPE_SPHERE: return v3_zero();
    case SHAPE_CAPSULE: return v3(0, 0, d.z >= 0 ? s->half_height : -s->half_height);
    default: return shape_support_local(s, d);
    }
}

vec3 gjk_core_support(const gjk_proxy *p, vec3 dir)
{
    vec3 d = q_inv_rotate(p->x.q, dir);
    if (p->s) return xf_point(p->x, core_support_local(p->s, d));
    int best = 0;
    for (int i = 1; i < p->point_count; i++)
        if (v3_dot(p->points[i], d) > v3_dot(p->points[best], d)) best = i;
    return xf_point(p->x, p->points[best]);
}

static simplex_vertex support_vertex(const gjk_proxy *a, const gjk_proxy *b, vec3 dir)
{
    simplex_vertex v;
    v.a = gjk_core_support(a, v3_neg(dir));
    v.b = gjk_core_support(b, dir);
    v.w = v3_sub(v.a, v.b);
    return v;
}

static void keep(simplex *s, int i0, double b0)
{
    s->v[0] = s->v[i0];
    s->bary[0] = b0;
    s->count = 1;
}

static void solve_segment(simplex *s)
{
    vec3 a = s->v[0].w, ab = v3_sub(s->v[1].w, a);
    double len2 = v3_len2(ab);
    double t = len2 > 0 ? -v3_dot(a, ab) / len2 : 0.0;
    if (t <= 0) keep(s, 0, 1.0);
    else if (t >= 1) keep(s, 1, 1.0);
    else { s->bary[0] = 1.0 - t; s->bary[1] = t; }
}

/* Closest point of triangle (i0, i1, i2) to the origin, by Voronoi regions
 * (Ericson, Real-Time Collision Detection, 5.1.5); writes the reduced
 * sub-simplex into out. */
static void closest_triangle(const simplex *in, int i0, int i1, int i2, simplex *out)
{
    vec3 a = in->v[i0].w, b = in->v[i1].w, c = in->v[i2].w;
    vec3 ab = v3_sub(b, a), ac = v3_sub(c, a);
    double d1 = -v3_dot(ab, a), d2 = -v3_dot(ac, a);
    out->count = 0;
    if (d1 <= 0 && d2 <= 0) { out->v[0] = in->v[i0]; out->bary[0] = 1; out->count = 1; return; }
    double d3 = -v3_dot(ab, b), d4 = -v3_dot(ac, b);
    if (d3 >= 0 && d4 <= d3) { out->v[0] = in->v[i1]; out->bary[0] = 1; out->count = 1; return; }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double t = d1 / (d1 - d3);
        out->v[0] = in->v[i0]; out->v[1] = in->v[i1];
        out->bary[0] = 1 - t; out->bary[1] = t; out->count = 2;
        return;
    }
    double d5 = -v3_dot(ab, c), d6 = -v3_dot(ac, c);
    if (d6 >= 0 && d5 <= d6) { out->v[0] = in->v[i2]; out->bary[0] = 1; out->count = 1; return; }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double t = d2 / (d2 - d6);
        out->v[0] = in->v[i0]; out->v[1] = in->v[i2];
        out->bary[0] = 1 - t; out->bary[1] = t; out->count = 2;
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        out->v[0] = in->v[i1]; out->v[1] = in->v[i2];
        out->bary[0] = 1 - t; out->bary[1] = t; out->count = 2;
        return;
    }
    double sum = va + vb + vc;
    double v = sum != 0 ? vb / sum : 1.0 / 3.0, w = sum != 0 ? vc / sum : 1.0 / 3.0;
    out->v[0] = in->v[i0]; out->v[1] = in->v[i1]; out->v[2] = in->v[i2];
    out->bary[0] = 1 - v - w; out->bary[1] = v; out->bary[2] = w; out->count = 3;
}

static vec3 simplex_point(const simplex *s)
{
    vec3 p = v3_zero();
    for (int i = 0; i < s->count; i++) p = v3_madd(p, s->bary[i], s->v[i].w);
    return p;
}

/* Reduces a tetrahedron to the face nearest the origin; returns 1 when the
 * origin is inside it (the shapes overlap). */
static int solve_tetrahedron(simplex *s)
{
    static const int faces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
    double best = INFINITY;
    simplex best_s = *s;
    int outside_any = 0;
    /* a nearly flat tetrahedron (the new point almost in the old triangle's
     * plane, as when GJK converges) decides "inside" by rounding: then every
     * face is a candidate and the origin is never declared inside */
    vec3 e1 = v3_sub(s->v[1].w, s->v[0].w), e2 = v3_sub(s->v[2].w, s->v[0].w), e3 = v3_sub(s->v[3].w, s->v[0].w);
    double size = dmax(v3_len2(e1), dmax(v3_len2(e2), v3_len2(e3)));
    int flat = fabs(v3_dot(e1, v3_cross(e2, e3))) <= 1e-9 * size * sqrt(size);
    for (int f = 0; f < 4; f++) {
        vec3 a = s->v[faces[f][0]].w, b = s->v[faces[f][1]].w, c = s->v[faces[f][2]].w;
        vec3 d = s->v[faces[f][3]].w;
        vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
        double side_o = -v3_dot(a, n), side_d = v3_dot(v3_sub(d, a), n);
        /* the origin is beyond this face (opposite the fourth vertex), or the
         * tetrahedron is flat: the face is a candidate */
        if (side_o * side_d > 0 && !flat) continue;
        outside_any = 1;
        simplex t;
        closest_triangle(s, faces[f][0], faces[f][1], faces[f][2], &t);
        double d2 = v3_len2(simplex_point(&t));
        if (d2 < best) { best = d2; best_s = t; }
    }
    if (!outside_any) return 1;
    *s = best_s;
    return 0;
}

/* Moves s to the sub-simplex supporting its closest point to the origin;
 * returns 1 when the origin is inside the full tetrahedron. */
static int solve_simplex(simplex *s)
{
    switch (s->count) {
    case 1: s->bary[0] = 1.0; return 0;
    case 2: solve_segment(s); return 0;
    case 3: { simplex t; closest_triangle(s, 0, 1, 2, &t); *s = t; return 0; }
    default: return solve_tetrahedron(s);
    }
}

static double proxy_reach(const gjk_proxy *p) { return proxy_radius(p) + v3_len(p->x.p); }

gjk_result gjk_distance(const gjk_proxy *pa, const gjk_proxy *pb)
{
    gjk_result r;
    double ra = gjk_core_radius(pa), rb = gjk_core_radius(pb);
    double scale = proxy_reach(pa) + proxy_reach(pb);
    simplex s;
    vec3 dir = v3_sub(pb->x.p, pa->x.p);
    if (v3_len2(dir) == 0) dir = v3(1, 0, 0);
    s.v[0] = support_vertex(pa, pb, v3_neg(dir));
    s.count = 1;
    s.bary[0] = 1;
    int inside = 0, it = 0, restarts = 0;
    double prev = INFINITY, best_vv = INFINITY, gap = INFINITY;
    double lower = -INFINITY; /* best lower bound on the core distance: v.w / |v| */
    vec3 lower_dir = v3_zero();
    simplex best = s;
    for (it = 0; it < GJK_MAX_ITERATIONS; it++) {
        inside = solve_simplex(&s);
        if (inside) break;
        vec3 v = simplex_point(&s);
        double vv = v3_len2(v);
        if (vv <= 1e-28 * scale * scale) { inside = 1; break; }
        if (!(vv < prev)) {
            /* no progress: the simplex has gone flat (curved shapes feed it
             * nearly collinear points) and rounding rules its closest point.
             * Restart from the best direction while the bounds disagree. */
            if (restarts++ >= GJK_MAX_RESTARTS || gap <= GJK_RESTART_GAP * best_vv) break;
            s = best;
            v = simplex_point(&s);
            s.v[0] = support_vertex(pa, pb, v);
            s.count = 1;
            prev = INFINITY;
            continue;
        }
        prev = vv;
        if (vv < best_vv) { best_vv = vv; best = s; }
        simplex_vertex nv = support_vertex(pa, pb, v);
        double len = sqrt(vv), bound = v3_dot(v, nv.w) / len;
        if (bound > lower) { lower = bound; lower_dir = v3_scale(v, -1.0 / len); }
        gap = vv - v3_dot(v, nv.w);
        if (gap <= GJK_RELATIVE_TOLERANCE * vv) break;
        int dup = 0;
        for (int i = 0; i < s.count; i++)
            if (v3_len2(v3_sub(s.v[i].w, nv.w)) == 0) dup = 1;
        if (dup) break;
        s.v[s.count++] = nv;
    }
    vec3 a = v3_zero(), b = v3_zero();
    if (inside) /* the tetrahedron holds the origin: any point of it will do */
        for (int i = 0; i < s.count; i++) s.bary[i] = 1.0 / s.count;
    else
        s = best; /* the reduced simplex nearest the origin */
    for (int i = 0; i < s.count; i++) {
        a = v3_madd(a, s.bary[i], s.v[i].a);
        b = v3_madd(b, s.bary[i], s.v[i].b);
    }
    r.iterations = it;
    if (inside) {
        r.distance = 0;
        r.lower_bound = 0;
        r.lower_normal = v3_zero();
        r.overlap = 1;
        r.normal = v3_zero();
        r.point_a = r.point_b = v3_scale(v3_add(a, b), 0.5);
        return r;
    }
    vec3 ab = v3_sub(b, a);
    double core = v3_normalize_len(&ab);
    r.normal = ab;
    r.distance = core - ra - rb;
    r.lower_bound = lower - ra - rb;
    r.lower_normal = lower_dir;
    r.point_a = v3_madd(a, ra, ab);
    r.point_b = v3_madd(b, -rb, ab);
    r.overlap = r.distance <= 0;
    if (r.overlap) {
        r.distance = 0;
        r.point_a = r.point_b = v3_madd(a, 0.5 * (core + ra - rb), ab);
    }
    return r;
}

gjk_cast_result gjk_shape_cast(const gjk_proxy *pa, vec3 translation, const gjk_proxy *pb)
{
    gjk_cast_result out = {0, 0, v3_zero(), v3_zero()};
    double scale = proxy_radius(pa) + proxy_radius(pb);
    /* Conservative advancement on GJK's lower bound and its separating
     * plane: no contact can happen before the plane is reached, so the
     * fraction is never late, and the normal reported separates the shapes
     * at the fraction. Each advance stops half of `target` short (reaching
     * contact exactly would let rounding make them overlap, where GJK has no
     * closest points); the last gap is closed to first order. */
    double target = 1e-7 * dmax(scale, 1e-3);
    gjk_proxy moved = *pa;
    double t = 0.0;
    vec3 last_point = v3_zero();
    for (int it = 0; it < CAST_MAX_ITERATIONS; it++) {
        moved.x.p = v3_madd(pa->x.p, t, translation);
        gjk_result r = gjk_distance(&moved, pb);
        if (r.overlap && it == 0) {
            out.hit = 1;
            out.fraction = 0.0;
            out.point = r.point_a;
            out.normal = v3_neg(v3_normalize(translation));
            return out;
        }
        double closing = v3_dot(r.lower_normal, translation);
        if (r.overlap || r.lower_bound <= target) {
            out.hit = 1;
            out.fraction = t;
            out.point = r.overlap ? last_point : r.point_b; /* (rounding): the last closest point */
            if (!r.overlap) {
                out.normal = v3_neg(r.lower_normal);
                if (closing > 0 && r.lower_bound > 0) out.fraction = dmin(1.0, t + r.lower_bound / closing);
            }
            return out;
        }
        if (!(closing > 0)) return out; /* the separating plane is not being approached */
        out.normal = v3_neg(r.lower_normal);
        last_point = r.point_b;
        t += (r.lower_bound - 0.5 * target) / closing;
        if (t > 1.0) return out;
    }
    /* not converged (a grazing approach): t is still a safe lower bound */
    moved.x.p = v3_madd(pa->x.p, t, translation);
    gjk_result r = gjk_distance(&moved, pb);
    if (!r.overlap && r.lower_bound <= 1e-6 * dmax(scale, 1e-3)) {
        out.hit = 1;
        out.fraction = t;
        out.point = r.point_b;
        out.normal = v3_neg(r.lower_normal);
    }
    return out;
}
