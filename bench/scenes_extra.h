/* scenes_extra.h - carom's benchmark scenes: the peers' canonical scenes
 * (peers/scenes.h geometry, built through carom's API) plus the large pyramid
 * and the analytic cases of the solver tests, each with one error metric.
 * Header-only (static functions) like peers/scenes.h; include after it. */
#ifndef CAROM_SCENES_EXTRA_H
#define CAROM_SCENES_EXTRA_H

#include "carom/carom.h"

typedef struct scene_result {
    double error;            /* the scene's error metric (lower is better) */
    const char *error_name;
    double extra;            /* a second number (scene-specific, see error_name) */
    double momentum_drift;   /* |p_end - p_start| / |p_start| where nothing external acts; -1 elsewhere */
} scene_result;

static carom_vec3 sx_vec(double x, double y, double z) { carom_vec3 v = {x, y, z}; return v; }

static void sx_static_plane(carom_world *w, double nx, double ny, double nz, double off, double mu, double e)
{
    carom_body_def g = carom_body_def_default();
    g.type = CAROM_BODY_STATIC;
    g.shape = carom_shape_plane(nx, ny, nz, off);
    g.friction = mu;
    g.restitution = e;
    carom_body_create(w, &g);
}

/* Builds a peers scene into w; ids receives the dynamic bodies in scene order. */
static void canonical_build(carom_world *w, SceneDesc *sc, carom_body_id *ids)
{
    if (sc->ground) sx_static_plane(w, 0, 0, 1, 0, sc->mu, 0);
    for (int i = 0; i < sc->nstatic; i++) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.position = sx_vec(sc->statics[i].pos[0], sc->statics[i].pos[1], sc->statics[i].pos[2]);
        g.shape = carom_shape_box(sc->statics[i].half[0], sc->statics[i].half[1], sc->statics[i].half[2]);
        g.friction = sc->mu;
        carom_body_create(w, &g);
    }
    for (int i = 0; i < sc->nbodies; i++) {
        const BodyDesc *b = &sc->bodies[i];
        carom_body_def d = carom_body_def_default();
        d.position = sx_vec(b->pos[0], b->pos[1], b->pos[2]);
        d.linear_velocity = sx_vec(b->vel[0], b->vel[1], b->vel[2]);
        d.shape = b->shape == SHAPE_BOX ? carom_shape_box(b->he, b->he, b->he) : carom_shape_sphere(b->he);
        d.mass = b->mass;
        d.friction = sc->mu;
        d.bullet = sc->id == SC_BULLET && sc->ccd;
        ids[i] = carom_body_create(w, &d);
    }
}

/* Box2D/Box3D's large pyramid: base 100, 5050 unit cubes (half extent 0.5). */
static void large_pyramid_make(SceneDesc *s)
{
    const int base = 100;
    int n = base * (base + 1) / 2, k = 0;
    memset(s, 0, sizeof *s);
    s->id = SC_PYRAMID; s->name = "large_pyramid"; s->steps = 200; s->ground = 1; s->mu = 0.6;
    s->nbodies = n; s->bodies = scene_alloc(n);
    for (int r = 0; r < base; r++)
        for (int i = 0; i < base - r; i++)
            scene_box(&s->bodies[k++], (i - 0.5 * (base - r - 1)), 0.0, 0.5 + r, 0.5, 1.0);
}

static double sx_max_disp(carom_world *w, const SceneDesc *sc, const carom_body_id *ids)
{
    double m = 0;
    for (int i = 0; i < sc->nbodies; i++) {
        carom_vec3 p;
        carom_body_get_position(w, ids[i], &p);
        double d = sqrt(pow(p.x - sc->bodies[i].pos[0], 2) + pow(p.y - sc->bodies[i].pos[1], 2) +
                        pow(p.z - sc->bodies[i].pos[2], 2));
        if (d > m) m = d;
    }
    return m;
}

/* Runs a canonical scene; returns its error metric. */
static int canonical_run(const char *name, const carom_world_def *def, double *ms_step, scene_result *r)
{
    SceneDesc sc;
    if (!strcmp(name, "large_pyramid")) large_pyramid_make(&sc);
    else if (!scene_make_by_name(&sc, name)) return 0;
    carom_world_def d = *def;
    if (sc.id == SC_BULLET && !sc.ccd) d.enable_continuous = 0;
    carom_world *w = carom_world_create(&d);
    if (!w) { scene_free(&sc); return 0; }
    r->momentum_drift = -1;
    carom_body_id *ids = malloc(sizeof *ids * (size_t)sc.nbodies);
    canonical_build(w, &sc, ids);
    double t0 = bench_now_ms();
    for (int s = 0; s < sc.steps; s++) carom_world_step(w, BENCH_DT);
    *ms_step = (bench_now_ms() - t0) / sc.steps;
    r->extra = 0;
    if (sc.id == SC_PYRAMID || sc.id == SC_STACK) {
        r->error = sx_max_disp(w, &sc, ids);
        r->error_name = "max_disp_m";
        carom_vec3 p;
        carom_body_get_position(w, ids[sc.nbodies - 1], &p);
        r->extra = p.z - sc.bodies[sc.nbodies - 1].pos[2];
    } else if (sc.id == SC_PILE) {
        r->error = carom_world_measure_max_penetration(w);
        r->error_name = "max_pen_m";
        double ke, pe;
        carom_world_get_energy(w, &ke, &pe);
        r->extra = ke;
    } else if (sc.id == SC_MASS_RATIO) {
        carom_vec3 p;
        carom_body_get_position(w, ids[1], &p);
        r->error = fabs(p.z - 1.5);
        r->error_name = "heavy_err_m";
    } else {
        carom_vec3 p;
        carom_body_get_position(w, ids[0], &p);
        r->error = p.x > BULLET_WALL_FRONT + BULLET_WALL_THICK ? 1.0 : 0.0;
        r->error_name = "tunneled";
        r->extra = p.x;
    }
    free(ids);
    scene_free(&sc);
    carom_world_destroy(w);
    return 1;
}

/* ---- analytic scenes --------------------------------------------------------- */

static carom_body_id sx_body(carom_world *w, carom_shape_def shape, double x, double y, double z, double mass,
                             double mu, double e)
{
    carom_body_def d = carom_body_def_default();
    d.position = sx_vec(x, y, z);
    d.shape = shape;
    d.mass = mass;
    d.friction = mu;
    d.restitution = e;
    return carom_body_create(w, &d);
}

static int analytic_run(const char *name, const carom_world_def *def, double *ms_step, scene_result *r)
{
    carom_world_def d = *def;
    const double dt = BENCH_DT, g = 9.81;
    int steps = 0;
    double t0, elapsed = 0;
    carom_world *w = NULL;
    r->extra = 0;
    r->momentum_drift = -1;
    if (!strcmp(name, "bounce")) {
        /* e = 0.5 from 1 m: apex e^2 h = 0.25 m */
        w = carom_world_create(&d);
        sx_static_plane(w, 0, 0, 1, 0, 0, 0);
        carom_body_id b = sx_body(w, carom_shape_sphere(0.1), 0, 0, 1.1, 1, 0, 0.5);
        int up = 0;
        double apex = 0;
        t0 = bench_now_ms();
        for (steps = 0; steps < 240; steps++) {
            carom_world_step(w, dt);
            carom_vec3 p, v;
            carom_body_get_position(w, b, &p);
            carom_body_get_linear_velocity(w, b, &v);
            if (v.z > 0) up = 1;
            if (up && p.z - 0.1 > apex) apex = p.z - 0.1;
            if (up && v.z < 0) break;
        }
        elapsed = bench_now_ms() - t0;
        r->error = fabs(apex - 0.25) / 0.25;
        r->error_name = "restitution_rel_err";
        r->extra = apex;
    } else if (!strcmp(name, "slide")) {
        /* 5 m/s, mu 0.5: stops after v^2 / (2 mu g) */
        w = carom_world_create(&d);
        sx_static_plane(w, 0, 0, 1, 0, 0.5, 0);
        carom_body_id b = sx_body(w, carom_shape_box(0.5, 0.5, 0.5), 0, 0, 0.5, 1, 0.5, 0);
        for (int i = 0; i < 10; i++) carom_world_step(w, dt);
        carom_vec3 p0, p1;
        carom_body_get_position(w, b, &p0);
        carom_body_set_linear_velocity(w, b, sx_vec(5, 0, 0));
        t0 = bench_now_ms();
        for (steps = 0; steps < 180; steps++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_body_get_position(w, b, &p1);
        double expect = 25.0 / (2 * 0.5 * g);
        r->error = fabs((p1.x - p0.x) - expect) / expect;
        r->error_name = "stop_dist_rel_err";
        r->extra = p1.x - p0.x;
    } else if (!strcmp(name, "incline")) {
        /* 35 degrees, mu 0.5: a = g (sin - mu cos) */
        double a = 35.0 * 3.14159265358979323846 / 180.0;
        w = carom_world_create(&d);
        sx_static_plane(w, sin(a), 0, cos(a), 0, 0.5, 0);
        carom_body_def bd = carom_body_def_default();
        bd.position = sx_vec(0.5 * sin(a), 0, 0.5 * cos(a));
        carom_quat q = {cos(0.5 * a), 0, sin(0.5 * a), 0};
        bd.orientation = q;
        bd.shape = carom_shape_box(0.5, 0.5, 0.5);
        bd.mass = 1;
        bd.friction = 0.5;
        carom_body_id b = carom_body_create(w, &bd);
        for (int i = 0; i < 30; i++) carom_world_step(w, dt);
        carom_vec3 v0, v1;
        carom_body_get_linear_velocity(w, b, &v0);
        t0 = bench_now_ms();
        for (steps = 0; steps < 120; steps++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_body_get_linear_velocity(w, b, &v1);
        /* acceleration = change of the down-slope speed over 2 s */
        double acc = ((v1.x - v0.x) * cos(a) - (v1.z - v0.z) * sin(a)) / 2.0, expect = g * (sin(a) - 0.5 * cos(a));
        r->error = fabs(acc - expect) / expect;
        r->error_name = "accel_rel_err";
        r->extra = acc;
    } else if (!strcmp(name, "rolling")) {
        /* launched at 5 m/s without spin: rolls at 5/7 of it */
        w = carom_world_create(&d);
        sx_static_plane(w, 0, 0, 1, 0, 0.4, 0);
        carom_body_def bd = carom_body_def_default();
        bd.position = sx_vec(0, 0, 0.25);
        bd.shape = carom_shape_sphere(0.25);
        bd.mass = 1;
        bd.friction = 0.4;
        bd.linear_velocity = sx_vec(5, 0, 0);
        carom_body_id b = carom_body_create(w, &bd);
        t0 = bench_now_ms();
        for (steps = 0; steps < 120; steps++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_vec3 v;
        carom_body_get_linear_velocity(w, b, &v);
        r->error = fabs(v.x - 25.0 / 7.0) / (25.0 / 7.0);
        r->error_name = "roll_speed_rel_err";
        r->extra = v.x;
    } else if (!strcmp(name, "gas") || !strcmp(name, "cradle")) {
        int cradle = !strcmp(name, "cradle");
        d.gravity = sx_vec(0, 0, 0);
        d.restitution_threshold = 0;
        d.enable_friction = 0;
        w = carom_world_create(&d);
        double ke0, ke1, pe;
        carom_body_id last = {0, 0};
        if (cradle) {
            /* five touching balls, the first hits at 2 m/s: the last leaves at 2 m/s */
            carom_body_id first = sx_body(w, carom_shape_sphere(0.1), -0.6, 0, 0, 1, 0, 1);
            for (int i = 0; i < 5; i++) last = sx_body(w, carom_shape_sphere(0.1), 0.2 * i, 0, 0, 1, 0, 1);
            carom_body_set_linear_velocity(w, first, sx_vec(2, 0, 0));
            steps = 60;
        } else {
            const double L = 3.0;
            double walls[6][4] = {{0, 0, 1, -L}, {0, 0, -1, -L}, {1, 0, 0, -L}, {-1, 0, 0, -L}, {0, 1, 0, -L}, {0, -1, 0, -L}};
            for (int i = 0; i < 6; i++) sx_static_plane(w, walls[i][0], walls[i][1], walls[i][2], walls[i][3], 0, 1);
            unsigned rng = 7u;
            for (int i = 0; i < 64; i++) {
                carom_body_id b = sx_body(w, carom_shape_sphere(0.3), -2.25 + 1.5 * (i % 4), -2.25 + 1.5 * ((i / 4) % 4),
                                          -2.25 + 1.5 * (i / 16), 1, 0, 1);
                double v[3];
                for (int c = 0; c < 3; c++) {
                    rng = rng * 1664525u + 1013904223u;
                    v[c] = 4.0 * ((double)(rng >> 8) / 16777216.0 - 0.5);
                }
                carom_body_set_linear_velocity(w, b, sx_vec(v[0], v[1], v[2]));
            }
            steps = 600;
        }
        carom_world_get_energy(w, &ke0, &pe);
        carom_vec3 p0, p1;
        carom_world_get_momentum(w, &p0, NULL);
        t0 = bench_now_ms();
        for (int s = 0; s < steps; s++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_world_get_energy(w, &ke1, &pe);
        carom_world_get_momentum(w, &p1, NULL);
        if (cradle) {
            /* walls are absent: total momentum is conserved exactly */
            double m0 = sqrt(p0.x * p0.x + p0.y * p0.y + p0.z * p0.z);
            r->momentum_drift = sqrt(pow(p1.x - p0.x, 2) + pow(p1.y - p0.y, 2) + pow(p1.z - p0.z, 2)) / m0;
        }
        if (cradle) {
            carom_vec3 v;
            carom_body_get_linear_velocity(w, last, &v);
            r->error = fabs(v.x - 2.0) / 2.0;
            r->error_name = "cradle_speed_rel_err";
            r->extra = ke1 / ke0;
        } else {
            r->error = fabs(ke1 / ke0 - 1.0);
            r->error_name = "energy_drift_rel";
            r->extra = ke1 / ke0;
        }
    } else if (!strcmp(name, "tumble")) {
        /* rotation: a torque-free box (0.5 x 0.25 x 0.1 m, 1 kg) about its
         * intermediate axis at 10 rad/s for 20 s: kinetic energy drift */
        d.gravity = sx_vec(0, 0, 0);
        w = carom_world_create(&d);
        carom_body_def bd = carom_body_def_default();
        bd.shape = carom_shape_box(0.5, 0.25, 0.1);
        bd.mass = 1.0;
        bd.angular_velocity = sx_vec(0.01, 10, 0.01);
        carom_body_id b = carom_body_create(w, &bd);
        double ke0, ke1, pe;
        carom_world_get_energy(w, &ke0, &pe);
        t0 = bench_now_ms();
        for (steps = 0; steps < 1200; steps++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_world_get_energy(w, &ke1, &pe);
        (void)b;
        r->error = fabs(ke1 / ke0 - 1.0);
        r->error_name = "tumble_energy_drift_rel";
        r->extra = ke1 / ke0;
    } else if (!strcmp(name, "oblique")) {
        /* impact geometry: a ball (r 0.1) meets a plane at (4, 0, -3) m/s,
         * mu 0.1, e 0.5, touching mid-step; the seed's spin out is
         * mu (1 + e) 3 r / (2/5 r^2) = 11.25 rad/s */
        d.gravity = sx_vec(0, 0, 0);
        w = carom_world_create(&d);
        sx_static_plane(w, 0, 0, 1, 0, 0.1, 0.5);
        carom_body_def bd = carom_body_def_default();
        bd.shape = carom_shape_sphere(0.1);
        bd.mass = 1.0;
        bd.friction = 0.1;
        bd.restitution = 0.5;
        bd.position = sx_vec(0, 0, 0.1 + 3.0 * dt * 3.5);
        bd.linear_velocity = sx_vec(4, 0, -3);
        carom_body_id b = carom_body_create(w, &bd);
        t0 = bench_now_ms();
        for (steps = 0; steps < 10; steps++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_vec3 av;
        carom_body_get_angular_velocity(w, b, &av);
        double want = 0.1 * 1.5 * 3.0 * 0.1 / (0.4 * 0.01);
        r->error = fabs(av.y - want) / want;
        r->error_name = "oblique_spin_rel_err";
        r->extra = av.y;
    } else if (!strcmp(name, "break")) {
        /* simultaneous impacts: 15 billiard balls racked touching, the cue at
         * 10 m/s, e = 1, mu = 0, no gravity; kinetic energy after 1 s */
        const double rb = 0.028575;
        d.gravity = sx_vec(0, 0, 0);
        w = carom_world_create(&d);
        carom_body_def bd = carom_body_def_default();
        bd.shape = carom_shape_sphere(rb);
        bd.mass = 0.17;
        bd.friction = 0.0;
        bd.restitution = 1.0;
        bd.position = sx_vec(-0.5, 0, 0);
        bd.linear_velocity = sx_vec(10, 0, 0);
        carom_body_create(w, &bd);
        bd.linear_velocity = sx_vec(0, 0, 0);
        for (int row = 0; row < 5; row++)
            for (int j = 0; j <= row; j++) {
                bd.position = sx_vec(row * sqrt(3.0) * rb, (2.0 * j - row) * rb, 0);
                carom_body_create(w, &bd);
            }
        double ke0, ke1, pe;
        carom_vec3 p0, l0, p1, l1;
        carom_world_get_energy(w, &ke0, &pe);
        carom_world_get_momentum(w, &p0, &l0);
        t0 = bench_now_ms();
        for (steps = 0; steps < 60; steps++) carom_world_step(w, dt);
        elapsed = bench_now_ms() - t0;
        carom_world_get_energy(w, &ke1, &pe);
        carom_world_get_momentum(w, &p1, &l1);
        r->error = fabs(ke1 / ke0 - 1.0);
        r->error_name = "break_energy_rel_err";
        r->extra = ke1 / ke0;
        r->momentum_drift = sqrt((p1.x - p0.x) * (p1.x - p0.x) + (p1.y - p0.y) * (p1.y - p0.y) +
                                 (p1.z - p0.z) * (p1.z - p0.z)) / 1.7;
    } else {
        return 0;
    }
    if (!w) return 0;
    *ms_step = steps > 0 ? elapsed / steps : 0;
    carom_world_destroy(w);
    return 1;
}

static const char *const extra_scene_names[] = {"pyramid", "pile", "stack", "mass_ratio", "bullet", "large_pyramid",
                                                "bounce", "slide", "incline", "rolling", "gas", "cradle",
                                                "tumble", "oblique", "break"};

static int extra_scene_count(void) { return (int)(sizeof extra_scene_names / sizeof *extra_scene_names); }
static const char *extra_scene_name(int i) { return extra_scene_names[i]; }
static int extra_scene_is_heavy(const char *name) { return !strcmp(name, "pile") || !strcmp(name, "large_pyramid"); }

static int extra_scene_run(const char *name, const carom_world_def *def, double *ms_step, scene_result *r)
{
    int i;
    for (i = 0; i < 6; i++)
        if (!strcmp(name, extra_scene_names[i])) return canonical_run(name, def, ms_step, r);
    return analytic_run(name, def, ms_step, r);
}

#endif
