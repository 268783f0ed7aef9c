/* material.h - surface materials (material.c): checked, copied into bodies
 * and compound children, mixed into each contact. */
#ifndef CAROM_MATERIAL_H
#define CAROM_MATERIAL_H

#include "world.h"

/* 1 when m is a valid material (its first m->size bytes); else 0 with a
 * message naming the bad field in msg. */
int material_valid(const carom_material *m, char *msg, size_t msg_size);
/* A valid material's values into the four outputs. */
void material_apply(const carom_material *m, double *friction, double *restitution, double *rolling_resistance,
                    int *combine);
/* The friction, restitution and rolling resistance a contact of manifold
 * number sub between the bodies in slots sa and sb mixes to (into out). */
void material_mix(const body_store *s, int sa, int sb, uint32_t sub, double out[3]);
/* The contact's friction, restitution and rolling resistance from its two
 * bodies (or compound children), by their combine modes. */
void material_mix_contact(carom_world *w, int contact_index);

#endif
