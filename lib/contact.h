/* contact.h - the persistent contact cache: one contact per broadphase pair,
 * holding the manifold and the impulses matched across steps by feature id
 * (falling back to local position) so the solver can warm-start. */
#ifndef CAROM_CONTACT_H
#define CAROM_CONTACT_H

#include <stdint.h>
#include "narrowphase.h"

enum {
    CONTACT_TOUCHING     = 1u << 0,   /* manifold has points this step */
    CONTACT_WAS_TOUCHING = 1u << 1,
    CONTACT_SIM          = 1u << 2,   /* solved this step (both bodies not asleep) */
    CONTACT_REUSABLE     = 1u << 3,   /* rel_pose and the points' local_a/separation are valid */
    CONTACT_APART        = 1u << 4,   /* no manifold: rel_pose, gap and reach_b are valid */
    CONTACT_ANY_TOUCHING = 1u << 5,   /* sub 0 of a mesh pair: some manifold of the pair has points */
    /* within the collision stage only (collision.c): the manifold was
     * computed ahead, in parallel, whether it has points, and whether
     * exactly one of its bodies is dynamic (the ordered pass then reads no
     * body) */
    CONTACT_PRECOMPUTED  = 1u << 6,
    CONTACT_PRECOMPUTED_TOUCHING = 1u << 7,
    CONTACT_PRECOMPUTED_MIXED = 1u << 8
};

/* A point's state. Its first five fields are also the solver's point
 * (constraint_point, constraint.h): a solved manifold's points live here
 * during the step, not in a per-step copy (40 B a point, 420 B a body at
 * 50,000 bodies), so the impulses the solver leaves are already the next
 * step's warm start. */
typedef struct contact_point_state {
    double normal_impulse;      /* accumulated (per sub-step): warm starting; the solver's own in a step */
    double tangent_impulse[2];
    double total_normal_impulse; /* the step's, over its sub-steps (restitution, hit and force events) */
    double relative_velocity;   /* the step's normal velocity before solving (restitution, hit events) */
    vec3 local_a;               /* point in A's body frame when the manifold was computed (fallback matching) */
    double separation;          /* its separation then (a reused manifold updates from it) */
} contact_point_state;

/* What the collision stage reads for every broadphase pair, touching or not
 * (most are not): the first line holds what a pair with far-apart bounds
 * needs, the second what a pair known to be apart needs. */
typedef struct contact {
    int id_a, id_b;             /* body id-table indices: A, the solve's first body, then B, by the
                                   rule of collision.c (not by id; docs/physics.md) */
    uint32_t flags;
    uint32_t sub;               /* 0: the broadphase pair's contact; k > 0: its k-th extra
                                   manifold (a mesh or height field gives one per normal) */
    uint32_t sub_limit;         /* sub 0 of a composite pair: every extra contact's sub is below this */
    int slot;                   /* its contact_data in the pool; 0: none yet (the shared empty
                                   record: a pair without a manifold reads zeros, never writes) */
    collide_cache cache;
    xform rel_pose;             /* B's frame in A's when the manifold was computed */
    double gap, reach_b;        /* apart: a lower bound on the distance then, and B's
                                   bounding radius (how far B's surface reaches) */
} contact;

/* The manifold and warm-start state of a pair, in the pool at its slot:
 * only pairs that have (or recently had) a manifold hold one. */
typedef struct contact_data {
    double friction, restitution; /* mixed from the two bodies' materials */
    double rolling_resistance;  /* mixed likewise (material.c) */
    manifold m;
    contact_point_state state[MANIFOLD_MAX_POINTS];
    vec3 tangent1;              /* friction basis kept across steps */
    vec3 normal_a;              /* the manifold normal in A's frame when computed */
} contact_data;

/* Open-addressing map from an ordered pair of id indices and a sub to a
 * contact index. A slot holds the key's 32-bit hash and the contact (8
 * bytes; the key itself is the contact's id_a, id_b and sub, compared when
 * the hashes agree): half the bytes of a slot that kept the key. */
typedef struct pair_map {
    uint32_t *hashes;           /* hash_key of the slot's contact */
    int *values;                /* contact index; -1 = empty */
    int capacity;               /* power of two */
    int count;
} pair_map;

typedef struct contact_set {
    contact *items;
    contact_data *data;         /* the pool: data[0] stays all zeros (a slotless pair reads it) */
    int count, capacity, data_count, data_capacity;
    int free_head;              /* slots given back, reused last in first out: the last one given back
                                   (0: none), each holding the next in its first bytes (contact_data_next_free) */
    int free_count;
    pair_map map;
} contact_set;

/* Contact i's data (the empty record when it holds none: read only). */
#define CONTACT_DATA(cs, i) (&(cs)->data[(cs)->items[(i)].slot])
/* Gives contact i a zeroed data slot when it has none; 0 on out of memory.
 * Moves the pool: pointers into it are stale after. */
int contact_data_alloc(contact_set *cs, int i);
/* Gives contact i's slot back (it reads the empty record after). */
void contact_data_release(contact_set *cs, int i);
/* The free slot given back before `slot` (a free slot; 0: none): the free
 * slots are free_head, then each one's next. */
int contact_data_next_free(const contact_set *cs, int slot);
/* Whether contact i's data holds nothing a zeroed record with the pair's
 * mixed material would not: no points, no kept friction basis, and no flag
 * under which its normal or A-frame normal is read. The material is left to
 * the caller (it is the bodies' mix everywhere but in a restored snapshot). */
int contact_data_idle(const contact_set *cs, int i);

int contact_set_init(contact_set *cs);
void contact_set_free(contact_set *cs);
/* Index of the contact for (a, b) in any order, or -1. */
int contact_find(const contact_set *cs, int a, int b);
/* Adds a contact for a new pair, a its body A (the order is kept: the
 * solve's A and B); returns its index or -1 on out of memory. */
int contact_add(contact_set *cs, int a, int b);
/* Room for n contacts without growing the arrays (restoring a snapshot: the
 * map is built by contact_set_index). 0 on out of memory. */
int contact_set_reserve(contact_set *cs, int n);
/* Removes every contact, keeping the memory (a restore into an existing
 * world: the map is rebuilt by contact_set_index). */
void contact_set_clear(contact_set *cs);
/* Gives back the pool's room beyond the slots in use (after restoring). */
void contact_set_trim(contact_set *cs);
/* The same for a pair's extra manifold number sub (> 0). */
int contact_find_sub(const contact_set *cs, int a, int b, uint32_t sub);
int contact_add_sub(contact_set *cs, int a, int b, uint32_t sub);
/* Restoring a snapshot: contacts appended without the pair map (index
 * -1 on out of memory), then the map built for all of them at once, in the
 * order of their home slots (a sequential walk of the table; the map's
 * layout is never observable). contact_set_index returns 0 on out of
 * memory; *repeated: -1, or the first contact whose pair and sub an
 * earlier one has (it is not in the map). */
int contact_append(contact_set *cs, int a, int b, uint32_t sub);
int contact_set_index(contact_set *cs, int *repeated);
/* Swap-removes contact i. */
void contact_remove(contact_set *cs, int i);
/* The friction basis's first vector the solver builds for normal n when it
 * keeps none (v3_basis, normalised; zero for a zero n): a sleeping pair's
 * basis is re-expressed in it (collision.c), and the snapshot predicts a
 * kept basis from it. */
vec3 contact_rest_basis(vec3 n);
/* Carries warm-start impulses from the old manifold to the new one. */
void contact_match_points(contact_data *c, const manifold *old_m, const contact_point_state old[MANIFOLD_MAX_POINTS],
                          xform xa);

#endif
