/* probe.c - accuracy probes (energy, momentum) and spatial queries (ray cast,
 * AABB overlap) over the world. */
#include <string.h>
#include "world.h"
#include "mesh.h"

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

typedef struct ray_query {
    const carom_world *w;
    carom_ray_hit *hit;
    int found;
    int part;              /* the hit's compound child, mesh triangle or field cell (-1 none) */
} ray_query;

/* shape_ray_cast_local, and which part of a compound or level shape was hit. */
static int ray_cast_part(const shape *s, vec3 o, vec3 d, double max_t, double *t, vec3 *n, int *part)
{
    *part = -1;
    uint32_t index = 0;
    switch (s->type) {
    case SHAPE_COMPOUND: return compound_ray_cast_local(s->compound, o, d, max_t, t, n, part);
    case SHAPE_MESH:
        if (!mesh_ray_cast(s->mesh, o, d, max_t, t, n, &index)) return 0;
        *part = (int)index;
        return 1;
    case SHAPE_HEIGHTFIELD:
        if (!heightfield_ray_cast(s->field, o, d, max_t, t, n, &index)) return 0;
        *part = (int)index;
        return 1;
    default: return shape_ray_cast_local(s, o, d, max_t, t, n);
    }
}

static double ray_visit(void *ctx, int id_index, vec3 origin, vec3 dir, double max_t)
{
    ray_query *q = ctx;
    const body_store *s = &q->w->bodies;
    int slot = s->ids[id_index].slot;
    if (slot < 0) return max_t;
    xform x = body_xform(s, slot);
    vec3 o = xf_inv_point(x, origin), d = q_inv_rotate(x.q, dir);
    double t;
    vec3 nl;
    int part;
    if (!ray_cast_part(&s->shapes[slot], o, d, max_t, &t, &nl, &part) || t > max_t) return max_t;
    q->part = part;
    vec3 p = v3_madd(origin, t, dir), n = q_rotate(x.q, nl);
    q->found = 1;
    q->hit->body = world_make_id(q->w, id_index);
    q->hit->point.x = p.x; q->hit->point.y = p.y; q->hit->point.z = p.z;
    q->hit->normal.x = n.x; q->hit->normal.y = n.y; q->hit->normal.z = n.z;
    q->hit->fraction = t;
    return t; /* clip: only closer hits from now on */
}

CAROM_API int carom_world_ray_cast(const carom_world *w, carom_vec3 origin, carom_vec3 translation, carom_ray_hit *hit)
{
    if (!w) return -1;
    if (!hit) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "ray_cast: hit is NULL"), -1;
    vec3 o = v3(origin.x, origin.y, origin.z), d = v3(translation.x, translation.y, translation.z);
    if (!v3_is_finite(o) || !v3_is_finite(d))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "ray_cast: origin and translation must be finite"), -1;
    memset(hit, 0, sizeof *hit);
    if (v3_len2(d) == 0) return 0;
    ray_query q = {w, hit, 0, -1};
    bp_ray_cast(w->bp, o, d, 1.0, ray_visit, &q);
    return q.found;
}

CAROM_API int carom_world_ray_cast_child(const carom_world *w, carom_vec3 origin, carom_vec3 translation,
                                         carom_ray_hit *hit, int *child)
{
    if (child) *child = -1;
    if (!w) return -1;
    if (!hit) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "ray_cast_child: hit is NULL"), -1;
    vec3 o = v3(origin.x, origin.y, origin.z), d = v3(translation.x, translation.y, translation.z);
    if (!v3_is_finite(o) || !v3_is_finite(d))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "ray_cast_child: origin and translation must be finite"), -1;
    memset(hit, 0, sizeof *hit);
    if (v3_len2(d) == 0) return 0;
    ray_query q = {w, hit, 0, -1};
    bp_ray_cast(w->bp, o, d, 1.0, ray_visit, &q);
    if (q.found && child) *child = q.part;
    return q.found;
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
