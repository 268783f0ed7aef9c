/* collision.c - the collision stage of the step: broadphase pair updates feed
 * the contact cache; the narrowphase refreshes every live contact's manifold
 * and raises begin/end events. */
#include <stdlib.h>
#include <string.h>
#include "world.h"

static void add_pair(void *ctx, int ida, int idb)
{
    carom_world *w = ctx;
    body_store *s = &w->bodies;
    int sa = s->ids[ida].slot, sb = s->ids[idb].slot;
    if (sa < 0 || sb < 0 || ida == idb) return;
    if (s->type[sa] != CAROM_BODY_DYNAMIC && s->type[sb] != CAROM_BODY_DYNAMIC) return;
    if (contact_find(&w->contacts, ida, idb) >= 0) return;
    int ci = contact_add(&w->contacts, ida, idb);
    if (ci < 0) return; /* out of memory: the pair is retried when a proxy moves again */
    contact *c = &w->contacts.items[ci];
    int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
    /* material mixing: friction sqrt(mu1 mu2), restitution max(e1, e2) */
    c->friction = sqrt(s->friction[a] * s->friction[b]);
    c->restitution = dmax(s->restitution[a], s->restitution[b]);
}

void world_update_pairs(carom_world *w)
{
    body_store *s = &w->bodies;
    double dt = w->last_dt;
    for (int i = 0; i < s->count; i++) {
        if (s->type[i] == CAROM_BODY_STATIC || !(s->flags[i] & BODY_AWAKE)) continue;
        aabb box = world_body_fat_aabb(w, i, 0.0);
        /* bullets and fast bodies: the box covers this step's travel so their
         * speculative contacts exist before they arrive */
        vec3 travel = v3_scale(s->velocity[i], dt);
        if (v3_len2(travel) > 0.25 * WORLD_AABB_MARGIN * WORLD_AABB_MARGIN) {
            box.lo = v3_min(box.lo, v3_add(box.lo, travel));
            box.hi = v3_max(box.hi, v3_add(box.hi, travel));
        }
        if (!aabb_contains(s->fat_box[i], box)) {
            aabb fat = aabb_fatten(box, WORLD_AABB_MARGIN);
            s->fat_box[i] = fat;
            bp_move_proxy(w->bp, s->proxy[i], fat);
        }
    }
    bp_update_pairs(w->bp, add_pair, w);
}

static void push_touch_event(carom_world *w, const contact *c, carom_event_type type)
{
    carom_contact_event e;
    memset(&e, 0, sizeof e);
    e.type = type;
    e.a = world_make_id(w, c->id_a);
    e.b = world_make_id(w, c->id_b);
    e.normal.x = c->m.normal.x; e.normal.y = c->m.normal.y; e.normal.z = c->m.normal.z;
    if (c->m.count > 0) {
        vec3 p = c->m.points[0].point;
        e.point.x = p.x; e.point.y = p.y; e.point.z = p.z;
    }
    world_push_event(w, &e);
}

void world_collide(carom_world *w)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    double speculative = w->def.speculative_distance;
    double dt = w->last_dt;
    for (int i = cs->count - 1; i >= 0; i--) {
        contact *c = &cs->items[i];
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        int awake_a = s->type[a] != CAROM_BODY_STATIC && (s->flags[a] & BODY_AWAKE);
        int awake_b = s->type[b] != CAROM_BODY_STATIC && (s->flags[b] & BODY_AWAKE);
        c->flags &= ~(uint32_t)CONTACT_SIM;
        if (!awake_a && !awake_b) continue; /* a sleeping pair keeps its manifold */
        if (!aabb_overlap(s->fat_box[a], s->fat_box[b])) {
            if (c->flags & CONTACT_TOUCHING) push_touch_event(w, c, CAROM_EVENT_END);
            contact_remove(cs, i);
            continue;
        }
        xform xa = body_xform(s, a), xb = body_xform(s, b);
        /* a fast pair looks ahead by its closing travel this step */
        double spec = speculative;
        double closing = v3_len(v3_sub(s->velocity[a], s->velocity[b])) * dt;
        if (closing > spec) spec = dmin(closing, speculative + 4.0 * WORLD_AABB_MARGIN);
        manifold old_m = c->m;
        contact_point_state old_state[MANIFOLD_MAX_POINTS];
        memcpy(old_state, c->state, sizeof old_state);
        collide(&s->shapes[a], xa, &s->shapes[b], xb, spec, &c->cache, &c->m);
        contact_match_points(c, &old_m, old_state, xa);
        int touching = c->m.count > 0;
        int was = (c->flags & CONTACT_TOUCHING) != 0;
        c->flags = (c->flags & ~(uint32_t)(CONTACT_TOUCHING | CONTACT_WAS_TOUCHING)) |
                   (touching ? CONTACT_TOUCHING : 0) | (was ? CONTACT_WAS_TOUCHING : 0) | CONTACT_SIM;
        if (touching && (!awake_a || !awake_b)) {
            /* an awake body touching a sleeping one wakes it for this very step */
            if (!awake_a) world_wake_body(w, a);
            if (!awake_b) world_wake_body(w, b);
        }
        if (touching && !was) push_touch_event(w, c, CAROM_EVENT_BEGIN);
        else if (!touching && was) push_touch_event(w, c, CAROM_EVENT_END);
    }
}
