/* carom.h - the whole public, stable C API of carom, a rigid-body collision
 * library. Double precision, SI units, z up.
 *
 * Stability rules: the def and settings structs start with a `size` field that
 * their static inline default functions stamp with the caller's compile-time
 * size; the library reads only that many bytes and defaults the rest. New
 * fields are only ever appended. Ids are values (index + generation), never
 * pointers: a stale id is detected and rejected. */
#ifndef CAROM_CAROM_H
#define CAROM_CAROM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(CAROM_BUILDING) && defined(__GNUC__)
#define CAROM_API __attribute__((visibility("default")))
#else
#define CAROM_API
#endif

/* The version: the one place it is written (the build and carom_version() read it). */
#define CAROM_VERSION_MAJOR 1
#define CAROM_VERSION_MINOR 0
#define CAROM_VERSION_PATCH 0

/* ---- values ------------------------------------------------------------ */

typedef struct carom_vec3 { double x, y, z; } carom_vec3;
/* Unit quaternion, w first. */
typedef struct carom_quat { double w, x, y, z; } carom_quat;

typedef enum carom_status {
    CAROM_OK = 0,
    CAROM_ERROR_INVALID_ARGUMENT = 1, /* NaN/inf, out of range, NULL, bad def */
    CAROM_ERROR_STALE_ID = 2,         /* the body was destroyed (or never existed) */
    CAROM_ERROR_LOCKED = 3,           /* the world is inside its step or a callback */
    CAROM_ERROR_OUT_OF_MEMORY = 4,
    CAROM_ERROR_UNSUPPORTED = 5       /* e.g. an operation a static body cannot do */
} carom_status;

/* A body id: index1 is the id slot + 1 (0 = null id); the generation changes
 * when the slot is reused, so an old id stays invalid forever. */
typedef struct carom_body_id {
    uint32_t index1;
    uint32_t generation;
} carom_body_id;

static inline carom_body_id carom_null_body(void)
{
    carom_body_id id = {0, 0};
    return id;
}
static inline int carom_body_id_is_null(carom_body_id id) { return id.index1 == 0; }
static inline uint64_t carom_body_id_pack(carom_body_id id)
{
    return ((uint64_t)id.generation << 32) | (uint64_t)id.index1;
}
static inline carom_body_id carom_body_id_unpack(uint64_t v)
{
    carom_body_id id;
    id.index1 = (uint32_t)(v & 0xffffffffu);
    id.generation = (uint32_t)(v >> 32);
    return id;
}
static inline int carom_body_id_equal(carom_body_id a, carom_body_id b)
{
    return a.index1 == b.index1 && a.generation == b.generation;
}

typedef struct carom_world carom_world;

/* ---- library ----------------------------------------------------------- */

/* "MAJOR.MINOR.PATCH" of the CAROM_VERSION_* numbers, e.g. "1.0.0" */
CAROM_API const char *carom_version(void);
/* Human-readable name of a status. */
CAROM_API const char *carom_status_string(carom_status status);

/* ---- world ------------------------------------------------------------- */

typedef enum carom_position_correction {
    CAROM_CORRECTION_SOFT = 0,      /* soft contacts (spring-damper in the constraint) */
    CAROM_CORRECTION_BAUMGARTE = 1, /* velocity bias beta * penetration / h */
    CAROM_CORRECTION_NONE = 2
} carom_position_correction;

typedef enum carom_contact_model {
    CAROM_CONTACT_IMPULSE = 0,      /* sequential impulses (rigid, the seed's classical method) */
    CAROM_CONTACT_PENALTY = 1       /* the seed's penalty springs */
} carom_contact_model;

typedef struct carom_contact_event carom_contact_event;
/* Called once per buffered event at the end of carom_world_step, while the
 * world is locked: creating bodies fails with CAROM_ERROR_LOCKED, destroying
 * is deferred to the end of the step, other setters are refused. */
typedef void carom_event_fn(void *context, const carom_contact_event *event);

/* Threads through the host's own job system (carom_world_def's task hooks).
 * The library hands the host a task over items 0 .. item_count-1; the host
 * runs it as ranges task(begin, end, worker, task_data) with
 * 0 <= begin < end <= item_count, every item in exactly one range, each range
 * at least min_range items long except possibly the last, on workers
 * 0 .. worker_count-1 (two ranges running at the same time never share a
 * worker index). The results do not depend on how the items are split or on
 * the order the ranges run in: they are bitwise the same as on one thread.
 * carom_threads.h has a reference implementation on POSIX threads. */
typedef void carom_task_fn(int begin, int end, int worker, void *task_data);
/* Starts a task; returns a handle for finish_task, or NULL when every range
 * has already run (a host may run a task inline). */
typedef void *carom_enqueue_task_fn(carom_task_fn *task, int item_count, int min_range, void *task_data,
                                    void *task_context);
/* Returns once every range of the task enqueue_task started has run. */
typedef void carom_finish_task_fn(void *task, void *task_context);
#define CAROM_MAX_WORKERS 64

typedef struct carom_world_def {
    uint32_t size;                      /* sizeof(carom_world_def), stamped by the default */
    carom_vec3 gravity;                 /* (0, 0, -9.81) */
    int substeps;                       /* 4: sub-steps per step (soft step) */
    int iterations;                     /* 1: velocity iterations per sub-step */
    int relax_iterations;               /* 1: relax passes per sub-step (0 = off) */
    carom_position_correction position_correction; /* SOFT */
    int warm_starting;                  /* 1 */
    double restitution_threshold;       /* 1.0 m/s: slower impacts do not bounce, where gravity
                                           or forces press the bodies together (the cap is twice
                                           the closing speed they add in a step; 0 without them) */
    double contact_hertz;               /* 30: soft contact stiffness */
    double contact_damping_ratio;       /* 10 */
    double contact_push_max_velocity;   /* 3 m/s: cap on the speed of push-out */
    double baumgarte;                   /* 0.2: beta for BAUMGARTE correction */
    double linear_slop;                 /* 0 m: the overlap position correction leaves alone, in
                                           every mode: soft and Baumgarte push out only the
                                           overlap beyond it (resting contacts sit that much
                                           deeper; an n-box column settles n times it more).
                                           Baumgarte jitters without one: use about 0.005 there */
    double speculative_distance;        /* 0.02 m: contacts exist this far before touching */
    carom_contact_model contact_model;  /* IMPULSE */
    double penalty_stiffness;           /* 0: auto (from contact_hertz and masses); else N/m */
    double penalty_damping;             /* 0: auto (critical from damping ratio 1); else N s/m */
    int penalty_implicit;               /* 1: implicit spring (stable); 0: explicit */
    int shock_propagation;              /* 1: bodies nearer the ground act immovable in a last
                                           bottom-up pass (holds large mass ratios) */
    int enable_friction;                /* 1 */
    int enable_restitution;             /* 1 */
    int enable_sleep;                   /* 1 */
    int enable_continuous;              /* 1: time of impact for fast and bullet bodies */
    double sleep_time;                  /* 0.5 s at rest before an island sleeps */
    double sleep_linear_velocity;       /* 0.05 m/s */
    double sleep_angular_velocity;      /* 0.05 rad/s */
    double max_linear_speed;            /* 4000 m/s: clamp; clamping raises stats.clamped */
    double max_angular_speed;           /* 0: automatic, the larger of 1000 rad/s and a quarter
                                           turn per sub-step (setters accept up to 1e9 rad/s);
                                           > 0: a cap honoured as given, also by the setters */
    int body_capacity;                  /* 0: initial storage hint */
    carom_event_fn *event_callback;     /* NULL: events are only buffered */
    void *event_context;
    double contact_reuse_distance;      /* 1e-4 m: a touching pair whose material at every
                                           contact point moved less than this relative to the
                                           other body since its manifold was computed keeps it
                                           (separations updated to first order); capped at
                                           speculative_distance; 0 = recompute every step */
    double hit_event_threshold;         /* 1.0 m/s: a contact approaching faster raises a hit
                                           event (restitution_threshold only decides bounces) */
    int worker_count;                   /* 1: workers the task hooks run ranges on, 1..CAROM_MAX_WORKERS
                                           (more than 1 needs enqueue_task) */
    carom_enqueue_task_fn *enqueue_task; /* NULL: every stage runs on the calling thread */
    carom_finish_task_fn *finish_task;  /* NULL: only with enqueue_task NULL */
    void *task_context;                 /* passed to both hooks */
} carom_world_def;

static inline carom_world_def carom_world_def_default(void)
{
    carom_world_def d;
    d.size = (uint32_t)sizeof(carom_world_def);
    d.gravity.x = 0.0; d.gravity.y = 0.0; d.gravity.z = -9.81;
    d.substeps = 4;
    d.iterations = 1;
    d.relax_iterations = 1;
    d.position_correction = CAROM_CORRECTION_SOFT;
    d.warm_starting = 1;
    d.restitution_threshold = 1.0;
    d.contact_hertz = 30.0;
    d.contact_damping_ratio = 10.0;
    d.contact_push_max_velocity = 3.0;
    d.baumgarte = 0.2;
    d.linear_slop = 0.0;
    d.speculative_distance = 0.02;
    d.contact_model = CAROM_CONTACT_IMPULSE;
    d.penalty_stiffness = 0.0;
    d.penalty_damping = 0.0;
    d.penalty_implicit = 1;
    d.shock_propagation = 1;
    d.enable_friction = 1;
    d.enable_restitution = 1;
    d.enable_sleep = 1;
    d.enable_continuous = 1;
    d.sleep_time = 0.5;
    d.sleep_linear_velocity = 0.05;
    d.sleep_angular_velocity = 0.05;
    d.max_linear_speed = 4000.0;
    d.max_angular_speed = 0.0;
    d.body_capacity = 0;
    d.event_callback = 0;
    d.event_context = 0;
    d.contact_reuse_distance = 1e-4;
    d.hit_event_threshold = 1.0;
    d.worker_count = 1;
    d.enqueue_task = 0;
    d.finish_task = 0;
    d.task_context = 0;
    return d;
}

/* Overwrites the solver fields of def with a named preset: "fast",
 * "default" or "accurate" (see README, "Choosing settings"). Only the first
 * def->size bytes are written. */
CAROM_API carom_status carom_world_def_apply_preset(carom_world_def *def, const char *preset);
/* Checks a def; on error writes a readable message to msg (if not NULL). */
CAROM_API carom_status carom_world_def_check(const carom_world_def *def, char *msg, size_t msg_size);

/* NULL when def is invalid (carom_world_def_check says why) or out of memory. */
CAROM_API carom_world *carom_world_create(const carom_world_def *def);
/* Refused (with an error message) when called from inside the world's own step. */
CAROM_API void carom_world_destroy(carom_world *world);
/* Message of the last failed call on this world ("" if none). */
CAROM_API const char *carom_world_last_error(const carom_world *world);
/* Replaces the world's settings (gravity, solver knobs, switches) between steps. */
CAROM_API carom_status carom_world_set_def(carom_world *world, const carom_world_def *def);
/* Copies the world's settings into def (def->size must be set). */
CAROM_API carom_status carom_world_get_def(const carom_world *world, carom_world_def *def);
/* Advances the world by dt seconds (0 < dt <= 1). */
CAROM_API carom_status carom_world_step(carom_world *world, double dt);
CAROM_API int carom_world_body_count(const carom_world *world);

/* ---- bodies ------------------------------------------------------------ */

typedef enum carom_body_type {
    CAROM_BODY_STATIC = 0,
    CAROM_BODY_KINEMATIC = 1,
    CAROM_BODY_DYNAMIC = 2
} carom_body_type;

typedef enum carom_shape_type {
    CAROM_SHAPE_SPHERE = 0,   /* radius */
    CAROM_SHAPE_BOX = 1,      /* half_extents */
    CAROM_SHAPE_CAPSULE = 2,  /* radius, half_height: segment on the local z axis */
    CAROM_SHAPE_CYLINDER = 3, /* radius, half_height: axis local z */
    CAROM_SHAPE_HULL = 4,     /* points (x,y,z triples), point_count >= 4, not coplanar */
    CAROM_SHAPE_PLANE = 5,    /* static only: dot(normal, x) = offset; solid where < offset */
    CAROM_SHAPE_MESH = 6,     /* static or kinematic: triangles, from carom_body_def.mesh */
    CAROM_SHAPE_HEIGHTFIELD = 7, /* static or kinematic: a grid of heights, from carom_body_def.heightfield */
    CAROM_SHAPE_COMPOUND = 8  /* several convex children, from carom_body_def.children */
} carom_shape_type;

/* A triangle mesh, copied at body creation (the body builds its own
 * bounding-volume tree once). Zero-area triangles are dropped. Edges shared
 * by two triangles at (nearly) the same slope, or folded concavely, do not
 * catch what slides across them. */
typedef struct carom_mesh_def {
    uint32_t size;            /* sizeof(carom_mesh_def), stamped by the default */
    const double *vertices;   /* x, y, z triples in the body frame */
    int vertex_count;
    const int *triangles;     /* 0-based vertex index triples, counter-clockwise seen from the front */
    int triangle_count;
    int two_sided;            /* 0: triangles collide on their front side only */
} carom_mesh_def;

static inline carom_mesh_def carom_mesh_def_default(void)
{
    carom_mesh_def d;
    d.size = (uint32_t)sizeof(carom_mesh_def);
    d.vertices = 0; d.vertex_count = 0;
    d.triangles = 0; d.triangle_count = 0;
    d.two_sided = 0;
    return d;
}

/* A height field, copied at body creation (no triangle list is kept). The
 * grid is centred on the body origin in x and y, heights are along +z;
 * heights[r * columns + c] is at x = (c - (columns - 1) / 2) cell_x,
 * y = (r - (rows - 1) / 2) cell_y. Cell (c, r), index r * (columns - 1) + c,
 * spans grid points c..c+1, r..r+1. */
typedef struct carom_heightfield_def {
    uint32_t size;            /* sizeof(carom_heightfield_def), stamped by the default */
    const double *heights;    /* rows * columns, row 0 at the lowest y */
    int rows, columns;        /* >= 2 each */
    double cell_x, cell_y;    /* grid spacing (m), > 0 */
    const int *holes;         /* NULL or hole_count cell indices without ground (not all of them) */
    int hole_count;
} carom_heightfield_def;

static inline carom_heightfield_def carom_heightfield_def_default(void)
{
    carom_heightfield_def d;
    d.size = (uint32_t)sizeof(carom_heightfield_def);
    d.heights = 0; d.rows = 0; d.columns = 0;
    d.cell_x = 1.0; d.cell_y = 1.0;
    d.holes = 0; d.hole_count = 0;
    return d;
}

typedef struct carom_shape_def {
    carom_shape_type type;
    double radius;
    double half_height;
    carom_vec3 half_extents;
    const double *points;     /* hull: copied at body creation */
    int point_count;
    carom_vec3 normal;        /* plane, body frame (need not be unit; not zero) */
    double offset;
} carom_shape_def;

static inline carom_shape_def carom_shape_sphere(double radius)
{
    carom_shape_def s = {CAROM_SHAPE_SPHERE, 0, 0, {0, 0, 0}, 0, 0, {0, 0, 1}, 0};
    s.radius = radius;
    return s;
}
static inline carom_shape_def carom_shape_box(double hx, double hy, double hz)
{
    carom_shape_def s = {CAROM_SHAPE_BOX, 0, 0, {0, 0, 0}, 0, 0, {0, 0, 1}, 0};
    s.half_extents.x = hx; s.half_extents.y = hy; s.half_extents.z = hz;
    return s;
}
static inline carom_shape_def carom_shape_capsule(double radius, double half_height)
{
    carom_shape_def s = {CAROM_SHAPE_CAPSULE, 0, 0, {0, 0, 0}, 0, 0, {0, 0, 1}, 0};
    s.radius = radius; s.half_height = half_height;
    return s;
}
static inline carom_shape_def carom_shape_cylinder(double radius, double half_height)
{
    carom_shape_def s = {CAROM_SHAPE_CYLINDER, 0, 0, {0, 0, 0}, 0, 0, {0, 0, 1}, 0};
    s.radius = radius; s.half_height = half_height;
    return s;
}
static inline carom_shape_def carom_shape_hull(const double *points, int point_count)
{
    carom_shape_def s = {CAROM_SHAPE_HULL, 0, 0, {0, 0, 0}, 0, 0, {0, 0, 1}, 0};
    s.points = points; s.point_count = point_count;
    return s;
}
static inline carom_shape_def carom_shape_plane(double nx, double ny, double nz, double offset)
{
    carom_shape_def s = {CAROM_SHAPE_PLANE, 0, 0, {0, 0, 0}, 0, 0, {0, 0, 1}, 0};
    s.normal.x = nx; s.normal.y = ny; s.normal.z = nz; s.offset = offset;
    return s;
}

/* One convex child of a compound body (sphere, box, capsule, cylinder or
 * hull), with its own pose in the body frame and its own material. The
 * body's mass, centre of mass and inertia combine the children's exactly. An
 * array of these is read with the stride of its first element's size. */
typedef struct carom_compound_child {
    uint32_t size;            /* sizeof(carom_compound_child), stamped by the default */
    carom_shape_def shape;
    carom_vec3 position;      /* the child's origin in the body frame */
    carom_quat orientation;   /* identity */
    double friction;          /* 0.6 */
    double restitution;       /* 0 */
    double density;           /* 1000 kg/m^3 (the body's mass, when given, rescales all children) */
    const struct carom_material *material; /* NULL: friction and restitution above; else copied from
                                              it at creation (friction, restitution, rolling
                                              resistance, combine) */
} carom_compound_child;

static inline carom_compound_child carom_compound_child_default(carom_shape_def shape)
{
    carom_compound_child c;
    c.size = (uint32_t)sizeof(carom_compound_child);
    c.shape = shape;
    c.position.x = 0; c.position.y = 0; c.position.z = 0;
    c.orientation.w = 1; c.orientation.x = 0; c.orientation.y = 0; c.orientation.z = 0;
    c.friction = 0.6;
    c.restitution = 0.0;
    c.density = 1000.0;
    c.material = 0;
    return c;
}

typedef struct carom_body_def {
    uint32_t size;                 /* sizeof(carom_body_def), stamped by the default */
    carom_body_type type;          /* DYNAMIC */
    carom_vec3 position;           /* body origin, world frame */
    carom_quat orientation;        /* identity; must be unit (|q| within 1e-6 of 1) */
    carom_vec3 linear_velocity;    /* of the centre of mass */
    carom_vec3 angular_velocity;   /* world frame */
    carom_shape_def shape;         /* sphere of radius 0.5 */
    double mass;                   /* > 0: total mass (wins over density); 0: use density */
    double density;                /* 1000 kg/m^3 */
    double friction;               /* 0.6 (Coulomb mu, >= 0) */
    double restitution;            /* 0 (0..1) */
    double linear_damping;         /* 0 (1/s) */
    double angular_damping;        /* 0 (1/s) */
    double gravity_scale;          /* 1 */
    int lock_rotation;             /* 0: 1 makes the body a particle (never rotates) */
    int lock_to_plane;             /* 0: 1 keeps the body in the plane through its start
                                      position with normal plane_normal (2D) */
    carom_vec3 plane_normal;       /* (0, 1, 0): the x-z plane; read only with lock_to_plane */
    int bullet;                    /* 0: 1 = swept every step, however slowly it moves (fast bodies always are) */
    int enable_sleep;              /* 1 */
    int awake;                     /* 1 */
    void *user_data;               /* NULL */
    const carom_mesh_def *mesh;    /* NULL: shape.type CAROM_SHAPE_MESH reads it */
    const carom_heightfield_def *heightfield; /* NULL: shape.type CAROM_SHAPE_HEIGHTFIELD reads it */
    const carom_compound_child *children; /* NULL: shape.type CAROM_SHAPE_COMPOUND reads child_count of them */
    int child_count;               /* 0 */
    /* collision filtering: A and B collide when (A.category & B.mask) and
     * (B.category & A.mask) are both non-zero, unless they share a non-zero
     * group: a positive group always collides, a negative one never */
    uint64_t category;             /* 1 */
    uint64_t mask;                 /* CAROM_MASK_ALL */
    int group;                     /* 0 */
    int sensor;                    /* 0: 1 makes the body a sensor: it touches nothing (no contacts,
                                      no response) and reports SENSOR_BEGIN/END events for the
                                      bodies its filter allows as they start and stop overlapping it
                                      at the end of a step (static and sleeping ones included, other
                                      sensors not; a body crossing it within one step is not seen) */
    double force_threshold;        /* 0: no force events; > 0 (N): a touching pair raises a FORCE
                                      event each step its total normal force exceeds the lower
                                      positive threshold of its two bodies */
    const struct carom_material *material; /* NULL: friction and restitution above; else copied from
                                              it at creation (see carom_material) */
} carom_body_def;

#define CAROM_MASK_ALL UINT64_MAX

static inline carom_body_def carom_body_def_default(void)
{
    carom_body_def d;
    d.size = (uint32_t)sizeof(carom_body_def);
    d.type = CAROM_BODY_DYNAMIC;
    d.position.x = 0; d.position.y = 0; d.position.z = 0;
    d.orientation.w = 1; d.orientation.x = 0; d.orientation.y = 0; d.orientation.z = 0;
    d.linear_velocity.x = 0; d.linear_velocity.y = 0; d.linear_velocity.z = 0;
    d.angular_velocity.x = 0; d.angular_velocity.y = 0; d.angular_velocity.z = 0;
    d.shape = carom_shape_sphere(0.5);
    d.mass = 0;
    d.density = 1000.0;
    d.friction = 0.6;
    d.restitution = 0.0;
    d.linear_damping = 0.0;
    d.angular_damping = 0.0;
    d.gravity_scale = 1.0;
    d.lock_rotation = 0;
    d.lock_to_plane = 0;
    d.plane_normal.x = 0; d.plane_normal.y = 1; d.plane_normal.z = 0;
    d.bullet = 0;
    d.enable_sleep = 1;
    d.awake = 1;
    d.user_data = 0;
    d.mesh = 0;
    d.heightfield = 0;
    d.children = 0;
    d.child_count = 0;
    d.category = 1;
    d.mask = CAROM_MASK_ALL;
    d.group = 0;
    d.sensor = 0;
    d.force_threshold = 0.0;
    d.material = 0;
    return d;
}

/* Returns the null id on failure (carom_world_last_error says why); the world
 * is then unchanged. */
CAROM_API carom_body_id carom_body_create(carom_world *world, const carom_body_def *def);
/* Inside an event callback the destroy is deferred to the end of the step. */
CAROM_API carom_status carom_body_destroy(carom_world *world, carom_body_id id);
CAROM_API int carom_body_is_valid(const carom_world *world, carom_body_id id);

CAROM_API carom_status carom_body_get_type(const carom_world *world, carom_body_id id, carom_body_type *out);
CAROM_API carom_status carom_body_set_type(carom_world *world, carom_body_id id, carom_body_type type);
CAROM_API carom_status carom_body_get_shape_type(const carom_world *world, carom_body_id id, carom_shape_type *out);
/* Position of the body origin; orientation (w, x, y, z). */
CAROM_API carom_status carom_body_get_position(const carom_world *world, carom_body_id id, carom_vec3 *out);
CAROM_API carom_status carom_body_set_position(carom_world *world, carom_body_id id, carom_vec3 position);
CAROM_API carom_status carom_body_get_orientation(const carom_world *world, carom_body_id id, carom_quat *out);
CAROM_API carom_status carom_body_set_orientation(carom_world *world, carom_body_id id, carom_quat q);
/* World position of the centre of mass. */
CAROM_API carom_status carom_body_get_center_of_mass(const carom_world *world, carom_body_id id, carom_vec3 *out);
CAROM_API carom_status carom_body_get_linear_velocity(const carom_world *world, carom_body_id id, carom_vec3 *out);
CAROM_API carom_status carom_body_set_linear_velocity(carom_world *world, carom_body_id id, carom_vec3 v);
CAROM_API carom_status carom_body_get_angular_velocity(const carom_world *world, carom_body_id id, carom_vec3 *out);
CAROM_API carom_status carom_body_set_angular_velocity(carom_world *world, carom_body_id id, carom_vec3 w);
/* Mass (0 for static and kinematic bodies). */
CAROM_API carom_status carom_body_get_mass(const carom_world *world, carom_body_id id, double *out);
/* Rescales the body's mass properties to a new mass > 0 (dynamic bodies). */
CAROM_API carom_status carom_body_set_mass(carom_world *world, carom_body_id id, double mass);
/* Inertia tensor about the centre of mass, body axes, row major 3x3. */
CAROM_API carom_status carom_body_get_inertia(const carom_world *world, carom_body_id id, double out[9]);
/* Centre of mass in the body frame. */
CAROM_API carom_status carom_body_get_local_center(const carom_world *world, carom_body_id id, carom_vec3 *out);
CAROM_API carom_status carom_body_get_friction(const carom_world *world, carom_body_id id, double *out);
CAROM_API carom_status carom_body_set_friction(carom_world *world, carom_body_id id, double friction);
CAROM_API carom_status carom_body_get_restitution(const carom_world *world, carom_body_id id, double *out);
CAROM_API carom_status carom_body_set_restitution(carom_world *world, carom_body_id id, double restitution);
CAROM_API carom_status carom_body_set_gravity_scale(carom_world *world, carom_body_id id, double scale);
CAROM_API carom_status carom_body_set_bullet(carom_world *world, carom_body_id id, int bullet);
CAROM_API void *carom_body_get_user_data(const carom_world *world, carom_body_id id);
CAROM_API carom_status carom_body_set_user_data(carom_world *world, carom_body_id id, void *user_data);
/* Applies impulse j (N s) at world point p (the centre of mass when p is NULL). Wakes the body. */
CAROM_API carom_status carom_body_apply_impulse(carom_world *world, carom_body_id id, carom_vec3 j,
                                                const carom_vec3 *point);
/* Adds a force (N) at the centre of mass for the next step only. */
CAROM_API carom_status carom_body_apply_force(carom_world *world, carom_body_id id, carom_vec3 force);
CAROM_API int carom_body_is_awake(const carom_world *world, carom_body_id id);
CAROM_API carom_status carom_body_set_awake(carom_world *world, carom_body_id id, int awake);
/* Kinetic energy (linear + rotational) of one body. */
CAROM_API carom_status carom_body_get_kinetic_energy(const carom_world *world, carom_body_id id, double *out);

/* ---- events, probes, queries ------------------------------------------- */

typedef enum carom_event_type {
    CAROM_EVENT_BEGIN = 0,   /* two bodies started touching */
    CAROM_EVENT_END = 1,     /* they stopped touching */
    CAROM_EVENT_HIT = 2,     /* an impact: approach speed above the restitution threshold */
    CAROM_EVENT_SENSOR_BEGIN = 3, /* body b started overlapping sensor a (see carom_body_def.sensor) */
    CAROM_EVENT_SENSOR_END = 4,   /* b stopped overlapping sensor a (or was destroyed: b is then stale) */
    CAROM_EVENT_FORCE = 5         /* a touching pair pressed harder than a body's force_threshold:
                                     average_force is the total normal force over the step (N),
                                     normal_impulse its impulse, point the manifold's centre of
                                     pressure, normal from a to b */
} carom_event_type;

struct carom_contact_event {
    carom_event_type type;
    carom_body_id a, b;
    carom_vec3 point;             /* world contact point (hit and begin) */
    carom_vec3 normal;            /* unit, from a to b */
    double normal_impulse;        /* N s over the step (hit; begin: the impulse so far) */
    double tangent_impulse;       /* magnitude of the friction impulse (N s) */
    double approach_speed;        /* relative normal speed before the impact (m/s, > 0) */
    double average_force;         /* normal_impulse / dt (N) */
};

/* Events of the last step, valid until the next step or world destroy. */
CAROM_API int carom_world_get_events(const carom_world *world, const carom_contact_event **events);

typedef struct carom_world_stats {
    uint32_t size;                /* sizeof(carom_world_stats) */
    int bodies;
    int awake_bodies;
    int islands;
    int pairs;                    /* broadphase pairs (fat AABBs overlap) */
    int contacts;                 /* touching manifolds */
    int contact_points;
    double max_penetration;       /* deepest overlap after the last step (m) */
    int clamped;                  /* velocities clamped in the last step (speed limit) */
    int toi_events;               /* time-of-impact sub-steps taken */
    int non_finite;               /* bodies whose state went non-finite and were reset */
    double ms_broadphase, ms_narrowphase, ms_solver, ms_continuous, ms_islands, ms_total;
    long long step_count;
} carom_world_stats;

static inline carom_world_stats carom_world_stats_init(void)
{
    carom_world_stats s;
    s.size = (uint32_t)sizeof(carom_world_stats);
    s.bodies = s.awake_bodies = s.islands = s.pairs = s.contacts = s.contact_points = 0;
    s.max_penetration = 0;
    s.clamped = s.toi_events = s.non_finite = 0;
    s.ms_broadphase = s.ms_narrowphase = s.ms_solver = s.ms_continuous = s.ms_islands = s.ms_total = 0;
    s.step_count = 0;
    return s;
}
/* stats->size must be set (carom_world_stats_init does it). */
CAROM_API carom_status carom_world_get_stats(const carom_world *world, carom_world_stats *stats);
/* Total kinetic energy and gravitational potential energy (relative to z = 0
 * along gravity: -m g.x) of the dynamic bodies. */
CAROM_API carom_status carom_world_get_energy(const carom_world *world, double *kinetic, double *potential);
/* Linear momentum and angular momentum about the world origin of the dynamic bodies. */
CAROM_API carom_status carom_world_get_momentum(const carom_world *world, carom_vec3 *linear, carom_vec3 *angular);

/* Deepest overlap of any pair at the bodies' current poses: an extra
 * narrowphase pass over the cached pairs (not the last step's measurement). */
CAROM_API double carom_world_measure_max_penetration(const carom_world *world);

typedef struct carom_ray_hit {
    carom_body_id body;
    carom_vec3 point;
    carom_vec3 normal;
    double fraction;              /* along the translation, 0..1 */
} carom_ray_hit;

/* Closest hit of the segment origin -> origin + translation. Returns 1 on a hit,
 * 0 on none, -1 on bad input. */
CAROM_API int carom_world_ray_cast(const carom_world *world, carom_vec3 origin, carom_vec3 translation,
                                   carom_ray_hit *hit);
/* Bodies whose bounds overlap the box [lo, hi]: fills up to capacity ids and
 * returns the total count (so a second call can size the array); -1 on bad input. */
CAROM_API int carom_world_query_aabb(const carom_world *world, carom_vec3 lo, carom_vec3 hi,
                                     carom_body_id *ids, int capacity);

/* ---- level geometry and compound bodies --------------------------------- */

/* carom_world_ray_cast, and which part of the body was hit: the child index
 * of a compound (for a ray starting inside it, the lowest-index child
 * holding the origin), the triangle index of a mesh (as given at creation),
 * the cell of a height field times 2 plus its triangle (0 lower, 1 upper);
 * -1 for other shapes. child may be NULL. */
CAROM_API int carom_world_ray_cast_child(const carom_world *world, carom_vec3 origin, carom_vec3 translation,
                                         carom_ray_hit *hit, int *child);
/* The children event `index` of carom_world_get_events names: the compound
 * child of a and of b (-1 where that body is not a compound). */
CAROM_API carom_status carom_world_get_event_children(const carom_world *world, int index, int *child_a,
                                                      int *child_b);

/* ---- snapshots ----------------------------------------------------------- */

/* Writes the world's complete state (settings, bodies, shapes, ids and
 * generations, the contact cache with its warm-start impulses, sleep timers)
 * into buf in carom's versioned little-endian format (docs/snapshot.md) and
 * returns its size in bytes. When that is more than capacity nothing usable
 * is written: call with capacity 0 (buf may be NULL) to learn the size.
 * Every shape is written, meshes, height fields and compounds whole.
 * Returns 0 for a NULL world, inside the world's step, or out of memory.
 * The event callback, its context and bodies' user data are pointers and
 * are not written. */
CAROM_API size_t carom_world_snapshot(const carom_world *world, void *buf, size_t capacity);
/* A new world from a snapshot; it continues bit for bit as the original
 * would have. NULL when the data is not a snapshot of this version, is
 * truncated or corrupted, or memory runs out: msg (if not NULL) says why. The
 * new world has no event callback and its bodies no user data. */
CAROM_API carom_world *carom_world_restore(const void *data, size_t size, char *msg, size_t msg_size);

/* carom_body_create with the failure as a status (INVALID_ARGUMENT, LOCKED,
 * OUT_OF_MEMORY; the last error says why): *out is the new body's id, or the
 * null id on failure. */
CAROM_API carom_status carom_body_try_create(carom_world *world, const carom_body_def *def, carom_body_id *out);

/* ---- filtering and game queries ---------------------------------------- */

/* The filter bits of a body (see carom_body_def). Changing them drops the
 * body's contacts that the new bits forbid (with end events) and finds the
 * new pairs at the next step; a sleeping body stays asleep. */
CAROM_API carom_status carom_body_set_filter(carom_world *world, carom_body_id id, uint64_t category, uint64_t mask,
                                             int group);
CAROM_API carom_status carom_body_get_filter(const carom_world *world, carom_body_id id, uint64_t *category,
                                             uint64_t *mask, int *group);

/* The world's pair filter: asked, during the step, about each new pair of
 * bodies whose bits allow them to touch (again whenever either body's
 * bounds move on, while they have no contact); return 0 and they do not
 * touch. It runs with the world locked. NULL (the default) allows all. A
 * contact that exists stays until the bodies separate or their bits change. */
typedef int carom_pair_filter_fn(void *context, carom_body_id a, carom_body_id b);
CAROM_API carom_status carom_world_set_pair_filter(carom_world *world, carom_pair_filter_fn *fn, void *context);

/* Which bodies a query sees: those whose category & mask is non-zero and, if
 * fn is set, for which fn returns non-zero. fn runs with the world locked
 * (it may read bodies; creating, destroying and setters are refused). */
typedef int carom_query_filter_fn(void *context, carom_body_id body);
typedef struct carom_query_filter {
    uint64_t mask;
    carom_query_filter_fn *fn;
    void *context;
} carom_query_filter;

static inline carom_query_filter carom_query_filter_default(void)
{
    carom_query_filter f;
    f.mask = CAROM_MASK_ALL;
    f.fn = 0;
    f.context = 0;
    return f;
}

/* Ray casts, all queries: a ray whose origin is inside (or on) a shape hits
 * it at fraction 0, at the origin, with the normal against the ray
 * (-translation / |translation|). filter may be NULL (every body). */
/* Closest hit through a filter; 1 hit, 0 none, -1 bad input. */
CAROM_API int carom_world_ray_cast_filtered(const carom_world *world, carom_vec3 origin, carom_vec3 translation,
                                            const carom_query_filter *filter, carom_ray_hit *hit);
/* Every hit (one per body), nearest first: fills up to capacity and returns
 * the total count (so a second call can size the array); -1 on bad input. */
CAROM_API int carom_world_ray_cast_all(const carom_world *world, carom_vec3 origin, carom_vec3 translation,
                                       const carom_query_filter *filter, carom_ray_hit *hits, int capacity);
/* Sweeps a convex shape (not a plane) from position/orientation along
 * translation: the first body it touches, the fraction of the translation,
 * the point on that body and its normal (against the sweep). A shape that
 * overlaps a body at the start hits it at fraction 0 (normal against the
 * sweep). 1 hit, 0 none, -1 bad input. */
CAROM_API int carom_world_shape_cast(const carom_world *world, const carom_shape_def *shape, carom_vec3 position,
                                     carom_quat orientation, carom_vec3 translation,
                                     const carom_query_filter *filter, carom_ray_hit *hit);
/* Bodies whose shape overlaps (or touches) the given convex shape at that
 * pose, exactly (not their bounds): fills up to capacity ids, returns the
 * total count; -1 on bad input. */
CAROM_API int carom_world_overlap(const carom_world *world, const carom_shape_def *shape, carom_vec3 position,
                                  carom_quat orientation, const carom_query_filter *filter, carom_body_id *ids,
                                  int capacity);

typedef struct carom_distance_result {
    carom_body_id body;           /* the other body (shape queries) */
    double distance;              /* between the surfaces; < 0: they overlap by that much */
    carom_vec3 point_a, point_b;  /* closest points on A (or the query shape) and on B */
    carom_vec3 normal;            /* unit, from A towards B */
} carom_distance_result;

/* Closest points of two bodies (at most one a plane). When they overlap the
 * distance is minus the deepest penetration the narrowphase measures. */
CAROM_API carom_status carom_world_body_distance(const carom_world *world, carom_body_id a, carom_body_id b,
                                                 carom_distance_result *out);
/* The body nearest to a convex shape at a pose, within max_distance (>= 0):
 * 1 found, 0 none that near, -1 bad input. Overlapping bodies are at
 * distance 0 (the first found). */
CAROM_API int carom_world_shape_distance(const carom_world *world, const carom_shape_def *shape, carom_vec3 position,
                                         carom_quat orientation, double max_distance,
                                         const carom_query_filter *filter, carom_distance_result *out);


/* ---- more body calls ----------------------------------------------------- */

/* Inside an event callback, carom_body_set_linear_velocity,
 * carom_body_set_angular_velocity, carom_body_apply_impulse,
 * carom_body_apply_angular_impulse and carom_body_apply_force are queued
 * (their vectors checked then) and applied once, in call order, right after
 * the step's callbacks; a body destroyed meanwhile is skipped. */
/* Changes the angular velocity by I^-1 impulse (N m s). Wakes the body. */
CAROM_API carom_status carom_body_apply_angular_impulse(carom_world *world, carom_body_id id, carom_vec3 impulse);
CAROM_API carom_status carom_body_set_damping(carom_world *world, carom_body_id id, double linear, double angular);
CAROM_API carom_status carom_body_get_damping(const carom_world *world, carom_body_id id, double *linear,
                                              double *angular);
/* Between the body frame (origin and axes of position/orientation) and the world. */
CAROM_API carom_status carom_body_get_world_point(const carom_world *world, carom_body_id id, carom_vec3 local,
                                                  carom_vec3 *out);
CAROM_API carom_status carom_body_get_local_point(const carom_world *world, carom_body_id id, carom_vec3 world_point,
                                                  carom_vec3 *out);
CAROM_API carom_status carom_body_get_world_vector(const carom_world *world, carom_body_id id, carom_vec3 local,
                                                   carom_vec3 *out);
CAROM_API carom_status carom_body_get_local_vector(const carom_world *world, carom_body_id id, carom_vec3 world_vector,
                                                   carom_vec3 *out);
/* The body's shape as a def (a hull's points are the hull's vertices, valid
 * while the body lives; a plane's normal is unit). */
CAROM_API carom_status carom_body_get_shape(const carom_world *world, carom_body_id id, carom_shape_def *out);
/* The pose at the start of the last step, to interpolate a render between
 * it and the current pose (after advance(): alpha). A new or teleported
 * (set_position / set_orientation) body's previous pose is its pose then. */
CAROM_API carom_status carom_body_get_previous_position(const carom_world *world, carom_body_id id, carom_vec3 *out);
CAROM_API carom_status carom_body_get_previous_orientation(const carom_world *world, carom_body_id id,
                                                           carom_quat *out);


/* ---- sensors and contact control ---------------------------------------- */

CAROM_API int carom_body_is_sensor(const carom_world *world, carom_body_id id);

/* The touching manifold handed to a pre-solve callback. */
typedef struct carom_manifold {
    carom_vec3 normal;            /* unit, from a to b */
    int point_count;              /* 1..4 */
    carom_vec3 points[4];         /* world points */
    double separations[4];        /* < 0: overlapping */
} carom_manifold;
/* Called during the step for each touching pair (neither a sensor) before
 * it is solved, with the world locked; return 0 to leave the pair out of
 * this step (no response, no impulses kept): one-way platforms, ghosts.
 * Begin/end events still follow the touching state. */
typedef int carom_pre_solve_fn(void *context, carom_body_id a, carom_body_id b, const carom_manifold *manifold);
CAROM_API carom_status carom_world_set_pre_solve(carom_world *world, carom_pre_solve_fn *fn, void *context);

typedef struct carom_contact_info {
    carom_body_id other;
    carom_vec3 normal;            /* unit, from the body asked about towards other */
    carom_vec3 point;             /* the deepest point of the manifold */
    double separation;            /* of that point (< 0 overlapping) */
    int point_count;
    double normal_impulse;        /* summed over the points, last step (N s); 0 if not solved */
} carom_contact_info;
/* The body's touching contacts: fills up to capacity and returns the total
 * count; -1 on bad input. */
CAROM_API int carom_body_get_contacts(const carom_world *world, carom_body_id id, carom_contact_info *contacts,
                                      int capacity);

/* ---- forces, force events, materials ------------------------------------ */

/* Adds a torque (N m, world frame) for the next step only: the body's
 * angular momentum grows by torque * dt over it. Wakes the body; no effect
 * on static, kinematic or rotation-locked bodies (a plane-locked body keeps
 * the part about its plane normal). Deferred inside an event callback. */
CAROM_API carom_status carom_body_apply_torque(carom_world *world, carom_body_id id, carom_vec3 torque);
/* Adds a force (N) at a world point for the next step only: the force at the
 * centre of mass and the torque (point - centre of mass) x force, the arm
 * taken now. Deferred inside an event callback. */
CAROM_API carom_status carom_body_apply_force_at_point(carom_world *world, carom_body_id id, carom_vec3 force,
                                                       carom_vec3 point);
/* The force and torque accumulated for the next step (zero after a step). */
CAROM_API carom_status carom_body_get_applied_force(const carom_world *world, carom_body_id id, carom_vec3 *force,
                                                    carom_vec3 *torque);
/* See carom_body_def.force_threshold (>= 0, finite; 0 turns the events off). */
CAROM_API carom_status carom_body_set_force_threshold(carom_world *world, carom_body_id id, double threshold);
CAROM_API carom_status carom_body_get_force_threshold(const carom_world *world, carom_body_id id, double *out);

/* How two materials mix into a contact's friction, restitution and rolling
 * resistance. When the two bodies (or children) name different modes, the
 * higher value below wins. */
typedef enum carom_combine_mode {
    CAROM_COMBINE_DEFAULT = 0,        /* friction sqrt(a b), restitution and rolling resistance max(a, b) */
    CAROM_COMBINE_AVERAGE = 1,        /* (a + b) / 2 */
    CAROM_COMBINE_GEOMETRIC_MEAN = 2, /* sqrt(a b) */
    CAROM_COMBINE_MIN = 3,
    CAROM_COMBINE_MULTIPLY = 4,       /* a b (restitution stays <= 1) */
    CAROM_COMBINE_MAX = 5
} carom_combine_mode;

/* A surface material, referred to by body defs and compound children and
 * copied into them at creation (or by carom_body_set_material). */
typedef struct carom_material {
    uint32_t size;                /* sizeof(carom_material), stamped by the default */
    double friction;              /* 0.6 (Coulomb mu, 0..1000) */
    double restitution;           /* 0 (0..1) */
    double rolling_resistance;    /* 0 (0..1000): a body rolling on flat ground without slipping
                                     slows at rolling_resistance * g (the resistance is a torque
                                     about the contact, capped by the normal force; 0 rolls freely) */
    carom_combine_mode combine;   /* DEFAULT */
} carom_material;

static inline carom_material carom_material_default(void)
{
    carom_material m;
    m.size = (uint32_t)sizeof(carom_material);
    m.friction = 0.6;
    m.restitution = 0.0;
    m.rolling_resistance = 0.0;
    m.combine = CAROM_COMBINE_DEFAULT;
    return m;
}

/* Checks a material; on error writes a readable message to msg (if not NULL). */
CAROM_API carom_status carom_material_check(const carom_material *material, char *msg, size_t msg_size);
/* Gives a body (all its children, for a compound) the material's values.
 * Touching pairs take them from their next manifold. */
CAROM_API carom_status carom_body_set_material(carom_world *world, carom_body_id id, const carom_material *material);
/* The body's material (a compound: the body-level values). out->size must be set. */
CAROM_API carom_status carom_body_get_material(const carom_world *world, carom_body_id id, carom_material *out);

/* Checks a shape def alone for a body of the given type, by the rules
 * carom_body_create applies to it (lengths in range, a hull's point count
 * and coordinates, a plane only static, a mesh or height field not
 * dynamic; the data of a mesh, height field or compound come with the body
 * def and are checked there, or alone by carom_mesh_def_check and the
 * functions after it). On error writes the reason (without a function
 * name, as carom_world_def_check) to msg (if not NULL) and returns
 * CAROM_ERROR_INVALID_ARGUMENT. */
CAROM_API carom_status carom_shape_def_check(const carom_shape_def *def, carom_body_type type, char *msg, size_t msg_size);

/* ---- structured errors and the data checks ------------------------------- */

/* The last error's reason: carom_world_last_error without the name of the
 * function that failed and its ": " ("" if none; "world is NULL" for NULL).
 * With the status the call returned, a binding reports the failure under
 * its own function's name without reading the message. */
CAROM_API const char *carom_world_last_error_reason(const carom_world *world);
/* Check the data of a mesh, a height field or a compound's children alone,
 * by the rules carom_body_create applies to them (sizes, counts, indices,
 * coordinates and heights finite and within 1e6 m, cell sizes, each child's
 * shape, pose, friction, restitution, density and material). A mesh's
 * zero-area triangles pass here: body_create drops them, and refuses a mesh
 * that has only those. On error write the reason (carom_shape_def_check's
 * style) to msg (if not NULL) and return CAROM_ERROR_INVALID_ARGUMENT. */
CAROM_API carom_status carom_mesh_def_check(const carom_mesh_def *def, char *msg, size_t msg_size);
CAROM_API carom_status carom_heightfield_def_check(const carom_heightfield_def *def, char *msg, size_t msg_size);
CAROM_API carom_status carom_compound_check(const carom_compound_child *children, int count, char *msg,
                                            size_t msg_size);

/* ---- a fixed-step clock -------------------------------------------------- */

#define CAROM_FIXED_STEP_MAX_STEPS 100000
/* For a host that steps by frame time: adds frame_time (finite, >= 0 s) to
 * *accumulator (finite, >= 0) and sets *steps to the whole steps of dt
 * (0 < dt <= 1 s) to take now, at most max_steps (1..CAROM_FIXED_STEP_MAX_STEPS).
 * The accumulator keeps the rest; a backlog beyond max_steps is dropped
 * (only its fraction of a step is kept) rather than chased, which would
 * only fall further behind. *accumulator / dt afterwards is in [0, 1): how
 * far real time is into the next step, to interpolate poses when drawing.
 * With frame_time 0 it checks dt and max_steps alone. On error writes the
 * reason to msg (if not NULL), changes nothing and returns
 * CAROM_ERROR_INVALID_ARGUMENT. */
CAROM_API carom_status carom_fixed_step(double dt, int max_steps, double frame_time, double *accumulator, int *steps,
                                        char *msg, size_t msg_size);

/* ---- restoring into a world ---------------------------------------------- */

/* carom_world_restore into an existing world (rollback networking restores
 * every frame): the world becomes the snapshot's, and continues bit for bit
 * as the snapshot's world would have. The host's settings stay: the event
 * callback and its context, the task hooks and worker count, the pair
 * filter and pre-solve callbacks, and the user data of every body the
 * snapshot also holds (the same id, index and generation); the last step's
 * events are gone. A snapshot carom_world_restore refuses is refused with
 * its reason (INVALID_ARGUMENT; OUT_OF_MEMORY; LOCKED inside the step) and
 * the world is left exactly as it was. */
CAROM_API carom_status carom_world_restore_into(carom_world *world, const void *data, size_t size);

/* ---- which part was hit: ray casts, shape casts, overlaps, contacts ------- */

/* These name the part of a body a query or contact is on, as
 * carom_world_ray_cast_child does: the child index of a compound, the
 * triangle index of a mesh (as given at creation), the cell of a height
 * field times 2 plus its triangle (0 lower, 1 upper); -1 for other shapes.
 * Each checks its input and fails as its sibling without _child(ren) does.
 * Where a ray starts inside a compound, these (and carom_world_ray_cast_child)
 * name the lowest-index child holding its origin. */

/* carom_world_ray_cast_all, and in children[i] (children may be NULL) the
 * part hits[i] is on. */
CAROM_API int carom_world_ray_cast_all_children(const carom_world *world, carom_vec3 origin, carom_vec3 translation,
                                                const carom_query_filter *filter, carom_ray_hit *hits, int *children,
                                                int capacity);
/* carom_world_shape_cast, and in *child (child may be NULL) the part the
 * sweep first touches (of several touched at the same fraction, one of them:
 * the lowest-index child of a compound). */
CAROM_API int carom_world_shape_cast_child(const carom_world *world, const carom_shape_def *shape,
                                           carom_vec3 position, carom_quat orientation, carom_vec3 translation,
                                           const carom_query_filter *filter, carom_ray_hit *hit, int *child);
/* carom_world_overlap (the same bodies, one entry each, in the same order),
 * and in children[i] (children may be NULL) the lowest-index part of ids[i]
 * the shape overlaps. */
CAROM_API int carom_world_overlap_children(const carom_world *world, const carom_shape_def *shape,
                                           carom_vec3 position, carom_quat orientation,
                                           const carom_query_filter *filter, carom_body_id *ids, int *children,
                                           int capacity);
/* For each contact carom_body_get_contacts lists (the same count and
 * order), the part of the body asked about (children_self) and of the other
 * (children_other) it is on: a compound's child, and for a mesh or height
 * field the triangle nearest the contact's point (carom_contact_info.point,
 * at the body's pose now; the lower index where two are as near), which a
 * manifold spanning several triangles does not keep itself (events name
 * none). Either array may be NULL, not both when capacity > 0. Returns the
 * total count; -1 on bad input. */
CAROM_API int carom_body_get_contact_children(const carom_world *world, carom_body_id id, int *children_self,
                                              int *children_other, int capacity);

#ifdef __cplusplus
}
#endif

#endif
