/* fuzz_api.c - libFuzzer harness: random sequences of C API calls with
 * hostile arguments, checked against a model of what must stay true:
 * a refused call leaves the world byte for byte as it was (its snapshot
 * unchanged); destroyed ids stay stale for every call; the body count is the
 * model's; after every step that returns OK nothing is non-finite; a
 * snapshot restored mid-sequence carries on in place of the original. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom/carom.h"
#include "fuzz_common.h"
#include "fuzz_input.h"

#define MAX_LIVE 48

typedef struct model {
    carom_body_id live[MAX_LIVE], dead[MAX_LIVE];
    int nlive, ndead;
} model;

static carom_vec3 any3(fuzz_input *in)
{
    carom_vec3 v;
    FZ_VEC3(v, fz_any(in));
    return v;
}

static carom_vec3 small3(fuzz_input *in, double r)
{
    carom_vec3 v;
    FZ_VEC3(v, fz_in(in, -r, r));
    return v;
}

static double hull_points[3 * 16];

static carom_shape_def any_shape(fuzz_input *in, int sane)
{
    double a = sane ? fz_in(in, 0.05, 1) : fz_any(in);
    double b = sane ? fz_in(in, 0.05, 1) : fz_any(in);
    double c = sane ? fz_in(in, 0.05, 1) : fz_any(in);
    switch (fz_below(in, 7)) {
    case 0: return carom_shape_sphere(a);
    case 1: return carom_shape_box(a, b, c);
    case 2: return carom_shape_capsule(a, b);
    case 3: return carom_shape_cylinder(a, b);
    case 4: {
        int n = (int)fz_below(in, 17);
        for (int i = 0; i < 3 * 16; i++) hull_points[i] = sane ? fz_in(in, -1, 1) : fz_any(in);
        carom_shape_def s = carom_shape_hull(fz_below(in, 8) ? hull_points : NULL, n);
        return s;
    }
    case 5: return carom_shape_plane(a, b, c, fz_any(in));
    default: {
        carom_shape_def s = carom_shape_sphere(a);
        s.type = (carom_shape_type)(int)fz_byte(in);
        return s;
    }
    }
}

static carom_body_id pick_id(fuzz_input *in, const model *m)
{
    unsigned k = fz_below(in, 8);
    if (k < 5 && m->nlive) return m->live[fz_below(in, (unsigned)m->nlive)];
    if (k < 7 && m->ndead) return m->dead[fz_below(in, (unsigned)m->ndead)];
    carom_body_id id;
    id.index1 = fz_byte(in);
    id.generation = fz_byte(in);
    return id;
}

typedef struct snap { unsigned char *p; size_t n; } snap;
static snap take(const carom_world *w)
{
    snap s;
    s.n = carom_world_snapshot(w, NULL, 0);
    s.p = malloc(s.n ? s.n : 1);
    FUZZ_CHECK(s.p && carom_world_snapshot(w, s.p, s.n) == s.n, "snapshot");
    return s;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_input in = {data, size, 0};
    carom_world_def wd = carom_world_def_default();
    static const char *const presets[] = {"fast", "default", "accurate"};
    carom_world_def_apply_preset(&wd, presets[fz_below(&in, 3)]);
    carom_world *w = carom_world_create(&wd);
    if (!w) return 0;
    model m;
    memset(&m, 0, sizeof m);
    for (int op = 0; op < 64 && !fz_done(&in); op++) {
        snap before = take(w);
        carom_status st = CAROM_OK;
        int checked = 1; /* the op's status says whether the world may have changed */
        unsigned kind = fz_below(&in, 20);
        carom_body_id id = pick_id(&in, &m);
        switch (kind) {
        case 0: case 1: case 2: {
            int sane = fz_below(&in, 4) != 0;
            carom_body_def d = carom_body_def_default();
            d.type = (carom_body_type)(fz_below(&in, 5) == 0 ? (int)fz_byte(&in) : (int)fz_below(&in, 3));
            d.shape = any_shape(&in, sane);
            d.position = sane ? small3(&in, 5) : any3(&in);
            if (!sane || fz_bool(&in)) d.linear_velocity = sane ? small3(&in, 10) : any3(&in);
            if (!sane || fz_bool(&in)) d.angular_velocity = sane ? small3(&in, 10) : any3(&in);
            if (!sane) {
                d.mass = fz_any(&in);
                d.density = fz_any(&in);
                d.friction = fz_any(&in);
                d.restitution = fz_any(&in);
                d.gravity_scale = fz_any(&in);
                d.linear_damping = fz_any(&in);
                d.orientation.w = fz_any(&in);
                d.plane_normal = any3(&in);
                d.size = fz_bool(&in) ? (uint32_t)fz_byte(&in) : d.size;
            }
            d.lock_rotation = fz_bool(&in);
            d.lock_to_plane = fz_below(&in, 4) == 0;
            d.bullet = fz_bool(&in);
            d.awake = fz_below(&in, 4) != 0;
            if (getenv("CAROM_FUZZ_TRACE"))
                fprintf(stderr, "create: type %d shape %d r %.17g hh %.17g he (%.17g %.17g %.17g) n (%.17g %.17g %.17g) off %.17g"
                        " pos (%.17g %.17g %.17g) v (%.17g %.17g %.17g) w (%.17g %.17g %.17g) mass %.17g density %.17g"
                        " mu %.17g e %.17g g %.17g qw %.17g pn (%.17g %.17g %.17g) locks %d %d bullet %d awake %d\n",
                        (int)d.type, (int)d.shape.type, d.shape.radius, d.shape.half_height, d.shape.half_extents.x,
                        d.shape.half_extents.y, d.shape.half_extents.z, d.shape.normal.x, d.shape.normal.y, d.shape.normal.z,
                        d.shape.offset, d.position.x, d.position.y, d.position.z, d.linear_velocity.x, d.linear_velocity.y,
                        d.linear_velocity.z, d.angular_velocity.x, d.angular_velocity.y, d.angular_velocity.z, d.mass,
                        d.density, d.friction, d.restitution, d.gravity_scale, d.orientation.w, d.plane_normal.x,
                        d.plane_normal.y, d.plane_normal.z, d.lock_rotation, d.lock_to_plane, d.bullet, d.awake);
            carom_body_id nid = carom_body_create(w, &d);
            if (carom_body_id_is_null(nid)) st = CAROM_ERROR_INVALID_ARGUMENT;
            else if (m.nlive < MAX_LIVE) m.live[m.nlive++] = nid;
            else { carom_body_destroy(w, nid); checked = 0; }
            break;
        }
        case 3: {
            st = carom_body_destroy(w, id);
            if (st == CAROM_OK) {
                for (int i = 0; i < m.nlive; i++)
                    if (carom_body_id_equal(m.live[i], id)) { m.live[i] = m.live[--m.nlive]; break; }
                if (m.ndead < MAX_LIVE) m.dead[m.ndead++] = id;
            }
            break;
        }
        case 4: st = carom_body_set_position(w, id, fz_bool(&in) ? small3(&in, 5) : any3(&in)); break;
        case 5: {
            carom_quat q;
            q.w = fz_any(&in);
            q.x = fz_any(&in);
            q.y = fz_any(&in);
            q.z = fz_any(&in);
            if (fz_bool(&in)) { q.w = 1; q.x = q.y = q.z = 0; }
            st = carom_body_set_orientation(w, id, q);
            break;
        }
        case 6: st = carom_body_set_linear_velocity(w, id, fz_bool(&in) ? small3(&in, 50) : any3(&in)); break;
        case 7: st = carom_body_set_angular_velocity(w, id, fz_bool(&in) ? small3(&in, 50) : any3(&in)); break;
        case 8: st = carom_body_set_mass(w, id, fz_any(&in)); break;
        case 9: st = carom_body_set_type(w, id, (carom_body_type)(int)fz_below(&in, 4)); break;
        case 10: {
            int which = fz_bool(&in);
            double v = fz_any(&in);
            st = which ? carom_body_set_friction(w, id, v) : carom_body_set_restitution(w, id, v);
            break;
        }
        case 11: {
            int which = fz_bool(&in);
            double v = fz_any(&in);
            st = which ? carom_body_set_gravity_scale(w, id, v) : carom_body_set_awake(w, id, v > 0);
            break;
        }
        case 12: {
            carom_vec3 p = small3(&in, 5);
            carom_vec3 j = fz_bool(&in) ? small3(&in, 10) : any3(&in);
            st = carom_body_apply_impulse(w, id, j, fz_bool(&in) ? &p : NULL);
            break;
        }
        case 13: st = carom_body_apply_force(w, id, fz_bool(&in) ? small3(&in, 100) : any3(&in)); break;
        case 14: case 15: {
            double dt = fz_below(&in, 3) ? 1.0 / 60 : fz_any(&in);
            st = carom_world_step(w, dt);
            checked = 0; /* a refused step changes nothing either: checked below */
            if (st == CAROM_OK) fuzz_assert_world_finite(w);
            else {
                snap after = take(w);
                FUZZ_CHECK(after.n == before.n && !memcmp(after.p, before.p, after.n), "a refused step changed the world");
                free(after.p);
            }
            break;
        }
        case 16: {
            carom_world_def d = carom_world_def_default();
            carom_world_get_def(w, &d);
            double *fields[] = {&d.gravity.z, &d.contact_hertz, &d.max_linear_speed, &d.max_angular_speed,
                                &d.linear_slop, &d.speculative_distance, &d.sleep_time, &d.contact_reuse_distance,
                                &d.penalty_stiffness, &d.contact_damping_ratio, &d.restitution_threshold};
            double *field = fields[fz_below(&in, 11)];
            *field = fz_any(&in);
            if (fz_bool(&in)) d.substeps = (int)fz_byte(&in) - 8;
            if (fz_bool(&in)) d.contact_model = (carom_contact_model)fz_below(&in, 3);
            st = carom_world_set_def(w, &d);
            break;
        }
        case 17: { /* carry on in a restored copy */
            char msg[256];
            carom_world *r = carom_world_restore(before.p, before.n, msg, sizeof msg);
            FUZZ_CHECK(r != NULL, "restoring a fresh snapshot failed: %s", msg);
            carom_world_def d = carom_world_def_default();
            carom_world_get_def(w, &d);
            carom_world_set_def(r, &d); /* nothing to carry: no callback here */
            carom_world_destroy(w);
            w = r;
            snap after = take(w);
            FUZZ_CHECK(after.n == before.n && !memcmp(after.p, before.p, after.n), "the restored world snapshots differently");
            free(after.p);
            checked = 0;
            break;
        }
        case 18: {
            carom_ray_hit hit;
            carom_vec3 o = any3(&in), d = any3(&in);
            int r = carom_world_ray_cast(w, o, d, &hit);
            if (r == 1) FUZZ_CHECK(fuzz_finite3(hit.point) && fuzz_finite3(hit.normal), "ray hit");
            carom_body_id ids[8];
            carom_vec3 lo = any3(&in), hi = any3(&in);
            carom_world_query_aabb(w, lo, hi, ids, (int)fz_below(&in, 9));
            checked = 0;
            break;
        }
        default: { /* getters on any id */
            carom_vec3 v;
            double x, I[9];
            st = carom_body_get_position(w, id, &v);
            carom_body_get_mass(w, id, &x);
            carom_body_get_inertia(w, id, I);
            carom_body_get_kinetic_energy(w, id, &x);
            checked = 0;
            break;
        }
        }
        if (getenv("CAROM_FUZZ_TRACE"))
            fprintf(stderr, "op %d: kind %u on id (%u, %u): status %d %s\n", op, kind, id.index1, id.generation, (int)st,
                    st ? carom_world_last_error(w) : "");
        if (checked && st != CAROM_OK) {
            snap after = take(w);
            FUZZ_CHECK(after.n == before.n && !memcmp(after.p, before.p, after.n), "refused op %u (status %d: %s) changed the world",
                       kind, (int)st, carom_world_last_error(w));
            FUZZ_CHECK(strlen(carom_world_last_error(w)) > 0, "refused op %u without a message", kind);
            free(after.p);
        }
        free(before.p);
        /* the model: the count, and destroyed ids stay stale */
        FUZZ_CHECK(carom_world_body_count(w) == m.nlive, "%d bodies, the model has %d", carom_world_body_count(w), m.nlive);
        for (int i = 0; i < m.ndead; i++) {
            carom_vec3 v;
            FUZZ_CHECK(!carom_body_is_valid(w, m.dead[i]), "a destroyed id is valid again");
            FUZZ_CHECK(carom_body_get_position(w, m.dead[i], &v) == CAROM_ERROR_STALE_ID, "a destroyed id is not stale");
        }
    }
    carom_world_destroy(w);
    return 0;
}
