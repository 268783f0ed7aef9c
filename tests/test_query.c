/* test_query.c - world queries against brute force: closest distances and
 * overlaps against densely sampled surfaces, shape casts against a sweep
 * stepped and bisected on the narrowphase (an independent implementation),
 * the ray convention for every shape, ray precision far from the origin,
 * ray_cast_all and filters, and bad input leaving the world as it was. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "helpers.h"
#include "mesh_scenes.h"
#include "world.h"
#include "compound.h"
#include "narrowphase.h"

enum { N_CONVEX = 5 };
static const char *const type_names[] = {"sphere", "box", "capsule", "cylinder", "hull", "plane"};

/* an irregular hull: a squashed, skewed octahedron with two extra points */
static const double hull_points[] = {0.7, 0, 0,   -0.5, 0.1, 0,   0, 0.6, 0.1,  0.1, -0.55, 0,
                                     0, 0, 0.45,  0.05, 0.1, -0.5, 0.35, 0.3, 0.3, -0.3, -0.3, -0.25};

static uint64_t rng_state = 0x243F6A8885A308D3ULL;
static double urand(void) { return rnd(&rng_state); }
static double srand1(void) { return 2.0 * urand() - 1.0; }

static carom_quat random_quat(void)
{
    carom_quat q = {srand1(), srand1(), srand1(), srand1()};
    double l = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (l < 1e-3) { q.w = 1; q.x = q.y = q.z = 0; return q; }
    q.w /= l; q.x /= l; q.y /= l; q.z /= l;
    return q;
}

/* Shape of a type, scaled by k (sizes vary between cases). */
static carom_shape_def make_def(int type, double k)
{
    switch (type) {
    case 0: return carom_shape_sphere(0.5 * k);
    case 1: return carom_shape_box(0.4 * k, 0.25 * k, 0.6 * k);
    case 2: return carom_shape_capsule(0.3 * k, 0.4 * k);
    case 3: return carom_shape_cylinder(0.45 * k, 0.3 * k);
    default: {
        static double scaled[sizeof hull_points / sizeof hull_points[0]];
        for (size_t i = 0; i < sizeof hull_points / sizeof hull_points[0]; i++) scaled[i] = hull_points[i] * k;
        return carom_shape_hull(scaled, (int)(sizeof hull_points / sizeof hull_points[0] / 3));
    }
    }
}

static carom_body_id add_posed(carom_world *w, carom_shape_def sd, carom_vec3 p, carom_quat q, carom_body_type type)
{
    carom_body_def d = carom_body_def_default();
    d.shape = sd;
    d.position = p;
    d.orientation = q;
    d.type = type;
    return add_body(w, &d);
}

static const shape *body_shape(const carom_world *w, carom_body_id id)
{
    return &w->bodies.shapes[body_store_slot(&w->bodies, id.index1, id.generation)];
}
static xform body_pose(const carom_world *w, carom_body_id id)
{
    return body_xform(&w->bodies, body_store_slot(&w->bodies, id.index1, id.generation));
}
static vec3 tv(carom_vec3 v) { return v3(v.x, v.y, v.z); }
static carom_vec3 cv(vec3 v) { carom_vec3 r = {v.x, v.y, v.z}; return r; }

/* ---- brute force: sampled surfaces, containment ---------------------------------- */

typedef struct samples { vec3 *p; int n, cap; } samples;
static void put(samples *s, xform x, vec3 local)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 1024;
        s->p = realloc(s->p, sizeof *s->p * (size_t)s->cap);
    }
    s->p[s->n++] = xf_point(x, local);
}

/* Points on the surface of a convex shape, spacing about h. */
static void sample_surface(const shape *sh, xform x, double h, samples *out)
{
    out->n = 0;
    if (sh->type == SHAPE_SPHERE || sh->type == SHAPE_CAPSULE) {
        double r = sh->radius, hh = sh->type == SHAPE_CAPSULE ? sh->half_height : 0;
        int n = (int)(4 * PI_ * r * r / (h * h)) + 16;
        for (int i = 0; i < n; i++) { /* Fibonacci sphere, split at the equator for a capsule */
            double z = 1 - 2 * (i + 0.5) / n, rr = sqrt(1 - z * z), phi = i * 2.399963229728653;
            vec3 p = v3(r * rr * cos(phi), r * rr * sin(phi), r * z);
            p.z += z >= 0 ? hh : -hh;
            put(out, x, p);
        }
        int nz = (int)(2 * hh / h) + 1, na = (int)(2 * PI_ * r / h) + 1;
        if (hh > 0)
            for (int i = 0; i <= nz; i++)
                for (int j = 0; j < na; j++) {
                    double a = 2 * PI_ * j / na;
                    put(out, x, v3(r * cos(a), r * sin(a), -hh + 2 * hh * i / nz));
                }
    } else if (sh->type == SHAPE_CYLINDER) {
        double r = sh->radius, hh = sh->half_height;
        int nz = (int)(2 * hh / h) + 1, na = (int)(2 * PI_ * r / h) + 1, nr = (int)(r / h) + 1;
        for (int i = 0; i <= nz; i++)
            for (int j = 0; j < na; j++) {
                double a = 2 * PI_ * j / na;
                put(out, x, v3(r * cos(a), r * sin(a), -hh + 2 * hh * i / nz));
            }
        for (int k = 1; k <= nr; k++) {
            double rk = r * k / nr;
            int nk = (int)(2 * PI_ * rk / h) + 1;
            for (int j = 0; j < nk; j++) {
                double a = 2 * PI_ * j / nk;
                put(out, x, v3(rk * cos(a), rk * sin(a), hh));
                put(out, x, v3(rk * cos(a), rk * sin(a), -hh));
            }
        }
        put(out, x, v3(0, 0, hh));
        put(out, x, v3(0, 0, -hh));
    } else {
        /* polytopes: every face fanned into triangles, each sampled on a grid */
        hull *hb = sh->type == SHAPE_BOX ? hull_make_box(sh->half_extents) : NULL;
        const hull *hl = hb ? hb : sh->hull;
        for (int f = 0; f < hl->face_count; f++) {
            const hull_face *fc = &hl->faces[f];
            vec3 a = hl->vertices[hl->face_vertices[fc->first]];
            for (int k = 1; k + 1 < fc->count; k++) {
                vec3 b = hl->vertices[hl->face_vertices[fc->first + k]];
                vec3 c = hl->vertices[hl->face_vertices[fc->first + k + 1]];
                double e = dmax(v3_len(v3_sub(b, a)), dmax(v3_len(v3_sub(c, a)), v3_len(v3_sub(c, b))));
                int n = (int)(e / h) + 1;
                for (int i = 0; i <= n; i++)
                    for (int j = 0; i + j <= n; j++) {
                        double u = (double)i / n, v = (double)j / n;
                        put(out, x, v3_add(a, v3_add(v3_scale(v3_sub(b, a), u), v3_scale(v3_sub(c, a), v))));
                    }
            }
        }
        hull_free(hb);
    }
}

/* 1 when world point p is inside the shape grown by tol. */
static int contains(const shape *sh, xform x, vec3 pw, double tol)
{
    vec3 p = xf_inv_point(x, pw);
    switch (sh->type) {
    case SHAPE_SPHERE: return v3_len(p) <= sh->radius + tol;
    case SHAPE_BOX:
        return fabs(p.x) <= sh->half_extents.x + tol && fabs(p.y) <= sh->half_extents.y + tol &&
               fabs(p.z) <= sh->half_extents.z + tol;
    case SHAPE_CAPSULE: {
        double z = dmax(-sh->half_height, dmin(sh->half_height, p.z));
        return v3_len(v3_sub(p, v3(0, 0, z))) <= sh->radius + tol;
    }
    case SHAPE_CYLINDER:
        return fabs(p.z) <= sh->half_height + tol && sqrt(p.x * p.x + p.y * p.y) <= sh->radius + tol;
    case SHAPE_HULL:
        for (int f = 0; f < sh->hull->face_count; f++)
            if (v3_dot(sh->hull->faces[f].normal, p) > sh->hull->faces[f].offset + tol) return 0;
        return 1;
    default: return v3_dot(sh->plane_normal, p) <= sh->plane_offset + tol;
    }
}

static double brute_distance(const samples *a, const samples *b)
{
    double best = INFINITY;
    for (int i = 0; i < a->n; i++)
        for (int j = 0; j < b->n; j++) {
            double d2 = v3_len2(v3_sub(a->p[i], b->p[j]));
            if (d2 < best) best = d2;
        }
    return sqrt(best);
}

/* ---- distances and overlaps ------------------------------------------------------- */

static void test_distance_against_sampling(void **state)
{
    (void)state;
    const double h = 0.03;
    samples sa = {0}, sb = {0};
    int checked = 0;
    for (int ta = 0; ta < N_CONVEX; ta++)
        for (int tb = 0; tb < N_CONVEX; tb++)
            for (int rep = 0; rep < 3; rep++) {
                carom_world *w = world_default();
                double far = rep == 2 ? 1e5 : 0.0; /* the same geometry far from the origin */
                carom_vec3 pa = {far + srand1(), srand1(), srand1()};
                vec3 dir = v3_normalize(v3(srand1(), srand1(), srand1()));
                double gap = 1.2 + 1.5 * urand();
                carom_vec3 pb = cv(v3_madd(tv(pa), gap, dir));
                carom_body_id a = add_posed(w, make_def(ta, 0.7 + 0.6 * urand()), pa, random_quat(), CAROM_BODY_DYNAMIC);
                carom_body_id b = add_posed(w, make_def(tb, 0.7 + 0.6 * urand()), pb, random_quat(), CAROM_BODY_DYNAMIC);
                carom_distance_result r;
                assert_int_equal(carom_world_body_distance(w, a, b, &r), CAROM_OK);
                sample_surface(body_shape(w, a), body_pose(w, a), h, &sa);
                sample_surface(body_shape(w, b), body_pose(w, b), h, &sb);
                double brute = brute_distance(&sa, &sb);
                if (brute < 3 * h) { carom_world_destroy(w); continue; } /* may touch: not this test */
                /* the exact distance is at most the sampled one, and not less by more than the spacing */
                if (!(r.distance <= brute + 1e-9 && r.distance >= brute - h))
                    fail_msg("%s-%s rep %d: distance %.9f, sampled %.9f", type_names[ta], type_names[tb], rep,
                             r.distance, brute);
                /* the points lie on the surfaces and are that far apart, along the normal */
                vec3 qa = tv(r.point_a), qb = tv(r.point_b);
                double tol = 1e-9 * (1 + far);
                assert_true(contains(body_shape(w, a), body_pose(w, a), qa, tol));
                assert_true(contains(body_shape(w, b), body_pose(w, b), qb, tol));
                assert_true(fabs(v3_len(v3_sub(qb, qa)) - r.distance) < tol + 1e-9);
                assert_true(v3_len(v3_sub(v3_sub(qb, qa), v3_scale(tv(r.normal), r.distance))) < tol + 1e-9);
                checked++;
                carom_world_destroy(w);
            }
    free(sa.p);
    free(sb.p);
    assert_true(checked >= 60);
}

/* Overlap is decided by brute force where it is clear: a sampled surface
 * point of one shape inside the other (overlap), or sampled surfaces farther
 * apart than the spacing (apart). */
static void test_overlap_against_sampling(void **state)
{
    (void)state;
    const double h = 0.03;
    samples sa = {0}, sb = {0};
    int decided_in = 0, decided_out = 0;
    for (int ta = 0; ta < N_CONVEX; ta++)
        for (int tb = 0; tb < N_CONVEX; tb++)
            for (int rep = 0; rep < 8; rep++) {
                carom_world *w = world_default();
                double k = 0.7 + 0.6 * urand();
                carom_vec3 pb = {srand1() * 0.2, srand1() * 0.2, srand1() * 0.2};
                carom_body_id b = add_posed(w, make_def(tb, k), pb, random_quat(), CAROM_BODY_STATIC);
                vec3 dir = v3_normalize(v3(srand1(), srand1(), srand1()));
                carom_vec3 pa = cv(v3_madd(tv(pb), 0.3 + 1.0 * urand(), dir));
                carom_quat qa = random_quat();
                carom_shape_def da = make_def(ta, 0.7 + 0.6 * urand());
                carom_body_id ids[4];
                int n = carom_world_overlap(w, &da, pa, qa, NULL, ids, 4);
                assert_true(n == 0 || n == 1);
                /* the same shape as a body, for the brute force */
                carom_body_id a = add_posed(w, da, pa, qa, CAROM_BODY_STATIC);
                sample_surface(body_shape(w, a), body_pose(w, a), h, &sa);
                sample_surface(body_shape(w, b), body_pose(w, b), h, &sb);
                int inside = 0;
                for (int i = 0; i < sa.n && !inside; i++) inside = contains(body_shape(w, b), body_pose(w, b), sa.p[i], -1e-9);
                for (int i = 0; i < sb.n && !inside; i++) inside = contains(body_shape(w, a), body_pose(w, a), sb.p[i], -1e-9);
                if (inside) {
                    if (n != 1) fail_msg("%s over %s rep %d: overlap missed", type_names[ta], type_names[tb], rep);
                    assert_true(carom_body_id_equal(ids[0], b));
                    decided_in++;
                } else if (brute_distance(&sa, &sb) > h) {
                    if (n != 0) fail_msg("%s over %s rep %d: apart but reported", type_names[ta], type_names[tb], rep);
                    decided_out++;
                }
                carom_world_destroy(w);
            }
    free(sa.p);
    free(sb.p);
    print_message("overlap: %d overlapping and %d apart decided by brute force\n", decided_in, decided_out);
    assert_true(decided_in >= 50 && decided_out >= 20);
}

/* A plane: distances and overlaps are exact along its normal. */
static void test_plane_distance_and_overlap(void **state)
{
    (void)state;
    for (int t = 0; t < N_CONVEX; t++) {
        carom_world *w = world_default();
        carom_quat id = {1, 0, 0, 0};
        carom_vec3 o = {0, 0, 0};
        carom_body_id ground = add_posed(w, carom_shape_plane(0, 0, 1, 0.25), o, id, CAROM_BODY_STATIC);
        carom_quat q = random_quat();
        carom_vec3 p = {srand1(), srand1(), 2.0};
        carom_body_id b = add_posed(w, make_def(t, 1.0), p, q, CAROM_BODY_DYNAMIC);
        /* lowest point from the support mapping, independent of the query */
        const shape *sh = body_shape(w, b);
        xform x = body_pose(w, b);
        double low = xf_point(x, shape_support_local(sh, q_inv_rotate(x.q, v3(0, 0, -1)))).z;
        carom_distance_result r;
        assert_int_equal(carom_world_body_distance(w, b, ground, &r), CAROM_OK);
        assert_true(fabs(r.distance - (low - 0.25)) < 1e-12);
        assert_true(fabs(r.normal.z + 1) < 1e-12);
        assert_int_equal(carom_world_body_distance(w, ground, b, &r), CAROM_OK);
        assert_true(fabs(r.distance - (low - 0.25)) < 1e-12 && fabs(r.normal.z - 1) < 1e-12);
        carom_shape_def sd = make_def(t, 1.0);
        carom_body_destroy(w, b); /* the query shape alone above the plane */
        carom_vec3 at = {p.x, p.y, p.z - (low - 0.25) + 1e-6}; /* just above: apart */
        carom_body_id ids[2];
        assert_int_equal(carom_world_overlap(w, &sd, at, q, NULL, ids, 2), 0);
        at.z -= 2e-6; /* just below: overlapping */
        assert_int_equal(carom_world_overlap(w, &sd, at, q, NULL, ids, 2), 1);
        assert_true(carom_body_id_equal(ids[0], ground));
        carom_world_destroy(w);
    }
}

static void test_overlapping_bodies_distance_is_penetration(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_quat id = {1, 0, 0, 0};
    carom_vec3 pa = {0, 0, 0}, pb = {0.9, 0, 0};
    carom_body_id a = add_posed(w, carom_shape_sphere(0.5), pa, id, CAROM_BODY_DYNAMIC);
    carom_body_id b = add_posed(w, carom_shape_sphere(0.5), pb, id, CAROM_BODY_DYNAMIC);
    carom_distance_result r;
    assert_int_equal(carom_world_body_distance(w, a, b, &r), CAROM_OK);
    assert_true(fabs(r.distance + 0.1) < 1e-12);
    assert_true(fabs(r.normal.x - 1) < 1e-12);
    /* the nearest body to a shape: the closest of several, within max_distance */
    carom_vec3 pc = {5, 0, 0};
    add_posed(w, carom_shape_box(0.5, 0.5, 0.5), pc, id, CAROM_BODY_STATIC);
    carom_shape_def probe = carom_shape_sphere(0.25);
    carom_vec3 at = {3.0, 0, 0};
    assert_int_equal(carom_world_shape_distance(w, &probe, at, id, 10.0, NULL, &r), 1);
    assert_true(fabs(r.distance - (4.5 - 3.25)) < 1e-9);
    assert_int_equal(carom_world_shape_distance(w, &probe, at, id, 1.0, NULL, &r), 0);
    carom_world_destroy(w);
}

/* ---- shape casts ------------------------------------------------------------------ */

static int narrowphase_overlap(const shape *a, xform xa, const shape *b, xform xb)
{
    collide_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.feature = -1;
    manifold m;
    collide(a, xa, b, xb, 0.0, &cache, &m);
    for (int i = 0; i < m.count; i++)
        if (m.points[i].separation <= 0) return 1;
    return 0;
}

/* 1 when a sampled surface point of either shape is inside the other (a
 * plane: any point of A below it). */
static int sampled_overlap(const shape *a, xform xa, const shape *b, xform xb, samples *sa, samples *sb)
{
    sample_surface(a, xa, 0.02, sa);
    for (int i = 0; i < sa->n; i++)
        if (contains(b, xb, sa->p[i], 0.0)) return 1;
    if (b->type == SHAPE_PLANE) return 0;
    sample_surface(b, xb, 0.02, sb);
    for (int i = 0; i < sb->n; i++)
        if (contains(a, xa, sb->p[i], 0.0)) return 1;
    return 0;
}

/* Every convex shape swept against every shape (plane included): the first
 * overlapping sample of a 200-step sweep, bisected, on the narrowphase. */
static void test_shape_cast_against_sweep(void **state)
{
    (void)state;
    int hits = 0, misses = 0;
    double worst = 0, worst_touch = 0, worst_touch_cyl = 0;
    samples sa = {0}, sb = {0};
    int late = 0;
    for (int ta = 0; ta < N_CONVEX; ta++)
        for (int tb = 0; tb <= N_CONVEX; tb++)
            for (int rep = 0; rep < 6; rep++) {
                carom_world *w = world_default();
                carom_quat id = {1, 0, 0, 0};
                carom_vec3 pb = {0, 0, 0};
                carom_body_id b = tb == N_CONVEX
                                      ? add_posed(w, carom_shape_plane(0, 0, 1, -0.8), pb, id, CAROM_BODY_STATIC)
                                      : add_posed(w, make_def(tb, 0.8 + 0.4 * urand()), pb, random_quat(), CAROM_BODY_STATIC);
                carom_shape_def da = make_def(ta, 0.8 + 0.4 * urand());
                carom_quat qa = random_quat();
                vec3 dir = v3_normalize(v3(srand1(), srand1(), 0.5 + urand()));
                vec3 start = v3_scale(dir, 3.0);
                /* aim near B's centre: most casts hit, some graze or miss */
                vec3 aim = v3(srand1() * 0.6, srand1() * 0.6, srand1() * 0.6);
                vec3 T = v3_scale(v3_sub(aim, start), 1.6);
                carom_ray_hit hit;
                int r = carom_world_shape_cast(w, &da, cv(start), qa, cv(T), NULL, &hit);
                assert_true(r == 0 || r == 1);
                carom_body_id a = add_posed(w, da, cv(start), qa, CAROM_BODY_STATIC);
                const shape *sha = body_shape(w, a), *shb = body_shape(w, b);
                xform xa = body_pose(w, a), xb = body_pose(w, b);
                assert_false(narrowphase_overlap(sha, xa, shb, xb));
                int first = -1;
                for (int i = 1; i <= 200 && first < 0; i++) {
                    xform x = xa;
                    x.p = v3_madd(start, i / 200.0, T);
                    if (narrowphase_overlap(sha, x, shb, xb)) first = i;
                }
                if (first < 0) {
                    if (r == 1) /* a graze between samples: the point is on B */
                        assert_true(contains(shb, xb, tv(hit.point), 1e-6));
                    misses++;
                    carom_world_destroy(w);
                    continue;
                }
                double lo = (first - 1) / 200.0, hi = first / 200.0;
                for (int it = 0; it < 50; it++) {
                    double mid = 0.5 * (lo + hi);
                    xform x = xa;
                    x.p = v3_madd(start, mid, T);
                    if (narrowphase_overlap(sha, x, shb, xb)) hi = mid;
                    else lo = mid;
                }
                if (r != 1) {
                    xform xo = xa;
                    xo.p = v3_madd(start, dmin(1.0, hi + 0.01), T);
                    if (sampled_overlap(sha, xo, shb, xb, &sa, &sb))
                        fail_msg("%s cast at %s rep %d: missed a hit at %.6f", type_names[ta], type_names[tb], rep, hi);
                    print_message("  %s cast at %s: the narrowphase reports an overlap sampling does not see\n",
                                  type_names[ta], type_names[tb]);
                    misses++;
                    carom_world_destroy(w);
                    continue;
                }
                assert_true(carom_body_id_equal(hit.body, b));
                /* at the fraction they touch: the point is on both surfaces */
                xform xh = xa;
                xh.p = v3_madd(start, hit.fraction, T);
                double touch = 1e-6;
                double miss_b = 0, miss_a = 0;
                while (!contains(shb, xb, tv(hit.point), miss_b) && miss_b < 1) miss_b = miss_b ? 2 * miss_b : 1e-9;
                while (!contains(sha, xh, tv(hit.point), miss_a) && miss_a < 1) miss_a = miss_a ? 2 * miss_a : 1e-9;
                if (ta == 3 || tb == 3) worst_touch_cyl = dmax(worst_touch_cyl, dmax(miss_a, miss_b));
                else worst_touch = dmax(worst_touch, dmax(miss_a, miss_b));
                if (miss_a > touch || miss_b > touch ||
                    (tb < N_CONVEX && (contains(shb, xb, tv(hit.point), -touch) || contains(sha, xh, tv(hit.point), -touch))))
                    fail_msg("%s cast at %s rep %d: the point is not on both surfaces (%.1e, %.1e from them)",
                             type_names[ta], type_names[tb], rep, miss_a, miss_b);
                /* exact: the normal's plane separates A from B at the fraction
                 * (so, the motion being a translation closing along it, at every
                 * earlier time), and they touch there */
                vec3 n = v3_neg(tv(hit.normal));
                double top_a = v3_dot(n, xf_point(xh, shape_support_local(sha, q_inv_rotate(xh.q, n))));
                double low_b = tb == N_CONVEX ? 0.8 / -n.z /* the plane z = -0.8, solid below */
                                              : v3_dot(n, xf_point(xb, shape_support_local(shb, q_inv_rotate(xb.q, v3_neg(n)))));
                if (!(low_b - top_a > -1e-7 && low_b - top_a < 1e-6))
                    fail_msg("%s cast at %s rep %d: the normal does not separate (gap %.3e)", type_names[ta], type_names[tb],
                             rep, low_b - top_a);
                /* the narrowphase sweep finds no overlap before ours, nor later
                 * (its cylinder pairs, 16-sided prisms until they worked on the
                 * true round shape, started reporting overlap up to 3.55 cm in) */
                double err = (hi - hit.fraction) * v3_len(T);
                if (err > worst) worst = err;
                if (err > 1e-3) late++;
                if (err > 0.05) { /* that far in, sampling sees them overlap: the narrowphase is late, not us */
                    xform xo = xa;
                    xo.p = v3_madd(start, 0.5 * (hit.fraction + hi), T);
                    if (!sampled_overlap(sha, xo, shb, xb, &sa, &sb))
                        fail_msg("%s cast at %s rep %d: no overlap %.2e m past our hit", type_names[ta], type_names[tb],
                                 rep, 0.5 * err);
                }
                if (err < -1e-7) {
                    /* the narrowphase claims an overlap the plane above rules
                     * out: sampling must find none there */
                    xform xo = xa;
                    xo.p = v3_madd(start, hi, T);
                    if (sampled_overlap(sha, xo, shb, xb, &sa, &sb))
                        fail_msg("%s cast at %s rep %d: fraction %.9f, sweep %.9f (%.2e m)", type_names[ta],
                                 type_names[tb], rep, hit.fraction, hi, err);
                    print_message("  %s cast at %s: the narrowphase reports overlap %.2e m before contact\n",
                                  type_names[ta], type_names[tb], -err);
                }
                /* the normal is unit and against the cast */
                assert_true(fabs(v3_len(tv(hit.normal)) - 1) < 1e-9);
                assert_true(v3_dot(tv(hit.normal), T) < 0);
                hits++;
                carom_world_destroy(w);
            }
    free(sa.p);
    free(sb.p);
    print_message("shape casts: %d hits, %d misses; the hit point is within %.1e m of both surfaces (%.1e with a "
                  "cylinder); the narrowphase sweep finds overlap more than 1 mm later in %d (at most %.2e m)\n",
                  hits, misses, worst_touch, worst_touch_cyl, late, worst);
    assert_true(hits >= 120);
    assert_int_equal(late, 0);
    assert_true(worst <= 1e-6);
}

static void test_shape_cast_initial_overlap_and_far(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_quat id = {1, 0, 0, 0};
    carom_vec3 o = {1e6, -1e6, 1e6};
    carom_body_id box = add_posed(w, carom_shape_box(1, 1, 1), o, id, CAROM_BODY_STATIC);
    carom_shape_def s = carom_shape_sphere(0.5);
    carom_ray_hit hit;
    /* overlapping at the start: fraction 0, normal against the sweep */
    carom_vec3 t = {0, 0, -3};
    assert_int_equal(carom_world_shape_cast(w, &s, o, id, t, NULL, &hit), 1);
    assert_true(hit.fraction == 0 && fabs(hit.normal.z - 1) < 1e-12);
    /* far from the origin: a sphere dropped on the box lands at z = 1.5 above it */
    carom_vec3 from = {o.x + 0.3, o.y - 0.2, o.z + 4};
    assert_int_equal(carom_world_shape_cast(w, &s, from, id, t, NULL, &hit), 1);
    assert_true(carom_body_id_equal(hit.body, box));
    assert_true(fabs(hit.fraction - 2.5 / 3.0) * 3.0 < 1e-7);
    assert_true(fabs(hit.point.z - (o.z + 1)) < 1e-7 && fabs(hit.point.x - from.x) < 1e-7);
    assert_true(fabs(hit.normal.z - 1) < 1e-9);
    carom_world_destroy(w);
}

/* ---- rays -------------------------------------------------------------------------- */

/* Every shape: a ray from inside hits at 0, at its origin, against itself. */
static void test_ray_inside_convention(void **state)
{
    (void)state;
    for (int t = 0; t <= N_CONVEX; t++) {
        carom_world *w = world_default();
        carom_vec3 p = {2, -1, 0.5};
        carom_quat q = random_quat(), level = {1, 0, 0, 0};
        carom_body_id b = t == N_CONVEX ? add_posed(w, carom_shape_plane(0, 0, 1, 0), p, level, CAROM_BODY_STATIC)
                                        : add_posed(w, make_def(t, 1.0), p, q, CAROM_BODY_STATIC);
        carom_vec3 origin = {p.x + 0.05, p.y - 0.03, p.z - 0.02}, tr = {0, 3, 4};
        carom_ray_hit hit;
        assert_int_equal(carom_world_ray_cast(w, origin, tr, &hit), 1);
        assert_true(carom_body_id_equal(hit.body, b));
        assert_true(hit.fraction == 0.0);
        assert_true(hit.point.x == origin.x && hit.point.y == origin.y && hit.point.z == origin.z);
        assert_true(fabs(hit.normal.y + 0.6) < 1e-15 && fabs(hit.normal.z + 0.8) < 1e-15);
        carom_ray_hit all[4];
        assert_int_equal(carom_world_ray_cast_all(w, origin, tr, NULL, all, 4), 1);
        assert_true(all[0].fraction == 0.0);
        carom_world_destroy(w);
    }
}

/* A ray from d metres away along each axis of each shape hits where the
 * geometry says, within 1e-6 m, for d = 1e2 .. 1e6, and the same with the
 * whole scene moved d from the origin. */
static void test_ray_precision_far_away(void **state)
{
    (void)state;
    double worst = 0;
    for (double d = 1e2; d <= 1e6 * 1.01; d *= 10)
        for (int t = 0; t <= N_CONVEX; t++)
            for (int moved = 0; moved < 2; moved++) {
                carom_world *w = world_default();
                carom_quat id = {1, 0, 0, 0};
                carom_vec3 p = {moved ? d : 0, moved ? -d : 0, moved ? d : 0};
                carom_shape_def sd = t == N_CONVEX ? carom_shape_plane(1, 0, 0, 0) : make_def(t, 1.0);
                if (t == 4) sd = make_def(1, 1.0); /* a hull's faces: see below */
                add_posed(w, sd, p, id, CAROM_BODY_STATIC);
                /* expected surface point along +x: radius, half extent, ... */
                double surface = t == 0 ? 0.5 : t == 1 || t == 4 ? 0.4 : t == 2 ? 0.3 : t == 3 ? 0.45 : 0.0;
                double start = moved ? 50.0 : d;
                carom_vec3 origin = {p.x + start, p.y + 0.01, p.z - 0.02};
                carom_vec3 tr = {-2 * start, 0, 0};
                carom_ray_hit hit;
                assert_int_equal(carom_world_ray_cast(w, origin, tr, &hit), 1);
                double want_x = p.x + (t == 0 ? sqrt(0.25 - 0.0001 - 0.0004)
                                        : t == 2 ? sqrt(0.09 - 0.0001) : t == 3 ? sqrt(0.2025 - 0.0001) : surface);
                double err = fabs(hit.point.x - want_x);
                if (err > worst) worst = err;
                if (err > 1e-6) fail_msg("%s at %g (moved %d): hit x off by %.3e m", type_names[t], d, moved, err);
                assert_true(hit.normal.x > 0.998); /* outward, nearly +x (the ray is 1-2 cm off axis) */
                carom_world_destroy(w);
            }
    print_message("ray precision: worst error %.2e m\n", worst);
}

/* A genuine hull (not a box) far away: the hit lies on the face plane. */
static void test_ray_precision_hull(void **state)
{
    (void)state;
    for (double d = 1e2; d <= 1e6 * 1.01; d *= 10) {
        carom_world *w = world_default();
        carom_quat id = {1, 0, 0, 0};
        carom_vec3 p = {0, 0, 0};
        carom_shape_def sd = make_def(4, 1.0);
        carom_body_id b = add_posed(w, sd, p, id, CAROM_BODY_STATIC);
        vec3 dir = v3_normalize(v3(1, 0.3, 0.2));
        carom_vec3 origin = cv(v3_scale(dir, d)), tr = cv(v3_scale(dir, -2 * d));
        carom_ray_hit hit;
        assert_int_equal(carom_world_ray_cast(w, origin, tr, &hit), 1);
        const shape *sh = body_shape(w, b);
        /* on the surface: inside grown by 1e-6, outside shrunk by 1e-6 */
        double out = -INFINITY;
        for (int f = 0; f < sh->hull->face_count; f++)
            out = dmax(out, v3_dot(sh->hull->faces[f].normal, tv(hit.point)) - sh->hull->faces[f].offset);
        assert_true(fabs(out) < 1e-6);
        carom_world_destroy(w);
    }
}

static int reject_second(void *ctx, carom_body_id id)
{
    carom_body_id *skip = ctx;
    return !carom_body_id_equal(*skip, id);
}

static void test_ray_cast_all_and_filters(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_quat id = {1, 0, 0, 0};
    carom_body_id row[5];
    for (int i = 0; i < 5; i++) {
        carom_vec3 p = {2.0 * (4 - i), 0, 0}; /* created far to near */
        carom_body_def d = carom_body_def_default();
        d.type = CAROM_BODY_STATIC;
        d.shape = carom_shape_sphere(0.5);
        d.position = p;
        d.orientation = id;
        d.category = i % 2 ? 2u : 1u;
        row[i] = carom_body_create(w, &d);
    }
    carom_vec3 origin = {-3, 0, 0}, tr = {20, 0, 0};
    carom_ray_hit hits[8];
    assert_int_equal(carom_world_ray_cast_all(w, origin, tr, NULL, hits, 8), 5);
    for (int i = 0; i < 5; i++) {
        assert_true(carom_body_id_equal(hits[i].body, row[4 - i])); /* nearest first */
        assert_true(fabs(hits[i].point.x - (2.0 * i - 0.5)) < 1e-12);
    }
    /* the count is the total even when the array is short */
    assert_int_equal(carom_world_ray_cast_all(w, origin, tr, NULL, hits, 2), 5);
    assert_int_equal(carom_world_ray_cast_all(w, origin, tr, NULL, NULL, 0), 5);
    carom_query_filter f = carom_query_filter_default();
    f.mask = 2;
    assert_int_equal(carom_world_ray_cast_all(w, origin, tr, &f, hits, 8), 2);
    assert_true(carom_body_id_equal(hits[0].body, row[3]) && carom_body_id_equal(hits[1].body, row[1]));
    carom_ray_hit one;
    assert_int_equal(carom_world_ray_cast_filtered(w, origin, tr, &f, &one), 1);
    assert_true(carom_body_id_equal(one.body, row[3]));
    f.mask = CAROM_MASK_ALL;
    f.fn = reject_second;
    f.context = &row[4];
    assert_int_equal(carom_world_ray_cast_filtered(w, origin, tr, &f, &one), 1);
    assert_true(carom_body_id_equal(one.body, row[3]));
    /* the filter also applies to overlaps and casts */
    carom_shape_def big = carom_shape_box(10, 1, 1);
    carom_vec3 mid = {4, 0, 0};
    carom_body_id ids[8];
    assert_int_equal(carom_world_overlap(w, &big, mid, id, NULL, ids, 8), 5);
    f.fn = NULL;
    f.mask = 1;
    assert_int_equal(carom_world_overlap(w, &big, mid, id, &f, ids, 8), 3);
    carom_shape_def ball = carom_shape_sphere(0.25);
    f.mask = 2;
    assert_int_equal(carom_world_shape_cast(w, &ball, origin, id, tr, &f, &one), 1);
    assert_true(carom_body_id_equal(one.body, row[3]));
    assert_true(fabs(one.fraction - (2.0 - 0.75 + 3.0) / 20.0) < 1e-9);
    carom_world_destroy(w);
}

/* A filter callback cannot change the world: it runs locked. */
static carom_world *g_world;
static int destroying_filter(void *ctx, carom_body_id id)
{
    int *refused = ctx;
    if (carom_body_destroy(g_world, id) == CAROM_ERROR_LOCKED) (*refused)++;
    return 1;
}

static void test_bad_input_leaves_world_unchanged(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_quat id = {1, 0, 0, 0}, bad_q = {2, 0, 0, 0};
    carom_vec3 o = {0, 0, 0}, nan3 = {NAN, 0, 0}, t = {0, 0, -1};
    carom_body_id a = add_posed(w, carom_shape_sphere(0.5), o, id, CAROM_BODY_DYNAMIC);
    carom_vec3 po = {3, 0, 0};
    carom_body_id b = add_posed(w, carom_shape_box(0.5, 0.5, 0.5), po, id, CAROM_BODY_DYNAMIC);
    carom_shape_def s = carom_shape_sphere(0.5), bad_s = carom_shape_sphere(-1), plane = carom_shape_plane(0, 0, 1, 0);
    carom_ray_hit hit;
    carom_body_id ids[4];
    carom_distance_result r;
    assert_int_equal(carom_world_shape_cast(w, NULL, o, id, t, NULL, &hit), -1);
    assert_non_null(strstr(carom_world_last_error(w), "shape"));
    assert_int_equal(carom_world_shape_cast(w, &s, nan3, id, t, NULL, &hit), -1);
    assert_non_null(strstr(carom_world_last_error(w), "position"));
    assert_int_equal(carom_world_shape_cast(w, &s, o, bad_q, t, NULL, &hit), -1);
    assert_non_null(strstr(carom_world_last_error(w), "orientation"));
    assert_int_equal(carom_world_shape_cast(w, &s, o, id, nan3, NULL, &hit), -1);
    assert_non_null(strstr(carom_world_last_error(w), "translation"));
    assert_int_equal(carom_world_shape_cast(w, &bad_s, o, id, t, NULL, &hit), -1);
    assert_non_null(strstr(carom_world_last_error(w), "radius"));
    assert_int_equal(carom_world_shape_cast(w, &plane, o, id, t, NULL, &hit), -1);
    assert_non_null(strstr(carom_world_last_error(w), "plane"));
    assert_int_equal(carom_world_shape_cast(w, &s, o, id, t, NULL, NULL), -1);
    assert_int_equal(carom_world_overlap(w, &s, o, id, NULL, NULL, 3), -1);
    assert_int_equal(carom_world_overlap(w, &s, o, id, NULL, ids, -1), -1);
    assert_int_equal(carom_world_ray_cast_all(w, nan3, t, NULL, NULL, 0), -1);
    assert_int_equal(carom_world_shape_distance(w, &s, o, id, -1, NULL, &r), -1);
    assert_non_null(strstr(carom_world_last_error(w), "max_distance"));
    assert_int_equal(carom_world_shape_distance(w, &s, o, id, NAN, NULL, &r), -1);
    assert_int_equal(carom_world_body_distance(w, a, a, &r), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_body_distance(w, a, b, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    carom_body_id gone = add_posed(w, carom_shape_sphere(0.5), po, id, CAROM_BODY_DYNAMIC);
    carom_body_destroy(w, gone);
    assert_int_equal(carom_world_body_distance(w, a, gone, &r), CAROM_ERROR_STALE_ID);
    assert_non_null(strstr(carom_world_last_error(w), "body b"));
    /* a callback that tries to destroy is refused; everything stays */
    int refused = 0;
    carom_query_filter f = carom_query_filter_default();
    f.fn = destroying_filter;
    f.context = &refused;
    g_world = w;
    carom_shape_def big = carom_shape_box(5, 5, 5);
    assert_int_equal(carom_world_overlap(w, &big, o, id, &f, ids, 4), 2);
    assert_int_equal(refused, 2);
    assert_int_equal(carom_world_body_count(w), 2);
    assert_true(carom_body_is_valid(w, a) && carom_body_is_valid(w, b));
    /* and the world is not left locked */
    assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    carom_world_destroy(w);
}

/* A mesh ground (a 4 x 4 grid of triangles at z = 0.3, tilted nothing): a
 * ball swept down lands at its radius above it, an overlap and a distance
 * see the nearest triangle, a ray hits the face. */
static void test_queries_against_a_mesh(void **state)
{
    (void)state;
    double verts[5 * 5 * 3];
    int tris[4 * 4 * 2 * 3], nt = 0;
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            double *v = &verts[3 * (j * 5 + i)];
            v[0] = -2 + i; v[1] = -2 + j; v[2] = 0.3;
        }
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            int a = j * 5 + i, b = a + 1, c = a + 6, d = a + 5;
            tris[nt++] = a; tris[nt++] = b; tris[nt++] = c;
            tris[nt++] = a; tris[nt++] = c; tris[nt++] = d;
        }
    carom_world *w = world_default();
    carom_mesh_def md = carom_mesh_def_default();
    md.vertices = verts; md.vertex_count = 25; md.triangles = tris; md.triangle_count = nt / 3;
    carom_body_def bd = carom_body_def_default();
    bd.type = CAROM_BODY_STATIC;
    bd.shape.type = CAROM_SHAPE_MESH;
    bd.mesh = &md;
    bd.position.x = 100; /* away from the origin: the frames must be used */
    carom_body_id ground = carom_body_create(w, &bd);
    assert_false(carom_body_id_is_null(ground));
    carom_quat id = {1, 0, 0, 0};
    for (int t = 0; t < N_CONVEX; t++) {
        carom_shape_def sd = make_def(t, 1.0);
        carom_quat q = random_quat();
        carom_vec3 from = {100.3 + 0.5 * srand1(), 0.4 * srand1(), 3.0}, down = {0, 0, -5};
        carom_ray_hit hit;
        assert_int_equal(carom_world_shape_cast(w, &sd, from, q, down, NULL, &hit), 1);
        assert_true(carom_body_id_equal(hit.body, ground));
        /* the lowest point along -z from the support mapping lands on z = 0.3 */
        carom_body_id probe = add_posed(w, sd, from, q, CAROM_BODY_STATIC);
        const shape *sh = body_shape(w, probe);
        xform x = body_pose(w, probe);
        double low = xf_point(x, shape_support_local(sh, q_inv_rotate(x.q, v3(0, 0, -1)))).z;
        carom_body_destroy(w, probe);
        double want = (low - 0.3) / 5.0;
        if (fabs(hit.fraction - want) * 5.0 > 1e-6)
            fail_msg("%s onto a mesh: fraction %.9f, want %.9f", type_names[t], hit.fraction, want);
        assert_true(fabs(hit.normal.z - 1) < 1e-6 && fabs(hit.point.z - 0.3) < 1e-6);
        /* distance and overlap from just above and just below */
        carom_distance_result r;
        carom_vec3 above = {from.x, from.y, from.z - (low - 0.3) + 0.01};
        assert_int_equal(carom_world_shape_distance(w, &sd, above, q, 1.0, NULL, &r), 1);
        assert_true(fabs(r.distance - 0.01) < 1e-6);
        carom_body_id ids[2];
        assert_int_equal(carom_world_overlap(w, &sd, above, q, NULL, ids, 2), 0);
        above.z -= 0.02;
        assert_int_equal(carom_world_overlap(w, &sd, above, q, NULL, ids, 2), 1);
    }
    carom_vec3 o = {100.5, 0.5, 5}, d = {0, 0, -10};
    carom_ray_hit hit;
    assert_int_equal(carom_world_ray_cast(w, o, d, &hit), 1);
    assert_true(fabs(hit.point.z - 0.3) < 1e-12);
    /* a body against the mesh */
    carom_vec3 pb = {100, 0, 2};
    carom_body_id ball = add_posed(w, carom_shape_sphere(0.5), pb, id, CAROM_BODY_DYNAMIC);
    carom_distance_result r;
    assert_int_equal(carom_world_body_distance(w, ball, ground, &r), CAROM_OK);
    assert_true(fabs(r.distance - 1.2) < 1e-9 && fabs(r.normal.z + 1) < 1e-9);
    assert_int_equal(carom_world_body_distance(w, ground, ball, &r), CAROM_OK);
    assert_true(fabs(r.distance - 1.2) < 1e-9 && fabs(r.normal.z - 1) < 1e-9);
    carom_world_destroy(w);
}

/* The parts of level geometry the _child(ren) queries name: a 2 x 2 m mesh
 * of 1 m cells at z = 1 over x, y in [0, 2], its 8 triangles listed in
 * reverse (cell (i, j)'s triangle below its diagonal, x > y in the cell, is
 * 2 (2 j + i), the one above it 2 (2 j + i) + 1, given as 7 minus that: the
 * index named is the one given, not the tree's), over a flat height field
 * at z = 0 of 3 x 4 points, 1 m cells, centred on (1.5, 1). */
static void test_level_parts_named(void **state)
{
    (void)state;
    double verts[9 * 3];
    int tris[8 * 3];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            double *v = &verts[3 * (j * 3 + i)];
            v[0] = i; v[1] = j; v[2] = 1;
        }
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int a = j * 3 + i, b = a + 1, c = a + 4, d = a + 3, k = 2 * (2 * j + i);
            int *below = &tris[3 * (7 - k)], *above = &tris[3 * (7 - (k + 1))];
            below[0] = a; below[1] = b; below[2] = c;
            above[0] = a; above[1] = c; above[2] = d;
        }
    carom_world *w = world_no_gravity();
    carom_quat q = {1, 0, 0, 0};
    carom_body_id mesh = scene_add_mesh(w, verts, 9, tris, 8, vec(0, 0, 0), q);
    carom_body_id field = scene_add_flat_field(w, 3, 4, 1.0, 0.0, vec(1.5, 1, 0));
    assert_false(carom_body_id_is_null(mesh) || carom_body_id_is_null(field));
    /* down at (1.3, 1.8): the mesh's cell (1, 1) above its diagonal, given
     * as 7 - 7 = 0; the field's cell column 1, row 1, upper half: 2 (1 * 3 + 1) + 1 */
    carom_ray_hit hits[2];
    int children[2] = {-7, -7};
    carom_vec3 from = {1.3, 1.8, 5}, down = {0, 0, -10};
    assert_int_equal(carom_world_ray_cast_all_children(w, from, down, NULL, hits, children, 2), 2);
    assert_true(carom_body_id_equal(hits[0].body, mesh) && carom_body_id_equal(hits[1].body, field));
    assert_int_equal(children[0], 0);
    assert_int_equal(children[1], 9);
    int child = -7;
    assert_int_equal(carom_world_ray_cast_child(w, from, down, &hits[0], &child), 1);
    assert_int_equal(child, 0);
    /* at (1.7, 0.2): the mesh's cell (1, 0) below its diagonal, 7 - 2 = 5;
     * the field's cell column 1, row 0, lower half: 2 */
    from = vec(1.7, 0.2, 5);
    assert_int_equal(carom_world_ray_cast_all_children(w, from, down, NULL, hits, children, 2), 2);
    assert_int_equal(children[0], 5);
    assert_int_equal(children[1], 2);
    /* a ball of radius 0.1 swept down at (1.3, 1.8) lands inside the same
     * triangle (0.35 from the diagonal, 0.2 from the cell's edges) */
    carom_shape_def ball = carom_shape_sphere(0.1);
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(1.3, 1.8, 5), q, down, NULL, &hits[0], &child), 1);
    assert_true(carom_body_id_equal(hits[0].body, mesh));
    assert_int_equal(child, 0);
    check_abs(hits[0].fraction, 3.9 / 10, 1e-9, "ball onto the mesh");
    /* beyond the mesh (x > 2) it lands on the field: column 2, row 0, lower half */
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(2.7, 0.2, 5), q, down, NULL, &hits[0], &child), 1);
    assert_true(carom_body_id_equal(hits[0].body, field));
    assert_int_equal(child, 2 * 2 + 0);
    /* a flat box over cell (1, 0) overlaps both its triangles (given as 5
     * and 4): the lower, 4; at z = 0 the field's cell column 1, row 0: 2 */
    carom_shape_def slab = carom_shape_box(0.4, 0.4, 0.05);
    carom_body_id ids[2];
    assert_int_equal(carom_world_overlap_children(w, &slab, vec(1.5, 0.5, 1), q, NULL, ids, children, 2), 1);
    assert_true(carom_body_id_equal(ids[0], mesh));
    assert_int_equal(children[0], 4);
    assert_int_equal(carom_world_overlap_children(w, &slab, vec(1.5, 0.5, 0), q, NULL, ids, children, 2), 1);
    assert_true(carom_body_id_equal(ids[0], field));
    assert_int_equal(children[0], 2);
    /* one over the whole mesh: its triangle 0 */
    carom_shape_def wide = carom_shape_box(0.9, 0.9, 0.05);
    assert_int_equal(carom_world_overlap_children(w, &wide, vec(1, 1, 1), q, NULL, ids, children, 2), 1);
    assert_int_equal(children[0], 0);
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_distance_against_sampling),
        cmocka_unit_test(test_overlap_against_sampling),
        cmocka_unit_test(test_plane_distance_and_overlap),
        cmocka_unit_test(test_overlapping_bodies_distance_is_penetration),
        cmocka_unit_test(test_shape_cast_against_sweep),
        cmocka_unit_test(test_shape_cast_initial_overlap_and_far),
        cmocka_unit_test(test_ray_inside_convention),
        cmocka_unit_test(test_ray_precision_far_away),
        cmocka_unit_test(test_ray_precision_hull),
        cmocka_unit_test(test_ray_cast_all_and_filters),
        cmocka_unit_test(test_bad_input_leaves_world_unchanged),
        cmocka_unit_test(test_queries_against_a_mesh),
        cmocka_unit_test(test_level_parts_named),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
