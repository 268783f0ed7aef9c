/* sensor.c - contact control around the solve: sensors (bodies that touch
 * nothing and report what overlaps them), the pre-solve callback that can
 * leave a touching pair out of a step, and reading a body's contacts.
 *
 * Sensors keep their own overlap set, separate from the contact cache: at
 * the end of each step every sensor finds the bodies whose shapes overlap
 * its own (exactly, through query.c), and the difference from the last
 * step's set becomes SENSOR_BEGIN / SENSOR_END events. So sleeping and
 * static bodies are seen too, a destroyed body ends its overlap at the
 * next step, and a body that crosses a sensor within one step is not seen
 * (the overlap is sampled at step ends). */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "compound.h"
#include "events.h"
#include "filter.h"
#include "query.h"
#include "sensor.h"
#include "world.h"

static carom_vec3 from_v3(vec3 v) { carom_vec3 r = {v.x, v.y, v.z}; return r; }

CAROM_API int carom_body_is_sensor(const carom_world *w, carom_body_id id)
{
    if (!w) return 0;
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    return slot >= 0 && (w->bodies.flags[slot] & BODY_SENSOR) != 0;
}

/* ---- pre-solve ------------------------------------------------------------------ */

CAROM_API carom_status carom_world_set_pre_solve(carom_world *w, carom_pre_solve_fn *fn, void *context)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "world_set_pre_solve: the world is locked (inside step or a callback)");
    w->pre_solve = fn;
    w->pre_solve_context = context;
    return CAROM_OK;
}

static carom_manifold public_manifold(const manifold *m)
{
    carom_manifold out;
    memset(&out, 0, sizeof out);
    out.normal = from_v3(m->normal);
    out.point_count = m->count;
    for (int i = 0; i < m->count && i < 4; i++) {
        out.points[i] = from_v3(m->points[i].point);
        out.separations[i] = m->points[i].separation;
    }
    return out;
}

void world_pre_solve(carom_world *w, const step_context *ctx)
{
    (void)ctx;
    if (!w->pre_solve) return;
    step_scratch *sc = &w->scratch;
    contact_set *cs = &w->contacts;
    int kept = 0;
    for (int k = 0; k < sc->touching_count; k++) {
        int i = sc->touching[k];
        contact *c = &cs->items[i];
        contact_data *d = CONTACT_DATA(cs, i);
        carom_manifold m = public_manifold(&d->m);
        if (w->pre_solve(w->pre_solve_context, world_make_id(w, c->id_a), world_make_id(w, c->id_b), &m)) {
            sc->touching[kept++] = i;
            continue;
        }
        /* left out: nothing to warm-start from when it comes back */
        for (int p = 0; p < MANIFOLD_MAX_POINTS; p++) {
            d->state[p].normal_impulse = 0;
            d->state[p].tangent_impulse[0] = d->state[p].tangent_impulse[1] = 0;
        }
    }
    sc->touching_count = kept;
}

/* ---- sensors -------------------------------------------------------------------- */

static int compare_overlaps(const void *pa, const void *pb)
{
    const sensor_overlap *a = pa, *b = pb;
    uint64_t sa = carom_body_id_pack(a->sensor), sb = carom_body_id_pack(b->sensor);
    if (sa != sb) return sa < sb ? -1 : 1;
    uint64_t oa = carom_body_id_pack(a->other), ob = carom_body_id_pack(b->other);
    return (oa > ob) - (oa < ob);
}

typedef struct sensor_scan {
    carom_world *w;
    int sensor;               /* slot */
    xform pose;
    sensor_overlap *found;
    int count, capacity;
    int failed;
} sensor_scan;

static int scan_candidate(void *ctx, int id_index)
{
    sensor_scan *q = ctx;
    const body_store *s = &q->w->bodies;
    int other = s->ids[id_index].slot;
    if (other < 0 || other == q->sensor || (s->flags[other] & BODY_SENSOR)) return 1;
    if (s->type[q->sensor] == CAROM_BODY_STATIC && s->type[other] == CAROM_BODY_STATIC) return 1;
    if (!filter_bits_allow(s, q->sensor, other)) return 1;
    if (!query_shapes_overlap(&s->shapes[q->sensor], q->pose, &s->shapes[other], body_xform(s, other))) return 1;
    if (!array_reserve((void **)&q->found, &q->capacity, q->count + 1, sizeof *q->found)) {
        q->failed = 1;
        return 0;
    }
    q->found[q->count].sensor = world_make_id(q->w, s->id_index[q->sensor]);
    q->found[q->count].other = world_make_id(q->w, id_index);
    q->count++;
    return 1;
}

static void push_sensor_event(carom_world *w, carom_event_type type, const sensor_overlap *o)
{
    carom_vec3 point = {0, 0, 0};
    int slot = body_store_slot(&w->bodies, o->other.index1, o->other.generation);
    if (slot >= 0) point = from_v3(w->bodies.center[slot]);
    events_sensor(w, type, o->sensor, o->other, point);
}

int world_update_sensors(carom_world *w, const step_context *ctx)
{
    (void)ctx;
    body_store *s = &w->bodies;
    sensor_scan q;
    memset(&q, 0, sizeof q);
    q.w = w;
    for (int i = 0; i < s->count; i++) {
        if (!(s->flags[i] & BODY_SENSOR)) continue;
        q.sensor = i;
        q.pose = body_xform(s, i);
        bp_query(w->bp, shape_aabb(&s->shapes[i], q.pose), scan_candidate, &q);
        if (q.failed) break;
    }
    if (q.failed) { free(q.found); return 0; }
    if (q.count == 0 && w->sensor_overlap_count == 0) { free(q.found); return 1; }
    if (q.count > 1) qsort(q.found, (size_t)q.count, sizeof *q.found, compare_overlaps);
    /* merge the sorted old and new sets: only in new = begin, only in old = end
     * (unless the sensor itself is gone) */
    const sensor_overlap *old = w->sensor_overlaps;
    int i = 0, j = 0, n_old = w->sensor_overlap_count;
    while (i < n_old || j < q.count) {
        int c = i >= n_old ? 1 : j >= q.count ? -1 : compare_overlaps(&old[i], &q.found[j]);
        if (c == 0) { i++; j++; continue; }
        if (c < 0) {
            if (body_store_slot(&w->bodies, old[i].sensor.index1, old[i].sensor.generation) >= 0)
                push_sensor_event(w, CAROM_EVENT_SENSOR_END, &old[i]);
            i++;
        } else {
            push_sensor_event(w, CAROM_EVENT_SENSOR_BEGIN, &q.found[j]);
            j++;
        }
    }
    free(w->sensor_overlaps);
    w->sensor_overlaps = q.found;
    w->sensor_overlap_count = q.count;
    w->sensor_overlap_capacity = q.capacity;
    return 1;
}

/* ---- reading contacts ------------------------------------------------------------- */

/* The id index of a body whose contacts are asked for with an output of
 * capacity entries (has_output: the array is not NULL), or -1 (the error set). */
static int contacts_of(const carom_world *w, carom_body_id id, const char *fn, int capacity, int has_output)
{
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    if (slot < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "%s: body has been destroyed (or the id is invalid)", fn), -1;
    if (capacity < 0 || (capacity > 0 && !has_output))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: bad output array", fn), -1;
    return (int)id.index1 - 1;
}

/* Whether contact c is one of body me's touching ones (the order both
 * carom_body_get_contacts and carom_body_get_contact_children list). */
static int touching_contact_of(const contact *c, int me)
{
    return (c->id_a == me || c->id_b == me) && (c->flags & CONTACT_TOUCHING);
}

static int deepest_point(const manifold *m)
{
    int deepest = 0;
    for (int p = 1; p < m->count; p++)
        if (m->points[p].separation < m->points[deepest].separation) deepest = p;
    return deepest;
}

/* The part of the body at slot a contact names: its compound child by the
 * sub, or the triangle of a mesh or height field nearest the manifold's
 * deepest point (the point carom_body_get_contacts reports; midway between
 * the surfaces, so within half its separation of the triangle). */
static int contact_part(const body_store *s, int slot, int child, const manifold *m)
{
    if (child >= 0 || m->count == 0) return child;
    const manifold_point *p = &m->points[deepest_point(m)];
    return query_triangle_near(&s->shapes[slot], body_xform(s, slot), p->point, fabs(p->separation) + 0.01);
}

CAROM_API int carom_body_get_contacts(const carom_world *w, carom_body_id id, carom_contact_info *out, int capacity)
{
    if (!w) return -1;
    int me = contacts_of(w, id, "body_get_contacts", capacity, out != NULL);
    if (me < 0) return -1;
    const contact_set *cs = &w->contacts;
    int count = 0;
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        if (!touching_contact_of(c, me)) continue;
        const contact_data *d = CONTACT_DATA(cs, i);
        if (count < capacity) {
            carom_contact_info *ci = &out[count];
            int flip = c->id_b == me;
            ci->other = world_make_id(w, flip ? c->id_a : c->id_b);
            ci->normal = from_v3(flip ? v3_neg(d->m.normal) : d->m.normal);
            ci->point_count = d->m.count;
            int deepest = deepest_point(&d->m);
            double impulse = 0;
            for (int p = 0; p < d->m.count; p++) impulse += d->state[p].normal_impulse;
            ci->point = from_v3(d->m.points[deepest].point);
            ci->separation = d->m.points[deepest].separation;
            /* the state keeps the sub-step impulse (warm start): times the
             * sub-steps is the step's */
            ci->normal_impulse = impulse * w->def.substeps;
        }
        count++;
    }
    return count;
}

CAROM_API int carom_body_get_contact_children(const carom_world *w, carom_body_id id, int *children_self,
                                              int *children_other, int capacity)
{
    if (!w) return -1;
    int me = contacts_of(w, id, "body_get_contact_children", capacity, children_self || children_other);
    if (me < 0) return -1;
    const contact_set *cs = &w->contacts;
    const body_store *s = &w->bodies;
    int count = 0;
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        if (!touching_contact_of(c, me)) continue;
        if (count < capacity) {
            /* the contact's sub names the child pair, as for its events */
            int ca = -1, cb = -1;
            int sa = s->ids[c->id_a].slot, sb = s->ids[c->id_b].slot;
            if (sa >= 0 && sb >= 0) {
                const manifold *m = &CONTACT_DATA(cs, i)->m;
                compound_sub_children(&s->shapes[sa], &s->shapes[sb], c->sub, &ca, &cb);
                ca = contact_part(s, sa, ca, m);
                cb = contact_part(s, sb, cb, m);
            }
            int flip = c->id_b == me;
            if (children_self) children_self[count] = flip ? cb : ca;
            if (children_other) children_other[count] = flip ? ca : cb;
        }
        count++;
    }
    return count;
}
