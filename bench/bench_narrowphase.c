/* bench_narrowphase.c - cost of collide() per pair type (ns per pair), on
 * random touching or nearly touching configurations (the case that matters:
 * pairs whose fat bounds overlap). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "narrowphase.h"
#include "compound.h"

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static double rnd(unsigned long long *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static quat rquat(unsigned long long *s)
{
    quat q = {rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5};
    return q_normalize(q);
}

int main(void)
{
    static const char *names[] = {"sphere", "box", "capsule", "cylinder", "hull", "plane"};
    shape shapes[SHAPE_PLANE + 1];
    memset(shapes, 0, sizeof shapes);
    shapes[SHAPE_SPHERE].type = SHAPE_SPHERE; shapes[SHAPE_SPHERE].radius = 0.5;
    shapes[SHAPE_BOX].type = SHAPE_BOX; shapes[SHAPE_BOX].half_extents = v3(0.5, 0.5, 0.5);
    shapes[SHAPE_CAPSULE].type = SHAPE_CAPSULE; shapes[SHAPE_CAPSULE].radius = 0.3; shapes[SHAPE_CAPSULE].half_height = 0.4;
    shapes[SHAPE_CYLINDER].type = SHAPE_CYLINDER; shapes[SHAPE_CYLINDER].radius = 0.4; shapes[SHAPE_CYLINDER].half_height = 0.4;
    /* an icosahedron-like hull: 12 points */
    double g = 1.618033988749895, pts[36], base[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                                                           {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (int i = 0; i < 12; i++)
        for (int c = 0; c < 3; c++) pts[3 * i + c] = 0.3 * base[i][c];
    shapes[SHAPE_HULL].type = SHAPE_HULL;
    shapes[SHAPE_HULL].hull = hull_build(pts, 12, NULL, 0);
    shapes[SHAPE_PLANE].type = SHAPE_PLANE; shapes[SHAPE_PLANE].plane_normal = v3(0, 0, 1);
    enum { N = 4096, REPEAT = 8, PRIMITIVE_COUNT = SHAPE_PLANE + 1 }; /* meshes, fields, compounds: not here */
    xform *xa = malloc(sizeof *xa * N), *xb = malloc(sizeof *xb * N);
    for (int a = 0; a < PRIMITIVE_COUNT; a++)
        for (int b = a; b < PRIMITIVE_COUNT; b++) {
            if (a == SHAPE_PLANE && b == SHAPE_PLANE) continue;
            unsigned long long s = 0x1234567ULL + (unsigned long long)(a * 7 + b);
            for (int i = 0; i < N; i++) {
                xa[i].p = v3(0, 0, b == SHAPE_PLANE ? 0.45 : 0.0);
                xa[i].q = rquat(&s);
                /* b placed about one contact distance away, in a random direction */
                vec3 dir = v3_normalize(v3(rnd(&s) - 0.5, rnd(&s) - 0.5, rnd(&s) - 0.5));
                xb[i].p = b == SHAPE_PLANE ? v3_zero() : v3_scale(dir, 0.8 + 0.3 * rnd(&s));
                xb[i].q = b == SHAPE_PLANE ? q_identity() : rquat(&s);
            }
            long points = 0;
            double t0 = now_ns();
            for (int r = 0; r < REPEAT; r++)
                for (int i = 0; i < N; i++) {
                    collide_cache cache;
                    memset(&cache, 0, sizeof cache);
                    cache.feature = -1;
                    manifold m;
                    points += collide(&shapes[a], xa[i], &shapes[b], xb[i], 0.02, &cache, &m);
                }
            double ns = (now_ns() - t0) / (N * REPEAT);
            printf("bench=narrowphase pair=%s-%s ns_per_pair=%.0f points_per_pair=%.2f\n", names[a], names[b], ns,
                   (double)points / (N * REPEAT));
        }
    hull_free(shapes[SHAPE_HULL].hull);
    free(xa);
    free(xb);
    return 0;
}
