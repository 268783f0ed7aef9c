/* shape.c - mass properties, bounds, support mapping and ray casts of the
 * shapes (the convex hull builder is hull.c). */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "shape.h"
#include "mesh.h"
#include "heightfield.h"

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
    case SHAPE_COMPOUND: {
        double v = 0;
        for (int i = 0; i < s->compound->count; i++) v += shape_volume(&s->compound->children[i]);
        return v;
    }
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
            ex[i] = s->half_height * fabs(ai) + s->radius * sqrt(dmax(0.0, 1.0 - ai * ai));
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
    case SHAPE_COMPOUND: return compound_aabb(s->compound, t);
    case SHAPE_MESH: case SHAPE_HEIGHTFIELD: {
        /* the local bounds' corners, rotated */
        aabb lb = s->type == SHAPE_MESH ? mesh_bounds(s->mesh) : heightfield_bounds(s->field);
        vec3 c = v3_scale(v3_add(lb.lo, lb.hi), 0.5), h = v3_scale(v3_sub(lb.hi, lb.lo), 0.5);
        mat3 m = m3_from_quat(t.q);
        vec3 e = v3_add(v3_add(v3_scale(v3_abs(m.c0), h.x), v3_scale(v3_abs(m.c1), h.y)), v3_scale(v3_abs(m.c2), h.z));
        vec3 wc = xf_point(t, c);
        b.lo = v3_sub(wc, e);
        b.hi = v3_add(wc, e);
        return b;
    }
    default:
        b.lo = b.hi = t.p;
        return b;
    }
}

void shape_free_data(shape *s)
{
    hull_free(s->hull);
    mesh_free(s->mesh);
    heightfield_free(s->field);
    compound_free(s->compound);
    s->hull = NULL;
    s->mesh = NULL;
    s->field = NULL;
    s->compound = NULL;
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
    case SHAPE_COMPOUND: {
        /* the children's farthest support point */
        const compound *c = s->compound;
        vec3 best = v3_zero();
        double bd = -INFINITY;
        for (int i = 0; i < c->count; i++) {
            vec3 p = xf_point(c->poses[i], shape_support_local(&c->children[i], q_inv_rotate(c->poses[i].q, d)));
            if (v3_dot(p, d) > bd) { bd = v3_dot(p, d); best = p; }
        }
        return best;
    }
    default:
        return v3_zero();
    }
}

double shape_thickness(const shape *s)
{
    switch (s->type) {
    case SHAPE_SPHERE: case SHAPE_CAPSULE: return s->radius;
    case SHAPE_BOX: return dmin(s->half_extents.x, dmin(s->half_extents.y, s->half_extents.z));
    case SHAPE_CYLINDER: return dmin(s->radius, s->half_height);
    case SHAPE_HULL: {
        double m = 1e300;
        for (int i = 0; i < s->hull->face_count; i++)
            m = dmin(m, s->hull->faces[i].offset - v3_dot(s->hull->faces[i].normal, s->hull->centroid));
        return m > 0 ? m : 0.0;
    }
    case SHAPE_COMPOUND: {
        /* the thinnest child can pass through first */
        double m = 1e300;
        for (int i = 0; i < s->compound->count; i++) m = dmin(m, shape_thickness(&s->compound->children[i]));
        return m;
    }
    default: return 1e300;
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
        for (int i = 0; i < s->hull->vertex_count; i++) m = dmax(m, v3_len(s->hull->vertices[i]));
        return m;
    }
    case SHAPE_MESH: case SHAPE_HEIGHTFIELD: {
        aabb lb = s->type == SHAPE_MESH ? mesh_bounds(s->mesh) : heightfield_bounds(s->field);
        return v3_len(v3_max(v3_abs(lb.lo), v3_abs(lb.hi)));
    }
    case SHAPE_COMPOUND: {
        double m = 0;
        for (int i = 0; i < s->compound->count; i++)
            m = dmax(m, v3_len(s->compound->poses[i].p) + shape_bounding_radius(&s->compound->children[i]));
        return m;
    }
    default: return PLANE_EXTENT;
    }
}

/* ---- ray casts --------------------------------------------------------------- */

/* Smallest t >= 0 with |o + t d| = r, for a ray starting outside the sphere. */
static int ray_sphere(vec3 o, vec3 d, double r, double *t)
{
    double a = v3_dot(d, d), b = v3_dot(o, d), c = v3_dot(o, o) - r * r;
    if (c <= 0 || a <= 0 || b >= 0) return 0; /* inside, no direction, or moving away */
    double disc = b * b - a * c;
    if (disc < 0) return 0;
    *t = c / (-b + sqrt(disc)); /* = (-b - sqrt(disc)) / a without cancellation */
    return 1;
}

/* Ray against the side of the z-axis cylinder of radius r, |z| <= hh, from outside it. */
static int ray_cylinder_side(vec3 o, vec3 d, double r, double hh, double *t)
{
    double a = d.x * d.x + d.y * d.y, b = o.x * d.x + o.y * d.y, c = o.x * o.x + o.y * o.y - r * r;
    if (a <= 0 || c <= 0 || b >= 0) return 0;
    double disc = b * b - a * c;
    if (disc < 0) return 0;
    double tt = c / (-b + sqrt(disc));
    if (fabs(o.z + tt * d.z) > hh) return 0;
    *t = tt;
    return 1;
}

/* Ray against the convex region {x : n_i . x <= offset_i}, by clipping the
 * parameter interval [0, max_t] with each plane; a ray starting inside gives
 * no entering plane and so no hit. */
static int ray_faces(vec3 o, vec3 d, const hull_face *faces, int count, double max_t, double *t, vec3 *normal)
{
    double enter = 0.0, leave = max_t;
    int face = -1;
    for (int i = 0; i < count; i++) {
        double num = faces[i].offset - v3_dot(faces[i].normal, o), den = v3_dot(faces[i].normal, d);
        if (den == 0) {
            if (num < 0) return 0; /* parallel and outside */
            continue;
        }
        double s = num / den;
        if (den < 0) {
            if (s > enter) { enter = s; face = i; }
        } else if (s < leave) {
            leave = s;
        }
        if (enter > leave) return 0;
    }
    if (face < 0) return 0;
    *t = enter;
    *normal = faces[face].normal;
    return 1;
}

int shape_ray_cast_local(const shape *s, vec3 o, vec3 d, double max_t, double *t, vec3 *normal)
{
    double tt = INFINITY, c;
    vec3 n = v3_zero();
    switch (s->type) {
    case SHAPE_SPHERE:
        if (ray_sphere(o, d, s->radius, &tt)) n = v3_normalize(v3_madd(o, tt, d));
        break;
    case SHAPE_BOX: {
        vec3 h = s->half_extents;
        hull_face box[6] = {{{1, 0, 0}, h.x, 0, 0}, {{-1, 0, 0}, h.x, 0, 0}, {{0, 1, 0}, h.y, 0, 0},
                            {{0, -1, 0}, h.y, 0, 0}, {{0, 0, 1}, h.z, 0, 0}, {{0, 0, -1}, h.z, 0, 0}};
        if (!ray_faces(o, d, box, 6, max_t, &tt, &n)) return 0;
        break;
    }
    case SHAPE_CAPSULE: {
        double hh = s->half_height, r = s->radius;
        double z = dmax(-hh, dmin(hh, o.z));
        if (v3_len2(v3_sub(o, v3(0, 0, z))) <= r * r) return 0; /* starts inside */
        if (ray_cylinder_side(o, d, r, hh, &c)) {
            tt = c;
            vec3 p = v3_madd(o, c, d);
            n = v3_normalize(v3(p.x, p.y, 0));
        }
        for (int end = -1; end <= 1; end += 2) {
            vec3 centre = v3(0, 0, end * hh);
            if (ray_sphere(v3_sub(o, centre), d, r, &c) && c < tt) {
                tt = c;
                n = v3_normalize(v3_sub(v3_madd(o, c, d), centre));
            }
        }
        break;
    }
    case SHAPE_CYLINDER: {
        double hh = s->half_height, r = s->radius;
        if (fabs(o.z) <= hh && o.x * o.x + o.y * o.y <= r * r) return 0; /* starts inside */
        if (ray_cylinder_side(o, d, r, hh, &c)) {
            tt = c;
            vec3 p = v3_madd(o, c, d);
            n = v3_normalize(v3(p.x, p.y, 0));
        }
        for (int end = -1; end <= 1; end += 2) {
            /* a cap is entered only from its outer side, moving inwards */
            if ((o.z - end * hh) * end <= 0 || d.z * end >= 0) continue;
            c = (end * hh - o.z) / d.z;
            vec3 p = v3_madd(o, c, d);
            if (p.x * p.x + p.y * p.y <= r * r && c < tt) { tt = c; n = v3(0, 0, end); }
        }
        break;
    }
    case SHAPE_HULL:
        if (!ray_faces(o, d, s->hull->faces, s->hull->face_count, max_t, &tt, &n)) return 0;
        break;
    case SHAPE_PLANE: {
        double num = s->plane_offset - v3_dot(s->plane_normal, o), den = v3_dot(s->plane_normal, d);
        if (num >= 0 || den >= 0) return 0; /* starts in the solid, or moves away from it */
        tt = num / den;
        n = s->plane_normal;
        break;
    }
    case SHAPE_MESH:
        if (!mesh_ray_cast(s->mesh, o, d, max_t, &tt, &n, NULL)) return 0;
        break;
    case SHAPE_HEIGHTFIELD:
        if (!heightfield_ray_cast(s->field, o, d, max_t, &tt, &n, NULL)) return 0;
        break;
    case SHAPE_COMPOUND:
        if (!compound_ray_cast_local(s->compound, o, d, max_t, &tt, &n, NULL)) return 0;
        break;
    default:
        return 0;
    }
    if (!(tt >= 0 && tt <= max_t)) return 0;
    *t = tt;
    *normal = n;
    return 1;
}

/* ---- compounds: their children through the functions above ------------------- */

compound *compound_alloc(int n)
{
    compound *c = calloc(1, sizeof *c);
    if (c) {
        c->children = calloc((size_t)n, sizeof *c->children);
        c->poses = malloc(sizeof *c->poses * (size_t)n);
        c->friction = malloc(sizeof *c->friction * (size_t)n);
        c->restitution = malloc(sizeof *c->restitution * (size_t)n);
        c->density = malloc(sizeof *c->density * (size_t)n);
        c->rolling_resistance = malloc(sizeof *c->rolling_resistance * (size_t)n);
        c->combine = malloc(sizeof *c->combine * (size_t)n);
    }
    if (!c || !c->children || !c->poses || !c->friction || !c->restitution || !c->density || !c->rolling_resistance ||
        !c->combine) {
        compound_free(c);
        return NULL;
    }
    return c;
}

void compound_free(compound *c)
{
    if (!c) return;
    for (int i = 0; i < c->count; i++) shape_free_data(&c->children[i]);
    free(c->children); free(c->poses); free(c->friction); free(c->restitution); free(c->density);
    free(c->rolling_resistance); free(c->combine);
    free(c);
}

static xform xf_mul(xform a, xform b)
{
    xform r = {xf_point(a, b.p), q_mul(a.q, b.q)};
    return r;
}

mass_props compound_mass(const compound *c)
{
    mass_props total = {0, {0, 0, 0}, {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
    mass_props part[256];
    mass_props *parts = c->count <= 256 ? part : malloc(sizeof *parts * (size_t)c->count);
    if (!parts) return total;
    vec3 moment = v3_zero();
    for (int i = 0; i < c->count; i++) {
        parts[i] = shape_mass_from_density(&c->children[i], c->density[i]);
        /* the child's centre in the body frame */
        parts[i].center = xf_point(c->poses[i], parts[i].center);
        total.mass += parts[i].mass;
        moment = v3_madd(moment, parts[i].mass, parts[i].center);
    }
    total.center = total.mass > 0 ? v3_scale(moment, 1.0 / total.mass) : v3_zero();
    /* each child's inertia turned into body axes, moved to the common centre */
    for (int i = 0; i < c->count; i++) {
        mat3 r = m3_from_quat(c->poses[i].q);
        mat3 ii = m3_rotate_tensor(r, parts[i].inertia);
        ii = m3_add(ii, m3_parallel_axis(parts[i].mass, v3_sub(parts[i].center, total.center)));
        total.inertia = m3_add(total.inertia, ii);
    }
    if (parts != part) free(parts);
    return total;
}

aabb compound_aabb(const compound *c, xform t)
{
    aabb b = shape_aabb(&c->children[0], xf_mul(t, c->poses[0]));
    for (int i = 1; i < c->count; i++) b = aabb_union(b, shape_aabb(&c->children[i], xf_mul(t, c->poses[i])));
    return b;
}

int compound_ray_cast_local(const compound *c, vec3 o, vec3 d, double max_t, double *t, vec3 *normal, int *child)
{
    int found = 0;
    double best = max_t;
    for (int i = 0; i < c->count; i++) {
        xform p = c->poses[i];
        double tt;
        vec3 n;
        if (!shape_ray_cast_local(&c->children[i], xf_inv_point(p, o), q_inv_rotate(p.q, d), best, &tt, &n)) continue;
        if (found && tt >= best) continue;
        found = 1;
        best = tt;
        *normal = q_rotate(p.q, n);
        if (child) *child = i;
    }
    if (found) *t = best;
    return found;
}
