/* test_tasks.c - the task hooks: any worker count and any scheduling give
 * bitwise the same world (the snapshot, which holds every body's state,
 * every contact's manifold and impulses, compared byte for byte); the
 * hooks' validation; a hook that breaks the contract stops a debug build. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "carom/carom_threads.h"
#include "helpers.h"

#define STEPS 200      /* the worker counts 1, 2 and 7 */
#define SHORT_STEPS 60 /* the presets and switches */

/* A mixed scene: a grid of piles of boxes, spheres, capsules, cylinders and
 * hulls of several sizes and masses dropped onto the ground and onto each
 * other, a row of plane-locked and rotation-locked bodies, bouncy balls, a
 * kinematic sweeper, a fast bullet that hits the piles and boxes sliding
 * over the seams of a tiled floor (the ghost-contact pass merges their
 * contacts on two tiles). Far from the origin, so that the positions have
 * few bits to spare. */
static void build_scene(carom_world *w)
{
    static const double tetra[] = {0, 0, 0.3, 0.3, 0, -0.1, -0.15, 0.26, -0.1, -0.15, -0.26, -0.1};
    const double ox = 1000.0, oy = -2000.0;
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    assert_false(carom_body_id_is_null(carom_body_create(w, &g)));
    int n = 0;
    for (int gx = 0; gx < 6; gx++)
        for (int gy = 0; gy < 6; gy++)
            for (int k = 0; k < 9; k++, n++) {
                carom_body_def d = carom_body_def_default();
                double s = 0.2 + 0.05 * (n % 4);
                d.position = vec(ox + 1.6 * gx + 0.07 * (k % 3), oy + 1.6 * gy - 0.05 * (k % 2), 0.3 + 0.55 * k);
                switch (n % 5) {
                case 0: d.shape = carom_shape_box(s, 0.8 * s, 0.6 * s); break;
                case 1: d.shape = carom_shape_sphere(s); break;
                case 2: d.shape = carom_shape_capsule(0.6 * s, s); break;
                case 3: d.shape = carom_shape_cylinder(s, 0.5 * s); break;
                default: d.shape = carom_shape_hull(tetra, 4); break;
                }
                d.orientation.w = 0.96;
                d.orientation.x = 0.2 * ((n % 3) - 1);
                d.orientation.y = 0.0;
                d.orientation.z = 0.28 * (n % 2);
                double q = sqrt(d.orientation.w * d.orientation.w + d.orientation.x * d.orientation.x +
                                d.orientation.z * d.orientation.z);
                d.orientation.w /= q;
                d.orientation.x /= q;
                d.orientation.z /= q;
                d.density = 500.0 + 400.0 * (n % 3);
                d.friction = 0.3 + 0.1 * (n % 4);
                d.restitution = n % 7 == 0 ? 0.5 : 0.0;
                d.angular_velocity = vec(0.5 * (n % 3), -0.3 * (n % 2), 0.2);
                d.lock_rotation = n % 23 == 0;
                assert_false(carom_body_id_is_null(carom_body_create(w, &d)));
            }
    for (int k = 0; k < 12; k++) { /* 2D bodies in the x-z plane through y = oy - 3 */
        carom_body_def d = carom_body_def_default();
        d.position = vec(ox + 0.45 * k, oy - 3.0, 0.4 + 0.3 * (k % 3));
        d.shape = k % 2 ? carom_shape_box(0.2, 0.2, 0.2) : carom_shape_sphere(0.2);
        d.lock_to_plane = 1;
        d.linear_velocity = vec(0.5 - 0.1 * k, 0.0, 0.0);
        assert_false(carom_body_id_is_null(carom_body_create(w, &d)));
    }
    for (int k = 0; k < 6; k++) { /* the tiles: 1 m boxes side by side, their tops 0.2 m above the ground */
        carom_body_def t = carom_body_def_default();
        t.type = CAROM_BODY_STATIC;
        t.position = vec(ox + 1.0 * k, oy - 6.0, -0.3);
        t.shape = carom_shape_box(0.5, 0.5, 0.5);
        assert_false(carom_body_id_is_null(carom_body_create(w, &t)));
    }
    for (int k = 0; k < 3; k++) { /* sliding across the seams */
        carom_body_def d = carom_body_def_default();
        d.position = vec(ox + 0.3 + 0.6 * k, oy - 6.0 + 0.25 * (k - 1), 0.35);
        d.shape = carom_shape_box(0.15 + 0.05 * k, 0.15, 0.15);
        d.linear_velocity = vec(2.0 - 0.4 * k, 0.0, 0.0);
        assert_false(carom_body_id_is_null(carom_body_create(w, &d)));
    }
    carom_body_def kin = carom_body_def_default();
    kin.type = CAROM_BODY_KINEMATIC;
    kin.position = vec(ox - 1.0, oy + 5.0, 0.3);
    kin.shape = carom_shape_box(0.3, 2.0, 0.3);
    kin.linear_velocity = vec(1.5, 0.0, 0.0);
    kin.angular_velocity = vec(0.0, 0.0, 0.4);
    assert_false(carom_body_id_is_null(carom_body_create(w, &kin)));
    carom_body_def bullet = carom_body_def_default();
    bullet.position = vec(ox - 6.0, oy + 3.2, 0.6);
    bullet.shape = carom_shape_sphere(0.1);
    bullet.linear_velocity = vec(200.0, 0.0, 1.0);
    bullet.bullet = 1;
    bullet.density = 8000.0;
    assert_false(carom_body_id_is_null(carom_body_create(w, &bullet)));
}

/* The world's snapshot after `steps` steps of the scene under def. */
static unsigned char *run_scene(carom_world_def def, int steps, size_t *size)
{
    carom_world *w = carom_world_create(&def);
    assert_non_null(w);
    build_scene(w);
    for (int i = 0; i < steps; i++) assert_int_equal(carom_world_step(w, DT), CAROM_OK);
    carom_world_stats st = carom_world_stats_init();
    assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
    *size = carom_world_snapshot(w, NULL, 0);
    assert_true(*size > 0);
    unsigned char *buf = malloc(*size);
    assert_non_null(buf);
    assert_int_equal(carom_world_snapshot(w, buf, *size), *size);
    carom_world_destroy(w);
    return buf;
}

static void expect_same(const unsigned char *a, size_t na, const unsigned char *b, size_t nb, const char *what)
{
    assert_int_equal(na, nb);
    size_t first = 0;
    while (first < na && a[first] == b[first]) first++;
    if (first != na) print_error("%s: snapshots differ from byte %zu of %zu\n", what, first, na);
    assert_true(first == na);
    print_message("%s: %zu bytes identical\n", what, na);
}

/* A host that runs every task on this one thread but as if it had seven
 * workers: ranges of random lengths (some shorter than min_range, which the
 * library must not rely on), run in a random order, each on a random worker. */
#define SHUFFLE_MAX_RANGES 4096

typedef struct shuffle_host {
    uint64_t state;
    int workers;
    int ranges_run;
    int begin[SHUFFLE_MAX_RANGES], end[SHUFFLE_MAX_RANGES];
} shuffle_host;

static uint32_t next_random(shuffle_host *h)
{
    h->state = h->state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(h->state >> 33);
}

static void *shuffle_enqueue(carom_task_fn *task, int count, int min_range, void *data, void *context)
{
    shuffle_host *h = context;
    int *begin = h->begin, *end = h->end;
    int n = 0;
    for (int at = 0; at < count;) {
        int len = 1 + (int)(next_random(h) % (uint32_t)(2 * min_range));
        if (n == SHUFFLE_MAX_RANGES - 1 || at + len > count) len = count - at;
        begin[n] = at;
        end[n] = at + len;
        n++;
        at += len;
    }
    for (int i = n - 1; i > 0; i--) { /* Fisher-Yates */
        int j = (int)(next_random(h) % (uint32_t)(i + 1));
        int b = begin[i], e = end[i];
        begin[i] = begin[j]; end[i] = end[j];
        begin[j] = b; end[j] = e;
    }
    for (int i = 0; i < n; i++) task(begin[i], end[i], (int)(next_random(h) % (uint32_t)h->workers), data);
    h->ranges_run += n;
    return NULL; /* all ran already */
}

static void shuffle_finish(void *task, void *context)
{
    (void)task;
    (void)context;
}

static void test_any_worker_count_gives_the_same_bits(void **state)
{
    (void)state;
    size_t n1, n2, n7, ns;
    carom_world_def def = carom_world_def_default();
    unsigned char *one = run_scene(def, STEPS, &n1);

    carom_thread_pool *pool2 = carom_thread_pool_create(2);
    assert_non_null(pool2);
    carom_world_def d2 = carom_world_def_default();
    assert_int_equal(carom_thread_pool_attach(pool2, &d2), CAROM_OK);
    assert_int_equal(d2.worker_count, 2);
    unsigned char *two = run_scene(d2, STEPS, &n2);
    carom_thread_pool_destroy(pool2);
    expect_same(one, n1, two, n2, "1 vs 2 workers");

    carom_thread_pool *pool7 = carom_thread_pool_create(7);
    assert_non_null(pool7);
    carom_world_def d7 = carom_world_def_default();
    assert_int_equal(carom_thread_pool_attach(pool7, &d7), CAROM_OK);
    unsigned char *seven = run_scene(d7, STEPS, &n7);
    carom_thread_pool_destroy(pool7);
    expect_same(one, n1, seven, n7, "1 vs 7 workers");

    static shuffle_host host;
    host.state = 12345u;
    host.workers = 7;
    host.ranges_run = 0;
    carom_world_def ds = carom_world_def_default();
    ds.worker_count = host.workers;
    ds.enqueue_task = shuffle_enqueue;
    ds.finish_task = shuffle_finish;
    ds.task_context = &host;
    unsigned char *shuffled = run_scene(ds, STEPS, &ns);
    print_message("shuffled host ran %d ranges\n", host.ranges_run);
    assert_true(host.ranges_run > 10 * STEPS); /* the stages did hand their loops over */
    expect_same(one, n1, shuffled, ns, "1 worker vs shuffled ranges on 7");
    free(one);
    free(two);
    free(seven);
    free(shuffled);
}

/* Every preset, and the switches that change which stages run. */
static void test_presets_and_switches_agree_across_workers(void **state)
{
    (void)state;
    static const char *const presets[] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++)
        for (int variant = 0; variant < (p == 1 ? 2 : 1); variant++) {
            carom_world_def def = carom_world_def_default();
            assert_int_equal(carom_world_def_apply_preset(&def, presets[p]), CAROM_OK);
            if (variant) {
                def.enable_friction = 0;
                def.enable_restitution = 0;
                def.enable_sleep = 0;
            }
            size_t na, nb;
            unsigned char *a = run_scene(def, SHORT_STEPS, &na);
            static shuffle_host host;
            host.state = 99u + (uint64_t)p;
            host.workers = 5;
            host.ranges_run = 0;
            def.worker_count = host.workers;
            def.enqueue_task = shuffle_enqueue;
            def.finish_task = shuffle_finish;
            def.task_context = &host;
            unsigned char *b = run_scene(def, SHORT_STEPS, &nb);
            char what[64];
            snprintf(what, sizeof what, "%s%s: 1 vs shuffled 5", presets[p], variant ? " (switches off)" : "");
            expect_same(a, na, b, nb, what);
            free(a);
            free(b);
        }
}

static void test_hook_validation(void **state)
{
    (void)state;
    char msg[256];
    carom_world_def d = carom_world_def_default();
    d.worker_count = 2;
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    print_message("refused: %s\n", msg);
    assert_non_null(strstr(msg, "enqueue_task"));
    assert_null(carom_world_create(&d));
    d.worker_count = 0;
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "worker_count"));
    d.worker_count = CAROM_MAX_WORKERS + 1;
    d.enqueue_task = shuffle_enqueue;
    d.finish_task = shuffle_finish;
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "worker_count"));
    d.worker_count = 3;
    d.finish_task = NULL;
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    print_message("refused: %s\n", msg);
    assert_non_null(strstr(msg, "finish_task"));
    d.finish_task = shuffle_finish;
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_OK);

    /* set_def refuses the same and leaves the world's settings as they were */
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    carom_world_def bad = d;
    bad.enqueue_task = NULL;
    bad.finish_task = NULL;
    assert_int_equal(carom_world_set_def(w, &bad), CAROM_ERROR_INVALID_ARGUMENT);
    print_message("set_def refused: %s\n", carom_world_last_error(w));
    assert_non_null(strstr(carom_world_last_error(w), "enqueue_task"));
    carom_world_def now = carom_world_def_default();
    assert_int_equal(carom_world_get_def(w, &now), CAROM_OK);
    assert_int_equal(now.worker_count, 3);
    assert_true(now.enqueue_task == shuffle_enqueue && now.finish_task == shuffle_finish);
    carom_world_destroy(w);

    /* a def from before the hooks existed (smaller size) gets one worker, no hooks */
    carom_world_def old = carom_world_def_default();
    old.size = (uint32_t)offsetof(carom_world_def, worker_count);
    old.worker_count = 9; /* beyond the caller's size: not read */
    w = carom_world_create(&old);
    assert_non_null(w);
    now = carom_world_def_default();
    assert_int_equal(carom_world_get_def(w, &now), CAROM_OK);
    assert_int_equal(now.worker_count, 1);
    assert_null(now.enqueue_task);
    carom_world_destroy(w);

    assert_null(carom_thread_pool_create(0));
    assert_null(carom_thread_pool_create(CAROM_MAX_WORKERS + 1));
    carom_thread_pool *pool = carom_thread_pool_create(3);
    assert_non_null(pool);
    assert_int_equal(carom_thread_pool_workers(pool), 3);
    assert_int_equal(carom_thread_pool_attach(pool, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    carom_world_def small = carom_world_def_default();
    small.size = (uint32_t)offsetof(carom_world_def, worker_count);
    assert_int_equal(carom_thread_pool_attach(pool, &small), CAROM_ERROR_INVALID_ARGUMENT);
    carom_thread_pool_destroy(pool);
    carom_thread_pool_destroy(NULL);
}

/* Hosts that break the contract: every range twice, or the last range never. */
static void *twice_enqueue(carom_task_fn *task, int count, int min_range, void *data, void *context)
{
    (void)min_range;
    (void)context;
    task(0, count, 0, data);
    task(0, count, 1, data);
    return NULL;
}

static void *skip_enqueue(carom_task_fn *task, int count, int min_range, void *data, void *context)
{
    (void)min_range;
    (void)context;
    if (count > 1) task(0, count - 1, 0, data);
    return NULL;
}

/* Runs the scene with the host in a child process; returns its signal (0: exited normally). */
static int child_signal(carom_enqueue_task_fn *enqueue)
{
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        /* the child's assertion message is expected: keep it out of the log */
        if (!freopen("/dev/null", "w", stderr)) _exit(3);
        carom_world_def d = carom_world_def_default();
        d.worker_count = 2;
        d.enqueue_task = enqueue;
        d.finish_task = shuffle_finish;
        carom_world *w = carom_world_create(&d);
        if (!w) _exit(2);
        build_scene(w);
        for (int i = 0; i < 3; i++) carom_world_step(w, DT);
        _exit(0);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    return WIFSIGNALED(status) ? WTERMSIG(status) : 0;
}

static void test_broken_hooks_are_caught(void **state)
{
    (void)state;
#ifdef NDEBUG
    skip();
#else
    int twice = child_signal(twice_enqueue), skipped = child_signal(skip_enqueue);
    print_message("a hook running each range twice: signal %d; one skipping a range: signal %d\n", twice, skipped);
    assert_int_equal(twice, SIGABRT);
    assert_int_equal(skipped, SIGABRT);
#endif
}

/* The reference pool's worker count: the check and the constructor agree at
 * and beyond both ends of 1..CAROM_MAX_WORKERS. */
static void test_pool_worker_range(void **state)
{
    (void)state;
    const int counts[] = {-1, 0, 1, 2, CAROM_MAX_WORKERS, CAROM_MAX_WORKERS + 1};
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
        int n = counts[i], ok = n >= 1 && n <= CAROM_MAX_WORKERS;
        char msg[128] = "untouched";
        assert_int_equal(carom_thread_pool_check(n, msg, sizeof msg), ok ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT);
        if (ok) assert_string_equal(msg, "");
        else assert_non_null(strstr(msg, "workers must be in 1..64"));
        carom_thread_pool *pool = n <= 4 ? carom_thread_pool_create(n) : NULL; /* (not 64 threads) */
        if (n <= 4) assert_int_equal(pool != NULL, ok);
        if (pool) assert_int_equal(carom_thread_pool_workers(pool), n);
        carom_thread_pool_destroy(pool);
    }
    assert_null(carom_thread_pool_create(CAROM_MAX_WORKERS + 1));
    assert_int_equal(carom_thread_pool_check(0, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hook_validation),
        cmocka_unit_test(test_pool_worker_range),
        cmocka_unit_test(test_broken_hooks_are_caught),
        cmocka_unit_test(test_any_worker_count_gives_the_same_bits),
        cmocka_unit_test(test_presets_and_switches_agree_across_workers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
