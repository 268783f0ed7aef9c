/* snapshot.c - a world's complete state as bytes, and a world built back
 * from them (docs/snapshot.md has the format). Everything the step reads
 * from one step to the next is written: settings, the id table with its
 * generations and free list, every body field that is not derived from the
 * others, shapes (hulls whole), the contact cache with its manifolds and
 * warm-start impulses, sleep timers, the broadphase's pending (moved) set.
 * Derived state (inverse masses and inertias, the broadphase trees, the pair
 * map) is rebuilt by the same code that built it, so a restored world
 * continues bit for bit.
 *
 * The reader trusts nothing: every count is checked against the bytes left
 * before anything is allocated, every index against its table, every number
 * against the ranges the API enforces; the first failure names what was
 * wrong and nothing is built. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "ranges.h"
#include "narrowphase.h"

#define SNAP_MAGIC "CAROMSNP"
#define SNAP_VERSION 1u
#define SNAP_HEADER_SIZE 32u

/* ---- writer: little-endian whatever the host ----------------------------------- */

/* On a little-endian host the bytes are the value's own: one copy (the
 * portable byte loops below are the definition, and the big-endian path). */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define SNAP_HOST_LE 1
#else
#define SNAP_HOST_LE 0
#endif

typedef struct writer {
    unsigned char *buf;
    size_t cap, pos;
} writer;

static void put_bytes(writer *o, const void *p, size_t n)
{
    if (o->pos + n <= o->cap) memcpy(o->buf + o->pos, p, n);
    o->pos += n;
}

static void put_u64(writer *o, uint64_t v)
{
    if (o->pos + 8 <= o->cap) {
        unsigned char *b = o->buf + o->pos;
        if (SNAP_HOST_LE) memcpy(b, &v, 8);
        else for (int i = 0; i < 8; i++) b[i] = (unsigned char)(v >> (8 * i));
    }
    o->pos += 8;
}

static void put_u32(writer *o, uint32_t v)
{
    if (o->pos + 4 <= o->cap) {
        unsigned char *b = o->buf + o->pos;
        if (SNAP_HOST_LE) memcpy(b, &v, 4);
        else for (int i = 0; i < 4; i++) b[i] = (unsigned char)(v >> (8 * i));
    }
    o->pos += 4;
}

static void put_u8(writer *o, unsigned v)
{
    if (o->pos < o->cap) o->buf[o->pos] = (unsigned char)v;
    o->pos++;
}

static void put_i32(writer *o, int v) { put_u32(o, (uint32_t)v); }
static void put_f64(writer *o, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    put_u64(o, v);
}
static void put_v3(writer *o, vec3 v) { put_f64(o, v.x); put_f64(o, v.y); put_f64(o, v.z); }
static void put_q(writer *o, quat q) { put_f64(o, q.w); put_f64(o, q.x); put_f64(o, q.y); put_f64(o, q.z); }
static void put_m3(writer *o, mat3 m) { put_v3(o, m.c0); put_v3(o, m.c1); put_v3(o, m.c2); }

/* ---- reader: bounds-checked, the first error sticks ---------------------------- */

typedef struct reader {
    const unsigned char *buf;
    size_t size, pos;
    char *msg;
    size_t msg_size;
    int failed;
} reader;

static int bad(reader *r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#include <stdarg.h>
static int bad(reader *r, const char *fmt, ...)
{
    if (!r->failed && r->msg && r->msg_size) {
        va_list ap;
        va_start(ap, fmt);
        int n = snprintf(r->msg, r->msg_size, "snapshot: ");
        if (n >= 0 && (size_t)n < r->msg_size) vsnprintf(r->msg + n, r->msg_size - (size_t)n, fmt, ap);
        va_end(ap);
    }
    r->failed = 1;
    return 0;
}

static int need(reader *r, size_t n, const char *what)
{
    if (r->failed) return 0;
    if (n > r->size - r->pos) return bad(r, "truncated: %s needs %zu bytes at offset %zu, %zu left", what, n, r->pos,
                                         r->size - r->pos);
    return 1;
}

static uint64_t get_u64(reader *r, const char *what)
{
    if (!need(r, 8, what)) return 0;
    uint64_t v = 0;
    if (SNAP_HOST_LE) memcpy(&v, r->buf + r->pos, 8);
    else for (int i = 7; i >= 0; i--) v = (v << 8) | r->buf[r->pos + (size_t)i];
    r->pos += 8;
    return v;
}

static uint32_t get_u32(reader *r, const char *what)
{
    if (!need(r, 4, what)) return 0;
    uint32_t v = 0;
    if (SNAP_HOST_LE) memcpy(&v, r->buf + r->pos, 4);
    else for (int i = 3; i >= 0; i--) v = (v << 8) | r->buf[r->pos + (size_t)i];
    r->pos += 4;
    return v;
}

static unsigned get_u8(reader *r, const char *what)
{
    if (!need(r, 1, what)) return 0;
    return r->buf[r->pos++];
}

static int get_i32(reader *r, const char *what) { return (int)get_u32(r, what); }

/* A finite double (the state never holds anything else). */
static double get_f64(reader *r, const char *what)
{
    uint64_t v = get_u64(r, what);
    double d;
    memcpy(&d, &v, 8);
    if (!r->failed && !isfinite(d)) { bad(r, "%s is not finite", what); return 0; }
    return d;
}

static vec3 get_v3(reader *r, const char *what)
{
    vec3 v;
    v.x = get_f64(r, what);
    v.y = get_f64(r, what);
    v.z = get_f64(r, what);
    return v;
}

static quat get_q(reader *r, const char *what)
{
    quat q;
    q.w = get_f64(r, what);
    q.x = get_f64(r, what);
    q.y = get_f64(r, what);
    q.z = get_f64(r, what);
    return q;
}

static mat3 get_m3(reader *r, const char *what)
{
    mat3 m;
    m.c0 = get_v3(r, what);
    m.c1 = get_v3(r, what);
    m.c2 = get_v3(r, what);
    return m;
}

/* A count whose records take at least `record` bytes each must fit in what is left. */
static int get_count(reader *r, size_t record, int max, const char *what)
{
    uint32_t n = get_u32(r, what);
    if (r->failed) return 0;
    if (n > (uint32_t)max) return bad(r, "%s %u is above %d", what, n, max), 0;
    if ((size_t)n * record > r->size - r->pos) return bad(r, "truncated: %u %s need more than the %zu bytes left", n, what,
                                                           r->size - r->pos), 0;
    return (int)n;
}

/* ---- checksum: 64-bit, eight bytes at a time (snapshots are megabytes) ---------- */

static uint64_t checksum(const unsigned char *p, size_t n)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL ^ (uint64_t)n;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t v = 0;
        if (SNAP_HOST_LE) memcpy(&v, p + i, 8);
        else for (int k = 7; k >= 0; k--) v = (v << 8) | p[i + (size_t)k];
        h = (h ^ v) * 0xff51afd7ed558ccdULL;
        h ^= h >> 29;
    }
    for (; i < n; i++) {
        h = (h ^ p[i]) * 0xc4ceb9fe1a85ec53ULL;
        h ^= h >> 31;
    }
    return h;
}

/* ---- settings -------------------------------------------------------------------- */

/* The def's fields in declaration order; the callback and its context are
 * pointers into the writer's process and are not written. */
#define DEF_FIELDS(F, I, V)                                                                                   \
    V(gravity) I(substeps) I(iterations) I(relax_iterations) I(position_correction) I(warm_starting)           \
    F(restitution_threshold) F(contact_hertz) F(contact_damping_ratio) F(contact_push_max_velocity)           \
    F(baumgarte) F(linear_slop) F(speculative_distance) I(contact_model) F(penalty_stiffness)                 \
    F(penalty_damping) I(penalty_implicit) I(shock_propagation) I(enable_friction) I(enable_restitution)      \
    I(enable_sleep) I(enable_continuous) F(sleep_time) F(sleep_linear_velocity) F(sleep_angular_velocity)     \
    F(max_linear_speed) F(max_angular_speed) I(body_capacity) F(contact_reuse_distance) F(hit_event_threshold)

/* A field appended to carom_world_def must be added above (and to
 * docs/snapshot.md): this stops the build until it is. The task hooks
 * (worker_count .. task_context, the last fields) are not written either:
 * they belong to the writer's process, and a worker count without its
 * hooks would be refused; a restored world runs on the calling thread until
 * the host sets its own hooks. */
typedef char snapshot_def_fields_cover_the_def
    [offsetof(carom_world_def, hit_event_threshold) + sizeof(double) == offsetof(carom_world_def, worker_count) &&
     offsetof(carom_world_def, task_context) + sizeof(void *) == sizeof(carom_world_def) ? 1 : -1];

static void write_def(writer *o, const carom_world_def *d)
{
#define WF(f) put_f64(o, d->f);
#define WI(f) put_i32(o, (int)d->f);
#define WV(f) put_f64(o, d->f.x); put_f64(o, d->f.y); put_f64(o, d->f.z);
    DEF_FIELDS(WF, WI, WV)
#undef WF
#undef WI
#undef WV
}

static void read_def(reader *r, carom_world_def *d)
{
    *d = carom_world_def_default();
#define RF(f) d->f = get_f64(r, "setting " #f);
#define RI(f) d->f = get_i32(r, "setting " #f);
#define RV(f) d->f.x = get_f64(r, "setting " #f); d->f.y = get_f64(r, "setting " #f); d->f.z = get_f64(r, "setting " #f);
    DEF_FIELDS(RF, RI, RV)
#undef RF
#undef RI
#undef RV
}

/* ---- shapes: one case per shape type ----------------------------------------------- */

static void write_shape(writer *o, const shape *s)
{
    put_u8(o, (unsigned)s->type);
    switch (s->type) {
    case SHAPE_SPHERE: put_f64(o, s->radius); break;
    case SHAPE_BOX: put_v3(o, s->half_extents); break;
    case SHAPE_CAPSULE:
    case SHAPE_CYLINDER: put_f64(o, s->radius); put_f64(o, s->half_height); break;
    case SHAPE_PLANE: put_v3(o, s->plane_normal); put_f64(o, s->plane_offset); break;
    case SHAPE_HULL: {
        const hull *h = s->hull;
        int nfv = 0;
        for (int f = 0; f < h->face_count; f++)
            if (h->faces[f].first + h->faces[f].count > nfv) nfv = h->faces[f].first + h->faces[f].count;
        put_i32(o, h->vertex_count);
        put_i32(o, h->face_count);
        put_i32(o, nfv);
        put_i32(o, h->edge_count);
        for (int i = 0; i < h->vertex_count; i++) put_v3(o, h->vertices[i]);
        for (int f = 0; f < h->face_count; f++) {
            put_v3(o, h->faces[f].normal);
            put_f64(o, h->faces[f].offset);
            put_i32(o, h->faces[f].first);
            put_i32(o, h->faces[f].count);
        }
        for (int i = 0; i < nfv; i++) put_i32(o, h->face_vertices[i]);
        for (int e = 0; e < h->edge_count; e++) { put_i32(o, h->edges[e][0]); put_i32(o, h->edges[e][1]); }
        put_v3(o, h->centroid);
        put_f64(o, h->volume);
        put_m3(o, h->unit_inertia);
        break;
    }
    }
}

static int length_ok(double x) { return x >= RANGE_LENGTH_MIN && x <= RANGE_LENGTH_MAX; }

static hull *read_hull(reader *r)
{
    int nv = get_i32(r, "hull vertex count"), nf = get_i32(r, "hull face count");
    int nfv = get_i32(r, "hull face vertex count"), ne = get_i32(r, "hull edge count");
    if (r->failed) return NULL;
    if (nv < 4 || nv > HULL_MAX_VERTICES || nf < 4 || nf > HULL_MAX_FACES || nfv < 3 * nf ||
        nfv > HULL_MAX_FACE_VERTICES || ne < 6 || ne > HULL_MAX_FACE_VERTICES / 2)
        return bad(r, "hull counts (%d vertices, %d faces, %d face vertices, %d edges) are out of range", nv, nf, nfv, ne),
               NULL;
    size_t bytes = (size_t)nv * 24 + (size_t)nf * 40 + (size_t)nfv * 4 + (size_t)ne * 8 + 104;
    if (!need(r, bytes, "hull")) return NULL;
    hull *h = calloc(1, sizeof *h);
    if (!h) return bad(r, "out of memory"), NULL;
    h->vertices = malloc(sizeof *h->vertices * (size_t)nv);
    h->faces = malloc(sizeof *h->faces * (size_t)nf);
    h->face_vertices = malloc(sizeof *h->face_vertices * (size_t)nfv);
    h->edges = malloc(sizeof *h->edges * (size_t)ne);
    if (!h->vertices || !h->faces || !h->face_vertices || !h->edges) { hull_free(h); return bad(r, "out of memory"), NULL; }
    h->vertex_count = nv;
    h->face_count = nf;
    h->edge_count = ne;
    for (int i = 0; i < nv; i++) {
        h->vertices[i] = get_v3(r, "hull vertex");
        if (!(fabs(h->vertices[i].x) <= RANGE_LENGTH_MAX && fabs(h->vertices[i].y) <= RANGE_LENGTH_MAX &&
              fabs(h->vertices[i].z) <= RANGE_LENGTH_MAX) && !r->failed)
            bad(r, "hull vertex %d is beyond 1e6 m", i);
    }
    for (int f = 0; f < nf && !r->failed; f++) {
        hull_face *hf = &h->faces[f];
        hf->normal = get_v3(r, "hull face normal");
        hf->offset = get_f64(r, "hull face offset");
        hf->first = get_i32(r, "hull face first");
        hf->count = get_i32(r, "hull face count");
        if (!r->failed && (hf->count < 3 || hf->first < 0 || hf->first > nfv - hf->count))
            bad(r, "hull face %d has %d vertices from index %d, of %d", f, hf->count, hf->first, nfv);
        if (!r->failed && fabs(v3_len(hf->normal) - 1.0) > 1e-6) bad(r, "hull face %d normal is not unit", f);
    }
    int total = 0;
    for (int f = 0; f < nf && !r->failed; f++) total += h->faces[f].count;
    if (!r->failed && total > HULL_MAX_FACE_VERTICES) bad(r, "hull faces hold %d vertices, at most %d", total, HULL_MAX_FACE_VERTICES);
    for (int i = 0; i < nfv && !r->failed; i++) {
        h->face_vertices[i] = get_i32(r, "hull face vertex");
        if (!r->failed && (h->face_vertices[i] < 0 || h->face_vertices[i] >= nv)) bad(r, "hull face vertex %d out of range", i);
    }
    for (int e = 0; e < ne && !r->failed; e++)
        for (int k = 0; k < 2; k++) {
            h->edges[e][k] = get_i32(r, "hull edge");
            if (!r->failed && (h->edges[e][k] < 0 || h->edges[e][k] >= nv)) bad(r, "hull edge %d out of range", e);
        }
    h->centroid = get_v3(r, "hull centroid");
    h->volume = get_f64(r, "hull volume");
    h->unit_inertia = get_m3(r, "hull inertia");
    if (!r->failed && !(h->volume > 0)) bad(r, "hull volume is not positive");
    if (r->failed) { hull_free(h); return NULL; }
    return h;
}

static int read_shape(reader *r, shape *s, int body_type)
{
    memset(s, 0, sizeof *s);
    s->type = (int)get_u8(r, "shape type");
    if (r->failed) return 0;
    switch (s->type) {
    case SHAPE_SPHERE:
        s->radius = get_f64(r, "sphere radius");
        if (!r->failed && !length_ok(s->radius)) return bad(r, "sphere radius %g is outside [1e-6, 1e6] m", s->radius);
        break;
    case SHAPE_BOX:
        s->half_extents = get_v3(r, "box half extents");
        if (!r->failed && !(length_ok(s->half_extents.x) && length_ok(s->half_extents.y) && length_ok(s->half_extents.z)))
            return bad(r, "box half extents are outside [1e-6, 1e6] m");
        break;
    case SHAPE_CAPSULE:
    case SHAPE_CYLINDER:
        s->radius = get_f64(r, "radius");
        s->half_height = get_f64(r, "half height");
        if (!r->failed && !(length_ok(s->radius) && length_ok(s->half_height)))
            return bad(r, "capsule or cylinder size is outside [1e-6, 1e6] m");
        break;
    case SHAPE_PLANE:
        s->plane_normal = get_v3(r, "plane normal");
        s->plane_offset = get_f64(r, "plane offset");
        if (!r->failed && fabs(v3_len(s->plane_normal) - 1.0) > 1e-9) return bad(r, "plane normal is not unit");
        if (!r->failed && !(fabs(s->plane_offset) <= RANGE_COORDINATE_MAX)) return bad(r, "plane offset beyond 1e12 m");
        if (!r->failed && body_type != CAROM_BODY_STATIC) return bad(r, "a plane on a body that is not static");
        break;
    case SHAPE_HULL:
        s->hull = read_hull(r);
        break;
    default:
        return bad(r, "unknown shape type %d", s->type);
    }
    return !r->failed;
}

/* ---- the snapshot ------------------------------------------------------------------- */

#define BODY_KNOWN_FLAGS (BODY_LOCK_ROTATION | BODY_LOCK_PLANE | BODY_BULLET | BODY_AWAKE | BODY_ENABLE_SLEEP | BODY_HAS_FORCE | \
                          BODY_SENSOR)
#define CONTACT_KNOWN_FLAGS \
    (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_SIM | CONTACT_REUSABLE | CONTACT_APART | CONTACT_ANY_TOUCHING)

static void write_world(writer *o, const carom_world *w)
{
    const body_store *s = &w->bodies;
    const contact_set *cs = &w->contacts;
    write_def(o, &w->def);
    put_f64(o, 0.0); /* reserved: was the last step's dt (each step now carries its own) */
    put_u64(o, (uint64_t)w->stats.step_count);

    put_i32(o, s->id_count);
    put_i32(o, s->free_id);
    for (int i = 0; i < s->id_count; i++) {
        put_i32(o, s->ids[i].slot);
        put_u32(o, s->ids[i].generation);
        put_i32(o, s->ids[i].next_free);
    }

    put_i32(o, s->count);
    for (int i = 0; i < s->count; i++) {
        put_u8(o, (unsigned)s->type[i]);
        put_u32(o, s->flags[i]);
        put_u8(o, (unsigned)bp_is_moved(w->bp, s->proxy[i]));
        put_v3(o, s->center[i]);
        put_q(o, s->rotation[i]);
        put_v3(o, s->velocity[i]);
        put_v3(o, s->angular_velocity[i]);
        put_v3(o, s->force[i]);
        put_v3(o, s->local_center[i]);
        put_f64(o, s->mass[i]);
        put_m3(o, s->inertia_local[i]);
        put_f64(o, s->friction[i]);
        put_f64(o, s->restitution[i]);
        put_f64(o, s->linear_damping[i]);
        put_f64(o, s->angular_damping[i]);
        put_f64(o, s->gravity_scale[i]);
        put_v3(o, s->plane_normal[i]);
        put_f64(o, s->plane_offset[i]);
        put_f64(o, s->sleep_time[i]);
        put_v3(o, s->fat_box[i].lo);
        put_v3(o, s->fat_box[i].hi);
        put_u64(o, s->category[i]);
        put_u64(o, s->filter_mask[i]);
        put_i32(o, s->group[i]);
        put_v3(o, s->previous_origin[i]);
        put_q(o, s->previous_rotation[i]);
        put_v3(o, s->torque[i]);
        put_f64(o, s->force_threshold[i]);
        put_f64(o, s->rolling_resistance[i]);
        put_u8(o, (unsigned)s->combine[i]);
        write_shape(o, &s->shapes[i]);
    }

    put_i32(o, cs->count);
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        const contact_data *d = &cs->data[i];
        put_i32(o, c->id_a);
        put_i32(o, c->id_b);
        put_u32(o, c->flags);
        put_u32(o, c->sub);
        put_u32(o, c->sub_limit);
        put_v3(o, c->cache.normal);
        put_u8(o, (unsigned)c->cache.has_normal);
        put_i32(o, c->cache.feature);
        put_u8(o, (unsigned)c->cache.flip);
        put_v3(o, c->rel_pose.p);
        put_q(o, c->rel_pose.q);
        put_f64(o, c->gap);
        put_f64(o, c->reach_b);
        put_f64(o, d->friction);
        put_f64(o, d->restitution);
        put_f64(o, d->rolling_resistance);
        put_v3(o, d->m.normal);
        put_u8(o, (unsigned)d->m.count);
        for (int k = 0; k < d->m.count; k++) {
            put_v3(o, d->m.points[k].point);
            put_f64(o, d->m.points[k].separation);
            put_u32(o, d->m.points[k].id);
            put_f64(o, d->state[k].normal_impulse);
            put_f64(o, d->state[k].tangent_impulse[0]);
            put_f64(o, d->state[k].tangent_impulse[1]);
            put_v3(o, d->state[k].local_a);
            put_f64(o, d->state[k].separation);
        }
        put_v3(o, d->tangent1);
        put_v3(o, d->normal_a);
    }
    /* the sensors' overlaps after the last step (sensor.c): their next events */
    put_i32(o, w->sensor_overlap_count);
    for (int i = 0; i < w->sensor_overlap_count; i++) {
        put_u64(o, carom_body_id_pack(w->sensor_overlaps[i].sensor));
        put_u64(o, carom_body_id_pack(w->sensor_overlaps[i].other));
    }
}

CAROM_API size_t carom_world_snapshot(const carom_world *w, void *buf, size_t capacity)
{
    if (!w) return 0;
    if (w->locked) {
        world_fail(w, CAROM_ERROR_LOCKED, "world_snapshot: the world is inside its step; snapshot it afterwards");
        return 0;
    }
    for (int i = 0; i < w->bodies.count; i++)
        if (shape_is_composite(&w->bodies.shapes[i])) {
            /* their format is still to be written (docs/snapshot.md): refuse rather than lose them */
            world_fail(w, CAROM_ERROR_UNSUPPORTED, "world_snapshot: meshes, height fields and compounds are not in snapshots yet");
            return 0;
        }
    if (!buf) capacity = 0;
    writer o = {buf, capacity, 0};
    put_bytes(&o, SNAP_MAGIC, 8);
    put_u32(&o, SNAP_VERSION);
    put_u32(&o, SNAP_HEADER_SIZE);
    put_u64(&o, 0); /* total size, filled below */
    put_u64(&o, 0); /* checksum, filled below */
    write_world(&o, w);
    if (o.pos <= capacity) {
        writer h = {buf, capacity, 16};
        put_u64(&h, (uint64_t)o.pos);
        put_u64(&h, checksum((const unsigned char *)buf + SNAP_HEADER_SIZE, o.pos - SNAP_HEADER_SIZE));
    }
    return o.pos;
}

/* Body fields, read into the store of a world just created from the def. */
static int read_bodies(reader *r, carom_world *w)
{
    body_store *s = &w->bodies;
    int id_count = get_count(r, 12, 1 << 26, "id count");
    int free_id = get_i32(r, "free id");
    if (r->failed) return 0;
    /* read into the store's own id table, so the world frees it on any failure */
    body_id_entry *ids = malloc(sizeof *ids * (size_t)(id_count > 0 ? id_count : 1));
    if (!ids) return bad(r, "out of memory");
    free(s->ids);
    s->ids = ids;
    s->id_capacity = id_count > 0 ? id_count : 1;
    s->id_count = 0;
    for (int i = 0; i < id_count; i++) {
        ids[i].slot = get_i32(r, "id slot");
        ids[i].generation = get_u32(r, "id generation");
        ids[i].next_free = get_i32(r, "id free link");
    }
    /* bodies: at least 300 bytes each */
    int count = get_count(r, 300, id_count, "body count");
    if (r->failed) return 0;
    if (free_id < -1 || free_id >= id_count) return bad(r, "free id %d out of range", free_id);
    /* every live id names a distinct slot below count; the free list visits every free id once */
    int live = 0, free_ids = 0;
    for (int i = 0; i < id_count; i++) {
        if (ids[i].slot < -1 || ids[i].slot >= count) return bad(r, "id %d has slot %d of %d", i, ids[i].slot, count);
        if (ids[i].next_free < -1 || ids[i].next_free >= id_count) return bad(r, "id %d free link out of range", i);
        if (ids[i].slot >= 0) live++;
        else free_ids++;
    }
    if (live != count) return bad(r, "%d live ids for %d bodies", live, count);
    int walked = 0;
    for (int f = free_id; f >= 0; f = ids[f].next_free)
        if (ids[f].slot >= 0 || ++walked > free_ids) return bad(r, "the free id list is corrupt");
    if (walked != free_ids) return bad(r, "the free id list misses ids");
    /* the dense arrays, sized for the bodies (the id table is kept aside meanwhile) */
    s->ids = NULL;
    body_store_free(s);
    int ok = body_store_init(s, count);
    s->ids = ids;
    s->id_capacity = id_count > 0 ? id_count : 1;
    s->id_count = id_count;
    s->free_id = free_id;
    if (!ok) return bad(r, "out of memory");
    for (int i = 0; i < count; i++) s->id_index[i] = -1;
    for (int i = 0; i < id_count; i++)
        if (ids[i].slot >= 0) {
            if (s->id_index[ids[i].slot] >= 0) return bad(r, "two ids share slot %d", ids[i].slot);
            s->id_index[ids[i].slot] = i;
        }
    for (int i = 0; i < count; i++) {
        char what[48];
        snprintf(what, sizeof what, "body %d", i);
        int type = (int)get_u8(r, what);
        uint32_t flags = get_u32(r, what);
        int moved = (int)get_u8(r, what);
        if (r->failed) return 0;
        if (type != CAROM_BODY_STATIC && type != CAROM_BODY_KINEMATIC && type != CAROM_BODY_DYNAMIC)
            return bad(r, "body %d has type %d", i, type);
        if ((flags & ~(uint32_t)BODY_KNOWN_FLAGS) || moved > 1) return bad(r, "body %d has unknown flags", i);
        if (type == CAROM_BODY_STATIC && (flags & BODY_AWAKE)) return bad(r, "static body %d is awake", i);
        s->type[i] = type;
        s->flags[i] = flags;
        s->solver_index[i] = moved; /* held here until the proxies exist */
        s->center[i] = get_v3(r, what);
        s->rotation[i] = get_q(r, what);
        s->velocity[i] = get_v3(r, what);
        s->angular_velocity[i] = get_v3(r, what);
        s->force[i] = get_v3(r, what);
        s->local_center[i] = get_v3(r, what);
        s->mass[i] = get_f64(r, what);
        s->inertia_local[i] = get_m3(r, what);
        s->friction[i] = get_f64(r, what);
        s->restitution[i] = get_f64(r, what);
        s->linear_damping[i] = get_f64(r, what);
        s->angular_damping[i] = get_f64(r, what);
        s->gravity_scale[i] = get_f64(r, what);
        s->plane_normal[i] = get_v3(r, what);
        s->plane_offset[i] = get_f64(r, what);
        s->sleep_time[i] = get_f64(r, what);
        s->fat_box[i].lo = get_v3(r, what);
        s->fat_box[i].hi = get_v3(r, what);
        s->category[i] = get_u64(r, what);
        s->filter_mask[i] = get_u64(r, what);
        s->group[i] = get_i32(r, what);
        s->previous_origin[i] = get_v3(r, what);
        s->previous_rotation[i] = get_q(r, what);
        s->torque[i] = get_v3(r, what);
        s->force_threshold[i] = get_f64(r, what);
        s->rolling_resistance[i] = get_f64(r, what);
        s->combine[i] = (int)get_u8(r, what);
        s->user_data[i] = NULL;
        s->proxy[i] = -1;
        if (r->failed) return 0;
        s->count = i; /* the shapes of bodies 0..i-1 are owned: freed if a later one fails */
        if (!read_shape(r, &s->shapes[i], type)) return 0;
        s->count = i + 1;
        int dynamic = type == CAROM_BODY_DYNAMIC;
        quat q = s->rotation[i];
        double ql = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
        if (fabs(ql - 1.0) > 1e-6) return bad(r, "body %d orientation is not unit", i);
        if (type == CAROM_BODY_DYNAMIC) {
            mat3 I = s->inertia_local[i];
            double trace = I.c0.x + I.c1.y + I.c2.z;
            if (!(s->mass[i] >= RANGE_MASS_MIN && s->mass[i] <= RANGE_MASS_MAX))
                return bad(r, "body %d mass %g is outside [1e-9, 1e15] kg", i, s->mass[i]);
            if (!(trace <= RANGE_INERTIA_MAX && m3_det(I) / (trace * trace) >= RANGE_INERTIA_MIN))
                return bad(r, "body %d inertia is outside [1e-24, 1e30] kg m^2", i);
        }
        if (!(v3_len(s->velocity[i]) <= RANGE_SPEED_MAX && v3_len(s->angular_velocity[i]) <= RANGE_SPEED_MAX))
            return bad(r, "body %d moves faster than any world allows", i);
        /* the force bound is the API's loosest (apply_force checks it against
         * the mass then; set_mass may lower the mass later) */
        if (!(s->mass[i] >= 0) || !(v3_len(s->force[i]) <= RANGE_ACCELERATION_MAX * RANGE_MASS_MAX))
            return bad(r, "body %d mass or force out of range", i);
        if (!(v3_len(s->torque[i]) <= RANGE_ACCELERATION_MAX * RANGE_INERTIA_MAX && isfinite(s->force_threshold[i]) &&
              s->force_threshold[i] >= 0 && s->rolling_resistance[i] >= 0 &&
              s->rolling_resistance[i] <= RANGE_FRICTION_MAX && s->combine[i] <= CAROM_COMBINE_MAX))
            return bad(r, "body %d torque, force threshold, rolling resistance or combine mode out of range", i);
        if (!(s->friction[i] >= 0 && s->friction[i] <= RANGE_FRICTION_MAX && s->restitution[i] >= 0 &&
              s->restitution[i] <= 1 && s->linear_damping[i] >= 0 && s->linear_damping[i] <= RANGE_DAMPING_MAX &&
              s->angular_damping[i] >= 0 && s->angular_damping[i] <= RANGE_DAMPING_MAX &&
              fabs(s->gravity_scale[i]) <= RANGE_GRAVITY_SCALE_MAX && s->sleep_time[i] >= 0))
            return bad(r, "body %d material, damping, gravity scale or sleep timer out of range", i);
        if ((flags & BODY_LOCK_PLANE) && fabs(v3_len(s->plane_normal[i]) - 1.0) > 1e-9)
            return bad(r, "body %d plane normal is not unit", i);
        aabb b = s->fat_box[i];
        if (!(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z)) return bad(r, "body %d bounds are inverted", i);
        /* derived fields, computed as body creation and the setters compute them */
        s->inv_mass[i] = dynamic ? 1.0 / s->mass[i] : 0.0;
        s->inv_inertia_local[i] = dynamic ? m3_inverse(s->inertia_local[i]) : m3_zero();
        body_update_inertia(s, i);
    }
    return 1;
}

/* (sensor.c's pairs: a sensor id and another, two packed ids each) */
static int read_sensor_overlaps(reader *r, carom_world *w)
{
    int count = get_count(r, 16, 1 << 28, "sensor overlap count");
    if (r->failed) return 0;
    if (count == 0) return 1;
    sensor_overlap *pairs = malloc(sizeof *pairs * (size_t)count);
    if (!pairs) return bad(r, "out of memory");
    for (int i = 0; i < count; i++) {
        pairs[i].sensor = carom_body_id_unpack(get_u64(r, "sensor overlap"));
        pairs[i].other = carom_body_id_unpack(get_u64(r, "sensor overlap"));
        if (!r->failed && !carom_body_is_sensor(w, pairs[i].sensor)) {
            free(pairs);
            return bad(r, "sensor overlap %d names a body that is not a live sensor", i);
        }
    }
    if (r->failed) { free(pairs); return 0; }
    w->sensor_overlaps = pairs;
    w->sensor_overlap_count = count;
    w->sensor_overlap_capacity = count;
    return 1;
}

static int read_contacts(reader *r, carom_world *w)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    int count = get_count(r, 188, 1 << 28, "contact count");
    for (int i = 0; i < count && !r->failed; i++) {
        int a = get_i32(r, "contact body"), b = get_i32(r, "contact body");
        if (r->failed) return 0;
        if (a < 0 || b >= s->id_count || a >= b || s->ids[a].slot < 0 || s->ids[b].slot < 0)
            return bad(r, "contact %d joins ids %d and %d, not two live bodies in order", i, a, b);
        uint32_t flags = get_u32(r, "contact flags"), sub = get_u32(r, "contact sub");
        if (r->failed) return 0;
        if (sub > 1000000) return bad(r, "contact %d has manifold number %u", i, (unsigned)sub);
        if ((sub ? contact_find_sub(cs, a, b, sub) : contact_find(cs, a, b)) >= 0)
            return bad(r, "contact %d repeats the pair (%d, %d) manifold %u", i, a, b, (unsigned)sub);
        int ci = sub ? contact_add_sub(cs, a, b, sub) : contact_add(cs, a, b);
        if (ci < 0) return bad(r, "out of memory");
        contact *c = &cs->items[ci];
        contact_data *d = &cs->data[ci];
        c->flags = flags;
        c->sub_limit = get_u32(r, "contact sub limit");
        c->cache.normal = get_v3(r, "contact cache normal");
        c->cache.has_normal = (int)get_u8(r, "contact cache");
        c->cache.feature = get_i32(r, "contact cache feature");
        c->cache.flip = (int)get_u8(r, "contact cache");
        c->rel_pose.p = get_v3(r, "contact pose");
        c->rel_pose.q = get_q(r, "contact pose");
        c->gap = get_f64(r, "contact gap");
        c->reach_b = get_f64(r, "contact reach");
        d->friction = get_f64(r, "contact friction");
        d->restitution = get_f64(r, "contact restitution");
        d->rolling_resistance = get_f64(r, "contact rolling resistance");
        d->m.normal = get_v3(r, "manifold normal");
        d->m.count = (int)get_u8(r, "manifold count");
        if (r->failed) return 0;
        if ((c->flags & ~(uint32_t)CONTACT_KNOWN_FLAGS) || c->cache.has_normal > 1 || c->cache.flip > 1 ||
            c->cache.feature < -1 || d->m.count > MANIFOLD_MAX_POINTS)
            return bad(r, "contact %d has unknown flags or a bad cache", i);
        if (!(d->friction >= 0 && d->friction <= RANGE_FRICTION_MAX && d->restitution >= 0 && d->restitution <= 1 &&
              d->rolling_resistance >= 0 && d->rolling_resistance <= RANGE_FRICTION_MAX))
            return bad(r, "contact %d material out of range", i);
        for (int k = 0; k < d->m.count; k++) {
            d->m.points[k].point = get_v3(r, "manifold point");
            d->m.points[k].separation = get_f64(r, "manifold point");
            d->m.points[k].id = get_u32(r, "manifold point");
            d->state[k].normal_impulse = get_f64(r, "warm-start impulse");
            d->state[k].tangent_impulse[0] = get_f64(r, "warm-start impulse");
            d->state[k].tangent_impulse[1] = get_f64(r, "warm-start impulse");
            d->state[k].local_a = get_v3(r, "contact point");
            d->state[k].separation = get_f64(r, "contact point");
        }
        d->tangent1 = get_v3(r, "friction basis");
        d->normal_a = get_v3(r, "contact normal");
    }
    return !r->failed;
}

CAROM_API carom_world *carom_world_restore(const void *data, size_t size, char *msg, size_t msg_size)
{
    reader r = {data, size, 0, msg, msg_size, 0};
    if (msg && msg_size) msg[0] = '\0';
    if (!data) return bad(&r, "data is NULL"), NULL;
    if (size < SNAP_HEADER_SIZE || memcmp(data, SNAP_MAGIC, 8) != 0)
        return bad(&r, "not a carom snapshot (no \"" SNAP_MAGIC "\" header)"), NULL;
    r.pos = 8;
    uint32_t version = get_u32(&r, "version"), header = get_u32(&r, "header size");
    uint64_t total = get_u64(&r, "size"), sum = get_u64(&r, "checksum");
    if (version != SNAP_VERSION)
        return bad(&r, "version %u; this carom reads version %u", (unsigned)version, SNAP_VERSION), NULL;
    if (header != SNAP_HEADER_SIZE) return bad(&r, "header size %u, expected %u", (unsigned)header, SNAP_HEADER_SIZE), NULL;
    if (total != size)
        return bad(&r, "truncated or padded: the header says %llu bytes, %zu given", (unsigned long long)total, size), NULL;
    if (checksum(r.buf + SNAP_HEADER_SIZE, size - SNAP_HEADER_SIZE) != sum)
        return bad(&r, "corrupted (checksum mismatch)"), NULL;

    carom_world_def def;
    read_def(&r, &def);
    double last_dt = get_f64(&r, "reserved f64"); /* was the last step's dt: read, checked, unused */
    uint64_t steps = get_u64(&r, "step count");
    if (r.failed) return NULL;
    char why[WORLD_ERROR_SIZE];
    if (carom_world_def_check(&def, why, sizeof why) != CAROM_OK) return bad(&r, "settings: %s", why), NULL;
    /* written as 0 (it was the last step's dt): anything else would not
     * snapshot back to the same bytes */
    if (last_dt != 0.0) return bad(&r, "reserved field after the settings is %g, not 0", last_dt), NULL;
    if (steps >> 63) return bad(&r, "step count out of range"), NULL;
    /* the storage hint is kept but not acted on: the store is sized for the
     * bodies the snapshot holds, never for a number the data merely claims */
    int capacity_hint = def.body_capacity;
    def.body_capacity = 0;
    carom_world *w = carom_world_create(&def);
    if (!w) return bad(&r, "out of memory"), NULL;
    w->def.body_capacity = capacity_hint;
    w->stats.step_count = (long long)steps;
    if (!read_bodies(&r, w) || !read_contacts(&r, w) || !read_sensor_overlaps(&r, w)) {
        carom_world_destroy(w);
        return NULL;
    }
    if (r.pos != size) {
        carom_world_destroy(w);
        return bad(&r, "%zu bytes left over after the sensor overlaps", size - r.pos), NULL;
    }
    /* the broadphase, rebuilt from the stored bounds in slot order, with the moved set restored */
    body_store *s = &w->bodies;
    for (int i = 0; i < s->count; i++) {
        s->proxy[i] = bp_create_proxy(w->bp, s->fat_box[i], s->type[i] == CAROM_BODY_STATIC, s->id_index[i]);
        if (s->proxy[i] < 0) {
            carom_world_destroy(w);
            return bad(&r, "out of memory"), NULL;
        }
    }
    for (int i = 0; i < s->count; i++) {
        bp_set_moved(w->bp, s->proxy[i], s->solver_index[i]);
        s->solver_index[i] = -1;
    }
    return w;
}
