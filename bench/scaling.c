/* scaling.c - time per step against body count.
 *
 *   scaling [COUNT]
 *     a pile (spheres and cubes dropped on a floor inside walls, 1 m bodies
 *     at the peers' pile density), 100 to 50,000 bodies (the first COUNT
 *     sizes). CSV: bodies,ms_step,contacts.
 *   scaling switches SWITCH [PLANAR [TIMED]]
 *     resting boxes with one switch off (see run_switches).
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
 * per run (`none`: all on). Settles 60 steps, then times `timed`. Prints
 * switch,planar,ms_step,cpu_ms_step. */
static int run_switches(const char *which, int planar, int timed)
{
    carom_world_def wd = carom_world_def_default();
    wd.enable_sleep = 0;
    int lock_rotation = 0;
    if (!strcmp(which, "friction")) wd.enable_friction = 0;
    else if (!strcmp(which, "restitution")) wd.enable_restitution = 0;
    else if (!strcmp(which, "ccd")) wd.enable_continuous = 0;
    else if (!strcmp(which, "rotation")) lock_rotation = 1;
    else if (strcmp(which, "none")) return 2;
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

int main(int argc, char **argv)
{
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
