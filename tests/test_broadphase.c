/* test_broadphase.c - the AABB trees against brute force: the pairs reported
 * after random creates, moves and destroys, AABB queries and ray casts. */
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

enum { MAX = 600 };

typedef struct model {
    int alive[MAX], is_static[MAX], proxy[MAX], moved[MAX];
    aabb box[MAX];
    unsigned char *seen; /* MAX x MAX: pair reported this round */
    int duplicates, self_pairs, static_pairs, count;
} model;

static double rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static aabb random_box(uint64_t *s)
{
    vec3 c = v3(20 * rnd(s), 20 * rnd(s), 20 * rnd(s));
    vec3 h = v3(0.2 + rnd(s), 0.2 + rnd(s), 0.2 + rnd(s));
    aabb b = {v3_sub(c, h), v3_add(c, h)};
    return b;
}

static void on_pair(void *ctx, int a, int b)
{
    model *m = ctx;
    if (a == b) { m->self_pairs++; return; }
    if (m->is_static[a] && m->is_static[b]) m->static_pairs++;
    int lo = a < b ? a : b, hi = a < b ? b : a;
    if (m->seen[lo * MAX + hi]) m->duplicates++;
    m->seen[lo * MAX + hi] = 1;
}

static void check_round(broadphase *bp, model *m)
{
    memset(m->seen, 0, (size_t)MAX * MAX);
    bp_update_pairs(bp, on_pair, m);
    assert_int_equal(m->self_pairs, 0);
    assert_int_equal(m->static_pairs, 0);
    assert_int_equal(m->duplicates, 0);
    /* exactly the overlapping pairs with at least one moved proxy, none static-static */
    for (int a = 0; a < MAX; a++)
        for (int b = a + 1; b < MAX; b++) {
            int expect = m->alive[a] && m->alive[b] && (m->moved[a] || m->moved[b]) &&
                         !(m->is_static[a] && m->is_static[b]) && aabb_overlap(m->box[a], m->box[b]);
            if (expect != m->seen[a * MAX + b]) {
                print_error("pair (%d, %d): expected %d, reported %d\n", a, b, expect, m->seen[a * MAX + b]);
                fail();
            }
        }
    memset(m->moved, 0, sizeof m->moved);
}

static int count_query(void *ctx, int user)
{
    int *hits = ctx;
    hits[user]++;
    return 1;
}

static double ray_collect(void *ctx, int user, vec3 o, vec3 d, double max_t)
{
    (void)o;
    (void)d;
    int *hits = ctx;
    hits[user]++;
    return max_t;
}

static double ray_box(aabb b, vec3 o, vec3 d, double max_t)
{
    double t0 = 0, t1 = max_t;
    for (int i = 0; i < 3; i++) {
        double oi = v3_get(o, i), di = v3_get(d, i), lo = v3_get(b.lo, i), hi = v3_get(b.hi, i);
        if (di == 0) { if (oi < lo || oi > hi) return -1; continue; }
        double a = (lo - oi) / di, c = (hi - oi) / di;
        if (a > c) { double t = a; a = c; c = t; }
        t0 = fmax(t0, a);
        t1 = fmin(t1, c);
        if (t0 > t1) return -1;
    }
    return t0;
}

static void test_pairs_queries_rays_against_brute_force(void **state)
{
    (void)state;
    model *m = calloc(1, sizeof *m);
    m->seen = calloc((size_t)MAX * MAX, 1);
    broadphase *bp = bp_create();
    uint64_t s = 0xABCDEF12345ULL;
    for (int round = 0; round < 40; round++) {
        for (int op = 0; op < 60; op++) {
            int i = (int)(rnd(&s) * MAX);
            if (!m->alive[i]) {
                m->box[i] = random_box(&s);
                m->is_static[i] = rnd(&s) < 0.2;
                m->proxy[i] = bp_create_proxy(bp, m->box[i], m->is_static[i], i);
                assert_true(m->proxy[i] >= 0);
                m->alive[i] = 1;
                m->moved[i] = 1;
            } else if (rnd(&s) < 0.3) {
                bp_destroy_proxy(bp, m->proxy[i]);
                m->alive[i] = 0;
                m->moved[i] = 0;
            } else {
                vec3 d = v3(rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5);
                m->box[i].lo = v3_add(m->box[i].lo, d);
                m->box[i].hi = v3_add(m->box[i].hi, d);
                bp_move_proxy(bp, m->proxy[i], m->box[i]);
                m->moved[i] = 1;
            }
        }
        check_round(bp, m);
        /* queries and rays */
        int hits[MAX];
        aabb q = random_box(&s);
        q.hi = v3_add(q.hi, v3(3, 3, 3));
        memset(hits, 0, sizeof hits);
        bp_query(bp, q, count_query, hits);
        for (int i = 0; i < MAX; i++) assert_int_equal(hits[i], m->alive[i] && aabb_overlap(q, m->box[i]));
        vec3 o = v3(-5, 20 * rnd(&s), 20 * rnd(&s)), d = v3(30, 5 * (rnd(&s) - 0.5), 5 * (rnd(&s) - 0.5));
        memset(hits, 0, sizeof hits);
        bp_ray_cast(bp, o, d, 1.0, ray_collect, hits);
        for (int i = 0; i < MAX; i++) assert_int_equal(hits[i], m->alive[i] && ray_box(m->box[i], o, d, 1.0) >= 0);
    }
    bp_destroy(bp);
    free(m->seen);
    free(m);
}

/* Sorted insertion (the worst case for a naive tree) keeps queries cheap. */
static int count_visits(void *ctx, int user)
{
    (void)user;
    (*(int *)ctx)++;
    return 1;
}

static void test_sorted_insertion_stays_balanced(void **state)
{
    (void)state;
    broadphase *bp = bp_create();
    for (int i = 0; i < 20000; i++) {
        aabb b = {v3(i, 0, 0), v3(i + 0.5, 0.5, 0.5)};
        assert_true(bp_create_proxy(bp, b, 0, i) >= 0);
    }
    assert_int_equal(bp_proxy_count(bp), 20000);
    int visits = 0;
    aabb q = {v3(10000.1, 0.1, 0.1), v3(10000.2, 0.2, 0.2)};
    bp_query(bp, q, count_visits, &visits);
    assert_int_equal(visits, 1);
    bp_destroy(bp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pairs_queries_rays_against_brute_force),
        cmocka_unit_test(test_sorted_insertion_stays_balanced),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
