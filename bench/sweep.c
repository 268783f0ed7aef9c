/* sweep.c - the speed/accuracy trade, measured. For each scene and each point
 * of a sweep over the solver knobs, runs the scene, takes the median ms/step
 * over several runs and the scene's error metric, and writes one CSV row:
 *   scene,knob,value,substeps,iterations,relax,correction,warm,model,ccd,friction,
 *   ms_step,error,error_name,extra,momentum_drift (empty where external forces act),
 *   hertz,reuse_mm
 * The error columns are deterministic (one run gives them); the median of N
 * runs is taken only for the scenes named by --timed (all when it is absent),
 * the others are timed once. The two heavy scenes are always timed once.
 * Usage: sweep [--quick] [--runs N] [--timed a,b,...] [--scenes a,b,...] > out.csv */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include "carom/carom.h"
#include "peers/scenes.h"
#include "scenes_extra.h"

typedef struct knobs {
    const char *knob, *value;   /* what this point varies */
    carom_world_def def;
} knobs;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static const char *correction_name(carom_position_correction c)
{
    return c == CAROM_CORRECTION_SOFT ? "soft" : c == CAROM_CORRECTION_BAUMGARTE ? "baumgarte" : "none";
}

static void emit(const char *scene, const knobs *k, double ms, const scene_result *r)
{
    const carom_world_def *d = &k->def;
    char drift[32] = "";
    if (r->momentum_drift >= 0) snprintf(drift, sizeof drift, "%.3g", r->momentum_drift);
    printf("%s,%s,%s,%d,%d,%d,%s,%d,%s,%d,%d,%.6f,%.6g,%s,%.6g,%s,%g,%g\n", scene, k->knob, k->value, d->substeps,
           d->iterations, d->relax_iterations, correction_name(d->position_correction), d->warm_starting,
           d->contact_model == CAROM_CONTACT_IMPULSE ? "impulse" : "penalty", d->enable_continuous,
           d->enable_friction, ms, r->error, r->error_name, r->extra, drift, d->contact_hertz,
           1000 * d->contact_reuse_distance);
    fflush(stdout);
}

static void run_point(const char *scene, const knobs *k, int runs)
{
    double ms[16];
    scene_result r = {0};
    if (runs > 16) runs = 16;
    for (int i = 0; i < runs; i++) {
        if (!extra_scene_run(scene, &k->def, &ms[i], &r)) {
            fprintf(stderr, "sweep: scene %s failed\n", scene);
            exit(1);
        }
    }
    qsort(ms, (size_t)runs, sizeof *ms, cmp_double);
    emit(scene, k, ms[runs / 2], &r);
}

/* name is one of the comma-separated names in list (whole names only:
 * "pyramid" is not in "large_pyramid") */
static int listed(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ',') && (p[n] == '\0' || p[n] == ',')) return 1;
    return 0;
}

int main(int argc, char **argv)
{
    int quick = 0, runs = 3;
    const char *only = NULL, *timed = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc) runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--scenes") && i + 1 < argc) only = argv[++i];
        else if (!strcmp(argv[i], "--timed") && i + 1 < argc) timed = argv[++i];
        else { fprintf(stderr, "usage: sweep [--quick] [--runs N] [--timed a,b] [--scenes a,b]\n"); return 2; }
    }
    if (runs < 1) runs = 1;
    printf("scene,knob,value,substeps,iterations,relax,correction,warm,model,ccd,friction,ms_step,error,error_name,extra,momentum_drift,hertz,reuse_mm\n");
    static const int substeps[] = {1, 2, 4, 8};
    static const int iterations[] = {1, 2, 4, 8, 16};
    for (int s = 0; s < extra_scene_count(); s++) {
        const char *scene = extra_scene_name(s);
        if (only && !listed(only, scene)) continue;
        int heavy = extra_scene_is_heavy(scene);
        int scene_runs = heavy || (timed && !listed(timed, scene)) ? 1 : runs;
        carom_world_def base = carom_world_def_default();
        base.enable_sleep = 0;
        if (!strcmp(scene, "large_pyramid")) {
            /* 5050 boxes: the three presets only, to keep make bench under 10 minutes */
            static const char *const presets[] = {"fast", "default", "accurate"};
            for (int p = 0; p < 3; p++) {
                knobs k = {"preset", presets[p], base};
                carom_world_def_apply_preset(&k.def, presets[p]);
                run_point(scene, &k, 1);
            }
            continue;
        }
        /* the substep x iteration grid (heavy scenes: the diagonal and axes only) */
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < 5; b++) {
                if ((heavy || quick) && !(a == 2 || b == 0)) continue;
                knobs k = {"grid", "", base};
                k.def.substeps = substeps[a];
                k.def.iterations = iterations[b];
                char v[32];
                snprintf(v, sizeof v, "s%d_i%d", substeps[a], iterations[b]);
                k.value = v;
                run_point(scene, &k, scene_runs);
            }
        /* one knob at a time around the default */
        knobs one[16];
        int n = 0;
        for (int i = 0; i < (int)(sizeof one / sizeof one[0]); i++) one[i].def = base;
        one[n].knob = "relax"; one[n].value = "off"; one[n++].def.relax_iterations = 0;
        one[n].knob = "correction"; one[n].value = "baumgarte"; one[n++].def.position_correction = CAROM_CORRECTION_BAUMGARTE;
        one[n].knob = "correction"; one[n].value = "none"; one[n++].def.position_correction = CAROM_CORRECTION_NONE;
        one[n].knob = "warm_start"; one[n].value = "off"; one[n++].def.warm_starting = 0;
        one[n].knob = "model"; one[n].value = "penalty_implicit"; one[n++].def.contact_model = CAROM_CONTACT_PENALTY;
        one[n].knob = "model"; one[n].value = "penalty_explicit"; one[n].def.contact_model = CAROM_CONTACT_PENALTY;
        one[n++].def.penalty_implicit = 0;
        one[n].knob = "ccd"; one[n].value = "off"; one[n++].def.enable_continuous = 0;
        one[n].knob = "shock"; one[n].value = "off"; one[n++].def.shock_propagation = 0;
        one[n].knob = "friction"; one[n].value = "off"; one[n++].def.enable_friction = 0;
        one[n].knob = "preset"; one[n].value = "fast"; carom_world_def_apply_preset(&one[n++].def, "fast");
        one[n].knob = "preset"; one[n].value = "accurate"; carom_world_def_apply_preset(&one[n++].def, "accurate");
        one[n].knob = "sleep"; one[n].value = "on"; one[n++].def.enable_sleep = 1;
        one[n].knob = "reuse"; one[n].value = "0"; one[n++].def.contact_reuse_distance = 0.0;
        one[n].knob = "reuse"; one[n].value = "1mm"; one[n++].def.contact_reuse_distance = 1e-3;
        for (int i = 0; i < n; i++) run_point(scene, &one[i], scene_runs);
    }
    return 0;
}
