/* body.c - the struct-of-arrays body store and its id table. */
#include <stdlib.h>
#include <string.h>
#include "body.h"
#include "pages.h"

/* Every dense array, so growth and swap-removal treat them uniformly. */
#define BODY_FIELDS(X) \
    X(id_index) X(type) X(flags) X(center) X(rotation) X(velocity) X(angular_velocity) X(force) \
    X(local_center) X(mass) X(inv_mass) X(inertia_local) X(inv_inertia_local) X(inv_inertia_world) \
    X(friction) X(restitution) X(linear_damping) X(angular_damping) X(gravity_scale) \
    X(plane_normal) X(plane_offset) X(sleep_time) X(shapes) X(proxy) X(fat_box) X(user_data) \
    X(solver_index) X(category) X(filter_mask) X(group) \
    X(previous_origin) X(previous_rotation) X(torque) X(rolling_resistance) X(combine) X(force_threshold) X(collided)

static int grow_field(void **p, size_t elem, int new_cap)
{
    void *n = realloc(*p, elem * (size_t)new_cap);
    if (!n) return 0;
    pages_hint_huge(n, elem * (size_t)new_cap);
    *p = n;
    return 1;
}

static int body_store_grow(body_store *s, int new_cap)
{
    int ok = 1;
#define GROW(f) if (ok && !grow_field((void **)&s->f, sizeof *s->f, new_cap)) ok = 0;
    BODY_FIELDS(GROW)
#undef GROW
    /* Arrays that did grow keep their new size; capacity only counts when all did. */
    if (ok) s->capacity = new_cap;
    return ok;
}

int body_store_init(body_store *s, int capacity)
{
    memset(s, 0, sizeof *s);
    s->free_id = -1;
    return body_store_grow(s, capacity > 16 ? capacity : 16);
}

void body_store_free(body_store *s)
{
#define FREE(f) free(s->f);
    BODY_FIELDS(FREE)
#undef FREE
    free(s->ids);
    memset(s, 0, sizeof *s);
}

int body_store_reserve(body_store *s)
{
    /* an eighth more, not twice: the store is 37 arrays (about 830 B a
     * body), and a doubled array's unused part is resident wherever the heap
     * hands out pages it used before (at 49,996 bodies doubling reserved
     * 65,536); bodies are added one call at a time, so this stays amortised */
    if (s->count >= s->capacity && !body_store_grow(s, s->capacity + s->capacity / 8 + 16)) return 0;
    if (s->free_id < 0 && s->id_count >= s->id_capacity) {
        int cap = s->id_capacity ? s->id_capacity * 2 : 16;
        body_id_entry *n = realloc(s->ids, sizeof *n * (size_t)cap);
        if (!n) return 0;
        s->ids = n;
        s->id_capacity = cap;
    }
    return 1;
}

int body_store_add(body_store *s, int *id_index_out)
{
    int id;
    if (s->free_id >= 0) {
        id = s->free_id;
        s->free_id = s->ids[id].next_free;
    } else {
        id = s->id_count++;
        s->ids[id].generation = 1;
    }
    int slot = s->count++;
    s->ids[id].slot = slot;
    s->ids[id].next_free = -1;
    s->id_index[slot] = id;
    *id_index_out = id;
    return slot;
}

int body_store_remove(body_store *s, int slot)
{
    int id = s->id_index[slot];
    int last = s->count - 1;
    s->ids[id].slot = -1;
    s->ids[id].generation++;
    s->ids[id].next_free = s->free_id;
    s->free_id = id;
    s->count--;
    if (slot == last) return -1;
#define MOVE(f) s->f[slot] = s->f[last];
    BODY_FIELDS(MOVE)
#undef MOVE
    s->ids[s->id_index[slot]].slot = slot;
    return slot;
}

int body_store_slot(const body_store *s, uint32_t index1, uint32_t generation)
{
    if (index1 == 0 || index1 > (uint32_t)s->id_count) return -1;
    const body_id_entry *e = &s->ids[index1 - 1];
    if (e->slot < 0 || e->generation != generation) return -1;
    return e->slot;
}

vec3 body_origin(const body_store *s, int slot)
{
    vec3 lc = s->local_center[slot];
    /* most shapes are centred on their origin: skip the rotation */
    if (lc.x == 0.0 && lc.y == 0.0 && lc.z == 0.0) return s->center[slot];
    return v3_sub(s->center[slot], q_rotate(s->rotation[slot], lc));
}

xform body_xform(const body_store *s, int slot)
{
    xform t = {body_origin(s, slot), s->rotation[slot]};
    return t;
}

void body_update_inertia(body_store *s, int slot)
{
    if (s->flags[slot] & BODY_LOCK_ROTATION) {
        s->inv_inertia_world[slot] = m3_zero();
        return;
    }
    mat3 r = m3_from_quat(s->rotation[slot]);
    if ((s->flags[slot] & BODY_LOCK_PLANE) && s->inv_mass[slot] > 0.0) {
        /* the body turns about the plane normal n only: the reduced system's
         * response to a torque t is n (n.t) / (n.I n) (not the free I^-1 t
         * projected onto n) */
        vec3 n = s->plane_normal[slot];
        vec3 nl = m3_tmulv(r, n); /* n in body axes */
        double inn = v3_dot(nl, m3_mulv(s->inertia_local[slot], nl));
        double k = inn > 0.0 ? 1.0 / inn : 0.0;
        s->inv_inertia_world[slot] = m3_cols(v3_scale(n, k * n.x), v3_scale(n, k * n.y), v3_scale(n, k * n.z));
        return;
    }
    s->inv_inertia_world[slot] = m3_rotate_tensor(r, s->inv_inertia_local[slot]);
}
