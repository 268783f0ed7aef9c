/* test_broadphase.c - the AABB trees against brute force (every pair, query and
 * ray checked box by box) over random creates, moves and destroys; hand-built
 * cases for static proxies and the moved buffer; tree height and 100k proxies. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "broadphase.h"
#include "helpers.h"

/* ---- helpers -------------------------------------------------------------- */

static aabb box_at(vec3 c, vec3 h)
{
    aabb b = {v3_sub(c, h), v3_add(c, h)};
    return b;
}

/* Pairs recorded as an n x n matrix of report counts, by user value. */
typedef struct pair_log {
    int n;
    unsigned char *count;
    int self_pairs, out_of_range;
} pair_log;

static void log_init(pair_log *l, int n)
{
    l->n = n;
    l->count = calloc((size_t)n * (size_t)n, 1);
    l->self_pairs = l->out_of_range = 0;
    assert_non_null(l->count);
}

static void log_clear(pair_log *l)
{
    memset(l->count, 0, (size_t)l->n * (size_t)l->n);
    l->self_pairs = l->out_of_range = 0;
}

static void log_pair(void *ctx, int a, int b)
{
    pair_log *l = ctx;
    if (a == b) { l->self_pairs++; return; }
    if (a < 0 || b < 0 || a >= l->n || b >= l->n) { l->out_of_range++; return; }
    int lo = a < b ? a : b, hi = a < b ? b : a;
    if (l->count[lo * l->n + hi] < 255) l->count[lo * l->n + hi]++;
}

static int reported(const pair_log *l, int a, int b)
{
    int lo = a < b ? a : b, hi = a < b ? b : a;
    return l->count[lo * l->n + hi];
}

static void count_pair(void *ctx, int a, int b)
{
    (void)a;
    (void)b;
    (*(long *)ctx)++;
}

/* Segment o + t d against a box by the slab method written out per axis:
 * the entry parameter in [0, max_t], or -1 when it misses. */
static double ray_box_reference(aabb b, vec3 o, vec3 d, double max_t)
{
    double enter = 0.0, leave = max_t;
    for (int k = 0; k < 3; k++) {
        double ok = v3_get(o, k), dk = v3_get(d, k), lo = v3_get(b.lo, k), hi = v3_get(b.hi, k);
        if (dk == 0.0) {
            if (ok < lo || ok > hi) return -1.0;
            continue;
        }
        double t_lo = (lo - ok) / dk, t_hi = (hi - ok) / dk;
        enter = fmax(enter, fmin(t_lo, t_hi));
        leave = fmin(leave, fmax(t_lo, t_hi));
    }
    return enter <= leave ? enter : -1.0;
}

/* ---- the random model ----------------------------------------------------- */

enum { MODEL_MAX = 700 };

typedef struct model {
    int alive[MODEL_MAX], is_static[MODEL_MAX], proxy[MODEL_MAX], moved[MODEL_MAX];
    aabb box[MODEL_MAX];
} model;

static aabb random_box(uint64_t *s, double extent)
{
    vec3 c = v3(extent * rnd(s), extent * rnd(s), extent * rnd(s));
    vec3 h = v3(0.1 + rnd(s), 0.1 + rnd(s), 0.1 + rnd(s));
    return box_at(c, h);
}

/* One round of random edits: creates (20% static), moves (static ones too),
 * destroys, and some destroy + immediate re-create under the same user. */
static void random_edits(broadphase *bp, model *m, uint64_t *s, int edits, double extent)
{
    for (int op = 0; op < edits; op++) {
        int i = (int)(rnd(s) * MODEL_MAX);
        double r = rnd(s);
        if (!m->alive[i]) {
            m->box[i] = random_box(s, extent);
            m->is_static[i] = rnd(s) < 0.2;
            m->proxy[i] = bp_create_proxy(bp, m->box[i], m->is_static[i], i);
            assert_true(m->proxy[i] >= 0);
            m->alive[i] = m->moved[i] = 1;
        } else if (r < 0.25) {
            bp_destroy_proxy(bp, m->proxy[i]);
            m->alive[i] = m->moved[i] = 0;
        } else if (r < 0.3) {
            bp_destroy_proxy(bp, m->proxy[i]);
            m->box[i] = random_box(s, extent);
            m->proxy[i] = bp_create_proxy(bp, m->box[i], m->is_static[i], i);
            assert_true(m->proxy[i] >= 0);
            m->moved[i] = 1;
        } else {
            vec3 d = v3(2 * rnd(s) - 1, 2 * rnd(s) - 1, 2 * rnd(s) - 1);
            m->box[i].lo = v3_add(m->box[i].lo, d);
            m->box[i].hi = v3_add(m->box[i].hi, d);
            bp_move_proxy(bp, m->proxy[i], m->box[i]);
            m->moved[i] = 1;
        }
    }
}

/* bp_update_pairs must report exactly the overlapping pairs with at least one
 * proxy moved (or created) this round and not both static, each once. */
static void check_pairs(broadphase *bp, model *m, pair_log *log, uint64_t seed, int round)
{
    log_clear(log);
    bp_update_pairs(bp, log_pair, log);
    assert_int_equal(log->self_pairs, 0);
    assert_int_equal(log->out_of_range, 0);
    for (int a = 0; a < MODEL_MAX; a++)
        for (int b = a + 1; b < MODEL_MAX; b++) {
            int expect = m->alive[a] && m->alive[b] && (m->moved[a] || m->moved[b]) &&
                         !(m->is_static[a] && m->is_static[b]) && aabb_overlap(m->box[a], m->box[b]);
            int got = reported(log, a, b);
            if (got != expect) {
                print_error("seed %llx round %d pair (%d, %d): expected %d reports, got %d\n",
                            (unsigned long long)seed, round, a, b, expect, got);
                fail();
            }
        }
    memset(m->moved, 0, sizeof m->moved);
    /* nothing moved since: the next call reports nothing */
    long again = 0;
    bp_update_pairs(bp, count_pair, &again);
    assert_int_equal(again, 0);
}

typedef struct query_log {
    int hits[MODEL_MAX];
    int calls, stop_after;
} query_log;

static int log_query(void *ctx, int user)
{
    query_log *q = ctx;
    q->hits[user]++;
    q->calls++;
    return q->stop_after == 0 || q->calls < q->stop_after;
}

static void check_query(const broadphase *bp, const model *m, aabb q, uint64_t seed, int round)
{
    query_log *log = calloc(1, sizeof *log);
    assert_non_null(log);
    bp_query(bp, q, log_query, log);
    int expected = 0;
    for (int i = 0; i < MODEL_MAX; i++) {
        int expect = m->alive[i] && aabb_overlap(q, m->box[i]);
        expected += expect;
        if (log->hits[i] != expect) {
            print_error("seed %llx round %d query: user %d expected %d got %d\n", (unsigned long long)seed, round, i,
                        expect, log->hits[i]);
            fail();
        }
    }
    /* a callback returning 0 ends the query at once */
    if (expected >= 2) {
        memset(log, 0, sizeof *log);
        log->stop_after = 2;
        bp_query(bp, q, log_query, log);
        assert_int_equal(log->calls, 2);
    }
    free(log);
}

typedef struct ray_log {
    const model *m;
    int hits[MODEL_MAX];
    int calls, closest, clip; /* clip: return each box's entry, as a shape cast would */
    double best_t, start_t;
    int unclipped, beyond; /* max_t not the last clip; a box entered only past it */
} ray_log;

static double log_ray(void *ctx, int user, vec3 o, vec3 d, double max_t)
{
    ray_log *r = ctx;
    r->hits[user]++;
    r->calls++;
    if (!r->clip) return max_t;
    if (max_t != (r->closest >= 0 ? r->best_t : r->start_t)) r->unclipped++;
    double t = ray_box_reference(r->m->box[user], o, d, r->start_t);
    if (t > max_t) r->beyond++;
    if (t >= 0.0 && t < r->best_t) {
        r->best_t = t;
        r->closest = user;
    }
    return t >= 0.0 ? t : max_t;
}

static double stop_ray(void *ctx, int user, vec3 o, vec3 d, double max_t)
{
    (void)user, (void)o, (void)d, (void)max_t;
    (*(int *)ctx)++;
    return -1.0;
}

static void check_ray(const broadphase *bp, const model *m, vec3 o, vec3 d, uint64_t seed, int round)
{
    ray_log *r = calloc(1, sizeof *r);
    assert_non_null(r);
    r->m = m;
    bp_ray_cast(bp, o, d, 1.0, log_ray, r);
    int expected = 0, closest = -1;
    double closest_t = HUGE_VAL;
    for (int i = 0; i < MODEL_MAX; i++) {
        double t = m->alive[i] ? ray_box_reference(m->box[i], o, d, 1.0) : -1.0;
        int expect = t >= 0.0;
        expected += expect;
        if (expect && t < closest_t) {
            closest_t = t;
            closest = i;
        }
        if (r->hits[i] != expect) {
            print_error("seed %llx round %d ray: user %d expected %d got %d\n", (unsigned long long)seed, round, i,
                        expect, r->hits[i]);
            fail();
        }
    }
    /* clipping to each hit finds the nearest box and never visits one beyond it */
    memset(r->hits, 0, sizeof r->hits);
    r->calls = 0;
    r->clip = 1;
    r->closest = -1;
    r->best_t = HUGE_VAL;
    r->start_t = 1.0;
    bp_ray_cast(bp, o, d, 1.0, log_ray, r);
    assert_int_equal(r->unclipped, 0);
    assert_int_equal(r->beyond, 0);
    /* (several boxes may share the nearest entry, e.g. 0 from inside) */
    if (closest < 0) {
        assert_int_equal(r->closest, -1);
    } else {
        assert_true(r->closest >= 0);
        assert_true(r->best_t == closest_t);
        assert_true(ray_box_reference(m->box[r->closest], o, d, 1.0) == closest_t);
    }
    assert_true(r->calls <= expected);
    /* a negative return ends the cast */
    int calls = 0;
    bp_ray_cast(bp, o, d, 1.0, stop_ray, &calls);
    assert_int_equal(calls, expected > 0);
    free(r);
}

static void run_random_model(uint64_t seed, int rounds, int edits, double extent)
{
    model *m = calloc(1, sizeof *m);
    pair_log log;
    assert_non_null(m);
    log_init(&log, MODEL_MAX);
    broadphase *bp = bp_create();
    assert_non_null(bp);
    uint64_t s = seed;
    for (int round = 0; round < rounds; round++) {
        random_edits(bp, m, &s, edits, extent);
        int alive = 0;
        for (int i = 0; i < MODEL_MAX; i++) {
            if (!m->alive[i]) continue;
            alive++;
            assert_int_equal(bp_get_user(bp, m->proxy[i]), i);
            aabb stored = bp_get_aabb(bp, m->proxy[i]);
            assert_memory_equal(&stored, &m->box[i], sizeof stored);
        }
        assert_int_equal(bp_proxy_count(bp), alive);
        assert_true(bp_validate(bp));
        check_pairs(bp, m, &log, seed, round);
        aabb q = random_box(&s, extent);
        q.hi = v3_add(q.hi, v3(3 * rnd(&s), 3 * rnd(&s), 3 * rnd(&s)));
        check_query(bp, m, q, seed, round);
        vec3 o = v3(-2, extent * rnd(&s), extent * rnd(&s));
        vec3 d = v3(extent + 4, extent * (rnd(&s) - 0.5), extent * (rnd(&s) - 0.5));
        check_ray(bp, m, o, d, seed, round);
        /* axis-parallel rays (zero direction components) from inside the volume */
        vec3 axis = round % 3 == 0 ? v3(1, 0, 0) : round % 3 == 1 ? v3(0, -1, 0) : v3(0, 0, 1);
        check_ray(bp, m, v3(extent * rnd(&s), extent * rnd(&s), extent * rnd(&s)), v3_scale(axis, extent), seed,
                  round);
    }
    /* destroy everything: the trees empty out cleanly */
    for (int i = 0; i < MODEL_MAX; i++)
        if (m->alive[i]) bp_destroy_proxy(bp, m->proxy[i]);
    assert_int_equal(bp_proxy_count(bp), 0);
    assert_int_equal(bp_tree_height(bp, 0), -1);
    assert_int_equal(bp_tree_height(bp, 1), -1);
    assert_true(bp_validate(bp));
    long pairs = 0;
    bp_update_pairs(bp, count_pair, &pairs);
    assert_int_equal(pairs, 0);
    bp_destroy(bp);
    free(log.count);
    free(m);
}

static void test_random_edits_sparse(void **state)
{
    (void)state;
    run_random_model(0xABCDEF12345ULL, 40, 80, 20.0);
}

static void test_random_edits_dense(void **state)
{
    (void)state;
    /* a tight volume: many overlaps, many pairs where both proxies moved */
    run_random_model(0x5EED0000C0FFEEULL, 30, 150, 6.0);
}

/* ---- hand-built cases ----------------------------------------------------- */

static void test_static_and_moving_pairs(void **state)
{
    (void)state;
    pair_log log;
    log_init(&log, 8);
    broadphase *bp = bp_create();
    /* users 0, 1: overlapping static boxes; 2: moving box over both; 3: moving, apart */
    int s0 = bp_create_proxy(bp, box_at(v3(0, 0, 0), v3(1, 1, 1)), 1, 0);
    int s1 = bp_create_proxy(bp, box_at(v3(1.5, 0, 0), v3(1, 1, 1)), 1, 1);
    int m2 = bp_create_proxy(bp, box_at(v3(0.75, 0, 1.5), v3(0.5, 0.5, 0.6)), 0, 2);
    int m3 = bp_create_proxy(bp, box_at(v3(10, 0, 0), v3(1, 1, 1)), 0, 3);
    assert_true(s0 >= 0 && s1 >= 0 && m2 >= 0 && m3 >= 0);
    bp_update_pairs(bp, log_pair, &log);
    /* z: 2 spans [0.9, 2.1], statics [-1, 1]: overlap; x: [0.25, 1.25] meets both */
    assert_int_equal(reported(&log, 0, 2), 1);
    assert_int_equal(reported(&log, 1, 2), 1);
    assert_int_equal(reported(&log, 0, 1), 0); /* static-static, though both new */
    assert_int_equal(reported(&log, 2, 3) + reported(&log, 0, 3) + reported(&log, 1, 3), 0);

    /* only the static proxy 0 moves: its pair with the unmoved 2 comes again, not 2's pair with 1 */
    log_clear(&log);
    bp_move_proxy(bp, s0, box_at(v3(0, 0, 0.05), v3(1, 1, 1)));
    bp_update_pairs(bp, log_pair, &log);
    assert_int_equal(reported(&log, 0, 2), 1);
    assert_int_equal(reported(&log, 1, 2), 0);
    assert_int_equal(reported(&log, 0, 1), 0);

    /* both members of a static-moving pair moved: reported once */
    log_clear(&log);
    bp_move_proxy(bp, s1, box_at(v3(1.5, 0, 0.05), v3(1, 1, 1)));
    bp_move_proxy(bp, m2, box_at(v3(0.75, 0, 1.4), v3(0.5, 0.5, 0.6)));
    bp_update_pairs(bp, log_pair, &log);
    assert_int_equal(reported(&log, 1, 2), 1);
    assert_int_equal(reported(&log, 0, 2), 1);
    assert_int_equal(reported(&log, 0, 1), 0);

    /* faces that touch count as overlapping: 3 moves to x in [2.5, 4.5], touching 1's face at 2.5 */
    log_clear(&log);
    bp_move_proxy(bp, m3, box_at(v3(3.5, 0, 0), v3(1, 1, 1)));
    bp_update_pairs(bp, log_pair, &log);
    assert_int_equal(reported(&log, 1, 3), 1);
    assert_int_equal(reported(&log, 0, 3), 0);
    assert_true(bp_validate(bp));
    bp_destroy(bp);
    free(log.count);
}

/* bp_create_proxies (a snapshot's restore) against one insertion at a time:
 * valid balanced trees, and the same pairs reported
 * (against brute force) now and after some proxies move. */
static void test_bulk_build_matches_insertion(void **state)
{
    (void)state;
    enum { N = 700 };
    static aabb box[N];
    static int is_static[N], user[N], proxy[N], proxy_one[N];
    unsigned seed = 2024;
    for (int i = 0; i < N; i++) {
        double r[6];
        for (int k = 0; k < 6; k++) {
            seed = seed * 1664525u + 1013904223u;
            r[k] = (double)(seed >> 8) / 16777216.0;
        }
        box[i] = box_at(v3(20 * r[0], 20 * r[1], 5 * r[2]), v3(0.1 + 0.6 * r[3], 0.1 + 0.6 * r[4], 0.1 + 0.6 * r[5]));
        is_static[i] = i % 4 == 1;
        user[i] = i;
    }
    broadphase *bulk = bp_create(), *one = bp_create();
    assert_true(bp_create_proxies(bulk, box, is_static, user, N, proxy));
    assert_int_equal(bp_create_proxies(bulk, box, is_static, user, N, proxy), 0); /* only into an empty one */
    for (int i = 0; i < N; i++) assert_true((proxy_one[i] = bp_create_proxy(one, box[i], is_static[i], user[i])) >= 0);
    for (int i = 0; i < N; i++) assert_int_equal(bp_get_user(bulk, proxy[i]), i);
    assert_true(bp_validate(bulk));
    assert_int_equal(bp_proxy_count(bulk), N);
    /* median splits: height ceil(log2 n) for each tree */
    /* as good as the tree the step keeps (one insertion at a time, with
     * rotations) by the surface-area cost a query pays: Morton order with
     * cubic cells measured 27,044 / 15,023 against 26,556 / 15,108
     * (median splits, the build before it: 27,863 / 15,740; cells scaled
     * per axis: 35,872, 1.35x) */
    assert_true(bp_tree_area(bulk, 0) <= 1.1 * bp_tree_area(one, 0));
    assert_true(bp_tree_area(bulk, 1) <= 1.1 * bp_tree_area(one, 1));
    pair_log a, b;
    log_init(&a, N);
    log_init(&b, N);
    for (int round = 0; round < 2; round++) {
        log_clear(&a);
        log_clear(&b);
        bp_update_pairs(bulk, log_pair, &a);
        bp_update_pairs(one, log_pair, &b);
        assert_int_equal(a.self_pairs + a.out_of_range, 0);
        for (int i = 0; i < N; i++)
            for (int j = i + 1; j < N; j++) {
                int overlap = box[i].lo.x <= box[j].hi.x && box[j].lo.x <= box[i].hi.x && box[i].lo.y <= box[j].hi.y &&
                              box[j].lo.y <= box[i].hi.y && box[i].lo.z <= box[j].hi.z && box[j].lo.z <= box[i].hi.z;
                int expect = round == 0 ? overlap && !(is_static[i] && is_static[j]) : -1;
                if (expect >= 0) assert_int_equal(reported(&a, i, j), expect);
                assert_int_equal(reported(&a, i, j), reported(&b, i, j));
            }
        /* every seventh proxy moves by a box size */
        for (int i = 0; i < N; i += 7) {
            box[i] = box_at(v3_add(v3_scale(v3_add(box[i].lo, box[i].hi), 0.5), v3(0.5, -0.3, 0.2)),
                            v3_scale(v3_sub(box[i].hi, box[i].lo), 0.5));
            bp_move_proxy(bulk, proxy[i], box[i]);
            bp_move_proxy(one, proxy_one[i], box[i]);
        }
    }
    assert_true(bp_validate(bulk));
    free(a.count);
    free(b.count);
    bp_destroy(bulk);
    bp_destroy(one);
}

/* Bulk builds where Morton codes cannot tell the boxes apart: boxes that
 * share one centre, and a dense cluster (1 m across) with one box 1e5 m
 * away (every cluster box in the same 98 m cell). Both fall back to median
 * splits: balanced trees, the pairs of brute force, and (the cluster) a
 * surface-area cost no worse than one insertion at a time. */
static void test_bulk_build_degenerate_codes(void **state)
{
    (void)state;
    enum { N = 301 };
    static aabb box[N];
    static int is_static[N], user[N], proxy[N];
    for (int scene = 0; scene < 2; scene++) {
        unsigned seed = 77u + (unsigned)scene;
        for (int i = 0; i < N; i++) {
            double r[6];
            for (int k = 0; k < 6; k++) {
                seed = seed * 1664525u + 1013904223u;
                r[k] = (double)(seed >> 8) / 16777216.0;
            }
            vec3 c = scene == 0 ? v3(3, -2, 1) : v3(r[0], r[1], r[2]);
            vec3 h = scene == 0 ? v3(0.01 + r[3], 0.01 + r[4], 0.01 + r[5]) : v3(0.02 + 0.05 * r[3], 0.02 + 0.05 * r[4], 0.02 + 0.05 * r[5]);
            box[i] = box_at(c, h);
            is_static[i] = 0;
            user[i] = i;
        }
        if (scene == 1) box[N / 2] = box_at(v3(1e5, -1e5, 1e5), v3(1, 1, 1));
        broadphase *bulk = bp_create(), *one = bp_create();
        assert_true(bp_create_proxies(bulk, box, is_static, user, N, proxy));
        for (int i = 0; i < N; i++) assert_true(bp_create_proxy(one, box[i], 0, i) >= 0);
        assert_true(bp_validate(bulk));
        /* median splits below the outlier's split: ceil(log2 300) + 1 */
        assert_true(bp_tree_height(bulk, 0) <= 10);
        /* the root (every box's union) holds the far box: the rest is the cluster's */
        aabb all = box[0];
        for (int i = 1; i < N; i++) all = aabb_union(all, box[i]);
        double cluster = bp_tree_area(bulk, 0) - aabb_area(all), cluster_one = bp_tree_area(one, 0) - aabb_area(all);
        if (scene == 1) assert_true(cluster <= 1.1 * cluster_one);
        pair_log a;
        log_init(&a, N);
        bp_update_pairs(bulk, log_pair, &a);
        assert_int_equal(a.self_pairs + a.out_of_range, 0);
        for (int i = 0; i < N; i++)
            for (int j = i + 1; j < N; j++) {
                int overlap = box[i].lo.x <= box[j].hi.x && box[j].lo.x <= box[i].hi.x && box[i].lo.y <= box[j].hi.y &&
                              box[j].lo.y <= box[i].hi.y && box[i].lo.z <= box[j].hi.z && box[j].lo.z <= box[i].hi.z;
                assert_int_equal(reported(&a, i, j), overlap);
            }
        free(a.count);
        bp_destroy(bulk);
        bp_destroy(one);
    }
}

static void test_destroy_removes_from_moved_buffer(void **state)
{
    (void)state;
    pair_log log;
    log_init(&log, 8);
    broadphase *bp = bp_create();
    int a = bp_create_proxy(bp, box_at(v3(0, 0, 0), v3(1, 1, 1)), 0, 0);
    int b = bp_create_proxy(bp, box_at(v3(0.5, 0, 0), v3(1, 1, 1)), 0, 1);
    int c = bp_create_proxy(bp, box_at(v3(-0.5, 0, 0), v3(1, 1, 1)), 0, 2);
    bp_update_pairs(bp, log_pair, &log);
    assert_int_equal(reported(&log, 0, 1) + reported(&log, 0, 2) + reported(&log, 1, 2), 3);

    /* a moves then dies, b dies unmoved: only c's new pairs remain, none with a dead proxy */
    log_clear(&log);
    bp_move_proxy(bp, a, box_at(v3(0.1, 0, 0), v3(1, 1, 1)));
    bp_move_proxy(bp, c, box_at(v3(-0.4, 0, 0), v3(1, 1, 1)));
    bp_destroy_proxy(bp, a);
    bp_destroy_proxy(bp, b);
    assert_true(bp_validate(bp));
    bp_update_pairs(bp, log_pair, &log);
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 8; j++)
            if (i != j) assert_int_equal(reported(&log, i, j), 0);

    /* a new proxy reuses a freed id; it is new, so its pair with c is reported */
    int d = bp_create_proxy(bp, box_at(v3(0, 0, 0), v3(1, 1, 1)), 0, 3);
    assert_true(d >= 0);
    bp_update_pairs(bp, log_pair, &log);
    assert_int_equal(reported(&log, 2, 3), 1);
    assert_int_equal(bp_get_user(bp, d), 3);
    assert_int_equal(bp_proxy_count(bp), 2);
    bp_destroy(bp);
    free(log.count);
}

static void test_ray_cast_by_hand(void **state)
{
    (void)state;
    model *m = calloc(1, sizeof *m);
    ray_log *r = calloc(1, sizeof *r);
    broadphase *bp = bp_create();
    m->box[0] = (aabb){v3(0, 0, 0), v3(1, 1, 1)};
    m->box[1] = (aabb){v3(2, 0, 0), v3(3, 1, 1)};
    m->box[2] = (aabb){v3(5, 5, 5), v3(6, 6, 6)};
    for (int i = 0; i < 3; i++) bp_create_proxy(bp, m->box[i], i == 1, i);
    r->m = m;
    /* along x from x = -1, 10 m long: enters box 0 at t = 0.1, box 1 at 0.3 */
    struct { vec3 o; double max_t; int hit0, hit1; double nearest; } cases[] = {
        {v3(-1, 0.5, 0.5), 1.0, 1, 1, 0.1},
        {v3(-1, 1.0, 0.5), 1.0, 1, 1, 0.1},   /* grazing the y = 1 faces: touching counts */
        {v3(-1, 1.001, 0.5), 1.0, 0, 0, -1},  /* just above them */
        {v3(-1, 0.5, 0.5), 0.25, 1, 0, 0.1},  /* too short to reach box 1 */
        {v3(0.5, 0.5, 0.5), 1.0, 1, 1, 0.0},  /* from inside box 0 */
        {v3(-1, 0.5, 0.5), 0.05, 0, 0, -1},   /* ends before box 0 */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memset(r->hits, 0, sizeof r->hits);
        r->clip = 0;
        bp_ray_cast(bp, cases[k].o, v3(10, 0, 0), cases[k].max_t, log_ray, r);
        assert_int_equal(r->hits[0], cases[k].hit0);
        assert_int_equal(r->hits[1], cases[k].hit1);
        assert_int_equal(r->hits[2], 0);
        r->clip = 1;
        r->closest = -1;
        r->best_t = HUGE_VAL;
        r->start_t = cases[k].max_t;
        bp_ray_cast(bp, cases[k].o, v3(10, 0, 0), cases[k].max_t, log_ray, r);
        if (cases[k].nearest < 0) {
            assert_int_equal(r->closest, -1);
        } else {
            assert_int_equal(r->closest, 0);
            assert_true(fabs(r->best_t - cases[k].nearest) < 1e-15);
        }
    }
    bp_destroy(bp);
    free(r);
    free(m);
}

/* Boxes nested inside each other make the tree deep: traversal must not care
 * (the stack grows on the heap past its local part). */
static void test_nested_boxes_deep_tree(void **state)
{
    (void)state;
    enum { N = 600 }; /* <= MODEL_MAX, and deeper than the walk's 256 local slots */
    broadphase *bp = bp_create();
    for (int i = 0; i < N; i++) {
        double h = 1.0 + i;
        assert_true(bp_create_proxy(bp, box_at(v3(0, 0, 0), v3(h, h, h)), 0, i) >= 0);
    }
    assert_true(bp_validate(bp));
    long pairs = 0;
    bp_update_pairs(bp, count_pair, &pairs);
    assert_int_equal(pairs, (long)N * (N - 1) / 2); /* all nested: every pair overlaps */
    /* a point at distance 100.5 along x lies in boxes of half-size >= 100.5: users 100..N-1 */
    query_log *q = calloc(1, sizeof *q);
    bp_query(bp, box_at(v3(100.5, 0, 0), v3(0, 0, 0)), log_query, q);
    assert_int_equal(q->calls, N - 100);
    for (int i = 0; i < N; i++) assert_int_equal(q->hits[i], i >= 100);
    /* a ray from outside along -x enters box i at x = 1 + i: the first hit clipped is the largest */
    model *m = calloc(1, sizeof *m);
    ray_log *r = calloc(1, sizeof *r);
    for (int i = 0; i < N; i++) m->box[i] = box_at(v3(0, 0, 0), v3(1.0 + i, 1.0 + i, 1.0 + i));
    r->m = m;
    r->clip = 1;
    r->closest = -1;
    r->best_t = HUGE_VAL;
    r->start_t = 1.0;
    bp_ray_cast(bp, v3(2 * N, 0.5, 0.5), v3(-4 * N, 0, 0), 1.0, log_ray, r);
    assert_int_equal(r->closest, N - 1);
    assert_int_equal(r->unclipped + r->beyond, 0);
    assert_true(fabs(r->best_t - (2.0 * N - N) / (4.0 * N)) < 1e-15);
    free(r);
    free(m);
    free(q);
    bp_destroy(bp);
}

/* ---- shape of the tree, scale ----------------------------------------------- */

static int count_visit(void *ctx, int user)
{
    (void)user;
    (*(int *)ctx)++;
    return 1;
}

static void test_sorted_insertion_stays_shallow(void **state)
{
    (void)state;
    enum { N = 10000 };
    int *proxy = malloc(sizeof *proxy * N);
    broadphase *bp = bp_create();
    for (int i = 0; i < N; i++) {
        aabb b = {v3(i, 0, 0), v3(i + 0.5, 0.5, 0.5)};
        proxy[i] = bp_create_proxy(bp, b, 0, i);
        assert_true(proxy[i] >= 0);
    }
    /* a binary tree of N leaves is at least ceil(log2 N) = 14 high */
    int h = bp_tree_height(bp, 0);
    print_message("sorted insertion of %d: height %d\n", N, h);
    assert_true(h >= 14);
    assert_true(h <= 3 * 14);
    assert_true(bp_validate(bp));
    int visits = 0;
    bp_query(bp, box_at(v3(5000.25, 0.25, 0.25), v3(0.1, 0.1, 0.1)), count_visit, &visits);
    assert_int_equal(visits, 1);
    /* remove every other one, in order: no deeper, still consistent, queries still exact */
    for (int i = 0; i < N; i += 2) bp_destroy_proxy(bp, proxy[i]);
    assert_true(bp_tree_height(bp, 0) <= h);
    assert_true(bp_validate(bp));
    query_log *q = calloc(1, sizeof *q);
    bp_query(bp, (aabb){v3(99.9, 0, 0), v3(110.1, 1, 1)}, log_query, q);
    for (int i = 0; i < MODEL_MAX; i++) assert_int_equal(q->hits[i], i >= 100 && i <= 110 && i % 2 == 1);
    free(q);
    bp_destroy(bp);
    free(proxy);
}

static void test_hundred_thousand_proxies(void **state)
{
    (void)state;
    /* boxes of half-size 0.6 on a unit grid of 40 x 50 x 50: each overlaps its
     * 26 grid neighbours and nothing else. Ordered pairs with |di|, |dj|, |dk|
     * <= 1 number (3a-2)(3b-2)(3c-2) including the a b c self pairs, so the
     * unordered pairs are ((3a-2)(3b-2)(3c-2) - abc) / 2 */
    enum { A = 40, B = 50, C = 50, N = A * B * C };
    const long expected = ((long)(3 * A - 2) * (3 * B - 2) * (3 * C - 2) - (long)N) / 2;
    int *proxy = malloc(sizeof *proxy * N);
    broadphase *bp = bp_create();
    uint64_t s = 0x100000ULL;
    for (int n = 0; n < N; n++) {
        int i = n % A, j = (n / A) % B, k = n / (A * B);
        proxy[n] = bp_create_proxy(bp, box_at(v3(i, j, k), v3(0.6, 0.6, 0.6)), 0, n);
        assert_true(proxy[n] >= 0);
    }
    assert_int_equal(bp_proxy_count(bp), N);
    int h = bp_tree_height(bp, 0);
    print_message("%d proxies on a grid: height %d\n", N, h);
    assert_true(h >= 17 && h <= 3 * 17);
    long pairs = 0;
    bp_update_pairs(bp, count_pair, &pairs);
    assert_int_equal(pairs, expected);
    /* shift every box by a tenth: nothing new overlaps, all pairs come again once */
    for (int n = 0; n < N; n++) {
        aabb b = bp_get_aabb(bp, proxy[n]);
        b.lo = v3_add(b.lo, v3(0.1, 0, 0));
        b.hi = v3_add(b.hi, v3(0.1, 0, 0));
        bp_move_proxy(bp, proxy[n], b);
    }
    pairs = 0;
    bp_update_pairs(bp, count_pair, &pairs);
    assert_int_equal(pairs, expected);
    assert_true(bp_validate(bp));
    /* move them all, then destroy them all in random order before any update:
     * each destroy drops the proxy from the moved buffer at constant cost */
    for (int n = 0; n < N; n++) bp_move_proxy(bp, proxy[n], bp_get_aabb(bp, proxy[n]));
    for (int n = N - 1; n > 0; n--) {
        int r = (int)(rnd(&s) * (n + 1));
        int t = proxy[n];
        proxy[n] = proxy[r];
        proxy[r] = t;
    }
    for (int n = 0; n < N; n++) bp_destroy_proxy(bp, proxy[n]);
    assert_int_equal(bp_proxy_count(bp), 0);
    pairs = 0;
    bp_update_pairs(bp, count_pair, &pairs);
    assert_int_equal(pairs, 0);
    assert_true(bp_validate(bp));
    bp_destroy(bp);
    free(proxy);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_edits_sparse),
        cmocka_unit_test(test_random_edits_dense),
        cmocka_unit_test(test_static_and_moving_pairs),
        cmocka_unit_test(test_bulk_build_matches_insertion),
        cmocka_unit_test(test_bulk_build_degenerate_codes),
        cmocka_unit_test(test_destroy_removes_from_moved_buffer),
        cmocka_unit_test(test_ray_cast_by_hand),
        cmocka_unit_test(test_nested_boxes_deep_tree),
        cmocka_unit_test(test_sorted_insertion_stays_shallow),
        cmocka_unit_test(test_hundred_thousand_proxies),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
