/* test_collision.c - the collision stage: feature ids stay stable while the same features
 * touch, kept manifolds match freshly computed ones, pairs skipped as apart
 * really are apart. */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include <stdarg.h>
#include <stdlib.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "world.h"
#include "compound.h"

#include "helpers.h"

/* Resting boxes keep the same 4 contact features for 600 steps. */
static void test_feature_ids_stable(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.enable_sleep = 0;
    carom_world *w = world_with(wd, 1, 0.6, 0.0);
    carom_body_id lower = add_box(w, 0, 0, 0.5, 0.5, 1.0, 0.6);
    carom_body_id upper = add_box(w, 0, 0, 1.5, 0.5, 1.0, 0.6);
    step_n(w, 5, DT);
    int ia = (int)lower.index1 - 1, ib = (int)upper.index1 - 1;
    int ci = contact_find(&w->contacts, ia, ib);
    assert_true(ci >= 0);
    uint32_t ids[4];
    assert_int_equal(w->contacts.data[ci].m.count, 4);
    for (int j = 0; j < 4; j++) ids[j] = w->contacts.data[ci].m.points[j].id;
    for (int s = 0; s < 600; s++) {
        step_n(w, 1, DT);
        ci = contact_find(&w->contacts, ia, ib);
        assert_true(ci >= 0);
        const manifold *m = &w->contacts.data[ci].m;
        assert_int_equal(m->count, 4);
        for (int j = 0; j < 4; j++) assert_int_equal(m->points[j].id, ids[j]);
    }
    carom_world_destroy(w);
}

/* A kept manifold (contact_reuse_distance) against a fresh one, every step: a
 * box turned 0.3 rad drifts, rises, tilts and spins slowly over a frictionless
 * static slab, so its manifold is kept for some steps and recomputed at others; kept
 * separations must match the narrowphase's to well under a micrometre and
 * points to the reuse distance. */
static void test_kept_manifolds_match_fresh(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.enable_sleep = 0;
    wd.gravity.z = 0.0; /* no load: the box rests exactly, so only the drift moves it */
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_box(5, 5, 0.5);
    g.position = vec(0, 0, -0.5);
    g.friction = 0.0;
    carom_body_create(w, &g);
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_box(0.5, 0.4, 0.3);
    d.position = vec(0, 0, 0.3); /* touching */
    carom_quat q = {cos(0.15), 0, 0, sin(0.15)};
    d.orientation = q;
    d.friction = 0.0;
    d.linear_velocity = vec(0.0005, 0.0003, 0.0002);
    d.angular_velocity = vec(0.0005, 0, 0.002);
    carom_body_id box = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(box));
    int kept = 0, fresh = 0;
    xform last_rel = {v3(1e9, 0, 0), q_identity()};
    for (int step = 0; step < 240; step++) {
        /* the manifold a step solves with belongs to the poses it starts from */
        body_store *bs = &w->bodies;
        xform pose[2] = {body_xform(bs, 0), body_xform(bs, 1)};
        step_n(w, 1, DT);
        /* hold the drift: the solver only pushes along the normal */
        carom_body_set_linear_velocity(w, box, vec(0.0005, 0.0003, 0.0002));
        carom_body_set_angular_velocity(w, box, vec(0.0005, 0, 0.002));
        assert_int_equal(w->contacts.count, 1);
        contact *c = &w->contacts.items[0];
        contact_data *cd = &w->contacts.data[0];
        assert_true(cd->m.count == 4);
        int same = memcmp(&c->rel_pose, &last_rel, sizeof last_rel) == 0;
        if (same) kept++; else fresh++;
        last_rel = c->rel_pose;
        int sa = bs->ids[c->id_a].slot, sb = bs->ids[c->id_b].slot;
        collide_cache cache = c->cache;
        manifold m;
        collide(&bs->shapes[sa], pose[sa], &bs->shapes[sb], pose[sb], wd.speculative_distance, &cache, &m);
        assert_int_equal(m.count, cd->m.count);
        assert_true(v3_len(v3_sub(m.normal, cd->m.normal)) < 1e-9);
        for (int i = 0; i < cd->m.count; i++) {
            int j = 0;
            while (j < m.count && m.points[j].id != cd->m.points[i].id) j++;
            assert_true(j < m.count);
            double ds = fabs(m.points[j].separation - cd->m.points[i].separation);
            double dp = v3_len(v3_sub(m.points[j].point, cd->m.points[i].point));
            if (!(ds < 1e-7 && dp <= wd.contact_reuse_distance)) {
                print_error("step %d point %d: separation off by %.3g m, point by %.3g m\n", step, i, ds, dp);
                fail();
            }
        }
    }
    print_message("manifold kept %d steps, computed %d\n", kept, fresh);
    assert_true(kept > 120 && fresh > 20);
    carom_world_destroy(w);
}

/* Pairs the collision stage left without a manifold (bounds apart, or known
 * apart from an earlier step and not moved enough since) must have none when
 * computed afresh: bodies of every shape drift and tumble slowly in a closed
 * room without gravity, and every step each empty pair is checked against
 * the narrowphase at the poses the step started from. */
static void test_skipped_pairs_are_apart(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.enable_sleep = 0;
    wd.gravity.z = 0.0;
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    const double walls[6][4] = {{1, 0, 0, -3}, {-1, 0, 0, -3}, {0, 1, 0, -3}, {0, -1, 0, -3}, {0, 0, 1, -3}, {0, 0, -1, -3}};
    for (int i = 0; i < 6; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(walls[i][0], walls[i][1], walls[i][2], walls[i][3]);
        carom_body_create(w, &g);
    }
    const double pts[24] = {0.3, 0, 0, -0.3, 0, 0, 0, 0.25, 0, 0, -0.25, 0, 0, 0, 0.35, 0, 0, -0.35, 0.1, 0.1, 0.1, -0.1, 0.1, -0.1};
    uint64_t r = 0x5EEDF00DULL;
    int n = 0;
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 5; j++)
            for (int k = 0; k < 5; k++) {
                carom_body_def d = carom_body_def_default();
                d.position = vec(-2.0 + i, -2.0 + j, -2.0 + k);
                switch (n % 5) {
                case 0: d.shape = carom_shape_box(0.35, 0.25, 0.3); break;
                case 1: d.shape = carom_shape_sphere(0.35); break;
                case 2: d.shape = carom_shape_capsule(0.2, 0.25); break;
                case 3: d.shape = carom_shape_cylinder(0.3, 0.25); break;
                default: d.shape = carom_shape_hull(pts, 8); break;
                }
                double u[6];
                for (int q = 0; q < 6; q++) {
                    r = r * 6364136223846793005ULL + 1442695040888963407ULL;
                    u[q] = (double)(r >> 11) / 9007199254740992.0 - 0.5;
                }
                d.linear_velocity = vec(0.6 * u[0], 0.6 * u[1], 0.6 * u[2]);
                d.angular_velocity = vec(2 * u[3], 2 * u[4], 2 * u[5]);
                d.restitution = 0.5;
                assert_false(carom_body_id_is_null(carom_body_create(w, &d)));
                n++;
            }
    int checked = 0, apart_kept = 0;
    for (int step = 0; step < 600; step++) {
        body_store *bs = &w->bodies;
        xform pose[256];
        assert_true(bs->count <= 256);
        for (int i = 0; i < bs->count; i++) pose[i] = body_xform(bs, i);
        step_n(w, 1, DT);
        for (int i = 0; i < w->contacts.count; i++) {
            const contact *c = &w->contacts.items[i];
            if (c->flags & CONTACT_TOUCHING) continue;
            int sa = bs->ids[c->id_a].slot, sb = bs->ids[c->id_b].slot;
            collide_cache cache = c->cache;
            manifold m;
            collide(&bs->shapes[sa], pose[sa], &bs->shapes[sb], pose[sb], wd.speculative_distance, &cache, &m);
            if (m.count != 0) {
                print_error("step %d: pair %d-%d skipped but has %d points (separation %.4g)\n", step, sa, sb, m.count,
                            m.points[0].separation);
                fail();
            }
            checked++;
            if (c->flags & CONTACT_APART) apart_kept++;
        }
    }
    print_message("%d empty pairs checked, %d of them known apart\n", checked, apart_kept);
    assert_true(apart_kept > 1000);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_feature_ids_stable),
        cmocka_unit_test(test_kept_manifolds_match_fresh),
        cmocka_unit_test(test_skipped_pairs_are_apart),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
