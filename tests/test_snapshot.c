/* test_snapshot.c - snapshots: a mixed scene snapshotted mid-run and
 * restored continues bit for bit with the original (its snapshot after every
 * step is byte-identical, and so are its events); a restored world's snapshot
 * is the snapshot it came from; every truncation, byte flips and a wrong
 * version are refused with a message, never read out of bounds (make check
 * runs this under ASan and UBSan too). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "helpers.h"
#include "mesh_scenes.h"
#include "snapshot.h" /* internal: snapshot_field_bytes */
#include "contact.h"  /* internal: the restore path's contact_set_index */
#include "world.h"    /* internal: which body of a restored pair is A */


typedef struct snap { unsigned char *data; size_t size; } snap;

/* Rewrites the header's checksum after a change (below). */
static void fix_checksum(unsigned char *p, size_t n);

static snap take(const carom_world *w)
{
    snap s;
    s.size = carom_world_snapshot(w, NULL, 0);
    assert_true(s.size > 32);
    s.data = malloc(s.size);
    assert_non_null(s.data);
    assert_int_equal(carom_world_snapshot(w, s.data, s.size), s.size);
    return s;
}

static void assert_same_snap(snap a, snap b, int step)
{
    if (a.size != b.size || memcmp(a.data, b.data, a.size) != 0) {
        size_t i = 0;
        while (i < a.size && i < b.size && a.data[i] == b.data[i]) i++;
        fail_msg("step %d: snapshots differ (sizes %zu, %zu; first difference at byte %zu)", step, a.size, b.size, i);
    }
}

static void assert_same_events(const carom_world *a, const carom_world *b, int step)
{
    const carom_contact_event *ea, *eb;
    int na = carom_world_get_events(a, &ea), nb = carom_world_get_events(b, &eb);
    if (na != nb) fail_msg("step %d: %d events against %d", step, na, nb);
    if (na && memcmp(ea, eb, sizeof *ea * (size_t)na) != 0) fail_msg("step %d: events differ", step);
}

/* Every shape; sleeping and awake, kinematic and static bodies; restitution,
 * friction; plane-locked, rotation-locked and bullet bodies; destroyed ids
 * (so the free list and generations matter); a force pending. */
static carom_world *mixed_scene(const char *preset, int *event_count)
{
    carom_world_def wd = carom_world_def_default();
    assert_int_equal(carom_world_def_apply_preset(&wd, preset), CAROM_OK);
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    g.shape = carom_shape_box(0.2, 3, 1);
    g.position = vec(3, 0, 1);
    carom_body_create(w, &g);
    static const double tetra[] = {0, 0, 0, 0.4, 0, 0, 0, 0.4, 0, 0, 0, 0.4, 0.3, 0.3, 0.3};
    const carom_shape_def shapes[] = {carom_shape_sphere(0.2), carom_shape_box(0.2, 0.15, 0.1),
                                      carom_shape_capsule(0.1, 0.2), carom_shape_cylinder(0.15, 0.1),
                                      carom_shape_hull(tetra, 5)};
    carom_body_id doomed[4];
    int nd = 0;
    for (int i = 0; i < 30; i++) {
        carom_body_def b = carom_body_def_default();
        b.shape = shapes[i % 5];
        b.position = vec(-1.5 + 0.5 * (i % 6), -1 + 0.6 * (i / 6 % 4), 0.3 + 0.5 * (i / 24) + 0.05 * (i % 3));
        b.linear_velocity = vec(0.3 * (i % 4) - 0.4, 0.2 * (i % 3) - 0.2, -0.5 * (i % 2));
        b.angular_velocity = vec(0.5 * (i % 3), -0.3 * (i % 2), 0.2);
        b.restitution = (i % 4) * 0.25;
        b.friction = 0.2 + 0.1 * (i % 7);
        b.density = 500 + 100 * (i % 5);
        b.lock_rotation = i == 7;
        b.lock_to_plane = i == 11;
        b.bullet = i == 13;
        if (i == 17) b.mass = 3.5;
        carom_body_id id = carom_body_create(w, &b);
        assert_false(carom_body_id_is_null(id));
        if (i % 9 == 4 && nd < 4) doomed[nd++] = id;
    }
    /* far from the others: it falls asleep before the snapshot */
    carom_body_def sl = carom_body_def_default();
    sl.shape = carom_shape_box(0.3, 0.3, 0.3);
    sl.position = vec(-6, 6, 0.3);
    carom_body_create(w, &sl);
    sl.awake = 0;
    sl.position = vec(-6, -6, 0.3);
    carom_body_create(w, &sl);
    /* a kinematic paddle sweeping through the pile */
    carom_body_def k = carom_body_def_default();
    k.type = CAROM_BODY_KINEMATIC;
    k.shape = carom_shape_box(0.1, 1.5, 0.2);
    k.position = vec(-3, 0, 0.25);
    k.linear_velocity = vec(0.8, 0, 0);
    k.angular_velocity = vec(0, 0, 0.3);
    carom_body_create(w, &k);
    /* every composite shape: a static mesh ramp, a kinematic height field
     * with a hole, compounds landing on both (the mesh and field are
     * written whole, their trees and triangle order kept) */
    static const double ramp_v[] = {2, -3, 0.05, 2.5, -3, 0.05, 2.5, -1.5, 0.4, 2, -1.5, 0.4, 2.25, -2.2, 0.3};
    static const int ramp_t[] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
    carom_mesh_def md = carom_mesh_def_default();
    md.vertices = ramp_v;
    md.vertex_count = 5;
    md.triangles = ramp_t;
    md.triangle_count = 4;
    carom_body_def mb = carom_body_def_default();
    mb.type = CAROM_BODY_STATIC;
    mb.shape.type = CAROM_SHAPE_MESH;
    mb.mesh = &md;
    assert_false(carom_body_id_is_null(carom_body_create(w, &mb)));
    static double heights[5 * 6];
    for (int i = 0; i < 30; i++) heights[i] = 0.02 * (i % 6) + 0.03 * (i / 6) - 0.1;
    static const int holes[] = {7};
    carom_heightfield_def hd = carom_heightfield_def_default();
    hd.heights = heights;
    hd.rows = 5;
    hd.columns = 6;
    hd.cell_x = 0.3;
    hd.cell_y = 0.25;
    hd.holes = holes;
    hd.hole_count = 1;
    carom_body_def hb = carom_body_def_default();
    hb.type = CAROM_BODY_KINEMATIC;
    hb.shape.type = CAROM_SHAPE_HEIGHTFIELD;
    hb.heightfield = &hd;
    hb.position = vec(-2.5, 2.5, 0.05);
    hb.angular_velocity = vec(0, 0, 0.05);
    assert_false(carom_body_id_is_null(carom_body_create(w, &hb)));
    carom_compound_child kids[3] = {carom_compound_child_default(carom_shape_box(0.15, 0.1, 0.05)),
                                    carom_compound_child_default(carom_shape_sphere(0.08)),
                                    carom_compound_child_default(carom_shape_hull(tetra, 5))};
    kids[1].position = vec(0.2, 0, 0.05);
    kids[1].friction = 0.9;
    kids[1].restitution = 0.4;
    kids[2].position = vec(-0.2, 0.05, 0);
    kids[2].density = 3000;
    for (int i = 0; i < 3; i++) {
        carom_body_def cb = carom_body_def_default();
        cb.shape.type = CAROM_SHAPE_COMPOUND;
        cb.children = kids;
        cb.child_count = 3;
        cb.position = i < 2 ? vec(2.25, -2.6 + 0.7 * i, 0.9) : vec(-2.4, 2.6, 0.6);
        cb.angular_velocity = vec(0.2 * i, 0.4, 0);
        assert_false(carom_body_id_is_null(carom_body_create(w, &cb)));
    }
    /* a fast bullet at the wall */
    carom_body_def f = carom_body_def_default();
    f.shape = carom_shape_sphere(0.05);
    f.position = vec(0, 2, 1.5);
    f.linear_velocity = vec(60, 0, 0);
    f.restitution = 0.8;
    carom_body_create(w, &f);
    for (int s = 0; s < 40; s++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        *event_count += carom_world_get_events(w, &(const carom_contact_event *){0});
    }
    for (int i = 0; i < nd; i++) assert_int_equal(carom_body_destroy(w, doomed[i]), CAROM_OK);
    return w;
}

static void continue_bitwise(const char *preset, int use_avx2_env)
{
    (void)use_avx2_env;
    int events = 0;
    carom_world *a = mixed_scene(preset, &events);
    for (int s = 40; s < 137; s++) {
        assert_int_equal(carom_world_step(a, 1.0 / 60), CAROM_OK);
        events += carom_world_get_events(a, &(const carom_contact_event *){0});
    }
    carom_body_id ids[64];
    int n = carom_world_query_aabb(a, vec(-100, -100, -100), vec(100, 100, 100), ids, 64);
    assert_true(n > 30);
    assert_int_equal(carom_body_apply_force(a, ids[5], vec(3, 0, 40)), CAROM_OK);
    /* pending broadphase work: a body moved by hand and one just created */
    carom_vec3 p;
    carom_body_get_position(a, ids[9], &p);
    assert_int_equal(carom_body_set_position(a, ids[9], vec(p.x + 0.05, p.y, p.z + 0.02)), CAROM_OK);
    carom_body_def late = carom_body_def_default();
    late.shape = carom_shape_capsule(0.1, 0.1);
    late.position = vec(0.1, 0.1, 1.2);
    assert_false(carom_body_id_is_null(carom_body_create(a, &late)));
    carom_world_stats st = carom_world_stats_init();
    carom_world_get_stats(a, &st);
    assert_true(st.awake_bodies < carom_world_body_count(a) - 2); /* some asleep */
    assert_true(st.contacts > 10);

    snap s0 = take(a);
    char msg[256];
    carom_world *b = carom_world_restore(s0.data, s0.size, msg, sizeof msg);
    if (!b) fail_msg("restore: %s", msg);
    snap s1 = take(b);
    assert_same_snap(s0, s1, 137); /* the snapshot of the restored world is the snapshot */
    free(s1.data);
    for (int step = 138; step < 137 + 500; step++) {
        assert_int_equal(carom_world_step(a, 1.0 / 60), CAROM_OK);
        assert_int_equal(carom_world_step(b, 1.0 / 60), CAROM_OK);
        events += carom_world_get_events(a, &(const carom_contact_event *){0});
        assert_same_events(a, b, step);
        snap x = take(a), y = take(b);
        assert_same_snap(x, y, step);
        free(x.data);
        free(y.data);
    }
    print_message("%s: %zu-byte snapshot of %d bodies; 500 steps identical; %d events\n", preset, s0.size,
                  carom_world_body_count(a), events);
    assert_true(events > 20);
    /* ids survive: a destroyed id stays invalid, live ones keep their generation */
    for (int i = 0; i < n; i++) assert_int_equal(carom_body_is_valid(a, ids[i]), carom_body_is_valid(b, ids[i]));
    carom_body_def nb = carom_body_def_default();
    nb.position = vec(0, 0, 5);
    carom_body_id na = carom_body_create(a, &nb), nbid = carom_body_create(b, &nb);
    assert_true(carom_body_id_equal(na, nbid));
    free(s0.data);
    carom_world_destroy(a);
    carom_world_destroy(b);
}

/* Compounds tumbling onto a plane and a mesh ramp, bouncing (restitution
 * 0.5) so their pairs touch through one child, part, then land on another:
 * a world restored from the snapshot of any step 0..150 continues bit for
 * bit for 25 steps. (A composite pair's contact for its first child pair
 * kept the normal and material of an earlier manifold after its points
 * went; the snapshot rightly left them out, but the next step another child
 * touched, the record became state, and the original wrote its stale
 * normal where the restored world had none.) */
static void test_compounds_restore_at_any_step(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++) {
        carom_world *w = world_with(preset_def(presets[p]), 1, 0.6, 0.0); /* (the default body's material) */
        static const double ramp_v[] = {1, -1, 0.0, 3, -1, 0.0, 3, 1, 0.6, 1, 1, 0.6};
        static const int ramp_t[] = {0, 1, 2, 0, 2, 3};
        const carom_quat identity = {1, 0, 0, 0};
        assert_false(carom_body_id_is_null(scene_add_mesh(w, ramp_v, 4, ramp_t, 2, vec(0, 0, 0), identity)));
        carom_compound_child bell[2] = {carom_compound_child_default(carom_shape_sphere(0.1)),
                                        carom_compound_child_default(carom_shape_box(0.08, 0.08, 0.08))};
        bell[0].position = vec(-0.3, 0, 0);
        bell[1].position = vec(0.3, 0, 0);
        for (int i = 0; i < 6; i++) {
            bell[0].restitution = bell[1].restitution = 0.5;
            carom_body_def cb = carom_body_def_default();
            cb.shape.type = CAROM_SHAPE_COMPOUND;
            cb.children = bell;
            cb.child_count = 2;
            cb.position = vec(i < 3 ? -1.5 + 0.9 * i : 1.6 + 0.5 * (i - 3), i < 3 ? 0 : -0.4 + 0.4 * (i - 3), 0.9 + 0.2 * i);
            /* tilted (0.5 + 0.3 i) rad about an axis near y */
            double ax = 0.3 * i, ay = 1, az = 0.1, al = sqrt(ax * ax + ay * ay + az * az), half = 0.5 * (0.5 + 0.3 * i);
            cb.orientation.w = cos(half);
            cb.orientation.x = sin(half) * ax / al;
            cb.orientation.y = sin(half) * ay / al;
            cb.orientation.z = sin(half) * az / al;
            cb.angular_velocity = vec(1.5, -2.0 + 0.5 * i, 0.7);
            assert_false(carom_body_id_is_null(carom_body_create(w, &cb)));
        }
        /* the original's snapshot at every step */
        enum { LAST = 150, AHEAD = 25 };
        snap *orig = malloc(sizeof *orig * (LAST + AHEAD + 1));
        assert_non_null(orig);
        for (int step = 0; step <= LAST + AHEAD; step++) {
            orig[step] = take(w);
            assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        }
        for (int step = 0; step <= LAST; step++) {
            char msg[256];
            carom_world *r = carom_world_restore(orig[step].data, orig[step].size, msg, sizeof msg);
            if (!r) fail_msg("%s step %d: restore: %s", presets[p], step, msg);
            for (int k = 1; k <= AHEAD; k++) {
                assert_int_equal(carom_world_step(r, 1.0 / 60), CAROM_OK);
                snap x = take(r);
                if (x.size != orig[step + k].size || memcmp(x.data, orig[step + k].data, x.size) != 0)
                    fail_msg("%s: restored at step %d, its snapshot %d steps on differs from the original's", presets[p],
                             step, k);
                free(x.data);
            }
            carom_world_destroy(r);
        }
        for (int step = 0; step <= LAST + AHEAD; step++) free(orig[step].data);
        free(orig);
        carom_world_destroy(w);
    }
}

static void test_restore_continues_bitwise(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++) continue_bitwise(presets[p], 0);
}

static void count_event(void *context, const carom_contact_event *event)
{
    (void)event;
    ++*(int *)context;
}

typedef struct locked_probe { carom_world *w; const snap *s; int tries; } locked_probe;

static void restore_inside_step(void *context, const carom_contact_event *event)
{
    (void)event;
    locked_probe *p = context;
    assert_int_equal(carom_world_restore_into(p->w, p->s->data, p->s->size), CAROM_ERROR_LOCKED);
    p->tries++;
}

/* carom_world_restore_into: a world restored into continues bit for bit as
 * the snapshot's world (and as carom_world_restore's), whatever state it
 * held before, again and again (the spare's memory reused); the host's event
 * callback and the user data of the bodies the snapshot holds stay; a bad
 * snapshot is refused with the reader's reason and leaves the world exactly
 * as it was; inside the step it is LOCKED. */
static void test_restore_into(void **state)
{
    (void)state;
    int events = 0;
    carom_world *a = mixed_scene("default", &events);
    for (int s = 40; s < 137; s++) assert_int_equal(carom_world_step(a, 1.0 / 60), CAROM_OK);
    snap s0 = take(a);
    carom_world *other = mixed_scene("fast", &events); /* another state to restore from */
    for (int s = 0; s < 30; s++) assert_int_equal(carom_world_step(other, 1.0 / 60), CAROM_OK);
    snap s_other = take(other);
    /* the target: an empty world with a callback and a body with user data */
    carom_world_def wd = carom_world_def_default();
    int called = 0;
    wd.event_callback = count_event;
    wd.event_context = &called;
    carom_world *b = carom_world_create(&wd);
    assert_non_null(b);
    carom_body_id ids[64];
    int n = carom_world_query_aabb(a, vec(-100, -100, -100), vec(100, 100, 100), ids, 64);
    assert_true(n > 30);
    int tag = 7;
    char msg[256];
    carom_world *c = carom_world_restore(s0.data, s0.size, msg, sizeof msg);
    if (!c) fail_msg("restore: %s", msg);
    for (int round = 0; round < 4; round++) {
        /* another state in between (the spare then holds it) */
        const snap *first = round % 2 ? &s_other : &s0;
        assert_int_equal(carom_world_restore_into(b, first->data, first->size), CAROM_OK);
        snap x = take(b);
        assert_same_snap(*first, x, round);
        free(x.data);
        if (round == 1) assert_int_equal(carom_body_set_user_data(b, ids[3], &tag), CAROM_OK);
        assert_int_equal(carom_world_restore_into(b, s0.data, s0.size), CAROM_OK);
        x = take(b);
        assert_same_snap(s0, x, round);
        free(x.data);
    }
    assert_ptr_equal(carom_body_get_user_data(b, ids[3]), &tag); /* the same body in both states */
    assert_null(carom_body_get_user_data(b, ids[4]));
    /* bad snapshots: the reader's reason, the world unchanged */
    unsigned char *bad_copy = malloc(s_other.size);
    assert_non_null(bad_copy);
    memcpy(bad_copy, s_other.data, s_other.size);
    bad_copy[38] |= 0xf0; /* gravity x (the settings' first f64) made infinite or NaN */
    bad_copy[39] |= 0x7f;
    fix_checksum(bad_copy, s_other.size);
    const void *bad_data[] = {s_other.data, bad_copy, NULL, "CAROMSNP"};
    size_t bad_size[] = {s_other.size - 1, s_other.size, 10, 8};
    for (int k = 0; k < 4; k++) {
        carom_status st = carom_world_restore_into(b, bad_data[k], bad_size[k]);
        assert_int_equal(st, CAROM_ERROR_INVALID_ARGUMENT);
        assert_true(strncmp(carom_world_last_error(b), "world_restore_into: snapshot: ", 30) == 0);
        snap x = take(b);
        assert_same_snap(s0, x, -k);
        free(x.data);
    }
    print_message("refused: %s\n", carom_world_last_error(b));
    assert_int_equal(carom_world_restore_into(NULL, s0.data, s0.size), CAROM_ERROR_INVALID_ARGUMENT);
    /* and it steps on as carom_world_restore's world and the original do */
    for (int step = 138; step < 137 + 300; step++) {
        assert_int_equal(carom_world_step(a, 1.0 / 60), CAROM_OK);
        assert_int_equal(carom_world_step(b, 1.0 / 60), CAROM_OK);
        assert_int_equal(carom_world_step(c, 1.0 / 60), CAROM_OK);
        assert_same_events(a, b, step);
        snap x = take(a), y = take(b), z = take(c);
        assert_same_snap(x, y, step);
        assert_same_snap(x, z, step);
        free(x.data);
        free(y.data);
        free(z.data);
    }
    assert_true(called > 20); /* the host's callback kept */
    /* inside the step */
    carom_world_def wl = carom_world_def_default();
    locked_probe probe = {NULL, &s0, 0};
    wl.event_callback = restore_inside_step;
    wl.event_context = &probe;
    carom_world *l = carom_world_create(&wl);
    probe.w = l;
    assert_int_equal(carom_world_restore_into(l, s0.data, s0.size), CAROM_OK);
    for (int s = 0; s < 10; s++) assert_int_equal(carom_world_step(l, 1.0 / 60), CAROM_OK);
    assert_true(probe.tries > 0);
    snap after = take(l);
    carom_world *l2 = carom_world_restore(s0.data, s0.size, msg, sizeof msg);
    for (int s = 0; s < 10; s++) assert_int_equal(carom_world_step(l2, 1.0 / 60), CAROM_OK);
    snap ref = take(l2);
    assert_same_snap(ref, after, 10); /* the refused calls changed nothing */
    free(after.data);
    free(ref.data);
    carom_world_destroy(l2);
    print_message("restore_into: %d events reached the kept callback, %d refused inside the step\n", called, probe.tries);
    free(bad_copy);
    free(s0.data);
    free(s_other.data);
    carom_world_destroy(l);
    carom_world_destroy(a);
    carom_world_destroy(b);
    carom_world_destroy(c);
    carom_world_destroy(other);
}

static void test_empty_world_and_errors(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.gravity = vec(0, 1, -3);
    wd.substeps = 7;
    wd.hit_event_threshold = 2.5;
    wd.contact_reuse_distance = 3e-3;
    carom_world *w = carom_world_create(&wd);
    snap s = take(w);
    char msg[256];
    carom_world *r = carom_world_restore(s.data, s.size, msg, sizeof msg);
    assert_non_null(r);
    carom_world_def got = carom_world_def_default();
    carom_world_get_def(r, &got);
    assert_true(got.gravity.y == 1 && got.gravity.z == -3 && got.substeps == 7);
    assert_true(got.hit_event_threshold == 2.5 && got.contact_reuse_distance == 3e-3);
    assert_int_equal(carom_world_snapshot(NULL, NULL, 0), 0);
    assert_null(carom_world_restore(NULL, 10, msg, sizeof msg));
    assert_non_null(strstr(msg, "NULL"));
    /* a buffer too small: the size is returned, nothing claimed written */
    unsigned char small[16];
    assert_int_equal(carom_world_snapshot(w, small, sizeof small), s.size);
    free(s.data);
    carom_world_destroy(w);
    carom_world_destroy(r);
}

/* Rewrites the header's checksum after a change, so the reader's deeper
 * checks are exercised too (the same rule as the fuzz harness). */
static void fix_checksum(unsigned char *p, size_t n);

/* The writer puts a record straight into the buffer where its largest size
 * fits, else into a copy cut to the capacity: the bytes are the same either
 * way (capacity the size, and 4 KB more), a smaller capacity is never written
 * past (a canary after it) and still returns the size, and the coded
 * doubles' table-driven tag is their definition for every pattern of zero
 * bytes. */
static void test_snapshot_into_any_capacity(void **state)
{
    (void)state;
    assert_int_equal(snapshot_coded_tags_disagree(), 0);
    int events = 0;
    carom_world *w = mixed_scene("default", &events);
    snap s = take(w);
    size_t room = s.size + 4096;
    unsigned char *buf = malloc(room + 64);
    assert_non_null(buf);
    memset(buf, 0xa5, room + 64);
    assert_int_equal(carom_world_snapshot(w, buf, room), s.size);
    assert_memory_equal(buf, s.data, s.size);
    for (size_t k = s.size; k < room + 64; k++)
        if (buf[k] != 0xa5) fail_msg("byte %zu past the snapshot's %zu was written", k, s.size);
    for (size_t cap = 0; cap < s.size; cap += cap < 64 || cap + 2100 > s.size ? 1 : 97) {
        memset(buf, 0xa5, cap + 64);
        assert_int_equal(carom_world_snapshot(w, buf, cap), s.size);
        for (size_t k = cap; k < cap + 64; k++)
            if (buf[k] != 0xa5) fail_msg("capacity %zu: byte %zu written", cap, k);
    }
    free(buf);
    free(s.data);
    carom_world_destroy(w);
}

/* The reader takes a group of coded doubles only in the writer's one form
 * (docs/snapshot.md): tag 0 no bytes; 1..8 the low t bytes, the highest of
 * them nonzero, and not a value whose trailing zero bytes outnumber its
 * leading ones (that one is sent high); 9..15 the high 16 - t bytes, the
 * lowest nonzero, and its trailing zero bytes more than its leading ones; an
 * odd group's unused nibble 0; every value finite. Random tags and
 * payloads (bytes often zero), n = 1..4, read with room after them (the
 * inlined way) and cut to their length (the checked way): both agree with
 * that definition. */
static int tag_by_definition(uint64_t x)
{
    if (x == 0) return 0;
    int lead = 0, trail = 0;
    while (!((x >> (56 - 8 * lead)) & 0xff)) lead++;
    while (!((x >> (8 * trail)) & 0xff)) trail++;
    return trail > lead ? 8 + trail : 8 - lead;
}

static void test_coded_groups_one_form(void **state)
{
    (void)state;
    static const int len_of[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 7, 6, 5, 4, 3, 2, 1};
    unsigned seed = 777;
    int accepted = 0, refused = 0;
    for (int trial = 0; trial < 200000; trial++) {
        int n = 1 + trial % 4;
        unsigned char bytes[2 + 32 + 64];
        size_t at = (size_t)(n + 1) / 2;
        int ok = 1;
        memset(bytes, 0, sizeof bytes);
        for (int i = 0; i < n + (n & 1); i++) {
            seed = seed * 1103515245u + 12345u;
            int tag = (int)(seed >> 16) & 15;
            if (i == n) tag = (seed >> 20) % 8 ? 0 : tag; /* the unused nibble: mostly 0 */
            bytes[i / 2] |= (unsigned char)(tag << (4 * (i & 1)));
            if (i == n) { ok &= tag == 0; break; }
            uint64_t x = 0;
            for (int k = 0; k < len_of[tag]; k++) {
                seed = seed * 1103515245u + 12345u;
                unsigned b = (seed >> 16) & 3 ? (seed >> 8) & 0xff : 0; /* a quarter zero bytes, as well as any 0 drawn */
                bytes[at + (size_t)k] = (unsigned char)b;
                x |= (uint64_t)b << (8 * (tag <= 8 ? k : k + tag - 8));
            }
            at += (size_t)len_of[tag];
            ok &= tag_by_definition(x) == tag && ((x >> 52) & 0x7ff) != 0x7ff;
        }
        double out[4];
        size_t roomy = snapshot_coded_group_read(bytes, sizeof bytes, n, out);
        size_t cut = snapshot_coded_group_read(bytes, at, n, out);
        if ((roomy != 0) != ok || (cut != 0) != ok || (ok && (roomy != at || cut != at)))
            fail_msg("trial %d (n %d): the definition says %s, the reader took %zu and %zu bytes of %zu", trial, n,
                     ok ? "take" : "refuse", roomy, cut, at);
        if (ok) accepted++;
        else refused++;
    }
    print_message("coded groups: %d taken, %d refused, as defined\n", accepted, refused);
}

/* Varints likewise: 1 to 11 random bytes (continuation bits mostly set,
 * last bytes often 0), read with room (the one-load way) and cut to 9 bytes
 * or fewer (the checked way), against [lo, hi] ranges of every size, signed
 * and not: taken exactly when the bytes are one value's only encoding (no
 * needless last 0 byte, at most 64 bits) in range. */
static void test_varints_one_form(void **state)
{
    (void)state;
    unsigned seed = 4242;
    int accepted = 0, refused = 0;
    for (int trial = 0; trial < 200000; trial++) {
        unsigned char bytes[32];
        memset(bytes, 0, sizeof bytes);
        seed = seed * 1103515245u + 12345u;
        int n = 1 + (int)((seed >> 16) % 11);
        for (int k = 0; k < n; k++) {
            seed = seed * 1103515245u + 12345u;
            unsigned b = (seed >> 8) & 0x7f;
            if ((seed >> 20) % 4 == 0) b = 0;
            bytes[k] = (unsigned char)(b | (k + 1 < n ? 0x80 : 0));
        }
        seed = seed * 1103515245u + 12345u;
        int is_signed = (seed >> 16) & 1;
        int64_t hi = ((seed >> 17) & 1) ? INT32_MAX : (int64_t)1 << ((seed >> 18) % 31), lo = is_signed ? -hi : 0;
        /* the definition */
        uint64_t u = 0;
        int ok = 1;
        for (int k = 0; k < n; k++) {
            if (7 * k >= 64 || (k == 9 && (bytes[k] & 0x7f) > 1)) { ok = 0; break; }
            u |= (uint64_t)(bytes[k] & 0x7f) << (7 * k);
        }
        if (n > 1 && bytes[n - 1] == 0) ok = 0;
        int64_t v = is_signed ? (int64_t)(u >> 1) ^ -(int64_t)(u & 1) : (int64_t)u;
        if (ok && (v < lo || v > hi || (!is_signed && u > (uint64_t)INT64_MAX))) ok = 0;
        int got_roomy = 0, got_cut = 0;
        size_t roomy = snapshot_small_read(bytes, sizeof bytes, lo, hi, is_signed, &got_roomy);
        size_t cut = snapshot_small_read(bytes, (size_t)n < 9 ? (size_t)n : 9, lo, hi, is_signed, &got_cut);
        if (n > 9) cut = roomy; /* (cut short of the value: not a test of it) */
        else got_cut = got_roomy;
        if ((roomy != 0) != ok || (cut != 0) != ok || (ok && (roomy != (size_t)n || got_roomy != (int)v)))
            fail_msg("trial %d (%d bytes, [%lld, %lld]%s): the definition says %s, the reader took %zu and %zu bytes", trial, n,
                     (long long)lo, (long long)hi, is_signed ? " signed" : "", ok ? "take" : "refuse", roomy, cut);
        (void)got_cut;
        if (ok) accepted++;
        else refused++;
    }
    print_message("varints: %d taken, %d refused, as defined\n", accepted, refused);
}

static void test_bad_snapshots_refused(void **state)
{
    (void)state;
    int events = 0;
    carom_world *w = mixed_scene("default", &events);
    snap s = take(w);
    char msg[256];
    /* every truncation */
    for (size_t len = 0; len < s.size; len++) {
        unsigned char *copy = malloc(len ? len : 1);
        memcpy(copy, s.data, len);
        msg[0] = 0;
        carom_world *r = carom_world_restore(copy, len, msg, sizeof msg);
        if (r) fail_msg("a snapshot cut to %zu of %zu bytes was accepted", len, s.size);
        assert_true(strncmp(msg, "snapshot: ", 10) == 0 && strlen(msg) > 12);
        free(copy);
    }
    /* wrong version, foreign data */
    unsigned char *copy = malloc(s.size);
    memcpy(copy, s.data, s.size);
    /* the writer's checksum is the one docs/snapshot.md defines (fix_checksum) */
    fix_checksum(copy, s.size);
    assert_memory_equal(copy, s.data, s.size);
    assert_int_equal(copy[8], 8);
    copy[8] = 6; /* the format before the oldest one read (7: test_reads_format_7) */
    assert_null(carom_world_restore(copy, s.size, msg, sizeof msg));
    assert_non_null(strstr(msg, "version 6"));
    copy[8] = 9;
    assert_null(carom_world_restore(copy, s.size, msg, sizeof msg));
    assert_non_null(strstr(msg, "version 9"));
    memcpy(copy, "PNG\r\n\x1a\n\0", 8);
    assert_null(carom_world_restore(copy, s.size, msg, sizeof msg));
    assert_non_null(strstr(msg, "not a carom snapshot"));
    /* random byte flips: caught by the checksum, and with the checksum
     * rewritten by the structural checks (or accepted as a different valid
     * world, which must then step without trouble) */
    unsigned seed = 12345;
    int refused = 0, accepted = 0;
    for (int t = 0; t < 3000; t++) {
        memcpy(copy, s.data, s.size);
        int flips = 1 + t % 4;
        for (int f = 0; f < flips; f++) {
            seed = seed * 1103515245u + 12345u;
            size_t at = 32 + (seed >> 8) % (s.size - 32);
            copy[at] ^= (unsigned char)(1u << ((seed >> 4) & 7));
        }
        if (t % 2 == 0) {
            assert_null(carom_world_restore(copy, s.size, msg, sizeof msg));
            assert_non_null(strstr(msg, "checksum"));
            continue;
        }
        fix_checksum(copy, s.size);
        carom_world *r = carom_world_restore(copy, s.size, msg, sizeof msg);
        if (!r) { refused++; assert_true(strlen(msg) > 12); continue; }
        accepted++;
        /* one encoding per state: what was accepted snapshots back to exactly its bytes */
        snap again = take(r);
        if (again.size != s.size || memcmp(again.data, copy, s.size) != 0)
            fail_msg("flip trial %d: an accepted snapshot does not snapshot back to its own bytes", t);
        free(again.data);
        for (int k = 0; k < 3; k++) assert_int_equal(carom_world_step(r, 1.0 / 60), CAROM_OK);
        carom_world_destroy(r);
    }
    print_message("flips with the checksum rewritten: %d refused, %d accepted as another valid world\n", refused, accepted);
    free(copy);
    free(s.data);
    carom_world_destroy(w);
}

/* A format-7 snapshot (fuzz/corpus/snapshot/mixed_reversed_v7: the mixed
 * scene of test_order.c built in reverse, 60 steps, written by main d7f6059;
 * 92 of its 135 pairs have the higher id as body A, format 7's record bit
 * 131072) is still read: its pairs keep their body A, it snapshots as format
 * 8, that reads back to the same bytes, and the two worlds step on alike for
 * 120 steps. (Outside the test: that world stepped 120 steps snapshots to
 * the same bytes as the same scene's format-7 snapshot at step 180 read
 * back, so format 7 is read as it was written.) Byte flips in it with the
 * checksum rewritten are refused with a message or accepted as another
 * valid world. */
static void test_reads_format_7(void **state)
{
    (void)state;
    const char *root = getenv("CAROM_ROOT");
    char path[1024];
    snprintf(path, sizeof path, "%s/fuzz/corpus/snapshot/mixed_reversed_v7", root ? root : ".");
    FILE *f = fopen(path, "rb");
    if (!f) fail_msg("cannot open %s (run from the repository root or set CAROM_ROOT)", path);
    snap old;
    assert_int_equal(fseek(f, 0, SEEK_END), 0);
    old.size = (size_t)ftell(f);
    rewind(f);
    old.data = malloc(old.size);
    assert_non_null(old.data);
    assert_int_equal(fread(old.data, 1, old.size, f), old.size);
    fclose(f);
    assert_int_equal(old.data[8], 7);
    char msg[256];
    carom_world *a = carom_world_restore(old.data, old.size, msg, sizeof msg);
    if (!a) fail_msg("format 7: %s", msg);
    int swapped = 0;
    for (int i = 0; i < a->contacts.count; i++) swapped += a->contacts.items[i].id_a > a->contacts.items[i].id_b;
    assert_int_equal(swapped, 92);
    assert_int_equal(a->contacts.count, 135);
    snap s = take(a);
    assert_int_equal(s.data[8], 8);
    carom_world *b = carom_world_restore(s.data, s.size, msg, sizeof msg);
    if (!b) fail_msg("format 8: %s", msg);
    snap again = take(b);
    assert_same_snap(s, again, 0);
    free(again.data);
    for (int i = 1; i <= 120; i++) {
        assert_int_equal(carom_world_step(a, 1.0 / 60), CAROM_OK);
        assert_int_equal(carom_world_step(b, 1.0 / 60), CAROM_OK);
        snap x = take(a), y = take(b);
        assert_same_snap(x, y, i);
        assert_same_events(a, b, i);
        free(x.data);
        free(y.data);
    }
    unsigned char *copy = malloc(old.size);
    assert_non_null(copy);
    unsigned seed = 777;
    int refused = 0, accepted = 0;
    for (int t = 0; t < 600; t++) {
        memcpy(copy, old.data, old.size);
        for (int k = 0; k <= t % 3; k++) {
            seed = seed * 1103515245u + 12345u;
            copy[32 + (seed >> 8) % (old.size - 32)] ^= (unsigned char)(1u << ((seed >> 4) & 7));
        }
        fix_checksum(copy, old.size);
        carom_world *r = carom_world_restore(copy, old.size, msg, sizeof msg);
        if (!r) {
            refused++;
            assert_true(strncmp(msg, "snapshot: ", 10) == 0 && strlen(msg) > 12);
            continue;
        }
        accepted++;
        for (int k = 0; k < 3; k++) assert_int_equal(carom_world_step(r, 1.0 / 60), CAROM_OK);
        carom_world_destroy(r);
    }
    print_message("format-7 flips: %d refused, %d accepted as another valid world\n", refused, accepted);
    free(copy);
    free(s.data);
    free(old.data);
    carom_world_destroy(a);
    carom_world_destroy(b);
}

/* A snapshot cut inside its body records (header size and checksum
 * rewritten, so the reader gets that far) is refused naming the body whose
 * record it cuts: as the cut moves on, "body k", "body k + 1", ... each in
 * turn up to the last (the reader counts the name up per body, carrying across
 * 9 -> 10 and 99 -> 100). */
static void test_truncated_body_records_named(void **state)
{
    (void)state;
    enum { N = 120 };
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    unsigned seed = 99;
    for (int i = 0; i < N; i++) {
        carom_body_def b = carom_body_def_default();
        b.shape = carom_shape_sphere(0.25);
        double q[4];
        for (int k = 0; k < 4; k++) {
            seed = seed * 1664525u + 1013904223u;
            q[k] = (double)(seed >> 8) / 16777216.0 - 0.5;
        }
        double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        b.position = (carom_vec3){3.0 * i + q[0], 7.0 * (i % 5) + q[1], 2.0 + q[2]};
        b.orientation = (carom_quat){q[0] / l, q[1] / l, q[2] / l, q[3] / l};
        assert_true(carom_body_is_valid(w, carom_body_create(w, &b)));
    }
    snap s = take(w);
    unsigned char *copy = malloc(s.size);
    char msg[256];
    int last = -1;
    for (size_t len = 33; len < s.size; len++) {
        memcpy(copy, s.data, len);
        for (int k = 0; k < 8; k++) copy[16 + k] = (unsigned char)((uint64_t)len >> (8 * k));
        fix_checksum(copy, len);
        assert_null(carom_world_restore(copy, len, msg, sizeof msg));
        int body;
        if (sscanf(msg, "snapshot: truncated: body %d ", &body) != 1) continue;
        /* (the first cuts are refused before the records: too few bytes for the body count) */
        if (last >= 0 && body != last && body != last + 1) fail_msg("cut at %zu: \"%s\" after body %d", len, msg, last);
        last = body;
    }
    assert_int_equal(last, N - 1);
    free(copy);
    free(s.data);
    carom_world_destroy(w);
}

/* The checksum as docs/snapshot.md defines it. */
static void fix_checksum(unsigned char *p, size_t n)
{
    const unsigned char *q = p + 32;
    size_t m = n - 32, i = 0;
    uint64_t lane[4], h;
    for (int k = 0; k < 4; k++) lane[k] = 0x9e3779b97f4a7c15ULL ^ (uint64_t)m ^ ((uint64_t)k << 56);
    for (; i + 32 <= m; i += 32)
        for (int k = 0; k < 4; k++) {
            uint64_t v = 0;
            for (int b = 7; b >= 0; b--) v = (v << 8) | q[i + 8 * (size_t)k + (size_t)b];
            lane[k] = (lane[k] ^ v) * 0xff51afd7ed558ccdULL;
            lane[k] ^= lane[k] >> 29;
        }
    h = lane[0];
    for (int k = 1; k < 4; k++) {
        h = (h ^ lane[k]) * 0xff51afd7ed558ccdULL;
        h ^= h >> 29;
    }
    for (; i + 8 <= m; i += 8) {
        uint64_t v = 0;
        for (int k = 7; k >= 0; k--) v = (v << 8) | q[i + (size_t)k];
        h = (h ^ v) * 0xff51afd7ed558ccdULL;
        h ^= h >> 29;
    }
    for (; i < m; i++) {
        h = (h ^ q[i]) * 0xc4ceb9fe1a85ec53ULL;
        h ^= h >> 31;
    }
    for (int k = 0; k < 8; k++) p[24 + k] = (unsigned char)(h >> (8 * k));
}

/* Restores s, checks its snapshot is s again, and steps the two worlds side
 * by side: every later snapshot byte-identical. */
static void assert_restores_and_continues(carom_world *w, int steps, const char *what)
{
    snap s = take(w);
    char msg[256];
    carom_world *r = carom_world_restore(s.data, s.size, msg, sizeof msg);
    if (!r) fail_msg("%s: restore refused: %s", what, msg);
    snap again = take(r);
    assert_same_snap(s, again, 0);
    free(again.data);
    for (int k = 1; k <= steps; k++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        assert_int_equal(carom_world_step(r, 1.0 / 60), CAROM_OK);
        snap a = take(w), b = take(r);
        assert_same_snap(a, b, k);
        free(a.data);
        free(b.data);
    }
    free(s.data);
    carom_world_destroy(r);
}

/* A step does not stop a body at the 1e12 m the calls allow: fuzz_api found
 * one that fell past z = -1e12 and whose snapshot the reader refused ("body 0
 * is beyond 1e12 m"). A plane-locked body at (1e12, 1e12, 0) with normal
 * (1, 1, 0) has plane offset 1.41e12, also refused before. Both restore and
 * continue bitwise; beyond the state bound (1e18 m) is refused. */
static void test_bodies_past_the_position_range(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    carom_body_def b = carom_body_def_default();
    b.shape = carom_shape_sphere(0.5);
    b.position = vec(3, -1e12, -1e12);
    b.linear_velocity = vec(0, -2000, -3000);
    carom_body_id fall = carom_body_create(w, &b);
    carom_body_def p = carom_body_def_default();
    p.shape = carom_shape_box(0.5, 0.5, 0.5);
    p.position = vec(1e12, 1e12, 0);
    p.lock_to_plane = 1;
    p.plane_normal = vec(1, 1, 0);
    p.linear_velocity = vec(4000, 4000, 0);
    carom_body_create(w, &p);
    for (int k = 0; k < 3; k++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    carom_vec3 at;
    assert_int_equal(carom_body_get_position(w, fall, &at), CAROM_OK);
    assert_true(at.z < -1e12 && at.y < -1e12);
    assert_restores_and_continues(w, 20, "bodies past 1e12 m");
    carom_world_destroy(w);
}

/* A contact's friction, restitution and rolling resistance are predicted as
 * material.c mixes them (every combine mode, compound children's own
 * materials): the worlds restore and continue bitwise, with and without. */
static void test_contact_materials_predicted(void **state)
{
    (void)state;
    size_t size[2];
    for (int with = 0; with < 2; with++) {
        carom_world_def wd = carom_world_def_default();
        carom_world *w = carom_world_create(&wd);
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(0, 0, 1, 0);
        carom_material ground = carom_material_default();
        ground.friction = 0.9;
        ground.restitution = 0.1;
        ground.rolling_resistance = 0.05;
        ground.combine = CAROM_COMBINE_AVERAGE;
        if (with) g.material = &ground;
        carom_body_create(w, &g);
        for (int i = 0; i < 30; i++) {
            carom_material m = carom_material_default();
            m.friction = 0.2 + 0.03 * i;
            m.restitution = 0.01 * i;
            m.rolling_resistance = 0.01 * (i % 7);
            m.combine = (carom_combine_mode)(i % 6);
            carom_body_def b = carom_body_def_default();
            b.shape = i % 3 == 0 ? carom_shape_sphere(0.2) : i % 3 == 1 ? carom_shape_box(0.2, 0.2, 0.2) : carom_shape_capsule(0.1, 0.2);
            b.position = vec(0.45 * (i % 6), 0.45 * (i / 6), 0.21);
            if (with) b.material = &m;
            carom_body_create(w, &b);
        }
        if (with) { /* a compound whose children have their own materials */
            carom_material cm[2] = {carom_material_default(), carom_material_default()};
            cm[0].friction = 0.3;
            cm[0].rolling_resistance = 0.2;
            cm[0].combine = CAROM_COMBINE_MAX;
            cm[1].restitution = 0.4;
            cm[1].combine = CAROM_COMBINE_MULTIPLY;
            carom_compound_child ch[2];
            for (int k = 0; k < 2; k++) {
                ch[k] = carom_compound_child_default(carom_shape_box(0.2, 0.2, 0.2));
                ch[k].position = vec(0.4 * k, 0, 0);
                ch[k].material = &cm[k];
            }
            carom_body_def b = carom_body_def_default();
            b.shape.type = CAROM_SHAPE_COMPOUND;
            b.children = ch;
            b.child_count = 2;
            b.position = vec(-1, 0, 0.21);
            carom_body_create(w, &b);
        }
        for (int k = 0; k < 30; k++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        carom_world_get_stats(w, &st);
        assert_true(st.contacts >= 30);
        size[with] = carom_world_snapshot(w, NULL, 0);
        assert_restores_and_continues(w, 30, with ? "materials" : "no materials");
        carom_world_destroy(w);
    }
    printf("materials: %zu bytes without, %zu with\n", size[0], size[1]);
}

/* snapshot_field_bytes (bench/snapshot.c prints it) accounts for every byte
 * of the snapshot, at every preset, and writes nothing itself. */
static void test_field_bytes_add_up(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++) {
        int events = 0;
        carom_world *w = mixed_scene(presets[p], &events);
        snap s = take(w);
        size_t bytes[SNAP_FIELD_COUNT], total = 0;
        const char *names[SNAP_FIELD_COUNT];
        assert_int_equal(snapshot_field_bytes(w, bytes, names), s.size);
        for (int f = 0; f < SNAP_FIELD_COUNT; f++) {
            assert_non_null(names[f]);
            total += bytes[f];
        }
        if (total != s.size) fail_msg("%s: the fields hold %zu of %zu bytes", presets[p], total, s.size);
        assert_true(bytes[SNAP_FIELD_point_local] > 0 && bytes[SNAP_FIELD_contact_header] > 0);
        snap again = take(w);
        assert_same_snap(s, again, 0);
        free(s.data);
        free(again.data);
        carom_world_destroy(w);
    }
}

/* The restore path's pair map, built at once in the order of the contacts'
 * home slots: every contact found at its index by its pair in either order,
 * whatever the count (the map doubles through several sizes), its bodies
 * kept in the order given (body A first), and a repeated pair or sub named
 * by the later of the two. */
/* The hull bodies of a restored world share their class's hull (each
 * restore used to clone it per body): one hull, held by every body of the
 * class (shares = bodies - 1), that outlives the bodies destroyed before the
 * rest and is freed with the last (ASan: no double free, no leak, no read
 * after free). The restored world and the original continue bit for bit
 * with hull bodies destroyed in both, and restore_into's spare gives its
 * holds back when it is read into again. */
static int hull_holders(const carom_world *w, const hull **shared)
{
    int n = 0;
    *shared = NULL;
    for (int i = 0; i < w->bodies.count; i++) {
        const shape *sh = &w->bodies.shapes[i];
        if (sh->type != SHAPE_HULL) continue;
        if (!*shared) *shared = sh->hull;
        if (sh->hull != *shared) fail_msg("body %d has a hull of its own", i);
        n++;
    }
    return n;
}

static void test_restored_hulls_shared(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *a = carom_world_create(&wd);
    assert_non_null(a);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(a, &g);
    static const double tetra[] = {0, 0, 0, 0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3, 0.2, 0.2, 0.2};
    carom_body_id hulls[6];
    for (int k = 0; k < 8; k++) {
        carom_body_def b = carom_body_def_default();
        b.shape = k < 6 ? carom_shape_hull(tetra, 5) : carom_shape_box(0.2, 0.2, 0.2);
        b.position = vec(0.5 * k, 0.1 * (k % 3), 0.2 + 0.4 * (k % 2));
        carom_body_id id = carom_body_create(a, &b);
        assert_false(carom_body_id_is_null(id));
        if (k < 6) hulls[k] = id;
    }
    for (int k = 0; k < 30; k++) assert_int_equal(carom_world_step(a, 1.0 / 60), CAROM_OK);
    snap s0 = take(a);
    char msg[256];
    carom_world *b = carom_world_restore(s0.data, s0.size, msg, sizeof msg);
    if (!b) fail_msg("restore: %s", msg);
    const hull *shared;
    assert_int_equal(hull_holders(b, &shared), 6);
    assert_int_equal(shared->shares, 5);
    /* restored into, twice (the second reads into the first's spare) */
    carom_world *c = carom_world_restore(s0.data, s0.size, msg, sizeof msg);
    if (!c) fail_msg("restore: %s", msg);
    for (int k = 0; k < 2; k++) assert_int_equal(carom_world_restore_into(c, s0.data, s0.size), CAROM_OK);
    assert_int_equal(hull_holders(c, &shared), 6);
    assert_int_equal(shared->shares, 5);
    /* hull bodies destroyed, the first and the last created */
    carom_world *worlds[3] = {a, b, c};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(carom_body_destroy(worlds[k], hulls[0]), CAROM_OK);
        assert_int_equal(carom_body_destroy(worlds[k], hulls[5]), CAROM_OK);
    }
    assert_int_equal(hull_holders(b, &shared), 4);
    assert_int_equal(shared->shares, 3);
    for (int step = 0; step < 120; step++) {
        for (int k = 0; k < 3; k++) assert_int_equal(carom_world_step(worlds[k], 1.0 / 60), CAROM_OK);
        snap sa = take(a), sb = take(b), sc = take(c);
        assert_same_snap(sa, sb, step);
        assert_same_snap(sa, sc, step);
        free(sa.data);
        free(sb.data);
        free(sc.data);
    }
    for (int k = 1; k < 5; k++) assert_int_equal(carom_body_destroy(b, hulls[k]), CAROM_OK);
    assert_int_equal(hull_holders(b, &shared), 0);
    for (int k = 0; k < 3; k++) carom_world_destroy(worlds[k]);
    free(s0.data);
}

static void test_restored_pair_map(void **state)
{
    (void)state;
    const int counts[] = {0, 1, 31, 32, 33, 1000, 5000};
    for (int t = 0; t < 7; t++) {
        int n = counts[t];
        contact_set cs;
        assert_true(contact_set_init(&cs));
        assert_true(contact_set_reserve(&cs, n));
        for (int i = 0; i < n; i++) {
            int a = (i * 7919) % 3001, b = 3001 + i / 3; /* distinct pairs, in no order */
            assert_int_equal(contact_append(&cs, b, a, (uint32_t)(i % 3)), i);
        }
        int repeated = 0;
        assert_true(contact_set_index(&cs, &repeated));
        assert_int_equal(repeated, -1);
        for (int i = 0; i < n; i++) {
            int a = (i * 7919) % 3001, b = 3001 + i / 3;
            assert_int_equal(contact_find_sub(&cs, a, b, (uint32_t)(i % 3)), i);
            assert_int_equal(contact_find_sub(&cs, b, a, (uint32_t)(i % 3)), i);
            assert_int_equal(cs.items[i].id_a, b); /* kept as given: body A first (collision.c's rank) */
            assert_int_equal(cs.items[i].id_b, a);
        }
        assert_int_equal(contact_find_sub(&cs, 0, 3001, 7), -1);
        if (n >= 31) { /* a copy of contact 5 appended (its bodies swapped: the same pair), then one of contact 2 with another sub (not a repeat) */
            assert_int_equal(contact_append(&cs, cs.items[5].id_b, cs.items[5].id_a, cs.items[5].sub), n);
            assert_int_equal(contact_append(&cs, cs.items[2].id_a, cs.items[2].id_b, cs.items[2].sub + 10), n + 1);
            assert_true(contact_set_index(&cs, &repeated));
            assert_int_equal(repeated, n);
            assert_int_equal(contact_find_sub(&cs, cs.items[2].id_a, cs.items[2].id_b, cs.items[2].sub + 10), n + 1);
        }
        contact_set_free(&cs);
    }
}

/* A heap at rest on a slope and on the ground: a box on a 20 degree slope
 * (friction 0.6 > tan 20 deg, so static friction holds it), a 3-box stack,
 * a sphere, capsule, cylinder and hull. Steps until every body sleeps (at
 * most 1200). slope/top: the slope box and the stack's top box. */
static carom_world *sleeping_heap(carom_body_id *slope, carom_body_id *top)
{
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    const double tilt = 20.0 * PI_ / 180.0;
    g.shape = carom_shape_box(2, 2, 0.1);
    g.position = vec(-4, 0, 1);
    g.orientation.w = cos(tilt / 2);
    g.orientation.y = sin(tilt / 2);
    carom_body_create(w, &g);
    carom_body_def b = carom_body_def_default();
    b.shape = carom_shape_box(0.2, 0.2, 0.2);
    b.orientation = g.orientation;
    /* on the slope's top face, 1 cm above it */
    b.position = vec(-4 + 0.31 * sin(tilt), 0, 1 + 0.31 * cos(tilt));
    *slope = carom_body_create(w, &b);
    b.orientation.w = 1;
    b.orientation.x = b.orientation.y = b.orientation.z = 0;
    for (int k = 0; k < 3; k++) {
        b.position = vec(2, 0, 0.2 + 0.4 * k + 0.001 * k);
        *top = carom_body_create(w, &b);
    }
    static const double tetra[] = {0, 0, 0, 0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3, 0.2, 0.2, 0.2};
    const carom_shape_def round[] = {carom_shape_sphere(0.2), carom_shape_capsule(0.1, 0.2), carom_shape_cylinder(0.15, 0.1),
                                     carom_shape_hull(tetra, 5)};
    carom_material mat = carom_material_default();
    mat.rolling_resistance = 0.3; /* round bodies come to rest */
    for (int k = 0; k < 4; k++) {
        carom_body_def r = carom_body_def_default();
        r.shape = round[k];
        r.material = &mat;
        r.position = vec(0.6 * k, 2, 0.3);
        carom_body_create(w, &r);
    }
    carom_world_stats st = carom_world_stats_init();
    for (int k = 0; k < 1200; k++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_world_get_stats(w, &st);
        if (st.awake_bodies == 0) break;
    }
    if (st.awake_bodies != 0) fail_msg("%d bodies still awake after 1200 steps", st.awake_bodies);
    return w;
}

/* When an island falls asleep its pairs keep only what the bodies' state
 * reproduces (collision.c, world_settle_contacts): the snapshot writes no
 * reuse pose, gap, A-frame normal, cache normal, friction basis or fat
 * bounds for it. Woken, the heap holds still (the box on the slope does not
 * slip: its friction impulses were re-expressed, not dropped), and a world
 * restored from the sleeping heap's snapshot wakes and continues bit for bit
 * with the original. */
static void test_sleeping_pairs_settled(void **state)
{
    (void)state;
    carom_body_id slope, top;
    carom_world *w = sleeping_heap(&slope, &top);
    /* a pair whose normal holds still keeps the basis the solver first built
     * from it, the one a settled pair gets: turn the slope box's by 60
     * degrees about the normal (its impulses re-expressed in it), wake it
     * and let it fall asleep again (the basis is kept meanwhile) */
    int slope_contact = contact_find(&w->contacts, 1, (int)slope.index1 - 1);
    assert_true(slope_contact >= 0);
    {
        contact_data *d = CONTACT_DATA(&w->contacts, slope_contact);
        assert_true(d->m.count > 0);
        vec3 n = d->m.normal, t1 = d->tangent1, t2 = v3_cross(n, t1);
        vec3 u1 = v3_add(v3_scale(t1, cos(PI_ / 3)), v3_scale(t2, sin(PI_ / 3))), u2 = v3_cross(n, u1);
        for (int k = 0; k < d->m.count; k++) {
            double *ti = d->state[k].tangent_impulse;
            vec3 j = v3_add(v3_scale(t1, ti[0]), v3_scale(t2, ti[1]));
            ti[0] = v3_dot(j, u1);
            ti[1] = v3_dot(j, u2);
        }
        d->tangent1 = u1;
        assert_int_equal(carom_body_set_awake(w, slope, 1), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        int k = 0;
        do {
            assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
            carom_world_get_stats(w, &st);
        } while (st.awake_bodies > 0 && ++k < 600);
        assert_int_equal(st.awake_bodies, 0);
        slope_contact = contact_find(&w->contacts, 1, (int)slope.index1 - 1);
        assert_true(slope_contact >= 0);
        d = CONTACT_DATA(&w->contacts, slope_contact);
        vec3 rest = contact_rest_basis(d->m.normal);
        assert_memory_equal(&d->tangent1, &rest, sizeof rest);
    }
    /* the rest state to 2^-30 (lengths) and 28 significant bits (impulses) */
    for (int i = 0; i < w->contacts.count; i++) {
        const contact_data *d = CONTACT_DATA(&w->contacts, i);
        for (int k = 0; k < d->m.count; k++) {
            const contact_point_state *st = &d->state[k];
            double v[4] = {st->local_a.x, st->local_a.y, st->local_a.z, st->separation};
            for (int j = 0; j < 4; j++)
                if (ldexp(v[j], 30) != nearbyint(ldexp(v[j], 30))) fail_msg("contact %d point %d: %.17g not a multiple of 2^-30", i, k, v[j]);
            double im[3] = {st->normal_impulse, st->tangent_impulse[0], st->tangent_impulse[1]};
            for (int j = 0; j < 3; j++) {
                uint64_t u;
                memcpy(&u, &im[j], 8);
                if (u & ((1u << 24) - 1)) fail_msg("contact %d point %d: impulse %.17g has more than 28 significant bits", i, k, im[j]);
            }
        }
    }
    for (int i = 0; i < w->bodies.count; i++) {
        vec3 c = w->bodies.center[i];
        if (w->bodies.type[i] == CAROM_BODY_DYNAMIC &&
            (ldexp(c.x, 30) != nearbyint(ldexp(c.x, 30)) || ldexp(c.z, 30) != nearbyint(ldexp(c.z, 30))))
            fail_msg("body %d: its centre is not on the 2^-30 m grid", i);
    }
    size_t bytes[SNAP_FIELD_COUNT];
    const char *names[SNAP_FIELD_COUNT];
    snapshot_field_bytes(w, bytes, names);
    const int settled[] = {SNAP_FIELD_contact_rel_position, SNAP_FIELD_contact_rel_rotation, SNAP_FIELD_contact_gap,
                           SNAP_FIELD_contact_reach, SNAP_FIELD_contact_normal_a, SNAP_FIELD_contact_cache_normal,
                           SNAP_FIELD_body_fat, SNAP_FIELD_point_world, SNAP_FIELD_contact_basis,
                           SNAP_FIELD_body_collided};
    for (int k = 0; k < (int)(sizeof settled / sizeof settled[0]); k++)
        if (bytes[settled[k]]) fail_msg("a sleeping heap writes %zu bytes of %s", bytes[settled[k]], names[settled[k]]);
    assert_true(bytes[SNAP_FIELD_point_local] > 0 && bytes[SNAP_FIELD_point_normal_impulse] > 0);
    {
        /* the settled friction impulses still hold the box on the slope: the
         * warm-start impulses (per sub-step) times the sub-steps over dt are
         * the contact force, m g cos 20 deg along the normal and m g sin 20
         * deg up the slope */
        const double tilt = 20.0 * PI_ / 180.0, m = 1000.0 * 0.4 * 0.4 * 0.4;
        const contact_data *d = CONTACT_DATA(&w->contacts, slope_contact);
        assert_true(d->m.count > 0);
        vec3 n = d->m.normal, t1 = d->tangent1, t2 = v3_cross(n, t1), ft = v3(0, 0, 0);
        double fn = 0, scale = w->def.substeps * 60.0;
        for (int k = 0; k < d->m.count; k++) {
            fn += d->state[k].normal_impulse * scale;
            ft = v3_add(ft, v3_scale(v3_add(v3_scale(t1, d->state[k].tangent_impulse[0]), v3_scale(t2, d->state[k].tangent_impulse[1])), scale));
        }
        /* A is the slope (id 1); the impulses are those on B, the box */
        vec3 up_slope = v3(-cos(tilt), 0, sin(tilt));
        EXPECT_NEAR(fn, m * G * cos(tilt), 0.01 * m * G, "settled normal force (N)");
        EXPECT_NEAR(v3_dot(ft, up_slope), m * G * sin(tilt), 0.01 * m * G, "settled friction force up the slope (N)");
        EXPECT_NEAR(v3_len(ft), m * G * sin(tilt), 0.01 * m * G, "settled friction force (N)");
    }
    snap s = take(w);
    char msg[256];
    carom_world *r = carom_world_restore(s.data, s.size, msg, sizeof msg);
    if (!r) fail_msg("restore refused: %s", msg);
    carom_vec3 p0, t0;
    assert_int_equal(carom_body_get_position(w, slope, &p0), CAROM_OK);
    assert_int_equal(carom_body_get_position(w, top, &t0), CAROM_OK);
    assert_int_equal(carom_body_set_awake(w, slope, 1), CAROM_OK);
    assert_int_equal(carom_body_set_awake(w, top, 1), CAROM_OK);
    assert_int_equal(carom_body_set_awake(r, slope, 1), CAROM_OK);
    assert_int_equal(carom_body_set_awake(r, top, 1), CAROM_OK);
    for (int k = 1; k <= 240; k++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        assert_int_equal(carom_world_step(r, 1.0 / 60), CAROM_OK);
        snap a = take(w), c = take(r);
        assert_same_snap(a, c, k);
        free(a.data);
        free(c.data);
        if (k == 1 || k == 240) {
            carom_vec3 p, t;
            assert_int_equal(carom_body_get_position(w, slope, &p), CAROM_OK);
            assert_int_equal(carom_body_get_position(w, top, &t), CAROM_OK);
            double slip = sqrt((p.x - p0.x) * (p.x - p0.x) + (p.y - p0.y) * (p.y - p0.y) + (p.z - p0.z) * (p.z - p0.z));
            double sway = sqrt((t.x - t0.x) * (t.x - t0.x) + (t.y - t0.y) * (t.y - t0.y) + (t.z - t0.z) * (t.z - t0.z));
            print_message("woken %d steps: slope box moved %.3g m, stack top %.3g m\n", k, slip, sway);
            /* static friction holds the box: no slip beyond the contact's
             * micrometre creep, and the stack stays where it slept */
            assert_true(slip < 1e-4);
            assert_true(sway < 1e-4);
        }
    }
    free(s.data);
    carom_world_destroy(r);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_empty_world_and_errors),
        cmocka_unit_test(test_restore_continues_bitwise),
        cmocka_unit_test(test_compounds_restore_at_any_step),
        cmocka_unit_test(test_restore_into),
        cmocka_unit_test(test_snapshot_into_any_capacity),
        cmocka_unit_test(test_coded_groups_one_form),
        cmocka_unit_test(test_varints_one_form),
        cmocka_unit_test(test_bad_snapshots_refused),
        cmocka_unit_test(test_reads_format_7),
        cmocka_unit_test(test_truncated_body_records_named),
        cmocka_unit_test(test_bodies_past_the_position_range),
        cmocka_unit_test(test_contact_materials_predicted),
        cmocka_unit_test(test_field_bytes_add_up),
        cmocka_unit_test(test_restored_pair_map),
        cmocka_unit_test(test_restored_hulls_shared),
        cmocka_unit_test(test_sleeping_pairs_settled),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
