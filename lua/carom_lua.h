/* carom_lua.h - shared between the files of the Lua module "carom"
 * (carom_lua.c: argument checking and luaopen_carom; wrap_shape.c,
 * wrap_world.c, wrap_body.c: one metatable per type, in the style of LÖVE's
 * wrap_*.cpp files). Only the public C API (carom/carom.h) is used.
 *
 * Argument numbers in error messages count the receiver of a method as #1
 * (world:add_body(t): t is #2), whether the method is called with ':' or
 * through pcall(world.add_body, world, t), and name the function explicitly,
 * so a message reads the same however the call was made. */
#ifndef CAROM_LUA_H
#define CAROM_LUA_H

#include <lua.h>
#include <lauxlib.h>
#include "carom/carom.h"
#include "carom/carom_threads.h"

#define CLUA_WORLD_MT "carom.World"
#define CLUA_BODY_MT "carom.Body"
#define CLUA_SHAPE_MT "carom.Shape"
#define CLUA_MATERIAL_MT "carom.Material"

/* A world userdata. Its user values hold the Lua side of the world: */
enum {
    WORLD_UV_PROXIES = 1, /* weak-valued: packed id -> the body's userdata (so event.a == ball) */
    WORLD_UV_IDS,         /* strong: packed id -> true, every body created here (world:bodies) */
    WORLD_UV_DATA,        /* strong: packed id -> the body's user_data */
    WORLD_UV_CALLBACK,    /* the contact callback (a function) or nil */
    WORLD_UV_ERROR,       /* message of a callback that failed during the current step */
    WORLD_UV_COUNT = WORLD_UV_ERROR
};

typedef struct clua_world {
    carom_world *world;     /* NULL once destroyed */
    lua_State *stepping;    /* the thread inside world:step (its index 1 is the world), or NULL */
    int has_callback;
    int callback_failed;    /* a callback raised an error during the current step */
    int deferred_destroys;  /* bodies destroyed from a callback: swept from the tables after the step */
    double fixed_dt;        /* advance(): the fixed step */
    double accumulator;     /* advance(): time not yet simulated */
    int max_steps;          /* advance(): steps per call before the backlog is dropped */
    carom_thread_pool *pool; /* the world option threads = N > 1: its own pool, or NULL */
} clua_world;

/* A body userdata: the id only; its single user value is its world's userdata,
 * so the world outlives every Lua reference to its bodies. */
enum { BODY_UV_WORLD = 1, BODY_UV_COUNT = 1 };
typedef struct clua_body {
    carom_body_id id;
} clua_body;

/* A shape descriptor: an immutable, validated carom_shape_def. */
typedef struct clua_shape {
    carom_shape_def def;
    double *points; /* hull points, mesh vertices, heights (owned; the world copies them at add_body) */
    int *indices;   /* mesh triangles (0-based), height field holes (owned) */
    carom_mesh_def mesh;               /* mesh: points over indices */
    carom_heightfield_def heightfield; /* heightfield: points and indices */
    carom_compound_child *children;    /* compound (owned; hull children's points in `points`) */
    carom_material *materials;         /* compound: the children's materials (owned; children point here) */
    int child_count;
} clua_shape;

/* ---- errors and arguments (carom_lua.c) ---------------------------------- */

/* Script tables are read raw (no __index or __len), so no script code can
 * run while arguments are being checked; and a carom_world pointer is read
 * from its clua_world just before each C call, never kept across anything
 * that may allocate (a collection may run a script's __gc finalizer, which
 * may destroy a world). */

/* Pushes t[key] without metamethods; returns its type. */
int clua_rawfield(lua_State *L, int t, const char *key);
/* Copies the world's last error reason (carom_world_last_error_reason: the
 * message without the C function's name; the caller names its own Lua
 * function) into buf (the world's own buffer may not outlive the next
 * allocation). */
const char *clua_copy_error(const carom_world *world, char *buf, size_t size);

/* Raises "bad argument #arg to 'fname' (message)". */
int clua_arg_error(lua_State *L, int arg, const char *fname, const char *fmt, ...);
/* Raises "bad argument #arg to 'fname' (expected expected, got <type>)". */
int clua_type_error(lua_State *L, int arg, const char *fname, const char *expected);
/* A finite number. */
double clua_check_number(lua_State *L, int arg, const char *fname);
/* An integer (a number with an exact integer value) in [lo, hi]. */
lua_Integer clua_check_integer(lua_State *L, int arg, const char *fname, lua_Integer lo, lua_Integer hi);
int clua_check_boolean(lua_State *L, int arg, const char *fname);
/* One of names (NULL-terminated); returns its index. */
int clua_check_option(lua_State *L, int arg, const char *fname, const char *const *names);
/* A vector as a table {x, y, z} (or {x=, y=, z=}) or as three numbers
 * starting at arg; returns the index of the argument after it. */
int clua_check_vec3(lua_State *L, int arg, const char *fname, carom_vec3 *out);
/* A quaternion {w, x, y, z} or four numbers; returns the next argument index. */
int clua_check_quat(lua_State *L, int arg, const char *fname, carom_quat *out);

void clua_push_vec3_table(lua_State *L, carom_vec3 v);
int clua_return_vec3(lua_State *L, carom_vec3 v);

/* Options tables (argument arg, a table): an unknown key is an error; each
 * reader returns 1 if the key is present (and then valid), 0 if absent. */
void clua_check_table(lua_State *L, int arg, const char *fname);
void clua_check_keys(lua_State *L, int arg, const char *fname, const char *const *allowed);
/* The same, also allowing the positions 1..positions. Which error is raised
 * does not depend on the table's traversal order (that changes from run to
 * run): a key of another type first, then a position out of range, then the
 * alphabetically first unknown name. */
void clua_check_option_keys(lua_State *L, int arg, const char *fname, const char *const *allowed, int positions);
int clua_field_number(lua_State *L, int arg, const char *fname, const char *key, double *out);
int clua_field_int(lua_State *L, int arg, const char *fname, const char *key, int *out);
int clua_field_bool(lua_State *L, int arg, const char *fname, const char *key, int *out);
int clua_field_vec3(lua_State *L, int arg, const char *fname, const char *key, carom_vec3 *out);
int clua_field_quat(lua_State *L, int arg, const char *fname, const char *key, carom_quat *out);
int clua_field_option(lua_State *L, int arg, const char *fname, const char *key, const char *const *names, int *out);

/* Message handler for lua_pcall: the message (or its __tostring) with a traceback. */
int clua_traceback(lua_State *L);

/* ---- types ---------------------------------------------------------------- */

/* The live world at arg ("world has been destroyed" otherwise). */
clua_world *clua_check_world(lua_State *L, int arg, const char *fname);
/* The shape descriptor at arg. */
clua_shape *clua_check_shape(lua_State *L, int arg, const char *fname);
/* Pushes the Lua body for id, reusing the existing userdata if there is one. */
void clua_push_body(lua_State *L, int world_index, carom_body_id id);
/* Drops a destroyed body from its world's tables. */
void clua_forget_body(lua_State *L, int world_index, carom_body_id id);
/* Removes destroyed bodies from the world's tables (after deferred destroys). */
void clua_sweep_bodies(lua_State *L, int world_index);

extern const char *const clua_shape_names[];
extern const char *const clua_body_type_names[];

void clua_open_shapes(lua_State *L);  /* metatable + carom.sphere ... carom.plane into the table on top */
void clua_open_world(lua_State *L);   /* metatable + carom.world */
void clua_open_body(lua_State *L);    /* metatable */
void clua_open_game(lua_State *L);    /* wrap_game.c: filtering and query methods, after the two above */
/* add_body's category/mask/group keys (wrap_game.c). */
void clua_read_filter_keys(lua_State *L, int arg, const char *fname, carom_body_def *d);
/* wrap_material.c: carom.material and the force and material body calls (after clua_open_body). */
void clua_open_material(lua_State *L);
/* add_body's material and force_threshold keys (the material stays referenced by the table at arg). */
void clua_read_material_keys(lua_State *L, int arg, const char *fname, carom_body_def *d);
/* The live body at arg: its world (raises naming the argument when the body
 * or its world is gone) and its id (wrap_game.c). */
carom_world *clua_check_body_id(lua_State *L, int arg, const char *fname, carom_body_id *id);
/* The carom.Material at arg. */
const carom_material *clua_check_material(lua_State *L, int arg, const char *fname);

#endif
