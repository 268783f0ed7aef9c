/* compound.h - the contacts of any pair of shapes (compound.c): collide(),
 * and collide_multi for a pair with a mesh, height field or compound on
 * either side. (A compound's mass, bounds and ray casts: shape.h.) */
#ifndef CAROM_COMPOUND_H
#define CAROM_COMPOUND_H

#include "shape.h"
#include "narrowphase.h"

/* Contacts between shape a at xa and shape b at xb, including speculative
 * points whose separation is below `speculative` (>= 0). Any order of types
 * works (the normal always points from a to b). Returns m->count. Results are
 * always finite. A pair with a mesh, height field or compound gives its
 * deepest manifold only (the contact stage asks collide_multi for all). */
int collide(const shape *a, xform xa, const shape *b, xform xb, double speculative,
            collide_cache *cache, manifold *m);

/* Any pair with a mesh, height field or compound on either side: its
 * manifolds (normal a to b) and for each the base of its contact numbers
 * (a multiple of COMPOSITE_MAX_MANIFOLDS naming the child pair); returns how
 * many. */
int collide_multi(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *out,
                  uint32_t *base, int max);
/* The compound children a contact number `sub` of the pair belongs to (-1: not a compound). */
void compound_sub_children(const shape *a, const shape *b, uint32_t sub, int *child_a, int *child_b);

#endif
