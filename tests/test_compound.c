/* test_compound.c - compound bodies: mass properties against closed forms,
 * a dumbbell rolling down an incline as the analytic rigid body does, a table
 * of five boxes standing on a mesh floor, the child named in ray casts and
 * events, and bad compounds refused with the world unchanged. */
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

static void expect_refused(carom_world *w, const carom_compound_child *c, int n, const char *words)
{
    int before = carom_world_body_count(w);
    carom_vec3 at = {0, 0, 0};
    assert_true(carom_body_id_is_null(add_compound(w, c, n, CAROM_BODY_DYNAMIC, at)));
    assert_int_equal(carom_world_body_count(w), before);
    if (!strstr(carom_world_last_error(w), words)) printf("  message: %s (wanted %s)\n", carom_world_last_error(w), words);
    assert_non_null(strstr(carom_world_last_error(w), words));
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
        cmocka_unit_test(test_plain_events_beside_compound_name_none),
        cmocka_unit_test(test_bad_compounds_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
