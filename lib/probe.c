/* probe.c - accuracy probes (energy, momentum, penetration) and the AABB
 * query over the world (ray and shape queries: query.c). */
#include <string.h>
#include "compound.h"
#include "world.h"

CAROM_API carom_status carom_world_get_energy(const carom_world *w, double *kinetic, double *potential)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (!kinetic && !potential) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "get_energy: both outputs are NULL");
    const body_store *s = &w->bodies;
    vec3 g = v3(w->def.gravity.x, w->def.gravity.y, w->def.gravity.z);
    double ke = 0.0, pe = 0.0;
    for (int i = 0; i < s->count; i++) {
        if (s->type[i] != CAROM_BODY_DYNAMIC) continue;
        mat3 r = m3_from_quat(s->rotation[i]);
        ke += kinetic_energy(s->mass[i], m3_rotate_tensor(r, s->inertia_local[i]), s->velocity[i], s->angular_velocity[i]);
        pe -= s->mass[i] * s->gravity_scale[i] * v3_dot(g, s->center[i]);
    }
    if (kinetic) *kinetic = ke;
    if (potential) *potential = pe;
    return CAROM_OK;
}

CAROM_API carom_status carom_world_get_momentum(const carom_world *w, carom_vec3 *linear, carom_vec3 *angular)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (!linear && !angular) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "get_momentum: both outputs are NULL");
    const body_store *s = &w->bodies;
    vec3 p = v3_zero(), l = v3_zero();
    for (int i = 0; i < s->count; i++) {
        if (s->type[i] != CAROM_BODY_DYNAMIC) continue;
        mat3 r = m3_from_quat(s->rotation[i]);
        p = v3_madd(p, s->mass[i], s->velocity[i]);
        l = v3_add(l, angular_momentum_about(s->mass[i], m3_rotate_tensor(r, s->inertia_local[i]), s->center[i],
                                             s->velocity[i], s->angular_velocity[i], v3_zero()));
    }
    if (linear) { linear->x = p.x; linear->y = p.y; linear->z = p.z; }
    if (angular) { angular->x = l.x; angular->y = l.y; angular->z = l.z; }
    return CAROM_OK;
}

typedef struct box_query {
    const carom_world *w;
    aabb box;
    carom_body_id *ids;
    int capacity, count;
} box_query;

static int box_visit(void *ctx, int id_index)
{
    box_query *q = ctx;
    const body_store *s = &q->w->bodies;
    int slot = s->ids[id_index].slot;
    if (slot < 0) return 1;
    /* the tree holds fat boxes: confirm against the tight one */
    if (!aabb_overlap(q->box, shape_aabb(&s->shapes[slot], body_xform(s, slot)))) return 1;
    if (q->count < q->capacity) q->ids[q->count] = world_make_id(q->w, id_index);
    q->count++;
    return 1;
}

CAROM_API int carom_world_query_aabb(const carom_world *w, carom_vec3 lo, carom_vec3 hi, carom_body_id *ids, int capacity)
{
    if (!w) return -1;
    vec3 l = v3(lo.x, lo.y, lo.z), h = v3(hi.x, hi.y, hi.z);
    if (!v3_is_finite(l) || !v3_is_finite(h) || l.x > h.x || l.y > h.y || l.z > h.z)
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "query_aabb: need finite lo <= hi"), -1;
    if (capacity < 0 || (capacity > 0 && !ids))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "query_aabb: bad output array"), -1;
    box_query q = {w, {l, h}, ids, capacity, 0};
    bp_query(w->bp, q.box, box_visit, &q);
    return q.count;
}

CAROM_API double carom_world_measure_max_penetration(const carom_world *w)
{
    if (!w) return 0.0;
    const body_store *s = &w->bodies;
    double deepest = 0.0;
    for (int i = 0; i < w->contacts.count; i++) {
        const contact *c = &w->contacts.items[i];
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        collide_cache cache = c->cache; /* a copy: measuring must not change the world */
        manifold m;
        collide(&s->shapes[a], body_xform(s, a), &s->shapes[b], body_xform(s, b), 0.0, &cache, &m);
        for (int j = 0; j < m.count; j++)
            if (-m.points[j].separation > deepest) deepest = -m.points[j].separation;
    }
    return deepest;
}
