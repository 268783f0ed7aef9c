/* compound.c - the contacts of any pair of shapes: collide() is every
 * caller's entry; a pair with a mesh, height field or compound on either side
 * goes through collide_multi (one manifold per child pair, a mesh's split
 * further by normal), a convex pair to the narrowphase (collide_convex). It
 * sits above narrowphase.c and triangle_contact.c, which never call it: the
 * recursion into children stays in this file. (A compound's mass, bounds and
 * ray casts are shape.c's.) */
#include <stdlib.h>
#include <string.h>
#include "narrowphase.h"
#include "mesh.h"
#include "triangle_contact.h"
#include "compound.h"

static xform xf_mul(xform a, xform b)
{
    xform r = {xf_point(a, b.p), q_mul(a.q, b.q)};
    return r;
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
    if (collide_convex(a, xa, b, xb, spec, &cache, &m) > 0) put(o, &m, base);
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

int collide(const shape *a, xform xa, const shape *b, xform xb, double speculative, collide_cache *cache, manifold *m)
{
    if (!shape_is_composite(a) && !shape_is_composite(b)) return collide_convex(a, xa, b, xb, speculative, cache, m);
    memset(m, 0, sizeof *m);
    m->normal = v3(0, 0, 1);
    /* a pose that overflowed has no contacts */
    if (!xf_is_finite(xa) || !xf_is_finite(xb)) return 0;
    manifold all[PAIR_MAX_MANIFOLDS];
    uint32_t base[PAIR_MAX_MANIFOLDS];
    int n = collide_multi(a, xa, b, xb, speculative, all, base, PAIR_MAX_MANIFOLDS);
    double deepest = 1e300;
    for (int k = 0; k < n; k++)
        for (int i = 0; i < all[k].count; i++)
            if (all[k].points[i].separation < deepest) { deepest = all[k].points[i].separation; *m = all[k]; }
    (void)cache;
    return m->count;
}
