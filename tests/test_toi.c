/* test_toi.c - continuous collision: a 750 m/s bullet does not tunnel through a
 * wall with continuous collision, and does without it. */
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

#include "helpers.h"

/* The peers' bullet: 1 cm, 10 g sphere at 750 m/s against a 5 cm wall. */
static void test_bullet_does_not_tunnel(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.5, 0.0);
    carom_body_def wall = carom_body_def_default();
    wall.type = CAROM_BODY_STATIC;
    wall.position = vec(1.025, 0, 2.0);
    wall.shape = carom_shape_box(0.025, 2.0, 2.0);
    wall.friction = 0.5;
    carom_body_create(w, &wall);
    carom_body_def d = carom_body_def_default();
    d.position = vec(0, 0, 2.0);
    d.shape = carom_shape_sphere(0.01);
    d.mass = 0.01;
    d.friction = 0.5;
    d.linear_velocity = vec(750, 0, 0);
    d.bullet = 1;
    carom_body_id b = carom_body_create(w, &d);
    int hits = 0;
    for (int i = 0; i < 60; i++) {
        step_n(w, 1, DT);
        const carom_contact_event *ev;
        int n = carom_world_get_events(w, &ev);
        for (int j = 0; j < n; j++)
            if (ev[j].type == CAROM_EVENT_HIT) {
                hits++;
                /* the wall stops it: J = m v, average force J / dt */
                EXPECT_NEAR(ev[j].normal_impulse, 0.01 * 750.0, 0.01 * 7.5, "bullet impulse");
                EXPECT_NEAR(ev[j].average_force, ev[j].normal_impulse / DT, 1e-9, "average force");
            }
        assert_true(pos(w, b).x < 1.0);
    }
    assert_int_equal(hits, 1);
    carom_world_destroy(w);
}

/* The same without continuous collision: the fast path must be what saves it. */
static void test_bullet_tunnels_without_ccd(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.enable_continuous = 0;
    carom_world *w = world_with(wd, 0, 0.5, 0.0);
    carom_body_def wall = carom_body_def_default();
    wall.type = CAROM_BODY_STATIC;
    wall.position = vec(1.025, 0, 2.0);
    wall.shape = carom_shape_box(0.025, 2.0, 2.0);
    carom_body_create(w, &wall);
    carom_body_def d = carom_body_def_default();
    d.position = vec(-20, 0, 2.0);
    d.shape = carom_shape_sphere(0.01);
    d.mass = 0.01;
    d.linear_velocity = vec(750, 0, 0);
    carom_body_id b = carom_body_create(w, &d);
    step_n(w, 60, DT);
    assert_true(pos(w, b).x > 1.05);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bullet_does_not_tunnel),
        cmocka_unit_test(test_bullet_tunnels_without_ccd),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
