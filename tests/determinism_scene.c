/* determinism_scene.c - one scene, run to its end; writes the world's final
 * snapshot (its complete state) to the file named by argv[1]. tests/
 * determinism.sh builds it with gcc and clang at -O1 and -O2 and runs each
 * build on the AVX2 and the SSE2 path: every snapshot must be the same bytes.
 * It first steps an empty world (issue 17, finding 1: the clang -O1 build
 * runs under UBSan, which reported that step). */
#include <stdio.h>
#include <stdlib.h>
#include "carom/carom.h"

int main(int argc, char **argv)
{
    if (argc < 2) return 2;
    carom_world_def wd = carom_world_def_default();
    carom_world *empty = carom_world_create(&wd);
    for (int i = 0; i < 3; i++)
        if (carom_world_step(empty, 1.0 / 60) != CAROM_OK) return 3;
    carom_world_destroy(empty);

    carom_world *w = carom_world_create(&wd);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    static const double tetra[] = {0, 0, 0, 0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3, 0.2, 0.2, 0.2};
    const carom_shape_def shapes[] = {carom_shape_box(0.2, 0.2, 0.2), carom_shape_sphere(0.2),
                                      carom_shape_capsule(0.1, 0.15), carom_shape_cylinder(0.15, 0.12),
                                      carom_shape_hull(tetra, 5)};
    /* enough touching manifolds (> 64) that the wide passes run */
    for (int i = 0; i < 150; i++) {
        carom_body_def b = carom_body_def_default();
        b.shape = shapes[i % 5];
        b.position.x = -1.8 + 0.45 * (i % 9) + 0.01 * (i % 4);
        b.position.y = -1.0 + 0.45 * (i / 9 % 5);
        b.position.z = 0.25 + 0.45 * (i / 45);
        b.angular_velocity.z = 0.1 * (i % 3);
        b.restitution = 0.1 * (i % 3);
        b.friction = 0.3 + 0.1 * (i % 4);
        if (carom_body_id_is_null(carom_body_create(w, &b))) return 4;
    }
    for (int s = 0; s < 240; s++)
        if (carom_world_step(w, 1.0 / 60) != CAROM_OK) return 5;
    carom_world_stats st = carom_world_stats_init();
    carom_world_get_stats(w, &st);
    size_t n = carom_world_snapshot(w, NULL, 0);
    unsigned char *buf = malloc(n);
    if (!buf || carom_world_snapshot(w, buf, n) != n) return 6;
    FILE *f = fopen(argv[1], "wb");
    if (!f || fwrite(buf, 1, n, f) != n) return 7;
    fclose(f);
    printf("%s: %zu-byte state, %d contacts\n", argv[1], n, st.contacts);
    free(buf);
    carom_world_destroy(w);
    return 0;
}
