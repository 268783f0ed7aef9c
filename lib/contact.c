/* contact.c - contact cache: pair hash map and warm-start point matching. */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "contact.h"

static uint64_t pair_key(int a, int b)
{
    if (a > b) { int t = a; a = b; b = t; }
    return ((uint64_t)(uint32_t)(a + 1) << 32) | (uint64_t)(uint32_t)(b + 1);
}

static uint32_t hash_key(uint64_t k, uint32_t sub)
{
    k ^= (uint64_t)sub * 0x9E3779B97F4A7C15ULL;
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    k *= 0xc4ceb9fe1a85ec53ULL;
    k ^= k >> 33;
    return (uint32_t)k;
}

static uint32_t contact_hash(const contact *c) { return hash_key(pair_key(c->id_a, c->id_b), c->sub); }

/* Whether a map of `capacity` slots is too full to hold `count` contacts:
 * past 3/4 (linear probing stays short there: a hit's chain averages 2.5
 * slots, a miss's 8.5; at 1/2 the 131,805 contacts of the 50,000-body grid
 * took 524,288 slots, 4 MB, instead of 262,144). */
static int map_full(int count, int capacity) { return (int64_t)count * 4 > (int64_t)capacity * 3; }

static int map_init(pair_map *m, int capacity)
{
    m->hashes = malloc((size_t)capacity * sizeof *m->hashes);
    m->values = malloc((size_t)capacity * sizeof *m->values);
    m->capacity = capacity;
    m->count = 0;
    if (!m->hashes || !m->values) return 0;
    memset(m->values, 0xff, (size_t)capacity * sizeof *m->values); /* every slot empty (-1) */
    return 1;
}

static void map_free(pair_map *m)
{
    free(m->hashes);
    free(m->values);
}

/* The slot holding the contact for (a, b, sub) of hash h (a < b; the
 * contact holds the pair in either order), or the empty slot that ends its
 * probe chain. */
static int map_slot(const contact_set *cs, uint32_t h, int a, int b, uint32_t sub)
{
    const pair_map *m = &cs->map;
    uint32_t mask = (uint32_t)m->capacity - 1;
    uint32_t i = h & mask;
    for (;;) {
        int v = m->values[i];
        if (v < 0) return (int)i;
        if (m->hashes[i] == h) {
            const contact *c = &cs->items[v];
            int lo = c->id_a < c->id_b ? c->id_a : c->id_b, hi = c->id_a < c->id_b ? c->id_b : c->id_a;
            if (lo == a && hi == b && c->sub == sub) return (int)i;
        }
        i = (i + 1) & mask;
    }
}

/* The first empty slot of h's probe chain (a key known not to be there). */
static int map_free_slot(const pair_map *m, uint32_t h)
{
    uint32_t mask = (uint32_t)m->capacity - 1;
    uint32_t i = h & mask;
    while (m->values[i] >= 0) i = (i + 1) & mask;
    return (int)i;
}

static void map_insert(pair_map *m, uint32_t h, int value)
{
    int i = map_free_slot(m, h);
    m->hashes[i] = h;
    m->values[i] = value;
    m->count++;
}

static int map_grow(pair_map *m)
{
    pair_map n;
    if (!map_init(&n, m->capacity * 2)) {
        map_free(&n);
        return 0;
    }
    for (int i = 0; i < m->capacity; i++)
        if (m->values[i] >= 0) map_insert(&n, m->hashes[i], m->values[i]);
    map_free(m);
    *m = n;
    return 1;
}

/* Empties slot i; backward-shift deletion keeps probe chains intact without
 * tombstones. */
static void map_erase(pair_map *m, uint32_t i)
{
    uint32_t mask = (uint32_t)m->capacity - 1;
    m->values[i] = -1;
    m->count--;
    uint32_t j = i;
    for (;;) {
        j = (j + 1) & mask;
        if (m->values[j] < 0) return;
        uint32_t home = m->hashes[j] & mask;
        /* move j back to i unless its home lies cyclically in (i, j] */
        int keep = (i <= j) ? (i < home && home <= j) : (i < home || home <= j);
        if (!keep) {
            m->hashes[i] = m->hashes[j];
            m->values[i] = m->values[j];
            m->values[j] = -1;
            i = j;
        }
    }
}

/* The slot whose value is contact index `value` (of hash h): it is in the map. */
static uint32_t map_slot_of(const pair_map *m, uint32_t h, int value)
{
    uint32_t mask = (uint32_t)m->capacity - 1;
    uint32_t i = h & mask;
    while (m->values[i] != value) i = (i + 1) & mask;
    return i;
}

int contact_set_init(contact_set *cs)
{
    memset(cs, 0, sizeof *cs);
    if (!array_reserve((void **)&cs->data, &cs->data_capacity, 1, sizeof *cs->data)) return 0;
    memset(&cs->data[0], 0, sizeof cs->data[0]);
    cs->data_count = 1;
    if (map_init(&cs->map, 64)) return 1;
    map_free(&cs->map);
    return 0;
}

int contact_data_alloc(contact_set *cs, int i)
{
    if (cs->items[i].slot) return 1;
    int slot;
    if (cs->free_head) {
        slot = cs->free_head;
        cs->free_head = contact_data_next_free(cs, slot);
        cs->free_count--;
    } else {
        if (!array_reserve((void **)&cs->data, &cs->data_capacity, cs->data_count + 1, sizeof *cs->data)) return 0;
        slot = cs->data_count++;
    }
    memset(&cs->data[slot], 0, sizeof cs->data[slot]);
    cs->items[i].slot = slot;
    return 1;
}

void contact_data_release(contact_set *cs, int i)
{
    int slot = cs->items[i].slot;
    if (!slot) return;
    cs->items[i].slot = 0;
    if (slot == cs->data_count - 1) { cs->data_count--; return; }
    /* the free list runs through the free slots themselves: no array of its
     * own (one int per contact ever made, 1 MB resident at 50,000 bodies) */
    memcpy(&cs->data[slot], &cs->free_head, sizeof cs->free_head);
    cs->free_head = slot;
    cs->free_count++;
}

int contact_data_next_free(const contact_set *cs, int slot)
{
    int next;
    memcpy(&next, &cs->data[slot], sizeof next);
    return next;
}

static int bits_zero(vec3 v)
{
    static const vec3 zero = {0, 0, 0};
    return memcmp(&v, &zero, sizeof v) == 0;
}

int contact_data_idle(const contact_set *cs, int i)
{
    const contact *c = &cs->items[i];
    const contact_data *d = &cs->data[c->slot];
    return !(c->flags & (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_ANY_TOUCHING | CONTACT_REUSABLE)) &&
           d->m.count == 0 && bits_zero(d->tangent1);
}

void contact_set_free(contact_set *cs)
{
    free(cs->items);
    free(cs->data);
    map_free(&cs->map);
    memset(cs, 0, sizeof *cs);
}

int contact_find_sub(const contact_set *cs, int a, int b, uint32_t sub)
{
    if (a > b) { int t = a; a = b; b = t; }
    return cs->map.values[map_slot(cs, hash_key(pair_key(a, b), sub), a, b, sub)];
}

int contact_find(const contact_set *cs, int a, int b) { return contact_find_sub(cs, a, b, 0); }

int contact_add(contact_set *cs, int a, int b) { return contact_add_sub(cs, a, b, 0); }

int contact_set_reserve(contact_set *cs, int n)
{
    /* (data slots for all, at most: pages never written cost nothing; contact_set_trim) */
    return array_reserve((void **)&cs->items, &cs->capacity, n, sizeof *cs->items) &&
           array_reserve((void **)&cs->data, &cs->data_capacity, n + 1, sizeof *cs->data);
}

void contact_set_clear(contact_set *cs)
{
    cs->count = 0;
    cs->data_count = 1; /* (data[0], the empty record, is never written) */
    cs->free_head = 0;
    cs->free_count = 0;
    cs->map.count = 0;
    if (cs->map.values) memset(cs->map.values, 0xff, (size_t)cs->map.capacity * sizeof *cs->map.values);
}

void contact_set_trim(contact_set *cs)
{
    if (cs->data_capacity <= cs->data_count) return;
    contact_data *d = realloc(cs->data, sizeof *cs->data * (size_t)cs->data_count);
    if (!d) return; /* keeps the larger block */
    cs->data = d;
    cs->data_capacity = cs->data_count;
}

int contact_append(contact_set *cs, int a, int b, uint32_t sub)
{
    if (!array_reserve((void **)&cs->items, &cs->capacity, cs->count + 1, sizeof *cs->items)) return -1;
    int i = cs->count++;
    contact *c = &cs->items[i];
    memset(c, 0, sizeof *c);
    c->id_a = a; /* in the caller's order: body A of the solve first (collision.c) */
    c->id_b = b;
    c->cache.feature = -1;
    c->sub = sub;
    return i;
}

/* A pair's hash and index, gathered in one sequential pass over the
 * contacts: placed in the order of their home slots, the contacts
 * themselves (128 bytes each) would be read at random, a cache miss each
 * (most of the map's build time in a 10,000-body restore). Only a slot of
 * the same hash sends the insert to the two contacts (same_pair): a repeated
 * pair, or one in 2^32 chance a slot. */
typedef struct pair_record {
    uint32_t hash;
    int index;
} pair_record;

/* Whether two contacts hold the same pair (in either order) and sub. */
static int same_pair(const contact *c, const contact *d)
{
    int clo = c->id_a < c->id_b ? c->id_a : c->id_b, chi = c->id_a < c->id_b ? c->id_b : c->id_a;
    int dlo = d->id_a < d->id_b ? d->id_a : d->id_b, dhi = d->id_a < d->id_b ? d->id_b : d->id_a;
    return clo == dlo && chi == dhi && c->sub == d->sub;
}

int contact_set_index(contact_set *cs, int *repeated)
{
    int n = cs->count;
    *repeated = -1;
    int capacity = 64, bits = 6;
    while (map_full(n + 1, capacity)) capacity *= 2, bits++;
    /* buckets by the top (at most 12) bits of the home slot: each bucket's
     * slots span a few cache lines, and start[] stays small */
    int bucket_bits = bits < 12 ? bits : 12, shift = bits - bucket_bits;
    uint32_t mask = (uint32_t)capacity - 1;
    /* the map's arrays are reused when they have the size (a restore into
     * an existing world: pages already written) */
    pair_map m;
    int reuse = cs->map.capacity == capacity && cs->map.hashes && cs->map.values;
    int ok = 1;
    if (reuse) { /* (emptied here, just before the inserts read it, even when
                    contact_set_clear emptied it: by now that was long out of cache) */
        m = cs->map;
        m.count = 0;
        memset(m.values, 0xff, (size_t)capacity * sizeof *m.values);
    } else {
        ok = map_init(&m, capacity);
    }
    int *start = calloc(((size_t)1 << bucket_bits) + 1, sizeof *start);
    pair_record *rec = malloc(sizeof *rec * 2 * (size_t)(n > 0 ? n : 1)), *sorted = rec ? rec + n : NULL;
    if (!ok || !start || !rec) {
        if (!reuse) map_free(&m);
        free(start);
        free(rec);
        return 0;
    }
    for (int i = 0; i < n; i++) {
        const contact *c = &cs->items[i];
        pair_record *p = &rec[i];
        p->hash = contact_hash(c);
        p->index = i;
        start[((p->hash & mask) >> shift) + 1]++;
    }
    for (int k = 0; k < (1 << bucket_bits); k++) start[k + 1] += start[k];
    for (int i = 0; i < n; i++) sorted[start[(rec[i].hash & mask) >> shift]++] = rec[i]; /* (stable) */
    pair_map old = cs->map;
    cs->map = m;
    for (int k = 0; k < n; k++) {
        const pair_record *p = &sorted[k];
        uint32_t slot = p->hash & mask;
        for (;;) { /* map_slot's walk, the contacts read only where a hash agrees */
            int v = cs->map.values[slot];
            if (v < 0 || (cs->map.hashes[slot] == p->hash && same_pair(&cs->items[v], &cs->items[p->index]))) break;
            slot = (slot + 1) & mask;
        }
        if (cs->map.values[slot] >= 0) { /* the later of the two repeats the earlier */
            int later = p->index > cs->map.values[slot] ? p->index : cs->map.values[slot];
            if (*repeated < 0 || later < *repeated) *repeated = later;
            continue;
        }
        cs->map.hashes[slot] = p->hash;
        cs->map.values[slot] = p->index;
        cs->map.count++;
    }
    free(start);
    free(rec);
    if (!reuse) map_free(&old);
    return 1;
}

/* (a new pair: the caller found none for it) */
int contact_add_sub(contact_set *cs, int a, int b, uint32_t sub)
{
    if (map_full(cs->map.count + 1, cs->map.capacity) && !map_grow(&cs->map)) return -1;
    int i = contact_append(cs, a, b, sub);
    if (i >= 0) map_insert(&cs->map, contact_hash(&cs->items[i]), i);
    return i;
}

void contact_remove(contact_set *cs, int i)
{
    contact *c = &cs->items[i];
    map_erase(&cs->map, map_slot_of(&cs->map, contact_hash(c), i));
    contact_data_release(cs, i);
    int last = cs->count - 1;
    if (i != last) {
        cs->items[i] = cs->items[last]; /* (its data stays in its slot) */
        cs->map.values[map_slot_of(&cs->map, contact_hash(&cs->items[i]), last)] = i;
    }
    cs->count--;
}

vec3 contact_rest_basis(vec3 n)
{
    if (n.x == 0 && n.y == 0 && n.z == 0) return n;
    vec3 t1, t2;
    v3_basis(n, &t1, &t2);
    return v3_normalize(t1);
}

void contact_match_points(contact_data *c, const manifold *old_m, const contact_point_state old[MANIFOLD_MAX_POINTS],
                          xform xa)
{
    /* Points keep their impulses when the same features touch again; a point
     * whose id changed but that sits within 1 cm of an old one in A's frame
     * is the same physical contact (ids change when a face clip reorders). */
    const double match_dist2 = 0.01 * 0.01;
    int used[MANIFOLD_MAX_POINTS] = {0, 0, 0, 0};
    for (int i = 0; i < c->m.count; i++) {
        contact_point_state *s = &c->state[i];
        vec3 local = xf_inv_point(xa, c->m.points[i].point);
        memset(s, 0, sizeof *s);
        s->local_a = local;
        int found = -1;
        for (int j = 0; j < old_m->count; j++)
            if (!used[j] && old_m->points[j].id == c->m.points[i].id) { found = j; break; }
        if (found < 0) {
            double best = match_dist2;
            for (int j = 0; j < old_m->count; j++) {
                double d2 = v3_len2(v3_sub(old[j].local_a, local));
                if (!used[j] && d2 < best) { best = d2; found = j; }
            }
        }
        if (found >= 0) {
            used[found] = 1;
            s->normal_impulse = old[found].normal_impulse;
            s->tangent_impulse[0] = old[found].tangent_impulse[0];
            s->tangent_impulse[1] = old[found].tangent_impulse[1];
        }
    }
}
