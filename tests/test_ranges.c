/* test_ranges.c - the ranges a world supports (docs/ranges.md): each edge
 * walked from both sides. Just inside, a scene using the value runs 600
 * steps at every preset with the state, the events and the probes finite;
 * just outside, the call that introduces the value is refused with the
 * documented range in its message and the world left as it was. Also the
 * fuzzers' findings 1-5 of issue 17, each as it was reported. And the
 * numerical stability at the edges of the envelope (fast versions;
 * bench/extremes runs the long ones). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <float.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "helpers.h"

static const char *const presets[] = {"fast", "default", "accurate"};

static int finite3(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* Everything a caller can read about a world, folded into one number: a
 * refused call must leave it bit for bit as it was. */
static double fingerprint(const carom_world *w)
{
    double h = carom_world_body_count(w);
    carom_body_id ids[64];
    int n = carom_world_query_aabb(w, vec(-2e12, -2e12, -2e12), vec(2e12, 2e12, 2e12), ids, 64);
    for (int i = 0; i < n && i < 64; i++) {
        carom_vec3 p, v, av;
        carom_quat q;
        double m, f;
        carom_body_get_position(w, ids[i], &p);
        carom_body_get_linear_velocity(w, ids[i], &v);
        carom_body_get_angular_velocity(w, ids[i], &av);
        carom_body_get_orientation(w, ids[i], &q);
        carom_body_get_mass(w, ids[i], &m);
        carom_body_get_friction(w, ids[i], &f);
        h = h * 1.000001 + p.x + 2 * p.y + 3 * p.z + 5 * v.x + 7 * v.y + 11 * v.z + 13 * av.x + 17 * av.y + 19 * av.z +
            23 * q.w + 29 * q.x + m + f;
    }
    carom_world_def d = carom_world_def_default();
    carom_world_get_def(w, &d);
    return h + d.gravity.z + d.contact_hertz + d.max_linear_speed;
}

static void assert_refused(carom_world *w, carom_status st, double before, const char *range)
{
    assert_int_not_equal(st, CAROM_OK);
    const char *msg = carom_world_last_error(w);
    if (!strstr(msg, range)) fail_msg("error \"%s\" does not name the range \"%s\"", msg, range);
    assert_true(fingerprint(w) == before);
}

/* Steps a world n times: every step OK, nothing non-finite in state, events or probes. */
static void run_finite(carom_world *w, int n, double dt)
{
    for (int i = 0; i < n; i++) {
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        const carom_contact_event *ev;
        int ne = carom_world_get_events(w, &ev);
        for (int k = 0; k < ne; k++) {
            assert_true(finite3(ev[k].point) && finite3(ev[k].normal));
            assert_true(isfinite(ev[k].normal_impulse) && isfinite(ev[k].tangent_impulse));
            assert_true(isfinite(ev[k].approach_speed) && isfinite(ev[k].average_force));
        }
    }
    carom_world_stats st = carom_world_stats_init();
    assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
    assert_int_equal(st.non_finite, 0);
    assert_true(isfinite(st.max_penetration));
    double ke, pe;
    carom_vec3 p, l;
    assert_int_equal(carom_world_get_energy(w, &ke, &pe), CAROM_OK);
    assert_int_equal(carom_world_get_momentum(w, &p, &l), CAROM_OK);
    assert_true(isfinite(ke) && isfinite(pe) && finite3(p) && finite3(l));
    assert_true(isfinite(carom_world_measure_max_penetration(w)));
    carom_ray_hit hit;
    assert_true(carom_world_ray_cast(w, vec(0.3, 0.2, 1e7), vec(0, 0, -2e7), &hit) >= 0);
}

/* ---- one edge: a value of one quantity, applied to a scene ------------------ */

typedef struct edge {
    const char *name;
    double inside;              /* just inside the range */
    int out;                    /* +1: the next double above it is outside, -1: the one below */
    const char *range;          /* the range as the error message states it */
    /* puts the value into a world def (returns 0 if this edge is not a world setting) */
    int (*world)(carom_world_def *d, double v);
    /* puts the value into the body def of the scene's test body */
    int (*body)(carom_body_def *d, double v);
    /* applies the value with a setter on the test body (0: not a setter edge) */
    carom_status (*setter)(carom_world *w, carom_body_id id, double v);
    double dt;                  /* the scene's step; 0 = the value is the step */
} edge;

/* The scene: a ground plane, a resting box, the test body dropped on it. */
static carom_world *edge_world(const edge *e, const char *preset, double v, int use_value, carom_body_id *test_body)
{
    carom_world_def wd = carom_world_def_default();
    assert_int_equal(carom_world_def_apply_preset(&wd, preset), CAROM_OK);
    if (use_value && e->world) e->world(&wd, v);
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    assert_false(carom_body_id_is_null(carom_body_create(w, &g)));
    carom_body_def b = carom_body_def_default();
    b.shape = carom_shape_box(0.5, 0.5, 0.5);
    b.position = vec(0, 0, 0.5);
    b.mass = 1;
    assert_false(carom_body_id_is_null(carom_body_create(w, &b)));
    carom_body_def t = carom_body_def_default();
    t.shape = carom_shape_sphere(0.25);
    t.position = vec(0.3, 0.2, 1.3);
    t.mass = 2;
    t.restitution = 0.5;
    if (use_value && e->body) e->body(&t, v);
    *test_body = carom_body_create(w, &t);
    if (!use_value || !e->setter) assert_false(carom_body_id_is_null(*test_body));
    return w;
}

static void walk_edge(const edge *e)
{
    double outside = nextafter(e->inside, e->out > 0 ? INFINITY : 0.0);
    for (int p = 0; p < 3; p++) {
        /* just inside: 600 steps, everything finite */
        carom_body_id id;
        carom_world *w = edge_world(e, presets[p], e->inside, 1, &id);
        if (e->setter) assert_int_equal(e->setter(w, id, e->inside), CAROM_OK);
        run_finite(w, 600, e->dt > 0 ? e->dt : e->inside);
        carom_world_destroy(w);
    }
    /* just outside: refused where it is introduced, the world unchanged */
    carom_body_id id;
    if (e->world) {
        carom_world_def wd = carom_world_def_default();
        e->world(&wd, outside);
        char msg[256];
        assert_int_equal(carom_world_def_check(&wd, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
        if (!strstr(msg, e->range)) fail_msg("%s: \"%s\" does not name \"%s\"", e->name, msg, e->range);
        assert_null(carom_world_create(&wd));
        carom_world *w = edge_world(e, "default", 0, 0, &id);
        double before = fingerprint(w);
        assert_refused(w, carom_world_set_def(w, &wd), before, e->range);
        carom_world_destroy(w);
    }
    if (e->body) {
        carom_world *w = edge_world(e, "default", 0, 0, &id);
        carom_body_def t = carom_body_def_default();
        t.mass = 2;
        t.position = vec(3, 0, 1);
        e->body(&t, outside);
        double before = fingerprint(w);
        carom_body_id bad = carom_body_create(w, &t);
        assert_true(carom_body_id_is_null(bad));
        assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, e->range);
        carom_world_destroy(w);
    }
    if (e->setter) {
        carom_world *w = edge_world(e, "default", 0, 0, &id);
        double before = fingerprint(w);
        assert_refused(w, e->setter(w, id, outside), before, e->range);
        carom_world_destroy(w);
    }
    if (!e->world && !e->body && !e->setter) { /* the time step */
        carom_world *w = edge_world(e, "default", 0, 0, &id);
        double before = fingerprint(w);
        assert_refused(w, carom_world_step(w, outside), before, e->range);
        carom_world_destroy(w);
    }
}


static int b_radius(carom_body_def *d, double v) { d->shape = carom_shape_sphere(v); return 1; }
static int b_box(carom_body_def *d, double v) { d->shape = carom_shape_box(v, 0.2, 0.2); return 1; }
/* a long body's cross-section keeps its inertia anisotropy (trace^3/det) within
 * 1e12: a 1e6 m beam 0.2 m thick would be 1.3e14 (see test_anisotropy_edge) */
static int b_box_long(carom_body_def *d, double v) { d->shape = carom_shape_box(v, 10, 10); return 1; }
static int b_capsule_r(carom_body_def *d, double v) { d->shape = carom_shape_capsule(v, 0.2); return 1; }
static int b_capsule_h(carom_body_def *d, double v) { d->shape = carom_shape_capsule(10, v); return 1; }
static int b_cylinder_r(carom_body_def *d, double v) { d->shape = carom_shape_cylinder(v, 0.2); return 1; }
static int b_cylinder_h(carom_body_def *d, double v) { d->shape = carom_shape_cylinder(0.2, v); return 1; }
static int b_mass(carom_body_def *d, double v) { d->mass = v; return 1; }
/* extreme masses on an extreme size: the inertia range's corners */
static int b_heavy_tiny(carom_body_def *d, double v) { d->mass = v; d->shape = carom_shape_sphere(1e-6); return 1; }
static int b_light_huge(carom_body_def *d, double v) { d->mass = v; d->shape = carom_shape_box(1e6, 1e6, 1e6); return 1; }
static int b_density(carom_body_def *d, double v) { d->mass = 0; d->density = v; d->shape = carom_shape_sphere(v < 1 ? 1 : 0.01); return 1; }
static int b_x(carom_body_def *d, double v) { d->position.x = v; return 1; }
static int b_friction(carom_body_def *d, double v) { d->friction = v; return 1; }
static int b_damping(carom_body_def *d, double v) { d->linear_damping = v; d->angular_damping = v; return 1; }
static int b_gravity_scale(carom_body_def *d, double v) { d->gravity_scale = v; return 1; }
static int b_speed(carom_body_def *d, double v) { d->linear_velocity = vec(0, 0, -v); return 1; }
static int b_spin(carom_body_def *d, double v) { d->angular_velocity = vec(v, 0, 0); return 1; }
static int w_gravity(carom_world_def *d, double v) { d->gravity = vec(0, 0, -v); return 1; }
static int w_hertz(carom_world_def *d, double v) { d->contact_hertz = v; return 1; }
static int w_max_speed(carom_world_def *d, double v) { d->max_linear_speed = v; return 1; }
static int w_max_spin(carom_world_def *d, double v) { d->max_angular_speed = v; return 1; }
static carom_status s_set_mass(carom_world *w, carom_body_id id, double v) { return carom_body_set_mass(w, id, v); }
static carom_status s_speed(carom_world *w, carom_body_id id, double v)
{
    return carom_body_set_linear_velocity(w, id, vec(v, 0, 0));
}
static carom_status s_force(carom_world *w, carom_body_id id, double v)
{
    return carom_body_apply_force(w, id, vec(0, 0, -2.0 * v)); /* the test body's mass is 2 kg */
}

static const edge edges[] = {
    {"sphere radius, low", 1e-6, -1, "[1e-6, 1e6] m", NULL, b_radius, NULL, 1.0 / 60},
    {"sphere radius, high", 1e6, +1, "[1e-6, 1e6] m", NULL, b_radius, NULL, 1.0 / 60},
    {"box half extent, low", 1e-6, -1, "[1e-6, 1e6] m", NULL, b_box, NULL, 1.0 / 60},
    {"box half extent, high", 1e6, +1, "[1e-6, 1e6] m", NULL, b_box_long, NULL, 1.0 / 60},
    {"capsule radius", 1e-6, -1, "[1e-6, 1e6] m", NULL, b_capsule_r, NULL, 1.0 / 60},
    {"capsule half height", 1e6, +1, "[1e-6, 1e6] m", NULL, b_capsule_h, NULL, 1.0 / 60},
    {"cylinder radius", 1e6, +1, "[1e-6, 1e6] m", NULL, b_cylinder_r, NULL, 1.0 / 60},
    {"cylinder half height", 1e-6, -1, "[1e-6, 1e6] m", NULL, b_cylinder_h, NULL, 1.0 / 60},
    {"mass, low", 1e-9, -1, "[1e-9, 1e15] kg", NULL, b_mass, NULL, 1.0 / 60},
    {"mass, high", 1e15, +1, "[1e-9, 1e15] kg", NULL, b_mass, NULL, 1.0 / 60},
    {"mass, high, on the smallest sphere", 1e15, +1, "[1e-9, 1e15] kg", NULL, b_heavy_tiny, NULL, 1.0 / 60},
    {"mass, low, on the largest box", 1e-9, -1, "[1e-9, 1e15] kg", NULL, b_light_huge, NULL, 1.0 / 60},
    {"set_mass", 1e15, +1, "[1e-9, 1e15] kg", NULL, NULL, s_set_mass, 1.0 / 60},
    {"density, low", 1e-6, -1, "[1e-6, 1e9] kg/m^3", NULL, b_density, NULL, 1.0 / 60},
    {"density, high", 1e9, +1, "[1e-6, 1e9] kg/m^3", NULL, b_density, NULL, 1.0 / 60},
    {"distance from the origin", 1e12, +1, "1e12 m", NULL, b_x, NULL, 1.0 / 60},
    {"friction", 1e3, +1, "[0, 1000]", NULL, b_friction, NULL, 1.0 / 60},
    {"damping", 1e6, +1, "[0, 1e6] 1/s", NULL, b_damping, NULL, 1.0 / 60},
    {"gravity scale", 1e4, +1, "[-1e4, 1e4]", NULL, b_gravity_scale, NULL, 1.0 / 60},
    {"speed at creation", 4000, +1, "max_linear_speed 4000 m/s", NULL, b_speed, NULL, 1.0 / 60},
    {"spin at creation", 1e9, +1, "max_angular_speed 1e+09 rad/s", NULL, b_spin, NULL, 1.0 / 60},
    {"set_linear_velocity", 4000, +1, "max_linear_speed 4000 m/s", NULL, NULL, s_speed, 1.0 / 60},
    {"force over mass", 1e9, +1, "above 1e9 m/s^2", NULL, NULL, s_force, 1.0 / 60},
    {"gravity", 1e4, +1, "at most 1e4 m/s^2", w_gravity, NULL, NULL, 1.0 / 60},
    {"contact_hertz, low", 1e-3, -1, "[1e-3, 1e6]", w_hertz, NULL, NULL, 1.0 / 60},
    {"contact_hertz, high", 1e6, +1, "[1e-3, 1e6]", w_hertz, NULL, NULL, 1.0 / 60},
    {"max_linear_speed", 1e9, +1, "[1e-6, 1e9]", w_max_speed, NULL, NULL, 1.0 / 60},
    {"max_linear_speed, low", 1e-6, -1, "[1e-6, 1e9]", w_max_speed, NULL, NULL, 1.0 / 60},
    {"max_angular_speed, low", 1e-6, -1, "[1e-6, 1e9]", w_max_spin, NULL, NULL, 1.0 / 60},
    {"max_angular_speed, high", 1e9, +1, "[1e-6, 1e9]", w_max_spin, NULL, NULL, 1.0 / 60},
    {"time step, low", 1e-6, -1, "[1e-6, 1] seconds", NULL, NULL, NULL, 0},
    {"time step, high", 1.0, +1, "[1e-6, 1] seconds", NULL, NULL, NULL, 0},
};

static void test_range_edges(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++) {
        print_message("edge: %s\n", edges[i].name);
        walk_edge(&edges[i]);
    }
}

/* The inertia anisotropy edge (trace^3/det <= 1e12): a 2 kg capsule of half
 * height 1 m as thin as it may be. Its moments are m r^2 / 2 about the axis
 * and m (2h)^2 / 12 across (to r / h ~ 1e-6), so trace^3/det = 8 I_t / I_a
 * (1 + I_a / 2 I_t)^3 = 16 h^2 / (3 r^2) and the edge is r = h sqrt(16 / 3e12):
 * the radius where creation starts to be refused lies there, and the edge is
 * walked from it like the others. */
static int b_needle(carom_body_def *d, double v) { d->shape = carom_shape_capsule(v, 1.0); return 1; }

static int needle_accepted(double r)
{
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    carom_body_def d = carom_body_def_default();
    d.mass = 2;
    b_needle(&d, r);
    int ok = !carom_body_id_is_null(carom_body_create(w, &d));
    if (!ok && !strstr(carom_world_last_error(w), "above 1e12")) fail_msg("r %g: \"%s\"", r, carom_world_last_error(w));
    carom_world_destroy(w);
    return ok;
}

static void test_anisotropy_edge(void **state)
{
    (void)state;
    double lo = 1e-6, hi = 1e-5; /* refused, accepted */
    assert_false(needle_accepted(lo));
    assert_true(needle_accepted(hi));
    while (nextafter(lo, hi) < hi) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) mid = nextafter(lo, hi);
        if (needle_accepted(mid)) hi = mid;
        else lo = mid;
    }
    double analytic = sqrt(16.0 / 3e12);
    print_message("thinnest accepted 1 m capsule: r = %.9g m (analytic %.9g m)\n", hi, analytic);
    assert_true(fabs(hi / analytic - 1) < 1e-5);
    edge e = {"inertia anisotropy (capsule radius)", hi, -1, "above 1e12", NULL, b_needle, NULL, 1.0 / 60};
    walk_edge(&e);
}

/* ---- the findings of issue 17 ------------------------------------------------ */

/* 1: stepping a world with no bodies (UBSan: zero offset applied to the
 * island arrays' NULL pointer); also after its last body is destroyed. */
static void test_finding1_empty_world(void **state)
{
    (void)state;
    for (int p = 0; p < 3; p++) {
        carom_world_def d = carom_world_def_default();
        carom_world_def_apply_preset(&d, presets[p]);
        carom_world *w = carom_world_create(&d);
        run_finite(w, 3, 1.0 / 60);
        carom_body_def b = carom_body_def_default();
        carom_body_id id = carom_body_create(w, &b);
        run_finite(w, 3, 1.0 / 60);
        assert_int_equal(carom_body_destroy(w, id), CAROM_OK);
        run_finite(w, 3, 1.0 / 60);
        carom_world_stats st = carom_world_stats_init();
        carom_world_get_stats(w, &st);
        assert_int_equal(st.islands, 0);
        assert_int_equal(st.awake_bodies, 0);
        carom_world_destroy(w);
    }
}

/* 2: shapes whose mass is finite but whose inertia is not (or is zero), and mass = DBL_MAX. */
static void test_finding2_degenerate_mass_properties(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    double before = fingerprint(w);
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(1e100);
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "sphere radius 1e+100 is outside [1e-6, 1e6] m");
    d.shape = carom_shape_box(1e-160, 1e-160, 1e-160);
    d.mass = 1;
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "[1e-6, 1e6] m");
    d.shape = carom_shape_sphere(0.5);
    d.mass = DBL_MAX;
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "is outside [1e-9, 1e15] kg");
    /* a hull (its points need only be within 1e6 m) too small for its inertia */
    const double speck[] = {0, 0, 0, 1e-8, 0, 0, 0, 1e-8, 0, 0, 0, 1e-8};
    d.shape = carom_shape_hull(speck, 4);
    d.mass = 1e-9;
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "must lie within [1e-24, 1e30]");
    carom_world_destroy(w);
}

/* 3: a lone sphere of 1e198 kg spinning at 1 rad/s went NaN in one step while
 * the step said OK. Refused now; at the heaviest mass it spins on unchanged. */
static void test_finding3_heavy_spinning_sphere(void **state)
{
    (void)state;
    for (int p = 0; p < 3; p++) {
        carom_world_def wd = carom_world_def_default();
        carom_world_def_apply_preset(&wd, presets[p]);
        wd.gravity = vec(0, 0, 0);
        carom_world *w = carom_world_create(&wd);
        carom_body_def d = carom_body_def_default();
        d.shape = carom_shape_sphere(0.25);
        d.density = 1e300;
        d.angular_velocity = vec(0, 0, 1);
        double before = fingerprint(w);
        assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
        assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "[1e-6, 1e9] kg/m^3");
        d.density = 0;
        d.mass = 1e198;
        assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
        assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "[1e-9, 1e15] kg");
        d.mass = 1e15;
        carom_body_id id = carom_body_create(w, &d);
        assert_false(carom_body_id_is_null(id));
        run_finite(w, 600, 1.0 / 60);
        carom_vec3 av;
        carom_body_get_angular_velocity(w, id, &av);
        /* a free sphere keeps its spin: I w with I isotropic */
        assert_true(fabs(av.z - 1.0) < 1e-12 && fabs(av.x) < 1e-12 && fabs(av.y) < 1e-12);
        carom_world_destroy(w);
    }
}

/* 4: a 1e100 m sphere touching a 9 km sphere and a small capsule gave a hit
 * event a NaN tangent impulse. Refused now; the largest sphere allowed,
 * struck by both, gives finite events. */
static void test_finding4_huge_sphere_hits(void **state)
{
    (void)state;
    const double radii[] = {1e100, 1e6};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 2; k++) {
            carom_world_def wd = carom_world_def_default();
            carom_world_def_apply_preset(&wd, presets[p]);
            carom_world *w = carom_world_create(&wd);
            carom_body_def big = carom_body_def_default();
            big.shape = carom_shape_sphere(radii[k]);
            big.mass = 1e15;
            big.gravity_scale = 0;
            double before = fingerprint(w);
            carom_body_id b = carom_body_create(w, &big);
            if (k == 0) {
                assert_true(carom_body_id_is_null(b));
                assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "[1e-6, 1e6] m");
                carom_world_destroy(w);
                continue;
            }
            assert_false(carom_body_id_is_null(b));
            carom_body_def s = carom_body_def_default();
            s.shape = carom_shape_sphere(4500);
            s.position = vec(0, 0, 1e6 + 4500 + 0.01);
            s.linear_velocity = vec(0.5, 0, -30);
            s.friction = 1;
            s.mass = 1e12;
            assert_false(carom_body_id_is_null(carom_body_create(w, &s)));
            carom_body_def c = carom_body_def_default();
            c.shape = carom_shape_capsule(0.1, 0.3);
            c.position = vec(0, 1e6 + 0.1 + 0.01, 0);
            c.linear_velocity = vec(0.3, -20, 1);
            c.friction = 1;
            assert_false(carom_body_id_is_null(carom_body_create(w, &c)));
            int hits = 0;
            for (int i = 0; i < 60; i++) {
                run_finite(w, 1, 1.0 / 60);
                const carom_contact_event *ev;
                int ne = carom_world_get_events(w, &ev);
                for (int e = 0; e < ne; e++) hits += ev[e].type == CAROM_EVENT_HIT;
            }
            assert_true(hits >= 2);
            carom_world_destroy(w);
        }
}

/* 5: the smallest positive double passed the 0 < dt check and made a hit's
 * average force J / dt infinite. Refused now; at dt = 1e-6 s a hit's average force is finite. */
static void test_finding5_tiny_time_step(void **state)
{
    (void)state;
    carom_world_def wd = carom_world_def_default();
    wd.gravity = vec(0, 0, 0);
    carom_world *w = carom_world_create(&wd);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    carom_body_def b = carom_body_def_default();
    b.shape = carom_shape_sphere(0.1);
    b.position = vec(0, 0, 0.1 + 1e-5);
    b.linear_velocity = vec(0, 0, -20);
    b.restitution = 1;
    carom_body_create(w, &b);
    double before = fingerprint(w);
    assert_refused(w, carom_world_step(w, 4.9e-324), before, "[1e-6, 1] seconds");
    int hits = 0;
    for (int i = 0; i < 200 && !hits; i++) {
        run_finite(w, 1, 1e-6);
        const carom_contact_event *ev;
        int ne = carom_world_get_events(w, &ev);
        for (int e = 0; e < ne; e++)
            if (ev[e].type == CAROM_EVENT_HIT) {
                hits++;
                /* J / dt with J about 2 m v = 2 * 4.19 kg * 20 m/s */
                assert_true(ev[e].average_force > 0 && ev[e].average_force < 1e9);
            }
    }
    assert_true(hits > 0);
    carom_world_destroy(w);
}

/* ---- stability at the edges of the ranges (was test_extremes.c) ---- */

/* numerical stability at the edges of the envelope (fast
 * versions; bench/extremes runs the long ones): mass ratios, speeds, sizes,
 * distance from the origin, time steps, and a soak. The state must stay
 * finite everywhere, and accurate where the README says carom holds. */

static carom_world *ground_world(carom_world_def d)
{
    d.enable_sleep = 0;
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    return w;
}

static carom_body_id box_at(carom_world *w, double x, double y, double z, double he, double mass)
{
    carom_body_def d = carom_body_def_default();
    d.position = vec(x, y, z);
    d.shape = carom_shape_box(he, he, he);
    d.mass = mass;
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    return id;
}

static void assert_world_finite(carom_world *w)
{
    double ke, pe;
    carom_vec3 p, l;
    assert_int_equal(carom_world_get_energy(w, &ke, &pe), CAROM_OK);
    assert_int_equal(carom_world_get_momentum(w, &p, &l), CAROM_OK);
    assert_true(isfinite(ke) && isfinite(pe));
    assert_true(isfinite(p.x) && isfinite(p.y) && isfinite(p.z) && isfinite(l.x) && isfinite(l.y) && isfinite(l.z));
}

static void run(carom_world *w, int n, double dt)
{
    for (int i = 0; i < n; i++) assert_int_equal(carom_world_step(w, dt), CAROM_OK);
}

/* 1000:1 holds; 1e6:1 stays finite and upright-ish (the light box is not squeezed out). */
static void test_mass_ratios(void **state)
{
    (void)state;
    double ratios[2] = {1e3, 1e6};
    for (int i = 0; i < 2; i++) {
        carom_world *w = ground_world(carom_world_def_default());
        carom_body_id light = box_at(w, 0, 0, 0.5, 0.5, 1.0);
        carom_body_id heavy = box_at(w, 0, 0, 1.5, 0.5, ratios[i]);
        run(w, 300, 1.0 / 60);
        assert_world_finite(w);
        carom_vec3 ph = pos(w, heavy), pl = pos(w, light);
        double tol = i == 0 ? 0.01 : 0.05;
        if (!(fabs(ph.z - 1.5) < tol && fabs(pl.z - 0.5) < tol)) {
            print_error("ratio %g: heavy z %.4f light z %.4f\n", ratios[i], ph.z, pl.z);
            fail();
        }
        carom_world_destroy(w);
    }
}

/* Projectiles up to 1000 m/s against a 5 cm wall never pass through. */
static void test_speeds(void **state)
{
    (void)state;
    double speeds[4] = {10, 100, 500, 1000};
    for (int i = 0; i < 4; i++) {
        carom_world_def d = carom_world_def_default();
        carom_world *w = carom_world_create(&d);
        carom_body_def wall = carom_body_def_default();
        wall.type = CAROM_BODY_STATIC;
        wall.position = vec(1.025, 0, 2);
        wall.shape = carom_shape_box(0.025, 2, 2);
        carom_body_create(w, &wall);
        carom_body_def s = carom_body_def_default();
        s.position = vec(0, 0, 2);
        s.shape = carom_shape_sphere(0.01);
        s.mass = 0.01;
        s.linear_velocity = vec(speeds[i], 0, 0);
        carom_body_id b = carom_body_create(w, &s);
        for (int k = 0; k < 60; k++) {
            run(w, 1, 1.0 / 60);
            if (!(pos(w, b).x < 1.0)) {
                print_error("speed %g m/s: x = %.4f after step %d\n", speeds[i], pos(w, b).x, k);
                fail();
            }
        }
        assert_world_finite(w);
        carom_world_destroy(w);
    }
}

/* A box resting on the ground stays put from 1 mm to 1 km. */
static void test_sizes(void **state)
{
    (void)state;
    double sizes[4] = {0.001, 0.01, 100.0, 1000.0};
    for (int i = 0; i < 4; i++) {
        carom_world *w = ground_world(carom_world_def_default());
        double he = 0.5 * sizes[i];
        carom_body_id b = box_at(w, 0, 0, he, he, 1000.0 * sizes[i] * sizes[i] * sizes[i]);
        run(w, 120, 1.0 / 60);
        assert_world_finite(w);
        carom_vec3 p = pos(w, b);
        /* within 1 % of its size, or the 5 mm slop, whichever is larger */
        double tol = fmax(0.01 * sizes[i], 0.006);
        if (!(fabs(p.z - he) < tol && fabs(p.x) < tol && fabs(p.y) < tol)) {
            print_error("size %g m: rest at (%.6f %.6f %.6f), expected z %.6f\n", sizes[i], p.x, p.y, p.z, he);
            fail();
        }
        carom_world_destroy(w);
    }
}

/* A five-box stack 1e5 m from the origin stands as it does at the origin. */
static void test_far_from_origin(void **state)
{
    (void)state;
    carom_world *w = ground_world(carom_world_def_default());
    const double X = 1e5, Y = -1e5;
    carom_body_id top = box_at(w, X, Y, 0.5, 0.5, 1);
    for (int i = 1; i < 5; i++) top = box_at(w, X, Y, 0.5 + i, 0.5, 1);
    run(w, 300, 1.0 / 60);
    assert_world_finite(w);
    carom_vec3 p = pos(w, top);
    double moved = sqrt(pow(p.x - X, 2) + pow(p.y - Y, 2) + pow(p.z - 4.5, 2));
    if (!(moved < 0.01)) { print_error("far stack top moved %.4f m\n", moved); fail(); }
    carom_world_destroy(w);
}

/* Time steps from 1/1000 to 1/15 s: a stack of five stands at each. */
static void test_time_steps(void **state)
{
    (void)state;
    double dts[4] = {1.0 / 1000, 1.0 / 120, 1.0 / 30, 1.0 / 15};
    for (int i = 0; i < 4; i++) {
        carom_world *w = ground_world(carom_world_def_default());
        carom_body_id top = box_at(w, 0, 0, 0.5, 0.5, 1);
        for (int k = 1; k < 5; k++) top = box_at(w, 0, 0, 0.5 + k, 0.5, 1);
        int steps = (int)(3.0 / dts[i]);
        run(w, steps, dts[i]);
        assert_world_finite(w);
        carom_vec3 p = pos(w, top);
        double moved = sqrt(p.x * p.x + p.y * p.y + pow(p.z - 4.5, 2));
        /* accurate to 3 cm at 60 Hz and finer; still standing (the peers' 0.1 m) at 30 and 15 Hz */
        double tol = dts[i] <= 1.0 / 60 ? 0.03 : 0.1;
        print_message("dt %.4f: top moved %.4f m\n", dts[i], moved);
        if (!(moved < tol)) { print_error("dt %g: stack top moved %.4f m\n", dts[i], moved); fail(); }
        carom_world_destroy(w);
    }
}

/* A short soak: a box and a ball bouncing around a closed room stay finite and inside. */
/* Finite but absurd velocities are refused by the setters (above the world's
 * speed limits), leaving the body as it was; velocities a later, lower limit
 * leaves too fast are clamped before they are integrated: no pose overflows,
 * no NaN reaches the narrowphase or the time-of-impact sweep. */
static void test_huge_velocities(void **state)
{
    (void)state;
    const carom_shape_def shapes[] = {carom_shape_capsule(0.1, 0.3), carom_shape_sphere(0.2), carom_shape_box(0.2, 0.2, 0.2)};
    for (int k = 0; k < 3; k++) {
        carom_world_def d = carom_world_def_default();
        d.max_angular_speed = 1000.0; /* an explicit cap (the default, 0, is automatic) */
        carom_world *w = ground_world(d);
        carom_body_def sb = carom_body_def_default();
        sb.type = CAROM_BODY_STATIC;
        sb.shape = carom_shape_box(2, 2, 0.5);
        sb.position = vec(0, 0, 0.5);
        carom_body_create(w, &sb);
        carom_body_def bd = carom_body_def_default();
        bd.shape = shapes[k];
        bd.position = vec(0, 0, 1.6);
        carom_body_id spin = carom_body_create(w, &bd);
        bd.position = vec(0.5, 0, 1.6);
        carom_body_id fly = carom_body_create(w, &bd);
        assert_int_equal(carom_body_set_angular_velocity(w, spin, vec(0, -1e308, 0)), CAROM_ERROR_INVALID_ARGUMENT);
        assert_int_equal(carom_body_set_linear_velocity(w, fly, vec(-1e308, 1e308, -1e308)), CAROM_ERROR_INVALID_ARGUMENT);
        carom_vec3 unchanged;
        assert_int_equal(carom_body_get_linear_velocity(w, fly, &unchanged), CAROM_OK);
        assert_true(unchanged.x == 0 && unchanged.y == 0 && unchanged.z == 0);
        assert_int_equal(carom_body_set_angular_velocity(w, spin, vec(0, -d.max_angular_speed, 0)), CAROM_OK);
        double c = d.max_linear_speed / sqrt(3.0) * (1 - 1e-12);
        assert_int_equal(carom_body_set_linear_velocity(w, fly, vec(-c, c, -c)), CAROM_OK);
        carom_world_def lower = d;
        lower.enable_sleep = 0;
        lower.max_linear_speed = d.max_linear_speed / 1e3;
        lower.max_angular_speed = d.max_angular_speed / 1e3;
        assert_int_equal(carom_world_set_def(w, &lower), CAROM_OK);
        d = lower;
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
        assert_true(st.clamped >= 2);
        assert_int_equal(st.non_finite, 0);
        carom_vec3 wv, v;
        assert_int_equal(carom_body_get_angular_velocity(w, spin, &wv), CAROM_OK);
        assert_true(sqrt(wv.x * wv.x + wv.y * wv.y + wv.z * wv.z) <= d.max_angular_speed * (1 + 1e-12));
        assert_int_equal(carom_body_get_linear_velocity(w, fly, &v), CAROM_OK);
        assert_true(sqrt(v.x * v.x + v.y * v.y + v.z * v.z) <= d.max_linear_speed * (1 + 1e-12));
        run(w, 120, 1.0 / 60);
        assert_world_finite(w);
        carom_vec3 p = pos(w, spin);
        assert_true(isfinite(p.x) && isfinite(p.y) && isfinite(p.z));
        carom_world_destroy(w);
    }
}

/* A 1 cm box on the ground with every manifold recomputed every step (no
 * reuse): it stays where it was put, flat (its eight corners are all within
 * the 2 cm look-ahead; the manifold must still be the bottom face's). */
static void test_small_box_rests_without_reuse(void **state)
{
    (void)state;
    carom_world_def d = carom_world_def_default();
    d.contact_reuse_distance = 0.0;
    carom_world *w = ground_world(d);
    carom_body_id id = box_at(w, 0, 0, 0.005, 0.005, 1e-3);
    run(w, 600, 1.0 / 60);
    carom_vec3 p = pos(w, id);
    carom_quat q;
    assert_int_equal(carom_body_get_orientation(w, id, &q), CAROM_OK);
    double drift = sqrt(p.x * p.x + p.y * p.y), tilt = 2.0 * acos(fmin(1.0, fabs(q.w)));
    print_message("1 cm box: drift %.3g m, sank %.3g m, tilt %.3g rad\n", drift, 0.005 - p.z, tilt);
    assert_true(drift < 1e-4);
    assert_true(fabs(p.z - 0.005) < 5e-4);
    assert_true(tilt < 0.01);
    carom_world_destroy(w);
}

/* Everything at once through the wide passes, under the sanitizers in make
 * check: 160 bodies of every shape falling into a walled bin (heavy ones
 * among them, so shock propagation runs between wide passes), kinematic
 * paddles sweeping through, plane-locked bodies, sleeping on. Nothing may go
 * non-finite, fall through the floor or leave the bin. */
static void test_mixed_bin_stress(void **state)
{
    (void)state;
    carom_world_def d = carom_world_def_default();
    d.enable_sleep = 1;
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    const double walls[5][4] = {{0, 0, 1, 0}, {1, 0, 0, -4}, {-1, 0, 0, -4}, {0, 1, 0, -4}, {0, -1, 0, -4}};
    for (int i = 0; i < 5; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(walls[i][0], walls[i][1], walls[i][2], walls[i][3]);
        carom_body_create(w, &g);
    }
    const double pts[15] = {0.3, 0, 0, -0.2, 0.25, 0, -0.2, -0.25, 0, 0, 0, 0.4, 0, 0, -0.3};
    carom_body_id ids[160];
    uint64_t r = 0xB1A5EDULL;
    for (int i = 0; i < 160; i++) {
        carom_body_def b = carom_body_def_default();
        b.position = vec(-3.0 + 0.75 * (i % 8), -3.0 + 0.75 * ((i / 8) % 8), 0.5 + 0.8 * (i / 64));
        switch (i % 6) {
        case 0: b.shape = carom_shape_box(0.3, 0.2, 0.25); break;
        case 1: b.shape = carom_shape_sphere(0.3); break;
        case 2: b.shape = carom_shape_capsule(0.15, 0.2); break;
        case 3: b.shape = carom_shape_cylinder(0.25, 0.2); break;
        case 4: b.shape = carom_shape_hull(pts, 5); break;
        default: b.shape = carom_shape_box(0.35, 0.35, 0.1); break;
        }
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        if (i % 17 == 0) b.mass = 1000.0; /* heavy */
        if (i % 23 == 5) { b.lock_to_plane = 1; b.plane_normal = vec(0, 1, 0); }
        if (i % 31 == 7) b.lock_rotation = 1;
        b.restitution = (double)(r >> 40 & 0xff) / 512.0;
        b.friction = 0.2 + (double)(r >> 48 & 0xff) / 512.0;
        b.angular_velocity = vec((double)(r >> 20 & 0xff) / 64.0 - 2, 0, (double)(r >> 28 & 0xff) / 64.0 - 2);
        ids[i] = carom_body_create(w, &b);
        assert_false(carom_body_id_is_null(ids[i]));
    }
    carom_body_id paddles[2];
    for (int k = 0; k < 2; k++) {
        carom_body_def p = carom_body_def_default();
        p.type = CAROM_BODY_KINEMATIC;
        p.shape = carom_shape_box(1.5, 0.1, 0.3);
        p.position = vec(0, k ? 2.0 : -2.0, 0.3);
        p.angular_velocity = vec(0, 0, k ? 1.0 : -1.5);
        paddles[k] = carom_body_create(w, &p);
    }
    int most = 0;
    for (int s = 0; s < 600; s++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        carom_world_stats st = carom_world_stats_init();
        assert_int_equal(carom_world_get_stats(w, &st), CAROM_OK);
        assert_int_equal(st.non_finite, 0);
        if (st.contacts > most) most = st.contacts;
    }
    assert_true(most >= 64); /* the wide passes ran */
    assert_world_finite(w);
    for (int i = 0; i < 160; i++) {
        carom_vec3 p = pos(w, ids[i]);
        if (!(p.z > -0.05 && fabs(p.x) < 4.0 && fabs(p.y) < 4.0)) {
            print_error("body %d left the bin: (%.3f %.3f %.3f)\n", i, p.x, p.y, p.z);
            fail();
        }
    }
    (void)paddles;
    carom_world_destroy(w);
}

static void test_soak(void **state)
{
    (void)state;
    carom_world_def d = carom_world_def_default();
    d.enable_sleep = 0;
    carom_world *w = carom_world_create(&d);
    double walls[6][4] = {{0, 0, 1, 0}, {0, 0, -1, -6}, {1, 0, 0, -3}, {-1, 0, 0, -3}, {0, 1, 0, -3}, {0, -1, 0, -3}};
    for (int i = 0; i < 6; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(walls[i][0], walls[i][1], walls[i][2], walls[i][3]);
        g.restitution = 0.9;
        carom_body_create(w, &g);
    }
    carom_body_def b = carom_body_def_default();
    b.position = vec(0, 0, 2);
    b.shape = carom_shape_box(0.3, 0.2, 0.1);
    b.linear_velocity = vec(7, -3, 5);
    b.angular_velocity = vec(4, 9, -2);
    b.restitution = 0.9;
    carom_body_id box = carom_body_create(w, &b);
    b.shape = carom_shape_sphere(0.2);
    b.position = vec(1, 1, 3);
    carom_body_id ball = carom_body_create(w, &b);
    for (int i = 0; i < 20000; i++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        if (i % 1000 == 0) assert_world_finite(w);
    }
    carom_vec3 p = pos(w, box), q = pos(w, ball);
    assert_true(fabs(p.x) < 3 && fabs(p.y) < 3 && p.z > 0 && p.z < 6);
    assert_true(fabs(q.x) < 3 && fabs(q.y) < 3 && q.z > 0 && q.z < 6);
    carom_world_destroy(w);
}

/* ---- findings of the fuzz hour of 2026-12-04 ------------------------------- */

/* A snapshot of the world restores (the fuzz_api invariant after every op). */
static void assert_snapshot_restores(const carom_world *w, const char *what)
{
    size_t n = carom_world_snapshot(w, NULL, 0);
    unsigned char *buf = malloc(n);
    assert_non_null(buf);
    assert_int_equal(carom_world_snapshot(w, buf, n), n);
    char msg[256];
    carom_world *r = carom_world_restore(buf, n, msg, sizeof msg);
    if (!r) fail_msg("%s: the world's own snapshot is refused: %s", what, msg);
    carom_world_destroy(r);
    free(buf);
}

/* fuzz_api: a body locked to a plane met another along the plane's normal,
 * where it cannot move. The row's inverse effective mass was rounding (about
 * 1e-33 of 1/m) and 1/k of it stored a warm-start impulse of 1.2e33 N s that
 * no snapshot could restore. The row is blocked now (row_mass, constraint.h):
 * the locked box gets no impulse at all, so it moves exactly as it would
 * alone, its velocity the in-plane part of gravity times the time. A lock
 * normal off the axes (the rounding is exact zero along them), both orders,
 * against a static and a kinematic box, every preset. */
static void test_locked_along_contact_normal(void **state)
{
    (void)state;
    const carom_vec3 axes[] = {{1, 2, 3}, {-0.3, 1, 0.05}, {0.7, -0.2, 0.9}};
    for (int a = 0; a < 3; a++)
        for (int p = 0; p < 3; p++)
            for (int kinematic = 0; kinematic < 2; kinematic++)
                for (int order = 0; order < 2; order++) {
                    carom_vec3 l = axes[a];
                    double len = sqrt(l.x * l.x + l.y * l.y + l.z * l.z);
                    l = vec(l.x / len, l.y / len, l.z / len);
                    /* the rotation taking y to l: about y x l by the angle between them */
                    carom_vec3 ax = vec(l.z, 0, -l.x); /* (0,1,0) x l */
                    double al = sqrt(ax.x * ax.x + ax.z * ax.z), ang = acos(l.y);
                    carom_quat q = {cos(ang / 2), sin(ang / 2) * ax.x / al, 0, sin(ang / 2) * ax.z / al};
                    carom_world_def wd = carom_world_def_default();
                    carom_world_def_apply_preset(&wd, presets[p]);
                    carom_world *w = carom_world_create(&wd);
                    carom_body_def fixed = carom_body_def_default();
                    fixed.type = kinematic ? CAROM_BODY_KINEMATIC : CAROM_BODY_STATIC;
                    fixed.shape = carom_shape_box(0.5, 0.5, 0.5);
                    fixed.orientation = q;
                    carom_body_def locked = carom_body_def_default();
                    locked.shape = carom_shape_box(0.5, 0.5, 0.5);
                    locked.orientation = q;
                    locked.position = vec(0.9 * l.x, 0.9 * l.y, 0.9 * l.z); /* 0.1 m into it along l */
                    locked.lock_to_plane = 1;
                    locked.plane_normal = l;
                    locked.enable_sleep = 0;
                    carom_body_id id;
                    if (order) { id = carom_body_create(w, &locked); carom_body_create(w, &fixed); }
                    else { carom_body_create(w, &fixed); id = carom_body_create(w, &locked); }
                    assert_false(carom_body_id_is_null(id));
                    const int n = 20;
                    const double dt = 1.0 / 60;
                    for (int k = 0; k < n; k++) {
                        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
                        assert_snapshot_restores(w, "a box locked along its contact normal");
                    }
                    carom_vec3 g = wd.gravity, v = vel(w, id), want;
                    double gl = g.x * l.x + g.y * l.y + g.z * l.z;
                    want = vec((g.x - gl * l.x) * n * dt, (g.y - gl * l.y) * n * dt, (g.z - gl * l.z) * n * dt);
                    double err = sqrt(pow(v.x - want.x, 2) + pow(v.y - want.y, 2) + pow(v.z - want.z, 2));
                    if (!(err <= 1e-9)) {
                        print_error("axis %d %s kinematic %d order %d: velocity (%g %g %g), free motion (%g %g %g)\n", a,
                                    presets[p], kinematic, order, v.x, v.y, v.z, want.x, want.y, want.z);
                        fail();
                    }
                    carom_world_destroy(w);
                }
}

/* fuzz_api: plane_normal is read only with lock_to_plane, but an unlocked
 * body kept a given (1, -inf, 1) in its state, and the world's snapshot was
 * refused ("class plane normal is not finite"). An unread value stays out of
 * the state now: the body is as if made with the default. */
static void test_unread_plane_normal(void **state)
{
    (void)state;
    const double bad[] = {-INFINITY, NAN, 0.0}; /* 0: (1, 0, 1), a valid one */
    for (int i = 0; i < 3; i++) {
        carom_world *w = ground_world(carom_world_def_default()), *u = ground_world(carom_world_def_default());
        carom_body_def b = carom_body_def_default();
        b.shape = carom_shape_capsule(0.3, 0.5);
        b.position = vec(0, 0, 2);
        b.angular_velocity = vec(1, 2, 3);
        carom_body_id plain = carom_body_create(u, &b);
        b.plane_normal = vec(1, bad[i], 1);
        carom_body_id odd = carom_body_create(w, &b);
        assert_false(carom_body_id_is_null(odd));
        run(w, 90, 1.0 / 60);
        run(u, 90, 1.0 / 60);
        assert_snapshot_restores(w, "an unlocked body given a bad plane normal");
        carom_vec3 po = pos(w, odd), pp = pos(u, plain);
        assert_true(po.x == pp.x && po.y == pp.y && po.z == pp.z);
        carom_world_destroy(u);
        carom_body_def locked = b; /* read, the same value is refused */
        locked.lock_to_plane = 1;
        double before = fingerprint(w);
        carom_body_id made = carom_body_create(w, &locked);
        if (isfinite(bad[i])) assert_false(carom_body_id_is_null(made));
        else {
            assert_true(carom_body_id_is_null(made));
            assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "plane_normal");
        }
        carom_world_destroy(w);
    }
}

/* fuzz_scene: a 3.45 um hull at 1e12 m (35 times thinner than an ulp of
 * its coordinates there) sank 0.1 m into a tilted ground. A moving body must
 * be at least 1e-13 of its coordinates thick (ranges.h): at the edge it is
 * taken and slides 600 steps over a tilted plane at every preset, finite and
 * within 2.5 % of its thickness of the surface; just below it body_create,
 * body_set_position and body_set_type refuse, naming the limit, the world
 * unchanged. Near the origin the rule never binds (1e-6 m at 1e7 m). */
static void test_thickness_far_from_origin(void **state)
{
    (void)state;
    const double far = 1e12, r = 1e-13 * far; /* 0.1 m */
    const double n[3] = {0.21945146130862031, -0.23505587110638249, 0.94688425564475986};
    for (int p = 0; p < 3; p++) {
        carom_world_def wd = carom_world_def_default();
        carom_world_def_apply_preset(&wd, presets[p]);
        carom_world *w = carom_world_create(&wd);
        double off = n[1] * far; /* the plane through (0, far, 0) */
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(n[0], n[1], n[2], off);
        carom_body_create(w, &g);
        carom_body_def b = carom_body_def_default();
        b.shape = carom_shape_sphere(r);
        b.position = vec(0, far, r + 0.01);
        b.linear_velocity = vec(4, -3, 0);
        b.enable_sleep = 0;
        carom_body_id id = carom_body_create(w, &b);
        assert_false(carom_body_id_is_null(id));
        double deepest = 0;
        for (int k = 0; k < 600; k++) {
            run_finite(w, 1, 1.0 / 60);
            carom_vec3 c = pos(w, id);
            double gap = n[0] * c.x + n[1] * c.y + n[2] * c.z - off - r;
            if (-gap > deepest) deepest = -gap;
        }
        if (!(deepest <= 0.025 * r)) { print_error("%s: %.3g m into the plane\n", presets[p], deepest); fail(); }
        /* just below the limit: refused at each call that would make it so */
        double before = fingerprint(w);
        carom_body_def thin = b;
        thin.shape = carom_shape_sphere(r * (1 - 1e-9));
        assert_true(carom_body_id_is_null(carom_body_create(w, &thin)));
        assert_refused(w, CAROM_ERROR_INVALID_ARGUMENT, before, "at least 1e-13");
        thin.position = vec(0, 0, 5);
        carom_body_id near = carom_body_create(w, &thin);
        assert_false(carom_body_id_is_null(near));
        before = fingerprint(w);
        assert_refused(w, carom_body_set_position(w, near, vec(0, far, 5)), before, "at least 1e-13");
        thin.type = CAROM_BODY_STATIC;
        thin.position = vec(0, -far, 5);
        carom_body_id still = carom_body_create(w, &thin); /* static: no limit */
        assert_false(carom_body_id_is_null(still));
        before = fingerprint(w);
        assert_refused(w, carom_body_set_type(w, still, CAROM_BODY_DYNAMIC), before, "at least 1e-13");
        /* the smallest length, 1e-6 m, at 1e7 m */
        carom_body_def speck = carom_body_def_default();
        speck.shape = carom_shape_sphere(1e-6);
        speck.mass = 1e-3;
        speck.position = vec(1e7, 0, 3);
        assert_false(carom_body_id_is_null(carom_body_create(w, &speck)));
        carom_world_destroy(w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_finding1_empty_world),
        cmocka_unit_test(test_finding2_degenerate_mass_properties),
        cmocka_unit_test(test_finding3_heavy_spinning_sphere),
        cmocka_unit_test(test_finding4_huge_sphere_hits),
        cmocka_unit_test(test_finding5_tiny_time_step),
        cmocka_unit_test(test_locked_along_contact_normal),
        cmocka_unit_test(test_unread_plane_normal),
        cmocka_unit_test(test_thickness_far_from_origin),
        cmocka_unit_test(test_range_edges),
        cmocka_unit_test(test_anisotropy_edge),
        cmocka_unit_test(test_mass_ratios),
        cmocka_unit_test(test_speeds),
        cmocka_unit_test(test_sizes),
        cmocka_unit_test(test_far_from_origin),
        cmocka_unit_test(test_time_steps),
        cmocka_unit_test(test_huge_velocities),
        cmocka_unit_test(test_small_box_rests_without_reuse),
        cmocka_unit_test(test_mixed_bin_stress),
        cmocka_unit_test(test_soak),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
