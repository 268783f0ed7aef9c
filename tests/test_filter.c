/* test_filter.c - collision filtering: the category/mask/group truth table in
 * both directions and creation orders, changes at runtime (awake and
 * asleep, with end events), the world's pair filter callback, continuous
 * collision honouring the bits, and bad input. */
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

typedef struct filter_bits { uint64_t category, mask; int group; } filter_bits;

static carom_body_id add_filtered_ground(carom_world *w, filter_bits f)
{
    carom_body_def d = carom_body_def_default();
    d.type = CAROM_BODY_STATIC;
    d.shape = carom_shape_box(5, 5, 0.5);
    d.position.z = -0.5;
    d.category = f.category;
    d.mask = f.mask;
    d.group = f.group;
    return add_body(w, &d);
}

static carom_body_id add_filtered_ball(carom_world *w, filter_bits f, double z)
{
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(0.25);
    d.position.z = z;
    d.category = f.category;
    d.mask = f.mask;
    d.group = f.group;
    return add_body(w, &d);
}

/* The rule, written out independently of the library. */
static int expected_collide(filter_bits a, filter_bits b)
{
    if (a.group != 0 && a.group == b.group) return a.group > 0;
    return (a.category & b.mask) && (b.category & a.mask);
}

/* Drops a ball on the ground for 1 s: 1 when it rests on it, 0 when it fell through. */
static int ball_lands(filter_bits ball, filter_bits ground, int ball_first)
{
    carom_world *w = world_default();
    carom_body_id b, g;
    if (ball_first) { b = add_filtered_ball(w, ball, 0.5); g = add_filtered_ground(w, ground); }
    else { g = add_filtered_ground(w, ground); b = add_filtered_ball(w, ball, 0.5); }
    assert_false(carom_body_id_is_null(b) || carom_body_id_is_null(g));
    for (int i = 0; i < 60; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    double z = pos(w, b).z;
    carom_world_destroy(w);
    if (fabs(z - 0.25) < 0.01) return 1;
    assert_true(z < -0.5); /* no half measures: through */
    return 0;
}

static void test_truth_table(void **state)
{
    (void)state;
    const uint64_t cats[] = {1, 2, 0x8000000000000000ULL};
    const uint64_t masks[] = {CAROM_MASK_ALL, 1, 2, 0, 0x8000000000000001ULL};
    const int groups[] = {0, 1, -1, 2};
    int cases = 0, collide = 0;
    for (int ca = 0; ca < 3; ca++)
        for (int ma = 0; ma < 5; ma++)
            for (int ga = 0; ga < 4; ga++) {
                /* the ground varies over a smaller set, both roles swapped below */
                filter_bits x = {cats[ca], masks[ma], groups[ga]};
                filter_bits y = {cats[(ca + ma) % 3], masks[(ma + ga + 1) % 5], groups[(ga * 3 + ca) % 4]};
                int want = expected_collide(x, y);
                assert_int_equal(expected_collide(y, x), want); /* the rule is symmetric */
                int order = (ca + ma + ga) % 2;
                if (ball_lands(x, y, order) != want)
                    fail_msg("ball %llx/%llx/%d on ground %llx/%llx/%d: expected %s", (unsigned long long)x.category,
                             (unsigned long long)x.mask, x.group, (unsigned long long)y.category,
                             (unsigned long long)y.mask, y.group, want ? "landing" : "falling through");
                if (ball_lands(y, x, !order) != want) fail_msg("swapped roles disagree");
                cases++;
                collide += want;
            }
    print_message("filter truth table: %d pairs (x2 roles), %d collide\n", cases, collide);
    assert_true(collide > 10 && cases - collide > 10);
}

static int count_events(carom_world *w, carom_event_type type)
{
    const carom_contact_event *e;
    int n = carom_world_get_events(w, &e), c = 0;
    for (int i = 0; i < n; i++) c += e[i].type == type;
    return c;
}

/* A ball asleep on the ground falls when its mask stops allowing the ground
 * (with an end event), and lands on it when allowed again. */
static void test_runtime_change_on_sleeping_body(void **state)
{
    (void)state;
    carom_world *w = world_default();
    filter_bits all = {1, CAROM_MASK_ALL, 0};
    carom_body_id g = add_filtered_ground(w, all), b = add_filtered_ball(w, all, 0.26);
    (void)g;
    for (int i = 0; i < 120; i++) carom_world_step(w, 1.0 / 60);
    assert_false(carom_body_is_awake(w, b));
    assert_int_equal(carom_body_set_filter(w, b, 1, 2, 0), CAROM_OK); /* the ground is category 1 */
    uint64_t c, m;
    int grp;
    assert_int_equal(carom_body_get_filter(w, b, &c, &m, &grp), CAROM_OK);
    assert_true(c == 1 && m == 2 && grp == 0);
    assert_true(carom_body_is_awake(w, b));
    carom_world_step(w, 1.0 / 60);
    assert_int_equal(count_events(w, CAROM_EVENT_END), 1);
    for (int i = 0; i < 10; i++) carom_world_step(w, 1.0 / 60);
    assert_true(pos(w, b).z < 0.2);
    /* allowed again while falling into the ground: pushed out and resting on it */
    assert_int_equal(carom_body_set_filter(w, b, 1, CAROM_MASK_ALL, 0), CAROM_OK);
    for (int i = 0; i < 120; i++) carom_world_step(w, 1.0 / 60);
    assert_true(fabs(pos(w, b).z - 0.25) < 0.01);
    carom_world_destroy(w);
}

/* A negative group wins over bits that allow; a positive one over bits that forbid. */
static void test_group_overrides_bits(void **state)
{
    (void)state;
    filter_bits never = {1, CAROM_MASK_ALL, -3}, always = {1, 0, 3};
    assert_int_equal(ball_lands(never, never, 0), 0);
    assert_int_equal(ball_lands(always, always, 1), 1);
    filter_bits other = {1, 0, 4};
    assert_int_equal(ball_lands(always, other, 0), 0); /* different groups: the bits decide */
}

typedef struct pair_log { carom_world *w; int calls, refused_destroy; carom_body_id reject; } pair_log;

static int reject_pair(void *ctx, carom_body_id a, carom_body_id b)
{
    pair_log *log = ctx;
    log->calls++;
    if (carom_body_destroy(log->w, a) == CAROM_ERROR_LOCKED) log->refused_destroy++;
    return !(carom_body_id_equal(a, log->reject) || carom_body_id_equal(b, log->reject));
}

static void test_pair_filter_callback(void **state)
{
    (void)state;
    carom_world *w = world_default();
    filter_bits all = {1, CAROM_MASK_ALL, 0};
    add_filtered_ground(w, all);
    carom_body_id kept = add_filtered_ball(w, all, 0.5), passed = add_filtered_ball(w, all, 0.5);
    carom_vec3 p = {2, 0, 0.5};
    carom_body_set_position(w, passed, p);
    pair_log log = {w, 0, 0, passed};
    assert_int_equal(carom_world_set_pair_filter(w, reject_pair, &log), CAROM_OK);
    for (int i = 0; i < 60; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    assert_true(fabs(pos(w, kept).z - 0.25) < 0.01);
    assert_true(pos(w, passed).z < -0.5);
    assert_true(log.calls >= 2);
    assert_int_equal(log.refused_destroy, log.calls); /* destroying from it is refused */
    assert_int_equal(carom_world_body_count(w), 3);
    /* removing the filter: the next pairs are allowed */
    assert_int_equal(carom_world_set_pair_filter(w, NULL, NULL), CAROM_OK);
    carom_vec3 up = {2, 0, 0.5}, still = {0, 0, 0};
    carom_body_set_position(w, passed, up);
    carom_body_set_linear_velocity(w, passed, still);
    for (int i = 0; i < 60; i++) carom_world_step(w, 1.0 / 60);
    assert_true(fabs(pos(w, passed).z - 0.25) < 0.01);
    carom_world_destroy(w);
}

/* A bullet does not stop at a thin wall its mask excludes. */
static void test_continuous_collision_honours_bits(void **state)
{
    (void)state;
    for (int allowed = 0; allowed < 2; allowed++) {
        carom_world_def wd = carom_world_def_default();
        wd.gravity.z = 0;
        carom_world *w = carom_world_create(&wd);
        carom_body_def d = carom_body_def_default();
        d.type = CAROM_BODY_STATIC;
        d.shape = carom_shape_box(0.05, 2, 2);
        d.position.x = 5;
        d.category = 4;
        carom_body_create(w, &d);
        d = carom_body_def_default();
        d.shape = carom_shape_sphere(0.1);
        d.linear_velocity.x = 300;
        d.bullet = 1;
        d.mask = allowed ? CAROM_MASK_ALL : ~(uint64_t)4;
        carom_body_id b = carom_body_create(w, &d);
        for (int i = 0; i < 10; i++) carom_world_step(w, 1.0 / 60);
        carom_vec3 p;
        carom_body_get_position(w, b, &p);
        if (allowed) assert_true(p.x < 5);
        else assert_true(p.x > 40);
        carom_world_destroy(w);
    }
}

typedef struct wall_filter {
    carom_body_id wall;
    int calls;
} wall_filter;

static int reject_wall(void *context, carom_body_id a, carom_body_id b)
{
    wall_filter *f = context;
    f->calls++;
    return !(carom_body_id_equal(a, f->wall) || carom_body_id_equal(b, f->wall));
}

/* The world's pair filter decides for continuous collision too: a bullet
 * whose pair with a thin wall the filter refuses flies through it (its
 * bits allow the pair, so only the callback can say no); allowed, it stops
 * there. Far from the origin too. */
static void test_continuous_collision_asks_pair_filter(void **state)
{
    (void)state;
    const double origins[] = {0.0, 1e5};
    for (int o = 0; o < 2; o++)
        for (int refuse = 0; refuse < 2; refuse++) {
            carom_world_def wd = carom_world_def_default();
            wd.gravity.z = 0;
            carom_world *w = carom_world_create(&wd);
            double x0 = origins[o];
            carom_body_def d = carom_body_def_default();
            d.type = CAROM_BODY_STATIC;
            d.shape = carom_shape_box(0.05, 2, 2);
            d.position.x = x0 + 5;
            wall_filter f = {carom_body_create(w, &d), 0};
            d = carom_body_def_default();
            d.shape = carom_shape_sphere(0.1);
            d.position.x = x0;
            d.linear_velocity.x = 300;
            d.bullet = 1;
            carom_body_id b = carom_body_create(w, &d);
            assert_int_equal(carom_world_set_pair_filter(w, refuse ? reject_wall : NULL, &f), CAROM_OK);
            for (int i = 0; i < 10; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
            carom_vec3 p;
            carom_body_get_position(w, b, &p);
            if (refuse) {
                if (!(p.x > x0 + 40)) fail_msg("origin %g: the refused bullet stopped at x - x0 = %g", x0, p.x - x0);
                assert_true(f.calls > 0);
            } else {
                assert_true(p.x < x0 + 5);
            }
            carom_world_destroy(w);
        }
}

static void test_bad_input(void **state)
{
    (void)state;
    carom_world *w = world_default();
    filter_bits all = {1, CAROM_MASK_ALL, 0};
    carom_body_id b = add_filtered_ball(w, all, 1);
    carom_body_destroy(w, b);
    assert_int_equal(carom_body_set_filter(w, b, 1, 1, 0), CAROM_ERROR_STALE_ID);
    assert_non_null(strstr(carom_world_last_error(w), "destroyed"));
    uint64_t c;
    assert_int_equal(carom_body_get_filter(w, b, &c, NULL, NULL), CAROM_ERROR_STALE_ID);
    carom_body_id b2 = add_filtered_ball(w, all, 1);
    assert_int_equal(carom_body_get_filter(w, b2, NULL, NULL, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_filter(NULL, b2, 1, 1, 0), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_set_pair_filter(NULL, NULL, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_truth_table),
        cmocka_unit_test(test_runtime_change_on_sleeping_body),
        cmocka_unit_test(test_group_overrides_bits),
        cmocka_unit_test(test_pair_filter_callback),
        cmocka_unit_test(test_continuous_collision_honours_bits),
        cmocka_unit_test(test_continuous_collision_asks_pair_filter),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
