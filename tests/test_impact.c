/* test_impact.c - impacts at the moment of contact, against the seed's
 * rigid-body impulse formulas and the conservation laws: an oblique ball on a
 * plane (sliding and sticking friction), an off-centre pair of spheres, a
 * 60 m/s reflection that keeps the rest of its step, a touching Newton's
 * cradle, a billiard break, an elastic gas at the default settings, a bounce
 * driven by a force instead of gravity, and bounces at large steps. Every
 * expected value is computed here from first principles. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "carom/carom.h"
#include "helpers.h"


static const char *PRESETS[3] = {"fast", "default", "accurate"};

static carom_vec3 cv(double x, double y, double z) { carom_vec3 v = {x, y, z}; return v; }
static double len3(carom_vec3 a) { return sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }
static carom_vec3 sub3(carom_vec3 a, carom_vec3 b) { return cv(a.x - b.x, a.y - b.y, a.z - b.z); }
static carom_vec3 cross3(carom_vec3 a, carom_vec3 b)
{
    return cv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

#define CHECK_REL(got, want, rel, what)                                                              \
    do {                                                                                             \
        double g_ = (got), w_ = (want);                                                              \
        print_message("%s: %.6g (expected %.6g)\n", (what), g_, w_);                                 \
        if (!(fabs(g_ - w_) <= (rel) * fabs(w_))) {                                                  \
            print_error("%s: got %.9g, expected %.9g (relative tolerance %g)\n", (what), g_, w_, (double)(rel)); \
            fail();                                                                                  \
        }                                                                                            \
    } while (0)

static carom_world *world_for(const char *preset, carom_vec3 gravity)
{
    carom_world_def wd = preset_def(preset);
    wd.gravity = gravity;
    return world_with(wd, 0, 0.0, 0.0);
}

static carom_body_id add_surface(carom_world *w, carom_shape_def shape, carom_vec3 at, double mu, double e)
{
    carom_body_def d = carom_body_def_default();
    d.type = CAROM_BODY_STATIC;
    d.shape = shape;
    d.position = at;
    d.friction = mu;
    d.restitution = e;
    return add_body(w, &d);
}

static carom_body_id add_ball(carom_world *w, double r, double m, carom_vec3 at, carom_vec3 v, double mu, double e)
{
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(r);
    d.mass = m;
    d.position = at;
    d.linear_velocity = v;
    d.friction = mu;
    d.restitution = e;
    return add_body(w, &d);
}

static carom_vec3 velocity(carom_world *w, carom_body_id id)
{
    carom_vec3 v;
    assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
    return v;
}

static carom_vec3 spin(carom_world *w, carom_body_id id)
{
    carom_vec3 v;
    assert_int_equal(carom_body_get_angular_velocity(w, id, &v), CAROM_OK);
    return v;
}

static carom_vec3 position(carom_world *w, carom_body_id id)
{
    carom_vec3 v;
    assert_int_equal(carom_body_get_position(w, id, &v), CAROM_OK);
    return v;
}

/* ---- an oblique ball on a plane ---------------------------------------------- */

/* A solid ball (I = 2/5 m r^2) meets a plane at (vt, 0, -vn) with friction mu
 * and restitution e. The seed's impulses: normal J = (1 + e) m vn; friction
 * along -slip, at most mu J and at most what stops the slip at the contact
 * point, vt / (1/m + r^2/I) = 2/7 m vt. Then v_t+ = vt - Jt/m, w = Jt r / I,
 * v_n+ = e vn. No gravity: the impact velocity is the one given. The ball is
 * placed so that it touches `frac` of the way into its fourth step. */
static void oblique_case(const char *preset, double dt, double r, double m, double mu, double e, double frac,
                         carom_vec3 origin)
{
    const double vt = 4.0, vn = 3.0;
    carom_world *w = world_for(preset, cv(0, 0, 0));
    add_surface(w, carom_shape_plane(0, 0, 1, origin.z), cv(0, 0, 0), mu, e);
    double gap = vn * dt * (3.0 + frac);
    carom_body_id ball = add_ball(w, r, m, cv(origin.x, origin.y, origin.z + r + gap), cv(vt, 0, -vn), mu, e);
    step_n(w, 10, dt);
    double jn = (1.0 + e) * m * vn;
    double jt = fmin(mu * jn, 2.0 / 7.0 * m * vt);
    double inertia = 0.4 * m * r * r;
    double want_spin = jt * r / inertia;
    double want_angle = atan2(e * vn, vt - jt / m) * 180.0 / PI_;
    carom_vec3 v = velocity(w, ball), av = spin(w, ball);
    double angle = atan2(v.z, v.x) * 180.0 / PI_;
    print_message("%s dt 1/%.0f r %g m %g mu %g, touching %.2f into a step:\n", preset, 1 / dt, r, m, mu, frac);
    CHECK_REL(av.y, want_spin, 0.02, "spin out (rad/s)");
    CHECK_REL(angle, want_angle, 0.02, "angle out (deg)");
    CHECK_REL(v.z, e * vn, 0.02, "normal speed out");
    carom_world_destroy(w);
}

static void test_oblique_ball_sliding_and_sticking(void **state)
{
    (void)state;
    const double dts[2] = {1.0 / 60, 1.0 / 30};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 2; k++) {
            oblique_case(PRESETS[p], dts[k], 0.1, 1.0, 0.1, 0.5, 0.5, cv(0, 0, 0)); /* slides: 11.25 rad/s */
            oblique_case(PRESETS[p], dts[k], 0.1, 1.0, 0.8, 0.5, 0.5, cv(0, 0, 0)); /* sticks: 28.57 rad/s */
        }
    /* sizes, masses, moments within the step, far from the origin */
    oblique_case("default", 1.0 / 60, 1.0, 50.0, 0.1, 0.5, 0.1, cv(0, 0, 0));
    oblique_case("default", 1.0 / 60, 0.02, 0.01, 0.8, 0.8, 0.9, cv(0, 0, 0));
    oblique_case("default", 1.0 / 60, 0.1, 1.0, 0.3, 0.2, 0.25, cv(3e3, -4e3, 1e3));
    oblique_case("accurate", 1.0 / 120, 0.1, 1.0, 0.1, 0.5, 0.7, cv(0, 0, 0));
}

/* ---- an off-centre pair of spheres ------------------------------------------- */

/* Equal-radius spheres, frictionless: the target leaves along the line of
 * centres at the moment of contact, at asin(b / 2r) from the projectile's
 * path (b the offset), whatever the masses. Momentum and the angular momentum
 * about any fixed point (orbital + spin) are conserved. */
static void pair_case(const char *preset, double dt, double r, double m1, double m2, double speed, double deg,
                      double e, carom_vec3 o)
{
    carom_world *w = world_for(preset, cv(0, 0, 0));
    double b = 2.0 * r * sin(deg * PI_ / 180.0);
    /* touches 0.4 of the way into the fourth step */
    double approach = 2.0 * r * cos(deg * PI_ / 180.0) + speed * dt * 3.4;
    carom_body_id p = add_ball(w, r, m1, cv(o.x - approach, o.y + b, o.z), cv(speed, 0, 0), 0.0, e);
    carom_body_id t = add_ball(w, r, m2, o, cv(0, 0, 0), 0.0, e);
    carom_vec3 P0, L0, P1, L1;
    assert_int_equal(carom_world_get_momentum(w, &P0, &L0), CAROM_OK);
    step_n(w, 12, dt);
    assert_int_equal(carom_world_get_momentum(w, &P1, &L1), CAROM_OK);
    carom_vec3 vt = velocity(w, t);
    double got = atan2(-vt.y, vt.x) * 180.0 / PI_;
    print_message("%s dt 1/%.0f r %g masses %g %g at %g m/s: deflection %.4f deg (expected %.4f)\n", preset, 1 / dt, r,
                  m1, m2, speed, got, deg);
    assert_true(fabs(got - deg) < 0.5);
    double pscale = len3(P0);
    assert_true(len3(sub3(P1, P0)) <= 1e-9 * pscale);
    /* about the origin and two other fixed points: L_Q = L_origin - Q x P */
    const carom_vec3 qs[3] = {{0, 0, 0}, {o.x + 1, o.y - 2, o.z + 0.5}, {o.x - 3, o.y + 1, o.z - 2}};
    for (int k = 0; k < 3; k++) {
        carom_vec3 a0 = sub3(L0, cross3(qs[k], P0)), a1 = sub3(L1, cross3(qs[k], P1));
        /* relative to |P| times the distance of the point from the impact */
        double scale = pscale * fmax(len3(sub3(qs[k], o)), r);
        double err = len3(sub3(a1, a0)) / scale;
        print_message("  angular momentum about point %d: relative error %.2e\n", k, err);
        assert_true(err <= 1e-9);
    }
    (void)p;
    carom_world_destroy(w);
}

static void test_off_centre_pair(void **state)
{
    (void)state;
    const double dts[4] = {1.0 / 15, 1.0 / 60, 1.0 / 240, 1.0 / 1000};
    for (int pr = 0; pr < 3; pr++)
        for (int k = 0; k < 4; k++) pair_case(PRESETS[pr], dts[k], 0.1, 1.0, 1.0, 2.0, 30.0, 1.0, cv(0, 0, 0));
    pair_case("default", 1.0 / 60, 0.1, 1.0, 1.0, 2.0, 30.0, 0.5, cv(0, 0, 0));
    pair_case("default", 1.0 / 60, 0.1, 1.0, 5.0, 3.0, 45.0, 1.0, cv(0, 0, 0));
    pair_case("default", 1.0 / 60, 1.0, 100.0, 2.0, 10.0, 10.0, 0.8, cv(0, 0, 0));
    pair_case("default", 1.0 / 60, 0.03, 0.2, 0.2, 1.0, 60.0, 1.0, cv(5e3, 2e3, -1e3));
}

/* ---- the rest of the step after a bounce ------------------------------------- */

/* A sphere (r 1, e 1) at speed u meets a static box `frac` of the way into a
 * step; it ends the step (1 - frac) u dt from the surface. */
static void reflection_case(const char *preset, double dt, double u, double frac)
{
    carom_world *w = world_for(preset, cv(0, 0, 0));
    add_surface(w, carom_shape_box(5, 5, 0.5), cv(0, 0, -0.5), 0.0, 1.0);
    /* one free step first, then the step of the impact */
    carom_body_id ball = add_ball(w, 1.0, 1.0, cv(0, 0, 1.0 + u * dt * (1.0 + frac)), cv(0, 0, -u), 0.0, 1.0);
    step_n(w, 2, dt);
    double want = 1.0 + (1.0 - frac) * u * dt;
    double z = position(w, ball).z;
    print_message("%s dt 1/%.0f %g m/s at %.2f of the step: z %.4f (exact %.4f)\n", preset, 1 / dt, u, frac, z, want);
    assert_true(fabs(z - want) <= 0.02 * want);
    assert_true(fabs(velocity(w, ball).z - u) <= 1e-9 * u);
    carom_world_destroy(w);
}

static void test_reflection_keeps_rest_of_step(void **state)
{
    (void)state;
    for (int p = 0; p < 3; p++) {
        reflection_case(PRESETS[p], 1.0 / 60, 60.0, 1.0 / 3.0);
        reflection_case(PRESETS[p], 1.0 / 60, 60.0, 0.1);
        reflection_case(PRESETS[p], 1.0 / 120, 60.0, 0.6);
        reflection_case(PRESETS[p], 1.0 / 30, 10.0, 0.5);
    }
}

/* ---- impacts that arrive together ------------------------------------------- */

/* Five touching balls, e = 1, no friction; the first moves into the others.
 * Momentum and energy together allow only one outcome for equal masses: the
 * last ball leaves at the impact speed, the rest stop. */
static void cradle_case(const char *preset, double r, double speed, double gap, int floor)
{
    carom_world *w = world_for(preset, floor ? cv(0, 0, -G) : cv(0, 0, 0));
    if (floor) add_surface(w, carom_shape_plane(0, 0, 1, 0), cv(0, 0, 0), 0.0, 0.0);
    carom_body_id ball[5];
    double z = floor ? r : 0.0;
    ball[0] = add_ball(w, r, 1.0, cv(-gap, 0, z), cv(speed, 0, 0), 0.0, 1.0);
    for (int i = 1; i < 5; i++) ball[i] = add_ball(w, r, 1.0, cv(2.0 * r * i, 0, z), cv(0, 0, 0), 0.0, 1.0);
    if (floor) step_n(w, 1, 1.0 / 60); /* the resting contacts exist before the impact */
    step_n(w, 60, 1.0 / 60);
    print_message("%s cradle r %g at %g m/s, gap %g%s:", preset, r, speed, gap, floor ? ", on a floor" : "");
    for (int i = 0; i < 5; i++) print_message(" %.4f", velocity(w, ball[i]).x / speed);
    print_message("\n");
    assert_true(velocity(w, ball[4]).x >= 0.95 * speed);
    for (int i = 0; i < 4; i++) assert_true(fabs(velocity(w, ball[i]).x) <= 0.05 * speed);
    carom_world_destroy(w);
}

static void test_touching_cradle(void **state)
{
    (void)state;
    for (int p = 0; p < 3; p++) {
        cradle_case(PRESETS[p], 0.1, 2.0, 0.2, 0);   /* all five touching, the first moving */
        cradle_case(PRESETS[p], 0.1, 2.0, 0.25, 0);  /* the striker arrives from a gap */
        cradle_case(PRESETS[p], 0.1, 2.0, 0.25, 1);  /* resting on a frictionless floor */
    }
    cradle_case("default", 1.0, 10.0, 2.0, 0);
    cradle_case("default", 0.02, 0.5, 0.04, 0);
}

/* A billiard break: 15 balls racked touching, the cue at 10 m/s, e = 1,
 * mu = 0, no gravity: kinetic energy within 1 %, momentum to 1e-9. */
static void break_case(const char *preset, double dt)
{
    const double r = 0.028575, m = 0.17;
    carom_world *w = world_for(preset, cv(0, 0, 0));
    add_ball(w, r, m, cv(-0.5, 0, 0), cv(10, 0, 0), 0.0, 1.0);
    for (int row = 0; row < 5; row++)
        for (int j = 0; j <= row; j++)
            add_ball(w, r, m, cv(row * sqrt(3.0) * r, (2.0 * j - row) * r, 0), cv(0, 0, 0), 0.0, 1.0);
    double e0, e1, pe;
    carom_vec3 P0, L0, P1, L1;
    carom_world_get_energy(w, &e0, &pe);
    carom_world_get_momentum(w, &P0, &L0);
    step_n(w, (int)(1.0 / dt), dt);
    carom_world_get_energy(w, &e1, &pe);
    carom_world_get_momentum(w, &P1, &L1);
    print_message("%s dt 1/%.0f break: energy kept %.5f, momentum error %.2e\n", preset, 1 / dt, e1 / e0,
                  len3(sub3(P1, P0)) / len3(P0));
    assert_true(fabs(e1 / e0 - 1.0) <= 0.01);
    assert_true(len3(sub3(P1, P0)) <= 1e-9 * len3(P0));
    carom_world_destroy(w);
}

static void test_billiard_break(void **state)
{
    (void)state;
    for (int p = 0; p < 3; p++) {
        break_case(PRESETS[p], 1.0 / 60);
        break_case(PRESETS[p], 1.0 / 240);
    }
    break_case("default", 1.0 / 30);
}

/* 125 elastic frictionless spheres in a closed box, no gravity, the default
 * settings (restitution threshold 1 m/s): energy within 1 % over 10 s. */
static void test_elastic_gas_default_settings(void **state)
{
    (void)state;
    carom_world *w = world_for("default", cv(0, 0, 0));
    const double L = 3.0;
    const double walls[6][3] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    for (int i = 0; i < 6; i++)
        add_surface(w, carom_shape_plane(walls[i][0], walls[i][1], walls[i][2], -L), cv(0, 0, 0), 0.0, 1.0);
    uint32_t rng = 11u;
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 5; j++)
            for (int k = 0; k < 5; k++) {
                double v[3];
                for (int c = 0; c < 3; c++) {
                    rng = rng * 1664525u + 1013904223u;
                    v[c] = 3.0 * ((double)(rng >> 8) / 16777216.0 - 0.5);
                }
                add_ball(w, 0.3, 1.0, cv(-2.4 + 1.2 * i, -2.4 + 1.2 * j, -2.4 + 1.2 * k), cv(v[0], v[1], v[2]), 0.0,
                         1.0);
            }
    double e0, e1, pe;
    carom_world_get_energy(w, &e0, &pe);
    step_n(w, 600, 1.0 / 60);
    carom_world_get_energy(w, &e1, &pe);
    print_message("elastic gas, default settings: energy kept %.5f over 10 s\n", e1 / e0);
    assert_true(fabs(e1 / e0 - 1.0) <= 0.01);
    carom_world_destroy(w);
}

/* ---- the closing speed from every force ------------------------------------- */

/* A ball (e = 1) dropped from h, once under world gravity and once with
 * gravity off and m g applied with apply_force every step: the same rebound
 * apex, within 1 %, and both near h. */
static double force_bounce_apex(const char *preset, int by_force, double h, double dt)
{
    carom_world *w = world_for(preset, by_force ? cv(0, 0, 0) : cv(0, 0, -G));
    add_surface(w, carom_shape_plane(0, 0, 1, 0), cv(0, 0, 0), 0.0, 1.0);
    const double r = 0.1, m = 2.0;
    carom_body_id ball = add_ball(w, r, m, cv(0, 0, h + r), cv(0, 0, 0), 0.0, 1.0);
    int bounced = 0;
    double apex = 0.0;
    for (int i = 0; i < (int)(5.0 / dt); i++) {
        if (by_force) assert_int_equal(carom_body_apply_force(w, ball, cv(0, 0, -m * G)), CAROM_OK);
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        carom_vec3 p = position(w, ball), v = velocity(w, ball);
        if (v.z > 0) bounced = 1;
        if (bounced) {
            if (p.z - r > apex) apex = p.z - r;
            if (v.z < 0) break;
        }
    }
    assert_true(bounced);
    carom_world_destroy(w);
    return apex;
}

static void test_force_driven_bounce(void **state)
{
    (void)state;
    const double dts[2] = {1.0 / 60, 1.0 / 30};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 2; k++) {
            double h = 6.0;
            double by_gravity = force_bounce_apex(PRESETS[p], 0, h, dts[k]);
            double by_force = force_bounce_apex(PRESETS[p], 1, h, dts[k]);
            print_message("%s dt 1/%.0f: apex %.4f by gravity, %.4f by force (dropped from %g)\n", PRESETS[p],
                          1 / dts[k], by_gravity, by_force, h);
            CHECK_REL(by_force, by_gravity, 0.01, "apex by force against by gravity");
            CHECK_REL(by_gravity, h, 0.03, "apex against the drop height (e = 1)");
        }
}

/* ---- bounces at large steps ------------------------------------------------- */

/* e = 0.5 from 1 m: the rebound rises e^2 h = 0.25 m (sampled at step ends):
 * within 3 % at dt 1/30 and 5 % at 1/15, at every preset. */
static double drop_apex(const char *preset, double dt, double h, double r)
{
    carom_world *w = world_for(preset, cv(0, 0, -G));
    add_surface(w, carom_shape_plane(0, 0, 1, 0), cv(0, 0, 0), 0.0, 0.5);
    carom_body_id ball = add_ball(w, r, 1.0, cv(0, 0, h + r), cv(0, 0, 0), 0.0, 0.5);
    int bounced = 0;
    double apex = 0.0;
    for (int i = 0; i < (int)(4.0 / dt); i++) {
        assert_int_equal(carom_world_step(w, dt), CAROM_OK);
        carom_vec3 p = position(w, ball), v = velocity(w, ball);
        if (v.z > 0) bounced = 1;
        if (bounced) {
            if (p.z - r > apex) apex = p.z - r;
            if (v.z < 0) break;
        }
    }
    assert_true(bounced);
    carom_world_destroy(w);
    return apex;
}

static void test_large_step_bounce(void **state)
{
    (void)state;
    for (int p = 0; p < 3; p++) {
        double a30 = drop_apex(PRESETS[p], 1.0 / 30, 1.0, 0.1), a15 = drop_apex(PRESETS[p], 1.0 / 15, 1.0, 0.1);
        print_message("%s: apex %.4f at dt 1/30, %.4f at dt 1/15 (e^2 h = 0.25)\n", PRESETS[p], a30, a15);
        CHECK_REL(a30, 0.25, 0.03, "apex at dt 1/30");
        CHECK_REL(a15, 0.25, 0.05, "apex at dt 1/15");
    }
    /* other heights and sizes at dt 1/30 */
    CHECK_REL(drop_apex("default", 1.0 / 30, 4.0, 0.5), 1.0, 0.03, "apex from 4 m, r 0.5");
    CHECK_REL(drop_apex("default", 1.0 / 30, 0.5, 0.02), 0.125, 0.03, "apex from 0.5 m, r 0.02");
}

/* ---- every shape pair ------------------------------------------------------- */

/* A body landing flat (face, side or lying capsule) on a plane or on a static
 * box, frictionless, e = 0.5, no gravity: all its contact points meet at once,
 * so it leaves at e vn straight up without turning, for every shape pair. */
static void test_flat_landings_every_shape(void **state)
{
    (void)state;
    const carom_shape_def shapes[4] = {carom_shape_box(0.4, 0.3, 0.2), carom_shape_cylinder(0.3, 0.2),
                                       carom_shape_capsule(0.2, 0.4), carom_shape_sphere(0.25)};
    /* half heights above the ground; the capsule lies along x */
    const double half[4] = {0.2, 0.2, 0.2, 0.25};
    for (int ground = 0; ground < 2; ground++)
        for (int k = 0; k < 4; k++)
            for (int p = 0; p < 3; p++) {
                carom_world *w = world_for(PRESETS[p], cv(0, 0, 0));
                if (ground == 0) add_surface(w, carom_shape_plane(0, 0, 1, 0), cv(0, 0, 0), 0.0, 0.5);
                else add_surface(w, carom_shape_box(3, 3, 0.5), cv(0, 0, -0.5), 0.0, 0.5);
                carom_body_def d = carom_body_def_default();
                d.shape = shapes[k];
                d.mass = 2.0;
                d.friction = 0.0;
                d.restitution = 0.5;
                /* the cylinder's axis is z: standing on its face; the capsule's is z: lay it along x */
                if (k == 2) { d.orientation.w = sqrt(0.5); d.orientation.y = sqrt(0.5); d.orientation.x = d.orientation.z = 0; }
                double h = k == 2 ? 0.2 : half[k];
                d.position = cv(0, 0, h + 2.0 * (1.0 / 60) * 3.3);
                d.linear_velocity = cv(0, 0, -2.0);
                carom_body_id id = carom_body_create(w, &d);
                assert_false(carom_body_id_is_null(id));
                step_n(w, 10, 1.0 / 60);
                carom_vec3 v = velocity(w, id), av = spin(w, id);
                print_message("%s shape %d on %s: v (%.5f %.5f %.5f), |w| %.2e\n", PRESETS[p], k,
                              ground ? "a box" : "a plane", v.x, v.y, v.z, len3(av));
                assert_true(fabs(v.z - 1.0) <= 0.02);
                assert_true(fabs(v.x) <= 1e-6 && fabs(v.y) <= 1e-6);
                /* not turning: the rim moves at under 1e-5 of the rebound speed */
                assert_true(len3(av) * 0.4 <= 1e-5 * 1.0);
                carom_world_destroy(w);
            }
}

/* ---- the hit event's own threshold ------------------------------------------- */

/* A plastic ball (e = 0) dropped from 0.1 m meets the floor at sqrt(2 g h) =
 * 1.40 m/s: a hit event exactly when hit_event_threshold is below that,
 * whatever restitution_threshold says. */
static int hits_for(double hit_threshold, double restitution_threshold, double *approach)
{
    carom_world_def wd = carom_world_def_default();
    wd.hit_event_threshold = hit_threshold;
    wd.restitution_threshold = restitution_threshold;
    carom_world *w = carom_world_create(&wd);
    assert_non_null(w);
    add_surface(w, carom_shape_plane(0, 0, 1, 0), cv(0, 0, 0), 0.5, 0.0);
    add_ball(w, 0.1, 1.0, cv(0, 0, 0.2), cv(0, 0, 0), 0.5, 0.0);
    int hits = 0;
    for (int i = 0; i < 60; i++) {
        assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
        const carom_contact_event *ev;
        int n = carom_world_get_events(w, &ev);
        for (int k = 0; k < n; k++)
            if (ev[k].type == CAROM_EVENT_HIT) {
                hits++;
                *approach = ev[k].approach_speed;
            }
    }
    carom_world_destroy(w);
    return hits;
}

static void test_hit_event_threshold_is_its_own_setting(void **state)
{
    (void)state;
    double want = sqrt(2 * G * 0.1), approach = 0.0;
    assert_int_equal(hits_for(1.0, 1.0, &approach), 1);
    CHECK_REL(approach, want, 0.02, "hit approach speed");
    assert_int_equal(hits_for(1.0, 5.0, &approach), 1);
    assert_int_equal(hits_for(1.0, 0.0, &approach), 1);
    assert_int_equal(hits_for(2.0, 0.0, &approach), 0);
    assert_int_equal(hits_for(2.0, 1.0, &approach), 0);
    carom_world_def wd = carom_world_def_default();
    wd.hit_event_threshold = -1.0;
    assert_int_equal(carom_world_def_check(&wd, NULL, 0), CAROM_ERROR_INVALID_ARGUMENT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_oblique_ball_sliding_and_sticking),
        cmocka_unit_test(test_off_centre_pair),
        cmocka_unit_test(test_reflection_keeps_rest_of_step),
        cmocka_unit_test(test_touching_cradle),
        cmocka_unit_test(test_billiard_break),
        cmocka_unit_test(test_elastic_gas_default_settings),
        cmocka_unit_test(test_force_driven_bounce),
        cmocka_unit_test(test_large_step_bounce),
        cmocka_unit_test(test_hit_event_threshold_is_its_own_setting),
        cmocka_unit_test(test_flat_landings_every_shape),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
