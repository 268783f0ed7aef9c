/* test_compound.c - compound bodies: mass properties against closed forms,
 * a dumbbell rolling down an incline as the analytic rigid body does, a table
 * of five boxes standing on a mesh floor, the child named in ray casts (closest
 * and all), shape casts, overlaps, events and a body's contacts, and bad
 * compounds refused with the world unchanged. */
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


static carom_body_id add_compound(carom_world *w, const carom_compound_child *c, int n, carom_body_type type,
                                  carom_vec3 at)
{
    carom_body_def bd = carom_body_def_default();
    bd.type = type;
    bd.shape.type = CAROM_SHAPE_COMPOUND;
    bd.children = c;
    bd.child_count = n;
    bd.position = at;
    return carom_body_create(w, &bd);
}

static void near_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want) + 1e-300)) printf("  %s: got %.17g, want %.17g\n", what, got, want);
    assert_true(fabs(got - want) <= rel * fabs(want) + 1e-300);
}

/* q rotating +z onto +x (a cylinder's axis along x) */
static carom_quat z_to_x(void)
{
    carom_quat q = {cos(PI_ / 4), 0, sin(PI_ / 4), 0};
    return q;
}

/* Two spheres of radius r at x = +-L on a rod (a cylinder of radius a,
 * half length h along x), all of density rho. */
static void dumbbell(carom_compound_child c[3], double r, double L, double a, double h, double rho, int axis_y)
{
    c[0] = carom_compound_child_default(carom_shape_sphere(r));
    c[1] = carom_compound_child_default(carom_shape_sphere(r));
    c[2] = carom_compound_child_default(carom_shape_cylinder(a, h));
    if (axis_y) {
        c[0].position.y = -L; c[1].position.y = L;
        carom_quat q = {cos(PI_ / 4), -sin(PI_ / 4), 0, 0}; /* z onto +y */
        c[2].orientation = q;
    } else {
        c[0].position.x = -L; c[1].position.x = L;
        c[2].orientation = z_to_x();
    }
    for (int i = 0; i < 3; i++) c[i].density = rho;
}

static void test_two_spheres_on_a_rod(void **state)
{
    (void)state;
    carom_world *w = world_default();
    const double r = 0.1, L = 0.5, a = 0.02, h = 0.4, rho = 7800;
    carom_compound_child c[3];
    dumbbell(c, r, L, a, h, rho, 0);
    carom_vec3 at = {1, 2, 3};
    carom_body_id id = add_compound(w, c, 3, CAROM_BODY_DYNAMIC, at);
    assert_false(carom_body_id_is_null(id));
    double ms = rho * 4.0 / 3.0 * PI_ * r * r * r, mr = rho * PI_ * a * a * 2 * h;
    double m = 2 * ms + mr;
    double ixx = 2 * 0.4 * ms * r * r + 0.5 * mr * a * a;
    double iyy = 2 * (0.4 * ms * r * r + ms * L * L) + mr * (3 * a * a + 4 * h * h) / 12.0;
    double got_m, I[9];
    carom_vec3 com;
    carom_body_get_mass(w, id, &got_m);
    carom_body_get_inertia(w, id, I);
    carom_body_get_local_center(w, id, &com);
    near_rel(got_m, m, 1e-12, "mass");
    near_rel(I[0], ixx, 1e-12, "Ixx");
    near_rel(I[4], iyy, 1e-12, "Iyy");
    near_rel(I[8], iyy, 1e-12, "Izz");
    for (int k = 0; k < 9; k++)
        if (k != 0 && k != 4 && k != 8) assert_true(fabs(I[k]) <= 1e-12 * iyy);
    assert_true(fabs(com.x) < 1e-15 && fabs(com.y) < 1e-15 && fabs(com.z) < 1e-15);
    /* a given total mass rescales the children */
    carom_body_def bd = carom_body_def_default();
    bd.shape.type = CAROM_SHAPE_COMPOUND;
    bd.children = c; bd.child_count = 3; bd.mass = 10;
    carom_body_id scaled = carom_body_create(w, &bd);
    carom_body_get_inertia(w, scaled, I);
    near_rel(I[0], ixx * 10 / m, 1e-12, "scaled Ixx");
    carom_world_destroy(w);
}

/* An L of two boxes: a 2 x 0.2 x 0.2 bar along x from the origin and a
 * 0.2 x 1 x 0.2 bar along y at its end, different densities: the centre and
 * the full tensor (with its product of inertia) from the parallel axis
 * theorem, computed here by hand. */
static void test_l_of_boxes(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_compound_child c[2];
    c[0] = carom_compound_child_default(carom_shape_box(1.0, 0.1, 0.1));
    c[0].position.x = 1.0;
    c[0].density = 1000;
    c[1] = carom_compound_child_default(carom_shape_box(0.1, 0.5, 0.1));
    c[1].position.x = 1.9; c[1].position.y = 0.6;
    c[1].density = 2500;
    carom_vec3 at = {0, 0, 5};
    carom_body_id id = add_compound(w, c, 2, CAROM_BODY_DYNAMIC, at);
    assert_false(carom_body_id_is_null(id));
    double m1 = 1000 * 2.0 * 0.2 * 0.2, m2 = 2500 * 0.2 * 1.0 * 0.2, m = m1 + m2;
    double cx = (m1 * 1.0 + m2 * 1.9) / m, cy = (m2 * 0.6) / m;
    /* each box about its own centre */
    double a1[3] = {m1 * (0.04 + 0.04) / 12, m1 * (4 + 0.04) / 12, m1 * (4 + 0.04) / 12};
    double a2[3] = {m2 * (1 + 0.04) / 12, m2 * (0.04 + 0.04) / 12, m2 * (0.04 + 1) / 12};
    double d1[3] = {1.0 - cx, 0 - cy, 0}, d2[3] = {1.9 - cx, 0.6 - cy, 0};
    double want[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double dd1 = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2], dd2 = d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2];
            double v = m1 * ((i == j) * dd1 - d1[i] * d1[j]) + m2 * ((i == j) * dd2 - d2[i] * d2[j]);
            if (i == j) v += a1[i] + a2[i];
            want[3 * i + j] = v;
        }
    double got_m, I[9];
    carom_vec3 com;
    carom_body_get_mass(w, id, &got_m);
    carom_body_get_inertia(w, id, I);
    carom_body_get_local_center(w, id, &com);
    near_rel(got_m, m, 1e-12, "mass");
    near_rel(com.x, cx, 1e-12, "centre x");
    near_rel(com.y, cy, 1e-12, "centre y");
    for (int k = 0; k < 9; k++) {
        char what[16];
        snprintf(what, sizeof what, "I[%d]", k);
        if (want[k] == 0) assert_true(fabs(I[k]) < 1e-12 * want[0]);
        else near_rel(I[k], want[k], 1e-12, what);
    }
    assert_true(fabs(want[1]) > 0.01 * want[0]); /* the product of inertia is really there */
    carom_world_destroy(w);
}

/* A dumbbell (two spheres on a thinner rod, axis along y) rolling from rest
 * down a plane inclined at theta about y: a = g sin / (1 + I_axis / (m r^2)),
 * at every preset, and at dt 1/30 and 1/15 (continuous collision bounded
 * the compound's turn by its whole reach, though rolling on its spheres
 * moves no surface: at dt 1/30 it stopped the dumbbell partway through each
 * fast step, 20 % short after 2 s). */
static void test_dumbbell_rolls_as_analytic(void **state)
{
    (void)state;
    const double r = 0.15, L = 0.4, a = 0.03, h = 0.3, rho = 1000;
    double thetas[2] = {0.15, 0.3};
    static const char *presets[3] = {"fast", "default", "accurate"};
    for (int k = 0; k < 8; k++) {
        double th = thetas[k % 2];
        const char *preset = presets[k < 6 ? k / 2 : 1];
        double dt = k < 6 ? 1.0 / 60.0 : k == 6 ? 1.0 / 30.0 : 1.0 / 15.0;
        if (k >= 6) th = 0.3;
        carom_world *w = world_preset(preset, 1);
        carom_body_def pd = carom_body_def_default();
        pd.type = CAROM_BODY_STATIC;
        pd.shape = carom_shape_plane(sin(th), 0, cos(th), 0); /* descends along +x */
        carom_body_create(w, &pd);
        carom_compound_child c[3];
        dumbbell(c, r, L, a, h, rho, 1);
        carom_vec3 at = {r * sin(th), 0, r * cos(th)};
        carom_body_id id = add_compound(w, c, 3, CAROM_BODY_DYNAMIC, at);
        assert_false(carom_body_id_is_null(id));
        carom_body_set_awake(w, id, 1);
        carom_vec3 p0, p1;
        carom_body_get_center_of_mass(w, id, &p0);
        const double T = 2.0;
        for (int i = 0; i < (int)lround(T / dt); i++) assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        carom_body_get_center_of_mass(w, id, &p1);
        double ms = rho * 4.0 / 3.0 * PI_ * r * r * r, mr = rho * PI_ * a * a * 2 * h, m = 2 * ms + mr;
        double iaxis = 2 * 0.4 * ms * r * r + 0.5 * mr * a * a;
        double acc = 9.81 * sin(th) / (1 + iaxis / (m * r * r));
        double s = (p1.x - p0.x) * cos(th) - (p1.z - p0.z) * sin(th);
        double want = 0.5 * acc * T * T;
        printf("  dumbbell on %.2f rad (%s, dt 1/%.0f): %.4f m down the slope (analytic %.4f), sideways %.2g m\n", th, preset,
               1 / dt, s, want, p1.y - p0.y);
        assert_true(fabs(s - want) <= 0.01 * want);
        assert_true(fabs(p1.y - p0.y) <= 1e-3 * want); /* the 0.1 % of the path */
        carom_world_destroy(w);
    }
}

/* A table (a top and four legs) on a flat mesh floor stays put for 10 s, at every preset. */
static void test_table_stands_on_mesh(void **state)
{
    (void)state;
    static const char *presets[3] = {"fast", "default", "accurate"};
    for (int k = 0; k < 3; k++) {
    carom_world *w = world_preset(presets[k], 1);
    double *v; int *t; int nv, nt;
    scene_grid(10, 1.0, 0.0, 5u, &v, &nv, &t, &nt);
    carom_vec3 o = {0, 0, 0};
    carom_quat I = {1, 0, 0, 0};
    assert_false(carom_body_id_is_null(scene_add_mesh(w, v, nv, t, nt, o, I)));
    free(v); free(t);
    carom_compound_child c[5];
    c[0] = carom_compound_child_default(carom_shape_box(0.6, 0.4, 0.03));
    c[0].position.z = 0.73;
    for (int i = 0; i < 4; i++) {
        c[1 + i] = carom_compound_child_default(carom_shape_box(0.03, 0.03, 0.35));
        c[1 + i].position.x = (i & 1) ? 0.55 : -0.55;
        c[1 + i].position.y = (i & 2) ? 0.35 : -0.35;
        c[1 + i].position.z = 0.35;
    }
    c[0].density = 600;
    carom_vec3 at = {0.3, -0.2, 0.0};
    carom_body_id id = add_compound(w, c, 5, CAROM_BODY_DYNAMIC, at);
    assert_false(carom_body_id_is_null(id));
    carom_vec3 p0, p;
    carom_body_get_position(w, id, &p0);
    double worst = 0;
    for (int i = 0; i < 600; i++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60.0), CAROM_OK);
        carom_body_get_position(w, id, &p);
        double d = sqrt((p.x - p0.x) * (p.x - p0.x) + (p.y - p0.y) * (p.y - p0.y) + (p.z - p0.z) * (p.z - p0.z));
        if (d > worst) worst = d;
    }
    printf("  table on a mesh (%s): largest move in 10 s %.3g m\n", presets[k], worst);
    assert_true(worst <= 1e-3);
    carom_world_destroy(w);
    }
}

static void test_child_in_ray_casts_and_events(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_body_def pd = carom_body_def_default();
    pd.type = CAROM_BODY_STATIC;
    pd.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &pd);
    carom_compound_child c[3];
    dumbbell(c, 0.1, 0.5, 0.02, 0.4, 1000, 0);
    carom_vec3 at = {0, 0, 1};
    carom_body_id id = add_compound(w, c, 3, CAROM_BODY_DYNAMIC, at);
    /* a ray down onto the +x sphere names child 1, onto the rod child 2 */
    carom_ray_hit hit;
    int child = -7;
    carom_vec3 from = {0.5, 0, 3}, down = {0, 0, -5};
    assert_int_equal(carom_world_ray_cast_child(w, from, down, &hit, &child), 1);
    assert_true(carom_body_id_equal(hit.body, id));
    assert_int_equal(child, 1);
    assert_true(fabs(hit.point.z - 1.1) < 1e-12);
    from.x = 0.2;
    assert_int_equal(carom_world_ray_cast_child(w, from, down, &hit, &child), 1);
    assert_int_equal(child, 2);
    /* tilted so the -x sphere lands first: its hit event names child 0 */
    carom_quat q = {cos(0.05), 0, -sin(0.05), 0};
    carom_body_set_orientation(w, id, q);
    int seen = 0;
    for (int i = 0; i < 60 && !seen; i++) {
        carom_world_step(w, 1.0 / 60.0);
        const carom_contact_event *ev;
        int n = carom_world_get_events(w, &ev);
        for (int k = 0; k < n; k++) {
            if (ev[k].type != CAROM_EVENT_HIT && ev[k].type != CAROM_EVENT_BEGIN) continue;
            int ca = -5, cb = -5;
            assert_int_equal(carom_world_get_event_children(w, k, &ca, &cb), CAROM_OK);
            int mine = carom_body_id_equal(ev[k].a, id) ? ca : cb, other = carom_body_id_equal(ev[k].a, id) ? cb : ca;
            assert_int_equal(mine, 0);
            assert_int_equal(other, -1);
            seen = 1;
        }
    }
    assert_true(seen);
    assert_int_equal(carom_world_get_event_children(w, 9999, NULL, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    carom_world_destroy(w);
}

/* Three spheres of radius 0.25 at x = -1, 0, +1 (children 0, 1, 2) of a
 * static compound at `at`. */
static carom_body_id add_three_spheres(carom_world *w, carom_vec3 at)
{
    carom_compound_child c[3];
    for (int i = 0; i < 3; i++) {
        c[i] = carom_compound_child_default(carom_shape_sphere(0.25));
        c[i].position.x = i - 1.0;
    }
    return add_compound(w, c, 3, CAROM_BODY_STATIC, at);
}

/* ray_cast_all_children: a ray along +y at x = 1 passes child 2 of A (at
 * the origin), child 0 of B (at x = 2, y = 5) and a plain sphere (y = 8):
 * each hit names its own child, in the order and with the hits of
 * carom_world_ray_cast_all. A ray from inside a child names that child. */
static void test_ray_cast_all_names_children(void **state)
{
    (void)state;
    carom_world *w = world_no_gravity();
    carom_body_id a = add_three_spheres(w, vec(0, 0, 0)), b = add_three_spheres(w, vec(2, 5, 0));
    carom_body_id plain = add_static(w, carom_shape_sphere(0.25), vec(1, 8, 0));
    carom_vec3 from = {1, -3, 0}, along = {0, 12, 0};
    carom_ray_hit hits[3], plain_hits[3];
    int children[3] = {-7, -7, -7};
    assert_int_equal(carom_world_ray_cast_all_children(w, from, along, NULL, hits, children, 3), 3);
    assert_int_equal(carom_world_ray_cast_all(w, from, along, NULL, plain_hits, 3), 3);
    const carom_body_id want_body[3] = {a, b, plain};
    const int want_child[3] = {2, 0, -1};
    const double want_y[3] = {-0.25, 4.75, 7.75};
    for (int i = 0; i < 3; i++) {
        assert_true(carom_body_id_equal(hits[i].body, want_body[i]));
        assert_int_equal(children[i], want_child[i]);
        assert_true(fabs(hits[i].point.y - want_y[i]) < 1e-12);
        assert_true(fabs(hits[i].fraction - (want_y[i] + 3) / 12) < 1e-12);
        assert_memory_equal(&hits[i], &plain_hits[i], sizeof hits[i]);
    }
    /* children may be NULL; a short array gets the nearest hits */
    assert_int_equal(carom_world_ray_cast_all_children(w, from, along, NULL, hits, NULL, 3), 3);
    children[1] = -7;
    assert_int_equal(carom_world_ray_cast_all_children(w, from, along, NULL, hits, children, 1), 3);
    assert_int_equal(children[0], 2);
    assert_int_equal(children[1], -7);
    /* a filter leaves A out: B's child 0 comes first */
    carom_body_set_filter(w, a, 2, CAROM_MASK_ALL, 0);
    carom_query_filter f = carom_query_filter_default();
    f.mask = 1;
    assert_int_equal(carom_world_ray_cast_all_children(w, from, along, &f, hits, children, 3), 2);
    assert_int_equal(children[0], 0);
    assert_int_equal(children[1], -1);
    /* starting inside A's child 0: fraction 0 on child 0, from every call
     * that names parts (ray_cast_child named none there, -1, before) */
    carom_vec3 inside = {-1, 0.1, 0}, up = {0, 0, 2};
    assert_int_equal(carom_world_ray_cast_all_children(w, inside, up, NULL, hits, children, 3), 1);
    assert_true(carom_body_id_equal(hits[0].body, a) && hits[0].fraction == 0.0);
    assert_int_equal(children[0], 0);
    int child = -7;
    assert_int_equal(carom_world_ray_cast_child(w, inside, up, hits, &child), 1);
    assert_true(carom_body_id_equal(hits[0].body, a) && hits[0].fraction == 0.0);
    assert_int_equal(child, 0);
    /* bad input as ray_cast_all */
    assert_int_equal(carom_world_ray_cast_all_children(NULL, from, along, NULL, hits, children, 3), -1);
    assert_int_equal(carom_world_ray_cast_all_children(w, from, along, NULL, hits, children, -1), -1);
    assert_non_null(strstr(carom_world_last_error(w), "ray_cast_all_children: bad output array"));
    assert_int_equal(carom_world_ray_cast_all_children(w, from, along, NULL, NULL, children, 3), -1);
    carom_vec3 bad = {NAN, 0, 0};
    assert_int_equal(carom_world_ray_cast_all_children(w, bad, along, NULL, hits, children, 3), -1);
    assert_non_null(strstr(carom_world_last_error(w), "origin and translation must be finite"));
    carom_world_destroy(w);
}

/* shape_cast_child: a sphere of radius 0.25 swept along +x at the spheres'
 * height first touches child 0 (centres 0.5 apart at x = -1.5: fraction
 * 1.5 / 6), swept along -x child 2; swept down at x = 0.6 it passes child 1
 * (0.6 > 0.5 off its centre) and lands on child 2 (0.4 off: the centres
 * 0.5 apart at 0.3 above it, fraction 2.7 / 6). */
static void test_shape_cast_names_child(void **state)
{
    (void)state;
    carom_world *w = world_no_gravity();
    carom_body_id a = add_three_spheres(w, vec(0, 0, 0));
    carom_shape_def ball = carom_shape_sphere(0.25);
    carom_quat q = {1, 0, 0, 0};
    carom_ray_hit hit, plain_hit;
    int child = -7;
    const struct { carom_vec3 from, along; int child; double fraction; } casts[3] = {
        {{-3, 0, 0}, {6, 0, 0}, 0, 1.5 / 6}, {{3, 0, 0}, {-6, 0, 0}, 2, 1.5 / 6}, {{0.6, 0, 3}, {0, 0, -6}, 2, 2.7 / 6}};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(carom_world_shape_cast_child(w, &ball, casts[k].from, q, casts[k].along, NULL, &hit, &child), 1);
        assert_true(carom_body_id_equal(hit.body, a));
        assert_int_equal(child, casts[k].child);
        check_abs(hit.fraction, casts[k].fraction, 1e-9, "shape cast fraction");
        assert_int_equal(carom_world_shape_cast(w, &ball, casts[k].from, q, casts[k].along, NULL, &plain_hit), 1);
        assert_memory_equal(&hit, &plain_hit, sizeof hit);
    }
    /* started overlapping child 1 only: fraction 0 on child 1 */
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(0.1, 0, 0.3), q, vec(0, 0, 1), NULL, &hit, &child), 1);
    assert_int_equal(child, 1);
    assert_true(hit.fraction == 0.0);
    /* a miss and a plain body: -1; child may be NULL */
    add_static(w, carom_shape_box(0.5, 0.5, 0.5), vec(0, 5, 0));
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(0, 5, 3), q, vec(0, 0, -6), NULL, &hit, &child), 1);
    assert_int_equal(child, -1);
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(0, 5, 3), q, vec(0, 0, -6), NULL, &hit, NULL), 1);
    child = -7;
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(0, -5, 3), q, vec(0, 0, -6), NULL, &hit, &child), 0);
    assert_int_equal(child, -1);
    /* bad input as shape_cast */
    assert_int_equal(carom_world_shape_cast_child(NULL, &ball, vec(0, 0, 3), q, vec(0, 0, -6), NULL, &hit, &child), -1);
    assert_int_equal(carom_world_shape_cast_child(w, &ball, vec(0, 0, 3), q, vec(0, 0, -6), NULL, NULL, &child), -1);
    assert_non_null(strstr(carom_world_last_error(w), "shape_cast_child: hit is NULL"));
    carom_shape_def plane = carom_shape_plane(0, 0, 1, 0);
    assert_int_equal(carom_world_shape_cast_child(w, &plane, vec(0, 0, 3), q, vec(0, 0, -6), NULL, &hit, &child), -1);
    assert_non_null(strstr(carom_world_last_error(w), "shape must be convex"));
    carom_world_destroy(w);
}

/* overlap_children: one entry per body, as carom_world_overlap; a box
 * covering only child 2 (x in [0.7, 1.3]) names 2, only child 0 names 0,
 * one over children 1 and 2 (x in [0.2, 0.8]) names the lower, 1. */
static void test_overlap_names_lowest_child(void **state)
{
    (void)state;
    carom_world *w = world_no_gravity();
    carom_body_id a = add_three_spheres(w, vec(0, 0, 0)), b = add_three_spheres(w, vec(0, 3, 0));
    carom_body_id plain = add_static(w, carom_shape_sphere(0.25), vec(0.5, -1, 0));
    carom_shape_def box = carom_shape_box(0.3, 0.3, 0.3);
    carom_quat q = {1, 0, 0, 0};
    carom_body_id ids[4], plain_ids[4];
    int children[4];
    const struct { double x; int child; } cases[3] = {{1, 2}, {-1, 0}, {0.5, 1}};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(carom_world_overlap_children(w, &box, vec(cases[k].x, 0, 0), q, NULL, ids, children, 4), 1);
        assert_true(carom_body_id_equal(ids[0], a));
        assert_int_equal(children[0], cases[k].child);
    }
    /* tall box over A, B and the plain sphere: three entries, in
     * carom_world_overlap's order */
    carom_shape_def tall = carom_shape_box(0.3, 3.5, 0.3);
    int n = carom_world_overlap_children(w, &tall, vec(0.5, 0, 0), q, NULL, ids, children, 4);
    assert_int_equal(n, 3);
    assert_int_equal(carom_world_overlap(w, &tall, vec(0.5, 0, 0), q, NULL, plain_ids, 4), 3);
    for (int i = 0; i < 3; i++) {
        assert_true(carom_body_id_equal(ids[i], plain_ids[i]));
        int want = carom_body_id_equal(ids[i], plain) ? -1 : 1;
        assert_true(carom_body_id_equal(ids[i], a) || carom_body_id_equal(ids[i], b) || want == -1);
        assert_int_equal(children[i], want);
    }
    /* children may be NULL; none overlapping: 0 */
    assert_int_equal(carom_world_overlap_children(w, &tall, vec(0.5, 0, 0), q, NULL, ids, NULL, 4), 3);
    assert_int_equal(carom_world_overlap_children(w, &box, vec(0, 0, 5), q, NULL, ids, children, 4), 0);
    /* bad input as overlap */
    assert_int_equal(carom_world_overlap_children(NULL, &box, vec(0, 0, 0), q, NULL, ids, children, 4), -1);
    assert_int_equal(carom_world_overlap_children(w, &box, vec(0, 0, 0), q, NULL, NULL, children, 4), -1);
    assert_non_null(strstr(carom_world_last_error(w), "overlap_children: bad output array"));
    assert_int_equal(carom_world_overlap_children(w, &box, vec(0, 0, 0), q, NULL, ids, children, -1), -1);
    carom_quat bad = {2, 0, 0, 0};
    assert_int_equal(carom_world_overlap_children(w, &box, vec(0, 0, 0), bad, NULL, ids, children, 4), -1);
    assert_non_null(strstr(carom_world_last_error(w), "orientation must be a finite unit quaternion"));
    carom_world_destroy(w);
}

/* A static 4 x 4 grid of 1 m cells centred on the origin at z = 0 (32
 * triangles: *triangle_count). */
static carom_body_id add_grid_floor(carom_world *w, int *triangle_count)
{
    double *v;
    int nv, *t;
    scene_grid(4, 1.0, 0.0, 0, &v, &nv, &t, triangle_count);
    carom_quat q = {1, 0, 0, 0};
    carom_body_id floor = scene_add_mesh(w, v, nv, t, *triangle_count, vec(0, 0, 0), q);
    free(v);
    free(t);
    return floor;
}

/* carom_body_get_contact_children: a compound (child 0 a ball on top,
 * child 1 a slab under it, child 2 a ball off the slab's edge, clear of
 * the floor)
 * resting on a flat mesh touches it with child 1 only; a static compound
 * (child 0 a ball off to the side, child 1 a plate) laid on child 0's top
 * touches it with its child 1. Each contact's children follow the order
 * and count of carom_body_get_contacts, from either body's side. */
static void test_contact_children(void **state)
{
    (void)state;
    carom_world *w = world_default();
    int nt;
    carom_body_id floor = add_grid_floor(w, &nt);
    carom_compound_child c[3];
    c[0] = carom_compound_child_default(carom_shape_sphere(0.2));
    c[0].position.z = 0.3;
    c[1] = carom_compound_child_default(carom_shape_box(0.5, 0.5, 0.1));
    c[2] = carom_compound_child_default(carom_shape_sphere(0.1));
    c[2].position.x = 0.7;
    c[2].position.z = 0.25;
    carom_body_id a = add_compound(w, c, 3, CAROM_BODY_DYNAMIC, vec(0.1, 0.2, 0.1));
    assert_false(carom_body_id_is_null(floor) || carom_body_id_is_null(a));
    step_n(w, 60, DT);
    int self[8], other[8];
    carom_contact_info info[8];
    int n = carom_body_get_contacts(w, a, info, 8);
    assert_true(n >= 1 && n <= 8);
    assert_int_equal(carom_body_get_contact_children(w, a, self, other, 8), n);
    for (int i = 0; i < n; i++) {
        assert_true(carom_body_id_equal(info[i].other, floor));
        assert_int_equal(self[i], 1);
        assert_true(other[i] >= 0 && other[i] < nt); /* a triangle: which, test_contact_names_triangle */
    }
    /* the plate's underside on the top ball (its top at 0.1 + 0.3 + 0.2 up, less what it sank) */
    carom_vec3 at = pos(w, a);
    c[0] = carom_compound_child_default(carom_shape_sphere(0.1));
    c[0].position.x = 3;
    c[1] = carom_compound_child_default(carom_shape_box(0.3, 0.3, 0.05));
    carom_body_id lid = add_compound(w, c, 2, CAROM_BODY_STATIC, vec(at.x, at.y, at.z + 0.5 + 0.05 - 1e-3));
    carom_body_set_awake(w, a, 1); /* it may sleep: a static body wakes nothing */
    step_n(w, 10, DT);
    n = carom_body_get_contacts(w, a, info, 8);
    assert_int_equal(carom_body_get_contact_children(w, a, self, other, 8), n);
    int with_lid = 0, with_floor = 0;
    for (int i = 0; i < n; i++) {
        int on_lid = carom_body_id_equal(info[i].other, lid);
        with_lid += on_lid;
        with_floor += carom_body_id_equal(info[i].other, floor);
        assert_int_equal(self[i], on_lid ? 0 : 1);
        if (on_lid) assert_int_equal(other[i], 1);
        else assert_true(other[i] >= 0 && other[i] < nt);
    }
    assert_int_equal(with_lid, 1);
    assert_true(with_floor >= 1 && with_lid + with_floor == n);
    /* from the lid's side: its child 1 on a's child 0; one array may be NULL */
    assert_int_equal(carom_body_get_contact_children(w, lid, self, other, 8), 1);
    assert_int_equal(self[0], 1);
    assert_int_equal(other[0], 0);
    other[0] = -7;
    assert_int_equal(carom_body_get_contact_children(w, lid, NULL, other, 8), 1);
    assert_int_equal(other[0], 0);
    self[0] = -7;
    assert_int_equal(carom_body_get_contact_children(w, lid, self, NULL, 1), 1);
    assert_int_equal(self[0], 1);
    assert_int_equal(carom_body_get_contact_children(w, lid, NULL, NULL, 0), 1);
    /* bad input as body_get_contacts */
    assert_int_equal(carom_body_get_contact_children(NULL, a, self, other, 8), -1);
    assert_int_equal(carom_body_get_contact_children(w, a, self, other, -1), -1);
    assert_non_null(strstr(carom_world_last_error(w), "body_get_contact_children: bad output array"));
    assert_int_equal(carom_body_get_contact_children(w, a, self, other, 8), n);
    assert_int_equal(carom_body_get_contact_children(w, a, NULL, NULL, 8), -1);
    assert_non_null(strstr(carom_world_last_error(w), "body_get_contact_children: bad output array"));
    carom_body_destroy(w, lid);
    assert_int_equal(carom_body_get_contact_children(w, lid, self, other, 8), -1);
    assert_non_null(strstr(carom_world_last_error(w), "body_get_contact_children: body has been destroyed"));
    carom_world_destroy(w);
}

/* A dumbbell (children 0 and 1, balls of radius 0.1 at x = -0.5 and 0.5 of
 * (0.3, 0.2)) resting on a 4 x 4 grid of 1 m cells centred on the origin,
 * cell (i, j) at x in [i - 2, i - 1], y in [j - 2, j - 1], its triangles
 * 2 (4 j + i) below the diagonal (x > y in the cell), + 1 above: ball 0
 * at (-0.2, 0.2) is over cell (1, 2) 0.8, 0.2 in, triangle 18; ball 1 at
 * (0.8, 0.2) over cell (2, 2), triangle 20. A ball on a 5 x 5 height field
 * centred on (10, 0) at (10.3, -0.6): column 2, row 1 (0.3, 0.4 in: above
 * the diagonal), 2 (4 * 1 + 2) + 1 = 13. Events still name no triangle. */
static void test_contact_names_triangle(void **state)
{
    (void)state;
    carom_world *w = world_default();
    int nt;
    carom_body_id floor = add_grid_floor(w, &nt);
    carom_body_id field = scene_add_flat_field(w, 5, 5, 1.0, 0.0, vec(10, 0, 0));
    carom_compound_child c[2];
    for (int i = 0; i < 2; i++) {
        c[i] = carom_compound_child_default(carom_shape_sphere(0.1));
        c[i].position.x = i - 0.5;
    }
    carom_body_id bell = add_compound(w, c, 2, CAROM_BODY_DYNAMIC, vec(0.3, 0.2, 0.1));
    carom_body_id ball = add_sphere(w, 10.3, -0.6, 0.25, 0.25);
    assert_false(carom_body_id_is_null(floor) || carom_body_id_is_null(field) || carom_body_id_is_null(bell));
    int named_in_events = 0;
    for (int k = 0; k < 30; k++) {
        carom_world_step(w, DT);
        const carom_contact_event *ev;
        int n = carom_world_get_events(w, &ev);
        for (int e = 0; e < n; e++) {
            int ca, cb;
            carom_world_get_event_children(w, e, &ca, &cb);
            named_in_events += carom_body_id_equal(ev[e].a, floor) ? ca >= 0 : carom_body_id_equal(ev[e].b, floor) ? cb >= 0 : 0;
        }
    }
    assert_int_equal(named_in_events, 0);
    int self[4], other[4];
    assert_int_equal(carom_body_get_contact_children(w, bell, self, other, 4), 2);
    for (int i = 0; i < 2; i++) assert_int_equal(other[i], self[i] == 0 ? 18 : 20);
    assert_true(self[0] != self[1]);
    /* from the mesh's side the same pairs, turned round */
    assert_int_equal(carom_body_get_contact_children(w, floor, self, other, 4), 2);
    for (int i = 0; i < 2; i++) assert_int_equal(self[i], other[i] == 0 ? 18 : 20);
    assert_int_equal(carom_body_get_contact_children(w, ball, self, other, 4), 1);
    assert_int_equal(self[0], -1);
    assert_int_equal(other[0], 13);
    carom_world_destroy(w);
}

static void expect_refused(carom_world *w, const carom_compound_child *c, int n, const char *words)
{
    int before = carom_world_body_count(w);
    carom_vec3 at = {0, 0, 0};
    assert_true(carom_body_id_is_null(add_compound(w, c, n, CAROM_BODY_DYNAMIC, at)));
    assert_int_equal(carom_world_body_count(w), before);
    if (!strstr(carom_world_last_error(w), words)) printf("  message: %s (wanted %s)\n", carom_world_last_error(w), words);
    assert_non_null(strstr(carom_world_last_error(w), words));
}

/* Each child's own friction (issue #18): a wide flat box with a small box
 * on top of it, one body, sliding down a 30 deg slope (gravity tilted;
 * ground friction 1, mixed sqrt(a b)) on the flat child alone. It slides at
 * a = g (sin(theta) - mu cos(theta)) with mu the flat child's: 0.1 (4.055
 * m/s^2) with the top child at 0.3, and 0.3 (2.356) the other way round
 * (one friction for both children would fail one of the two; the body's
 * default 0.6 would hold it). Every preset, dt 1/60 and 1/240. (Both
 * children on the ground would not do: how a rigid body's load divides
 * between two faces is not fixed by its balance, the solver's springs
 * decide it.) */
static void test_children_keep_their_friction(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    const double theta = 30.0 * 3.141592653589793 / 180.0, g = 9.81;
    for (int p = 0; p < 3; p++)
        for (int rev = 0; rev < 2; rev++)
            for (int k = 0; k < 2; k++) {
                double dt = k ? 1.0 / 240 : 1.0 / 60;
                carom_world_def wd = preset_def(presets[p]);
                wd.gravity.x = g * sin(theta);
                wd.gravity.z = -g * cos(theta);
                wd.enable_sleep = 0;
                carom_world *w = world_with(wd, 1, 1.0, 0.0);
                double mu[2] = {rev ? 0.3 : 0.1, rev ? 0.1 : 0.3}; /* [0] the flat child on the ground */
                carom_compound_child c[2] = {carom_compound_child_default(carom_shape_box(0.5, 0.5, 0.1)),
                                             carom_compound_child_default(carom_shape_box(0.1, 0.1, 0.1))};
                c[1].position = vec(0, 0, 0.2);
                for (int i = 0; i < 2; i++) c[i].friction = mu[i] * mu[i]; /* sqrt(1 * mu^2) = mu against the ground */
                carom_body_id b = add_compound(w, c, 2, CAROM_BODY_DYNAMIC, vec(0, 0, 0.1));
                assert_false(carom_body_id_is_null(b));
                double want = g * (sin(theta) - mu[0] * cos(theta));
                /* past the first contact's settling, the speed gained over 1 s */
                int steps = (int)(0.25 / dt + 0.5), more = (int)(1.0 / dt + 0.5);
                for (int s = 0; s < steps; s++) assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                carom_vec3 v0, v1;
                carom_body_get_linear_velocity(w, b, &v0);
                for (int s = 0; s < more; s++) assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                carom_body_get_linear_velocity(w, b, &v1);
                double got = (v1.x - v0.x) / (more * dt);
                print_message("%s dt 1/%.0f mu %.1f on the ground, %.1f above: a %.5f m/s^2 (want %.5f)\n", presets[p],
                              1 / dt, mu[0], mu[1], got, want);
                near_rel(got, want, 1e-3, "sliding acceleration");
                carom_world_destroy(w);
            }
}

/* Each child's own restitution: a dumbbell held upright (its axis vertical)
 * drops 1 m onto a plane of restitution 0 (mixed max(a, b)): only the lower
 * child touches, under the centre of mass, so the body leaves at e times its
 * impact speed, e the lower child's, with no spin. Upright both ways, every
 * preset. */
static void test_children_keep_their_restitution(void **state)
{
    (void)state;
    const char *presets[] = {"fast", "default", "accurate"};
    const double e[2] = {0.3, 0.8};
    for (int p = 0; p < 3; p++)
        for (int low = 0; low < 2; low++) {
            carom_world_def wd = preset_def(presets[p]);
            carom_world *w = world_with(wd, 1, 0.6, 0.0);
            carom_compound_child c[2];
            for (int i = 0; i < 2; i++) {
                c[i] = carom_compound_child_default(carom_shape_sphere(0.1));
                c[i].position = vec(0, 0, i == low ? -0.4 : 0.4);
                c[i].restitution = e[i];
            }
            carom_body_id b = add_compound(w, c, 2, CAROM_BODY_DYNAMIC, vec(0, 0, 1.5));
            assert_false(carom_body_id_is_null(b));
            /* the fastest fall and the fastest rise after it */
            double down = 0, up = 0;
            for (int s = 0; s < 120; s++) {
                assert_int_equal(carom_world_step(w, 1.0 / 240), CAROM_OK);
                carom_vec3 v;
                carom_body_get_linear_velocity(w, b, &v);
                if (up == 0 && -v.z > down) down = -v.z;
                if (v.z > up) up = v.z;
            }
            carom_vec3 spin;
            carom_body_get_angular_velocity(w, b, &spin);
            print_message("%s, child %d (e %.1f) below: down %.4f m/s, up %.4f m/s, ratio %.4f\n", presets[p], low, e[low],
                          down, up, up / down);
            near_rel(up / down, e[low], 0.02, "bounce ratio");
            assert_true(fabs(spin.x) + fabs(spin.y) < 1e-9);
            carom_world_destroy(w);
        }
}

/* Events of plain pairs name no child, before and after a compound's in the
 * same step (the children are kept only up to the last event naming one). */
static void test_plain_events_beside_compound_name_none(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_body_def pd = carom_body_def_default();
    pd.type = CAROM_BODY_STATIC;
    pd.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &pd);
    carom_compound_child c[3];
    dumbbell(c, 0.1, 0.5, 0.02, 0.4, 1000, 0);
    carom_body_id boxes[8];
    carom_body_id compound = {0};
    /* boxes beside the dumbbell on the plane, the last one on top of the one before it: pairs
     * come in rank order (docs/physics.md 1.1), the plane's pairs first, then the stacked boxes' */
    for (int k = 0; k < 9; k++) {
        carom_vec3 at = {3.0 * (k - 4), 0, k == 4 ? 0.1 : 0.5};
        if (k == 8) { at.x = 3.0 * 3; at.z = 1.5; }
        if (k == 4) { compound = add_compound(w, c, 3, CAROM_BODY_DYNAMIC, at); continue; }
        carom_body_def bd = carom_body_def_default();
        bd.shape = carom_shape_box(0.5, 0.5, 0.5);
        bd.position = at;
        boxes[k < 4 ? k : k - 1] = carom_body_create(w, &bd);
    }
    carom_world_step(w, 1.0 / 60.0);
    const carom_contact_event *ev;
    int n = carom_world_get_events(w, &ev), first_compound = -1, last_compound = -1, plain = 0, plain_after = 0;
    for (int k = 0; k < n; k++) {
        if (ev[k].type != CAROM_EVENT_BEGIN) continue;
        int ca = -5, cb = -5;
        assert_int_equal(carom_world_get_event_children(w, k, &ca, &cb), CAROM_OK);
        if (carom_body_id_equal(ev[k].a, compound) || carom_body_id_equal(ev[k].b, compound)) {
            int mine = carom_body_id_equal(ev[k].a, compound) ? ca : cb, other = carom_body_id_equal(ev[k].a, compound) ? cb : ca;
            assert_true(mine >= 0 && mine <= 1); /* a sphere touches the plane */
            assert_int_equal(other, -1);
            if (first_compound < 0) first_compound = k;
            last_compound = k;
        } else {
            assert_int_equal(ca, -1);
            assert_int_equal(cb, -1);
            plain++;
            plain_after += last_compound >= 0;
        }
    }
    assert_true(first_compound >= 0);
    assert_int_equal(plain, 8); /* 7 boxes on the plane, 1 on a box */
    assert_true(plain_after > 0 && plain_after < plain); /* plain events on both sides of the compound's */
    (void)boxes;
    carom_world_destroy(w);
}

static void test_bad_compounds_refused(void **state)
{
    (void)state;
    carom_world *w = world_default();
    carom_compound_child c[2];
    c[0] = carom_compound_child_default(carom_shape_sphere(0.5));
    c[1] = carom_compound_child_default(carom_shape_box(0.5, 0.5, 0.5));
    expect_refused(w, c, 0, "needs children");
    expect_refused(w, NULL, 2, "needs children");
    c[1].shape = carom_shape_plane(0, 0, 1, 0);
    expect_refused(w, c, 2, "children[1].shape must be convex");
    c[1].shape.type = CAROM_SHAPE_MESH;
    expect_refused(w, c, 2, "children[1].shape must be convex");
    c[1].shape = carom_shape_sphere(-1);
    expect_refused(w, c, 2, "children[1]: sphere radius");
    c[1].shape = carom_shape_box(0.5, 0.5, 0.5);
    c[1].position.y = NAN;
    expect_refused(w, c, 2, "children[1].position");
    c[1].position.y = 0;
    c[1].orientation.w = 2;
    expect_refused(w, c, 2, "children[1].orientation");
    c[1].orientation.w = 1;
    c[0].density = 0;
    expect_refused(w, c, 2, "children[0].density");
    c[0].density = 1000;
    c[0].friction = -1;
    expect_refused(w, c, 2, "children[0].friction");
    c[0].friction = 0.5;
    double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    c[0].shape = carom_shape_hull(flat, 4);
    expect_refused(w, c, 2, "children[0]: bad hull");
    c[0].shape = carom_shape_sphere(0.5);
    carom_vec3 at = {0, 0, 0};
    assert_false(carom_body_id_is_null(add_compound(w, c, 2, CAROM_BODY_DYNAMIC, at)));
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_spheres_on_a_rod),
        cmocka_unit_test(test_l_of_boxes),
        cmocka_unit_test(test_dumbbell_rolls_as_analytic),
        cmocka_unit_test(test_table_stands_on_mesh),
        cmocka_unit_test(test_child_in_ray_casts_and_events),
        cmocka_unit_test(test_ray_cast_all_names_children),
        cmocka_unit_test(test_shape_cast_names_child),
        cmocka_unit_test(test_overlap_names_lowest_child),
        cmocka_unit_test(test_contact_children),
        cmocka_unit_test(test_contact_names_triangle),
        cmocka_unit_test(test_children_keep_their_friction),
        cmocka_unit_test(test_children_keep_their_restitution),
        cmocka_unit_test(test_plain_events_beside_compound_name_none),
        cmocka_unit_test(test_bad_compounds_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
