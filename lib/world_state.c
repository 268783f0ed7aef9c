/* world_state.c - the world's internal services, for the stages and the
 * public API files alike (which call in; nothing here calls out to the
 * public API): errors, ids, waking, a body's removal. */
#include <assert.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "world.h"

/* The length of the function name and ": " that fmt (with its first
 * argument, `first`, when fmt begins "%s: ") writes at the start of the
 * message; 0 when fmt follows no such form. */
static size_t name_length(const char *fmt, const char *first)
{
    if (strncmp(fmt, "%s: ", 4) == 0) return strlen(first) + 2;
    size_t n = strspn(fmt, "abcdefghijklmnopqrstuvwxyz_");
    return n > 0 && fmt[n] == ':' && fmt[n + 1] == ' ' ? n + 2 : 0;
}

carom_status world_fail(const carom_world *w, carom_status status, const char *fmt, ...)
{
    if (w) {
        /* The message buffer is diagnostic state, not simulation state: const
         * getters may record why they failed. */
        carom_world *mw = (carom_world *)(uintptr_t)w;
        va_list ap;
        va_start(ap, fmt);
        const char *first = NULL;
        if (strncmp(fmt, "%s: ", 4) == 0) {
            va_list peek;
            va_copy(peek, ap);
            first = va_arg(peek, const char *);
            va_end(peek);
        }
        int n = vsnprintf(mw->error, sizeof mw->error, fmt, ap);
        va_end(ap);
        size_t name = name_length(fmt, first), written = n > 0 ? strlen(mw->error) : 0;
        /* a format without the name would hand the name to the reason:
         * stop a debug build at the call that breaks the convention */
        assert(name > 0 && "world_fail: the format must begin \"name: \" or \"%s: \" (the name first)");
        mw->error_reason = (int)(name <= written ? name : written);
        mw->last_status = status;
    }
    return status;
}

carom_body_id world_make_id(const carom_world *w, int id_index)
{
    carom_body_id id = {(uint32_t)id_index + 1, w->bodies.ids[id_index].generation};
    return id;
}

aabb world_body_fat_aabb(const carom_world *w, int slot, double margin)
{
    aabb box = shape_aabb(&w->bodies.shapes[slot], body_xform(&w->bodies, slot));
    return aabb_fatten(box, margin + w->def.speculative_distance);
}

void world_wake_body(carom_world *w, int slot)
{
    body_store *s = &w->bodies;
    if (s->type[slot] == CAROM_BODY_STATIC) return;
    s->flags[slot] |= BODY_AWAKE;
    s->sleep_time[slot] = 0;
}

void world_remove_body_contacts(carom_world *w, int id_index)
{
    contact_set *cs = &w->contacts;
    for (int i = cs->count - 1; i >= 0; i--)
        if (cs->items[i].id_a == id_index || cs->items[i].id_b == id_index) {
            /* wake the other body: what rested on this one must fall */
            int other = cs->items[i].id_a == id_index ? cs->items[i].id_b : cs->items[i].id_a;
            int oslot = w->bodies.ids[other].slot;
            if (oslot >= 0) world_wake_body(w, oslot);
            contact_remove(cs, i);
        }
}

void world_destroy_body(carom_world *w, int id_index)
{
    int slot = w->bodies.ids[id_index].slot;
    world_remove_body_contacts(w, id_index);
    bp_destroy_proxy(w->bp, w->bodies.proxy[slot]);
    shape_free_data(&w->bodies.shapes[slot]);
    body_store_remove(&w->bodies, slot);
}

void world_remember_poses(carom_world *w)
{
    body_store *s = &w->bodies;
    for (int i = 0; i < s->count; i++) {
        s->previous_origin[i] = body_origin(s, i);
        s->previous_rotation[i] = s->rotation[i];
    }
}
