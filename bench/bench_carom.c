/* bench_carom.c - carom on the peers' canonical scenes (bench/peers/scenes.h:
 * same geometry, same metrics, same result line as ODE's and Bullet's
 * harnesses), so bench/peers/run.sh compares the three engines in one run.
 *
 * Usage: bench_carom [scene ...]   (default: pyramid pile stack mass_ratio bullet)
 * Environment: CAROM_PRESET (fast|default|accurate), CAROM_SUBSTEPS,
 * CAROM_ITERATIONS, CAROM_SLEEP=1 (sleeping on; off by default, like the
 * peers' harnesses), CAROM_THREADS=N (the reference thread pool, engine
 * carom_tN). Scaling scenes (pyramidsN) run their untimed warm-up steps first. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom/carom.h"
#include "carom/carom_threads.h"
#include "peers/scenes.h"
#include "scenes_extra.h"

static void run_scene(SceneDesc *sc)
{
    carom_world_def wd = carom_world_def_default();
    const char *preset = getenv("CAROM_PRESET");
    if (preset && carom_world_def_apply_preset(&wd, preset) != CAROM_OK) {
        fprintf(stderr, "unknown CAROM_PRESET %s\n", preset);
        exit(2);
    }
    if (getenv("CAROM_SUBSTEPS")) wd.substeps = atoi(getenv("CAROM_SUBSTEPS"));
    if (getenv("CAROM_ITERATIONS")) wd.iterations = atoi(getenv("CAROM_ITERATIONS"));
    wd.enable_sleep = getenv("CAROM_SLEEP") ? atoi(getenv("CAROM_SLEEP")) : 0;
    wd.enable_continuous = sc->ccd || sc->id != SC_BULLET;
    wd.gravity.z = -BENCH_GRAVITY;
    int threads = getenv("CAROM_THREADS") ? atoi(getenv("CAROM_THREADS")) : 1;
    carom_thread_pool *pool = threads > 1 ? carom_thread_pool_create(threads) : NULL;
    if (pool) carom_thread_pool_attach(pool, &wd);
    carom_world *w = carom_world_create(&wd);
    if (!w) { fprintf(stderr, "bad world settings\n"); exit(2); }
    sc->ccd_supported = 1;
    carom_body_id *ids = malloc(sizeof *ids * (size_t)sc->nbodies);
    BodyFinal *fin = calloc((size_t)sc->nbodies, sizeof *fin);
    canonical_build(w, sc, ids);
    for (int s = 0; s < sc->warm; s++) carom_world_step(w, BENCH_DT);
    double t0 = bench_now_ms();
    for (int s = 0; s < sc->steps; s++) carom_world_step(w, BENCH_DT);
    double t1 = bench_now_ms();
    for (int i = 0; i < sc->nbodies; i++) {
        carom_vec3 p;
        carom_body_get_position(w, ids[i], &p);
        fin[i].pos[0] = p.x; fin[i].pos[1] = p.y; fin[i].pos[2] = p.z;
        carom_body_get_kinetic_energy(w, ids[i], &fin[i].ke);
    }
    double pen = sc->id == SC_PILE ? carom_world_measure_max_penetration(w) : -1.0;
    /* a preset shows as its own engine row: carom_fast, carom_accurate */
    char engine[32] = "carom";
    if (preset && strcmp(preset, "default") != 0) snprintf(engine, sizeof engine, "carom_%s", preset);
    if (pool) snprintf(engine + strlen(engine), sizeof engine - strlen(engine), "_t%d", threads);
    scene_report(engine, sc, fin, t1 - t0, pen, sc->steps);
    free(ids);
    free(fin);
    carom_world_destroy(w);
    carom_thread_pool_destroy(pool);
}

int main(int argc, char **argv)
{
    static const char *defaults[] = {"pyramid", "pile", "stack", "mass_ratio", "bullet", "bullet_noccd"};
    int n = argc > 1 ? argc - 1 : (int)(sizeof defaults / sizeof *defaults);
    for (int i = 0; i < n; i++) {
        const char *name = argc > 1 ? argv[i + 1] : defaults[i];
        SceneDesc sc;
        if (!scene_make_by_name(&sc, name)) { fprintf(stderr, "unknown scene %s\n", name); return 2; }
        run_scene(&sc);
        scene_free(&sc);
    }
    return 0;
}
