/* toi.c - continuous collision. Speculative contacts catch ordinary motion;
 * a body that moved farther than its own thickness this step (or any bullet)
 * is swept from its start to its end position by conservative advancement,
 * against static geometry (bullets: against every body), and stopped just
 * short of the first hit, so the next step's speculative contact lands it
 * exactly on the surface instead of tunnelling or being pushed out softly. */
#include <stdlib.h>
#include <string.h>
#include "filter.h"
#include "world.h"
#include "toi.h"

#define TOI_MAX_ITERATIONS 40

/* Thickness below which a shape can pass through others in one step. */
static double min_extent(const shape *s)
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
        for (int i = 0; i < s->compound->count; i++) m = dmin(m, min_extent(&s->compound->children[i]));
        return m;
    }
    default: return 1e300;
    }
}

typedef struct sweep_query {
    carom_world *w;
    int slot;                  /* the moving body */
    vec3 start, end;           /* centre of mass at the step's start and end */
    int bullet;
    double best_t;             /* earliest hit fraction */
    double target;             /* separation to stop at */
} sweep_query;

/* Separation between the moving body (centre at c) and body `other`; large when
 * farther than `range`. */
static double separation_at(const carom_world *w, int slot, vec3 c, int other, double range)
{
    const body_store *s = &w->bodies;
    xform xa = {v3_sub(c, q_rotate(s->rotation[slot], s->local_center[slot])), s->rotation[slot]};
    xform xb = body_xform(s, other);
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(&s->shapes[slot], xa, &s->shapes[other], xb, range, &cache, &m);
    if (m.count == 0) return range;
    double d = m.points[0].separation;
    for (int i = 1; i < m.count; i++) d = dmin(d, m.points[i].separation);
    return d;
}

static int sweep_against(void *ctx, int id_index)
{
    sweep_query *q = ctx;
    const body_store *s = &q->w->bodies;
    int other = s->ids[id_index].slot;
    if (other < 0 || other == q->slot || !filter_bits_allow(s, q->slot, other)) return 1;
    if ((s->flags[other] | s->flags[q->slot]) & BODY_SENSOR) return 1;
    if (s->type[other] == CAROM_BODY_DYNAMIC && !q->bullet) return 1;
    if (s->type[other] == CAROM_BODY_DYNAMIC && (s->flags[other] & BODY_BULLET)) return 1;
    vec3 delta = v3_sub(q->end, q->start);
    double travel = v3_len(delta);
    if (travel <= 0) return 1;
    /* already touching at the start: the contact solver owns this pair */
    double d0 = separation_at(q->w, q->slot, q->start, other, travel + q->target);
    if (d0 <= q->target) return 1;
    double t = 0.0;
    for (int it = 0; it < TOI_MAX_ITERATIONS; it++) {
        double d = separation_at(q->w, q->slot, v3_madd(q->start, t, delta), other, travel + q->target);
        if (d <= q->target * 1.5) break;
        /* the body cannot close a gap d faster than it travels */
        t += (d - q->target) / travel;
        if (t >= q->best_t) return 1;
    }
    if (t < q->best_t) q->best_t = t;
    return 1;
}

void world_continuous(carom_world *w, const step_context *ctx)
{
    body_store *s = &w->bodies;
    for (int i = 0; i < s->count; i++) {
        if (s->type[i] != CAROM_BODY_DYNAMIC || !(s->flags[i] & BODY_AWAKE)) continue;
        int k = s->solver_index[i];
        if (k <= 0) continue;
        vec3 delta = ctx->dp[k];
        double travel = v3_len(delta);
        int bullet = (s->flags[i] & BODY_BULLET) != 0;
        if (!bullet && travel <= min_extent(&s->shapes[i])) continue;
        if (!(travel > 0) || !isfinite(travel)) continue;
        sweep_query q = {w, i, v3_sub(s->center[i], delta), s->center[i], bullet, 1.0,
                         dmax(0.5 * w->def.linear_slop, 1e-4)};
        aabb a0 = shape_aabb(&s->shapes[i], (xform){v3_sub(body_origin(s, i), delta), s->rotation[i]});
        aabb a1 = shape_aabb(&s->shapes[i], body_xform(s, i));
        bp_query(w->bp, aabb_fatten(aabb_union(a0, a1), q.target), sweep_against, &q);
        if (q.best_t < 1.0) {
            s->center[i] = v3_madd(q.start, q.best_t, delta);
            w->stats.toi_events++;
            aabb fat = aabb_fatten(shape_aabb(&s->shapes[i], body_xform(s, i)), WORLD_AABB_MARGIN + w->def.speculative_distance);
            s->fat_box[i] = fat;
            bp_move_proxy(w->bp, s->proxy[i], fat);
        }
    }
}
