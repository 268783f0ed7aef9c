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

/* The motion of a body over the step the collision stage looks ahead for,
 * from its velocity at the start: the velocity gravity takes it to by the
 * end of the step (zero for a static or sleeping body), and how far its
 * rotation at the start velocity can move its surface in the step (the
 * angle times the farthest surface point from its centre of mass). */
typedef struct look_ahead {
    vec3 velocity;
    double turn;
} look_ahead;

/* A pair of bodies looks ahead for contacts this step by the speculative
 * distance, or by the distance their surfaces can close by the motion of
 * look_ahead (relative travel, plus both turns where one of them is static
 * or kinematic), capped at the speculative distance plus 4 AABB margins.
 * This is that look-ahead (m) of the body in slot `slot` against a static
 * body; valid after world_update_pairs, until the next step. */
double world_look_ahead_at_rest(const carom_world *w, const step_context *ctx, int slot);

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
