/* scaling.c - time per step against body count.
 *
 *   scaling [COUNT]
 *     a pile (spheres and cubes dropped on a floor inside walls, 1 m bodies
 *     at the peers' pile density), 100 to 50,000 bodies (the first COUNT
 *     sizes). CSV: bodies,ms_step,contacts.
 *   scaling switches SWITCH [PLANAR [TIMED]]
 *     resting boxes with one switch off (see run_switches).
 *   scaling switch-table PLANAR [ROUNDS [STEPS]]
 *     every switch of that scene, timed in interleaved rounds (101 of 4
 *     steps; see run_switch_table).
 *   scaling pyramids N [WORKERS [PRESET [TIMED]]]
 *     one row of the peers' pyramid grid (peers/scenes.h pyramidsN: base-10
 *     pyramids, 55 boxes each, mu 0.6, sleeping off): 30 untimed steps, then
 *     TIMED (150) timed ones, on WORKERS workers of the reference thread pool
 *     (1: no hooks). Also the first step after adding every body (on a fresh
 *     world, and again with one box thrown at the speed clamp) and the peak
 *     memory of the process (getrusage's ru_maxrss, what /usr/bin/time -v
 *     reports), so run one row per process. CSV (header with `scaling
 *     pyramids header`):
 *     engine,preset,workers,bodies,ms_step,us_body_step,first_step_ms,first_step_clamp_ms,peak_kb,kb_per_body,
 *     cpu_ms_step (the process's CPU time per timed step, all threads: on a
 *     loaded machine the one-worker figure that wall time cannot give) */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include "carom/carom.h"
#include "carom/carom_threads.h"
#include "peers/scenes.h"
#include "scenes_extra.h"

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void run(int n, int warm, int steps)
{
    carom_world_def wd = carom_world_def_default();
    wd.enable_sleep = 0;
    carom_world *w = carom_world_create(&wd);
    int grid = (int)ceil(sqrt(n / 8.0)); /* about 8 layers */
    double half = 0.6 * grid + 1.0;
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    double walls[4][6] = {{half + 0.5, 0, 10, 0.5, half + 1, 10}, {-half - 0.5, 0, 10, 0.5, half + 1, 10},
                          {0, half + 0.5, 10, half, 0.5, 10}, {0, -half - 0.5, 10, half, 0.5, 10}};
    for (int i = 0; i < 4; i++) {
        g.position.x = walls[i][0]; g.position.y = walls[i][1]; g.position.z = walls[i][2];
        g.shape = carom_shape_box(walls[i][3], walls[i][4], walls[i][5]);
        carom_body_create(w, &g);
    }
    for (int k = 0; k < n; k++) {
        int layer = k / (grid * grid), i = k % grid, j = (k / grid) % grid;
        carom_body_def d = carom_body_def_default();
        d.position.x = -0.6 * grid + 1.2 * i + 0.6;
        d.position.y = -0.6 * grid + 1.2 * j + 0.6;
        d.position.z = 1.0 + 1.5 * layer;
        d.shape = (i + j + layer) % 2 ? carom_shape_box(0.5, 0.5, 0.5) : carom_shape_sphere(0.5);
        d.mass = 1;
        carom_body_create(w, &d);
    }
    for (int s = 0; s < warm; s++) carom_world_step(w, 1.0 / 60);
    double *ms = malloc(sizeof *ms * (size_t)steps);
    for (int s = 0; s < steps; s++) {
        double t0 = bench_now_ms();
        carom_world_step(w, 1.0 / 60);
        ms[s] = bench_now_ms() - t0;
    }
    qsort(ms, (size_t)steps, sizeof *ms, cmp);
    carom_world_stats st = carom_world_stats_init();
    carom_world_get_stats(w, &st);
    printf("%d,%.4f,%d\n", n, ms[steps / 2], st.contacts);
    fflush(stdout);
    free(ms);
    carom_world_destroy(w);
}

static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* This thread's CPU time: the step's own cost, whatever else the machine runs. */
static double thread_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* A world of the grid on `workers` workers, every body added; one step timed
 * (the first) when first_ms is not NULL. clamp: one box starts at the speed
 * clamp, thrown over the grid. */
static carom_world *pyramid_world(SceneDesc *sc, carom_thread_pool *pool, const char *preset, int clamp,
                                  double *first_ms)
{
    carom_world_def wd = carom_world_def_default();
    if (carom_world_def_apply_preset(&wd, preset) != CAROM_OK) { fprintf(stderr, "bad preset %s\n", preset); exit(2); }
    wd.enable_sleep = 0;
    wd.gravity.z = -BENCH_GRAVITY;
    if (pool) carom_thread_pool_attach(pool, &wd);
    carom_world *w = carom_world_create(&wd);
    if (!w) { fprintf(stderr, "bad world settings\n"); exit(2); }
    carom_body_id *ids = malloc(sizeof *ids * (size_t)sc->nbodies);
    canonical_build(w, sc, ids);
    if (clamp) { /* the top box of the first pyramid, thrown at the clamp (4000 m/s) along x */
        carom_vec3 v = {wd.max_linear_speed, 0.0, 0.0};
        carom_body_set_linear_velocity(w, ids[sc->group - 1], v);
    }
    free(ids);
    if (first_ms) {
        double t0 = bench_now_ms();
        carom_world_step(w, BENCH_DT);
        *first_ms = bench_now_ms() - t0;
    }
    return w;
}

static int run_pyramids(int n, int workers, const char *preset, int timed)
{
    SceneDesc sc;
    char name[32];
    snprintf(name, sizeof name, "pyramids%d", n);
    if (!scene_make_by_name(&sc, name)) return 2;
    carom_thread_pool *pool = workers > 1 ? carom_thread_pool_create(workers) : NULL;
    if (workers > 1 && !pool) { fprintf(stderr, "cannot start %d threads\n", workers); return 2; }
    double first = 0.0, first_clamp = 0.0;
    carom_world_destroy(pyramid_world(&sc, pool, preset, 1, &first_clamp));
    carom_world *w = pyramid_world(&sc, pool, preset, 0, &first);
    for (int s = 1; s < sc.warm; s++) carom_world_step(w, BENCH_DT);
    double *ms = malloc(sizeof *ms * (size_t)timed);
    double cpu0 = cpu_ms();
    for (int s = 0; s < timed; s++) {
        double t0 = bench_now_ms();
        carom_world_step(w, BENCH_DT);
        ms[s] = bench_now_ms() - t0;
    }
    double cpu_step = (cpu_ms() - cpu0) / timed;
    qsort(ms, (size_t)timed, sizeof *ms, cmp);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double med = ms[timed / 2];
    printf("carom,%s,%d,%d,%.4f,%.3f,%.3f,%.3f,%ld,%.3f,%.4f\n", preset, workers, sc.nbodies, med, 1e3 * med / sc.nbodies,
           first, first_clamp, ru.ru_maxrss, (double)ru.ru_maxrss / sc.nbodies, cpu_step);
    fflush(stdout);
    free(ms);
    carom_world_destroy(w);
    carom_thread_pool_destroy(pool);
    scene_free(&sc);
    return 0;
}

/* The switches' scene: a 32 x 32 grid of separated unit boxes each resting
 * on the ground (2 m apart, sleeping off), the motion the same with every
 * switch; `planar`: the same grid locked to the x-z plane. One switch off
 * per world (`none`: all on), settled 60 steps. */
static const char *const switch_names[] = {"none", "friction", "restitution", "rotation", "ccd", "none"};
#define SWITCHES 6 /* the last: all on again (run_switch_table's noise floor) */

static carom_world *switch_world(const char *which, int planar)
{
    carom_world_def wd = carom_world_def_default();
    wd.enable_sleep = 0;
    int lock_rotation = 0;
    if (!strcmp(which, "friction")) wd.enable_friction = 0;
    else if (!strcmp(which, "restitution")) wd.enable_restitution = 0;
    else if (!strcmp(which, "ccd")) wd.enable_continuous = 0;
    else if (!strcmp(which, "rotation")) lock_rotation = 1;
    else if (strcmp(which, "none")) return NULL;
    carom_world *w = carom_world_create(&wd);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    for (int k = 0; k < 1024; k++) {
        carom_body_def d = carom_body_def_default();
        d.position.x = 2.0 * (k % 32);
        d.position.y = 2.0 * (k / 32);
        d.position.z = 0.5;
        d.shape = carom_shape_box(0.5, 0.5, 0.5);
        d.mass = 1;
        d.lock_rotation = lock_rotation;
        d.lock_to_plane = planar;
        carom_body_create(w, &d);
    }
    for (int s = 0; s < 60; s++) carom_world_step(w, 1.0 / 60);
    return w;
}

/* One switch, timed alone (a profiling driver): `timed` steps after the
 * settle. Prints switch,planar,ms_step,cpu_ms_step. */
static int run_switches(const char *which, int planar, int timed)
{
    carom_world *w = switch_world(which, planar);
    if (!w) return 2;
    double *ms = malloc(sizeof *ms * (size_t)timed);
    double cpu0 = cpu_ms();
    for (int s = 0; s < timed; s++) {
        double t0 = bench_now_ms();
        carom_world_step(w, 1.0 / 60);
        ms[s] = bench_now_ms() - t0;
    }
    double cpu_step = (cpu_ms() - cpu0) / timed;
    qsort(ms, (size_t)timed, sizeof *ms, cmp);
    printf("%s,%d,%.4f,%.4f\n", which, planar, ms[timed / 2], cpu_step);
    free(ms);
    carom_world_destroy(w);
    return 0;
}

/* The switches' table: the five worlds (all on and each switch off) and a
 * second all-on world side by side in one process, timed in `rounds` interleaved rounds: in each, every
 * world steps once untimed (its data back in the caches after the others
 * ran) and then `steps` timed steps, the worlds in an order rotated by one
 * each round, so that a slow spell of the machine (other processes, clock
 * changes) falls on every switch alike instead of on whichever one ran
 * then. Printed: the medians over the rounds of the wall and the CPU time
 * per step (this thread's: what the step itself costs), and the median of
 * each round's CPU time over all on's in the same round (a paired ratio: a
 * slow spell that spans a round cancels) with its 95 % interval (the
 * order statistics n/2 -+ 0.98 sqrt(n) of the n rounds' ratios: a switch
 * reads slower only when the whole interval lies above 1; a switch whose
 * removed work is below the machine's noise reads "the same"). The second
 * all-on world ("again") does the same work as the first: its ratio and
 * interval are the noise floor of the run, measured rather than assumed
 * (on the loaded 2-core machine the order-statistics interval alone was too
 * narrow: runs' medians moved by +-1.5 %). A single timing of each switch
 * after the other read restitution off and ccd off 0.7 and 1 % slower than
 * all on (make bench, main 762a48d), work they remove being 0.14 and 1.6 %
 * of the step. Prints switch,planar,ms_step,cpu_ms_step,cpu_vs_on,
 * cpu_vs_on_lo,cpu_vs_on_hi, one line a switch. */
static int run_switch_table(int planar, int rounds, int steps)
{
    carom_world *w[SWITCHES];
    size_t n = (size_t)rounds * SWITCHES;
    double *ms = malloc(sizeof *ms * n), *cpu = malloc(sizeof *cpu * n), *ratio = malloc(sizeof *ratio * n);
    if (!ms || !cpu || !ratio) return 2;
    for (int k = 0; k < SWITCHES; k++) w[k] = switch_world(switch_names[k], planar);
    for (int r = 0; r < rounds; r++)
        for (int i = 0; i < SWITCHES; i++) {
            int k = (i + r) % SWITCHES;
            carom_world_step(w[k], 1.0 / 60);
            double t0 = bench_now_ms(), c0 = thread_cpu_ms();
            for (int s = 0; s < steps; s++) carom_world_step(w[k], 1.0 / 60);
            cpu[k * rounds + r] = (thread_cpu_ms() - c0) / steps;
            ms[k * rounds + r] = (bench_now_ms() - t0) / steps;
        }
    for (int k = 0; k < SWITCHES; k++)
        for (int r = 0; r < rounds; r++) ratio[k * rounds + r] = cpu[k * rounds + r] / cpu[r];
    for (int k = 0; k < SWITCHES; k++) {
        qsort(ms + k * rounds, (size_t)rounds, sizeof *ms, cmp);
        qsort(cpu + k * rounds, (size_t)rounds, sizeof *cpu, cmp);
        qsort(ratio + k * rounds, (size_t)rounds, sizeof *ratio, cmp);
        int m = k * rounds + rounds / 2, half = (int)ceil(0.98 * sqrt((double)rounds));
        int lo = rounds / 2 - half < 0 ? 0 : rounds / 2 - half, hi = rounds / 2 + half >= rounds ? rounds - 1 : rounds / 2 + half;
        printf("%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f\n", k == SWITCHES - 1 ? "again" : switch_names[k], planar, ms[m], cpu[m], ratio[m],
               ratio[k * rounds + lo], ratio[k * rounds + hi]);
        carom_world_destroy(w[k]);
    }
    free(ms);
    free(cpu);
    free(ratio);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "switch-table") == 0) {
        int rounds = argc > 3 ? atoi(argv[3]) : 101, steps = argc > 4 ? atoi(argv[4]) : 4;
        if (rounds < 1 || steps < 1) return 2;
        return run_switch_table(atoi(argv[2]) != 0, rounds, steps);
    }
    if (argc > 2 && strcmp(argv[1], "switches") == 0)
        return run_switches(argv[2], argc > 3 && atoi(argv[3]), argc > 4 ? atoi(argv[4]) : 120);
    if (argc > 2 && strcmp(argv[1], "first") == 0) { /* profiling: build the grid, one step */
        SceneDesc sc;
        char name[32];
        double ms = 0.0;
        snprintf(name, sizeof name, "pyramids%d", atoi(argv[2]));
        if (!scene_make_by_name(&sc, name)) return 2;
        carom_world_destroy(pyramid_world(&sc, NULL, "default", argc > 3, &ms));
        printf("first step %.3f ms\n", ms);
        scene_free(&sc);
        return 0;
    }
    if (argc > 1 && strcmp(argv[1], "pyramids") == 0) {
        if (argc > 2 && strcmp(argv[2], "header") == 0) {
            printf("engine,preset,workers,bodies,ms_step,us_body_step,first_step_ms,first_step_clamp_ms,peak_kb,"
                   "kb_per_body,cpu_ms_step\n");
            return 0;
        }
        int n = argc > 2 ? atoi(argv[2]) : 990, workers = argc > 3 ? atoi(argv[3]) : 1;
        int timed = argc > 5 ? atoi(argv[5]) : 150;
        if (n < 1 || workers < 1 || workers > CAROM_MAX_WORKERS || timed < 1) return 2;
        return run_pyramids(n, workers, argc > 4 ? argv[4] : "default", timed);
    }
    static const int sizes[] = {100, 300, 1000, 3000, 10000, 30000, 50000};
    int count = argc > 1 ? atoi(argv[1]) : 7;
    printf("bodies,ms_step,contacts\n");
    for (int i = 0; i < count && i < 7; i++) run(sizes[i], 60, sizes[i] >= 30000 ? 5 : 15);
    return 0;
}
