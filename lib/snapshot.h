/* snapshot.h - internal: where a snapshot's bytes go (bench/snapshot.c
 * prints it). The public face is carom_world_snapshot / carom_world_restore. */
#ifndef CAROM_SNAPSHOT_H
#define CAROM_SNAPSHOT_H

#include <stddef.h>
#include <stdint.h>
#include "world.h"

#define SNAP_FIELDS(X)                                                                                          \
    X(header) X(settings) X(ids) X(classes) X(body_header) X(body_center) X(body_orientation) X(body_velocity)   \
    X(body_spin) X(body_force) X(body_sleep) X(body_plane) X(body_previous) X(body_collided) X(body_fat)         \
    X(contact_header) X(contact_normal) X(contact_cache_normal) X(contact_material) X(contact_basis)              \
    X(contact_rel_position) X(contact_rel_rotation) X(contact_gap) X(contact_reach) X(contact_normal_a)           \
    X(point_id) X(point_local) X(point_separation) X(point_normal_impulse) X(point_tangent_impulse) X(point_world)  \
    X(sensors)

#define SNAP_FIELD_ENUM(f) SNAP_FIELD_##f,
enum { SNAP_FIELDS(SNAP_FIELD_ENUM) SNAP_FIELD_COUNT };
#undef SNAP_FIELD_ENUM

/* The snapshot's size, and in bytes[f] the bytes of each field f (summed
 * over bodies and contacts); names[f] its name. 0 on out of memory. */
size_t snapshot_field_bytes(const carom_world *w, size_t bytes[SNAP_FIELD_COUNT], const char *names[SNAP_FIELD_COUNT]);

/* How many values the coded doubles' table-driven tag gets otherwise than
 * their definition (0: it agrees for every pattern of zero bytes). */
int snapshot_coded_tags_disagree(void);
/* One group of n <= 4 coded doubles from bytes[0, size), predicted 0: the
 * bytes it took, 0 if the reader refuses it. */
size_t snapshot_coded_group_read(const unsigned char *bytes, size_t size, int n, double out[4]);
/* One varint in [lo, hi] (zigzag when is_signed) from bytes[0, size): the
 * bytes it took, 0 if the reader refuses it. */
size_t snapshot_small_read(const unsigned char *bytes, size_t size, int64_t lo, int64_t hi, int is_signed, int *out);

#endif
