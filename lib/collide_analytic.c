/* collide_analytic.c - closed-form manifolds: sphere, capsule and box against
 * each other and against planes (see collide_analytic.h for the contract). */
#include <string.h>
#include "collide_analytic.h"

/* Below this distance (m) two features count as touching: the direction between
 * them is noise, so a fixed or separating-axis normal is used instead. */
#define TOUCH_DISTANCE 1e-12
/* capsule_box: gaps below this (m) between segment and box go through the
 * separating-axis test, which gives a clean normal when they touch or cross
 * (its separation can differ from the true gap by about this much). */
#define SEGMENT_TOUCH_DISTANCE 1e-9
/* capsule_box: an edge axis must beat the best face axis by this much (m), so
 * ties (a capsule lying on a face) keep the face and its two points. */
#define EDGE_AXIS_MARGIN 1e-9
/* capsule_capsule: sin of the largest angle between axes treated as parallel
 * (two points instead of one, so a capsule lying on another does not rock). */
#define PARALLEL_SIN 0.05

static double clamp(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

static void manifold_begin(manifold *m, vec3 normal)
{
    memset(m, 0, sizeof *m);
    m->normal = normal;
}

static void manifold_add(manifold *m, vec3 p, double separation, uint32_t id)
{
    if (m->count >= MANIFOLD_MAX_POINTS) return;
    manifold_point *mp = &m->points[m->count++];
    mp->point = p;
    mp->separation = separation;
    mp->id = id;
}

/* A fixed unit direction for coincident features: +z, or +x when the axis is
 * along z. It is kept perpendicular to a non-zero axis, so overlapping
 * capsules are pushed apart sideways (their shallowest way out). */
static vec3 fallback_normal(vec3 axis)
{
    double l2 = v3_len2(axis);
    if (!(l2 > 1e-300)) return v3(0, 0, 1);
    vec3 p = v3_madd(v3(0, 0, 1), -axis.z / l2, axis);
    if (v3_len2(p) < 1e-6) p = v3_madd(v3(1, 0, 0), -axis.x / l2, axis);
    return v3_normalize(p);
}

/* n or -n, whichever points along dir; when dir is (nearly) perpendicular, as
 * for the centres of capsules whose axes intersect, the one with its first
 * non-zero coordinate of (z, y, x) positive, so the choice is deterministic. */
static vec3 orient_towards(vec3 n, vec3 dir)
{
    double key = v3_dot(n, dir);
    if (fabs(key) <= 1e-12 * v3_len(dir)) key = n.z != 0.0 ? n.z : (n.y != 0.0 ? n.y : n.x);
    return key < 0.0 ? v3_neg(n) : n;
}

static void plane_in_world(const shape *pl, xform x, vec3 *n, double *offset)
{
    *n = q_rotate(x.q, pl->plane_normal);
    *offset = pl->plane_offset + v3_dot(*n, x.p);
}

static void capsule_ends(const shape *s, xform x, vec3 *p0, vec3 *p1)
{
    vec3 half = q_rotate(x.q, v3(0, 0, s->half_height));
    *p0 = v3_sub(x.p, half);
    *p1 = v3_add(x.p, half);
}

double segment_segment_closest(vec3 p1, vec3 q1, vec3 p2, vec3 q2, double *s_out, double *t_out)
{
    const double tiny = 1e-30; /* squared length (m^2) below which a segment is a point */
    vec3 d1 = v3_sub(q1, p1), d2 = v3_sub(q2, p2), r = v3_sub(p1, p2);
    double a = v3_dot(d1, d1), e = v3_dot(d2, d2), f = v3_dot(d2, r);
    double s = 0.0, t = 0.0;
    if (a <= tiny && e <= tiny) {
        /* two points */
    } else if (a <= tiny) {
        t = clamp(f / e, 0.0, 1.0);
    } else {
        double c = v3_dot(d1, r);
        if (e <= tiny) {
            s = clamp(-c / a, 0.0, 1.0);
        } else {
            /* minimise over the infinite lines, clamp s, then t, then s again */
            double b = v3_dot(d1, d2), den = a * e - b * b;
            s = den > 1e-14 * a * e ? clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
            double tn = b * s + f;
            if (tn <= 0.0) {
                t = 0.0;
                s = clamp(-c / a, 0.0, 1.0);
            } else if (tn >= e) {
                t = 1.0;
                s = clamp((b - c) / a, 0.0, 1.0);
            } else {
                t = tn / e;
            }
        }
    }
    *s_out = s;
    *t_out = t;
    return v3_len2(v3_sub(v3_madd(p1, s, d1), v3_madd(p2, t, d2)));
}

/* Two spheres (or the swept spheres of capsules at their closest points).
 * axis_hint is the capsule axis used for the coincident fallback. */
static int round_round(vec3 ca, double ra, vec3 cb, double rb, vec3 axis_hint, double spec, manifold *m)
{
    vec3 d = v3_sub(cb, ca);
    double dist = v3_len(d);
    vec3 n = dist > TOUCH_DISTANCE ? v3_scale(d, 1.0 / dist) : fallback_normal(axis_hint);
    double sep = dist - ra - rb;
    manifold_begin(m, n);
    if (sep < spec) {
        vec3 pa = v3_madd(ca, ra, n), pb = v3_madd(cb, -rb, n);
        manifold_add(m, v3_lerp(pa, pb, 0.5), sep, 0);
    }
    return m->count;
}

int collide_sphere_sphere(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    return round_round(xa.p, a->radius, xb.p, b->radius, v3_zero(), speculative, m);
}

/* One sphere (centre c, radius r) against the plane dot(n, x) = offset. */
static void round_plane(vec3 c, double r, vec3 n, double offset, double spec, uint32_t id, manifold *m)
{
    double sep = v3_dot(n, c) - offset - r;
    if (sep < spec) manifold_add(m, v3_madd(c, -(r + 0.5 * sep), n), sep, id);
}

int collide_sphere_plane(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 n;
    double offset;
    plane_in_world(b, xb, &n, &offset);
    manifold_begin(m, v3_neg(n));
    round_plane(xa.p, a->radius, n, offset, speculative, 0, m);
    return m->count;
}

int collide_capsule_plane(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 n, p0, p1;
    double offset;
    plane_in_world(b, xb, &n, &offset);
    capsule_ends(a, xa, &p0, &p1);
    manifold_begin(m, v3_neg(n));
    round_plane(p0, a->radius, n, offset, speculative, 0, m);
    round_plane(p1, a->radius, n, offset, speculative, 1, m);
    return m->count;
}

int collide_box_plane(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 n;
    double offset;
    plane_in_world(b, xb, &n, &offset);
    manifold_begin(m, v3_neg(n));
    vec3 h = a->half_extents;
    vec3 corner[8];
    double sep[8];
    int keep[8], kept = 0;
    for (int i = 0; i < 8; i++) {
        vec3 local = v3(i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z);
        corner[i] = xf_point(xa, local);
        sep[i] = v3_dot(n, corner[i]) - offset;
        if (sep[i] < speculative) keep[kept++] = i;
    }
    /* more than 4 within reach: keep the 4 deepest (ties to the lower index) */
    while (kept > MANIFOLD_MAX_POINTS) {
        int worst = 0;
        for (int k = 1; k < kept; k++)
            if (sep[keep[k]] >= sep[keep[worst]]) worst = k;
        for (int k = worst; k + 1 < kept; k++) keep[k] = keep[k + 1];
        kept--;
    }
    /* in corner order, so the array layout does not flicker with depth order */
    for (int k = 0; k < kept; k++) {
        int i = keep[k];
        manifold_add(m, v3_madd(corner[i], -0.5 * sep[i], n), sep[i], (uint32_t)i);
    }
    return m->count;
}

/* ---- against a box, in the box frame ----------------------------------------------- */

static vec3 clamp_to_box(vec3 p, vec3 h)
{
    return v3(clamp(p.x, -h.x, h.x), clamp(p.y, -h.y, h.y), clamp(p.z, -h.z, h.z));
}

static vec3 axis_unit(int i) { return v3(i == 0, i == 1, i == 2); }

int collide_sphere_box(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 h = b->half_extents, c = xf_inv_point(xb, xa.p);
    vec3 q = clamp_to_box(c, h); /* box point nearest the centre */
    vec3 out;                    /* box frame: from the box towards the sphere */
    double gap = v3_len(v3_sub(c, q));
    if (gap > TOUCH_DISTANCE) {
        out = v3_scale(v3_sub(c, q), 1.0 / gap);
    } else {
        /* centre inside (or on) the box: leave through the nearest face */
        int face = 0;
        double depth = h.x - fabs(c.x);
        for (int i = 1; i < 3; i++) {
            double d = v3_get(h, i) - fabs(v3_get(c, i));
            if (d < depth) { depth = d; face = i; }
        }
        double side = v3_get(c, face) >= 0.0 ? 1.0 : -1.0;
        out = v3_scale(axis_unit(face), side);
        /* the face point under the centre */
        q = v3_madd(c, side * v3_get(h, face) - v3_get(c, face), axis_unit(face));
        gap = -depth;
    }
    double sep = gap - a->radius;
    manifold_begin(m, q_rotate(xb.q, v3_neg(out)));
    if (sep < speculative) manifold_add(m, xf_point(xb, v3_madd(q, 0.5 * sep, out)), sep, 0);
    return m->count;
}

static double point_box_distance2(vec3 p, vec3 h) { return v3_len2(v3_sub(p, clamp_to_box(p, h))); }

/* Squared distance from the segment p0 + t d (t in 0..1) to the box [-h, h],
 * and a minimising t. The squared distance is convex and piecewise quadratic in
 * t, the pieces split where a coordinate crosses a slab boundary, so each
 * piece is minimised in closed form. */
static double segment_box_closest(vec3 p0, vec3 d, vec3 h, double *t_best)
{
    double cut[8];
    int n = 0;
    cut[n++] = 0.0;
    cut[n++] = 1.0;
    for (int i = 0; i < 3; i++) {
        double pi = v3_get(p0, i), di = v3_get(d, i), hi = v3_get(h, i);
        if (di == 0.0) continue;
        for (int side = -1; side <= 1; side += 2) {
            double t = (side * hi - pi) / di;
            if (t > 0.0 && t < 1.0) cut[n++] = t;
        }
    }
    for (int i = 1; i < n; i++) /* insertion sort: at most 8 values */
        for (int j = i; j > 0 && cut[j - 1] > cut[j]; j--) {
            double tmp = cut[j];
            cut[j] = cut[j - 1];
            cut[j - 1] = tmp;
        }
    double best = point_box_distance2(p0, h);
    *t_best = 0.0;
    for (int k = 0; k + 1 < n; k++) {
        double t0 = cut[k], t1 = cut[k + 1], tm = 0.5 * (t0 + t1);
        double num = 0.0, den = 0.0; /* sum over the coordinates outside their slab of (o + t d)^2 */
        for (int i = 0; i < 3; i++) {
            double pi = v3_get(p0, i), di = v3_get(d, i), hi = v3_get(h, i), x = pi + tm * di;
            if (x >= -hi && x <= hi) continue;
            double o = x > hi ? pi - hi : pi + hi; /* excess beyond the slab is o + t di */
            num += o * di;
            den += di * di;
        }
        double t = den > 0.0 ? clamp(-num / den, t0, t1) : t0;
        double d2 = point_box_distance2(v3_madd(p0, t, d), h);
        if (d2 < best) {
            best = d2;
            *t_best = t;
        }
    }
    return best;
}

/* Capsule contact on box face `axis` (side +1 / -1) in the box frame: the
 * segment clipped to the face's side slabs gives up to two points, each
 * measured straight to the face plane. t_closest is the segment parameter
 * nearest the box; with add_closest, that point is added when the clip left it
 * out (a segment grazing the face's rim from beside the face, within the touch
 * distance), so the deepest spot is never lost. Normal and points go to world. */
static int capsule_on_face(vec3 p0, vec3 d, vec3 h, double r, int axis, double side, double t_closest,
                           int add_closest, xform xb, double spec, manifold *m)
{
    vec3 out = v3_scale(axis_unit(axis), side);
    double lo = 0.0, hi = 1.0;
    for (int j = 0; j < 3; j++) {
        if (j == axis) continue;
        double pj = v3_get(p0, j), dj = v3_get(d, j), hj = v3_get(h, j);
        if (dj == 0.0) {
            if (fabs(pj) > hj) hi = -1.0;
            continue;
        }
        double ta = (-hj - pj) / dj, tb = (hj - pj) / dj;
        lo = dmax(lo, dmin(ta, tb));
        hi = dmin(hi, dmax(ta, tb));
    }
    double ts[3];
    uint32_t slot[3];
    int nt = 0;
    if (lo <= hi) {
        ts[nt] = lo;
        slot[nt++] = 0;
        if ((hi - lo) * v3_len(d) > 1e-9) {
            ts[nt] = hi;
            slot[nt++] = 1;
        }
    }
    if (nt == 0 || (add_closest && (t_closest < lo - 1e-12 || t_closest > hi + 1e-12))) {
        ts[nt] = t_closest;
        slot[nt++] = 2;
    }
    uint32_t face = (uint32_t)(2 * axis + (side > 0.0));
    manifold_begin(m, q_rotate(xb.q, v3_neg(out)));
    for (int k = 0; k < nt; k++) {
        vec3 p = v3_madd(p0, ts[k], d);
        double height = side * v3_get(p, axis) - v3_get(h, axis), sep = height - r;
        /* the face point under p, kept on the face when p is beside it */
        vec3 on_face = clamp_to_box(v3_madd(p, -height, out), h);
        if (sep < spec) manifold_add(m, xf_point(xb, v3_madd(on_face, 0.5 * sep, out)), sep, 1u + 3u * face + slot[k]);
    }
    return m->count;
}

int collide_capsule_box(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 h = b->half_extents, w0, w1;
    double r = a->radius;
    capsule_ends(a, xa, &w0, &w1);
    vec3 p0 = xf_inv_point(xb, w0), p1 = xf_inv_point(xb, w1), d = v3_sub(p1, p0);
    double t;
    segment_box_closest(p0, d, h, &t);
    vec3 p = v3_madd(p0, t, d), q = clamp_to_box(p, h), gap_vec = v3_sub(p, q);
    double gap = v3_len(gap_vec);

    if (gap > SEGMENT_TOUCH_DISTANCE) {
        /* apart: the closest points decide; on a face, clip for a second point */
        vec3 out = v3_scale(gap_vec, 1.0 / gap);
        int outside_count = (gap_vec.x != 0.0) + (gap_vec.y != 0.0) + (gap_vec.z != 0.0);
        if (outside_count == 1 && gap - r < speculative) {
            int axis = gap_vec.x != 0.0 ? 0 : (gap_vec.y != 0.0 ? 1 : 2);
            return capsule_on_face(p0, d, h, r, axis, v3_get(out, axis) > 0.0 ? 1.0 : -1.0, t, 0, xb, speculative, m);
        }
        double sep = gap - r;
        manifold_begin(m, q_rotate(xb.q, v3_neg(out)));
        if (sep < speculative) manifold_add(m, xf_point(xb, v3_lerp(v3_madd(p, -r, out), q, 0.5)), sep, 0);
        return m->count;
    }

    /* touching or crossing: the separating axis of least overlap, over the box
     * faces and the segment-edge cross products (the faces of their Minkowski sum) */
    vec3 c = v3_madd(p0, 0.5, d), half = v3_scale(d, 0.5);
    int best_face = 0;
    double best = INFINITY;
    for (int i = 0; i < 3; i++) {
        double overlap = v3_get(h, i) + fabs(v3_get(half, i)) - fabs(v3_get(c, i));
        if (overlap < best) { best = overlap; best_face = i; }
    }
    int best_edge = -1;
    vec3 edge_axis = v3_zero();
    double dl = v3_len(d);
    for (int k = 0; k < 3; k++) {
        vec3 l = v3_cross(d, axis_unit(k));
        double ll = v3_len(l);
        if (!(ll > 1e-9 * dl)) continue; /* segment along this edge direction (or a point) */
        l = v3_scale(l, 1.0 / ll);
        double overlap = v3_dot(h, v3_abs(l)) - fabs(v3_dot(c, l)); /* the segment has no extent along l */
        if (overlap < best - EDGE_AXIS_MARGIN) {
            best = overlap;
            best_edge = k;
            edge_axis = v3_dot(c, l) >= 0.0 ? l : v3_neg(l);
        }
    }
    if (best_edge < 0) {
        double side = v3_get(c, best_face) >= 0.0 ? 1.0 : -1.0;
        return capsule_on_face(p0, d, h, r, best_face, side, t, 1, xb, speculative, m);
    }
    /* the box edge along best_edge farthest out along the axis, against the segment */
    vec3 e0 = v3(edge_axis.x >= 0.0 ? h.x : -h.x, edge_axis.y >= 0.0 ? h.y : -h.y, edge_axis.z >= 0.0 ? h.z : -h.z);
    double hk = v3_get(h, best_edge);
    vec3 e1 = v3_madd(e0, hk - v3_get(e0, best_edge), axis_unit(best_edge));
    e0 = v3_madd(e0, -hk - v3_get(e0, best_edge), axis_unit(best_edge));
    double s, u;
    segment_segment_closest(p0, p1, e0, e1, &s, &u);
    vec3 ps = v3_madd(p0, s, d), pe = v3_lerp(e0, e1, u);
    double sep = v3_dot(v3_sub(ps, pe), edge_axis) - r;
    uint32_t corner = 0, bit = 0;
    for (int j = 0; j < 3; j++) {
        if (j == best_edge) continue;
        if (v3_get(edge_axis, j) >= 0.0) corner |= 1u << bit;
        bit++;
    }
    manifold_begin(m, q_rotate(xb.q, v3_neg(edge_axis)));
    if (sep < speculative)
        manifold_add(m, xf_point(xb, v3_madd(pe, 0.5 * sep, edge_axis)), sep, 32u + 4u * (uint32_t)best_edge + corner);
    return m->count;
}

/* ---- capsule pairs ----------------------------------------------------------------- */

int collide_sphere_capsule(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 b0, b1;
    capsule_ends(b, xb, &b0, &b1);
    vec3 db = v3_sub(b1, b0);
    double l2 = v3_len2(db);
    double t = l2 > 1e-30 ? clamp(v3_dot(v3_sub(xa.p, b0), db) / l2, 0.0, 1.0) : 0.5;
    return round_round(xa.p, a->radius, v3_madd(b0, t, db), b->radius, db, speculative, m);
}

int collide_capsule_capsule(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *m)
{
    vec3 a0, a1, b0, b1;
    capsule_ends(a, xa, &a0, &a1);
    capsule_ends(b, xb, &b0, &b1);
    vec3 da = v3_sub(a1, a0), db = v3_sub(b1, b0);
    double s, t;
    double dist = sqrt(segment_segment_closest(a0, a1, b0, b1, &s, &t));
    vec3 ca = v3_madd(a0, s, da), cb = v3_madd(b0, t, db);
    double ra = a->radius, rb = b->radius;

    vec3 n;
    if (dist > TOUCH_DISTANCE) {
        n = v3_scale(v3_sub(cb, ca), 1.0 / dist);
    } else {
        /* crossing axes: their common perpendicular, turned towards b */
        vec3 cr = v3_cross(da, db);
        double cl2 = v3_len2(cr);
        if (cl2 > 1e-12 * v3_len2(da) * v3_len2(db) && cl2 > 1e-300) {
            n = orient_towards(v3_scale(cr, 1.0 / sqrt(cl2)), v3_sub(xb.p, xa.p));
        } else {
            n = fallback_normal(v3_len2(da) > 1e-30 ? da : db);
        }
    }
    manifold_begin(m, n);

    double la2 = v3_len2(da), lb2 = v3_len2(db);
    if (la2 > 1e-30 && lb2 > 1e-30 &&
        v3_len2(v3_cross(da, db)) < PARALLEL_SIN * PARALLEL_SIN * la2 * lb2) {
        /* nearly parallel: two points at the ends of the overlap of b projected on a,
         * both measured along the one normal */
        double la = sqrt(la2);
        vec3 ua = v3_scale(da, 1.0 / la);
        double sb0 = v3_dot(v3_sub(b0, a0), ua), sb1 = v3_dot(v3_sub(b1, a0), ua);
        double lo = dmax(0.0, dmin(sb0, sb1)), hi = dmin(la, dmax(sb0, sb1));
        if (hi - lo > 1e-9 * (1.0 + la)) {
            for (int i = 0; i < 2; i++) {
                vec3 pa = v3_madd(a0, i ? hi : lo, ua);
                double tb = clamp(v3_dot(v3_sub(pa, b0), db) / lb2, 0.0, 1.0);
                vec3 pb = v3_madd(b0, tb, db);
                double sep = v3_dot(v3_sub(pb, pa), n) - ra - rb;
                if (sep < speculative) manifold_add(m, v3_lerp(v3_madd(pa, ra, n), v3_madd(pb, -rb, n), 0.5), sep, (uint32_t)(1 + i));
            }
            return m->count;
        }
    }
    double sep = dist - ra - rb;
    if (sep < speculative) manifold_add(m, v3_lerp(v3_madd(ca, ra, n), v3_madd(cb, -rb, n), 0.5), sep, 0);
    return m->count;
}
