/* scaling.c - time per step against body count in a pile (spheres and cubes
 * dropped on a floor inside walls, 1 m bodies at the peers' pile density),
 * 100 to 50,000 bodies. Prints CSV: bodies,ms_step,contacts. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "carom/carom.h"
#include "peers/scenes.h"

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

int main(int argc, char **argv)
{
    static const int sizes[] = {100, 300, 1000, 3000, 10000, 30000, 50000};
    int count = argc > 1 ? atoi(argv[1]) : 7;
    printf("bodies,ms_step,contacts\n");
    for (int i = 0; i < count && i < 7; i++) run(sizes[i], 60, sizes[i] >= 30000 ? 5 : 15);
    return 0;
}
