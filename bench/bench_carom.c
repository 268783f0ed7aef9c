/* bench_carom.c - carom on the peers' canonical scenes (bench/peers/scenes.h:
 * same geometry, same metrics, same result line as ODE's and Bullet's
 * harnesses), so bench/peers/run.sh compares the three engines in one run.
 *
 * Usage: bench_carom [scene ...]   (default: pyramid pile stack mass_ratio bullet)
 * Environment: CAROM_PRESET (fast|default|accurate), CAROM_SUBSTEPS,
 * CAROM_ITERATIONS, CAROM_SLEEP=1 (sleeping on; off by default, like the
 * peers' harnesses). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom/carom.h"
#include "peers/scenes.h"

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
    carom_world *w = carom_world_create(&wd);
    if (!w) { fprintf(stderr, "bad world settings\n"); exit(2); }
    sc->ccd_supported = 1;
    if (sc->ground) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(0, 0, 1, 0);
        g.friction = sc->mu;
        carom_body_create(w, &g);
    }
    for (int i = 0; i < sc->nstatic; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.position.x = sc->statics[i].pos[0];
        g.position.y = sc->statics[i].pos[1];
        g.position.z = sc->statics[i].pos[2];
        g.shape = carom_shape_box(sc->statics[i].half[0], sc->statics[i].half[1], sc->statics[i].half[2]);
        g.friction = sc->mu;
        carom_body_create(w, &g);
    }
    carom_body_id *ids = malloc(sizeof *ids * (size_t)sc->nbodies);
    BodyFinal *fin = calloc((size_t)sc->nbodies, sizeof *fin);
    for (int i = 0; i < sc->nbodies; i++) {
        const BodyDesc *b = &sc->bodies[i];
        carom_body_def d = carom_body_def_default();
        d.position.x = b->pos[0]; d.position.y = b->pos[1]; d.position.z = b->pos[2];
        d.linear_velocity.x = b->vel[0]; d.linear_velocity.y = b->vel[1]; d.linear_velocity.z = b->vel[2];
        d.shape = b->shape == SHAPE_BOX ? carom_shape_box(b->he, b->he, b->he) : carom_shape_sphere(b->he);
        d.mass = b->mass;
        d.friction = sc->mu;
        d.bullet = sc->id == SC_BULLET && sc->ccd;
        ids[i] = carom_body_create(w, &d);
    }
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
    scene_report("carom", sc, fin, t1 - t0, pen, sc->steps);
    free(ids);
    free(fin);
    carom_world_destroy(w);
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
