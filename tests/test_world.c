/* test_world.c - the foundation: ids with generations, the dense body store
 * against a reference model, mass properties through the public API, and
 * every rejection path leaving the world exactly as it was. */
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
#include "world.h"

static void test_version_and_status(void **state)
{
    (void)state;
    /* the header's numbers are the one place the version is written */
    char expected[64];
    snprintf(expected, sizeof expected, "%d.%d.%d", CAROM_VERSION_MAJOR, CAROM_VERSION_MINOR, CAROM_VERSION_PATCH);
    assert_string_equal(carom_version(), expected);
    assert_string_equal(carom_status_string(CAROM_OK), "ok");
    assert_non_null(strstr(carom_status_string(CAROM_ERROR_STALE_ID), "stale"));
}

/* The reason is the message after the failing function's name, for a name
 * written in the format ("body_set_friction: ...") and one passed as its
 * first argument ("%s: ..." with fn), for every failing call below; a new
 * world has neither, a NULL world says so. */
static void expect_reason(const carom_world *w, const char *name, const char *words)
{
    const char *msg = carom_world_last_error(w), *reason = carom_world_last_error_reason(w);
    size_t n = strlen(name);
    if (strncmp(msg, name, n) != 0 || msg[n] != ':') fail_msg("message '%s' does not begin with %s:", msg, name);
    assert_string_equal(reason, msg + n + 2);
    assert_non_null(strstr(reason, words));
}

static void test_last_error_reason(void **state)
{
    (void)state;
    carom_world *w = world_default();
    assert_string_equal(carom_world_last_error_reason(w), "");
    assert_string_equal(carom_world_last_error_reason(NULL), "world is NULL");
    carom_body_id ball = add_sphere(w, 0, 0, 1, 0.5);
    assert_int_equal(carom_body_set_friction(w, ball, -1), CAROM_ERROR_INVALID_ARGUMENT);
    expect_reason(w, "body_set_friction", "friction");
    carom_body_def d = carom_body_def_default();
    d.shape = carom_shape_sphere(-1); /* shape_def_check's "%s: %s" with fn "body_create" */
    assert_true(carom_body_id_is_null(carom_body_create(w, &d)));
    expect_reason(w, "body_create", "sphere radius -1 is outside");
    carom_vec3 p;
    carom_body_id stale = ball;
    stale.generation += 1; /* the id lookup's "%s: ..." */
    assert_int_equal(carom_body_get_position(w, stale, &p), CAROM_ERROR_STALE_ID);
    expect_reason(w, "body_get_position", "");
    assert_int_equal(carom_world_step(w, 2.0), CAROM_ERROR_INVALID_ARGUMENT);
    expect_reason(w, "step", "dt");
    /* a success leaves the last failure as it was */
    assert_int_equal(carom_body_get_position(w, ball, &p), CAROM_OK);
    expect_reason(w, "step", "dt");
    carom_world_destroy(w);
}

static void test_id_generations(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.0, 0.0);
    carom_body_id a = add_sphere(w, 0, 0, 1, 0.5);
    assert_false(carom_body_id_is_null(a));
    assert_true(carom_body_is_valid(w, a));
    assert_int_equal(carom_body_destroy(w, a), CAROM_OK);
    assert_false(carom_body_is_valid(w, a));
    /* the slot is reused with a new generation: the old id stays invalid */
    carom_body_id b = add_sphere(w, 1, 0, 1, 0.5);
    assert_int_equal(b.index1, a.index1);
    assert_int_not_equal(b.generation, a.generation);
    assert_false(carom_body_is_valid(w, a));
    assert_true(carom_body_is_valid(w, b));
    carom_vec3 p;
    assert_int_equal(carom_body_get_position(w, a, &p), CAROM_ERROR_STALE_ID);
    assert_non_null(strstr(carom_world_last_error(w), "destroyed"));
    assert_int_equal(carom_body_destroy(w, a), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_position(w, b, &p), CAROM_OK);
    assert_true(fabs(p.x - 1) < 1e-15);
    /* packing round-trips; the null id is never valid */
    assert_true(carom_body_id_equal(carom_body_id_unpack(carom_body_id_pack(b)), b));
    assert_false(carom_body_is_valid(w, carom_null_body()));
    carom_body_id forged = {999, 1};
    assert_false(carom_body_is_valid(w, forged));
    carom_world_destroy(w);
}

/* Thousands of random creates and destroys against a plain reference model. */
static void test_store_stays_dense(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.0, 0.0);
    enum { N = 4000 };
    carom_body_id *ids = calloc(N, sizeof *ids);
    double *xs = calloc(N, sizeof *xs);
    int *alive = calloc(N, sizeof *alive);
    carom_body_id *dead = calloc(N, sizeof *dead);
    int created = 0, live = 0, ndead = 0;
    uint64_t rng = 0x9E3779B97F4A7C15ULL;
    for (int op = 0; op < 12000; op++) {
        rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
        int destroy = live > 0 && (rng % 100) < 45;
        if (destroy || created == N) {
            if (live == 0) continue;
            int k = (int)((rng >> 8) % (uint64_t)created);
            while (!alive[k]) k = (k + 1) % created;
            assert_int_equal(carom_body_destroy(w, ids[k]), CAROM_OK);
            alive[k] = 0;
            dead[ndead++] = ids[k];
            live--;
        } else {
            xs[created] = (double)op;
            ids[created] = add_sphere(w, xs[created], 0, 0, 0.5);
            assert_false(carom_body_id_is_null(ids[created]));
            alive[created++] = 1;
            live++;
        }
        if (op % 500 == 0 || op == 11999) {
            assert_int_equal(carom_world_body_count(w), live);
            const body_store *s = &w->bodies;
            for (int slot = 0; slot < s->count; slot++)
                assert_int_equal(s->ids[s->id_index[slot]].slot, slot); /* dense, consistent */
            for (int k = 0; k < created; k++) {
                carom_vec3 p;
                if (alive[k]) {
                    assert_int_equal(carom_body_get_position(w, ids[k], &p), CAROM_OK);
                    assert_true(p.x == xs[k]);
                } else {
                    assert_false(carom_body_is_valid(w, ids[k]));
                }
            }
            for (int k = 0; k < ndead; k++) assert_false(carom_body_is_valid(w, dead[k]));
        }
    }
    free(ids); free(xs); free(alive); free(dead);
    carom_world_destroy(w);
}

static void inertia_of(carom_world *w, carom_shape_def sh, double mass, double out[9], double *m)
{
    carom_body_def d = carom_body_def_default();
    d.shape = sh;
    d.mass = mass;
    carom_body_id id = carom_body_create(w, &d);
    assert_false(carom_body_id_is_null(id));
    assert_int_equal(carom_body_get_mass(w, id, m), CAROM_OK);
    assert_int_equal(carom_body_get_inertia(w, id, out), CAROM_OK);
}

static void assert_close(double a, double b, double rel)
{
    if (!(fabs(a - b) <= rel * fmax(fabs(a), fabs(b)) + 1e-300)) {
        print_error("expected %.15g got %.15g\n", b, a);
        fail();
    }
}

static void test_mass_properties(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.0, 0.0);
    double I[9], m;
    inertia_of(w, carom_shape_sphere(0.3), 2.0, I, &m);
    assert_close(m, 2.0, 1e-14);
    assert_close(I[0], 0.4 * 2.0 * 0.09, 1e-12);
    assert_close(I[4], I[0], 1e-12);
    inertia_of(w, carom_shape_box(0.5, 1.0, 1.5), 3.0, I, &m);
    assert_close(I[0], 3.0 * (4.0 + 9.0) / 12.0, 1e-12);   /* m (b^2 + c^2) / 12, full extents */
    assert_close(I[4], 3.0 * (1.0 + 9.0) / 12.0, 1e-12);
    assert_close(I[8], 3.0 * (1.0 + 4.0) / 12.0, 1e-12);
    assert_true(fabs(I[1]) < 1e-12);
    inertia_of(w, carom_shape_cylinder(0.5, 1.0), 4.0, I, &m);
    assert_close(I[8], 4.0 * 0.25 / 2.0, 1e-12);             /* m r^2 / 2 about the axis */
    assert_close(I[0], 4.0 * (3 * 0.25 + 4.0) / 12.0, 1e-12); /* m (3 r^2 + h^2) / 12 */
    /* density: a 1 m cube of water is 1000 kg */
    {
        carom_body_def d = carom_body_def_default();
        d.shape = carom_shape_box(0.5, 0.5, 0.5);
        d.density = 1000;
        carom_body_id id = carom_body_create(w, &d);
        assert_int_equal(carom_body_get_mass(w, id, &m), CAROM_OK);
        assert_close(m, 1000.0, 1e-12);
    }
    /* hull of a cube's corners equals the box */
    {
        double pts[24];
        int k = 0;
        for (int i = 0; i < 8; i++) {
            pts[k++] = (i & 1) ? 0.5 : -0.5;
            pts[k++] = (i & 2) ? 1.0 : -1.0;
            pts[k++] = (i & 4) ? 1.5 : -1.5;
        }
        double Ib[9], mb;
        inertia_of(w, carom_shape_hull(pts, 8), 3.0, I, &m);
        inertia_of(w, carom_shape_box(0.5, 1.0, 1.5), 3.0, Ib, &mb);
        for (int i = 0; i < 9; i++) assert_true(fabs(I[i] - Ib[i]) < 1e-12);
    }
    /* static bodies report no mass */
    {
        carom_body_def d = carom_body_def_default();
        d.type = CAROM_BODY_STATIC;
        d.shape = carom_shape_plane(0, 0, 1, 0);
        carom_body_id id = carom_body_create(w, &d);
        assert_false(carom_body_id_is_null(id));
        assert_int_equal(carom_body_get_mass(w, id, &m), CAROM_OK);
        assert_true(m == 0.0);
    }
    carom_world_destroy(w);
}

/* ---- rejection paths ----------------------------------------------------- */

typedef struct snapshot {
    int count;
    double data[64][13];
} snapshot;

static void take(carom_world *w, carom_body_id *ids, int n, snapshot *s)
{
    memset(s, 0, sizeof *s);
    s->count = carom_world_body_count(w);
    for (int i = 0; i < n; i++) {
        carom_vec3 p, v, av;
        carom_quat q;
        assert_int_equal(carom_body_get_position(w, ids[i], &p), CAROM_OK);
        assert_int_equal(carom_body_get_linear_velocity(w, ids[i], &v), CAROM_OK);
        assert_int_equal(carom_body_get_angular_velocity(w, ids[i], &av), CAROM_OK);
        assert_int_equal(carom_body_get_orientation(w, ids[i], &q), CAROM_OK);
        double row[13] = {p.x, p.y, p.z, v.x, v.y, v.z, av.x, av.y, av.z, q.w, q.x, q.y, q.z};
        memcpy(s->data[i], row, sizeof row);
    }
}

static void expect_unchanged(carom_world *w, carom_body_id *ids, int n, const snapshot *before, const char *what)
{
    snapshot after;
    take(w, ids, n, &after);
    if (memcmp(before, &after, sizeof after) != 0) {
        print_error("world changed after rejected call: %s\n", what);
        fail();
    }
    if (strlen(carom_world_last_error(w)) == 0) {
        print_error("no error message after: %s\n", what);
        fail();
    }
}

static void test_rejections_leave_world_unchanged(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.0, 0.0);
    carom_body_id ids[3];
    ids[0] = add_sphere(w, 0, 0, 1, 0.5);
    ids[1] = add_sphere(w, 2, 0, 1, 0.5);
    {
        carom_body_def d = carom_body_def_default();
        d.type = CAROM_BODY_STATIC;
        d.shape = carom_shape_box(5, 5, 0.5);
        ids[2] = carom_body_create(w, &d);
    }
    carom_body_id stale = add_sphere(w, 9, 9, 9, 0.5);
    carom_body_destroy(w, stale);
    snapshot s0;
    take(w, ids, 3, &s0);
    const double nan = NAN, inf = INFINITY;

#define REJECT_DEF(field_stmt, label)                                                    \
    do {                                                                                 \
        carom_body_def d = carom_body_def_default();                                     \
        field_stmt;                                                                      \
        carom_body_id id = carom_body_create(w, &d);                                     \
        assert_true(carom_body_id_is_null(id));                                          \
        expect_unchanged(w, ids, 3, &s0, label);                                         \
    } while (0)

    REJECT_DEF(d.position.x = nan, "NaN position");
    REJECT_DEF(d.position.z = inf, "inf position");
    REJECT_DEF(d.linear_velocity.y = nan, "NaN velocity");
    REJECT_DEF(d.angular_velocity.x = -inf, "inf angular velocity");
    REJECT_DEF(d.orientation.w = 2.0, "non-unit quaternion");
    REJECT_DEF((d.orientation.w = 0.0, d.orientation.x = 0.0), "zero quaternion");
    REJECT_DEF(d.orientation.y = nan, "NaN quaternion");
    REJECT_DEF(d.mass = -1.0, "negative mass");
    REJECT_DEF((d.mass = 0.0, d.density = 0.0), "zero mass and density on a dynamic body");
    REJECT_DEF(d.density = nan, "NaN density");
    REJECT_DEF(d.shape = carom_shape_sphere(0.0), "zero radius");
    REJECT_DEF(d.shape = carom_shape_sphere(-1.0), "negative radius");
    REJECT_DEF(d.shape = carom_shape_box(1, -1, 1), "negative box extent");
    REJECT_DEF(d.shape = carom_shape_box(1, 0, 1), "zero box extent");
    REJECT_DEF(d.shape = carom_shape_capsule(0.5, -0.1), "negative capsule height");
    REJECT_DEF(d.shape = carom_shape_cylinder(nan, 1), "NaN cylinder radius");
    REJECT_DEF(d.shape = carom_shape_plane(0, 0, 1, 0), "dynamic plane");
    REJECT_DEF((d.type = CAROM_BODY_STATIC, d.shape = carom_shape_plane(0, 0, 0, 0)), "zero plane normal");
    REJECT_DEF(d.shape = carom_shape_hull(NULL, 8), "NULL hull points");
    {
        static const double flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.5, 0};
        REJECT_DEF(d.shape = carom_shape_hull(flat, 5), "coplanar hull");
    }
    {
        /* a hull finer than the narrowphase holds (points on a sphere) is refused, not ignored */
        double ball[3 * 2000];
        for (int i = 0; i < 2000; i++) {
            double z = 1.0 - 2.0 * (i + 0.5) / 2000, r = sqrt(1 - z * z), a = 2.399963229728653 * i;
            ball[3 * i] = r * cos(a); ball[3 * i + 1] = r * sin(a); ball[3 * i + 2] = z;
        }
        REJECT_DEF(d.shape = carom_shape_hull(ball, 2000), "hull with too many vertices");
    }
    REJECT_DEF(d.friction = -0.1, "negative friction");
    REJECT_DEF(d.restitution = 1.5, "restitution above 1");
    REJECT_DEF(d.type = (carom_body_type)7, "unknown body type");
    REJECT_DEF(d.shape.type = (carom_shape_type)42, "unknown shape type");
    REJECT_DEF(d.size = 4, "tiny def size");
    assert_true(carom_body_id_is_null(carom_body_create(w, NULL)));
    expect_unchanged(w, ids, 3, &s0, "NULL def");

    carom_vec3 bad = {nan, 0, 0}, ok = {1, 2, 3};
    carom_quat badq = {0.5, 0, 0, 0};
    assert_int_equal(carom_body_set_position(w, ids[0], bad), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "set_position NaN");
    assert_int_equal(carom_body_set_linear_velocity(w, ids[0], bad), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "set_linear_velocity NaN");
    assert_int_equal(carom_body_set_angular_velocity(w, ids[0], bad), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "set_angular_velocity NaN");
    assert_int_equal(carom_body_set_orientation(w, ids[0], badq), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "set_orientation non-unit");
    assert_int_equal(carom_body_apply_impulse(w, ids[0], bad, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "apply_impulse NaN");
    assert_int_equal(carom_body_apply_impulse(w, ids[0], ok, &bad), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "apply_impulse NaN point");
    assert_int_equal(carom_body_set_mass(w, ids[0], -2.0), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_mass(w, ids[0], nan), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_friction(w, ids[0], -1), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_restitution(w, ids[0], 2), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_gravity_scale(w, ids[0], inf), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_type(w, ids[0], (carom_body_type)9), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_set_linear_velocity(w, ids[2], ok), CAROM_ERROR_UNSUPPORTED);
    expect_unchanged(w, ids, 3, &s0, "setters with bad values");

    /* stale ids on every entry */
    carom_vec3 v;
    carom_quat q;
    double x, I[9];
    carom_body_type t;
    assert_int_equal(carom_body_get_position(w, stale, &v), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_orientation(w, stale, &q), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_linear_velocity(w, stale, &v), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_angular_velocity(w, stale, &v), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_mass(w, stale, &x), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_inertia(w, stale, I), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_get_type(w, stale, &t), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_set_position(w, stale, ok), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_set_linear_velocity(w, stale, ok), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_set_angular_velocity(w, stale, ok), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_apply_impulse(w, stale, ok, NULL), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_set_mass(w, stale, 1.0), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_set_type(w, stale, CAROM_BODY_STATIC), CAROM_ERROR_STALE_ID);
    assert_int_equal(carom_body_destroy(w, stale), CAROM_ERROR_STALE_ID);
    assert_null(carom_body_get_user_data(w, stale));
    expect_unchanged(w, ids, 3, &s0, "stale ids");

    /* NULL outputs and NULL worlds */
    assert_int_equal(carom_body_get_position(w, ids[0], NULL), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_body_get_position(NULL, ids[0], &v), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_step(NULL, 0.01), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_get_energy(w, NULL, NULL), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_step(w, nan), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_step(w, -1.0 / 60), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_step(w, 0.0), CAROM_ERROR_INVALID_ARGUMENT);
    expect_unchanged(w, ids, 3, &s0, "NULL outputs and bad dt");
    carom_world_destroy(w);
}

static void test_world_def_validation(void **state)
{
    (void)state;
    char msg[256];
    carom_world_def d = carom_world_def_default();
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_OK);
    d.substeps = 0;
    assert_int_equal(carom_world_def_check(&d, msg, sizeof msg), CAROM_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "substeps"));
    assert_null(carom_world_create(&d));
    d = carom_world_def_default();
    d.gravity.z = NAN;
    assert_null(carom_world_create(&d));
    d = carom_world_def_default();
    d.contact_hertz = -1;
    assert_null(carom_world_create(&d));
    assert_null(carom_world_create(NULL));
    /* an older caller's smaller def: missing fields take their defaults */
    d = carom_world_def_default();
    d.size = (uint32_t)offsetof(carom_world_def, relax_iterations);
    d.substeps = 2;
    carom_world *w = carom_world_create(&d);
    assert_non_null(w);
    carom_world_def got = carom_world_def_default();
    assert_int_equal(carom_world_get_def(w, &got), CAROM_OK);
    assert_int_equal(got.substeps, 2);
    assert_int_equal(got.relax_iterations, 1);
    /* presets by name, and a bad name rejected */
    carom_world_def p = carom_world_def_default();
    assert_int_equal(carom_world_def_apply_preset(&p, "accurate"), CAROM_OK);
    assert_true(p.substeps > carom_world_def_default().substeps);
    assert_int_equal(carom_world_def_apply_preset(&p, "turbo"), CAROM_ERROR_INVALID_ARGUMENT);
    /* set_def validates too and keeps the old settings on error */
    carom_world_def bad = carom_world_def_default();
    bad.iterations = -3;
    assert_int_equal(carom_world_set_def(w, &bad), CAROM_ERROR_INVALID_ARGUMENT);
    assert_int_equal(carom_world_get_def(w, &got), CAROM_OK);
    assert_int_equal(got.substeps, 2);
    carom_world_destroy(w);
}

typedef struct callback_probe {
    carom_world *w;
    int calls, create_refused, step_refused, destroy_ok, world_destroy_refused;
    carom_body_id victim;
} callback_probe;

static void on_event(void *ctx, const carom_contact_event *e)
{
    callback_probe *p = ctx;
    (void)e;
    p->calls++;
    carom_body_def d = carom_body_def_default();
    if (carom_body_id_is_null(carom_body_create(p->w, &d))) p->create_refused++;
    if (carom_world_step(p->w, 0.01) == CAROM_ERROR_LOCKED) p->step_refused++;
    if (carom_body_destroy(p->w, p->victim) == CAROM_OK) p->destroy_ok++;
    carom_world_destroy(p->w); /* refused: the world is inside its step */
    if (strstr(carom_world_last_error(p->w), "inside its step")) p->world_destroy_refused++;
}

static void test_mutation_inside_callback(void **state)
{
    (void)state;
    callback_probe probe;
    memset(&probe, 0, sizeof probe);
    carom_world_def d = carom_world_def_default();
    d.event_callback = on_event;
    d.event_context = &probe;
    carom_world *w = carom_world_create(&d);
    probe.w = w;
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &g);
    carom_body_id ball = add_sphere(w, 0, 0, 0.6, 0.5);
    probe.victim = ball;
    for (int i = 0; i < 30 && probe.calls == 0; i++) assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    assert_true(probe.calls > 0);
    assert_int_equal(probe.create_refused, probe.calls);
    assert_int_equal(probe.step_refused, probe.calls);
    assert_int_equal(probe.world_destroy_refused, probe.calls);
    /* the destroy was deferred to the end of the step, and happened */
    assert_true(probe.destroy_ok > 0);
    assert_false(carom_body_is_valid(w, ball));
    assert_int_equal(carom_world_body_count(w), 1);
    assert_int_equal(carom_world_step(w, 1.0 / 60), CAROM_OK);
    carom_world_destroy(w);
}

/* Ray casts return the closest hit; AABB queries count exactly the overlapping bodies. */
static void test_queries(void **state)
{
    (void)state;
    carom_world *w = world_with(carom_world_def_default(), 0, 0.0, 0.0);
    carom_body_def d = carom_body_def_default();
    d.type = CAROM_BODY_STATIC;
    d.position.x = 5;
    d.shape = carom_shape_box(1, 1, 1);
    carom_body_id near_box = carom_body_create(w, &d);
    d.position.x = 9;
    d.shape = carom_shape_sphere(1);
    carom_body_create(w, &d);
    carom_vec3 o = {0, 0, 0}, t = {20, 0, 0};
    carom_ray_hit hit;
    assert_int_equal(carom_world_ray_cast(w, o, t, &hit), 1);
    assert_true(carom_body_id_equal(hit.body, near_box));
    assert_true(fabs(hit.fraction - 0.2) < 1e-12 && fabs(hit.point.x - 4) < 1e-12 && hit.normal.x == -1);
    carom_vec3 up = {0, 0, 20};
    assert_int_equal(carom_world_ray_cast(w, o, up, &hit), 0);
    carom_vec3 bad = {NAN, 0, 0};
    assert_int_equal(carom_world_ray_cast(w, bad, t, &hit), -1);
    assert_int_equal(carom_world_ray_cast(w, o, t, NULL), -1);
    carom_vec3 lo = {3.5, -0.5, -0.5}, hi = {9.5, 0.5, 0.5};
    carom_body_id ids[4];
    assert_int_equal(carom_world_query_aabb(w, lo, hi, ids, 4), 2);
    assert_int_equal(carom_world_query_aabb(w, lo, hi, NULL, 0), 2); /* count only */
    assert_int_equal(carom_world_query_aabb(w, hi, lo, ids, 4), -1);  /* inverted box */
    carom_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version_and_status),
        cmocka_unit_test(test_last_error_reason),
        cmocka_unit_test(test_id_generations),
        cmocka_unit_test(test_store_stays_dense),
        cmocka_unit_test(test_mass_properties),
        cmocka_unit_test(test_rejections_leave_world_unchanged),
        cmocka_unit_test(test_world_def_validation),
        cmocka_unit_test(test_mutation_inside_callback),
        cmocka_unit_test(test_queries),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
