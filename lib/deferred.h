/* deferred.h - velocity changes asked for inside an event callback (the world
 * is locked then), kept in call order and applied once, right after the
 * callbacks of the step. */
#ifndef CAROM_DEFERRED_H
#define CAROM_DEFERRED_H

#include "world.h"

typedef enum deferred_kind {
    DEFER_IMPULSE,            /* carom_body_apply_impulse (point optional) */
    DEFER_ANGULAR_IMPULSE,    /* carom_body_apply_angular_impulse */
    DEFER_LINEAR_VELOCITY,    /* carom_body_set_linear_velocity */
    DEFER_ANGULAR_VELOCITY,   /* carom_body_set_angular_velocity */
    DEFER_FORCE,              /* carom_body_apply_force: for the next step */
    DEFER_TORQUE,             /* carom_body_apply_torque: for the next step */
    DEFER_FORCE_AT_POINT      /* carom_body_apply_force_at_point: for the next step */
} deferred_kind;

typedef struct deferred_op {
    deferred_kind kind;
    carom_body_id id;
    carom_vec3 value, point;
    int has_point;
} deferred_op;

/* Queues an op (its vectors must be finite: checked here, fn names the
 * caller in the error). */
carom_status world_defer_op(carom_world *w, deferred_kind kind, carom_body_id id, carom_vec3 value,
                            const carom_vec3 *point, const char *fn);
/* Applies the queued ops in order (bodies destroyed since are skipped) and
 * empties the queue; called by the step once the world is unlocked. */
void world_run_deferred_ops(carom_world *w);

#endif
