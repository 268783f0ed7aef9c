/* bench_broadphase.c - pair-finding cost of the broadphase at 1k, 10k and 100k
 * moving bodies, against brute force at 1k and 10k.
 *
 * The scene keeps density constant: ~1 m boxes on a jittered grid of 1.2 m
 * pitch (a settled pile: each box's fat AABB touches its neighbours'), a floor
 * and four walls as static proxies. Each step every body drifts a little; as in
 * the world, a proxy holds its box enlarged by a 0.1 m margin and is moved only
 * when the tight box leaves the fat one. Each body starts at a random point of
 * its re-insertion cycle, so every step moves a steady ~10% of the proxies. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "broadphase.h"

#define MARGIN 0.1
#define HALF 0.5
#define PITCH 1.2
#define MAX_SPEED 0.02 /* m per step along each axis: 1.2 m/s at 60 Hz */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static double rnd(unsigned long long *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static void count_pair(void *ctx, int a, int b)
{
    (void)a;
    (void)b;
    (*(long *)ctx)++;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static aabb tight_box(vec3 p) { aabb b = {v3_sub(p, v3(HALF, HALF, HALF)), v3_add(p, v3(HALF, HALF, HALF))}; return b; }

static double max_abs3(vec3 v)
{
    double a = fabs(v.x), b = fabs(v.y), c = fabs(v.z);
    return a > b ? (a > c ? a : c) : (b > c ? b : c);
}

static void run(int n, int steps, int with_brute_force)
{
    unsigned long long seed = 0x9E3779B97F4A7C15ULL ^ (unsigned long long)n;
    int side = 1;
    while (side * side * side < n) side++;
    vec3 *pos = malloc(sizeof *pos * (size_t)n), *vel = malloc(sizeof *vel * (size_t)n);
    aabb *fat = malloc(sizeof *fat * (size_t)(n + 5));
    int *proxy = malloc(sizeof *proxy * (size_t)n);
    double *ms_update = malloc(sizeof *ms_update * (size_t)steps), *ms_move = malloc(sizeof *ms_move * (size_t)steps);
    if (!pos || !vel || !fat || !proxy || !ms_update || !ms_move) {
        fprintf(stderr, "bench_broadphase: out of memory\n");
        exit(1);
    }
    for (int i = 0; i < n; i++) {
        pos[i] = v3(PITCH * (i % side) + 0.1 * rnd(&seed), PITCH * ((i / side) % side) + 0.1 * rnd(&seed),
                    PITCH * (i / (side * side)) + 0.1 * rnd(&seed));
        vel[i] = v3(2 * MAX_SPEED * (rnd(&seed) - 0.5), 2 * MAX_SPEED * (rnd(&seed) - 0.5),
                    2 * MAX_SPEED * (rnd(&seed) - 0.5));
        /* fattened some random number of steps ago (less than it takes to leave) */
        double age = rnd(&seed) * MARGIN / (max_abs3(vel[i]) + 1e-12);
        fat[i] = aabb_fatten(tight_box(v3_madd(pos[i], -age, vel[i])), MARGIN);
    }
    double L = PITCH * side;
    aabb walls[5] = {{v3(-1, -1, -2), v3(L + 1, L + 1, -0.5)}, {v3(-2, -1, -1), v3(-0.6, L + 1, L)},
                     {v3(L, -1, -1), v3(L + 1, L + 1, L)},     {v3(-1, -2, -1), v3(L + 1, -0.6, L)},
                     {v3(-1, L, -1), v3(L + 1, L + 1, L)}};
    memcpy(fat + n, walls, sizeof walls);

    broadphase *bp = bp_create();
    double t0 = now_ms();
    for (int i = 0; i < n; i++) proxy[i] = bp_create_proxy(bp, fat[i], 0, i);
    for (int i = 0; i < 5; i++) bp_create_proxy(bp, walls[i], 1, n + i);
    double build_ms = now_ms() - t0;
    long initial_pairs = 0;
    t0 = now_ms();
    bp_update_pairs(bp, count_pair, &initial_pairs); /* every proxy is new: all overlapping pairs */
    double first_ms = now_ms() - t0;

    long moved = 0, reported = 0;
    for (int k = 0; k < steps; k++) {
        double t1 = now_ms();
        for (int i = 0; i < n; i++) {
            pos[i] = v3_add(pos[i], vel[i]);
            aabb box = tight_box(pos[i]);
            if (!aabb_contains(fat[i], box)) {
                fat[i] = aabb_fatten(box, MARGIN);
                bp_move_proxy(bp, proxy[i], fat[i]);
                moved++;
            }
        }
        double t2 = now_ms();
        long pairs = 0;
        bp_update_pairs(bp, count_pair, &pairs);
        double t3 = now_ms();
        reported += pairs;
        ms_move[k] = t2 - t1;
        ms_update[k] = t3 - t2;
    }
    double update = median(ms_update, steps), move = median(ms_move, steps);
    printf("bench=broadphase bodies=%d static=5 build_ms=%.2f first_update_ms=%.2f initial_pairs=%ld height=%d "
           "moved_per_step=%.0f ms_move=%.3f ms_update=%.3f pairs=%.0f ns_per_body=%.1f ns_per_body_step=%.1f\n",
           n, build_ms, first_ms, initial_pairs, bp_tree_height(bp, 0), (double)moved / steps, move, update,
           (double)reported / steps, update * 1e6 / n, (update + move) * 1e6 / n);

    if (with_brute_force) {
        /* every pair of the current boxes but static-static, the O(n^2) way;
         * a tree built from the same boxes must report exactly as many */
        t0 = now_ms();
        long brute_pairs = 0;
        for (int i = 0; i < n + 5; i++)
            for (int j = i + 1 > n ? n + 5 : i + 1; j < n + 5; j++) brute_pairs += aabb_overlap(fat[i], fat[j]);
        double brute_ms = now_ms() - t0;
        broadphase *fresh = bp_create();
        for (int i = 0; i < n + 5; i++) bp_create_proxy(fresh, fat[i], i >= n, i);
        long tree_pairs = 0;
        bp_update_pairs(fresh, count_pair, &tree_pairs);
        bp_destroy(fresh);
        printf("bench=brute_force bodies=%d ms_update=%.3f pairs=%ld ns_per_body=%.1f tree_agrees=%s\n", n, brute_ms,
               brute_pairs, brute_ms * 1e6 / n, tree_pairs == brute_pairs ? "yes" : "NO");
    }
    bp_destroy(bp);
    free(pos);
    free(vel);
    free(fat);
    free(proxy);
    free(ms_update);
    free(ms_move);
}

int main(void)
{
    run(1000, 200, 1);
    run(10000, 100, 1);
    run(100000, 40, 0);
    return 0;
}
