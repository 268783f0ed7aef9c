/* snapshot.c - snapshot size and speed on a settled pile of 10,000 bodies of
 * mixed shapes (contact cache included): bytes per body, and the median
 * time of carom_world_snapshot and carom_world_restore over 9 runs each.
 * The pile is two layers, the upper one offset by half a cell so its bodies
 * fall into the gaps of the lower (taller drops of mixed shapes keep
 * avalanching for minutes), in heaps of 25 x 25 x 2 = 1,250 bodies 2.5 m
 * apart: one heap sleeps by step ~440, but one 71 x 71 x 2 pile of 10,000
 * is one island and did NOT settle (9,895 awake after 2,400 steps, 774
 * B/body), so 10,000 bodies are eight heaps, each its own island (all
 * asleep at step 440: 629 B/body). Round bodies need rolling resistance
 * to stop rolling (0.2: a ball slows at 0.2 g), and a sphere resting on
 * others keeps a slow spin about the vertical that friction cannot take
 * away, so islands sleep below 0.2 rad/s (surface speed 4 cm/s at r 0.2 m)
 * instead of the default 0.05.
 * Targets (issue 17): <= 256 bytes per body, < 5 ms each. It also prints
 * where the bytes go, per field (lib/snapshot.h, snapshot_field_bytes). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "carom/carom.h"
#include "snapshot.h" /* internal: bytes per field */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The settled pile (see the top of the file). */
static carom_world *settled_pile(int n)
{
    carom_world_def wd = carom_world_def_default();
    wd.sleep_angular_velocity = 0.2;
    carom_world *w = carom_world_create(&wd);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    static const double tetra[] = {0, 0, 0, 0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3, 0.2, 0.2, 0.2};
    const carom_shape_def shapes[] = {carom_shape_box(0.2, 0.2, 0.2), carom_shape_sphere(0.2),
                                      carom_shape_capsule(0.1, 0.15), carom_shape_cylinder(0.15, 0.12),
                                      carom_shape_hull(tetra, 5)};
    carom_material mat = carom_material_default();
    mat.rolling_resistance = 0.2;
    /* heaps of at most 25 x 25 x 2 = 1,250 bodies, 14 m apart (2.5 m
     * between them): each its own island, so each sleeps on its own */
    int side = 1; /* two layers of side x side */
    while (2 * side * side < n && side < 25) side++;
    int per_heap = 2 * side * side;
    for (int i = 0; i < n; i++) {
        carom_body_def b = carom_body_def_default();
        b.shape = shapes[i % 5];
        b.material = &mat;
        int heap = i / per_heap, j = i % per_heap;
        int layer = j / (side * side), offset = layer % 2;
        b.position.x = 14.0 * (heap % 3) + 0.45 * (j % side) + 0.02 * (j / side % 3) + 0.225 * offset;
        b.position.y = 14.0 * (heap / 3) + 0.45 * (j / side % side) + 0.225 * offset;
        b.position.z = 0.25 + 0.45 * layer;
        carom_body_create(w, &b);
    }
    double t0 = now_ms();
    int steps = 0;
    carom_world_stats st = carom_world_stats_init();
    do {
        carom_world_step(w, 1.0 / 60);
        carom_world_get_stats(w, &st);
        steps++;
    } while (st.awake_bodies > n / 100 && steps < 2400);
    printf("pile of %d bodies: %d steps to settle (%.1f s), %d awake, %d broadphase pairs, %d touching manifolds\n", n,
           steps, (now_ms() - t0) / 1e3, st.awake_bodies, st.pairs, st.contacts);
    return w;
}

/* snapshot [N] [-o FILE]: the pile of N bodies (10,000), its snapshot saved
 * to FILE when asked; snapshot -i FILE: a saved snapshot's world instead
 * (no settling: for callgrind, e.g. --toggle-collect=carom_world_restore). */
int main(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    int n = 10000;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-i") && i + 1 < argc) in = argv[++i];
        else if (!strcmp(argv[i], "-o") && i + 1 < argc) out = argv[++i];
        else n = atoi(argv[i]);
    }
    carom_world *w;
    if (in) {
        FILE *f = fopen(in, "rb");
        if (!f) { perror(in); return 1; }
        fseek(f, 0, SEEK_END);
        long len = ftell(f);
        fseek(f, 0, SEEK_SET);
        unsigned char *data = malloc(len > 0 ? (size_t)len : 1);
        if (!data || len <= 0 || fread(data, 1, (size_t)len, f) != (size_t)len) { fprintf(stderr, "%s: cannot read\n", in); return 1; }
        fclose(f);
        char msg[256];
        w = carom_world_restore(data, (size_t)len, msg, sizeof msg);
        free(data);
        if (!w) { fprintf(stderr, "%s: %s\n", in, msg); return 1; }
        n = carom_world_body_count(w) - 1;
    } else {
        w = settled_pile(n);
    }
    size_t size = carom_world_snapshot(w, NULL, 0);
    {
        size_t bytes[SNAP_FIELD_COUNT];
        const char *names[SNAP_FIELD_COUNT];
        snapshot_field_bytes(w, bytes, names);
        printf("bytes per body by field:");
        for (int f = 0, k = 0; f < SNAP_FIELD_COUNT; f++)
            if (bytes[f]) printf("%s %s %.1f", k++ % 6 ? "," : "\n ", names[f], (double)bytes[f] / (n + 1));
        printf("\n");
    }
    unsigned char *buf = malloc(size);
    if (out) {
        FILE *f = fopen(out, "wb");
        carom_world_snapshot(w, buf, size);
        if (!f || fwrite(buf, 1, size, f) != size || fclose(f) != 0) { perror(out); return 1; }
    }
    double ts[9], tr[9];
    for (int k = 0; k < 9; k++) {
        double a = now_ms();
        carom_world_snapshot(w, buf, size);
        ts[k] = now_ms() - a;
        char msg[256];
        a = now_ms();
        carom_world *r = carom_world_restore(buf, size, msg, sizeof msg);
        tr[k] = now_ms() - a;
        if (!r) { fprintf(stderr, "restore: %s\n", msg); return 1; }
        carom_world_destroy(r);
    }
    /* into an existing world, as rollback networking restores every frame
     * (carom_world_restore_into: the new state is read into a world of its
     * own, then the target takes it over and its old state is freed) */
    double ti[9];
    {
        char msg[256];
        carom_world *r = carom_world_restore(buf, size, msg, sizeof msg);
        if (!r) { fprintf(stderr, "restore: %s\n", msg); return 1; }
        for (int k = 0; k < 9; k++) {
            double a = now_ms();
            carom_status st = carom_world_restore_into(r, buf, size);
            ti[k] = now_ms() - a;
            if (st != CAROM_OK) { fprintf(stderr, "restore_into: %s\n", carom_world_last_error(r)); return 1; }
        }
        carom_world_destroy(r);
    }
    qsort(ts, 9, sizeof ts[0], cmp);
    qsort(tr, 9, sizeof tr[0], cmp);
    qsort(ti, 9, sizeof ti[0], cmp);
    printf("snapshot: %zu bytes, %.0f bytes per body (target <= 256)\n", size, (double)size / (n + 1));
    printf("snapshot %.2f ms, restore %.2f ms (medians of 9; target < 5 ms each)\n", ts[4], tr[4]);
    printf("restore into a world %.2f ms (carom_world_restore_into, median of 9)\n", ti[4]);
    free(buf);
    carom_world_destroy(w);
    return 0;
}
