/* compound.h - compound shapes (compound.c): children at their own poses
 * and densities; their mass, bounds and ray casts, and the contacts of any
 * pair with a mesh, height field or compound on either side. */
#ifndef CAROM_COMPOUND_H
#define CAROM_COMPOUND_H

#include "shape.h"
#include "narrowphase.h"

void compound_free(compound *c);
/* Mass properties combined exactly (parallel axis); each child at its own density. */
mass_props compound_mass(const compound *c);
aabb compound_aabb(const compound *c, xform t);
int compound_ray_cast_local(const compound *c, vec3 o, vec3 d, double max_t, double *t, vec3 *normal, int *child);

/* Any pair with a mesh, height field or compound on either side: its
 * manifolds (normal a to b) and for each the base of its contact numbers
 * (a multiple of COMPOSITE_MAX_MANIFOLDS naming the child pair); returns how
 * many. */
int collide_multi(const shape *a, xform xa, const shape *b, xform xb, double speculative, manifold *out,
                  uint32_t *base, int max);
/* The compound children a contact number `sub` of the pair belongs to (-1: not a compound). */
void compound_sub_children(const shape *a, const shape *b, uint32_t sub, int *child_a, int *child_b);

#endif
