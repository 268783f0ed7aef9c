/* extremes.c - the stability envelope at each preset (full versions of
 * tests/test_ranges.c): mass ratios, speeds, sizes, distance from the
 * origin, time steps and a one-million-step soak. One line per case and
 * preset: holds yes/no and the measured error. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom/carom.h"

static carom_vec3 vec(double x, double y, double z) { carom_vec3 v = {x, y, z}; return v; }

static carom_world *world_for(const char *preset, int ground)
{
    carom_world_def d = carom_world_def_default();
    carom_world_def_apply_preset(&d, preset);
    d.enable_sleep = 0;
    carom_world *w = carom_world_create(&d);
    if (ground) {
        carom_body_def g = carom_body_def_default();
        g.type = CAROM_BODY_STATIC;
        g.shape = carom_shape_plane(0, 0, 1, 0);
        carom_body_create(w, &g);
    }
    return w;
}

static carom_body_id box_at(carom_world *w, double x, double y, double z, double he, double mass)
{
    carom_body_def d = carom_body_def_default();
    d.position = vec(x, y, z);
    d.shape = carom_shape_box(he, he, he);
    d.mass = mass;
    return carom_body_create(w, &d);
}

static int finite_world(carom_world *w)
{
    double ke, pe;
    carom_world_get_energy(w, &ke, &pe);
    carom_world_stats st = carom_world_stats_init();
    carom_world_get_stats(w, &st);
    return isfinite(ke) && isfinite(pe) && st.non_finite == 0;
}

static void report(const char *preset, const char *name, int holds, double err, const char *unit)
{
    printf("preset=%s case=%s holds=%s error=%.4g %s\n", preset, name, holds ? "yes" : "NO", err, unit);
    fflush(stdout);
}

static void stack_case(const char *preset, const char *name, double x, double y, double dt, double seconds, double tol)
{
    carom_world *w = world_for(preset, 1);
    carom_body_id top = box_at(w, x, y, 0.5, 0.5, 1);
    for (int i = 1; i < 5; i++) top = box_at(w, x, y, 0.5 + i, 0.5, 1);
    int steps = (int)(seconds / dt);
    for (int s = 0; s < steps; s++) carom_world_step(w, dt);
    carom_vec3 p;
    carom_body_get_position(w, top, &p);
    double moved = sqrt(pow(p.x - x, 2) + pow(p.y - y, 2) + pow(p.z - 4.5, 2));
    report(preset, name, finite_world(w) && moved < tol, moved, "m (top of a 5-box stack)");
    carom_world_destroy(w);
}

int main(int argc, char **argv)
{
    static const char *presets[] = {"fast", "default", "accurate"};
    long soak = argc > 1 ? atol(argv[1]) : 1000000;
    for (int k = 0; k < 3; k++) {
        const char *p = presets[k];
        double ratios[3] = {1e3, 1e6, 1e9};
        for (int i = 0; i < 3; i++) {
            carom_world *w = world_for(p, 1);
            box_at(w, 0, 0, 0.5, 0.5, 1);
            carom_body_id heavy = box_at(w, 0, 0, 1.5, 0.5, ratios[i]);
            for (int s = 0; s < 600; s++) carom_world_step(w, 1.0 / 60);
            carom_vec3 ph;
            carom_body_get_position(w, heavy, &ph);
            char name[64];
            snprintf(name, sizeof name, "mass_ratio_%g", ratios[i]);
            report(p, name, finite_world(w) && fabs(ph.z - 1.5) < 0.01, fabs(ph.z - 1.5), "m (heavy box height error)");
            carom_world_destroy(w);
        }
        double speeds[3] = {100, 1000, 3000};
        for (int i = 0; i < 3; i++) {
            carom_world *w = world_for(p, 0);
            carom_body_def wall = carom_body_def_default();
            wall.type = CAROM_BODY_STATIC;
            wall.position = vec(1.025, 0, 2);
            wall.shape = carom_shape_box(0.025, 2, 2);
            carom_body_create(w, &wall);
            carom_body_def b = carom_body_def_default();
            b.position = vec(0, 0, 2);
            b.shape = carom_shape_sphere(0.01);
            b.mass = 0.01;
            b.linear_velocity = vec(speeds[i], 0, 0);
            carom_body_id id = carom_body_create(w, &b);
            double xmax = 0;
            for (int s = 0; s < 60; s++) {
                carom_world_step(w, 1.0 / 60);
                carom_vec3 q;
                carom_body_get_position(w, id, &q);
                xmax = fmax(xmax, q.x);
            }
            char name[64];
            snprintf(name, sizeof name, "speed_%gm/s", speeds[i]);
            report(p, name, finite_world(w) && xmax < 1.0, xmax, "m (furthest x; wall face at 1.0)");
            carom_world_destroy(w);
        }
        double sizes[4] = {0.001, 0.01, 100, 1000};
        for (int i = 0; i < 4; i++) {
            carom_world *w = world_for(p, 1);
            double he = 0.5 * sizes[i];
            carom_body_id id = box_at(w, 0, 0, he, he, 1000 * pow(sizes[i], 3));
            for (int s = 0; s < 600; s++) carom_world_step(w, 1.0 / 60);
            carom_vec3 q;
            carom_body_get_position(w, id, &q);
            double err = sqrt(q.x * q.x + q.y * q.y + pow(q.z - he, 2));
            char name[64];
            snprintf(name, sizeof name, "size_%gm", sizes[i]);
            report(p, name, finite_world(w) && err < fmax(0.01 * sizes[i], 0.006), err, "m (rest position error)");
            carom_world_destroy(w);
        }
        stack_case(p, "stack_at_1e5m", 1e5, -1e5, 1.0 / 60, 10, 0.03);
        stack_case(p, "stack_at_1e7m", 1e7, 0, 1.0 / 60, 10, 0.03);
        double dts[4] = {1.0 / 1000, 1.0 / 120, 1.0 / 30, 1.0 / 15};
        for (int i = 0; i < 4; i++) {
            char name[64];
            snprintf(name, sizeof name, "dt_1/%g", 1.0 / dts[i]);
            stack_case(p, name, 0, 0, dts[i], 10, 0.1);
        }
        /* the soak: a box and a ball in a closed room, e = 0.9, for `soak` steps */
        {
            carom_world *w = world_for(p, 0);
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
            long s = 0;
            int inside = 1;
            for (; s < soak && inside; s++) {
                carom_world_step(w, 1.0 / 60);
                if (s % 10000 == 0) {
                    carom_vec3 q;
                    carom_body_get_position(w, box, &q);
                    inside = finite_world(w) && fabs(q.x) < 3 && fabs(q.y) < 3 && q.z > 0 && q.z < 6;
                }
            }
            char name[64];
            snprintf(name, sizeof name, "soak_%ld_steps", soak);
            report(p, name, inside, (double)s, "steps run, state finite and inside the room");
            carom_world_destroy(w);
        }
    }
    return 0;
}
