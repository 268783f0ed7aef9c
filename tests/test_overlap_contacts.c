/* test_overlap_contacts.c - the narrowphase reports every overlap: each pair
 * of convex shapes (random sizes and orientations) is brought together
 * along a random line until GJK (an independent algorithm, lib/gjk.c) finds
 * them touching, then pushed 1 mm .. 128 mm further; at each depth the
 * manifold must hold a point with separation <= 0. Cylinders are 16-sided
 * prisms in the narrowphase, inscribed in the true cylinder GJK sees, so
 * their pairs may start overlapping up to r (1 - cos(pi / 16)) later. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "world.h"
#include "narrowphase.h"
#include "compound.h"
#include "gjk.h"
#include "helpers.h"

static uint64_t rng = 88172645463325252ull;
static double urand(void) { return rnd(&rng); } /* helpers.h's xorshift64, the same sequence */
static double srand1(void) { return 2 * urand() - 1; }

enum { N_TYPES = 5 };
static const char *const type_names[N_TYPES] = {"sphere", "box", "capsule", "cylinder", "hull"};
static double hull_points[8 * 3];

static carom_shape_def make_def(int type, double s)
{
    switch (type) {
    case 0: return carom_shape_sphere(0.5 * s);
    case 1: return carom_shape_box(0.5 * s, 0.3 * s, 0.4 * s);
    case 2: return carom_shape_capsule(0.3 * s, 0.4 * s);
    case 3: return carom_shape_cylinder(0.4 * s, 0.4 * s);
    default:
        for (int i = 0; i < 8; i++) {
            hull_points[3 * i] = ((i & 1) ? 0.5 : -0.4) * s + 0.05 * srand1();
            hull_points[3 * i + 1] = ((i & 2) ? 0.45 : -0.3) * s;
            hull_points[3 * i + 2] = ((i & 4) ? 0.3 : -0.5) * s;
        }
        return carom_shape_hull(hull_points, 8);
    }
}

static carom_quat random_quat(void)
{
    double a = srand1(), b = srand1(), c = srand1(), d = srand1(), l = sqrt(a * a + b * b + c * c + d * d);
    carom_quat q = {a / l, b / l, c / l, d / l};
    return q;
}

static double deepest_point(const shape *a, xform xa, const shape *b, xform xb)
{
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(a, xa, b, xb, 0.0, &cache, &m);
    double s = INFINITY;
    for (int i = 0; i < m.count; i++) s = fmin(s, m.points[i].separation);
    return s;
}

static const shape *shape_of(carom_world *w, carom_body_id id, xform *x)
{
    int slot = body_store_slot(&w->bodies, id.index1, id.generation);
    *x = body_xform(&w->bodies, slot);
    return &w->bodies.shapes[slot];
}

static void test_every_overlap_has_a_point(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    int checked = 0, missed = 0;
    double worst_cyl = 0;
    for (int ta = 0; ta < N_TYPES; ta++)
        for (int tb = 0; tb < N_TYPES; tb++)
            for (int rep = 0; rep < 40; rep++) {
                carom_body_def d = carom_body_def_default();
                d.type = CAROM_BODY_STATIC;
                d.shape = make_def(ta, 0.8 + 0.4 * urand());
                d.orientation = random_quat();
                carom_body_id A = carom_body_create(w, &d);
                d.shape = make_def(tb, 0.8 + 0.4 * urand());
                d.orientation = random_quat();
                d.position.x = 50;
                carom_body_id B = carom_body_create(w, &d);
                xform xa, xb;
                const shape *sa = shape_of(w, A, &xa), *sb = shape_of(w, B, &xb);
                xb.p = v3(0, 0, 0);
                vec3 dir = v3_normalize(v3(srand1(), srand1(), srand1()));
                double lo = 0, hi = 3; /* A's offset along dir from B: overlapping at lo, apart at hi */
                for (int it = 0; it < 60; it++) {
                    double mid = 0.5 * (lo + hi);
                    xform x = xa;
                    x.p = v3_scale(dir, mid);
                    gjk_proxy pa = {sa, NULL, 0, x}, pb = {sb, NULL, 0, xb};
                    if (gjk_distance(&pa, &pb).overlap) lo = mid;
                    else hi = mid;
                }
                int cyl = ta == 3 || tb == 3;
                for (double depth = 1e-3; depth <= 0.13; depth *= 2) {
                    xform x = xa;
                    x.p = v3_scale(dir, hi - depth);
                    checked++;
                    if (deepest_point(sa, x, sb, xb) <= 0) continue;
                    if (cyl) {
                        worst_cyl = fmax(worst_cyl, depth);
                        if (depth <= 0.48 * (1 - cos(3.14159265358979323846 / 16)) * 1.5) continue; /* the prism, a grazing line */
                    }
                    missed++;
                    print_error("%s against %s rep %d: %.3f m into each other, the narrowphase has no point\n",
                                type_names[ta], type_names[tb], rep, depth);
                }
                carom_body_destroy(w, A);
                carom_body_destroy(w, B);
            }
    print_message("overlaps: %d poses 1 mm .. 128 mm deep, %d without a contact point; cylinder pairs start "
                  "overlapping at most %.3f m later (the 16-sided prism)\n", checked, missed, worst_cyl);
    assert_int_equal(missed, 0);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_overlap_has_a_point),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
