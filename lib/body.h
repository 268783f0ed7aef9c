/* body.h - the struct-of-arrays body store: one dense array per field indexed
 * by a slot; a sparse id table (index + generation, free list) maps ids to
 * slots; destroy swap-removes so the arrays stay dense. */
#ifndef CAROM_BODY_H
#define CAROM_BODY_H

#include <stdint.h>
#include "shape.h"

enum {
    BODY_LOCK_ROTATION = 1u << 0,
    BODY_LOCK_PLANE    = 1u << 1,
    BODY_BULLET        = 1u << 2,
    BODY_AWAKE         = 1u << 3,
    BODY_ENABLE_SLEEP  = 1u << 4,
    BODY_HAS_FORCE     = 1u << 5,
    BODY_SENSOR        = 1u << 6   /* touches nothing; sensor.c reports what overlaps it */
};

typedef struct body_id_entry {
    int slot;               /* dense slot, -1 when free */
    uint32_t generation;    /* bumped on destroy */
    int next_free;          /* free list link */
} body_id_entry;

typedef struct body_store {
    int count, capacity;
    /* sparse ids */
    body_id_entry *ids;
    int id_count, id_capacity, free_id;
    /* dense fields, index = slot */
    int *id_index;              /* slot -> id table index */
    int *type;                  /* carom_body_type */
    uint32_t *flags;
    vec3 *center;               /* world centre of mass */
    quat *rotation;
    vec3 *velocity, *angular_velocity;
    vec3 *force;                /* accumulated for the next step */
    vec3 *torque;               /* world frame, accumulated for the next step (with force: BODY_HAS_FORCE) */
    vec3 *local_center;         /* centre of mass in the body frame */
    double *mass, *inv_mass;
    mat3 *inertia_local;        /* about the centre of mass, body axes */
    mat3 *inv_inertia_local;
    mat3 *inv_inertia_world;    /* kept current for the solver */
    double *friction, *restitution;
    double *rolling_resistance; /* dimensionless (material.c) */
    int *combine;               /* carom_combine_mode of the body's material */
    double *force_threshold;    /* N: force events above it (0: none) */
    double *linear_damping, *angular_damping, *gravity_scale;
    vec3 *plane_normal;         /* lock_to_plane: unit normal */
    double *plane_offset;       /* lock_to_plane: dot(normal, centre) kept */
    double *sleep_time;         /* seconds at rest */
    shape *shapes;
    int *proxy;                 /* broadphase proxy */
    aabb *fat_box;
    void **user_data;
    uint64_t *category, *filter_mask; /* collision filtering (see carom_body_def) */
    int *group;
    vec3 *previous_origin;      /* the pose at the start of the last step (interpolation) */
    quat *previous_rotation;
    xform *collided;            /* the pose the body's last pair update and collision test used (the
                                 * start of its last awake step): never read by the step, only the
                                 * snapshot's prediction of contact poses (lib/snapshot.c) */
    int *solver_index;          /* scratch during a step */
} body_store;

int body_store_init(body_store *s, int capacity);
void body_store_free(body_store *s);
/* Reserve room for one more body (all arrays and one id). 0 on out of memory. */
int body_store_reserve(body_store *s);
/* Allocates an id and a slot (after body_store_reserve succeeded); returns the slot. */
int body_store_add(body_store *s, int *id_index_out);
/* Swap-removes the slot; bumps the id's generation; returns the slot that
 * moved into it (or -1). The shape's hull is NOT freed here. */
int body_store_remove(body_store *s, int slot);
/* Slot of a valid id, or -1. */
int body_store_slot(const body_store *s, uint32_t index1, uint32_t generation);
/* Body origin from centre of mass (and back). */
vec3 body_origin(const body_store *s, int slot);
xform body_xform(const body_store *s, int slot);
void body_update_inertia(body_store *s, int slot);

#endif
