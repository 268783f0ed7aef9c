/* material.c - named surface materials: friction, restitution, rolling
 * resistance and how two of them combine. Bodies and compound children keep
 * copies; a contact mixes them once, when its pair (or its sub-manifold)
 * appears, and again when a body's material is set. */
#include <stdio.h>
#include <string.h>
#include "material.h"
#include "ranges.h"
#include "compound.h"

static carom_material read_material(const carom_material *src)
{
    carom_material m = carom_material_default();
    memcpy(&m, src, src->size < sizeof m ? src->size : sizeof m);
    m.size = (uint32_t)sizeof m;
    return m;
}

int material_valid(const carom_material *src, char *msg, size_t msg_size)
{
    char scratch[8];
    if (!msg) { msg = scratch; msg_size = sizeof scratch; }
    if (!src) return snprintf(msg, msg_size, "material is NULL"), 0;
    if (src->size < offsetof(carom_material, restitution) + sizeof(double))
        return snprintf(msg, msg_size, "material size %u too small: use carom_material_default()", (unsigned)src->size), 0;
    carom_material m = read_material(src);
    if (!(isfinite(m.friction) && m.friction >= 0 && m.friction <= RANGE_FRICTION_MAX))
        return snprintf(msg, msg_size, "material friction %g is outside [0, 1000]", m.friction), 0;
    if (!(isfinite(m.restitution) && m.restitution >= 0 && m.restitution <= 1))
        return snprintf(msg, msg_size, "material restitution %g is outside [0, 1]", m.restitution), 0;
    if (!(isfinite(m.rolling_resistance) && m.rolling_resistance >= 0 && m.rolling_resistance <= RANGE_FRICTION_MAX))
        return snprintf(msg, msg_size, "material rolling_resistance %g is outside [0, 1000]", m.rolling_resistance), 0;
    if ((int)m.combine < CAROM_COMBINE_DEFAULT || (int)m.combine > CAROM_COMBINE_MAX)
        return snprintf(msg, msg_size, "material combine %d is not a carom_combine_mode", (int)m.combine), 0;
    return 1;
}

void material_apply(const carom_material *src, double *friction, double *restitution, double *rolling_resistance,
                    int *combine)
{
    carom_material m = read_material(src);
    *friction = m.friction;
    *restitution = m.restitution;
    *rolling_resistance = m.rolling_resistance;
    *combine = (int)m.combine;
}

CAROM_API carom_status carom_material_check(const carom_material *m, char *msg, size_t msg_size)
{
    if (msg && msg_size) msg[0] = 0;
    return material_valid(m, msg, msg_size) ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT;
}

/* which: 0 friction, 1 restitution, 2 rolling resistance */
static double combine_values(int mode, int which, double a, double b)
{
    switch (mode) {
    case CAROM_COMBINE_AVERAGE: return 0.5 * (a + b);
    case CAROM_COMBINE_GEOMETRIC_MEAN: return sqrt(a * b);
    case CAROM_COMBINE_MIN: return dmin(a, b);
    case CAROM_COMBINE_MULTIPLY: return a * b;
    case CAROM_COMBINE_MAX: return dmax(a, b);
    default: return which == 0 ? sqrt(a * b) : dmax(a, b); /* DEFAULT: carom's mixing before materials */
    }
}

typedef struct surface {
    double friction, restitution, rolling_resistance;
    int combine;
} surface;

static surface body_surface(const body_store *s, int slot, int child)
{
    surface f = {s->friction[slot], s->restitution[slot], s->rolling_resistance[slot], s->combine[slot]};
    const shape *sh = &s->shapes[slot];
    if (child >= 0 && sh->type == SHAPE_COMPOUND) {
        const compound *c = sh->compound;
        f.friction = c->friction[child];
        f.restitution = c->restitution[child];
        f.rolling_resistance = c->rolling_resistance[child];
        f.combine = c->combine[child];
    }
    return f;
}

void material_mix(const body_store *s, int sa, int sb, uint32_t sub, double out[3])
{
    int ca = -1, cb = -1;
    compound_sub_children(&s->shapes[sa], &s->shapes[sb], sub, &ca, &cb);
    surface fa = body_surface(s, sa, ca), fb = body_surface(s, sb, cb);
    int mode = fa.combine > fb.combine ? fa.combine : fb.combine; /* the higher mode wins */
    out[0] = combine_values(mode, 0, fa.friction, fb.friction);
    out[1] = combine_values(mode, 1, fa.restitution, fb.restitution);
    out[2] = combine_values(mode, 2, fa.rolling_resistance, fb.rolling_resistance);
}

void material_mix_contact(carom_world *w, int contact_index)
{
    const body_store *s = &w->bodies;
    const contact *c = &w->contacts.items[contact_index];
    if (!c->slot) return; /* mixed when it takes a slot (collision.c) */
    contact_data *d = CONTACT_DATA(&w->contacts, contact_index);
    double m[3];
    material_mix(s, s->ids[c->id_a].slot, s->ids[c->id_b].slot, c->sub, m);
    d->friction = m[0];
    d->restitution = m[1];
    d->rolling_resistance = m[2];
}

CAROM_API carom_status carom_body_set_material(carom_world *w, carom_body_id id, const carom_material *material)
{
    const char *fn = "body_set_material";
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    body_store *s = &w->bodies;
    int slot = body_store_slot(s, id.index1, id.generation);
    if (slot < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "%s: body has been destroyed (or the id is invalid)", fn);
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "%s: the world is locked (inside step or a callback)", fn);
    char msg[160];
    if (!material_valid(material, msg, sizeof msg)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: %s", fn, msg);
    material_apply(material, &s->friction[slot], &s->restitution[slot], &s->rolling_resistance[slot], &s->combine[slot]);
    if (s->shapes[slot].type == SHAPE_COMPOUND) {
        compound *c = s->shapes[slot].compound;
        for (int i = 0; i < c->count; i++)
            material_apply(material, &c->friction[i], &c->restitution[i], &c->rolling_resistance[i], &c->combine[i]);
    }
    int id_index = (int)id.index1 - 1;
    for (int k = 0; k < w->contacts.count; k++) {
        const contact *ct = &w->contacts.items[k];
        if (ct->id_a == id_index || ct->id_b == id_index) material_mix_contact(w, k);
    }
    return CAROM_OK;
}

CAROM_API carom_status carom_body_get_material(const carom_world *w, carom_body_id id, carom_material *out)
{
    const char *fn = "body_get_material";
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    const body_store *s = &w->bodies;
    int slot = body_store_slot(s, id.index1, id.generation);
    if (slot < 0) return world_fail(w, CAROM_ERROR_STALE_ID, "%s: body has been destroyed (or the id is invalid)", fn);
    if (!out) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: output pointer is NULL", fn);
    if (out->size < offsetof(carom_material, restitution) + sizeof(double))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "%s: out->size %u too small: use carom_material_default()", fn,
                          (unsigned)out->size);
    carom_material m = carom_material_default();
    m.friction = s->friction[slot];
    m.restitution = s->restitution[slot];
    m.rolling_resistance = s->rolling_resistance[slot];
    m.combine = (carom_combine_mode)s->combine[slot];
    uint32_t size = out->size;
    memcpy(out, &m, size < sizeof m ? size : sizeof m);
    out->size = size;
    return CAROM_OK;
}
