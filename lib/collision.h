/* collision.h - the collision stage (collision.c): broadphase pairs into the
 * contact cache, then the narrowphase over every live contact. */
#ifndef CAROM_COLLISION_H
#define CAROM_COLLISION_H

#include "step.h"

/* The order of two bodies (slots a, b) that does not depend on their ids
 * (collision.c, docs/physics.md "Creation order"): negative when a ranks
 * first. A new pair's body A is the one ranked first, and the new pairs are
 * added in rank order. */
int world_rank_cmp(const body_store *s, int a, int b);
/* Sorts n distinct slots by world_rank_cmp (tmp: room for n). */
void world_rank_sort(const body_store *s, int *slots, int *tmp, int n);

/* Updates the awake bodies' proxies and adds the new broadphase pairs; 0 on out of memory. */
int world_update_pairs(carom_world *w, const step_context *ctx);
/* Refreshes every live contact's manifold, lists the touching ones, raises
 * begin/end events; 0 on out of memory. */
int world_collide(carom_world *w, const step_context *ctx);

/* An island fell asleep this step (island.c): world_settle_body for each of
 * its bodies (the pose its pairs are held at, its bounds refitted about it),
 * then world_settle_contacts once, which rewrites every contact this step
 * tested whose bodies are all asleep or static so that what it keeps follows
 * from the bodies' state (docs/snapshot.md: a snapshot then need not carry
 * poses of older steps). The first test after waking runs the narrowphase. */
void world_settle_body(carom_world *w, int slot);
void world_settle_contacts(carom_world *w);

#endif
