/* helpers.h - what every C test shares. For all tests: PI_, G, DT and
 * EXPECT_NEAR, which prints every value it checks. For tests of the public
 * API (carom/carom.h included first): worlds (from a def, a preset, without
 * gravity), a ground, bodies (each creation asserted), positions and
 * velocities read back, stepping. Include after cmocka.h. */
#ifndef CAROM_TEST_HELPERS_H
#define CAROM_TEST_HELPERS_H

#include <math.h>
#include <stdint.h>

#define G 9.81
#define DT (1.0 / 60.0)
#define PI_ 3.14159265358979323846

#define EXPECT_NEAR(got, want, tol, what)                                                          \
    do {                                                                                           \
        double g_ = (got), w_ = (want);                                                           \
        print_message("%s: %.6f (expected %.6f)\n", (what), g_, w_);                             \
        if (!(fabs(g_ - w_) <= (tol))) {                                                          \
            print_error("%s: got %.6f, expected %.6f (tolerance %.6f)\n", (what), g_, w_, (double)(tol)); \
            fail();                                                                                \
        }                                                                                          \
    } while (0)

/* xorshift64: the state is passed around, never global */
static inline uint64_t xorshift64(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* uniform in [0, 1) from the top 53 bits */
static inline double rnd(uint64_t *s) { return (double)(xorshift64(s) >> 11) / 9007199254740992.0; }

/* silent unless they fail: |got - want| within rel |want|, within tol */
static inline void check_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want))) {
        print_error("%s: got %.9g, expected %.9g (rel %.3g)\n", what, got, want, rel);
        fail();
    }
}

static inline void check_abs(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) {
        print_error("%s: got %.9g, expected %.9g (abs %.3g)\n", what, got, want, tol);
        fail();
    }
}

#ifdef CAROM_CAROM_H

static inline carom_vec3 vec(double x, double y, double z) { carom_vec3 v = {x, y, z}; return v; }

static inline carom_world *world_with(carom_world_def d, int ground, double ground_mu, double ground_e)
{
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    if (ground) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(0, 0, 1, 0);
        g.friction = ground_mu;
        g.restitution = ground_e;
        assert_false(carom_body_id_is_null(carom_body_create(w, &g)));
    }
    return w;
}

/* a preset's def (fast, default, accurate), asserted */
static inline carom_world_def preset_def(const char *preset)
{
    carom_world_def d = carom_world_def_default();
    assert_int_equal(carom_world_def_apply_preset(&d, preset), CAROM_OK);
    return d;
}

/* a world at a preset, with or without gravity, no ground */
static inline carom_world *world_preset(const char *preset, int gravity)
{
    carom_world_def d = preset_def(preset);
    if (!gravity) d.gravity = vec(0, 0, 0);
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    return w;
}

/* the default world, no ground */
static inline carom_world *world_default(void) { return world_with(carom_world_def_default(), 0, 0.0, 0.0); }

/* the default world without gravity */
static inline carom_world *world_no_gravity(void)
{
    carom_world_def d = carom_world_def_default();
    d.gravity = vec(0, 0, 0);
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    return w;
}

/* any body from its def, asserted */
static inline carom_body_id add_body(carom_world *w, const carom_body_def *d)
{
    carom_body_id id = carom_body_create(w, d);
    assert_false(carom_body_id_is_null(id));
    return id;
}

/* a static body of any shape at p */
static inline carom_body_id add_static(carom_world *w, carom_shape_def shape, carom_vec3 p)
{
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = shape;
    g.position = p;
    return add_body(w, &g);
}

/* the ground plane z = 0 with the default friction and restitution */
static inline carom_body_id add_ground(carom_world *w)
{
    return add_static(w, carom_shape_plane(0, 0, 1, 0), vec(0, 0, 0));
}

/* a sphere of radius r at (x, y, z), density 1 */
static inline carom_body_id add_sphere(carom_world *w, double x, double y, double z, double r)
{
    carom_body_def d = carom_body_def_default();
    d.position = vec(x, y, z);
    d.shape = carom_shape_sphere(r);
    return add_body(w, &d);
}

static inline carom_body_id add_box(carom_world *w, double x, double y, double z, double he, double mass, double mu)
{
    carom_body_def d = carom_body_def_default();
    d.position = vec(x, y, z);
    d.shape = carom_shape_box(he, he, he);
    d.mass = mass;
    d.friction = mu;
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    return id;
}

static inline carom_vec3 pos(carom_world *w, carom_body_id id)
{
    carom_vec3 p;
    assert_int_equal(carom_body_get_position(w, id, &p), CAROM_OK);
    return p;
}

static inline carom_vec3 vel(carom_world *w, carom_body_id id)
{
    carom_vec3 v;
    assert_int_equal(carom_body_get_linear_velocity(w, id, &v), CAROM_OK);
    return v;
}

static inline void step_n(carom_world *w, int n, double dt)
{
    for (int i = 0; i < n; i++) assert_int_equal(carom_world_step(w, dt), CAROM_OK);
}

#endif /* CAROM_CAROM_H */

#endif
