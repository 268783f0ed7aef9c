/* terrain.c - 1,000 mixed bodies (spheres, boxes, capsules, cylinders,
 * hulls, compounds) dropped onto hilly level geometry: a 100,352-triangle
 * mesh (225 x 225 vertices) and a 316 x 316 height field (198,450 triangles
 * made on demand), at each preset. Prints ms/step (median over the run),
 * and the tunnelling check: bodies whose centre ended below the surface (a
 * ray cast down from above finds the surface), and the deepest overlap at
 * the end against the speculative distance (of any contact, and of the
 * bodies with the ground: the line, "no body below the surface by
 * more than the speculative distance").
 * Also the deepest overlap of any body with the ground while the layers
 * land (every step, from the bodies' contacts with the ground).
 * Usage: terrain [steps [preset [mesh|field]]] (default 600 steps: 10 s at
 * 60 Hz, every preset, both grounds). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "carom/carom.h"
#include "world.h"    /* the ground overlap at the end: the narrowphase on the final poses */
#include "compound.h"

#define BODIES 1000

/* TERRAIN_FLAT=1 (a bench switch, not a library one): flat ground, and
 * ground "plane" runs the same drop on a plane for comparison */
static int flat_ground(void) { const char *f = getenv("TERRAIN_FLAT"); return f && *f == '1'; }

static double hill(double x, double y)
{
    if (flat_ground()) return 0;
    return 1.2 * sin(0.21 * x) * cos(0.17 * y) + 0.4 * sin(0.05 * x + 0.3);
}

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

/* this process's CPU time: on a shared machine it moves less than the wall clock */
static double cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static carom_body_id add_mesh_terrain(carom_world *w)
{
    const int n = 224; /* cells per side: 2 * 224^2 = 100,352 triangles */
    const double cell = 0.25;
    int nv = (n + 1) * (n + 1), nt = 2 * n * n;
    double *v = malloc(sizeof *v * 3 * (size_t)nv);
    int *t = malloc(sizeof *t * 3 * (size_t)nt);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double x = (i - 0.5 * n) * cell, y = (j - 0.5 * n) * cell;
            double *p = v + 3 * (j * (n + 1) + i);
            p[0] = x; p[1] = y; p[2] = hill(x, y);
        }
    int k = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            int q[6] = {a, b, c, a, c, d};
            for (int m = 0; m < 6; m++) t[k + m] = q[m];
            k += 6;
        }
    carom_mesh_def md = carom_mesh_def_default();
    md.vertices = v; md.vertex_count = nv; md.triangles = t; md.triangle_count = nt;
    carom_body_def bd = carom_body_def_default();
    bd.type = CAROM_BODY_STATIC;
    bd.shape.type = CAROM_SHAPE_MESH;
    bd.mesh = &md;
    carom_body_id id = carom_body_create(w, &bd);
    free(v); free(t);
    return id;
}

static carom_body_id add_field_terrain(carom_world *w)
{
    const int n = 316;
    const double cell = 56.0 / (n - 1); /* the same 56 m square as the mesh */
    double *h = malloc(sizeof *h * (size_t)n * n);
    for (int r = 0; r < n; r++)
        for (int c = 0; c < n; c++) h[r * n + c] = hill((c - 0.5 * (n - 1)) * cell, (r - 0.5 * (n - 1)) * cell);
    carom_heightfield_def hd = carom_heightfield_def_default();
    hd.heights = h; hd.rows = n; hd.columns = n; hd.cell_x = cell; hd.cell_y = cell;
    carom_body_def bd = carom_body_def_default();
    bd.type = CAROM_BODY_STATIC;
    bd.shape.type = CAROM_SHAPE_HEIGHTFIELD;
    bd.heightfield = &hd;
    carom_body_id id = carom_body_create(w, &bd);
    free(h);
    return id;
}

static carom_body_id add_plane(carom_world *w)
{
    carom_body_def bd = carom_body_def_default();
    bd.type = CAROM_BODY_STATIC;
    bd.shape = carom_shape_plane(0, 0, 1, 0);
    return carom_body_create(w, &bd);
}

static void add_bodies(carom_world *w, carom_body_id *ids)
{
    static const double hull_pts[24] = {0.25, 0, 0, -0.2, 0.1, 0, 0, 0.25, 0.05, 0, -0.22, 0.02,
                                        0.05, 0.05, 0.2, -0.05, 0, -0.2, 0.12, -0.1, 0.1, -0.1, -0.12, -0.1};
    carom_compound_child dumbbell[2];
    dumbbell[0] = carom_compound_child_default(carom_shape_sphere(0.15));
    dumbbell[1] = carom_compound_child_default(carom_shape_box(0.12, 0.12, 0.12));
    dumbbell[0].position.x = -0.2;
    dumbbell[1].position.x = 0.2;
    unsigned s = 99;
    for (int k = 0; k < BODIES; k++) {
        int layer = k / 100, i = k % 10, j = (k / 10) % 10;
        carom_body_def d = carom_body_def_default();
        double x = -9 + 2.0 * i, y = -9 + 2.0 * j;
        s = s * 1103515245u + 12345u;
        d.position.x = x + 0.3 * ((s >> 16 & 1023) / 1023.0 - 0.5);
        d.position.y = y;
        d.position.z = hill(x, y) + 1.5 + 0.9 * layer;
        d.friction = 0.6;
        switch (k % 6) {
        case 0: d.shape = carom_shape_sphere(0.25); break;
        case 1: d.shape = carom_shape_box(0.25, 0.2, 0.15); break;
        case 2: d.shape = carom_shape_capsule(0.15, 0.2); break;
        case 3: d.shape = carom_shape_cylinder(0.2, 0.15); break;
        case 4: d.shape = carom_shape_hull(hull_pts, 8); break;
        default:
            d.shape.type = CAROM_SHAPE_COMPOUND;
            d.children = dumbbell;
            d.child_count = 2;
            break;
        }
        ids[k] = carom_body_create(w, &d);
    }
}

/* Deepest overlap of any body with the ground at the current poses (the
 * narrowphase afresh, as carom_world_measure_max_penetration does for every
 * contact). */
static double ground_overlap(const carom_world *w, carom_body_id ground, const carom_body_id *ids)
{
    const body_store *s = &w->bodies;
    int g = s->ids[ground.index1 - 1].slot;
    double deepest = 0;
    for (int k = 0; k < BODIES; k++) {
        int b = s->ids[ids[k].index1 - 1].slot;
        collide_cache cache;
        memset(&cache, 0, sizeof cache);
        cache.feature = -1;
        manifold m;
        collide(&s->shapes[g], body_xform(s, g), &s->shapes[b], body_xform(s, b), 0.0, &cache, &m);
        for (int i = 0; i < m.count; i++)
            if (-m.points[i].separation > deepest) deepest = -m.points[i].separation;
    }
    return deepest;
}

static void run(const char *preset, int field, int steps)
{
    carom_world_def wd = carom_world_def_default();
    carom_world_def_apply_preset(&wd, preset);
    carom_world *w = carom_world_create(&wd);
    double t0 = now_ms();
    carom_body_id ground = field == 2 ? add_plane(w) : field ? add_field_terrain(w) : add_mesh_terrain(w);
    double build_ms = now_ms() - t0;
    if (carom_body_id_is_null(ground)) { printf("terrain: %s\n", carom_world_last_error(w)); exit(1); }
    static carom_body_id ids[BODIES];
    add_bodies(w, ids);
    double *ms = malloc(sizeof *ms * (size_t)steps);
    double cpu_ms_total = 0, landing = 0;
    int landing_step = -1;
    for (int i = 0; i < steps; i++) {
        double a = now_ms(), c0 = cpu_ms();
        carom_world_step(w, 1.0 / 60.0);
        ms[i] = now_ms() - a;
        cpu_ms_total += cpu_ms() - c0;
        /* outside the timing: the deepest contact with the ground */
        for (int k = 0; k < BODIES; k++) {
            carom_contact_info info[8];
            int n = carom_body_get_contacts(w, ids[k], info, 8);
            for (int q = 0; q < n && q < 8; q++)
                if (carom_body_id_equal(info[q].other, ground) && -info[q].separation > landing) {
                    landing = -info[q].separation;
                    landing_step = i;
                }
        }
    }
    double cpu_per_step = cpu_ms_total / steps;
    qsort(ms, (size_t)steps, sizeof *ms, cmp);
    /* tunnelling: a centre below the surface, found by a ray cast down */
    int below = 0, missing = 0;
    double worst = 0;
    for (int k = 0; k < BODIES; k++) {
        carom_vec3 p;
        carom_body_get_center_of_mass(w, ids[k], &p);
        carom_vec3 from = {p.x, p.y, 50}, down = {0, 0, -100};
        carom_ray_hit hit;
        int c = -1;
        /* the terrain is the lowest thing under the body: take the last hit going down */
        carom_vec3 o = from;
        double surface = -1e9;
        for (int guard = 0; guard < 2000; guard++) {
            if (carom_world_ray_cast_child(w, o, down, &hit, &c) != 1) break;
            if (carom_body_id_equal(hit.body, ground)) { surface = hit.point.z; break; }
            o.z = hit.point.z - 1e-6; /* past this body */
            down.z = -(o.z + 50);
        }
        if (surface == -1e9) { missing++; continue; }
        if (p.z < surface) { below++; if (surface - p.z > worst) worst = surface - p.z; }
    }
    carom_world_stats st = carom_world_stats_init();
    carom_world_get_stats(w, &st);
    double pen = carom_world_measure_max_penetration(w), ground_pen = ground_overlap(w, ground, ids);
    printf("%-8s %-11s build %7.1f ms  ms/step median %6.2f  p90 %6.2f  max %6.2f  awake %4d  "
           "centres below the surface %d (deepest %.3f m)%s  deepest overlap %.4f m, with the ground %.4f m (speculative %.3f)  "
           "cpu ms/step mean %.2f  deepest ground overlap while landing %.4f m (step %d)\n",
           preset, field == 2 ? "plane" : field ? "heightfield" : "mesh", build_ms, ms[steps / 2], ms[steps * 9 / 10], ms[steps - 1],
           st.awake_bodies, below, worst, missing ? " (some off the terrain)" : "", pen, ground_pen, wd.speculative_distance,
           cpu_per_step, landing, landing_step);
    fflush(stdout);
    free(ms);
    carom_world_destroy(w);
}

int main(int argc, char **argv)
{
    int steps = argc > 1 ? atoi(argv[1]) : 600;
    if (steps < 10) steps = 10;
    printf("terrain: %d mixed bodies dropped on a 100,352-triangle mesh and a 316 x 316 height field, %d steps at 60 Hz\n",
           BODIES, steps);
    const char *presets[3] = {"fast", "default", "accurate"};
    for (int p = 0; p < 3; p++)
        for (int f = 0; f < 3; f++) {
            if (argc > 2 && strcmp(argv[2], presets[p]) != 0) continue;
            if (f == 2 ? !(argc > 3 && strcmp(argv[3], "plane") == 0) : argc > 3 && strcmp(argv[3], f ? "field" : "mesh") != 0) continue;
            run(presets[p], f, steps);
        }
    return 0;
}
