/* triangle_contact.c - convex shapes against the triangles of meshes and
 * height fields.
 *
 * One triangle: a one-sided triangle is treated as the half-infinite prism
 * below it (its face, and side walls at its edges), so the separating-axis
 * test only ever finds normals on the front side. Spheres and capsules take
 * the face when their core projects onto it, else the nearest edge or vertex.
 * Cylinders take the polytope path with their true shape on every axis: the
 * face's gap from the true lowest point, the caps (exact faces) but not the
 * prism's side facets, and each edge's axes searched along its arc of the
 * Gauss map with the exact support (cyl_edge_axis); the face contact uses
 * the true line of support and deepest rim point.
 *
 * Internal edges: each triangle edge is flagged active when its neighbour is
 * folded away from it (a convex crease of more than 5 degrees) or missing
 * (mesh boundary, a hole). A contact whose normal comes from an inactive edge
 * or from a vertex with only inactive edges is turned to the triangle's face
 * normal: on a flat or concave join the neighbour's face holds the body, and
 * the edge normal would only make it bump or snag (the approach of Jolt's
 * active edges; Bullet's btAdjustInternalEdgeContacts corrects the normal
 * after the fact with the same adjacency). Face contacts are left alone.
 *
 * Many triangles: the contacts of all triangles overlapping the convex shape
 * are grouped by normal (within 2.5 degrees), each group reduced to four
 * points; a flat floor of any number of triangles gives one manifold, a floor
 * and a wall two. */
#include <stdlib.h>
#include <string.h>
#include "gjk.h"
#include "manifold.h"
#include "mesh.h"
#include "heightfield.h"
#include "triangle_contact.h"

#define TRI_FACE_TOLERANCE 1e-3   /* prefer the triangle's face unless another axis separates more (m) */
#define GROUP_COS 0.999           /* polytope contacts within ~2.5 degrees of a group's normal join it */
#define CORE_GROUP_COS (1.0 - 1e-9) /* sphere and capsule contacts: only the same normal */
#define GROUP_CAPACITY 64

/* ---- one triangle ------------------------------------------------------------- */

static void triangle_poly(poly *p, const vec3 v[3], vec3 n)
{
    p->nv = 3; p->nf = 2; p->ne = 3;
    for (int k = 0; k < 3; k++) {
        p->v[k] = v[k];
        p->e[k][0] = k;
        p->e[k][1] = (k + 1) % 3;
    }
    p->fn[0] = n; p->ffirst[0] = 0; p->fcount[0] = 3;
    p->fv[0] = 0; p->fv[1] = 1; p->fv[2] = 2;
    p->fn[1] = v3_neg(n); p->ffirst[1] = 3; p->fcount[1] = 3;
    p->fv[3] = 0; p->fv[4] = 2; p->fv[5] = 1;
    poly_finish(p);
}

/* Outward side direction of edge k (in the triangle's plane). */
static vec3 edge_side(const vec3 v[3], vec3 n, int k)
{
    return v3_normalize(v3_cross(v3_sub(v[(k + 1) % 3], v[k]), n));
}

static int vertex_active(unsigned active, int i) { return (active >> i & 1u) || (active >> ((i + 2) % 3) & 1u); }

static void push_point(manifold *m, vec3 p, double sep, uint32_t id)
{
    if (m->count >= MANIFOLD_MAX_POINTS) return;
    m->points[m->count].point = p;
    m->points[m->count].separation = sep;
    m->points[m->count].id = id;
    m->count++;
}

/* A sphere or capsule (core c0..c1, radius r) against the triangle. */
static void triangle_core(const vec3 v[3], vec3 n, unsigned active, vec3 c0, vec3 c1, double r, double spec, manifold *m)
{
    double d = v3_dot(n, v[0]);
    m->normal = n;
    if (v3_dot(n, c0) - d < 0 && v3_dot(n, c1) - d < 0) return; /* behind a one-sided face */
    int seg = v3_len2(v3_sub(c1, c0)) > 0;
    clip_vertex b1[4], b2[4];
    b1[0].p = c0; b1[0].id = 0;
    b1[1].p = c1; b1[1].id = 1;
    clip_vertex *in = b1, *out = b2;
    int nb = seg ? 2 : 1;
    for (int k = 0; k < 3 && nb > 0; k++) {
        vec3 side = edge_side(v, n, k);
        double sd = v3_dot(side, v[k]);
        if (nb == 2) {
            nb = clip_polygon(in, 2, side, sd, (uint32_t)k, out);
            if (nb > 2) nb = 2;
        } else {
            nb = v3_dot(side, in[0].p) <= sd ? 1 : 0;
            out[0] = in[0];
        }
        clip_vertex *t = in; in = out; out = t;
    }
    double face_sep = 1e300;
    for (int i = 0; i < nb; i++) face_sep = dmin(face_sep, v3_dot(n, in[i].p) - d - r);
    /* nearest edge or vertex (a capsule partly over the face can still be
     * nearest to an edge) */
    double best = 1e300, best_s = 0;
    vec3 q = v[0], pc = c0;
    int bk = 0;
    for (int k = 0; k < 3; k++) {
        vec3 a, b;
        closest_segments(v[k], v[(k + 1) % 3], c0, c1, &a, &b);
        double d2 = v3_len2(v3_sub(b, a));
        if (d2 < best) {
            vec3 e = v3_sub(v[(k + 1) % 3], v[k]);
            best = d2; q = a; pc = b; bk = k;
            best_s = v3_dot(v3_sub(a, v[k]), e) / v3_len2(e);
        }
    }
    int at_vertex = best_s <= 1e-9 ? bk : best_s >= 1 - 1e-9 ? (bk + 1) % 3 : -1;
    int feature_active = at_vertex >= 0 ? vertex_active(active, at_vertex) : (int)(active >> bk & 1u);
    double dist = sqrt(best);
    /* A vertex with one active edge (a mesh's boundary, the other edge
     * internal) is a corner only towards that edge's outer side. A core past
     * an acute vertex on the inner side of the active edge's line lies across
     * the internal edge, over the neighbour, whose face (or its own boundary
     * edge beyond) is nearer: this vertex's tilted normal would push the body
     * back (a sphere rolling over a patch's border vertex, where two patches
     * of 2 x 2 cells meet, at dt 1/15, was thrown up at 0.14 m/s). Such a
     * vertex gives no contact. */
    int inner_vertex = 0;
    if (at_vertex >= 0 && feature_active && dist > 1e-12) {
        int e_out = at_vertex, e_in = (at_vertex + 2) % 3; /* the edges leaving and reaching the vertex */
        int a_out = active >> e_out & 1u, a_in = active >> e_in & 1u;
        if (a_out != a_in && v3_dot(v3_sub(pc, q), edge_side(v, n, a_out ? e_out : e_in)) < 0) {
            feature_active = 0;
            inner_vertex = 1;
        }
    }
    if (nb > 0 && !(feature_active && dist - r < face_sep - 1e-12 && dist > 1e-12)) {
        /* the core over the face, nearest to it */
        for (int i = 0; i < nb; i++) {
            double sep = v3_dot(n, in[i].p) - d - r;
            if (sep < spec) push_point(m, v3_madd(in[i].p, -(r + 0.5 * sep), n), sep, in[i].id & 0xffffu);
        }
        return;
    }
    if (inner_vertex) return;
    vec3 nrm;
    double sep;
    if (!feature_active || dist < 1e-12) {
        /* an internal edge: the neighbour's face continues this one, so the
         * face normal; but the true distance, not the height over this
         * face's plane (never more room along the normal than there is,
         * never deeper than the feature itself). A triangle does not know
         * where its neighbours end: a sphere rolled off a terrain mesh's
         * border, its centre 0.27 m past the border edge, was 0.033 m
         * "deep" under the plane of a triangle whose edges and vertex at
         * that corner are all internal, and was thrown back up. The
         * neighbour's own face contact holds a core over it. */
        nrm = n;
        sep = dist - r;
    } else {
        nrm = v3_scale(v3_sub(pc, q), 1.0 / dist);
        sep = dist - r;
        if (v3_dot(nrm, n) < 0) return; /* from below a one-sided face */
    }
    m->normal = nrm;
    if (sep < spec) push_point(m, v3_madd(pc, -(r + 0.5 * sep), nrm), sep, 0x100u + (uint32_t)bk);
}

/* A cylinder's prism lies inside the true rim: add the true rim's deepest
 * point when it lies over the triangle (as the plane contact does). */
static void add_rim_point(const vec3 v[3], vec3 n, const shape *cyl, xform x, double spec, manifold *m)
{
    vec3 axis = q_rotate(x.q, v3(0, 0, 1));
    vec3 radial = v3_madd(v3_neg(n), v3_dot(n, axis), axis);
    if (v3_len2(radial) < 1e-12) return; /* the cap lies flat: its polygon is exact */
    radial = v3_normalize(radial);
    double hz = v3_dot(axis, n) > 0 ? -cyl->half_height : cyl->half_height;
    vec3 p = v3_add(v3_madd(x.p, hz, axis), v3_scale(radial, cyl->radius));
    for (int k = 0; k < 3; k++) {
        vec3 side = edge_side(v, n, k);
        if (v3_dot(side, p) > v3_dot(side, v[k])) return;
    }
    double sep = v3_dot(n, p) - v3_dot(n, v[0]);
    if (!(sep < spec)) return;
    /* already there: a cylinder on its side touches along its true line of
     * support, whose lower end is this rim point (a second point on the
     * same spot makes the manifold's normal rows singular for a block solve) */
    for (int i = 0; i < m->count; i++)
        if (v3_len2(v3_sub(m->points[i].point, v3_madd(p, -0.5 * sep, n))) <= 1e-18 + 1e-12 * cyl->radius * cyl->radius) return;
    manifold_point pts[MANIFOLD_MAX_POINTS + 1];
    int c = m->count;
    for (int i = 0; i < c; i++) pts[i] = m->points[i];
    pts[c].point = v3_madd(p, -0.5 * sep, n);
    pts[c].separation = sep;
    pts[c].id = 0x60u;
    c = manifold_reduce(pts, c + 1, n);
    for (int i = 0; i < c; i++) m->points[i] = pts[i];
    m->count = c;
    m->normal = n;
}

/* The cylinder's true point farthest along unit u (world). */
static vec3 cyl_support(const shape *cyl, xform x, vec3 u)
{
    return xf_point(x, shape_support_local(cyl, q_inv_rotate(x.q, u)));
}

/* A cylinder in world space: centre, unit axis, half height, radius. */
typedef struct cyl_world { vec3 c, a; double hh, r; } cyl_world;

static cyl_world cyl_world_of(const shape *cyl, xform x)
{
    cyl_world cw = {x.p, q_rotate(x.q, v3(0, 0, 1)), cyl->half_height, cyl->radius};
    return cw;
}

/* The exact room between the cylinder and the one-sided triangle (the prism
 * below it) along unit u with u . n >= 0: the cylinder's lowest point along
 * u (its support along -u in closed form) less the triangle's highest
 * vertex. */
static double cyl_gap(const vec3 v[3], const cyl_world *cw, vec3 u)
{
    double top = dmax(v3_dot(u, v[0]), dmax(v3_dot(u, v[1]), v3_dot(u, v[2])));
    double au = v3_dot(cw->a, u);
    double radial2 = dmax(0, 1 - au * au); /* |u without its axial part|^2 */
    return v3_dot(u, cw->c) - cw->hh * fabs(au) - cw->r * sqrt(radial2) - top;
}

/* The best axis of edge k's part of the Gauss map, the arc from the face
 * normal n to the edge's side wall, for the true cylinder: the arc's
 * directions normalize((1 - l) n + l side) for l in [0, 1], a scan of 9,
 * then a golden-section search around the best (no trigonometry). The
 * prism's edge pairs read up to its sagitta too far; any axis's gap here is
 * exact, so the best found is never more room than there is. Returns the
 * gap and sets *u; the face's own axis (l = 0) returns -1e300. */
static vec3 arc_dir(vec3 n, vec3 side, double l) { return v3_normalize(v3_add(v3_scale(n, 1 - l), v3_scale(side, l))); }

static double cyl_edge_axis(const vec3 v[3], vec3 n, int k, const cyl_world *cw, vec3 *u)
{
    vec3 side = edge_side(v, n, k);
    double best = -1e300, bl = 0;
    for (int i = 0; i <= 8; i++) {
        double l = i / 8.0, g = cyl_gap(v, cw, arc_dir(n, side, l));
        if (g > best) { best = g; bl = l; }
    }
    double lo = dmax(0, bl - 0.125), hi = dmin(1, bl + 0.125);
    const double r = 0.6180339887498949;
    double l1 = hi - r * (hi - lo), l2 = lo + r * (hi - lo);
    double g1 = cyl_gap(v, cw, arc_dir(n, side, l1)), g2 = cyl_gap(v, cw, arc_dir(n, side, l2));
    for (int it = 0; it < 24; it++) {
        if (g1 > g2) { hi = l2; l2 = l1; g2 = g1; l1 = hi - r * (hi - lo); g1 = cyl_gap(v, cw, arc_dir(n, side, l1)); }
        else { lo = l1; l1 = l2; g1 = g2; l2 = lo + r * (hi - lo); g2 = cyl_gap(v, cw, arc_dir(n, side, l2)); }
    }
    if (g1 > best) { best = g1; bl = l1; }
    if (g2 > best) { best = g2; bl = l2; }
    if (!(bl > 1e-9)) return -1e300; /* the face's own axis: not this edge's */
    *u = arc_dir(n, side, bl);
    return best;
}

/* A cylinder against the triangle along an edge's axis u (gap sep): the
 * cylinder's lowest point along u, or, its side square to u, the side's
 * line clipped to the edge's span (a log lying along a border edge rests on
 * two points). */
static void cyl_edge_contact(const vec3 v[3], int k, const shape *cyl, xform x, vec3 u, double sep, double spec,
                             manifold *m)
{
    m->normal = u;
    vec3 axis = q_rotate(x.q, v3(0, 0, 1));
    double top = dmax(v3_dot(u, v[0]), dmax(v3_dot(u, v[1]), v3_dot(u, v[2])));
    vec3 radial = v3_madd(v3_neg(u), v3_dot(u, axis), axis);
    if (fabs(v3_dot(axis, u)) < 2e-2 && v3_len2(radial) > 1e-12) {
        radial = v3_normalize(radial);
        vec3 e0 = v3_add(v3_madd(x.p, -cyl->half_height, axis), v3_scale(radial, cyl->radius));
        vec3 e1 = v3_add(v3_madd(x.p, cyl->half_height, axis), v3_scale(radial, cyl->radius));
        vec3 a = v[k], ed = v3_sub(v[(k + 1) % 3], a);
        double el2 = v3_len2(ed), s0 = v3_dot(v3_sub(e0, a), ed) / el2, s1 = v3_dot(v3_sub(e1, a), ed) / el2;
        double lo = dmax(0, dmin(s0, s1)), hi = dmin(1, dmax(s0, s1));
        if (hi > lo + 1e-9 && fabs(s1 - s0) > 1e-12) {
            for (int i = 0; i < 2; i++) {
                vec3 q = v3_lerp(e0, e1, ((i ? hi : lo) - s0) / (s1 - s0));
                double sq = v3_dot(u, q) - top;
                if (sq < spec) push_point(m, v3_madd(q, -0.5 * sq, u), sq, 0x4800u | ((uint32_t)k << 12) | (uint32_t)i);
            }
            if (m->count > 0) return;
        }
    }
    vec3 q = cyl_support(cyl, x, v3_neg(u));
    if (sep < spec) push_point(m, v3_madd(q, -0.5 * sep, u), sep, 0x4800u | ((uint32_t)k << 12) | 2u);
}

/* Whether edge k is active and the contact normal -fn (from the triangle
 * to the shape) leans out across it: an edge or vertex speaks only for
 * normals in its own part of the Gauss map. A vertex where a mesh's
 * boundary runs straight on (an internal edge meets the border: two
 * collinear border edges) has no normals of its own beyond its edges'
 * sides: a box face square to the border reached it with a normal along
 * the border, a wall across a flat floor of patches (a box sliding over the
 * seam of 2 m patches of 3 x 3 cells was thrown up 0.29 m/s). */
static int edge_faces_normal(const vec3 v[3], vec3 n, unsigned active, int k, vec3 fn)
{
    return (active >> k & 1u) && -v3_dot(fn, edge_side(v, n, k)) > 1e-6;
}

/* Whether a contact on the shape's face (outward normal fn; its points on
 * the triangle, each moved half its separation along -fn) comes from an
 * active feature of the triangle: the one its deepest point lies on, an
 * edge or a vertex (a point inside the triangle: its face). Judged by the
 * clipped points, not by the triangle's vertex nearest the face's plane: a
 * face turned a hair off parallel to an internal edge would otherwise see
 * that edge's far vertex, active on a mesh's border a metre away.
 * interior_ok: whether a point inside the triangle counts (not for a shape
 * beside the triangle: its face reaches the triangle across an edge). */
static int face_contact_active(const vec3 v[3], vec3 n, unsigned active, vec3 fn, const manifold *alt, int interior_ok)
{
    int deepest = 0;
    for (int i = 1; i < alt->count; i++)
        if (alt->points[i].separation < alt->points[deepest].separation) deepest = i;
    vec3 q = v3_madd(alt->points[deepest].point, 0.5 * alt->points[deepest].separation, fn);
    double scale = v3_len(v3_sub(v[1], v[0])) + v3_len(v3_sub(v[2], v[0]));
    int on[3], count = 0;
    for (int k = 0; k < 3; k++) count += on[k] = v3_dot(edge_side(v, n, k), v3_sub(q, v[k])) >= -1e-9 * scale;
    if (count == 0) return interior_ok;
    if (count >= 2) {
        int i = on[0] && on[1] ? 1 : on[1] && on[2] ? 2 : 0;
        return edge_faces_normal(v, n, active, i, fn) || edge_faces_normal(v, n, active, (i + 2) % 3, fn);
    }
    return edge_faces_normal(v, n, active, on[0] ? 0 : on[1] ? 1 : 2, fn);
}

/* No axis separates the shape from the triangle by more than the
 * look-ahead, yet neither face nor edge pair gave a point: beside the
 * triangle, its nearest features are a vertex and an edge or two vertices
 * (axes the separating-axis test does not try). The closest points (GJK
 * on the true shape) give one point, from an active edge or vertex whose
 * part of the Gauss map holds the normal. */
static void look_ahead_point(const vec3 v[3], vec3 n, unsigned active, const shape *s, xform xs, double spec, manifold *m)
{
    if (!(active & 7u)) return; /* every edge internal: the neighbours' faces hold the shape */
    vec3 local[3] = {v3(0, 0, 0), v3_sub(v[1], v[0]), v3_sub(v[2], v[0])};
    gjk_proxy pt = {NULL, local, 3, {v3(0, 0, 0), q_identity()}};
    gjk_proxy ps = {s, NULL, 0, {v3_sub(xs.p, v[0]), xs.q}};
    gjk_result r = gjk_distance(&pt, &ps);
    if (r.overlap || !(r.distance > 0) || !(r.distance < spec)) return;
    vec3 nrm = r.normal, q = r.point_a;
    double dist = r.distance;
    if (!(v3_dot(nrm, n) >= 0)) {
        /* below the triangle's plane: the one-sided triangle is the prism
         * under it, whose side walls face along the plane; the room along
         * the normal turned into the plane (both shapes' extents along it) */
        nrm = v3_madd(nrm, -v3_dot(nrm, n), n);
        if (!(v3_len2(nrm) > 1e-18)) return;
        nrm = v3_normalize(nrm);
        int top = 0;
        for (int k = 1; k < 3; k++)
            if (v3_dot(nrm, local[k]) > v3_dot(nrm, local[top])) top = k;
        q = local[top];
        vec3 low = xf_point(ps.x, shape_support_local(s, q_inv_rotate(xs.q, v3_neg(nrm))));
        dist = v3_dot(nrm, v3_sub(low, q));
        if (!(dist > 0) || !(dist < spec)) return;
    }
    double scale = v3_len(local[1]) + v3_len(local[2]);
    int on[3], count = 0;
    for (int k = 0; k < 3; k++) count += on[k] = v3_dot(edge_side(local, n, k), v3_sub(q, local[k])) >= -1e-9 * scale;
    int ok = 0;
    vec3 fn = v3_neg(nrm);
    if (count == 1) ok = edge_faces_normal(local, n, active, on[0] ? 0 : on[1] ? 1 : 2, fn);
    else if (count >= 2) {
        int i = on[0] && on[1] ? 1 : on[1] && on[2] ? 2 : 0;
        ok = edge_faces_normal(local, n, active, i, fn) || edge_faces_normal(local, n, active, (i + 2) % 3, fn);
    }
    if (!ok) return; /* over the face (the face contact's) or an internal feature (the neighbour's) */
    m->normal = nrm;
    push_point(m, v3_add(v[0], v3_madd(q, 0.5 * dist, nrm)), dist, 0x7000u | (uint32_t)(on[0] | on[1] << 1 | on[2] << 2));
}

/* A polytope p (built from shape s at xs; edge faces filled) against the triangle. */
static void triangle_polytope(const vec3 v[3], vec3 n, unsigned active, const poly *p, const shape *s, xform xs,
                              double spec, manifold *m)
{
    double d = v3_dot(n, v[0]);
    m->normal = n;
    if (v3_dot(n, p->center) - d < 0) return; /* behind a one-sided face */
    /* a cylinder is its true shape on every axis below (its prism's
     * vertices lie on the rims, but between them the rims and the round
     * side reach up to the sagitta r (1 - cos(pi/16)) farther) */
    const shape *cyl = s->type == SHAPE_CYLINDER ? s : NULL;
    cyl_world cw = cyl_world_of(s, xs);
    double sep_t = 1e300;
    if (cyl) sep_t = v3_dot(n, cyl_support(cyl, xs, v3_neg(n)));
    else
        for (int i = 0; i < p->nv; i++) sep_t = dmin(sep_t, v3_dot(n, p->v[i]));
    sep_t -= d;
    if (sep_t > spec) return;
    /* the polytope's faces whose outward normal looks at the triangle's front */
    double sep_f = -1e300;
    int best_f = -1;
    for (int f = cyl ? CYL_SIDES : 0; f < p->nf; f++) { /* a cylinder's caps only: its facets are not its surface */
        if (v3_dot(p->fn[f], n) > 1e-9) continue;
        double sv = 1e300;
        for (int k = 0; k < 3; k++) sv = dmin(sv, v3_dot(p->fn[f], v[k]));
        sv -= p->fd[f];
        if (sv > spec) { m->normal = v3_neg(p->fn[f]); return; }
        if (sv > sep_f) { sep_f = sv; best_f = f; }
    }
    /* edge pairs whose Gauss-map arcs cross: the triangle's edge k spans
     * the arc from its face normal to its side wall */
    double sep_e = -1e300;
    int ek = -1, ej = -1;
    vec3 en = n;
    for (int k = 0; k < 3 && cyl; k++) {
        /* the cylinder: the best axis of each active edge's arc (an
         * internal edge's axes are never used: its contacts take the face) */
        vec3 u;
        if (!(active >> k & 1u)) continue;
        double sv = cyl_edge_axis(v, n, k, &cw, &u);
        if (sv > spec) { m->normal = u; return; }
        if (sv > sep_e) { sep_e = sv; ek = k; en = u; }
    }
    for (int k = 0; k < 3 && !cyl; k++) {
        vec3 a0 = v[k], da = v3_sub(v[(k + 1) % 3], a0);
        vec3 na = n, nb = edge_side(v, n, k);
        vec3 bxa = v3_cross(nb, na);
        for (int j = 0; j < p->ne; j++) {
            if (p->ef[j][0] < 0 || p->ef[j][1] < 0) continue;
            vec3 nc = v3_neg(p->fn[p->ef[j][0]]), nd = v3_neg(p->fn[p->ef[j][1]]);
            vec3 dxc = v3_cross(nd, nc);
            double cba = v3_dot(nc, bxa), dba = v3_dot(nd, bxa), adc = v3_dot(na, dxc), bdc = v3_dot(nb, dxc);
            if (!(cba * dba < 0 && adc * bdc < 0 && cba * bdc > 0)) continue;
            vec3 b0 = p->v[p->e[j][0]], db = v3_sub(p->v[p->e[j][1]], b0);
            vec3 ax = v3_cross(da, db);
            double l2 = v3_len2(ax);
            if (l2 < 1e-12 * v3_len2(da) * v3_len2(db)) continue;
            ax = v3_scale(ax, 1.0 / sqrt(l2));
            if (v3_dot(ax, v3_add(na, nb)) < 0) ax = v3_neg(ax);
            double sv = v3_dot(ax, v3_sub(b0, a0));
            if (sv > spec) { m->normal = ax; return; }
            if (sv > sep_e) { sep_e = sv; ek = k; ej = j; en = ax; }
        }
    }
    /* the triangle's face first (a resting shape keeps it, and contacts from
     * internal edges are turned to it) */
    poly t;
    triangle_poly(&t, v, n);
    poly_face_contact(&t, 0, p, cyl, xs, 0, spec, 0, m);
    /* a cylinder: its true line of support or deepest rim point, and no
     * other round points (a rim point beside the deepest, where the rim
     * crosses an edge of the triangle, is a point of the body that a
     * rolling cylinder moves down onto the floor: a speculative contact
     * there braked it, 0.5 m/s off the slope on a tessellated incline; the
     * neighbouring triangle holds the deepest point) */
    if (cyl) add_rim_point(v, n, s, xs, spec, m);
    /* another axis that separates more, from an active feature of the
     * triangle, replaces it when its contact is nearer: the face's points,
     * clipped to the triangle, can miss the shape's nearest corner. A shape
     * beside the triangle has no points over its face at all: then the
     * better of the other axes, however little better (else a box touching
     * a border edge had no contact) */
    manifold alt;
    memset(&alt, 0, sizeof alt);
    int beside = m->count == 0;
    double prefer_face = beside ? 0 : TRI_FACE_TOLERANCE;
    if (ek >= 0 && (active >> ek & 1u) &&
        (beside ? !(best_f >= 0 && sep_f > sep_e) : sep_e > dmax(sep_t, sep_f) + TRI_FACE_TOLERANCE)) {
        if (cyl) {
            cyl_edge_contact(v, ek, cyl, xs, en, sep_e, spec, &alt);
        } else {
            vec3 ca, cb;
            closest_segments(v[ek], v[(ek + 1) % 3], p->v[p->e[ej][0]], p->v[p->e[ej][1]], &ca, &cb);
            alt.normal = en;
            push_point(&alt, v3_scale(v3_add(ca, cb), 0.5), sep_e, 0x4000u | ((uint32_t)ek << 12) | (uint32_t)(ej & 0xfff));
        }
    } else if (best_f >= 0 && (beside || sep_f > sep_t + TRI_FACE_TOLERANCE) &&
               !(ek >= 0 && (active >> ek & 1u) && sep_e > sep_f + prefer_face)) {
        poly_face_contact(p, best_f, &t, NULL, xs, 1, spec, 0x20000000u, &alt);
        if (alt.count > 0 && !face_contact_active(v, n, active, p->fn[best_f], &alt, !beside)) alt.count = 0;
    }
    if (alt.count > 0) *m = alt;
    if (m->count == 0) look_ahead_point(v, n, active, s, xs, spec, m);
    /* apart: points clipped to a reference face can miss the nearest corner
     * of the other side; the separating axes bound the distance from below,
     * so no point may claim more room than they do. Overlapping on every
     * axis: the deepest point is at least as deep as the best axis says
     * (the face's points, clipped to the triangle, can all lie above its
     * plane while the shape's side cuts into a border edge) */
    double bound = dmax(sep_t, dmax(sep_f, sep_e));
    if (cyl && m->count > 0) {
        /* the internal edges' arcs bound the room too; searched only when
         * the bound would move a point (a cylinder over the neighbour, its
         * lowest line beside this triangle, was held as deep as that line
         * and rolled off its plane path by up to 0.4 mm more) */
        int moves = 0;
        double deepest = 1e300;
        for (int i = 0; i < m->count; i++) {
            deepest = dmin(deepest, m->points[i].separation);
            if (bound > 0 && m->points[i].separation > bound) moves = 1;
        }
        if (bound <= 0 && deepest > bound) moves = 1;
        for (int k = 0; k < 3 && moves; k++) {
            vec3 u;
            if (!(active >> k & 1u)) bound = dmax(bound, cyl_edge_axis(v, n, k, &cw, &u));
        }
    }
    if (bound > 0) {
        for (int i = 0; i < m->count; i++) m->points[i].separation = dmin(m->points[i].separation, bound);
    } else if (m->count > 0) {
        int deepest = 0;
        for (int i = 1; i < m->count; i++)
            if (m->points[i].separation < m->points[deepest].separation) deepest = i;
        if (m->points[deepest].separation > bound) m->points[deepest].separation = bound;
    }
}

/* Prepared once per pair: the convex shape in world space. */
typedef struct convex_view {
    const shape *s;
    xform x;
    int is_core;            /* sphere or capsule */
    vec3 c0, c1;            /* the core */
    poly p;                 /* box, hull, cylinder */
} convex_view;

static int convex_view_init(convex_view *cv, const shape *s, xform x)
{
    cv->s = s;
    cv->x = x;
    cv->is_core = s->type == SHAPE_SPHERE || s->type == SHAPE_CAPSULE;
    cv->c0 = cv->c1 = x.p;
    if (s->type == SHAPE_CAPSULE) capsule_segment(s, x, &cv->c0, &cv->c1);
    if (cv->is_core) return 1;
    if (!poly_from_shape(&cv->p, s, x)) return 0;
    poly_edge_faces(&cv->p);
    return 1;
}

static void triangle_contact(const convex_view *cv, const vec3 tri[3], unsigned active, int two_sided, double spec,
                             manifold *m)
{
    memset(m, 0, sizeof *m);
    vec3 v[3] = {tri[0], tri[1], tri[2]};
    vec3 n = v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0]));
    double len = v3_len(n);
    m->normal = v3(0, 0, 1);
    if (!(len > 0) || !isfinite(len)) return;
    n = v3_scale(n, 1.0 / len);
    if (two_sided) {
        /* the side the shape's centre is on is the front */
        vec3 c = cv->is_core ? v3_scale(v3_add(cv->c0, cv->c1), 0.5) : cv->p.center;
        if (v3_dot(n, v3_sub(c, v[0])) < 0) {
            v[1] = tri[2]; v[2] = tri[1];
            n = v3_neg(n);
            /* edges now run v0->v2 (was edge 2), v2->v1 (edge 1), v1->v0 (edge 0) */
            active = ((active >> 2) & 1u) | (active & 2u) | ((active & 1u) << 2);
        }
    }
    if (cv->is_core) triangle_core(v, n, active, cv->c0, cv->c1, cv->s->radius, spec, m);
    else triangle_polytope(v, n, active, &cv->p, cv->s, cv->x, spec, m);
}

int collide_triangle(const vec3 v[3], unsigned active, int two_sided, const shape *s, xform xs, double spec, manifold *m)
{
    convex_view cv;
    memset(m, 0, sizeof *m);
    m->normal = v3(0, 0, 1);
    if (!convex_view_init(&cv, s, xs)) return 0;
    triangle_contact(&cv, v, active, two_sided, spec, m);
    return m->count;
}

/* ---- many triangles --------------------------------------------------------- */

typedef struct contact_group {
    vec3 normal;
    double deepest;
    int count;
    manifold_point points[GROUP_CAPACITY];
} contact_group;

typedef struct composite_query {
    convex_view cv;
    xform xm;               /* the mesh's frame */
    int two_sided;
    double spec;
    int max_groups, group_count;
    contact_group groups[COMPOSITE_MAX_MANIFOLDS];
} composite_query;

/* Keeps only the corners of the points' outline in the contact plane: the
 * points clipped at triangle edges inside a face (or along its sides) add
 * nothing, and left in they could take the place of a true corner in the
 * reduction, shifting the support and twisting a sliding box. */
int manifold_outline(manifold_point *pts, int n, vec3 normal)
{
    if (n <= 3 || n > GROUP_CAPACITY) return n;
    vec3 u, w;
    v3_basis(normal, &u, &w);
    double x[GROUP_CAPACITY], y[GROUP_CAPACITY];
    int order[GROUP_CAPACITY], hull[2 * GROUP_CAPACITY];
    for (int i = 0; i < n; i++) {
        x[i] = v3_dot(pts[i].point, u);
        y[i] = v3_dot(pts[i].point, w);
        order[i] = i;
    }
    /* insertion sort by x, then y (n <= 64) */
    for (int i = 1; i < n; i++) {
        int k = order[i], j = i - 1;
        while (j >= 0 && (x[order[j]] > x[k] || (x[order[j]] == x[k] && y[order[j]] > y[k]))) { order[j + 1] = order[j]; j--; }
        order[j + 1] = k;
    }
    double span = fabs(x[order[n - 1]] - x[order[0]]);
    for (int i = 0; i < n; i++) span = dmax(span, fabs(y[i] - y[order[0]]));
    double tol = 1e-9 * span * span;
    /* Andrew's monotone chain; collinear points are dropped */
    int h = 0;
    for (int pass = 0; pass < 2; pass++) {
        int start = h;
        for (int t = 0; t < n; t++) {
            int i = pass == 0 ? order[t] : order[n - 1 - t];
            while (h >= start + 2) {
                int a = hull[h - 2], b = hull[h - 1];
                double cr = (x[b] - x[a]) * (y[i] - y[a]) - (y[b] - y[a]) * (x[i] - x[a]);
                if (cr > tol) break;
                h--;
            }
            hull[h++] = i;
        }
        h--; /* the last point starts the other chain */
    }
    if (h < 3) return n; /* all on a line: leave them to the reduction */
    manifold_point kept[GROUP_CAPACITY];
    for (int i = 0; i < h; i++) kept[i] = pts[hull[i]];
    /* on a plane no point inside is deeper than every corner; on a curved
     * surface one can be, and it stays (the reduction keeps the deepest):
     * a sphere's points from several triangles, all on the line through its
     * centre, made a "hull" of rounding noise that left out the one 0.027 m
     * deep, for one 0.014 m above */
    int deepest = 0;
    double kept_low = 1e300;
    for (int i = 1; i < n; i++)
        if (pts[i].separation < pts[deepest].separation) deepest = i;
    for (int i = 0; i < h; i++) kept_low = dmin(kept_low, kept[i].separation);
    if (pts[deepest].separation < kept_low - 1e-6 && h < GROUP_CAPACITY) kept[h++] = pts[deepest];
    for (int i = 0; i < h; i++) pts[i] = kept[i];
    return h;
}

/* manifold_reduce picks its fourth point by the largest of the three
 * triangles it makes with the first three's edges, unsigned: a corner next
 * to the second point, inside the triangle's edge, scores as much as the
 * true fourth corner across it. On a 16 mm strip of a patch beside a box's
 * footprint that dropped the box's own corner for a point 1 mm from
 * another, and the merged floor manifold (ghost.c) lost a corner: the box
 * tipped (5 mm/s vertical at fast). Here the area counts only outside the
 * triangle. */
int manifold_reduce_outline(manifold_point *pts, int n, vec3 normal)
{
    if (n <= MANIFOLD_MAX_POINTS) return n;
    if (n > GROUP_CAPACITY) n = GROUP_CAPACITY;
    int i0 = 0;
    for (int i = 1; i < n; i++)
        if (pts[i].separation < pts[i0].separation) i0 = i;
    int i1 = -1, i2 = -1, i3 = -1;
    double best = -1;
    for (int i = 0; i < n; i++) {
        if (i == i0) continue;
        vec3 d = v3_sub(pts[i].point, pts[i0].point);
        d = v3_madd(d, -v3_dot(d, normal), normal);
        if (v3_len2(d) > best) { best = v3_len2(d); i1 = i; }
    }
    best = -1;
    double orient = 0;
    for (int i = 0; i < n; i++) {
        if (i == i0 || i == i1) continue;
        double a = v3_dot(v3_cross(v3_sub(pts[i1].point, pts[i0].point), v3_sub(pts[i].point, pts[i0].point)), normal);
        if (fabs(a) > best) { best = fabs(a); i2 = i; orient = a < 0 ? -1.0 : 1.0; }
    }
    best = -INFINITY;
    const int tri[3] = {i0, i1, i2};
    for (int i = 0; i < n; i++) {
        if (i == i0 || i == i1 || i == i2) continue;
        double added = -INFINITY;
        for (int k = 0; k < 3; k++) {
            vec3 a = pts[tri[k]].point, b = pts[tri[(k + 1) % 3]].point;
            /* outside edge a-b of a triangle turning `orient`: the turn reverses */
            added = dmax(added, -orient * v3_dot(v3_cross(v3_sub(b, a), v3_sub(pts[i].point, a)), normal));
        }
        if (added > best) { best = added; i3 = i; }
    }
    manifold_point out[MANIFOLD_MAX_POINTS] = {pts[i0], pts[i1], pts[i2], pts[i3]};
    for (int i = 0; i < MANIFOLD_MAX_POINTS; i++) pts[i] = out[i];
    return MANIFOLD_MAX_POINTS;
}

/* A sphere or capsule contact point (p, separation along n) moved to the
 * group's normal g: the point at the bottom of the core along g, the
 * separation of the same triangle feature along g (no more than the true
 * distance). A sphere's point left where an edge's normal put it, off the
 * line through its centre along g, moves up and down as the sphere rolls:
 * the solver then lifts it (the bump of a sphere rolling onto the next of
 * several separate mesh patches, 51 mm off its path on a plane). */
static void core_along(manifold_point *mp, vec3 n, vec3 g, double r)
{
    vec3 core = v3_madd(mp->point, r + 0.5 * mp->separation, n);
    vec3 feature = v3_madd(mp->point, -0.5 * mp->separation, n);
    double sep = v3_dot(g, v3_sub(core, feature)) - r;
    mp->point = v3_madd(core, -(r + 0.5 * sep), g);
    mp->separation = sep;
}

static int visit_triangle(void *ctx, const vec3 v[3], unsigned active, uint32_t index)
{
    composite_query *q = ctx;
    vec3 w[3] = {xf_point(q->xm, v[0]), xf_point(q->xm, v[1]), xf_point(q->xm, v[2])};
    manifold m;
    triangle_contact(&q->cv, w, active, q->two_sided, q->spec, &m);
    if (m.count == 0) return 1;
    int g = -1;
    double best = -2;
    for (int i = 0; i < q->group_count; i++) {
        double c = v3_dot(q->groups[i].normal, m.normal);
        if (c > best) { best = c; g = i; }
    }
    if (best < (q->cv.is_core ? CORE_GROUP_COS : GROUP_COS) && q->group_count < q->max_groups) {
        g = q->group_count++;
        q->groups[g].normal = m.normal;
        q->groups[g].count = 0;
        q->groups[g].deepest = 1e300;
    }
    contact_group *gr = &q->groups[g];
    for (int i = 0; i < m.count; i++) {
        if (gr->count == GROUP_CAPACITY) {
            gr->count = manifold_outline(gr->points, gr->count, gr->normal);
            if (gr->count > GROUP_CAPACITY / 2) gr->count = manifold_reduce_outline(gr->points, gr->count, gr->normal);
        }
        manifold_point mp = m.points[i];
        /* more normals than groups: a sphere's point goes to the group's normal */
        int moved = q->cv.is_core && v3_dot(gr->normal, m.normal) < CORE_GROUP_COS;
        if (moved) core_along(&mp, m.normal, gr->normal, q->cv.s->radius);
        /* a vertex of the shape itself on the triangle's face keeps its id
         * from triangle to triangle (warm starting follows it); other points
         * are told apart by the triangle */
        if (mp.id & 0xfff0ff80u) mp.id = (mp.id & 0x3fffffffu) ^ (index * 0x9E3779B1u);
        if (mp.separation < gr->deepest) {
            gr->deepest = mp.separation;
            if (!moved) gr->normal = m.normal; /* the deepest triangle's normal speaks for the group */
        }
        gr->points[gr->count++] = mp;
    }
    return 1;
}

/* Points all on one line (a cylinder on its side, a box's edge, a capsule,
 * across several triangles): two points only, as a plane gives. Four points
 * on a line make the manifold's normal rows singular for the block solve: a
 * cylinder rolling on a flat mesh at `fast` moved 1.6 mm/s vertically, on a
 * plane 1.7e-11.
 * The two are the line's ends, each the deepest of the points at that end,
 * where the points are placed at the shape's own surface (a point is midway
 * between the shapes: the same end of a capsule's core over two triangles
 * is two points, one deep over the triangle under it, one shallow beside
 * the next, half their separations apart along the normal, which a tilted
 * normal turns into millimetres along the line; taking the farther one, a
 * capsule lying across a hillside lost its deepest point, 0.020 m deep,
 * and sank to 0.028 m the next step). And on a curved surface the deepest
 * point can lie between the ends (a ridge under the middle): deeper than
 * both ends by more than 1 um, it takes the place of the nearer end, so no
 * manifold ever leaves out its deepest point. */
static vec3 line_position(const manifold_point *mp, vec3 normal)
{
    vec3 p = v3_madd(mp->point, 0.5 * mp->separation, normal); /* on the shape */
    return v3_madd(p, -v3_dot(p, normal), normal);
}

static int keep_line_ends(manifold_point *pts, int n, vec3 normal)
{
    if (n <= 2) return n;
    vec3 at[GROUP_CAPACITY];
    if (n > GROUP_CAPACITY) n = GROUP_CAPACITY;
    for (int i = 0; i < n; i++) at[i] = line_position(&pts[i], normal);
    int a = 0, b = 0;
    double best = -1;
    for (int i = 1; i < n; i++)
        if (v3_len2(v3_sub(at[i], at[0])) > best) { best = v3_len2(v3_sub(at[i], at[0])); a = i; }
    best = -1;
    for (int i = 0; i < n; i++)
        if (v3_len2(v3_sub(at[i], at[a])) > best) { best = v3_len2(v3_sub(at[i], at[a])); b = i; }
    vec3 ab = v3_sub(at[b], at[a]);
    double l2 = v3_len2(ab);
    if (!(l2 > 1e-18)) return n;
    for (int i = 0; i < n; i++) {
        vec3 off = v3_cross(ab, v3_sub(at[i], at[a])); /* |ab| times the distance off the line */
        if (v3_len2(off) > 1e-12 * l2 * l2) return n; /* farther than 1e-6 of the length: not a line */
    }
    /* each end: the deepest point there (within 1e-6 of the length) */
    int ea = a, eb = b;
    for (int i = 0; i < n; i++) {
        if (v3_len2(v3_sub(at[i], at[a])) <= 1e-12 * l2 && pts[i].separation < pts[ea].separation) ea = i;
        if (v3_len2(v3_sub(at[i], at[b])) <= 1e-12 * l2 && pts[i].separation < pts[eb].separation) eb = i;
    }
    /* the deepest point between them, if deeper than both by more than 1 um */
    int low = -1;
    double lowest = dmin(pts[ea].separation, pts[eb].separation) - 1e-6;
    for (int i = 0; i < n; i++)
        if (pts[i].separation < lowest) { lowest = pts[i].separation; low = i; }
    manifold_point ends[2] = {pts[ea], pts[eb]};
    if (low >= 0) /* it and the end farther from it */
        ends[v3_len2(v3_sub(at[low], at[ea])) < v3_len2(v3_sub(at[low], at[eb])) ? 0 : 1] = pts[low];
    pts[0] = ends[0];
    pts[1] = ends[1];
    return 2;
}

int collide_composite(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *out, int max)
{
    int mesh_first = shape_is_composite(a);
    const shape *ms = mesh_first ? a : b, *cs = mesh_first ? b : a;
    xform xm = mesh_first ? xa : xb, xc = mesh_first ? xb : xa;
    if (max > COMPOSITE_MAX_MANIFOLDS) max = COMPOSITE_MAX_MANIFOLDS;
    if (shape_is_composite(cs) || cs->type == SHAPE_PLANE || max < 1) return 0;
    composite_query *q = malloc(sizeof *q);
    if (!q) return 0;
    if (!convex_view_init(&q->cv, cs, xc)) { free(q); return 0; }
    q->xm = xm;
    q->two_sided = ms->type == SHAPE_MESH && ms->mesh->two_sided;
    q->spec = spec;
    q->max_groups = max;
    q->group_count = 0;
    /* the convex shape's bounds in the mesh's frame */
    xform rel = {xf_inv_point(xm, xc.p), q_mul(q_conj(xm.q), xc.q)};
    aabb box = aabb_fatten(shape_aabb(cs, rel), spec > 0 ? spec : 0);
    if (ms->type == SHAPE_MESH) mesh_query(ms->mesh, box, visit_triangle, q);
    else heightfield_query(ms->field, box, visit_triangle, q);
    int n = 0;
    for (int g = 0; g < q->group_count; g++) {
        contact_group *gr = &q->groups[g];
        manifold *m = &out[n++];
        memset(m, 0, sizeof *m);
        int c = manifold_outline(gr->points, gr->count, gr->normal);
        c = manifold_reduce_outline(gr->points, c, gr->normal);
        c = keep_line_ends(gr->points, c, gr->normal);
        m->normal = mesh_first ? gr->normal : v3_neg(gr->normal);
        for (int i = 0; i < c; i++) m->points[i] = gr->points[i];
        m->count = c;
    }
    free(q);
    return n;
}
