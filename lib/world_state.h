/* world_state.h - the world's internal services (world_state.c), for the
 * stages and the public API files alike. Included by world.h. */
#ifndef CAROM_WORLD_STATE_H
#define CAROM_WORLD_STATE_H

/* Records a formatted error on the world; returns status for chaining.
 * Every message begins with the name of the public function that failed
 * and ": ", either in fmt itself ("body_set_mass: ...") or as fmt's leading
 * "%s: " with the name the first argument; world_fail records where the
 * reason after it starts (carom_world_last_error_reason). */
carom_status world_fail(const carom_world *w, carom_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* The public id of the body at id_index. */
carom_body_id world_make_id(const carom_world *w, int id_index);
/* Fattened bounds used by the broadphase for a body at its current pose. */
aabb world_body_fat_aabb(const carom_world *w, int slot, double margin);
/* Wakes the body (and, through contacts, its island on the next step). */
void world_wake_body(carom_world *w, int slot);
/* Removes every contact of a body (id index), waking the bodies on the other side. */
void world_remove_body_contacts(carom_world *w, int id_index);
/* Removes the live body at id_index: its contacts, proxy, shape data, slot. */
void world_destroy_body(carom_world *w, int id_index);
/* Records every body's pose as its previous pose, at the start of the step. */
void world_remember_poses(carom_world *w);

#endif
