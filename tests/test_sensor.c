/* test_sensor.c - sensors (begin/end for bodies entering, leaving, destroyed
 * inside, teleported through, asleep, filtered; no effect on motion), the
 * pre-solve callback (a one-way platform: bodies pass up through it and land
 * on it), and reading a body's contacts (a resting box: m g dt per step). */
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

typedef struct event_log { int begin, end; carom_body_id sensor, other; } event_log;

static void count_sensor_events(carom_world *w, event_log *log)
{
    const carom_contact_event *e;
    int n = carom_world_get_events(w, &e);
    for (int i = 0; i < n; i++) {
        if (e[i].type == CAROM_EVENT_SENSOR_BEGIN) log->begin++;
        else if (e[i].type == CAROM_EVENT_SENSOR_END) log->end++;
        else continue;
        log->sensor = e[i].a;
        log->other = e[i].b;
    }
}

static carom_body_id add_sensor(carom_world *w, carom_body_type type, double z, uint64_t mask)
{
    carom_body_def d = carom_body_def_default();
    d.type = type;
    d.shape = carom_shape_box(1, 1, 0.5);
    d.position.z = z;
    d.sensor = 1;
    d.mask = mask;
    return add_body(w, &d);
}

/* A ball falls through a static sensor: one begin while it overlaps, one end
 * after; its fall is the same bit for bit as without the sensor. */
static void test_enter_and_leave(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 15, 1.0 / 60, 1.0 / 240};
    for (int k = 0; k < 3; k++) {
        carom_world_def wd = carom_world_def_default();
        carom_world *w = carom_world_create(&wd), *twin = carom_world_create(&wd);
        carom_body_id s = add_sensor(w, CAROM_BODY_STATIC, 5, CAROM_MASK_ALL);
        carom_body_id b = add_sphere(w, 0.3, 0, 8, 0.25), tb = add_sphere(twin, 0.3, 0, 8, 0.25);
        event_log log = {0, 0, {0, 0}, {0, 0}};
        int begin_step = -1, end_step = -1;
        double entered_z = 0, left_z = 0;
        for (int i = 0; i < (int)(2.0 / dts[k]); i++) {
            carom_world_step(w, dts[k]);
            carom_world_step(twin, dts[k]);
            int b0 = log.begin, e0 = log.end;
            count_sensor_events(w, &log);
            carom_vec3 p;
            carom_body_get_position(w, b, &p);
            if (log.begin > b0) { begin_step = i; entered_z = p.z; }
            if (log.end > e0) { end_step = i; left_z = p.z; }
        }
        assert_int_equal(log.begin, 1);
        assert_int_equal(log.end, 1);
        assert_true(carom_body_id_equal(log.sensor, s) && carom_body_id_equal(log.other, b));
        assert_true(begin_step >= 0 && end_step > begin_step);
        /* at the first overlapping step end the ball's bottom is below the top 5.5 */
        assert_true(entered_z - 0.25 <= 5.5 && entered_z + 0.25 > 4.5);
        assert_true(left_z + 0.25 < 4.5);
        carom_vec3 p, tp;
        carom_body_get_position(w, b, &p);
        carom_body_get_position(twin, tb, &tp);
        assert_true(p.z == tp.z); /* no response at all */
        carom_world_destroy(w);
        carom_world_destroy(twin);
    }
}

/* Destroyed inside: an end at the next step naming the stale id. Teleported
 * through between steps: nothing. Filtered out by the sensor's mask: nothing. */
static void test_destroyed_teleported_filtered(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.gravity.z = 0;
    carom_world *w = carom_world_create(&wd);
    add_sensor(w, CAROM_BODY_STATIC, 0, ~(uint64_t)2);
    carom_body_id inside = add_sphere(w, 0.5, 0, 0, 0.25);
    event_log log = {0, 0, {0, 0}, {0, 0}};
    carom_world_step(w, 1.0 / 60);
    count_sensor_events(w, &log);
    assert_int_equal(log.begin, 1);
    carom_body_destroy(w, inside);
    carom_world_step(w, 1.0 / 60);
    count_sensor_events(w, &log);
    assert_int_equal(log.end, 1);
    assert_true(carom_body_id_equal(log.other, inside) && !carom_body_is_valid(w, inside));
    /* teleported from one side to the other between steps */
    carom_body_id t = add_sphere(w, -5, 0, 0, 0.25);
    carom_world_step(w, 1.0 / 60);
    carom_vec3 far = {5, 0, 0};
    carom_body_set_position(w, t, far);
    carom_world_step(w, 1.0 / 60);
    count_sensor_events(w, &log);
    assert_int_equal(log.begin, 1);
    assert_int_equal(log.end, 1);
    /* a category the sensor's mask leaves out */
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(0.25);
    d.category = 2;
    carom_body_create(w, &d);
    carom_world_step(w, 1.0 / 60);
    count_sensor_events(w, &log);
    assert_int_equal(log.begin, 1);
    /* sensors are not in the way of queries either */
    carom_vec3 o = {-3, 0, 0}, tr = {6, 0, 0};
    carom_ray_hit hit;
    assert_int_equal(carom_world_ray_cast(w, o, tr, &hit), 1); /* the category-2 ball, not the sensor */
    assert_true(fabs(hit.point.x + 0.25) < 1e-12);
    carom_world_destroy(w);
}

/* A kinematic sensor moved onto a sleeping body sees it, and the body sleeps on. */
static void test_sleeping_body(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_box(5, 5, 0.5);
    g.position.z = -0.5;
    carom_body_create(w, &g);
    carom_body_id b = add_sphere(w, 0, 0, 0.25, 0.25);
    carom_body_id s = add_sensor(w, CAROM_BODY_KINEMATIC, 10, CAROM_MASK_ALL);
    for (int i = 0; i < 120; i++) carom_world_step(w, 1.0 / 60);
    assert_false(carom_body_is_awake(w, b));
    event_log log = {0, 0, {0, 0}, {0, 0}};
    carom_vec3 down = {0, 0, 0.3};
    carom_body_set_position(w, s, down);
    carom_world_step(w, 1.0 / 60);
    count_sensor_events(w, &log);
    /* the ground is static and the sensor kinematic: it sees the ground too */
    assert_int_equal(log.begin, 2);
    assert_false(carom_body_is_awake(w, b));
    assert_true(carom_body_is_sensor(w, s) && !carom_body_is_sensor(w, b));
    carom_world_destroy(w);
}

/* One-way platform: contacts with a body below the platform's top are left
 * out, so a ball thrown up from below passes through and lands on top. */
typedef struct platform { carom_world *w; carom_body_id platform; double top; int refused, calls, locked; } platform;

static int one_way(void *ctx, carom_body_id a, carom_body_id b, const carom_manifold *m)
{
    platform *p = ctx;
    p->calls++;
    if (carom_body_destroy(p->w, a) == CAROM_ERROR_LOCKED) p->locked++;
    assert_true(m->point_count >= 1 && m->point_count <= 4);
    carom_body_id other = carom_body_id_equal(a, p->platform) ? b : a;
    if (carom_body_id_equal(other, p->platform)) return 1;
    int touches_platform = carom_body_id_equal(a, p->platform) || carom_body_id_equal(b, p->platform);
    if (!touches_platform) return 1;
    carom_vec3 c;
    carom_body_get_position(p->w, other, &c);
    if (c.z - 0.25 < p->top - 0.05) { p->refused++; return 0; } /* still coming up through it */
    return 1;
}

static void test_one_way_platform(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    for (int k = 0; k < 3; k++)
        for (int with = 0; with < 2; with++) {
            carom_world_def wd = carom_world_def_default();
            carom_world_def_apply_preset(&wd, presets[k]);
            carom_world *w = carom_world_create(&wd);
            carom_body_def g = carom_body_def_default();
            g.type = CAROM_BODY_STATIC;
            g.shape = carom_shape_box(5, 5, 0.5);
            g.position.z = -0.5;
            carom_body_create(w, &g);
            carom_body_def pd = g;
            pd.shape = carom_shape_box(2, 2, 0.1);
            pd.position.z = 2.0;
            carom_body_id plat = carom_body_create(w, &pd);
            carom_body_def bd = carom_body_def_default();
            bd.shape = carom_shape_sphere(0.25);
            bd.position.z = 0.25;
            bd.linear_velocity.z = 8; /* would rise to 0.25 + 64 / 19.62 = 3.5 m */
            carom_body_id ball = carom_body_create(w, &bd);
            platform p = {w, plat, 2.1, 0, 0, 0};
            if (with) carom_world_set_pre_solve(w, one_way, &p);
            for (int i = 0; i < 240; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
            carom_vec3 c;
            carom_body_get_position(w, ball, &c);
            if (with) {
                if (fabs(c.z - 2.35) > 0.01) fail_msg("%s: the ball is at %.4f, not on the platform (2.35)", presets[k], c.z);
                assert_true(p.refused > 0 && p.calls > p.refused);
                assert_int_equal(p.locked, p.calls); /* destroying from it is refused */
            } else {
                assert_true(fabs(c.z - 0.25) < 0.01); /* bounced off the underside, back on the ground */
            }
            carom_world_destroy(w);
        }
}

/* A box resting on the ground: one contact, normal up from the box's side
 * down, impulse m g dt per step. */
static void test_read_contacts(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_box(5, 5, 0.5);
    g.position.z = -0.5;
    carom_body_id ground = carom_body_create(w, &g);
    carom_body_def bd = carom_body_def_default();
    bd.shape = carom_shape_box(0.5, 0.5, 0.5);
    bd.position.z = 0.5;
    bd.mass = 10;
    bd.enable_sleep = 0;
    carom_body_id box = carom_body_create(w, &bd);
    for (int i = 0; i < 120; i++) carom_world_step(w, 1.0 / 60);
    carom_contact_info ci[4];
    assert_int_equal(carom_body_get_contacts(w, box, ci, 4), 1);
    assert_true(carom_body_id_equal(ci[0].other, ground));
    assert_true(fabs(ci[0].normal.z + 1) < 1e-9);
    assert_int_equal(ci[0].point_count, 4);
    double want = 10 * 9.81 / 60;
    if (fabs(ci[0].normal_impulse / want - 1) > 0.01)
        fail_msg("impulse %.6f N s, want m g dt = %.6f", ci[0].normal_impulse, want);
    assert_int_equal(carom_body_get_contacts(w, ground, ci, 4), 1);
    assert_true(carom_body_id_equal(ci[0].other, box) && fabs(ci[0].normal.z - 1) < 1e-9);
    assert_int_equal(carom_body_get_contacts(w, box, NULL, 0), 1);
    assert_int_equal(carom_body_get_contacts(w, box, NULL, 2), -1);
    carom_body_destroy(w, box);
    assert_int_equal(carom_body_get_contacts(w, box, ci, 4), -1);
    carom_world_destroy(w);
}

/* A snapshot keeps the filter bits, the sensor and what it holds, and the
 * previous poses: the restored world's next steps and events are the same. */
static void test_snapshot_round_trip(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    add_sensor(w, CAROM_BODY_STATIC, 2, CAROM_MASK_ALL);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_box(5, 5, 0.5);
    g.position.z = -0.5;
    g.category = 4;
    carom_body_create(w, &g);
    carom_body_id a = add_sphere(w, 0, 0, 3.0, 0.25), b = add_sphere(w, 0.6, 0, 2.4, 0.25);
    carom_body_set_filter(w, b, 1, ~(uint64_t)4, 0); /* b falls through the ground */
    for (int i = 0; i < 5; i++) carom_world_step(w, 1.0 / 60);
    size_t n = carom_world_snapshot(w, NULL, 0);
    assert_true(n > 0);
    void *buf = malloc(n);
    assert_int_equal(carom_world_snapshot(w, buf, n), n);
    char msg[256];
    carom_world *r = carom_world_restore(buf, n, msg, sizeof msg);
    if (!r) fail_msg("restore: %s", msg);
    free(buf);
    carom_vec3 pa, pr;
    carom_body_get_previous_position(w, a, &pa);
    carom_body_get_previous_position(r, a, &pr);
    assert_true(pa.z == pr.z);
    uint64_t c, m;
    int grp;
    carom_body_get_filter(r, b, &c, &m, &grp);
    assert_true(c == 1 && m == ~(uint64_t)4);
    for (int i = 0; i < 120; i++) {
        carom_world_step(w, 1.0 / 60);
        carom_world_step(r, 1.0 / 60);
        const carom_contact_event *ew, *er;
        int nw = carom_world_get_events(w, &ew), nr = carom_world_get_events(r, &er);
        assert_int_equal(nw, nr);
        for (int k = 0; k < nw; k++) assert_int_equal(ew[k].type, er[k].type);
    }
    carom_body_get_position(w, b, &pa);
    carom_body_get_position(r, b, &pr);
    assert_true(pa.z == pr.z && pa.z < -1);
    carom_body_get_position(w, a, &pa);
    carom_body_get_position(r, a, &pr);
    assert_true(pa.z == pr.z && fabs(pa.z - 0.25) < 0.01);
    carom_world_destroy(w);
    carom_world_destroy(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_enter_and_leave),
        cmocka_unit_test(test_destroyed_teleported_filtered),
        cmocka_unit_test(test_sleeping_body),
        cmocka_unit_test(test_one_way_platform),
        cmocka_unit_test(test_read_contacts),
        cmocka_unit_test(test_snapshot_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
