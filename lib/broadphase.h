/* broadphase.h - dynamic AABB trees over fattened bounds; static and moving
 * proxies in separate trees so static geometry costs nothing per step. */
#ifndef CAROM_BROADPHASE_H
#define CAROM_BROADPHASE_H

#include "vecmath.h"

typedef struct broadphase broadphase;

/* Called for each overlapping pair found; user values as given at creation. */
typedef void bp_pair_fn(void *ctx, int user_a, int user_b);
/* Return 0 to stop the query. */
typedef int bp_query_fn(void *ctx, int user);
/* Return the new max fraction (clip), or < 0 to stop; max_t to continue unchanged. */
typedef double bp_ray_fn(void *ctx, int user, vec3 origin, vec3 dir, double max_t);

broadphase *bp_create(void);
void bp_destroy(broadphase *bp);
/* Returns the proxy id (>= 0) or -1 when out of memory. The box is stored as given
 * (the caller fattens it). A new proxy counts as moved. */
int bp_create_proxy(broadphase *bp, aabb box, int is_static, int user);
void bp_destroy_proxy(broadphase *bp, int proxy);
/* Creates n proxies at once in a broadphase that has none (a snapshot's
 * restore), each tree built bottom up in Z (Morton) order of the boxes'
 * centres instead of one insertion at a time; proxy[i] gets box[i]'s id. Every new proxy counts as
 * moved. Returns 0 when out of memory, changing nothing. */
int bp_create_proxies(broadphase *bp, const aabb *box, const int *is_static, const int *user, int n, int *proxy);
/* Removes every proxy at once, keeping the memory (a restore into an
 * existing world reads the next state into it). */
void bp_clear(broadphase *bp);
/* Replaces the proxy's box and marks it moved. */
void bp_move_proxy(broadphase *bp, int proxy, aabb box);
aabb bp_get_aabb(const broadphase *bp, int proxy);
int bp_get_user(const broadphase *bp, int proxy);
/* Reports every pair of overlapping boxes where at least one was moved (or
 * created) since the last call, then clears the moved set. Static-static
 * pairs are never reported. A pair is reported at most once per call. */
void bp_update_pairs(broadphase *bp, bp_pair_fn *fn, void *ctx);
void bp_query(const broadphase *bp, aabb box, bp_query_fn *fn, void *ctx);
void bp_ray_cast(const broadphase *bp, vec3 origin, vec3 dir, double max_t, bp_ray_fn *fn, void *ctx);
int bp_proxy_count(const broadphase *bp);
/* Whether the proxy is in the moved set (pairs pending for the next
 * bp_update_pairs), and setting it: snapshots carry the set across. */
int bp_is_moved(const broadphase *bp, int proxy);
void bp_set_moved(broadphase *bp, int proxy, int moved);

/* Height of the static or moving tree (-1 when empty; a single proxy is 0). */
int bp_tree_height(const broadphase *bp, int is_static);
/* Summed surface area of the tree's inner nodes (the surface-area cost a
 * query pays, up to a constant); for tests comparing builds. */
double bp_tree_area(const broadphase *bp, int is_static);
/* 1 when every internal invariant holds (links, boxes, heights, counts, moved
 * buffer); for tests. */
int bp_validate(const broadphase *bp);

#endif
