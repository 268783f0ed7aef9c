/* events.c - builds the step's contact events into the world's buffer, each
 * with the compound children its contact names. */
#include <string.h>
#include "array.h"
#include "world.h"
#include "events.h"
#include "compound.h"

static int push_event(carom_world *w, const carom_contact_event *e, int contact_index)
{
    event_buffer *b = &w->events;
    /* grown to within an eighth, not doubled: a world's first step may raise
     * a begin event for every contact (131,805 at 50,000 bodies, 14 MB kept
     * until the next step), and a doubled buffer's unused half is resident
     * wherever the allocator hands out pages it used before */
    if (!array_reserve_near((void **)&b->items, &b->capacity, b->count + 1, sizeof *b->items)) return 0;
    int child[2] = {-1, -1};
    if (contact_index >= 0) { /* from a contact (not a sensor) */
        const contact *c = &w->contacts.items[contact_index];
        int sa = w->bodies.ids[c->id_a].slot, sb = w->bodies.ids[c->id_b].slot;
        if (sa >= 0 && sb >= 0)
            compound_sub_children(&w->bodies.shapes[sa], &w->bodies.shapes[sb], c->sub, &child[0], &child[1]);
    }
    /* the children are written only up to the last event that names one */
    if (child[0] >= 0 || child[1] >= 0) {
        if (!array_reserve_near((void **)&b->children, &b->children_capacity, b->count + 1, sizeof *b->children))
            return 0;
        for (int i = b->children_count; i < b->count; i++) b->children[i][0] = b->children[i][1] = -1;
        b->children[b->count][0] = child[0];
        b->children[b->count][1] = child[1];
        b->children_count = b->count + 1;
    }
    b->items[b->count++] = *e;
    return 1;
}

static void event_pair(carom_world *w, const contact *c, carom_contact_event *e, carom_event_type type)
{
    memset(e, 0, sizeof *e);
    e->type = type;
    e->a = world_make_id(w, c->id_a);
    e->b = world_make_id(w, c->id_b);
}

int events_touch(carom_world *w, int contact_index, carom_event_type type)
{
    const contact *c = &w->contacts.items[contact_index];
    const contact_data *d = CONTACT_DATA(&w->contacts, contact_index);
    carom_contact_event e;
    event_pair(w, c, &e, type);
    e.normal.x = d->m.normal.x; e.normal.y = d->m.normal.y; e.normal.z = d->m.normal.z;
    if (d->m.count > 0) {
        vec3 p = d->m.points[0].point;
        e.point.x = p.x; e.point.y = p.y; e.point.z = p.z;
    }
    return push_event(w, &e, contact_index);
}

int events_hit(carom_world *w, int contact_index, int point, double normal_impulse, double tangent_impulse,
               double approach_speed, double dt)
{
    const contact *c = &w->contacts.items[contact_index];
    const contact_data *d = CONTACT_DATA(&w->contacts, contact_index);
    carom_contact_event e;
    event_pair(w, c, &e, CAROM_EVENT_HIT);
    vec3 pt = d->m.points[point].point;
    e.point.x = pt.x; e.point.y = pt.y; e.point.z = pt.z;
    e.normal.x = d->m.normal.x; e.normal.y = d->m.normal.y; e.normal.z = d->m.normal.z;
    e.normal_impulse = normal_impulse;
    e.tangent_impulse = tangent_impulse;
    e.approach_speed = approach_speed;
    e.average_force = impulse_average_force(normal_impulse, dt);
    return push_event(w, &e, contact_index);
}

int events_force(carom_world *w, int contact_index, double normal_impulse, double force, vec3 point)
{
    const contact *c = &w->contacts.items[contact_index];
    const contact_data *d = CONTACT_DATA(&w->contacts, contact_index);
    carom_contact_event e;
    event_pair(w, c, &e, CAROM_EVENT_FORCE);
    e.point.x = point.x; e.point.y = point.y; e.point.z = point.z;
    e.normal.x = d->m.normal.x; e.normal.y = d->m.normal.y; e.normal.z = d->m.normal.z;
    e.normal_impulse = normal_impulse;
    e.average_force = force;
    return push_event(w, &e, contact_index);
}

int events_sensor(carom_world *w, carom_event_type type, carom_body_id sensor, carom_body_id other, carom_vec3 point)
{
    carom_contact_event e;
    memset(&e, 0, sizeof e);
    e.type = type;
    e.a = sensor;
    e.b = other;
    e.point = point;
    return push_event(w, &e, -1);
}

/* The lower positive threshold of the two, or 0 when neither asks. */
static double pair_threshold(double a, double b)
{
    if (a > 0 && b > 0) return a < b ? a : b;
    return a > 0 ? a : b;
}

void events_raise_forces(carom_world *w, const contact_constraint *constraints, int count, double dt)
{
    const body_store *s = &w->bodies;
    /* Most worlds set no threshold: one sequential pass over the bodies is
     * cheaper than visiting every constraint's two bodies at random. */
    int any = 0;
    for (int i = 0; i < s->count && !any; i++) any = s->force_threshold[i] > 0;
    if (!any) return;
    for (int k = 0; k < count; k++) {
        const contact_constraint *con = &constraints[k];
        const contact *c = &w->contacts.items[con->contact];
        int sa = s->ids[c->id_a].slot, sb = s->ids[c->id_b].slot;
        double threshold = pair_threshold(s->force_threshold[sa], s->force_threshold[sb]);
        if (!(threshold > 0)) continue;
        double total = 0.0;
        vec3 weighted = v3_zero();
        for (int j = 0; j < con->count; j++) {
            double impulse = dmax(con->p[j].total_normal_impulse, 0.0);
            total += impulse;
            weighted = v3_madd(weighted, impulse, con->m->points[j].point);
        }
        double force = total / dt;
        if (!(force > threshold)) continue;
        /* a subnormal total (under a subnormal threshold) has no finite
         * reciprocal: the point of the largest impulse instead */
        double inv = 1.0 / total;
        vec3 point = v3_scale(weighted, inv);
        if (!isfinite(inv)) {
            int best = 0;
            for (int j = 1; j < con->count; j++)
                if (con->p[j].total_normal_impulse > con->p[best].total_normal_impulse) best = j;
            point = con->m->points[best].point;
        }
        events_force(w, con->contact, force * dt, force, point);
    }
}
