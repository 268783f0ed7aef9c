/* compound.c - bodies made of several convex children: combined mass
 * properties, bounds, ray casts, and the contacts of every pair that has a
 * mesh, height field or compound on either side (one manifold per child
 * pair, a mesh's split further by normal). */
#include <stdlib.h>
#include <string.h>
#include "narrowphase.h"
#include "mesh.h"
#include "triangle_contact.h"
#include "compound.h"

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

/* ---- contacts ----------------------------------------------------------------- */

typedef struct multi_out {
    manifold *m;
    uint32_t *base;
    int count, max;
} multi_out;

static void put(multi_out *o, const manifold *m, uint32_t base)
{
    if (o->count >= o->max || m->count == 0) return;
    o->m[o->count] = *m;
    o->base[o->count] = base;
    o->count++;
}

/* A convex or level shape a against b (either side may be level, neither a
 * compound): one manifold, or a mesh's per normal. */
static void collide_parts(const shape *a, xform xa, const shape *b, xform xb, double spec, uint32_t base, multi_out *o)
{
    if (shape_is_composite(a) || shape_is_composite(b)) {
        if (shape_is_composite(a) && shape_is_composite(b)) return; /* level geometry never meets level geometry */
        manifold found[COMPOSITE_MAX_MANIFOLDS];
        int n = collide_composite(a, xa, b, xb, spec, found, COMPOSITE_MAX_MANIFOLDS);
        for (int k = 0; k < n; k++) put(o, &found[k], base);
        return;
    }
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    if (collide(a, xa, b, xb, spec, &cache, &m) > 0) put(o, &m, base);
}

static int child_near(const shape *child, xform x, aabb other, double spec)
{
    return aabb_overlap(aabb_fatten(shape_aabb(child, x), spec), other);
}

int collide_multi(const shape *a, xform xa, const shape *b, xform xb, double spec, manifold *out, uint32_t *base,
                  int max)
{
    multi_out o = {out, base, 0, max};
    if (a->type == SHAPE_COMPOUND || b->type == SHAPE_COMPOUND) {
        const compound *ca = a->type == SHAPE_COMPOUND ? a->compound : NULL;
        const compound *cb = b->type == SHAPE_COMPOUND ? b->compound : NULL;
        int na = ca ? ca->count : 1, nb = cb ? cb->count : 1;
        aabb box_b = shape_aabb(b, xb);
        for (int i = 0; i < na; i++) {
            const shape *sa = ca ? &ca->children[i] : a;
            xform xi = ca ? xf_mul(xa, ca->poses[i]) : xa;
            if (!child_near(sa, xi, box_b, spec)) continue;
            aabb box_i = shape_aabb(sa, xi);
            for (int j = 0; j < nb; j++) {
                const shape *sb = cb ? &cb->children[j] : b;
                xform xj = cb ? xf_mul(xb, cb->poses[j]) : xb;
                if (cb && !child_near(sb, xj, box_i, spec)) continue;
                collide_parts(sa, xi, sb, xj, spec, (uint32_t)(i * nb + j) * COMPOSITE_MAX_MANIFOLDS, &o);
            }
        }
        return o.count;
    }
    collide_parts(a, xa, b, xb, spec, 0, &o);
    return o.count;
}

void compound_sub_children(const shape *a, const shape *b, uint32_t sub, int *child_a, int *child_b)
{
    uint32_t pair = sub / COMPOSITE_MAX_MANIFOLDS;
    int nb = b->type == SHAPE_COMPOUND ? b->compound->count : 1;
    *child_a = a->type == SHAPE_COMPOUND ? (int)(pair / (uint32_t)nb) : -1;
    *child_b = b->type == SHAPE_COMPOUND ? (int)(pair % (uint32_t)nb) : -1;
}

