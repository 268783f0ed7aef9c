/* island.c - islands and sleeping. Each step, bodies joined by touching
 * contacts form islands (union-find); an island whose every body has rested
 * for sleep_time goes to sleep and costs nothing until touched or moved; an
 * island with any restless body is awake as a whole. */
#include <stdlib.h>
#include "world.h"
#include "island.h"
#include "collision.h"

static int find_root(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

void world_update_sleep(carom_world *w, const step_context *ctx)
{
    double dt = ctx->dt;
    body_store *s = &w->bodies;
    const carom_world_def *def = &w->def;
    step_scratch *sc = &w->scratch;
    int n = s->count;
    if (n == 0) { /* no bodies: the island arrays may not exist yet */
        w->stats.islands = 0;
        w->stats.awake_bodies = 0;
        return;
    }
    if (!def->enable_sleep) {
        for (int i = 0; i < n; i++)
            if (s->type[i] != CAROM_BODY_STATIC) { s->flags[i] |= BODY_AWAKE; s->sleep_time[i] = 0; }
        w->stats.islands = 0;
        return;
    }
    /* parent and "island minimum sleep time" share one scratch block, indexed by slot */
    if (sc->island_capacity < 2 * n) {
        int cap = 2 * n > 64 ? 2 * n : 64;
        int *p = realloc(sc->island_parent, sizeof *p * (size_t)cap);
        if (!p) return; /* out of memory: sleep state unchanged this step */
        sc->island_parent = p;
        sc->island_capacity = cap;
    }
    int *parent = sc->island_parent;
    int *restless = parent + n;   /* per root: 1 if any member is not ready to sleep */
    double lin2 = def->sleep_linear_velocity * def->sleep_linear_velocity;
    double ang2 = def->sleep_angular_velocity * def->sleep_angular_velocity;
    for (int i = 0; i < n; i++) {
        parent[i] = i;
        restless[i] = 0;
        if (s->type[i] == CAROM_BODY_STATIC) continue;
        if (s->flags[i] & BODY_AWAKE) {
            int resting = (s->flags[i] & BODY_ENABLE_SLEEP) && v3_len2(s->velocity[i]) < lin2 &&
                          v3_len2(s->angular_velocity[i]) < ang2;
            s->sleep_time[i] = resting ? s->sleep_time[i] + dt : 0.0;
        }
    }
    const contact_set *cs = &w->contacts;
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        if (!(c->flags & CONTACT_TOUCHING)) continue;
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        if (s->type[a] == CAROM_BODY_STATIC || s->type[b] == CAROM_BODY_STATIC) continue;
        /* a resting kinematic body does not chain islands together */
        if (s->type[a] == CAROM_BODY_KINEMATIC && s->sleep_time[a] > 0) continue;
        if (s->type[b] == CAROM_BODY_KINEMATIC && s->sleep_time[b] > 0) continue;
        int ra = find_root(parent, a), rb = find_root(parent, b);
        if (ra != rb) parent[ra] = rb;
    }
    for (int i = 0; i < n; i++) {
        if (s->type[i] == CAROM_BODY_STATIC) continue;
        if (s->sleep_time[i] < def->sleep_time) restless[find_root(parent, i)] = 1;
    }
    int islands = 0, awake = 0, slept = 0;
    for (int i = 0; i < n; i++) {
        if (s->type[i] == CAROM_BODY_STATIC) continue;
        int r = find_root(parent, i);
        if (r == i) islands++;
        if (restless[r]) {
            if (!(s->flags[i] & BODY_AWAKE)) s->sleep_time[i] = 0.0;
            s->flags[i] |= BODY_AWAKE;
            awake++;
        } else if (s->flags[i] & BODY_AWAKE) {
            s->flags[i] &= ~(uint32_t)BODY_AWAKE;
            s->velocity[i] = v3_zero();
            s->angular_velocity[i] = v3_zero();
            world_settle_body(w, i);
            slept++;
        }
    }
    /* the pairs of the islands that fell asleep keep only what their bodies reproduce */
    if (slept > 0) world_settle_contacts(w);
    w->stats.islands = islands;
    w->stats.awake_bodies = awake;
}
