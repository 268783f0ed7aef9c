/* world.h - the world: settings, body store, broadphase, contacts, events,
 * stats. Internal; the public face is include/carom/carom.h. */
#ifndef CAROM_WORLD_H
#define CAROM_WORLD_H

#include "carom/carom.h"
#include "body.h"
#include "broadphase.h"
#include "contact.h"
#include "impulse.h"
#include "step.h"
#include "solver.h"
#include "impact.h"

#define WORLD_ERROR_SIZE 256
/* Fat AABB margin (m): a body moves this far before its proxy is re-inserted. */
#define WORLD_AABB_MARGIN 0.1

typedef struct event_buffer {
    carom_contact_event *items;
    int count, capacity;
    int (*children)[2];         /* per event below children_count: compound child of a and of b, -1 none;
                                   events from children_count on name none (most worlds have no
                                   compound: 8 B an event, 1 MB at a 50,000-body first step, unwritten) */
    int children_count, children_capacity;
} event_buffer;

/* Scratch arrays reused every step (never freed between steps). */
typedef struct step_scratch {
    impulse_body *bodies;       /* solver bodies: index 0 is the shared static body */
    vec3 *delta_position;       /* per solver body, since the start of the step */
    vec3 *delta_rotation;       /* accumulated rotation vector (small-angle) */
    int *body_slot;             /* solver body -> store slot */
    int body_capacity;
    solver_memory solver;       /* solver.c's constraints and batches */
    int *island_parent;         /* union-find over id indices */
    int island_capacity;
    aabb *tight_box;            /* per store slot, awake dynamic/kinematic bodies: this step's bounds */
    xform *pose;                /* per store slot, same bodies: this step's body frame */
    struct look_ahead *ahead;   /* per store slot, every body: the motion the collision stage looks
                                   ahead for (collision.c; toi.c sweeps what it did not foresee) */
    unsigned char *refit;       /* per store slot, on several workers: 1 where the collision stage
                                   moves the body's proxy (collision.c) */
    int slot_capacity;
    int *touching;              /* contacts solved this step (SIM and TOUCHING), by index */
    int touching_count, touching_capacity;
    int *mixed;                 /* indices into touching of the contacts between a dynamic body and a
                                   static or kinematic one (the seam pass reads these alone) */
    int mixed_count, mixed_capacity;
    impact_memory impact;       /* impact.c's per-body states and pairs */
    int *asleep_pairs;          /* contacts both of whose bodies slept when the collision pass met them */
    int asleep_pair_count, asleep_pair_capacity;
    void *toi;                  /* toi.c's per-slot index of the bodies its sweeps read */
    size_t toi_capacity;
    struct toi_body *toi_bodies; /* toi.c: those bodies' sweeps and stop fractions */
    int toi_body_count, toi_body_capacity;
    int *toi_fast, *toi_near;   /* toi.c: the fast bodies, and those near one's path (each with merge space) */
    int toi_fast_capacity, toi_near_capacity;
    int *deferred_destroy;      /* id indices destroyed from callbacks */
    int deferred_count, deferred_capacity;
    uint64_t *new_pairs;        /* pairs the broadphase found this step, sorted before they are added */
    int new_pair_count, new_pair_capacity;
    struct deferred_op *deferred_ops; /* velocity changes from callbacks (deferred.c) */
    int deferred_op_count, deferred_op_capacity;
    int *merged;                /* ghost.c: (lead, follower) contact indices of this step's coplanar merges */
    int merged_count, merged_capacity; /* pairs, capacity in ints */
} step_scratch;

/* A sensor and a body overlapping it after the last step (sensor.c). */
typedef struct sensor_overlap {
    carom_body_id sensor, other;
} sensor_overlap;

struct carom_world {
    carom_world_def def;
    body_store bodies;
    broadphase *bp;
    contact_set contacts;
    event_buffer events;
    step_scratch scratch;
    carom_world_stats stats;
    int locked;                 /* inside step or a callback */
    int in_callback;
    carom_pair_filter_fn *pair_filter; /* carom_world_set_pair_filter (filter.c) */
    void *pair_filter_context;
    int filters_settled;        /* 1 once a collision pass has checked every contact's filter bits and no
                                   body's bits changed since (set_filter clears it; 0 in a new world) */
    carom_pre_solve_fn *pre_solve;     /* carom_world_set_pre_solve (sensor.c) */
    void *pre_solve_context;
    sensor_overlap *sensor_overlaps; /* sorted by sensor, then other */
    int sensor_overlap_count, sensor_overlap_capacity;
    char error[WORLD_ERROR_SIZE];
    int error_reason;           /* error + error_reason: the message without the failing function's name */
    carom_status last_status;   /* the status world_fail last recorded */
    struct carom_world *spare;  /* carom_world_restore_into's other buffer: the state before the last
                                   restore, its memory kept for the next (snapshot.c); NULL: none */
};

/* The angular speed clamp. max_angular_speed > 0 is the user's cap, honoured
 * as given (also by the setters). 0 (the default) is automatic: the step
 * clamps at the larger of 1000 rad/s and a quarter turn per sub-step, so it
 * never alters a body the rotation can still resolve (w h < pi/2, the
 * quarter-turn rule), and setters accept up to the range's ceiling. */
#define WORLD_SPIN_AUTO_FLOOR 1000.0 /* rad/s: the automatic clamp at long steps */
#define WORLD_SPIN_AUTO_LIMIT 1e9    /* rad/s: what setters accept when automatic (RANGE_SPEED_MAX) */
static inline double world_spin_clamp(const carom_world_def *d, double h)
{
    if (d->max_angular_speed > 0.0) return d->max_angular_speed;
    double quarter_turn = 1.5707963267948966 / h;
    return quarter_turn > WORLD_SPIN_AUTO_FLOOR ? quarter_turn : WORLD_SPIN_AUTO_FLOOR;
}
static inline double world_spin_limit(const carom_world_def *d)
{
    return d->max_angular_speed > 0.0 ? d->max_angular_speed : WORLD_SPIN_AUTO_LIMIT;
}

#include "world_state.h"

#endif
