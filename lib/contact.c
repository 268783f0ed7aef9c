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

static int map_init(pair_map *m, int capacity)
{
    m->keys = calloc((size_t)capacity, sizeof *m->keys);
    m->subs = calloc((size_t)capacity, sizeof *m->subs);
    m->values = malloc((size_t)capacity * sizeof *m->values);
    m->capacity = capacity;
    m->count = 0;
    return m->keys && m->subs && m->values;
}

static int map_slot(const pair_map *m, uint64_t key, uint32_t sub)
{
    uint32_t mask = (uint32_t)m->capacity - 1;
    uint32_t i = hash_key(key, sub) & mask;
    while (m->keys[i] != 0 && (m->keys[i] != key || m->subs[i] != sub)) i = (i + 1) & mask;
    return (int)i;
}

static void map_put(pair_map *m, uint64_t key, uint32_t sub, int value)
{
    int i = map_slot(m, key, sub);
    if (m->keys[i] == 0) m->count++;
    m->keys[i] = key;
    m->subs[i] = sub;
    m->values[i] = value;
}

static int map_grow(pair_map *m)
{
    pair_map n;
    if (!map_init(&n, m->capacity * 2)) {
        free(n.keys);
        free(n.subs);
        free(n.values);
        return 0;
    }
    for (int i = 0; i < m->capacity; i++)
        if (m->keys[i]) map_put(&n, m->keys[i], m->subs[i], m->values[i]);
    free(m->keys);
    free(m->subs);
    free(m->values);
    *m = n;
    return 1;
}

/* Backward-shift deletion keeps probe chains intact without tombstones. */
static void map_remove(pair_map *m, uint64_t key, uint32_t sub)
{
    uint32_t mask = (uint32_t)m->capacity - 1;
    uint32_t i = (uint32_t)map_slot(m, key, sub);
    if (m->keys[i] == 0) return;
    m->keys[i] = 0;
    m->count--;
    uint32_t j = i;
    for (;;) {
        j = (j + 1) & mask;
        if (m->keys[j] == 0) return;
        uint32_t home = hash_key(m->keys[j], m->subs[j]) & mask;
        /* move j back to i unless its home lies cyclically in (i, j] */
        int keep = (i <= j) ? (i < home && home <= j) : (i < home || home <= j);
        if (!keep) {
            m->keys[i] = m->keys[j];
            m->subs[i] = m->subs[j];
            m->values[i] = m->values[j];
            m->keys[j] = 0;
            i = j;
        }
    }
}

int contact_set_init(contact_set *cs)
{
    memset(cs, 0, sizeof *cs);
    if (!array_reserve((void **)&cs->data, &cs->data_capacity, 1, sizeof *cs->data)) return 0;
    memset(&cs->data[0], 0, sizeof cs->data[0]);
    cs->data_count = 1;
    return map_init(&cs->map, 64);
}

int contact_data_alloc(contact_set *cs, int i)
{
    if (cs->items[i].slot) return 1;
    int slot;
    if (cs->free_count > 0) {
        slot = cs->data_free[--cs->free_count];
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
    /* room for every slot was reserved when the slot was made (below): cannot fail */
    cs->data_free[cs->free_count++] = slot;
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
    free(cs->data_free);
    free(cs->map.keys);
    free(cs->map.subs);
    free(cs->map.values);
    memset(cs, 0, sizeof *cs);
}

int contact_find_sub(const contact_set *cs, int a, int b, uint32_t sub)
{
    uint64_t key = pair_key(a, b);
    int i = map_slot(&cs->map, key, sub);
    return cs->map.keys[i] == key ? cs->map.values[i] : -1;
}

int contact_find(const contact_set *cs, int a, int b) { return contact_find_sub(cs, a, b, 0); }

int contact_add(contact_set *cs, int a, int b) { return contact_add_sub(cs, a, b, 0); }

int contact_set_reserve(contact_set *cs, int n)
{
    /* (data slots for all, at most: pages never written cost nothing; contact_set_trim) */
    return array_reserve((void **)&cs->items, &cs->capacity, n, sizeof *cs->items) &&
           array_reserve((void **)&cs->data, &cs->data_capacity, n + 1, sizeof *cs->data);
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
    if (!array_reserve((void **)&cs->data_free, &cs->free_capacity, cs->count + 1, sizeof *cs->data_free)) return -1;
    int i = cs->count++;
    contact *c = &cs->items[i];
    memset(c, 0, sizeof *c);
    c->id_a = a < b ? a : b;
    c->id_b = a < b ? b : a;
    c->cache.feature = -1;
    c->sub = sub;
    return i;
}

int contact_set_index(contact_set *cs, int *repeated)
{
    int n = cs->count;
    *repeated = -1;
    int capacity = 64;
    while ((n + 1) * 2 > capacity) capacity *= 2;
    uint32_t mask = (uint32_t)capacity - 1;
    pair_map m;
    int ok = map_init(&m, capacity);
    int *start = calloc((size_t)capacity + 1, sizeof *start);
    int *order = malloc(sizeof *order * (size_t)(n > 0 ? n : 1));
    uint32_t *home = malloc(sizeof *home * (size_t)(n > 0 ? n : 1));
    if (!ok || !start || !order || !home) {
        free(m.keys);
        free(m.subs);
        free(m.values);
        free(start);
        free(order);
        free(home);
        return 0;
    }
    /* the contacts by home slot (counting sort, stable) */
    for (int i = 0; i < n; i++) {
        home[i] = hash_key(pair_key(cs->items[i].id_a, cs->items[i].id_b), cs->items[i].sub) & mask;
        start[home[i] + 1]++;
    }
    for (int k = 0; k < capacity; k++) start[k + 1] += start[k];
    for (int i = 0; i < n; i++) order[start[home[i]]++] = i;
    for (int k = 0; k < n; k++) {
        int i = order[k];
        uint64_t key = pair_key(cs->items[i].id_a, cs->items[i].id_b);
        int slot = map_slot(&m, key, cs->items[i].sub);
        if (m.keys[slot] == key) { /* the later of the two repeats the earlier */
            int later = i > m.values[slot] ? i : m.values[slot];
            if (*repeated < 0 || later < *repeated) *repeated = later;
            continue;
        }
        m.keys[slot] = key;
        m.subs[slot] = cs->items[i].sub;
        m.values[slot] = i;
        m.count++;
    }
    free(start);
    free(order);
    free(home);
    free(cs->map.keys);
    free(cs->map.subs);
    free(cs->map.values);
    cs->map = m;
    return 1;
}

int contact_add_sub(contact_set *cs, int a, int b, uint32_t sub)
{
    if ((cs->map.count + 1) * 2 > cs->map.capacity && !map_grow(&cs->map)) return -1;
    int i = contact_append(cs, a, b, sub);
    if (i >= 0) map_put(&cs->map, pair_key(a, b), sub, i);
    return i;
}

void contact_remove(contact_set *cs, int i)
{
    contact *c = &cs->items[i];
    map_remove(&cs->map, pair_key(c->id_a, c->id_b), c->sub);
    contact_data_release(cs, i);
    int last = cs->count - 1;
    if (i != last) {
        cs->items[i] = cs->items[last]; /* (its data stays in its slot) */
        map_put(&cs->map, pair_key(cs->items[i].id_a, cs->items[i].id_b), cs->items[i].sub, i);
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
