/* filter.c - collision filtering: the rule on category/mask/group, the body
 * setters, and the world's pair filter callback (see carom.h). */
#include "filter.h"
#include "world.h"

int filter_pair_allowed(carom_world *w, int slot_a, int slot_b)
{
    const body_store *s = &w->bodies;
    if (!filter_bits_allow(s, slot_a, slot_b)) return 0;
    if (!w->pair_filter) return 1;
    int ia = s->id_index[slot_a], ib = s->id_index[slot_b];
    if (ia > ib) { int t = ia; ia = ib; ib = t; }
    if (contact_find(&w->contacts, ia, ib) >= 0) return 1;
    return w->pair_filter(w->pair_filter_context, world_make_id(w, ia), world_make_id(w, ib)) != 0;
}

CAROM_API carom_status carom_body_set_filter(carom_world *w, carom_body_id id, uint64_t category, uint64_t mask,
                                             int group)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    if (slot < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "body_set_filter: body has been destroyed (or the id is invalid)");
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "body_set_filter: the world is locked (inside step or a callback)");
    body_store *s = &w->bodies;
    s->category[slot] = category;
    s->filter_mask[slot] = mask;
    s->group[slot] = group;
    w->filters_settled = 0; /* the next collision pass checks every contact's bits */
    /* contacts the new bits forbid end at the next step (with end events);
     * pairs they now allow are found then: the proxy counts as moved. The
     * body wakes so it responds to the new rule (a sleeper resting on what
     * it may no longer touch falls). */
    bp_move_proxy(w->bp, s->proxy[slot], s->fat_box[slot]);
    world_wake_body(w, slot);
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_filter(const carom_world *w, carom_body_id id, uint64_t *category,
                                             uint64_t *mask, int *group)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    if (slot < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "body_get_filter: body has been destroyed (or the id is invalid)");
    if (!category && !mask && !group) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "body_get_filter: all outputs are NULL");
    if (category) *category = w->bodies.category[slot];
    if (mask) *mask = w->bodies.filter_mask[slot];
    if (group) *group = w->bodies.group[slot];
    return CAROM_OK;
}

CAROM_API carom_status carom_world_set_pair_filter(carom_world *w, carom_pair_filter_fn *fn, void *context)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "world_set_pair_filter: the world is locked (inside step or a callback)");
    w->pair_filter = fn;
    w->pair_filter_context = context;
    /* every pair is asked again at the next step */
    for (int i = 0; i < w->bodies.count; i++) bp_move_proxy(w->bp, w->bodies.proxy[i], w->bodies.fat_box[i]);
    return CAROM_OK;
}
