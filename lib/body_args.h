/* body_args.h - what the body entry points of body_calls.c and forces.c
 * share: public vectors to internal ones and back, the finite check, and
 * the id -> slot lookup that fails with a stale-id error naming the call. */
#ifndef CAROM_BODY_ARGS_H
#define CAROM_BODY_ARGS_H

#include "world.h"

static inline vec3 args_v3(carom_vec3 v) { return v3(v.x, v.y, v.z); }
static inline carom_vec3 args_c3(vec3 v) { carom_vec3 r = {v.x, v.y, v.z}; return r; }
static inline int args_finite(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* The slot of a live id, or -1 with the world's error set (fn: the call). */
static inline int args_slot(const carom_world *w, carom_body_id id, const char *fn)
{
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    if (slot < 0) world_fail(w, CAROM_ERROR_STALE_ID, "%s: body has been destroyed (or the id is invalid)", fn);
    return slot;
}

/* In a function with a world `w` and an id `id`: declares `slot`. */
#define SLOT_OR_FAIL(fn)                                       \
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;               \
    int slot = args_slot(w, id, fn);                           \
    if (slot < 0) return CAROM_ERROR_STALE_ID;
#define OUT_OR_FAIL(p, fn) \
    if (!(p)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: output pointer is NULL", fn);
#define UNLOCKED_OR_FAIL(fn) \
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "%s: the world is locked (inside step or a callback)", fn);

#endif
