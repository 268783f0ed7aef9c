/* bench_broadphase.c - pair-finding cost of the broadphase at 1k, 10k and
 * 100k moving bodies at constant density (a jittered grid of ~1 m boxes
 * drifting a little each step; a proxy is re-inserted only when its tight box
 * leaves the fat one, as in the world), against brute force at 1k and 10k. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "broadphase.h"

#define MARGIN 0.1

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

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void run(int n, int steps, int brute)
{
    unsigned long long s = 0x9E3779B97F4A7C15ULL ^ (unsigned long long)n;
    int side = 1;
    while (side * side * side < n) side++;
    vec3 *pos = malloc(sizeof *pos * (size_t)n), *vel = malloc(sizeof *vel * (size_t)n);
    aabb *fat = malloc(sizeof *fat * (size_t)n);
    int *proxy = malloc(sizeof *proxy * (size_t)n);
    broadphase *bp = bp_create();
    double t0 = now_ms();
    for (int i = 0; i < n; i++) {
        /* spacing 1.2 m: neighbours' fat boxes overlap, as in a settling pile */
        pos[i] = v3(1.2 * (i % side) + 0.1 * rnd(&s), 1.2 * ((i / side) % side) + 0.1 * rnd(&s),
                    1.2 * (i / (side * side)) + 0.1 * rnd(&s));
        vel[i] = v3(0.04 * (rnd(&s) - 0.5), 0.04 * (rnd(&s) - 0.5), 0.04 * (rnd(&s) - 0.5));
        aabb box = {v3_sub(pos[i], v3(0.5, 0.5, 0.5)), v3_add(pos[i], v3(0.5, 0.5, 0.5))};
        fat[i] = aabb_fatten(box, MARGIN);
        proxy[i] = bp_create_proxy(bp, fat[i], 0, i);
    }
    /* a floor and four walls: static, never queried against each other */
    double L = 1.2 * side;
    aabb statics[5] = {{v3(-1, -1, -2), v3(L + 1, L + 1, -0.5)}, {v3(-2, -1, -1), v3(-0.6, L + 1, L)},
                       {v3(L, -1, -1), v3(L + 1, L + 1, L)}, {v3(-1, -2, -1), v3(L + 1, -0.6, L)},
                       {v3(-1, L, -1), v3(L + 1, L + 1, L)}};
    for (int i = 0; i < 5; i++) bp_create_proxy(bp, statics[i], 1, n + i);
    long pairs = 0;
    bp_update_pairs(bp, count_pair, &pairs);
    double build = now_ms() - t0;
    double *ms = malloc(sizeof *ms * (size_t)steps);
    long reported = 0, moved = 0;
    for (int k = 0; k < steps; k++) {
        double t1 = now_ms();
        for (int i = 0; i < n; i++) {
            pos[i] = v3_add(pos[i], vel[i]);
            aabb box = {v3_sub(pos[i], v3(0.5, 0.5, 0.5)), v3_add(pos[i], v3(0.5, 0.5, 0.5))};
            if (!aabb_contains(fat[i], box)) {
                fat[i] = aabb_fatten(box, MARGIN);
                bp_move_proxy(bp, proxy[i], fat[i]);
                moved++;
            }
        }
        long p = 0;
        bp_update_pairs(bp, count_pair, &p);
        reported += p;
        ms[k] = now_ms() - t1;
    }
    qsort(ms, (size_t)steps, sizeof *ms, cmp);
    double med = ms[steps / 2];
    printf("bench=broadphase bodies=%d build_ms=%.2f initial_pairs=%ld ms_per_step=%.4f ns_per_body=%.1f "
           "moved_per_step=%.0f new_pairs_per_step=%.0f\n",
           n, build, pairs, med, med * 1e6 / n, (double)moved / steps, (double)reported / steps);
    if (brute) {
        double t2 = now_ms();
        long bp_pairs = 0;
        for (int i = 0; i < n; i++)
            for (int j = i + 1; j < n; j++) bp_pairs += aabb_overlap(fat[i], fat[j]);
        double bms = now_ms() - t2;
        printf("bench=brute_force bodies=%d ms_per_step=%.3f ns_per_body=%.1f overlapping_pairs=%ld\n", n, bms,
               bms * 1e6 / n, bp_pairs);
    }
    bp_destroy(bp);
    free(pos); free(vel); free(fat); free(proxy); free(ms);
}

int main(void)
{
    run(1000, 200, 1);
    run(10000, 60, 1);
    run(100000, 30, 0);
    return 0;
}
