/* collision.h - the collision stage (collision.c): broadphase pairs into the
 * contact cache, then the narrowphase over every live contact. */
#ifndef CAROM_COLLISION_H
#define CAROM_COLLISION_H

#include "step.h"

/* Updates the awake bodies' proxies and adds the new broadphase pairs; 0 on out of memory. */
int world_update_pairs(carom_world *w, const step_context *ctx);
/* Refreshes every live contact's manifold, lists the touching ones, raises
 * begin/end events; 0 on out of memory. */
int world_collide(carom_world *w, const step_context *ctx);

#endif
