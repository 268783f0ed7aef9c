/* filter.h - which pairs of bodies may touch: category/mask bits, groups and
 * the world's pair filter callback. */
#ifndef CAROM_FILTER_H
#define CAROM_FILTER_H

#include "body.h"

/* 1 when the bits and groups of the bodies at slots a and b let them touch
 * (inline: the collision stage asks it of every pair every step). */
static inline int filter_bits_allow(const body_store *s, int a, int b)
{
    int ga = s->group[a], gb = s->group[b];
    if (ga != 0 && ga == gb) return ga > 0; /* a shared group decides alone */
    return (s->category[a] & s->filter_mask[b]) != 0 && (s->category[b] & s->filter_mask[a]) != 0;
}
/* The bits, then the world's pair filter for a pair with no contact yet
 * (one that exists was admitted when it began): what continuous collision
 * asks before it sweeps one body against another. */
struct carom_world;
int filter_pair_allowed(struct carom_world *w, int slot_a, int slot_b);

#endif
