/* narrowphase.c - contact manifolds by pair type. Round pairs are analytic;
 * boxes and hulls go through one exact separating-axis test over faces and
 * edge pairs, then reference/incident face clipping; a cylinder against any
 * of them works on the true round shape (GJK apart, libccd's MPR
 * overlapping, faces and caps as preferred axes; see cylinder_contact). The
 * normal always points from a to b. */
#include <string.h>
#include <ccd/ccd.h>
#include "gjk.h"
#include "manifold.h"

#define FACE_TOLERANCE 1e-3   /* prefer a face axis unless an edge axis separates more than this (m) */
#define KEEP_TOLERANCE 5e-4   /* keep last step's reference face when within this (m) */
#define CLIP_TOLERANCE 5e-4   /* incident vertices this close outside a side plane are kept, so
                                 aligned stacks keep the same feature ids under tiny jitter */

/* ---- building polytopes ------------------------------------------------------- */

/* Faces beside each edge, by matching face boundary segments to edges. */
void poly_edge_faces(poly *p)
{
    /* each edge listed under its lower vertex, in increasing edge order (the
     * first match is the one a scan of every edge would find), so a face
     * edge looks at a vertex's few edges, not at all of them (this ran for
     * every mesh query: 11 % of a terrain step) */
    int head[POLY_MAX_V], next[POLY_MAX_FV / 2];
    for (int i = 0; i < p->nv; i++) head[i] = -1;
    for (int i = p->ne - 1; i >= 0; i--) {
        int lo = p->e[i][0] < p->e[i][1] ? p->e[i][0] : p->e[i][1];
        next[i] = head[lo];
        head[lo] = i;
        p->ef[i][0] = p->ef[i][1] = -1;
    }
    for (int f = 0; f < p->nf; f++) {
        int n = p->fcount[f], first = p->ffirst[f];
        for (int k = 0; k < n; k++) {
            int u = p->fv[first + k], v = p->fv[first + (k + 1) % n];
            int lo = u < v ? u : v, hi = u < v ? v : u;
            for (int i = head[lo]; i >= 0; i = next[i])
                if (p->e[i][0] + p->e[i][1] - lo == hi) {
                    p->ef[i][p->ef[i][0] < 0 ? 0 : 1] = f;
                    break;
                }
        }
    }
}

void poly_finish(poly *p)
{
    p->center = v3_zero();
    for (int i = 0; i < p->nv; i++) p->center = v3_add(p->center, p->v[i]);
    p->center = v3_scale(p->center, 1.0 / p->nv);
    for (int f = 0; f < p->nf; f++) p->fd[f] = v3_dot(p->fn[f], p->v[p->fv[p->ffirst[f]]]);
}

static void poly_from_hull(poly *p, const hull *h, xform x)
{
    p->nv = h->vertex_count;
    p->nf = h->face_count;
    p->ne = h->edge_count;
    for (int i = 0; i < h->vertex_count; i++) p->v[i] = xf_point(x, h->vertices[i]);
    int k = 0;
    for (int f = 0; f < h->face_count; f++) {
        p->fn[f] = q_rotate(x.q, h->faces[f].normal);
        p->ffirst[f] = k;
        p->fcount[f] = h->faces[f].count;
        for (int j = 0; j < h->faces[f].count; j++) p->fv[k++] = h->face_vertices[h->faces[f].first + j];
    }
    for (int i = 0; i < h->edge_count; i++) { p->e[i][0] = h->edges[i][0]; p->e[i][1] = h->edges[i][1]; }
    poly_finish(p);
}

/* A box's vertices: vertex i has +x when bit 0 is set, +y bit 1, +z bit 2.
 * Faces in the order +x -x +y -y +z -z, each counter-clockwise from outside. */
static const int box_faces[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3}, {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};
static const double box_normals[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

static inline vec3 box_vertex(vec3 he, const xform *x, int i)
{
    return xf_point(*x, v3((i & 1) ? he.x : -he.x, (i & 2) ? he.y : -he.y, (i & 4) ? he.z : -he.z));
}

static void poly_from_box(poly *p, vec3 he, xform x)
{
    static const int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3}, {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    p->nv = 8; p->nf = 6; p->ne = 12;
    for (int i = 0; i < 8; i++) p->v[i] = box_vertex(he, &x, i);
    for (int f = 0; f < 6; f++) {
        p->fn[f] = q_rotate(x.q, v3(box_normals[f][0], box_normals[f][1], box_normals[f][2]));
        p->ffirst[f] = 4 * f;
        p->fcount[f] = 4;
        for (int j = 0; j < 4; j++) p->fv[4 * f + j] = box_faces[f][j];
    }
    for (int i = 0; i < 12; i++) { p->e[i][0] = edges[i][0]; p->e[i][1] = edges[i][1]; }
    poly_finish(p);
}

/* A cylinder as a prism whose vertices lie on the true rims. */
static void poly_from_cylinder(poly *p, double r, double hh, xform x)
{
    const int n = CYL_SIDES;
    p->nv = 2 * n; p->nf = n + 2; p->ne = 3 * n;
    for (int i = 0; i < n; i++) {
        double a = 6.283185307179586 * i / n;
        p->v[i] = xf_point(x, v3(r * cos(a), r * sin(a), -hh));
        p->v[n + i] = xf_point(x, v3(r * cos(a), r * sin(a), hh));
    }
    int k = 0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double a = 6.283185307179586 * (i + 0.5) / n;
        p->fn[i] = q_rotate(x.q, v3(cos(a), sin(a), 0));
        p->ffirst[i] = k;
        p->fcount[i] = 4;
        p->fv[k++] = i; p->fv[k++] = j; p->fv[k++] = n + j; p->fv[k++] = n + i;
        p->e[i][0] = i; p->e[i][1] = j;
        p->e[n + i][0] = n + i; p->e[n + i][1] = n + j;
        p->e[2 * n + i][0] = i; p->e[2 * n + i][1] = n + i;
    }
    p->fn[n] = q_rotate(x.q, v3(0, 0, 1));
    p->ffirst[n] = k; p->fcount[n] = n;
    for (int i = 0; i < n; i++) p->fv[k++] = n + i;
    p->fn[n + 1] = q_rotate(x.q, v3(0, 0, -1));
    p->ffirst[n + 1] = k; p->fcount[n + 1] = n;
    for (int i = n - 1; i >= 0; i--) p->fv[k++] = i;
    poly_finish(p);
}

int poly_from_shape(poly *p, const shape *s, xform x)
{
    switch (s->type) {
    case SHAPE_BOX: poly_from_box(p, s->half_extents, x); return 1;
    case SHAPE_HULL:
        if (s->hull->vertex_count > POLY_MAX_V || s->hull->face_count > POLY_MAX_F ||
            s->hull->edge_count > POLY_MAX_FV / 2)
            return 0; /* cannot happen: body creation rejects such hulls */
        poly_from_hull(p, s->hull, x);
        return 1;
    case SHAPE_CYLINDER: poly_from_cylinder(p, s->radius, s->half_height, x); return 1;
    default: return 0;
    }
}

/* ---- small geometry -------------------------------------------------------- */

static double poly_min_along(const poly *p, vec3 n)
{
    double m = v3_dot(p->v[0], n);
    for (int i = 1; i < p->nv; i++) m = dmin(m, v3_dot(p->v[i], n));
    return m;
}

/* Closest points of segments p1q1 and p2q2 (Ericson, Real-Time Collision Detection 5.1.9). */
void closest_segments(vec3 p1, vec3 q1, vec3 p2, vec3 q2, vec3 *c1, vec3 *c2)
{
    vec3 d1 = v3_sub(q1, p1), d2 = v3_sub(q2, p2), r = v3_sub(p1, p2);
    double a = v3_dot(d1, d1), e = v3_dot(d2, d2), f = v3_dot(d2, r), s, t;
    if (a <= 1e-30 && e <= 1e-30) { *c1 = p1; *c2 = p2; return; }
    if (a <= 1e-30) { s = 0; t = dmin(dmax(f / e, 0), 1); }
    else {
        double c = v3_dot(d1, r);
        if (e <= 1e-30) { t = 0; s = dmin(dmax(-c / a, 0), 1); }
        else {
            double b = v3_dot(d1, d2), den = a * e - b * b;
            s = den > 1e-30 * a * e ? dmin(dmax((b * f - c * e) / den, 0), 1) : 0;
            t = (b * s + f) / e;
            if (t < 0) { t = 0; s = dmin(dmax(-c / a, 0), 1); }
            else if (t > 1) { t = 1; s = dmin(dmax((b - c) / a, 0), 1); }
        }
    }
    *c1 = v3_madd(p1, s, d1);
    *c2 = v3_madd(p2, t, d2);
}

static vec3 any_unit(vec3 n, vec3 fallback)
{
    double l = v3_len(n);
    return l > 1e-12 ? v3_scale(n, 1.0 / l) : fallback;
}

static void add_point(manifold *m, vec3 p, double sep, uint32_t id)
{
    if (m->count >= MANIFOLD_MAX_POINTS) return;
    m->points[m->count].point = p;
    m->points[m->count].separation = sep;
    m->points[m->count].id = id;
    m->count++;
}

/* ---- analytic pairs ---------------------------------------------------------- */

/* Two spheres (or sphere-swept points) of radii ra, rb at ca, cb. */
static void sphere_sphere(vec3 ca, double ra, vec3 cb, double rb, double spec, uint32_t id, manifold *m)
{
    vec3 d = v3_sub(cb, ca);
    double dist = v3_len(d);
    vec3 n = dist > 1e-12 ? v3_scale(d, 1.0 / dist) : v3(0, 0, 1);
    double sep = dist - ra - rb;
    m->normal = n;
    if (sep >= spec) return;
    vec3 pa = v3_madd(ca, ra, n), pb = v3_madd(cb, -rb, n);
    add_point(m, v3_scale(v3_add(pa, pb), 0.5), sep, id);
}

static void plane_world(const shape *pl, xform x, vec3 *n, double *d)
{
    *n = q_rotate(x.q, pl->plane_normal);
    *d = pl->plane_offset + v3_dot(*n, x.p);
}

/* Shape a against plane b (normal of the manifold: from a into the plane, i.e. -plane normal). */
static void shape_plane(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *m)
{
    vec3 n;
    double d;
    plane_world(b, xb, &n, &d);
    m->normal = v3_neg(n);
    manifold_point cand[POLY_MAX_V];
    int nc = 0;
    switch (a->type) {
    case SHAPE_SPHERE: {
        double sep = v3_dot(n, xa.p) - d - a->radius;
        if (sep < spec) add_point(m, v3_madd(xa.p, -(a->radius + 0.5 * sep), n), sep, 0);
        return;
    }
    case SHAPE_CAPSULE: {
        vec3 axis = q_rotate(xa.q, v3(0, 0, a->half_height));
        for (int i = 0; i < 2; i++) {
            vec3 c = i ? v3_sub(xa.p, axis) : v3_add(xa.p, axis);
            double sep = v3_dot(n, c) - d - a->radius;
            if (sep < spec) add_point(m, v3_madd(c, -(a->radius + 0.5 * sep), n), sep, (uint32_t)i);
        }
        return;
    }
    case SHAPE_CYLINDER: {
        /* exact rim points: the deepest rim point and its neighbours a quarter turn away */
        vec3 axis = q_rotate(xa.q, v3(0, 0, 1));
        vec3 radial = v3_sub(v3_neg(n), v3_scale(axis, v3_dot(v3_neg(n), axis)));
        vec3 u, w;
        if (v3_len2(radial) > 1e-16) { u = v3_normalize(radial); w = v3_cross(axis, u); }
        else v3_basis(axis, &u, &w);
        double cap_side = v3_dot(axis, n) > 0 ? -1.0 : 1.0; /* the cap nearer the plane */
        vec3 rims[6];
        int ids[6];
        int k = 0;
        for (int cap = 0; cap < 2; cap++) {
            double hz = (cap == 0 ? cap_side : -cap_side) * a->half_height;
            vec3 c = v3_madd(xa.p, hz, axis);
            rims[k] = v3_madd(c, a->radius, u); ids[k++] = (uint32_t)(cap * 4 + 0);
            if (cap == 0) {
                rims[k] = v3_madd(c, a->radius, w); ids[k++] = 1;
                rims[k] = v3_madd(c, -a->radius, w); ids[k++] = 2;
                rims[k] = v3_madd(c, -a->radius, u); ids[k++] = 3;
            }
        }
        for (int i = 0; i < k; i++) {
            double sep = v3_dot(n, rims[i]) - d;
            if (sep < spec) {
                cand[nc].point = v3_madd(rims[i], -0.5 * sep, n);
                cand[nc].separation = sep;
                cand[nc].id = (uint32_t)ids[i];
                nc++;
            }
        }
        break;
    }
    case SHAPE_BOX: case SHAPE_HULL: {
        /* the face turned to the plane, and the deepest vertex: a body smaller
         * than the look-ahead has every vertex within it, and letting the far
         * face's vertices into the four points would leave it standing on
         * fewer than its real supports (a 1 cm box then rocked and walked) */
        poly p;
        if (!poly_from_shape(&p, a, xa)) return;
        int face = 0, deepest = 0;
        for (int f = 1; f < p.nf; f++)
            if (v3_dot(p.fn[f], n) < v3_dot(p.fn[face], n)) face = f;
        for (int i = 1; i < p.nv; i++)
            if (v3_dot(n, p.v[i]) < v3_dot(n, p.v[deepest])) deepest = i;
        unsigned char keep[POLY_MAX_V] = {0};
        for (int k = 0; k < p.fcount[face]; k++) keep[p.fv[p.ffirst[face] + k]] = 1;
        keep[deepest] = 1;
        for (int i = 0; i < p.nv; i++) { /* in vertex order, as the ids */
            if (!keep[i]) continue;
            double sep = v3_dot(n, p.v[i]) - d;
            if (sep < spec) {
                cand[nc].point = v3_madd(p.v[i], -0.5 * sep, n);
                cand[nc].separation = sep;
                cand[nc].id = (uint32_t)i;
                nc++;
            }
        }
        break;
    }
    default:
        return;
    }
    nc = manifold_reduce(cand, nc, n);
    for (int i = 0; i < nc; i++) m->points[i] = cand[i];
    m->count = nc;
}

static void sphere_box(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *m)
{
    vec3 c = xf_inv_point(xb, xa.p), h = b->half_extents;
    vec3 q = v3(dmin(dmax(c.x, -h.x), h.x), dmin(dmax(c.y, -h.y), h.y), dmin(dmax(c.z, -h.z), h.z));
    vec3 d = v3_sub(c, q);
    double dist = v3_len(d), sep;
    vec3 nl; /* local normal from the box towards the sphere */
    if (dist > 1e-12) {
        nl = v3_scale(d, 1.0 / dist);
        sep = dist - a->radius;
    } else {
        /* centre inside: leave through the nearest face */
        double dx = h.x - fabs(c.x), dy = h.y - fabs(c.y), dz = h.z - fabs(c.z);
        if (dx <= dy && dx <= dz) { nl = v3(c.x < 0 ? -1 : 1, 0, 0); q = v3(nl.x * h.x, c.y, c.z); sep = -dx - a->radius; }
        else if (dy <= dz) { nl = v3(0, c.y < 0 ? -1 : 1, 0); q = v3(c.x, nl.y * h.y, c.z); sep = -dy - a->radius; }
        else { nl = v3(0, 0, c.z < 0 ? -1 : 1); q = v3(c.x, c.y, nl.z * h.z); sep = -dz - a->radius; }
    }
    vec3 n = q_rotate(xb.q, nl);
    m->normal = v3_neg(n); /* from the sphere (a) to the box (b) */
    if (sep >= spec) return;
    vec3 pb = xf_point(xb, q);
    add_point(m, v3_madd(pb, 0.5 * sep, n), sep, 0);
}

void capsule_segment(const shape *s, xform x, vec3 *p0, vec3 *p1)
{
    vec3 axis = q_rotate(x.q, v3(0, 0, s->half_height));
    *p0 = v3_sub(x.p, axis);
    *p1 = v3_add(x.p, axis);
}

static void sphere_capsule(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *m)
{
    vec3 p0, p1, ca, cb;
    capsule_segment(b, xb, &p0, &p1);
    closest_segments(xa.p, xa.p, p0, p1, &ca, &cb);
    sphere_sphere(ca, a->radius, cb, b->radius, spec, 0, m);
}

static void capsule_capsule(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *m)
{
    vec3 a0, a1, b0, b1, ca, cb;
    capsule_segment(a, xa, &a0, &a1);
    capsule_segment(b, xb, &b0, &b1);
    vec3 da = v3_sub(a1, a0), db = v3_sub(b1, b0);
    vec3 cr = v3_cross(da, db);
    double par = v3_len2(cr) / (v3_len2(da) * v3_len2(db) + 1e-300);
    if (par < 1e-6) {
        /* parallel: two points over the overlap of the segments */
        vec3 u = v3_normalize(da);
        double s0 = v3_dot(v3_sub(b0, a0), u), s1 = v3_dot(v3_sub(b1, a0), u), len = v3_len(da);
        double lo = dmax(0, dmin(s0, s1)), hi = dmin(len, dmax(s0, s1));
        if (hi > lo + 1e-9) {
            vec3 off = v3_sub(b0, v3_madd(a0, s0, u)); /* from a's line to b's line */
            vec3 n = any_unit(off, v3(0, 0, 1));
            double dist = v3_len(off), sep = dist - a->radius - b->radius;
            m->normal = n;
            if (sep >= spec) return;
            for (int i = 0; i < 2; i++) {
                vec3 pa = v3_madd(a0, i ? hi : lo, u);
                vec3 p = v3_madd(pa, a->radius + 0.5 * sep, n);
                add_point(m, p, sep, (uint32_t)i);
            }
            return;
        }
    }
    closest_segments(a0, a1, b0, b1, &ca, &cb);
    sphere_sphere(ca, a->radius, cb, b->radius, spec, 0, m);
}

/* ---- polytope against polytope ----------------------------------------------- */

/* The true cylinder's line of support against a plane of normal n (pointing
 * away from the plane): the two rim points deepest along -n. Returns 0 when
 * the axis is along n (the cap lies flat: its prism face is exact). */
static int cylinder_support_line(const shape *cyl, xform x, vec3 n, clip_vertex out[2])
{
    vec3 axis = q_rotate(x.q, v3(0, 0, 1));
    vec3 radial = v3_madd(v3_neg(n), v3_dot(n, axis), axis); /* -n without its axial part */
    if (v3_len2(radial) < 1e-12) return 0;
    radial = v3_normalize(radial);
    for (int i = 0; i < 2; i++) {
        out[i].p = v3_add(v3_madd(x.p, i ? cyl->half_height : -cyl->half_height, axis), v3_scale(radial, cyl->radius));
        out[i].id = 0x40u + (uint32_t)i; /* apart from the prism's vertex ids (< 2 CYL_SIDES) */
    }
    return 1;
}

/* Incident face clipped against reference face rf. inc_cyl: the incident
 * shape when it is a cylinder (its round side then touches along the true
 * line of support, not along a prism facet, which would let it settle onto
 * the facet: roll up to 11 degrees and away), else NULL. */
void poly_face_contact(const poly *ref, int rf, const poly *inc, const shape *inc_cyl, xform inc_x, int flip,
                              double spec, uint32_t tag, manifold *m)
{
    vec3 n = ref->fn[rf];
    /* incident face: the most anti-parallel */
    int inf = 0;
    double best = 1e300;
    for (int f = 0; f < inc->nf; f++) {
        double dd = v3_dot(inc->fn[f], n);
        if (dd < best) { best = dd; inf = f; }
    }
    clip_vertex buf1[CLIP_MAX], buf2[CLIP_MAX];
    int nbuf = inc->fcount[inf];
    if (nbuf > CLIP_MAX / 2) nbuf = CLIP_MAX / 2;
    for (int i = 0; i < nbuf; i++) {
        int vi = inc->fv[inc->ffirst[inf] + i];
        buf1[i].p = inc->v[vi];
        buf1[i].id = (uint32_t)(vi & 0x7f);
    }
    int segment = inc_cyl && inf < CYL_SIDES && cylinder_support_line(inc_cyl, inc_x, n, buf1);
    if (segment) nbuf = 2;
    clip_vertex *in = buf1, *out = buf2;
    int rc = ref->fcount[rf];
    /* parallel faces (a stack): a vertex just outside a side plane is as deep
     * as the ones inside, and keeping it keeps the ids steady under jitter */
    double tol = 1.0 + best < 1e-8 ? CLIP_TOLERANCE : 0.0;
    for (int e = 0; e < rc && nbuf > 0; e++) {
        vec3 a = ref->v[ref->fv[ref->ffirst[rf] + e]], b = ref->v[ref->fv[ref->ffirst[rf] + (e + 1) % rc]];
        vec3 side = v3_normalize(v3_cross(v3_sub(b, a), n));
        if (nbuf + 1 > CLIP_MAX) break;
        nbuf = clip_polygon(in, nbuf, side, v3_dot(side, a) + tol, (uint32_t)(e & 0xff), out);
        if (segment && nbuf > 2) nbuf = 2; /* a segment clipped as a closed polygon repeats a point */
        clip_vertex *t = in; in = out; out = t;
    }
    manifold_point cand[CLIP_MAX];
    int nc = 0;
    for (int i = 0; i < nbuf; i++) {
        double sep = v3_dot(n, in[i].p) - ref->fd[rf];
        if (sep >= spec) continue;
        cand[nc].point = v3_madd(in[i].p, -0.5 * sep, n);
        cand[nc].separation = sep;
        cand[nc].id = tag | ((uint32_t)(rf & 0xff) << 20) | ((uint32_t)(inf & 0x0f) << 16) | (in[i].id & 0xffffu);
        nc++;
    }
    nc = manifold_reduce(cand, nc, n);
    m->normal = flip ? v3_neg(n) : n;
    for (int i = 0; i < nc; i++) m->points[i] = cand[i];
    m->count = nc;
}

/* Support of the true shape (libccd callback): the shape and its transform. */
typedef struct ccd_obj { const shape *s; xform x; } ccd_obj;

static void ccd_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const ccd_obj *o = obj;
    vec3 d = q_inv_rotate(o->x.q, v3(dir->v[0], dir->v[1], dir->v[2]));
    vec3 p = xf_point(o->x, shape_support_local(o->s, d));
    out->v[0] = p.x; out->v[1] = p.y; out->v[2] = p.z;
}

static void ccd_center(const void *obj, ccd_vec3_t *out)
{
    const ccd_obj *o = obj;
    out->v[0] = o->x.p.x; out->v[1] = o->x.p.y; out->v[2] = o->x.p.z;
}

static void poly_poly(const shape *sa, xform xa, const shape *sb, xform xb, double spec, collide_cache *cache,
                      manifold *m)
{
    poly pa_buf, pb_buf; /* on the stack: no shared state between worlds or threads */
    poly *pa = &pa_buf, *pb = &pb_buf;
    if (!poly_from_shape(pa, sa, xa) || !poly_from_shape(pb, sb, xb)) return;
    /* face axes of a, of b */
    double sa_best = -1e300, sb_best = -1e300;
    int fa = -1, fb = -1;
    for (int f = 0; f < pa->nf; f++) {
        double s = poly_min_along(pb, pa->fn[f]) - pa->fd[f];
        if (s > sa_best) { sa_best = s; fa = f; }
    }
    if (fa < 0) return; /* non-finite distances: no contact */
    if (sa_best > spec) { m->normal = pa->fn[fa]; return; }
    for (int f = 0; f < pb->nf; f++) {
        double s = poly_min_along(pa, pb->fn[f]) - pb->fd[f];
        if (s > sb_best) { sb_best = s; fb = f; }
    }
    if (fb < 0) return;
    if (sb_best > spec) { m->normal = v3_neg(pb->fn[fb]); return; }
    /* edge pairs: only those whose Gauss-map arcs cross (they bound a face of
     * the Minkowski difference); for them the edges' own points give the
     * separation, no vertex loop needed (Gregorius, GDC 2013) */
    double se_best = -1e300;
    int ea = -1, eb = -1;
    vec3 en = v3_zero();
    poly_edge_faces(pa); /* only this path needs the adjacency */
    poly_edge_faces(pb);
    for (int i = 0; i < pa->ne; i++) {
        if (pa->ef[i][0] < 0 || pa->ef[i][1] < 0) continue;
        vec3 a0 = pa->v[pa->e[i][0]], da = v3_sub(pa->v[pa->e[i][1]], a0);
        vec3 na = pa->fn[pa->ef[i][0]], nb = pa->fn[pa->ef[i][1]];
        vec3 bxa = v3_cross(nb, na);
        for (int j = 0; j < pb->ne; j++) {
            if (pb->ef[j][0] < 0 || pb->ef[j][1] < 0) continue;
            vec3 nc = v3_neg(pb->fn[pb->ef[j][0]]), nd = v3_neg(pb->fn[pb->ef[j][1]]);
            vec3 dxc = v3_cross(nd, nc);
            double cba = v3_dot(nc, bxa), dba = v3_dot(nd, bxa), adc = v3_dot(na, dxc), bdc = v3_dot(nb, dxc);
            if (!(cba * dba < 0 && adc * bdc < 0 && cba * bdc > 0)) continue;
            vec3 b0 = pb->v[pb->e[j][0]];
            vec3 db = v3_sub(pb->v[pb->e[j][1]], b0);
            vec3 ax = v3_cross(da, db);
            double l2 = v3_len2(ax);
            if (l2 < 1e-12 * v3_len2(da) * v3_len2(db)) continue;
            ax = v3_scale(ax, 1.0 / sqrt(l2));
            if (v3_dot(ax, v3_sub(a0, pa->center)) < 0) ax = v3_neg(ax);
            double s = v3_dot(ax, v3_sub(b0, a0));
            if (s > se_best) { se_best = s; ea = i; eb = j; en = ax; }
            if (s > spec) { m->normal = ax; return; }
        }
    }
    double face_best = dmax(sa_best, sb_best);
    if (ea >= 0 && se_best > face_best + FACE_TOLERANCE) {
        vec3 ca, cb;
        closest_segments(pa->v[pa->e[ea][0]], pa->v[pa->e[ea][1]], pb->v[pb->e[eb][0]], pb->v[pb->e[eb][1]], &ca, &cb);
        m->normal = en;
        add_point(m, v3_scale(v3_add(ca, cb), 0.5), se_best, 0x40000000u | ((uint32_t)ea << 12) | (uint32_t)eb);
        cache->feature = -1;
        return;
    }
    /* reference face: a's unless b's separates clearly more; keep last step's choice when close */
    int use_b = sb_best > sa_best + KEEP_TOLERANCE;
    if (cache->feature >= 0 && fabs(sb_best - sa_best) <= KEEP_TOLERANCE) use_b = cache->flip;
    cache->feature = use_b ? fb : fa;
    cache->flip = use_b;
    if (use_b) poly_face_contact(pb, fb, pa, NULL, xa, 1, spec, 0x20000000u, m);
    else poly_face_contact(pa, fa, pb, NULL, xb, 0, spec, 0, m);
    int sat_fa = fa, sat_fb = fb, sat_use_b = use_b;
    if (m->count == 0) {
        /* a narrow reference facet (a prism's side) can clip the whole incident
         * feature away: the incident body's deepest vertex along the separating
         * face's normal, at that axis' separation */
        const poly *ref = sat_use_b ? pb : pa, *inc = sat_use_b ? pa : pb;
        int rf = sat_use_b ? sat_fb : sat_fa;
        vec3 n = ref->fn[rf];
        int deepest = 0;
        for (int i = 1; i < inc->nv; i++)
            if (v3_dot(inc->v[i], n) < v3_dot(inc->v[deepest], n)) deepest = i;
        double sep = v3_dot(inc->v[deepest], n) - ref->fd[rf];
        if (sep < spec) {
            m->normal = sat_use_b ? v3_neg(n) : n;
            add_point(m, v3_madd(inc->v[deepest], -0.5 * sep, n), sep, 0x30000000u | (uint32_t)deepest);
        }
    }
}

/* poly_face_contact for a box face against a box, without building either
 * polytope: only the reference face's 4 vertices and the incident face's 4.
 * Every value is computed by the same operations as through poly_from_box and
 * poly_face_contact (same normal, vertices, side planes, clip order and ids),
 * so the manifold is bit for bit the same. iax: the incident box's axes
 * (q_rotate of the unit axes, i.e. its +x +y +z face normals). */
static void box_face_contact(vec3 rh, const xform *rx, int rf, vec3 ih, const xform *ix, const vec3 iax[3], int flip,
                             double spec, uint32_t tag, manifold *m)
{
    /* not +-axis: a -axis face's q_rotate can differ from the negated axis in
     * the sign of a zero component, and the solver's tangent basis reads it */
    vec3 n = q_rotate(rx->q, v3(box_normals[rf][0], box_normals[rf][1], box_normals[rf][2]));
    /* incident face: the most anti-parallel, in face order (+x -x +y -y +z -z);
     * q_rotate is odd in v, so a -axis face's dot is exactly the +axis one negated */
    int inf = 0;
    double best = 1e300;
    for (int k = 0; k < 3; k++) {
        double dd = v3_dot(iax[k], n);
        if (dd < best) { best = dd; inf = 2 * k; }
        if (-dd < best) { best = -dd; inf = 2 * k + 1; }
    }
    clip_vertex buf1[CLIP_MAX], buf2[CLIP_MAX];
    for (int i = 0; i < 4; i++) {
        int vi = box_faces[inf][i];
        buf1[i].p = box_vertex(ih, ix, vi);
        buf1[i].id = (uint32_t)vi;
    }
    /* the reference face's side planes (outward), as poly_face_contact makes them */
    double tol = 1.0 + best < 1e-8 ? CLIP_TOLERANCE : 0.0; /* parallel faces: see poly_face_contact */
    vec3 rv[4], side[4];
    double sd[4];
    for (int i = 0; i < 4; i++) rv[i] = box_vertex(rh, rx, box_faces[rf][i]);
    for (int e = 0; e < 4; e++) {
        side[e] = v3_normalize(v3_cross(v3_sub(rv[(e + 1) & 3], rv[e]), n));
        sd[e] = v3_dot(side[e], rv[e]) + tol;
    }
    double fd = v3_dot(n, rv[0]);
    clip_vertex *in = buf1, *out = buf2;
    int nbuf = 4;
    for (int e = 0; e < 4 && nbuf > 0; e++) {
        /* a plane with every point inside: clip_polygon would return the polygon as it is */
        int cut = 0;
        for (int i = 0; i < nbuf; i++) cut |= !(v3_dot(side[e], in[i].p) - sd[e] <= 0);
        if (!cut) continue;
        if (nbuf + 1 > CLIP_MAX) break;
        nbuf = clip_polygon(in, nbuf, side[e], sd[e], (uint32_t)e, out);
        clip_vertex *t = in; in = out; out = t;
    }
    manifold_point cand[CLIP_MAX];
    int nc = 0;
    for (int i = 0; i < nbuf; i++) {
        double sep = v3_dot(n, in[i].p) - fd;
        if (sep >= spec) continue;
        cand[nc].point = v3_madd(in[i].p, -0.5 * sep, n);
        cand[nc].separation = sep;
        cand[nc].id = tag | ((uint32_t)rf << 20) | ((uint32_t)inf << 16) | (in[i].id & 0xffffu);
        nc++;
    }
    nc = manifold_reduce(cand, nc, n);
    m->normal = flip ? v3_neg(n) : n;
    for (int i = 0; i < nc; i++) m->points[i] = cand[i];
    m->count = nc;
}

/* Box-box: the 15-axis separating-axis test in A's frame (closed forms, no
 * vertex loops); a face contact clips the incident face to the reference face
 * (box_face_contact), an edge-edge winner gives one point between the edges. */
static void box_box(const shape *sa, xform xa, const shape *sb, xform xb, double spec, collide_cache *cache,
                    manifold *m)
{
    mat3 ra = m3_from_quat(xa.q), rb = m3_from_quat(xb.q);
    vec3 ax[3] = {ra.c0, ra.c1, ra.c2}, bx[3] = {rb.c0, rb.c1, rb.c2};
    double R[3][3], AR[3][3], t[3] = {0, 0, 0}, ha[3] = {0, 0, 0}, hb[3] = {0, 0, 0};
    vec3 d = v3_sub(xb.p, xa.p);
    for (int i = 0; i < 3; i++) {
        t[i] = v3_dot(d, ax[i]);
        ha[i] = v3_get(sa->half_extents, i);
        hb[i] = v3_get(sb->half_extents, i);
        for (int j = 0; j < 3; j++) {
            R[i][j] = v3_dot(ax[i], bx[j]);
            AR[i][j] = fabs(R[i][j]);
        }
    }
    double sa_best = -1e300, sb_best = -1e300;
    int fa = 0, fb = 0;
    for (int i = 0; i < 3; i++) {
        double s = fabs(t[i]) - (ha[i] + hb[0] * AR[i][0] + hb[1] * AR[i][1] + hb[2] * AR[i][2]);
        if (s > sa_best) { sa_best = s; fa = 2 * i + (t[i] < 0); }
    }
    if (sa_best > spec) { m->normal = v3_scale(ax[fa / 2], fa & 1 ? -1.0 : 1.0); return; }
    for (int j = 0; j < 3; j++) {
        double tb = t[0] * R[0][j] + t[1] * R[1][j] + t[2] * R[2][j];
        double s = fabs(tb) - (hb[j] + ha[0] * AR[0][j] + ha[1] * AR[1][j] + ha[2] * AR[2][j]);
        /* b's face whose outward normal points towards a */
        if (s > sb_best) { sb_best = s; fb = 2 * j + (tb > 0); }
    }
    if (sb_best > spec) { m->normal = v3_scale(bx[fb / 2], fb & 1 ? 1.0 : -1.0); return; }
    double se_best = -1e300;
    int ei = -1, ej = -1;
    for (int i = 0; i < 3; i++) {
        int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; j++) {
            int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            double len = sqrt(dmax(0.0, 1.0 - R[i][j] * R[i][j]));
            if (len < 1e-6) continue;
            double rad = ha[i1] * AR[i2][j] + ha[i2] * AR[i1][j] + hb[j1] * AR[i][j2] + hb[j2] * AR[i][j1];
            double dist = fabs(t[i2] * R[i1][j] - t[i1] * R[i2][j]);
            double s = (dist - rad) / len;
            if (s > se_best) { se_best = s; ei = i; ej = j; }
        }
    }
    double face_best = dmax(sa_best, sb_best);
    if (ei >= 0 && (se_best > spec || se_best > face_best + FACE_TOLERANCE)) {
        /* edge against edge: the two edges nearest each other along the axis */
        vec3 L = v3_normalize(v3_cross(ax[ei], bx[ej]));
        if (v3_dot(L, d) < 0) L = v3_neg(L);
        m->normal = L;
        cache->feature = -1;
        if (se_best > spec) return;
        vec3 ca = xa.p, cb = xb.p;
        for (int k = 0; k < 3; k++) {
            if (k != ei) ca = v3_madd(ca, v3_dot(L, ax[k]) > 0 ? ha[k] : -ha[k], ax[k]);
            if (k != ej) cb = v3_madd(cb, v3_dot(L, bx[k]) > 0 ? -hb[k] : hb[k], bx[k]);
        }
        vec3 pa, pb;
        closest_segments(v3_madd(ca, -ha[ei], ax[ei]), v3_madd(ca, ha[ei], ax[ei]),
                         v3_madd(cb, -hb[ej], bx[ej]), v3_madd(cb, hb[ej], bx[ej]), &pa, &pb);
        add_point(m, v3_scale(v3_add(pa, pb), 0.5), v3_dot(L, v3_sub(pb, pa)),
                  0x40000000u | ((uint32_t)(3 * ei + ej) << 8));
        return;
    }
    int use_b = sb_best > sa_best + KEEP_TOLERANCE;
    if (cache->feature >= 0 && fabs(sb_best - sa_best) <= KEEP_TOLERANCE) use_b = cache->flip;
    cache->feature = use_b ? fb : fa;
    cache->flip = use_b;
    if (use_b) box_face_contact(sb->half_extents, &xb, fb, sa->half_extents, &xa, ax, 1, spec, 0x20000000u, m);
    else box_face_contact(sa->half_extents, &xa, fa, sb->half_extents, &xb, bx, 0, spec, 0, m);
}

/* ---- polytope against a sphere or capsule (a point or segment core + radius) -- */

/* The core (point c0, or segment c0-c1) clipped to face f's side planes:
 * the part of it over the face, 0..2 points (ids 0 and 1: the ends). */
static int clip_core_to_face(const poly *p, int f, vec3 c0, vec3 c1, int seg, clip_vertex kept[2])
{
    clip_vertex b1[CLIP_MAX], b2[CLIP_MAX];
    int nb = seg ? 2 : 1;
    b1[0].p = c0; b1[0].id = 0;
    b1[1].p = c1; b1[1].id = 1;
    clip_vertex *in = b1, *out = b2;
    vec3 n = p->fn[f];
    int rc = p->fcount[f];
    for (int e = 0; e < rc && nb > 0; e++) {
        vec3 a = p->v[p->fv[p->ffirst[f] + e]], b = p->v[p->fv[p->ffirst[f] + (e + 1) % rc]];
        vec3 side = v3_normalize(v3_cross(v3_sub(b, a), n));
        if (nb == 2) {
            nb = clip_polygon(in, 2, side, v3_dot(side, a), (uint32_t)e, out);
            if (nb > 2) nb = 2;
        } else {
            nb = v3_dot(side, in[0].p) <= v3_dot(side, a) + 1e-12 ? 1 : 0;
            out[0] = in[0];
        }
        clip_vertex *t = in; in = out; out = t;
    }
    for (int i = 0; i < nb; i++) kept[i] = in[i];
    return nb;
}

/* Distance from a core outside the polytope to the inside of face f: the
 * nearest point of the part over the face to its plane (written to *at);
 * 1e300 when no part of the core lies over the face or it is behind it. */
static double core_face_distance(const poly *p, int f, vec3 c0, vec3 c1, int seg, vec3 *at)
{
    clip_vertex kept[2];
    int nb = clip_core_to_face(p, f, c0, c1, seg, kept);
    double best = 1e300;
    for (int i = 0; i < nb; i++) {
        double d = v3_dot(p->fn[f], kept[i].p) - p->fd[f];
        if (d >= 0 && d < best) { best = d; *at = kept[i].p; }
    }
    return best;
}

/* 1 when the core (point c0, or segment c0-c1) meets the polytope: the part
 * of it inside every face's half-space is not empty. (Every face plane
 * having an end of the segment behind it is not enough: a segment can pass
 * a corner that way.) */
static int core_meets_poly(const poly *p, vec3 c0, vec3 c1)
{
    double t0 = 0.0, t1 = 1.0;
    for (int f = 0; f < p->nf; f++) {
        double d0 = v3_dot(p->fn[f], c0) - p->fd[f], d1 = v3_dot(p->fn[f], c1) - p->fd[f];
        if (d0 > 0 && d1 > 0) return 0;
        if (d0 > 0) t0 = dmax(t0, d0 / (d0 - d1));
        else if (d1 > 0) t1 = dmin(t1, d0 / (d0 - d1));
        if (t0 > t1) return 0;
    }
    return 1;
}

static void poly_core(const shape *sp, xform xp, const shape *sc, xform xc, double spec, manifold *m)
{
    poly pbuf;
    poly *p = &pbuf;
    if (!poly_from_shape(p, sp, xp)) return;
    vec3 c0 = xc.p, c1 = xc.p;
    int seg = sc->type == SHAPE_CAPSULE;
    if (seg) capsule_segment(sc, xc, &c0, &c1);
    double r = sc->radius;
    /* face axes */
    double best = -1e300;
    int bf = -1;
    for (int f = 0; f < p->nf; f++) {
        double s = dmin(v3_dot(p->fn[f], c0), v3_dot(p->fn[f], c1)) - p->fd[f];
        if (s > best) { best = s; bf = f; }
    }
    if (bf < 0) return; /* no finite face distance */
    vec3 n = p->fn[bf];
    /* the core (point or segment) clipped to the reference face's side planes */
    clip_vertex in[2];
    int nb = clip_core_to_face(p, bf, c0, c1, seg, in);
    if (!core_meets_poly(p, c0, c1)) {
        /* outside: the nearest feature may be this face, another face, an edge
         * or a vertex (the part of the core over the best face can be the far
         * part, the near end hanging past an edge) */
        double ebest = 1e300;
        vec3 ep = v3_zero(), ec = v3_zero();
        int eidx = 0;
        for (int i = 0; i < p->ne; i++) {
            vec3 pa, pc;
            closest_segments(p->v[p->e[i][0]], p->v[p->e[i][1]], c0, c1, &pa, &pc);
            double d2 = v3_len2(v3_sub(pc, pa));
            if (d2 < ebest) { ebest = d2; ep = pa; ec = pc; eidx = i; }
        }
        ebest = sqrt(ebest);
        int face = -1;
        double fbest = 1e300;
        vec3 fc = c0;
        for (int f = 0; f < p->nf; f++) {
            vec3 pc = c0;
            double d = core_face_distance(p, f, c0, c1, seg, &pc);
            if (d < fbest) { fbest = d; face = f; fc = pc; }
        }
        if (ebest - r >= spec && fbest - r >= spec) {
            m->normal = n;
            return;
        }
        if (!(face == bf && nb > 0 && fbest <= ebest)) {
            /* one point at the nearest feature */
            int on_face = face >= 0 && fbest <= ebest;
            double d = on_face ? fbest : ebest;
            if (on_face) { ec = fc; ep = v3_madd(fc, -fbest, p->fn[face]); }
            vec3 en = on_face ? p->fn[face] : any_unit(v3_sub(ec, ep), n);
            double sep = d - r;
            m->normal = en;
            uint32_t id = on_face ? ((uint32_t)face << 16) | 0x8000u : 0x10000000u | (uint32_t)eidx;
            if (sep < spec) add_point(m, v3_madd(ep, 0.5 * sep, en), sep, id);
            return;
        }
    }
    m->normal = n;
    if (best - r >= spec) return;
    if (nb == 0) {
        /* overlapping but the core projects outside the face: its deepest end */
        nb = 1;
        in[0].p = v3_dot(n, c0) <= v3_dot(n, c1) ? c0 : c1;
        in[0].id = 0;
    }
    for (int i = 0; i < nb; i++) {
        double sep = v3_dot(n, in[i].p) - p->fd[bf] - r;
        if (sep < spec) add_point(m, v3_madd(in[i].p, -(r + 0.5 * sep), n), sep, ((uint32_t)bf << 16) | (in[i].id & 0xffffu));
    }
}

/* ---- cylinder pairs on the true shapes -----------------------------------------
 *
 * Contacts of a round cylinder with a sphere, box,
 * capsule, cylinder or hull, on the true shapes (not the 16-sided prism).
 *
 * The normal and separation come from the true surfaces: GJK (lib/gjk.c)
 * when they are apart, libccd's MPR when they overlap; each candidate face
 * (a box or hull face, a cylinder cap) is also tried as an axis, its gap
 * taken from the exact supports. A face within FACE_TOLERANCE of that best
 * gap becomes the reference: its normal is the contact normal, and the
 * other shape's feature turned to it (a face, the cylinder's true side line
 * or its cap with the true deepest rim point, a capsule's segment, a
 * sphere's point) is clipped to the face's side planes. Otherwise (round
 * against round: a side against a sphere, a capsule or another side) the
 * contact is the pair of closest points, or the overlap of two parallel
 * lines. Every separation is a gap measured on the true shapes along the
 * normal, so no pair is reported apart when the true shapes touch (the
 * prism lay up to r (1 - cos(pi/16)) inside the round side). */

#define LINE_SIN 2e-2        /* a cylinder side or capsule within this sine of perpendicular is a line */
#define SIDE_COS 0.70710678118654752 /* a cylinder nearer than 45 degrees to lying on its side shows its side */

typedef struct feature {
    int n;
    clip_vertex v[CLIP_MAX / 2];
    vec3 normal;   /* a polygon's outward normal; zero for a point or segment */
} feature;

/* Exact support height of s at x along unit u (world): max over s of u.p. */
static double support_h(const shape *s, xform x, vec3 u)
{
    return v3_dot(u, xf_point(x, shape_support_local(s, q_inv_rotate(x.q, u))));
}

static vec3 support_p(const shape *s, xform x, vec3 u)
{
    return xf_point(x, shape_support_local(s, q_inv_rotate(x.q, u)));
}

/* Gap between a and b along unit u (a towards b): min_b u.p - max_a u.p. */
static double gap_along(const shape *a, xform xa, const shape *b, xform xb, vec3 u)
{
    return -support_h(b, xb, v3_neg(u)) - support_h(a, xa, u);
}

static vec3 cyl_axis(xform x) { return q_rotate(x.q, v3(0, 0, 1)); }

/* The part of s farthest along unit u: a point, a segment, or a polygon
 * (counter-clockwise about u) whose every vertex lies on the true surface. */
static void support_feature(const shape *s, xform x, const poly *p, vec3 u, feature *f)
{
    f->n = 0;
    f->normal = v3_zero();
    switch (s->type) {
    case SHAPE_SPHERE:
        f->v[0].p = v3_madd(x.p, s->radius, u);
        f->v[0].id = 0;
        f->n = 1;
        return;
    case SHAPE_CAPSULE: {
        vec3 c0, c1;
        capsule_segment(s, x, &c0, &c1);
        f->v[0].p = v3_madd(c0, s->radius, u);
        f->v[1].p = v3_madd(c1, s->radius, u);
        f->v[0].id = 0;
        f->v[1].id = 1;
        f->n = 2;
        return;
    }
    case SHAPE_CYLINDER: {
        vec3 axis = cyl_axis(x);
        double c = v3_dot(axis, u);
        vec3 radial = v3_madd(u, -c, axis);
        double rl = v3_len(radial);
        if (fabs(c) < SIDE_COS && rl > 1e-12) {
            radial = v3_scale(radial, 1.0 / rl);
            for (int i = 0; i < 2; i++) {
                f->v[i].p = v3_add(v3_madd(x.p, i ? s->half_height : -s->half_height, axis), v3_scale(radial, s->radius));
                f->v[i].id = 0x40u + (uint32_t)i;
            }
            f->n = 2;
            return;
        }
        /* the cap turned to u: the prism's rim vertices (on the true rim)
         * with the true deepest rim point inserted in angular order */
        const int n = CYL_SIDES;
        int top = c > 0, k = -1;
        vec3 extra = v3_zero();
        f->normal = top ? axis : v3_neg(axis);
        /* tilted less than 1e-4 rad the true rim lies below the prism's by
         * under 2e-6 r: left out, its angle would only jitter */
        if (rl > 1e-4) {
            vec3 lr = q_inv_rotate(x.q, radial);
            double ang = atan2(lr.y, lr.x);
            if (ang < 0) ang += 6.283185307179586;
            double t = ang * n / 6.283185307179586;
            k = (int)floor(t);
            if (k >= n) k = n - 1;
            if (k < 0) k = 0;
            if (t - k < 1e-6 || t - k > 1 - 1e-6) k = -1; /* on a vertex already */
            else extra = support_p(s, x, u);
        }
        int m = 0;
        if (top) {
            for (int i = 0; i < n; i++) {
                f->v[m].p = p->v[n + i]; f->v[m].id = (uint32_t)(n + i); m++;
                if (i == k) { f->v[m].p = extra; f->v[m].id = 0x50u; m++; }
            }
        } else {
            for (int i = n - 1; i >= 0; i--) {
                if (i == k) { f->v[m].p = extra; f->v[m].id = 0x50u; m++; }
                f->v[m].p = p->v[i]; f->v[m].id = (uint32_t)i; m++;
            }
        }
        f->n = m;
        return;
    }
    default: { /* box, hull: the face most turned to u */
        int best = 0;
        for (int i = 1; i < p->nf; i++)
            if (v3_dot(p->fn[i], u) > v3_dot(p->fn[best], u)) best = i;
        int cnt = p->fcount[best];
        if (cnt > CLIP_MAX / 2) cnt = CLIP_MAX / 2;
        for (int i = 0; i < cnt; i++) {
            int vi = p->fv[p->ffirst[best] + i];
            f->v[i].p = p->v[vi];
            f->v[i].id = (uint32_t)(vi & 0x7f);
        }
        f->n = cnt;
        f->normal = p->fn[best];
        return;
    }
    }
}

/* The point or line of s farthest along unit u (round or edge pairs): a
 * segment when s has one within LINE_SIN of perpendicular to u, else a point. */
static int support_line(const shape *s, xform x, const poly *p, vec3 u, vec3 out[2])
{
    if (s->type == SHAPE_CAPSULE || s->type == SHAPE_CYLINDER) {
        vec3 axis = cyl_axis(x);
        if (fabs(v3_dot(axis, u)) < LINE_SIN) {
            feature f;
            if (s->type == SHAPE_CYLINDER) {
                vec3 radial = v3_normalize(v3_madd(u, -v3_dot(axis, u), axis));
                for (int i = 0; i < 2; i++)
                    out[i] = v3_add(v3_madd(x.p, i ? s->half_height : -s->half_height, axis), v3_scale(radial, s->radius));
                return 2;
            }
            support_feature(s, x, p, u, &f);
            out[0] = f.v[0].p;
            out[1] = f.v[1].p;
            return 2;
        }
    } else if (s->type == SHAPE_BOX || s->type == SHAPE_HULL) {
        int best = 0;
        for (int i = 1; i < p->nv; i++)
            if (v3_dot(p->v[i], u) > v3_dot(p->v[best], u)) best = i;
        int be = -1;
        double bs = LINE_SIN;
        for (int e = 0; e < p->ne; e++) {
            if (p->e[e][0] != best && p->e[e][1] != best) continue;
            vec3 d = v3_sub(p->v[p->e[e][1]], p->v[p->e[e][0]]);
            double l = v3_len(d);
            if (l < 1e-12) continue;
            double sn = fabs(v3_dot(d, u)) / l;
            if (sn < bs) { bs = sn; be = e; }
        }
        if (be >= 0) {
            out[0] = p->v[p->e[be][0]];
            out[1] = p->v[p->e[be][1]];
            return 2;
        }
        out[0] = p->v[best];
        return 1;
    }
    out[0] = support_p(s, x, u);
    return 1;
}

/* Clips a point, segment or polygon to the side planes of face rf of ref
 * (outward, extruded along the face normal); returns the count left. */
static int clip_to_face(const poly *ref, int rf, feature *f, double tol)
{
    vec3 n = ref->fn[rf];
    int rc = ref->fcount[rf];
    clip_vertex buf[CLIP_MAX];
    for (int e = 0; e < rc && f->n > 0; e++) {
        vec3 a = ref->v[ref->fv[ref->ffirst[rf] + e]], b = ref->v[ref->fv[ref->ffirst[rf] + (e + 1) % rc]];
        vec3 side = v3_normalize(v3_cross(v3_sub(b, a), n));
        double sd = v3_dot(side, a) + tol;
        if (f->n == 1) {
            if (v3_dot(side, f->v[0].p) > sd + 1e-12) f->n = 0;
        } else if (f->n == 2) {
            double d0 = v3_dot(side, f->v[0].p) - sd, d1 = v3_dot(side, f->v[1].p) - sd;
            if (d0 > 0 && d1 > 0) f->n = 0;
            else if (d0 > 0 || d1 > 0) {
                int out = d0 > 0 ? 0 : 1;
                double t = d0 / (d0 - d1);
                f->v[out].p = v3_lerp(f->v[0].p, f->v[1].p, t);
                f->v[out].id = (f->v[out].id & 0xffu) | 0x80u | ((uint32_t)(e & 0xff) << 8);
            }
        } else {
            if (f->n + 1 > CLIP_MAX / 2) break;
            int k = clip_polygon(f->v, f->n, side, sd, (uint32_t)(e & 0xff), buf);
            if (k > CLIP_MAX / 2) k = CLIP_MAX / 2;
            for (int i = 0; i < k; i++) f->v[i] = buf[i];
            f->n = k;
        }
    }
    return f->n;
}

/* A face of s (box or hull face, cylinder cap) as a candidate axis. */
typedef struct face_axis {
    int face;      /* index in the poly, -1 none */
    double gap;    /* exact gap along its outward normal */
} face_axis;

/* The face of s (poly p) with the largest exact gap to the other shape. */
static face_axis best_face(const shape *s, const poly *p, const shape *o, xform xo)
{
    face_axis fa = {-1, -1e300};
    if (!p) return fa;
    int first = 0;
    if (s->type == SHAPE_CYLINDER) first = CYL_SIDES; /* the caps; the side facets are not the true surface */
    for (int f = first; f < p->nf; f++) {
        double g = -support_h(o, xo, v3_neg(p->fn[f])) - p->fd[f];
        if (g > fa.gap) { fa.gap = g; fa.face = f; }
    }
    return fa;
}

/* The unit circle at the prism's 16 vertex angles (constant data). */
static const double cyl_rim[CYL_SIDES][2] = {
    {1, 0},
    {0.92387953251128674, 0.38268343236508978},
    {0.70710678118654757, 0.70710678118654746},
    {0.38268343236508984, 0.92387953251128674},
    {6.123233995736766e-17, 1},
    {-0.38268343236508973, 0.92387953251128674},
    {-0.70710678118654746, 0.70710678118654757},
    {-0.92387953251128674, 0.38268343236508989},
    {-1, 1.2246467991473532e-16},
    {-0.92387953251128685, -0.38268343236508967},
    {-0.70710678118654768, -0.70710678118654746},
    {-0.38268343236509034, -0.92387953251128652},
    {-1.8369701987210297e-16, -1},
    {0.38268343236509, -0.92387953251128663},
    {0.70710678118654735, -0.70710678118654768},
    {0.92387953251128652, -0.38268343236509039}};

/* A cylinder's rims and caps only, as poly_from_cylinder numbers them
 * (vertices i bottom, CYL_SIDES + i top; faces CYL_SIDES top and
 * CYL_SIDES + 1 bottom); the side facets, which nothing here reads, are
 * left empty. No trigonometry: a table and the three rotated axes. */
static void cylinder_caps(poly *p, const shape *s, xform x)
{
    const int n = CYL_SIDES;
    vec3 ex = q_rotate(x.q, v3(1, 0, 0)), ey = q_rotate(x.q, v3(0, 1, 0)), ez = q_rotate(x.q, v3(0, 0, 1));
    vec3 top = v3_madd(x.p, s->half_height, ez), bot = v3_madd(x.p, -s->half_height, ez);
    p->nv = 2 * n; p->nf = n + 2; p->ne = 0;
    for (int i = 0; i < n; i++) {
        vec3 off = v3_add(v3_scale(ex, s->radius * cyl_rim[i][0]), v3_scale(ey, s->radius * cyl_rim[i][1]));
        p->v[i] = v3_add(bot, off);
        p->v[n + i] = v3_add(top, off);
        p->fn[i] = v3_zero(); p->fd[i] = 0; p->ffirst[i] = 0; p->fcount[i] = 0;
    }
    p->fn[n] = ez; p->ffirst[n] = 0; p->fcount[n] = n;
    p->fn[n + 1] = v3_neg(ez); p->ffirst[n + 1] = n; p->fcount[n + 1] = n;
    for (int i = 0; i < n; i++) { p->fv[i] = n + i; p->fv[n + i] = n - 1 - i; }
    p->fd[n] = v3_dot(ez, top);
    p->fd[n + 1] = -v3_dot(ez, bot);
    p->center = x.p;
}

/* Signed distance from world point c to the cylinder s at x (negative
 * inside), and the unit normal out of the cylinder at its nearest surface
 * point (the direction from that point to c when outside). */
static double point_cylinder(const shape *s, xform x, vec3 c, vec3 *n)
{
    vec3 l = xf_inv_point(x, c);
    double rho = sqrt(l.x * l.x + l.y * l.y);
    double ux = rho > 1e-300 ? l.x / rho : 1.0, uy = rho > 1e-300 ? l.y / rho : 0.0;
    double dr = rho - s->radius, dz = fabs(l.z) - s->half_height, sz = l.z < 0 ? -1.0 : 1.0;
    vec3 nl;
    double d;
    if (dr > 0 || dz > 0) {
        double qr = dmin(rho, s->radius), qz = dmax(-s->half_height, dmin(s->half_height, l.z));
        vec3 v = v3(l.x - qr * ux, l.y - qr * uy, l.z - qz);
        d = v3_len(v);
        nl = d > 1e-300 ? v3_scale(v, 1.0 / d) : (dr > dz ? v3(ux, uy, 0) : v3(0, 0, sz));
    } else if (dr > dz) {
        d = dr;
        nl = v3(ux, uy, 0);
    } else {
        d = dz;
        nl = v3(0, 0, sz);
    }
    *n = q_rotate(x.q, nl);
    return d;
}

/* Distance from p inside s (poly p for a box or hull) to its surface, or -1
 * when p is not inside. */
static double interior_distance(const shape *s, xform x, const poly *pp, vec3 p)
{
    if (s->type == SHAPE_CYLINDER) {
        vec3 l = xf_inv_point(x, p);
        double d = dmin(s->radius - sqrt(l.x * l.x + l.y * l.y), s->half_height - fabs(l.z));
        return d >= 0 ? d : -1;
    }
    if (!pp) return -1;
    double d = 1e300;
    for (int f = 0; f < pp->nf; f++) d = dmin(d, pp->fd[f] - v3_dot(pp->fn[f], p));
    return d >= 0 ? d : -1;
}

/* 1 when face fx of s is, within FACE_TOLERANCE, the best axis of all: the
 * other shape's deepest point q along it certifies it. Apart: q over the
 * face, so that point of the face is as far from q as the gap (the gap is
 * always a lower bound of the distance). Overlapping: q inside s, at least
 * -gap - FACE_TOLERANCE from its surface, so no translation shorter than
 * that separates them (the face's gap is a lower bound of minus the depth). */
static int face_is_exact(const shape *s, xform xs, const poly *p, face_axis fx, const shape *o, xform xo)
{
    vec3 n = p->fn[fx.face];
    vec3 q = support_p(o, xo, v3_neg(n));
    if (fx.gap > 0) {
        int rc = p->fcount[fx.face];
        for (int e = 0; e < rc; e++) {
            vec3 a = p->v[p->fv[p->ffirst[fx.face] + e]], b = p->v[p->fv[p->ffirst[fx.face] + (e + 1) % rc]];
            vec3 side = v3_cross(v3_sub(b, a), n); /* outward, not unit */
            if (v3_dot(side, v3_sub(q, a)) > 0) return 0;
        }
        return 1;
    }
    return interior_distance(s, xs, p, q) >= -fx.gap - FACE_TOLERANCE;
}

static int mpr(const shape *a, xform xa, const shape *b, xform xb, vec3 *n, vec3 *pos)
{
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = ccd_support;
    ccd.support2 = ccd_support;
    ccd.center1 = ccd_center;
    ccd.center2 = ccd_center;
    ccd.max_iterations = 100;
    ccd.mpr_tolerance = 1e-10;
    ccd_obj oa = {a, xa}, ob = {b, xb};
    ccd_real_t depth;
    ccd_vec3_t dir, p;
    if (ccdMPRPenetration(&oa, &ob, &ccd, &depth, &dir, &p) != 0) return 0;
    vec3 d = v3(dir.v[0], dir.v[1], dir.v[2]);
    *pos = v3(p.v[0], p.v[1], p.v[2]);
    if (!v3_is_finite(d) || !v3_is_finite(*pos) || v3_len2(d) < 0.25) return 0;
    *n = v3_normalize(d);
    return 1;
}

#define NEAR_GAP 1e-2 /* GJK's normal is refined below this distance, and a is backed off to it */

/* Overlapping by -*gap along *n: a backed off along -n until apart, GJK's
 * normal there is a direction whose gap at the true pose is compared; the
 * fixed point is where the gap is largest (the gradient of the exact gap,
 * concave in the direction, is along n: the least penetration). MPR's
 * direction alone claimed up to 17 times the true depth (1.7 mm for 0.1). */
static void refine_overlap_normal(const shape *sa, xform xa, const shape *sb, xform xb, vec3 *n, double *gap)
{
    for (int it = 0; it < 8; it++) {
        double back = NEAR_GAP - *gap;
        xform xm = {v3_madd(xa.p, -back, *n), xa.q};
        gjk_proxy pa = {sa, NULL, 0, xm}, pb = {sb, NULL, 0, xb};
        gjk_result g = gjk_distance(&pa, &pb);
        if (g.overlap || !(v3_len2(g.normal) > 0.5)) return;
        double gn = gap_along(sa, xa, sb, xb, g.normal);
        if (!(gn > *gap)) return;
        int done = gn < *gap + 1e-9; /* a nanometre: converged */
        *n = g.normal;
        *gap = gn;
        if (done) return;
    }
}

static void push(manifold_point *cand, int *nc, vec3 p, double sep, uint32_t id)
{
    if (*nc >= CLIP_MAX) return;
    cand[*nc].point = p;
    cand[*nc].separation = sep;
    cand[*nc].id = id;
    (*nc)++;
}

static void cylinder_contact(const shape *sa, xform xa0, const shape *sb, xform xb0, double spec, collide_cache *cache,
                      manifold *m)
{
    /* in a frame at a's origin: no precision lost far from the world origin */
    vec3 ref = xa0.p;
    xform xa = {v3_zero(), xa0.q}, xb = {v3_sub(xb0.p, ref), xb0.q};
    poly pa_buf, pb_buf;
    const poly *pa = NULL, *pb = NULL;
    if (sa->type == SHAPE_CYLINDER) { cylinder_caps(&pa_buf, sa, xa); pa = &pa_buf; }
    else if (poly_from_shape(&pa_buf, sa, xa)) pa = &pa_buf;
    if (sb->type == SHAPE_CYLINDER) { cylinder_caps(&pb_buf, sb, xb); pb = &pb_buf; }
    else if (poly_from_shape(&pb_buf, sb, xb)) pb = &pb_buf;
    /* face axes of a (outward: a towards b) and of b (outward: b towards a),
     * their gaps exact (the other shape's true support) */
    face_axis fa = best_face(sa, pa, sb, xb), fb = best_face(sb, pb, sa, xa);
    double face_gap = dmax(fa.gap, fb.gap);
    if (face_gap >= spec) { /* an axis separates them beyond the look-ahead */
        m->normal = fa.gap >= fb.gap ? pa->fn[fa.face] : v3_neg(pb->fn[fb.face]);
        return;
    }
    /* a face whose gap is the true one needs no GJK: the face path below */
    int certified = (fa.face >= 0 && face_is_exact(sa, xa, pa, fa, sb, xb)) ||
                    (fb.face >= 0 && face_is_exact(sb, xb, pb, fb, sa, xa));
    /* else the true normal and gap: GJK apart, MPR overlapping */
    gjk_result g;
    memset(&g, 0, sizeof g);
    vec3 n0 = v3(0, 0, 1), p0 = v3_zero();
    double d0 = face_gap;
    int have_n0 = 1, exact = 0;
    const shape *sph = sa->type == SHAPE_SPHERE ? sa : sb->type == SHAPE_SPHERE ? sb : NULL;
    if (certified) {
        have_n0 = 0;
    } else if (sph) {
        /* a sphere: its centre's signed distance to the cylinder, in closed form */
        int sa_is = sph == sa;
        const shape *cyl = sa_is ? sb : sa;
        xform xc = sa_is ? xb : xa;
        vec3 c = sa_is ? xa.p : xb.p, nc;
        double dist = point_cylinder(cyl, xc, c, &nc); /* nc: out of the cylinder, towards c */
        d0 = dist - sph->radius;
        n0 = sa_is ? v3_neg(nc) : nc;
        p0 = v3_madd(c, -(dist - 0.5 * d0), nc);
        exact = 1;
        if (d0 >= spec) { m->normal = n0; return; }
    } else if (!(g = gjk_distance(&(gjk_proxy){sa, NULL, 0, xa}, &(gjk_proxy){sb, NULL, 0, xb})).overlap) {
        if (g.lower_bound >= spec || g.distance >= spec) {
            m->normal = v3_len2(g.normal) > 0.5 ? g.normal : g.lower_normal;
            return;
        }
        n0 = g.normal;
        p0 = v3_scale(v3_add(g.point_a, g.point_b), 0.5);
        d0 = g.distance;
        if (!(v3_len2(n0) > 0.5)) have_n0 = 0;
    } else {
        /* overlapping (or touching within GJK's tolerance): of MPR's
         * direction (it fails on some touching pairs: parallel logs side by
         * side), last step's normal and the line of centres, the one with
         * the largest exact gap */
        vec3 cand_n[3];
        int nn = 0;
        if (mpr(sa, xa, sb, xb, &cand_n[nn], &p0)) nn++;
        if (cache->has_normal) cand_n[nn++] = cache->normal;
        vec3 c = v3_sub(xb.p, xa.p);
        if (v3_len2(c) > 1e-24) cand_n[nn++] = v3_normalize(c);
        have_n0 = nn > 0;
        d0 = -1e300;
        for (int i = 0; i < nn; i++) {
            double gi = gap_along(sa, xa, sb, xb, cand_n[i]);
            if (gi > d0) { d0 = gi; n0 = cand_n[i]; }
        }
    }
    if (!have_n0) d0 = certified ? face_gap : -1e300;
    if (g.overlap && have_n0 && !exact) {
        /* refined to the least penetration near the best direction (GJK
         * backed off, above: a face clearly better than MPR's direction is
         * not enough, MPR's depth is up to 100 times the true one); b's
         * deepest point along it from the exact supports */
        refine_overlap_normal(sa, xa, sb, xb, &n0, &d0);
        p0 = v3_madd(support_p(sb, xb, v3_neg(n0)), -0.5 * d0, n0);
    }
    if (face_gap >= d0 - FACE_TOLERANCE && (fa.face >= 0 || fb.face >= 0)) {
        int use_b = fa.face < 0 || (fb.face >= 0 && fb.gap > fa.gap + KEEP_TOLERANCE);
        if (fa.face >= 0 && fb.face >= 0 && cache->feature >= 0 && fabs(fb.gap - fa.gap) <= KEEP_TOLERANCE)
            use_b = cache->flip;
        const poly *rp = use_b ? pb : pa;
        int rf = use_b ? fb.face : fa.face;
        const shape *inc = use_b ? sa : sb;
        xform ix = use_b ? xa : xb;
        const poly *ip = use_b ? pa : pb;
        vec3 nr = rp->fn[rf];
        feature f;
        support_feature(inc, ix, ip, v3_neg(nr), &f);
        /* parallel faces (a stack): keep vertices just outside a side plane,
         * as poly_face_contact does, so the ids stay under tiny jitter */
        double tol = 1.0 + v3_dot(f.normal, nr) < 1e-8 ? CLIP_TOLERANCE : 0.0;
        /* a cap's side planes are the prism's, inside the true rim by up to
         * its sagitta: pushed out to touch the rim, they keep the incident
         * points over the true cap (a stacked cylinder's rim among them) */
        const shape *rs = use_b ? sb : sa;
        if (rs->type == SHAPE_CYLINDER) tol += rs->radius * (1 - cos(3.141592653589793 / CYL_SIDES));
        clip_to_face(rp, rf, &f, tol);
        manifold_point cand[CLIP_MAX];
        int nc = 0;
        uint32_t tag = (use_b ? 0x20000000u : 0u) | ((uint32_t)(rf & 0xff) << 20);
        for (int i = 0; i < f.n; i++) {
            double sep = v3_dot(nr, f.v[i].p) - rp->fd[rf];
            if (sep < spec) push(cand, &nc, v3_madd(f.v[i].p, -0.5 * sep, nr), sep, tag | (f.v[i].id & 0xffffu));
        }
        double kept = INFINITY;
        for (int i = 0; i < nc; i++) kept = dmin(kept, cand[i].separation);
        double face = use_b ? fb.gap : fa.gap;
        if (!(kept <= face + 1e-6)) {
            /* the deepest part hangs past the face's sides (clipped away): the
             * other shape's deepest point along the face normal, at the face's
             * gap, which is not more than the distance (the clipped points
             * alone claimed more room than there is) */
            vec3 q = support_p(inc, ix, v3_neg(nr));
            double sep = v3_dot(nr, q) - rp->fd[rf];
            if (sep < spec) push(cand, &nc, v3_madd(q, -0.5 * sep, nr), sep, tag | 0x30000u);
        }
        nc = manifold_reduce(cand, nc, nr);
        cache->feature = rf;
        cache->flip = use_b;
        m->normal = use_b ? v3_neg(nr) : nr;
        for (int i = 0; i < nc; i++) {
            m->points[i] = cand[i];
            m->points[i].point = v3_add(cand[i].point, ref);
        }
        m->count = nc;
        return;
    }
    /* round against round or an edge: the closest points, or two parallel lines' overlap */
    cache->feature = -1;
    if (!g.overlap && !exact && d0 < NEAR_GAP) {
        /* GJK's normal between surfaces almost touching is the direction of a
         * tiny vector (0.1 degree off between resting parallel logs): backed
         * off, it is well conditioned */
        d0 = gap_along(sa, xa, sb, xb, n0);
        refine_overlap_normal(sa, xa, sb, xb, &n0, &d0);
        p0 = v3_madd(support_p(sb, xb, v3_neg(n0)), -0.5 * d0, n0);
    }
    m->normal = n0;
    if (d0 >= spec) return;
    vec3 la[2], lb[2];
    int na = support_line(sa, xa, pa, n0, la), nb = support_line(sb, xb, pb, v3_neg(n0), lb);
    manifold_point cand[2];
    int nc = 0;
    if (na == 2 && nb == 2) {
        vec3 da = v3_sub(la[1], la[0]), db = v3_sub(lb[1], lb[0]);
        double la2 = v3_len2(da);
        if (la2 > 1e-24 && v3_len2(v3_cross(da, db)) < LINE_SIN * LINE_SIN * la2 * v3_len2(db)) {
            /* b's line over a's: the ends of the overlap, on b's line */
            double t0 = v3_dot(v3_sub(lb[0], la[0]), da) / la2, t1 = v3_dot(v3_sub(lb[1], la[0]), da) / la2;
            double lo = dmax(0, dmin(t0, t1)), hi = dmin(1, dmax(t0, t1));
            if (hi > lo + 1e-9 && fabs(t1 - t0) > 1e-12) {
                double ha = support_h(sa, xa, n0);
                for (int i = 0; i < 2; i++) {
                    double s = ((i ? hi : lo) - t0) / (t1 - t0);
                    vec3 q = v3_lerp(lb[0], lb[1], s);
                    double sep = v3_dot(n0, q) - ha;
                    if (sep < spec) push(cand, &nc, v3_madd(q, -0.5 * sep, n0), sep, 0x70000000u | (uint32_t)i);
                }
            }
        }
    }
    if (nc == 0) push(cand, &nc, p0, d0, 0x70000002u);
    for (int i = 0; i < nc; i++) {
        m->points[i] = cand[i];
        m->points[i].point = v3_add(cand[i].point, ref);
    }
    m->count = nc;
}

/* ---- dispatch ------------------------------------------------------------- */

static void collide_ordered(const shape *a, xform xa, const shape *b, xform xb, double spec, collide_cache *cache,
                            manifold *m)
{
    /* a->type <= b->type */
    int ta = a->type, tb = b->type;
    if (tb == SHAPE_PLANE) {
        if (ta != SHAPE_PLANE) shape_plane(a, xa, b, xb, spec, m);
        return;
    }
    if (ta == SHAPE_CYLINDER || tb == SHAPE_CYLINDER) {
        cylinder_contact(a, xa, b, xb, spec, cache, m);
        return;
    }
    if (ta == SHAPE_SPHERE) {
        if (tb == SHAPE_SPHERE) sphere_sphere(xa.p, a->radius, xb.p, b->radius, spec, 0, m);
        else if (tb == SHAPE_BOX) sphere_box(a, xa, b, xb, spec, m);
        else if (tb == SHAPE_CAPSULE) sphere_capsule(a, xa, b, xb, spec, m);
        else {
            poly_core(b, xb, a, xa, spec, m);
            m->normal = v3_neg(m->normal);
        }
        return;
    }
    if (ta == SHAPE_CAPSULE) {
        if (tb == SHAPE_CAPSULE) capsule_capsule(a, xa, b, xb, spec, m);
        else {
            poly_core(b, xb, a, xa, spec, m);
            m->normal = v3_neg(m->normal);
        }
        return;
    }
    if (ta == SHAPE_BOX && tb == SHAPE_CAPSULE) {
        poly_core(a, xa, b, xb, spec, m);
        return;
    }
    if (ta == SHAPE_BOX && tb == SHAPE_BOX) box_box(a, xa, b, xb, spec, cache, m);
    else poly_poly(a, xa, b, xb, spec, cache, m);
}

int collide_convex(const shape *a, xform xa, const shape *b, xform xb, double speculative, collide_cache *cache,
                   manifold *m)
{
    memset(m, 0, sizeof *m);
    m->normal = v3(0, 0, 1);
    /* a pose that overflowed has no contacts (the feature searches below would
     * find no best face and index with -1) */
    if (!xf_is_finite(xa) || !xf_is_finite(xb)) return 0;
    int swap = a->type > b->type;
    /* capsule (2) against box (1) is handled box-first; everything else by type order */
    if (swap) {
        collide_cache flipped = *cache;
        flipped.flip = !cache->flip;
        flipped.normal = v3_neg(cache->normal);
        collide_ordered(b, xb, a, xa, speculative, &flipped, m);
        m->normal = v3_neg(m->normal);
        cache->feature = flipped.feature;
        cache->flip = !flipped.flip;
    } else {
        collide_ordered(a, xa, b, xb, speculative, cache, m);
    }
    /* always finite: a degenerate result becomes no contact */
    if (!v3_is_finite(m->normal) || v3_len2(m->normal) < 0.5) {
        m->normal = cache->has_normal ? cache->normal : v3(0, 0, 1);
        m->count = 0;
    }
    for (int i = 0; i < m->count; i++)
        if (!v3_is_finite(m->points[i].point) || !isfinite(m->points[i].separation)) { m->count = 0; break; }
    if (m->count > 0) {
        cache->normal = m->normal;
        cache->has_normal = 1;
    }
    return m->count;
}
