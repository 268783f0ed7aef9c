/* world.c - world lifecycle, settings and presets, errors, and the step. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "array.h"
#include "deferred.h"
#include "sensor.h"
#include "world.h"
#include "ranges.h"
#include "collision.h"
#include "ghost.h"
#include "solver.h"
#include "toi.h"
#include "island.h"

/* "major.minor.patch" from the header's numbers, the one place the version is written */
#define CAROM_STRINGIFY_(x) #x
#define CAROM_STRINGIFY(x) CAROM_STRINGIFY_(x)
CAROM_API const char *carom_version(void)
{
    return CAROM_STRINGIFY(CAROM_VERSION_MAJOR) "." CAROM_STRINGIFY(CAROM_VERSION_MINOR) "."
        CAROM_STRINGIFY(CAROM_VERSION_PATCH);
}

CAROM_API const char *carom_status_string(carom_status status)
{
    switch (status) {
    case CAROM_OK: return "ok";
    case CAROM_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case CAROM_ERROR_STALE_ID: return "stale or invalid body id";
    case CAROM_ERROR_LOCKED: return "world is locked (inside step or callback)";
    case CAROM_ERROR_OUT_OF_MEMORY: return "out of memory";
    case CAROM_ERROR_UNSUPPORTED: return "unsupported operation";
    }
    return "unknown status";
}


CAROM_API const char *carom_world_last_error(const carom_world *world)
{
    return world ? world->error : "world is NULL";
}

CAROM_API const char *carom_world_last_error_reason(const carom_world *world)
{
    return world ? world->error + world->error_reason : "world is NULL";
}

/* ---- settings -------------------------------------------------------------- */

/* Copies the caller's def (of its own compile-time size) over our defaults. */
static int def_import(const carom_world_def *in, carom_world_def *out, char *msg, size_t n)
{
    *out = carom_world_def_default();
    if (!in) { snprintf(msg, n, "world def is NULL"); return 0; }
    if (in->size < offsetof(carom_world_def, gravity) + sizeof(carom_vec3)) {
        snprintf(msg, n, "world def size %u is too small: initialise it with carom_world_def_default()",
                 (unsigned)in->size);
        return 0;
    }
    size_t sz = in->size < sizeof *out ? in->size : sizeof *out;
    memcpy(out, in, sz);
    out->size = (uint32_t)sizeof *out;
    return 1;
}

static int finite3(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static int def_validate(const carom_world_def *d, char *msg, size_t n)
{
#define REQUIRE(cond, ...) do { if (!(cond)) { snprintf(msg, n, __VA_ARGS__); return 0; } } while (0)
    REQUIRE(finite3(d->gravity), "gravity must be finite");
    REQUIRE(sqrt(d->gravity.x * d->gravity.x + d->gravity.y * d->gravity.y + d->gravity.z * d->gravity.z) <= RANGE_GRAVITY_MAX,
            "|gravity| must be at most 1e4 m/s^2 (got (%g, %g, %g))", d->gravity.x, d->gravity.y, d->gravity.z);
    REQUIRE(d->substeps >= 1 && d->substeps <= 64, "substeps must be in 1..64 (got %d)", d->substeps);
    REQUIRE(d->iterations >= 1 && d->iterations <= 256, "iterations must be in 1..256 (got %d)", d->iterations);
    REQUIRE(d->relax_iterations >= 0 && d->relax_iterations <= 256, "relax_iterations must be in 0..256 (got %d)",
            d->relax_iterations);
    REQUIRE(d->position_correction >= CAROM_CORRECTION_SOFT && d->position_correction <= CAROM_CORRECTION_NONE,
            "position_correction must be SOFT, BAUMGARTE or NONE");
    REQUIRE(d->contact_model == CAROM_CONTACT_IMPULSE || d->contact_model == CAROM_CONTACT_PENALTY,
            "contact_model must be IMPULSE or PENALTY");
    REQUIRE(isfinite(d->hit_event_threshold) && d->hit_event_threshold >= 0 && d->hit_event_threshold <= RANGE_SPEED_MAX,
            "hit_event_threshold must be in [0, 1e9] m/s (got %g)", d->hit_event_threshold);
    REQUIRE(d->restitution_threshold >= 0 && d->restitution_threshold <= RANGE_SPEED_MAX,
            "restitution_threshold must be in [0, 1e9] m/s (got %g)", d->restitution_threshold);
    REQUIRE(d->contact_hertz >= RANGE_HERTZ_MIN && d->contact_hertz <= RANGE_HERTZ_MAX,
            "contact_hertz must be in [1e-3, 1e6] (got %g)", d->contact_hertz);
    REQUIRE(d->contact_damping_ratio >= 0 && d->contact_damping_ratio <= RANGE_RATIO_MAX,
            "contact_damping_ratio must be in [0, 1e6] (got %g)", d->contact_damping_ratio);
    REQUIRE(d->contact_push_max_velocity > 0 && d->contact_push_max_velocity <= RANGE_SPEED_MAX,
            "contact_push_max_velocity must be in (0, 1e9] m/s (got %g)", d->contact_push_max_velocity);
    REQUIRE(isfinite(d->baumgarte) && d->baumgarte >= 0 && d->baumgarte <= 1, "baumgarte must be in [0, 1]");
    REQUIRE(isfinite(d->linear_slop) && d->linear_slop >= 0 && d->linear_slop < 1, "linear_slop must be in [0, 1)");
    REQUIRE(isfinite(d->speculative_distance) && d->speculative_distance >= 0 && d->speculative_distance < 10,
            "speculative_distance must be in [0, 10)");
    REQUIRE(d->penalty_stiffness >= 0 && d->penalty_stiffness <= RANGE_PENALTY_MAX,
            "penalty_stiffness must be in [0, 1e20] N/m (got %g)", d->penalty_stiffness);
    REQUIRE(d->penalty_damping >= 0 && d->penalty_damping <= RANGE_PENALTY_MAX,
            "penalty_damping must be in [0, 1e20] N s/m (got %g)", d->penalty_damping);
    REQUIRE(d->sleep_time >= 0 && d->sleep_time <= 1e9, "sleep_time must be in [0, 1e9] s (got %g)", d->sleep_time);
    REQUIRE(d->sleep_linear_velocity >= 0 && d->sleep_linear_velocity <= RANGE_SPEED_MAX,
            "sleep_linear_velocity must be in [0, 1e9] m/s (got %g)", d->sleep_linear_velocity);
    REQUIRE(d->sleep_angular_velocity >= 0 && d->sleep_angular_velocity <= RANGE_SPEED_MAX,
            "sleep_angular_velocity must be in [0, 1e9] rad/s (got %g)", d->sleep_angular_velocity);
    /* the clamps divide by the largest component above half the cap: a cap of
     * a few subnormals (fuzz: 1.9e-322) overflowed it and made NaN */
    REQUIRE(d->max_linear_speed >= RANGE_SPEED_MIN && d->max_linear_speed <= RANGE_SPEED_MAX,
            "max_linear_speed must be in [1e-6, 1e9] (got %g)", d->max_linear_speed);
    REQUIRE(d->max_angular_speed == 0 ||
                (d->max_angular_speed >= RANGE_SPEED_MIN && d->max_angular_speed <= RANGE_SPEED_MAX),
            "max_angular_speed must be 0 (automatic) or in [1e-6, 1e9] (got %g)", d->max_angular_speed);
    REQUIRE(isfinite(d->contact_reuse_distance) && d->contact_reuse_distance >= 0 && d->contact_reuse_distance <= 0.01,
            "contact_reuse_distance must be in [0, 0.01] m");
    REQUIRE(d->body_capacity >= 0 && d->body_capacity <= (1 << 26), "body_capacity must be in 0..2^26");
    REQUIRE(d->worker_count >= 1 && d->worker_count <= CAROM_MAX_WORKERS, "worker_count must be in 1..%d (got %d)",
            CAROM_MAX_WORKERS, d->worker_count);
    REQUIRE(d->worker_count == 1 || d->enqueue_task,
            "worker_count is %d but enqueue_task is NULL: set the task hooks (carom_threads.h has a pool) or use 1 worker",
            d->worker_count);
    REQUIRE(!d->enqueue_task == !d->finish_task, "enqueue_task and finish_task must be set together (%s is NULL)",
            d->enqueue_task ? "finish_task" : "enqueue_task");
#undef REQUIRE
    return 1;
}

CAROM_API carom_status carom_world_def_check(const carom_world_def *def, char *msg, size_t msg_size)
{
    char local[WORLD_ERROR_SIZE];
    carom_world_def d;
    if (!msg || msg_size == 0) { msg = local; msg_size = sizeof local; }
    msg[0] = '\0';
    if (!def_import(def, &d, msg, msg_size) || !def_validate(&d, msg, msg_size))
        return CAROM_ERROR_INVALID_ARGUMENT;
    return CAROM_OK;
}

/* Presets derived from the measured speed/accuracy fronts (README, "Choosing settings"). */
CAROM_API carom_status carom_world_def_apply_preset(carom_world_def *def, const char *preset)
{
    if (!def || !preset) return CAROM_ERROR_INVALID_ARGUMENT;
    if (def->size < sizeof(uint32_t)) return CAROM_ERROR_INVALID_ARGUMENT;
    carom_world_def d = carom_world_def_default();
    size_t sz = def->size < sizeof d ? def->size : sizeof d;
    memcpy(&d, def, sz);
    if (strcmp(preset, "default") == 0) {
        d.substeps = 4; d.iterations = 1; d.relax_iterations = 1;
        d.contact_hertz = 30.0; d.contact_damping_ratio = 10.0;
        d.contact_reuse_distance = 1e-4;
    } else if (strcmp(preset, "fast") == 0) {
        /* the sweep's cheapest point that keeps the pyramid standing: no relax
         * pass (2 sub-steps at 15 Hz, tried first, let stacks sink 0.1-0.4 m) */
        d.substeps = 4; d.iterations = 1; d.relax_iterations = 0;
        d.contact_hertz = 30.0; d.contact_damping_ratio = 10.0;
        /* resting pairs keep their manifold until their contact points move 1 mm */
        d.contact_reuse_distance = 1e-3;
    } else if (strcmp(preset, "accurate") == 0) {
        d.substeps = 8; d.iterations = 2; d.relax_iterations = 1;
        d.contact_hertz = 60.0; d.contact_damping_ratio = 10.0;
        d.contact_reuse_distance = 0.0; /* every manifold computed every step */
    } else {
        return CAROM_ERROR_INVALID_ARGUMENT;
    }
    d.position_correction = CAROM_CORRECTION_SOFT;
    d.warm_starting = 1;
    d.contact_model = CAROM_CONTACT_IMPULSE;
    memcpy(def, &d, sz);
    def->size = (uint32_t)sz;
    return CAROM_OK;
}

CAROM_API carom_world *carom_world_create(const carom_world_def *def)
{
    char msg[WORLD_ERROR_SIZE];
    carom_world_def d;
    if (!def_import(def, &d, msg, sizeof msg) || !def_validate(&d, msg, sizeof msg)) return NULL;
    carom_world *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    w->def = d;
    w->bp = bp_create();
    if (!w->bp || !body_store_init(&w->bodies, d.body_capacity) || !contact_set_init(&w->contacts)) {
        carom_world_destroy(w);
        return NULL;
    }
    w->stats = carom_world_stats_init();
    return w;
}

CAROM_API void carom_world_destroy(carom_world *w)
{
    if (!w) return;
    if (w->locked) {
        /* from inside its own step (an event callback): refusing is the only
         * safe answer; the caller can destroy it after the step returns */
        world_fail(w, CAROM_ERROR_LOCKED, "world_destroy: the world is inside its step; destroy it afterwards");
        return;
    }
    for (int i = 0; i < w->bodies.count; i++) shape_free_data(&w->bodies.shapes[i]);
    body_store_free(&w->bodies);
    if (w->bp) bp_destroy(w->bp);
    contact_set_free(&w->contacts);
    free(w->events.items);
    free(w->events.children);
    step_scratch *s = &w->scratch;
    free(s->bodies); free(s->delta_position); free(s->delta_rotation); free(s->body_slot);
    solver_memory_free(&s->solver);
    impact_memory_free(&s->impact);
    free(s->island_parent); free(s->deferred_destroy); free(s->deferred_ops);
    free(s->tight_box); free(s->pose); free(s->ahead); free(s->refit); free(s->touching); free(s->mixed);
    free(w->sensor_overlaps);
    free(s->new_pairs); free(s->asleep_pairs); free(s->toi); free(s->toi_bodies); free(s->toi_fast); free(s->toi_near); free(s->merged);
    carom_world_destroy(w->spare);
    free(w);
}

CAROM_API carom_status carom_world_set_def(carom_world *w, const carom_world_def *def)
{
    char msg[WORLD_ERROR_SIZE];
    carom_world_def d;
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "set_def: world is locked");
    if (!def_import(def, &d, msg, sizeof msg) || !def_validate(&d, msg, sizeof msg))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "set_def: %s", msg);
    int wake = d.enable_sleep != w->def.enable_sleep || !finite3(d.gravity) ||
               d.gravity.x != w->def.gravity.x || d.gravity.y != w->def.gravity.y || d.gravity.z != w->def.gravity.z;
    w->def = d;
    if (wake)
        for (int i = 0; i < w->bodies.count; i++) world_wake_body(w, i);
    return CAROM_OK;
}

CAROM_API carom_status carom_world_get_def(const carom_world *w, carom_world_def *def)
{
    if (!w || !def) return CAROM_ERROR_INVALID_ARGUMENT;
    if (def->size < sizeof(uint32_t)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "get_def: def->size not set");
    size_t sz = def->size < sizeof w->def ? def->size : sizeof w->def;
    memcpy(def, &w->def, sz);
    def->size = (uint32_t)sz;
    return CAROM_OK;
}

CAROM_API int carom_world_body_count(const carom_world *w) { return w ? w->bodies.count : 0; }


CAROM_API carom_status carom_world_get_event_children(const carom_world *w, int index, int *child_a, int *child_b)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (index < 0 || index >= w->events.count)
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "world_get_event_children: index %d outside 0..%d", index,
                          w->events.count - 1);
    int named = index < w->events.children_count; /* later events name no child */
    if (child_a) *child_a = named ? w->events.children[index][0] : -1;
    if (child_b) *child_b = named ? w->events.children[index][1] : -1;
    return CAROM_OK;
}

CAROM_API int carom_world_get_events(const carom_world *w, const carom_contact_event **events)
{
    if (!w || !events) return 0;
    *events = w->events.items;
    return w->events.count;
}

CAROM_API carom_status carom_world_get_stats(const carom_world *w, carom_world_stats *stats)
{
    if (!w || !stats) return CAROM_ERROR_INVALID_ARGUMENT;
    if (stats->size < sizeof(uint32_t)) return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "get_stats: size not set");
    carom_world_stats s = w->stats;
    s.bodies = w->bodies.count;
    size_t sz = stats->size < sizeof s ? stats->size : sizeof s;
    memcpy(stats, &s, sz);
    stats->size = (uint32_t)sz;
    return CAROM_OK;
}

/* ---- the step -------------------------------------------------------------- */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void run_deferred_destroys(carom_world *w)
{
    step_scratch *s = &w->scratch;
    for (int i = 0; i < s->deferred_count; i++) {
        int id = s->deferred_destroy[i];
        if (w->bodies.ids[id].slot >= 0) world_destroy_body(w, id);
    }
    s->deferred_count = 0;
}

CAROM_API carom_status carom_world_step(carom_world *w, double dt)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (w->locked) return world_fail(w, CAROM_ERROR_LOCKED, "step: world is locked (called from a callback?)");
    /* below 1e-6 s a hit's average force J / dt and the soft contact's 1 / h
     * leave the ranges' arithmetic (the smallest double passed as dt made it inf) */
    if (!(dt >= RANGE_DT_MIN && dt <= RANGE_DT_MAX))
        return world_fail(w, CAROM_ERROR_INVALID_ARGUMENT, "step: dt must be in [1e-6, 1] seconds (got %g)", dt);
    double t0 = now_ms();
    w->locked = 1;
    step_context ctx;
    step_context_init(&ctx, &w->def, dt);
    w->events.count = 0;
    w->events.children_count = 0;
    world_remember_poses(w);
    w->stats.clamped = 0;
    w->stats.toi_events = 0;

    double t1 = now_ms();
    /* out of memory in a stage stops the step there: later stages read what
     * the earlier ones produced this step */
    int ok = world_update_pairs(w, &ctx);
    double t2 = now_ms();
    if (ok) ok = world_collide(w, &ctx);
    if (ok) world_remove_ghost_contacts(w, &ctx);
    if (ok) world_pre_solve(w, &ctx);
    double t3 = now_ms();
    if (ok) {
        ok = world_solve(w, &ctx);
        if (ok < 0) {
            /* settings the step cannot integrate (world_solve said why): no body moved */
            w->locked = 0;
            return CAROM_ERROR_INVALID_ARGUMENT;
        }
        if (ok) world_share_merged_impulses(w, &ctx);
    }
    double t4 = now_ms();
    if (ok && w->def.enable_continuous) ok = world_continuous(w, &ctx);
    double t5 = now_ms();
    if (ok) world_update_sleep(w, &ctx);
    if (ok) ok = world_update_sensors(w, &ctx);
    double t6 = now_ms();

    w->stats.ms_broadphase = t2 - t1;
    w->stats.ms_narrowphase = t3 - t2;
    w->stats.ms_solver = t4 - t3;
    w->stats.ms_continuous = t5 - t4;
    w->stats.ms_islands = t6 - t5;
    w->stats.step_count++;

    if (w->def.event_callback) {
        w->in_callback = 1;
        for (int i = 0; i < w->events.count; i++) w->def.event_callback(w->def.event_context, &w->events.items[i]);
        w->in_callback = 0;
    }
    w->locked = 0;
    world_run_deferred_ops(w);
    run_deferred_destroys(w);
    w->stats.ms_total = now_ms() - t0;
    if (!ok) return world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "step: out of memory (the step was not solved)");
    return CAROM_OK;
}
