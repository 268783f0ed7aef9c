/* carom_lua.c - the Lua 5.4 module "carom": worlds, bodies and shape
 * descriptors as full userdata with one metatable per type. Bodies hold ids,
 * never pointers; every argument is checked and every failure is a Lua error
 * naming the bad argument. Callbacks run under lua_pcall with a traceback, and
 * their errors are raised after the step, with the world consistent. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <lua.h>
#include <lauxlib.h>
#include "carom/carom.h"

#define WORLD_MT "carom.World"
#define BODY_MT "carom.Body"
#define SHAPE_MT "carom.Shape"

#if defined(__GNUC__)
#define CAROM_LUA_EXPORT __attribute__((visibility("default")))
#else
#define CAROM_LUA_EXPORT
#endif

typedef struct lworld {
    carom_world *w;
    lua_State *L;          /* the thread running the current step */
    double fixed_dt, accumulator;
    int max_steps;         /* per advance() call: avoids the spiral of death */
    int callback_error;    /* a callback failed during this step */
} lworld;

typedef struct lbody {
    carom_body_id id;
} lbody;

typedef struct lshape {
    carom_shape_def def;
    double *points;        /* hull points, owned */
} lshape;

/* uservalues of a world: 1 = bodies table (packed id -> body), 2 = contact callback,
 * 3 = error message of a failed callback */
/* uservalues of a body: 1 = its world, 2 = user data */

/* ---- arguments ------------------------------------------------------------- */

static int finite3(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* A vector as three numbers or a table {x, y, z}; returns the next argument index. */
static int check_vec3(lua_State *L, int arg, carom_vec3 *out)
{
    if (lua_type(L, arg) == LUA_TTABLE) {
        double c[3];
        for (int i = 0; i < 3; i++) {
            lua_geti(L, arg, i + 1);
            if (!lua_isnumber(L, -1)) luaL_argerror(L, arg, "expected a vector {x, y, z} of numbers");
            c[i] = lua_tonumber(L, -1);
            lua_pop(L, 1);
        }
        out->x = c[0]; out->y = c[1]; out->z = c[2];
        if (!finite3(*out)) luaL_argerror(L, arg, "vector components must be finite");
        return arg + 1;
    }
    out->x = luaL_checknumber(L, arg);
    out->y = luaL_checknumber(L, arg + 1);
    out->z = luaL_checknumber(L, arg + 2);
    if (!finite3(*out)) luaL_argerror(L, arg, "vector components must be finite");
    return arg + 3;
}

static void push_vec3(lua_State *L, carom_vec3 v)
{
    lua_createtable(L, 3, 0);
    lua_pushnumber(L, v.x); lua_rawseti(L, -2, 1);
    lua_pushnumber(L, v.y); lua_rawseti(L, -2, 2);
    lua_pushnumber(L, v.z); lua_rawseti(L, -2, 3);
}

static int return_vec3(lua_State *L, carom_vec3 v)
{
    lua_pushnumber(L, v.x);
    lua_pushnumber(L, v.y);
    lua_pushnumber(L, v.z);
    return 3;
}

/* Field `key` of the options table at `arg` as a vector (false if absent). */
static int opt_vec3_field(lua_State *L, int arg, const char *key, carom_vec3 *out)
{
    int t = lua_getfield(L, arg, key);
    if (t == LUA_TNIL) { lua_pop(L, 1); return 0; }
    if (t != LUA_TTABLE) luaL_error(L, "bad argument #%d (%s must be a vector {x, y, z})", arg, key);
    double c[3];
    for (int i = 0; i < 3; i++) {
        lua_geti(L, -1, i + 1);
        if (!lua_isnumber(L, -1)) luaL_error(L, "bad argument #%d (%s must be a vector of 3 numbers)", arg, key);
        c[i] = lua_tonumber(L, -1);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    out->x = c[0]; out->y = c[1]; out->z = c[2];
    if (!finite3(*out)) luaL_error(L, "bad argument #%d (%s must be finite)", arg, key);
    return 1;
}

static int opt_number_field(lua_State *L, int arg, const char *key, double *out)
{
    int t = lua_getfield(L, arg, key);
    if (t == LUA_TNIL) { lua_pop(L, 1); return 0; }
    if (!lua_isnumber(L, -1)) luaL_error(L, "bad argument #%d (%s must be a number)", arg, key);
    *out = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (!isfinite(*out)) luaL_error(L, "bad argument #%d (%s must be finite)", arg, key);
    return 1;
}

static int opt_int_field(lua_State *L, int arg, const char *key, int *out)
{
    double v;
    if (!opt_number_field(L, arg, key, &v)) return 0;
    if (v != floor(v) || v < -1e9 || v > 1e9) luaL_error(L, "bad argument #%d (%s must be an integer)", arg, key);
    *out = (int)v;
    return 1;
}

static int opt_bool_field(lua_State *L, int arg, const char *key, int *out)
{
    int t = lua_getfield(L, arg, key);
    if (t == LUA_TNIL) { lua_pop(L, 1); return 0; }
    if (t != LUA_TBOOLEAN) luaL_error(L, "bad argument #%d (%s must be a boolean)", arg, key);
    *out = lua_toboolean(L, -1);
    lua_pop(L, 1);
    return 1;
}

/* Rejects keys of the options table at `arg` that are not in `allowed`. */
static void check_keys(lua_State *L, int arg, const char *fname, const char *const *allowed)
{
    lua_pushnil(L);
    while (lua_next(L, arg)) {
        lua_pop(L, 1);
        if (lua_type(L, -1) != LUA_TSTRING) luaL_error(L, "bad argument #%d to '%s' (option keys must be strings)", arg, fname);
        const char *k = lua_tostring(L, -1);
        int ok = 0;
        for (int i = 0; allowed[i]; i++) if (strcmp(k, allowed[i]) == 0) ok = 1;
        if (!ok) luaL_error(L, "bad argument #%d to '%s' (unknown option '%s')", arg, fname, k);
    }
}

/* ---- shapes ---------------------------------------------------------------- */

static lshape *new_shape(lua_State *L)
{
    lshape *s = lua_newuserdatauv(L, sizeof *s, 0);
    memset(s, 0, sizeof *s);
    luaL_setmetatable(L, SHAPE_MT);
    return s;
}

static double positive_field(lua_State *L, const char *fname, const char *key)
{
    double v = 0;
    if (!opt_number_field(L, 1, key, &v)) luaL_error(L, "bad argument #1 to '%s' (%s is required)", fname, key);
    if (!(v > 0)) luaL_error(L, "bad argument #1 to '%s' (%s must be positive)", fname, key);
    return v;
}

static int l_sphere(lua_State *L)
{
    static const char *const keys[] = {"radius", NULL};
    luaL_checktype(L, 1, LUA_TTABLE);
    check_keys(L, 1, "sphere", keys);
    double r = positive_field(L, "sphere", "radius");
    new_shape(L)->def = carom_shape_sphere(r);
    return 1;
}

static int l_box(lua_State *L)
{
    static const char *const keys[] = {"half_extents", NULL};
    luaL_checktype(L, 1, LUA_TTABLE);
    check_keys(L, 1, "box", keys);
    carom_vec3 h;
    if (!opt_vec3_field(L, 1, "half_extents", &h)) luaL_error(L, "bad argument #1 to 'box' (half_extents is required)");
    if (!(h.x > 0 && h.y > 0 && h.z > 0)) luaL_error(L, "bad argument #1 to 'box' (half_extents must be positive)");
    new_shape(L)->def = carom_shape_box(h.x, h.y, h.z);
    return 1;
}

static int round_shape(lua_State *L, const char *fname, int capsule)
{
    static const char *const keys[] = {"radius", "half_height", NULL};
    luaL_checktype(L, 1, LUA_TTABLE);
    check_keys(L, 1, fname, keys);
    double r = positive_field(L, fname, "radius");
    double h = positive_field(L, fname, "half_height");
    new_shape(L)->def = capsule ? carom_shape_capsule(r, h) : carom_shape_cylinder(r, h);
    return 1;
}

static int l_capsule(lua_State *L) { return round_shape(L, "capsule", 1); }
static int l_cylinder(lua_State *L) { return round_shape(L, "cylinder", 0); }

static int shape_gc(lua_State *L)
{
    lshape *s = luaL_checkudata(L, 1, SHAPE_MT);
    free(s->points);
    s->points = NULL;
    return 0;
}

static int l_hull(lua_State *L)
{
    static const char *const keys[] = {"points", NULL};
    luaL_checktype(L, 1, LUA_TTABLE);
    check_keys(L, 1, "hull", keys);
    if (lua_getfield(L, 1, "points") != LUA_TTABLE) luaL_error(L, "bad argument #1 to 'hull' (points must be a table of vectors)");
    lua_Integer n = luaL_len(L, -1);
    if (n < 4 || n > 100000) luaL_error(L, "bad argument #1 to 'hull' (a hull needs 4 to 100000 points)");
    lshape *s = new_shape(L); /* owns the array, so an error below cannot leak it */
    s->points = malloc(sizeof(double) * 3 * (size_t)n);
    if (!s->points) luaL_error(L, "hull: out of memory");
    for (lua_Integer i = 0; i < n; i++) {
        lua_geti(L, -2, i + 1);
        if (!lua_istable(L, -1)) luaL_error(L, "bad argument #1 to 'hull' (point %d is not a vector)", (int)i + 1);
        for (int c = 0; c < 3; c++) {
            lua_geti(L, -1, c + 1);
            if (!lua_isnumber(L, -1)) luaL_error(L, "bad argument #1 to 'hull' (point %d is not a vector of 3 numbers)", (int)i + 1);
            double v = lua_tonumber(L, -1);
            if (!isfinite(v)) luaL_error(L, "bad argument #1 to 'hull' (point %d is not finite)", (int)i + 1);
            s->points[3 * i + c] = v;
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    s->def = carom_shape_hull(s->points, (int)n);
    return 1;
}

static int l_plane(lua_State *L)
{
    static const char *const keys[] = {"normal", "offset", NULL};
    luaL_checktype(L, 1, LUA_TTABLE);
    check_keys(L, 1, "plane", keys);
    carom_vec3 n = {0, 0, 1};
    double off = 0;
    opt_vec3_field(L, 1, "normal", &n);
    opt_number_field(L, 1, "offset", &off);
    if (n.x == 0 && n.y == 0 && n.z == 0) luaL_error(L, "bad argument #1 to 'plane' (normal must not be zero)");
    new_shape(L)->def = carom_shape_plane(n.x, n.y, n.z, off);
    return 1;
}

static int shape_tostring(lua_State *L)
{
    lshape *s = luaL_checkudata(L, 1, SHAPE_MT);
    static const char *const names[] = {"sphere", "box", "capsule", "cylinder", "hull", "plane"};
    lua_pushfstring(L, "carom.%s", names[s->def.type]);
    return 1;
}

/* ---- worlds ---------------------------------------------------------------- */

static lworld *check_world(lua_State *L, int arg)
{
    lworld *lw = luaL_checkudata(L, arg, WORLD_MT);
    if (!lw->w) luaL_error(L, "world has been destroyed");
    return lw;
}

static void world_event_callback(void *ctx, const carom_contact_event *e);

static void apply_world_options(lua_State *L, int arg, carom_world_def *d, lworld *lw)
{
    static const char *const keys[] = {"gravity", "substeps", "iterations", "relax_iterations", "ccd", "sleep",
                                       "friction", "restitution", "contact_model", "preset", "hertz", "damping_ratio",
                                       "warm_starting", "position_correction", "shock_propagation",
                                       "restitution_threshold", "speculative_distance", "linear_slop",
                                       "penalty_stiffness", "penalty_damping", "penalty_implicit", "dt", "max_steps",
                                       "push_velocity", "baumgarte", NULL};
    check_keys(L, arg, "world", keys);
    if (lua_getfield(L, arg, "preset") != LUA_TNIL) {
        const char *p = lua_tostring(L, -1);
        if (!p || carom_world_def_apply_preset(d, p) != CAROM_OK)
            luaL_error(L, "bad argument #%d to 'world' (preset must be \"fast\", \"default\" or \"accurate\")", arg);
    }
    lua_pop(L, 1);
    opt_vec3_field(L, arg, "gravity", &d->gravity);
    opt_int_field(L, arg, "substeps", &d->substeps);
    opt_int_field(L, arg, "iterations", &d->iterations);
    opt_int_field(L, arg, "relax_iterations", &d->relax_iterations);
    opt_bool_field(L, arg, "ccd", &d->enable_continuous);
    opt_bool_field(L, arg, "sleep", &d->enable_sleep);
    opt_bool_field(L, arg, "friction", &d->enable_friction);
    opt_bool_field(L, arg, "restitution", &d->enable_restitution);
    opt_bool_field(L, arg, "warm_starting", &d->warm_starting);
    opt_bool_field(L, arg, "shock_propagation", &d->shock_propagation);
    opt_bool_field(L, arg, "penalty_implicit", &d->penalty_implicit);
    opt_number_field(L, arg, "hertz", &d->contact_hertz);
    opt_number_field(L, arg, "damping_ratio", &d->contact_damping_ratio);
    opt_number_field(L, arg, "restitution_threshold", &d->restitution_threshold);
    opt_number_field(L, arg, "speculative_distance", &d->speculative_distance);
    opt_number_field(L, arg, "linear_slop", &d->linear_slop);
    opt_number_field(L, arg, "penalty_stiffness", &d->penalty_stiffness);
    opt_number_field(L, arg, "penalty_damping", &d->penalty_damping);
    opt_number_field(L, arg, "push_velocity", &d->contact_push_max_velocity);
    opt_number_field(L, arg, "baumgarte", &d->baumgarte);
    if (lua_getfield(L, arg, "contact_model") != LUA_TNIL) {
        const char *m = lua_tostring(L, -1);
        if (m && strcmp(m, "impulse") == 0) d->contact_model = CAROM_CONTACT_IMPULSE;
        else if (m && strcmp(m, "penalty") == 0) d->contact_model = CAROM_CONTACT_PENALTY;
        else luaL_error(L, "bad argument #%d to 'world' (contact_model must be \"impulse\" or \"penalty\")", arg);
    }
    lua_pop(L, 1);
    if (lua_getfield(L, arg, "position_correction") != LUA_TNIL) {
        const char *m = lua_tostring(L, -1);
        if (m && strcmp(m, "soft") == 0) d->position_correction = CAROM_CORRECTION_SOFT;
        else if (m && strcmp(m, "baumgarte") == 0) d->position_correction = CAROM_CORRECTION_BAUMGARTE;
        else if (m && strcmp(m, "none") == 0) d->position_correction = CAROM_CORRECTION_NONE;
        else luaL_error(L, "bad argument #%d to 'world' (position_correction must be \"soft\", \"baumgarte\" or \"none\")", arg);
    }
    lua_pop(L, 1);
    if (lw) {
        double dt = lw->fixed_dt;
        if (opt_number_field(L, arg, "dt", &dt) && !(dt > 0 && dt <= 1))
            luaL_error(L, "bad argument #%d to 'world' (dt must be in (0, 1])", arg);
        lw->fixed_dt = dt;
        int ms = lw->max_steps;
        if (opt_int_field(L, arg, "max_steps", &ms) && ms < 1)
            luaL_error(L, "bad argument #%d to 'world' (max_steps must be >= 1)", arg);
        lw->max_steps = ms;
    }
    char msg[256];
    if (carom_world_def_check(d, msg, sizeof msg) != CAROM_OK) luaL_error(L, "bad argument #%d to 'world' (%s)", arg, msg);
}

static int l_world(lua_State *L)
{
    carom_world_def d = carom_world_def_default();
    lworld *lw = lua_newuserdatauv(L, sizeof *lw, 3);
    memset(lw, 0, sizeof *lw);
    lw->fixed_dt = 1.0 / 60.0;
    lw->max_steps = 8;
    luaL_setmetatable(L, WORLD_MT);
    if (!lua_isnoneornil(L, 1)) {
        luaL_checktype(L, 1, LUA_TTABLE);
        apply_world_options(L, 1, &d, lw);
    }
    d.event_callback = world_event_callback;
    d.event_context = lw;
    lw->w = carom_world_create(&d);
    if (!lw->w) luaL_error(L, "world: could not create the world (out of memory)");
    lua_newtable(L);
    lua_setiuservalue(L, -2, 1);
    return 1;
}

static int world_configure(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    carom_world_def d = carom_world_def_default();
    carom_world_get_def(lw->w, &d);
    apply_world_options(L, 2, &d, lw);
    if (carom_world_set_def(lw->w, &d) != CAROM_OK) luaL_error(L, "%s", carom_world_last_error(lw->w));
    return 0;
}

static int world_destroy(lua_State *L)
{
    lworld *lw = luaL_checkudata(L, 1, WORLD_MT);
    if (lw->w) {
        if (lw->L) luaL_error(L, "cannot destroy a world inside its own step");
        carom_world_destroy(lw->w);
        lw->w = NULL;
    }
    return 0;
}

static int world_tostring(lua_State *L)
{
    lworld *lw = luaL_checkudata(L, 1, WORLD_MT);
    if (!lw->w) lua_pushliteral(L, "carom.World (destroyed)");
    else lua_pushfstring(L, "carom.World (%d bodies)", carom_world_body_count(lw->w));
    return 1;
}

/* Pushes the Lua body for an id (creating a proxy if the world made it). */
static void push_body(lua_State *L, int world_idx, carom_body_id id)
{
    world_idx = lua_absindex(L, world_idx);
    lua_getiuservalue(L, world_idx, 1);
    lua_Integer key = (lua_Integer)carom_body_id_pack(id);
    if (lua_rawgeti(L, -1, key) == LUA_TUSERDATA) {
        lua_remove(L, -2);
        return;
    }
    lua_pop(L, 1);
    lbody *b = lua_newuserdatauv(L, sizeof *b, 2);
    b->id = id;
    luaL_setmetatable(L, BODY_MT);
    lua_pushvalue(L, world_idx);
    lua_setiuservalue(L, -2, 1);
    lua_pushvalue(L, -1);
    lua_rawseti(L, -3, key);
    lua_remove(L, -2);
}

static const char *const body_keys[] = {"type", "shape", "position", "velocity", "orientation", "angular_velocity",
                                        "mass", "density", "restitution", "friction", "bullet", "lock_rotation",
                                        "lock_to_plane", "plane_normal", "gravity_scale", "linear_damping",
                                        "angular_damping", "sleep", "awake", "data", NULL};

/* Errors of add_body name it and its table argument explicitly (as
 * "bad argument #2 to 'add_body' (...)"), however the method was reached. */
static int add_body_error(lua_State *L, const char *msg)
{
    return luaL_error(L, "bad argument #2 to 'add_body' (%s)", msg);
}

static int world_add_body(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    check_keys(L, 2, "add_body", body_keys);
    carom_body_def d = carom_body_def_default();
    if (lua_getfield(L, 2, "type") != LUA_TNIL) {
        const char *t = lua_tostring(L, -1);
        if (t && strcmp(t, "static") == 0) d.type = CAROM_BODY_STATIC;
        else if (t && strcmp(t, "kinematic") == 0) d.type = CAROM_BODY_KINEMATIC;
        else if (t && strcmp(t, "dynamic") == 0) d.type = CAROM_BODY_DYNAMIC;
        else add_body_error(L, "type must be \"static\", \"kinematic\" or \"dynamic\"");
    }
    lua_pop(L, 1);
    if (lua_getfield(L, 2, "shape") == LUA_TNIL) add_body_error(L, "shape is required (e.g. carom.sphere{radius = 0.5})");
    lshape *s = luaL_testudata(L, -1, SHAPE_MT);
    if (!s) add_body_error(L, "shape must be made by carom.sphere/box/capsule/cylinder/hull/plane");
    d.shape = s->def;
    opt_vec3_field(L, 2, "position", &d.position);
    opt_vec3_field(L, 2, "velocity", &d.linear_velocity);
    opt_vec3_field(L, 2, "angular_velocity", &d.angular_velocity);
    opt_vec3_field(L, 2, "plane_normal", &d.plane_normal);
    if (lua_getfield(L, 2, "orientation") != LUA_TNIL) {
        double q[4];
        if (!lua_istable(L, -1)) add_body_error(L, "orientation must be a quaternion {w, x, y, z}");
        for (int i = 0; i < 4; i++) {
            lua_geti(L, -1, i + 1);
            if (!lua_isnumber(L, -1)) add_body_error(L, "orientation must be a quaternion {w, x, y, z}");
            q[i] = lua_tonumber(L, -1);
            lua_pop(L, 1);
        }
        d.orientation.w = q[0]; d.orientation.x = q[1]; d.orientation.y = q[2]; d.orientation.z = q[3];
    }
    lua_pop(L, 1);
    opt_number_field(L, 2, "mass", &d.mass);
    opt_number_field(L, 2, "density", &d.density);
    opt_number_field(L, 2, "restitution", &d.restitution);
    opt_number_field(L, 2, "friction", &d.friction);
    opt_number_field(L, 2, "gravity_scale", &d.gravity_scale);
    opt_number_field(L, 2, "linear_damping", &d.linear_damping);
    opt_number_field(L, 2, "angular_damping", &d.angular_damping);
    opt_bool_field(L, 2, "bullet", &d.bullet);
    opt_bool_field(L, 2, "lock_rotation", &d.lock_rotation);
    opt_bool_field(L, 2, "lock_to_plane", &d.lock_to_plane);
    opt_bool_field(L, 2, "sleep", &d.enable_sleep);
    opt_bool_field(L, 2, "awake", &d.awake);
    carom_body_id id = carom_body_create(lw->w, &d);
    if (carom_body_id_is_null(id)) {
        const char *msg = carom_world_last_error(lw->w);
        if (strncmp(msg, "body_create: ", 13) == 0) msg += 13;
        if (strstr(msg, "locked") || strstr(msg, "callback")) luaL_error(L, "add_body: %s", msg);
        add_body_error(L, msg);
    }
    push_body(L, 1, id);
    if (lua_getfield(L, 2, "data") != LUA_TNIL) lua_setiuservalue(L, -2, 2);
    else lua_pop(L, 1);
    return 1;
}

static void push_event(lua_State *L, int world_idx, const carom_contact_event *e)
{
    static const char *const names[] = {"begin", "end", "hit"};
    lua_createtable(L, 0, 8);
    lua_pushstring(L, names[e->type]); lua_setfield(L, -2, "type");
    push_body(L, world_idx, e->a); lua_setfield(L, -2, "a");
    push_body(L, world_idx, e->b); lua_setfield(L, -2, "b");
    push_vec3(L, e->point); lua_setfield(L, -2, "point");
    push_vec3(L, e->normal); lua_setfield(L, -2, "normal");
    lua_pushnumber(L, e->normal_impulse); lua_setfield(L, -2, "impulse");
    lua_pushnumber(L, e->tangent_impulse); lua_setfield(L, -2, "tangent_impulse");
    lua_pushnumber(L, e->approach_speed); lua_setfield(L, -2, "speed");
    lua_pushnumber(L, e->average_force); lua_setfield(L, -2, "force");
}

static int traceback(lua_State *L)
{
    const char *msg = lua_tostring(L, 1);
    luaL_traceback(L, L, msg ? msg : "(error object is not a string)", 1);
    return 1;
}

/* Called by the C world for each event while it is locked. The world's Lua
 * userdata sits at index 1 of the stepping thread (world:step's self). */
static void world_event_callback(void *ctx, const carom_contact_event *e)
{
    lworld *lw = ctx;
    lua_State *L = lw->L;
    if (!L || lw->callback_error) return;
    if (lua_getiuservalue(L, 1, 2) != LUA_TFUNCTION) { lua_pop(L, 1); return; }
    lua_pushcfunction(L, traceback);
    lua_insert(L, -2);
    int handler = lua_gettop(L) - 1;
    push_event(L, 1, e);
    if (lua_pcall(L, 1, 0, handler) != LUA_OK) {
        lw->callback_error = 1;
        lua_setiuservalue(L, 1, 3); /* keep the message to raise after the step */
    }
    lua_pop(L, 1); /* handler */
}

static void step_once(lua_State *L, lworld *lw, double dt)
{
    lw->L = L;
    lw->callback_error = 0;
    carom_status st = carom_world_step(lw->w, dt);
    lw->L = NULL;
    if (lw->callback_error) {
        lua_getiuservalue(L, 1, 3);
        lua_error(L);
    }
    if (st != CAROM_OK) luaL_error(L, "step: %s", carom_world_last_error(lw->w));
}

static int world_step(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    if (lw->L) luaL_error(L, "step: cannot step a world from inside its own callback");
    double dt = luaL_checknumber(L, 2);
    if (!(isfinite(dt) && dt > 0 && dt <= 1)) luaL_argerror(L, 2, "dt must be in (0, 1] seconds");
    lua_Integer n = luaL_optinteger(L, 3, 1);
    if (n < 0 || n > 100000000) luaL_argerror(L, 3, "step count must be in 0..1e8");
    lua_settop(L, 1);
    for (lua_Integer i = 0; i < n; i++) step_once(L, lw, dt);
    return 0;
}

static int world_advance(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    if (lw->L) luaL_error(L, "advance: cannot step a world from inside its own callback");
    double frame = luaL_checknumber(L, 2);
    if (!(isfinite(frame) && frame >= 0 && frame <= 10)) luaL_argerror(L, 2, "frame time must be in [0, 10] seconds");
    lua_settop(L, 1);
    lw->accumulator += frame;
    int steps = 0;
    while (lw->accumulator >= lw->fixed_dt && steps < lw->max_steps) {
        step_once(L, lw, lw->fixed_dt);
        lw->accumulator -= lw->fixed_dt;
        steps++;
    }
    /* too far behind: drop the backlog rather than spiral */
    if (lw->accumulator >= lw->fixed_dt) lw->accumulator = fmod(lw->accumulator, lw->fixed_dt);
    lua_pushinteger(L, steps);
    lua_pushnumber(L, lw->accumulator / lw->fixed_dt);
    return 2;
}

static int world_set_contact_callback(lua_State *L)
{
    check_world(L, 1);
    if (!lua_isnil(L, 2)) luaL_checktype(L, 2, LUA_TFUNCTION);
    lua_settop(L, 2);
    lua_setiuservalue(L, 1, 2);
    return 0;
}

static int world_energy(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    double ke, pe;
    carom_world_get_energy(lw->w, &ke, &pe);
    lua_pushnumber(L, ke);
    lua_pushnumber(L, pe);
    return 2;
}

static int world_momentum(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    carom_vec3 p, l;
    carom_world_get_momentum(lw->w, &p, &l);
    return_vec3(L, p);
    push_vec3(L, l);
    return 4;
}

static int world_events(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    const carom_contact_event *ev;
    int n = carom_world_get_events(lw->w, &ev);
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        push_event(L, 1, &ev[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int world_stats(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    carom_world_stats s = carom_world_stats_init();
    carom_world_get_stats(lw->w, &s);
    lua_createtable(L, 0, 20);
#define SETI(name, v) (lua_pushinteger(L, (lua_Integer)(v)), lua_setfield(L, -2, name))
#define SETN(name, v) (lua_pushnumber(L, (v)), lua_setfield(L, -2, name))
    SETI("bodies", s.bodies);
    SETI("awake_bodies", s.awake_bodies);
    SETI("islands", s.islands);
    SETI("pairs", s.pairs);
    SETI("contacts", s.contacts);
    SETI("contact_points", s.contact_points);
    SETN("max_penetration", s.max_penetration);
    SETI("clamped", s.clamped);
    SETI("toi_events", s.toi_events);
    SETI("non_finite", s.non_finite);
    SETN("ms_broadphase", s.ms_broadphase);
    SETN("ms_narrowphase", s.ms_narrowphase);
    SETN("ms_solver", s.ms_solver);
    SETN("ms_continuous", s.ms_continuous);
    SETN("ms_islands", s.ms_islands);
    SETN("ms_total", s.ms_total);
    SETI("steps", s.step_count);
#undef SETI
#undef SETN
    return 1;
}

static int world_ray_cast(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    carom_vec3 o, t;
    int next = check_vec3(L, 2, &o);
    check_vec3(L, next, &t);
    carom_ray_hit hit;
    int r = carom_world_ray_cast(lw->w, o, t, &hit);
    if (r < 0) luaL_error(L, "ray_cast: %s", carom_world_last_error(lw->w));
    if (r == 0) { lua_pushnil(L); return 1; }
    push_body(L, 1, hit.body);
    push_vec3(L, hit.point);
    push_vec3(L, hit.normal);
    lua_pushnumber(L, hit.fraction);
    return 4;
}

static int world_query_aabb(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    carom_vec3 lo, hi;
    int next = check_vec3(L, 2, &lo);
    check_vec3(L, next, &hi);
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) luaL_argerror(L, 2, "lower corner must not exceed the upper corner");
    int n = carom_world_query_aabb(lw->w, lo, hi, NULL, 0);
    if (n < 0) luaL_error(L, "query_aabb: %s", carom_world_last_error(lw->w));
    carom_body_id *ids = lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    n = carom_world_query_aabb(lw->w, lo, hi, ids, n);
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        push_body(L, 1, ids[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int world_bodies(lua_State *L)
{
    check_world(L, 1);
    lua_getiuservalue(L, 1, 1);
    lua_newtable(L);
    int k = 0;
    lua_pushnil(L);
    while (lua_next(L, -3)) {
        lbody *b = lua_touserdata(L, -1);
        lworld *lw = lua_touserdata(L, 1);
        if (b && carom_body_is_valid(lw->w, b->id)) lua_rawseti(L, -3, ++k);
        else lua_pop(L, 1);
    }
    return 1;
}

static int world_body_count(lua_State *L)
{
    lworld *lw = check_world(L, 1);
    lua_pushinteger(L, carom_world_body_count(lw->w));
    return 1;
}

/* ---- bodies ---------------------------------------------------------------- */

/* The body at arg, its world on the stack top removed; errors if either is gone. */
static carom_world *check_body(lua_State *L, int arg, lbody **out)
{
    lbody *b = luaL_checkudata(L, arg, BODY_MT);
    lua_getiuservalue(L, arg, 1);
    lworld *lw = lua_touserdata(L, -1);
    lua_pop(L, 1);
    if (!lw || !lw->w) luaL_error(L, "body's world has been destroyed");
    if (!carom_body_is_valid(lw->w, b->id)) luaL_error(L, "body has been destroyed");
    *out = b;
    return lw->w;
}

static int status_error(lua_State *L, carom_world *w, carom_status st, const char *fname)
{
    if (st == CAROM_OK) return 0;
    const char *msg = carom_world_last_error(w);
    const char *colon = strstr(msg, ": ");
    if (st == CAROM_ERROR_INVALID_ARGUMENT) return luaL_error(L, "bad argument to '%s' (%s)", fname, colon ? colon + 2 : msg);
    return luaL_error(L, "%s: %s", fname, colon ? colon + 2 : msg);
}

#define BODY_VEC_GETTER(name, fn)                                                      \
    static int body_##name(lua_State *L)                                               \
    {                                                                                  \
        lbody *b;                                                                      \
        carom_world *w = check_body(L, 1, &b);                                         \
        carom_vec3 v;                                                                  \
        fn(w, b->id, &v);                                                              \
        return return_vec3(L, v);                                                      \
    }
BODY_VEC_GETTER(position, carom_body_get_position)
BODY_VEC_GETTER(velocity, carom_body_get_linear_velocity)
BODY_VEC_GETTER(angular_velocity, carom_body_get_angular_velocity)
BODY_VEC_GETTER(center_of_mass, carom_body_get_center_of_mass)

#define BODY_VEC_SETTER(name, fn)                                                      \
    static int body_##name(lua_State *L)                                               \
    {                                                                                  \
        lbody *b;                                                                      \
        carom_world *w = check_body(L, 1, &b);                                         \
        carom_vec3 v;                                                                  \
        check_vec3(L, 2, &v);                                                          \
        return status_error(L, w, fn(w, b->id, v), #name);                             \
    }
BODY_VEC_SETTER(set_position, carom_body_set_position)
BODY_VEC_SETTER(set_velocity, carom_body_set_linear_velocity)
BODY_VEC_SETTER(set_angular_velocity, carom_body_set_angular_velocity)
BODY_VEC_SETTER(apply_force, carom_body_apply_force)

static int body_orientation(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    carom_quat q;
    carom_body_get_orientation(w, b->id, &q);
    lua_pushnumber(L, q.w);
    lua_pushnumber(L, q.x);
    lua_pushnumber(L, q.y);
    lua_pushnumber(L, q.z);
    return 4;
}

static int body_set_orientation(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    carom_quat q;
    if (lua_istable(L, 2)) {
        double c[4];
        for (int i = 0; i < 4; i++) {
            lua_geti(L, 2, i + 1);
            if (!lua_isnumber(L, -1)) luaL_argerror(L, 2, "expected a quaternion {w, x, y, z}");
            c[i] = lua_tonumber(L, -1);
            lua_pop(L, 1);
        }
        q.w = c[0]; q.x = c[1]; q.y = c[2]; q.z = c[3];
    } else {
        q.w = luaL_checknumber(L, 2); q.x = luaL_checknumber(L, 3);
        q.y = luaL_checknumber(L, 4); q.z = luaL_checknumber(L, 5);
    }
    return status_error(L, w, carom_body_set_orientation(w, b->id, q), "set_orientation");
}

static int body_apply_impulse(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    carom_vec3 j, p;
    int next = check_vec3(L, 2, &j);
    int has_point = !lua_isnoneornil(L, next);
    if (has_point) check_vec3(L, next, &p);
    return status_error(L, w, carom_body_apply_impulse(w, b->id, j, has_point ? &p : NULL), "apply_impulse");
}

static int body_mass(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double m;
    carom_body_get_mass(w, b->id, &m);
    lua_pushnumber(L, m);
    return 1;
}

static int body_set_mass(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double m = luaL_checknumber(L, 2);
    if (!(isfinite(m) && m > 0)) luaL_argerror(L, 2, "mass must be positive");
    return status_error(L, w, carom_body_set_mass(w, b->id, m), "set_mass");
}

static int body_kinetic_energy(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double k;
    carom_body_get_kinetic_energy(w, b->id, &k);
    lua_pushnumber(L, k);
    return 1;
}

static int body_friction(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double v;
    carom_body_get_friction(w, b->id, &v);
    lua_pushnumber(L, v);
    return 1;
}

static int body_restitution(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double v;
    carom_body_get_restitution(w, b->id, &v);
    lua_pushnumber(L, v);
    return 1;
}

static int body_set_friction(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double v = luaL_checknumber(L, 2);
    if (!(isfinite(v) && v >= 0)) luaL_argerror(L, 2, "friction must be finite and >= 0");
    return status_error(L, w, carom_body_set_friction(w, b->id, v), "set_friction");
}

static int body_set_restitution(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    double v = luaL_checknumber(L, 2);
    if (!(isfinite(v) && v >= 0 && v <= 1)) luaL_argerror(L, 2, "restitution must be in [0, 1]");
    return status_error(L, w, carom_body_set_restitution(w, b->id, v), "set_restitution");
}

static int body_type(lua_State *L)
{
    static const char *const names[] = {"static", "kinematic", "dynamic"};
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    carom_body_type t;
    carom_body_get_type(w, b->id, &t);
    lua_pushstring(L, names[t]);
    return 1;
}

static int body_set_type(lua_State *L)
{
    static const char *const names[] = {"static", "kinematic", "dynamic", NULL};
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    int t = luaL_checkoption(L, 2, NULL, names);
    return status_error(L, w, carom_body_set_type(w, b->id, (carom_body_type)t), "set_type");
}

static int body_is_awake(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    lua_pushboolean(L, carom_body_is_awake(w, b->id));
    return 1;
}

static int body_set_awake(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    luaL_checktype(L, 2, LUA_TBOOLEAN);
    return status_error(L, w, carom_body_set_awake(w, b->id, lua_toboolean(L, 2)), "set_awake");
}

static int body_data(lua_State *L)
{
    lbody *b;
    check_body(L, 1, &b);
    lua_getiuservalue(L, 1, 2);
    return 1;
}

static int body_set_data(lua_State *L)
{
    lbody *b;
    check_body(L, 1, &b);
    lua_settop(L, 2);
    lua_setiuservalue(L, 1, 2);
    return 0;
}

static int body_id(lua_State *L)
{
    lbody *b = luaL_checkudata(L, 1, BODY_MT);
    lua_pushinteger(L, (lua_Integer)b->id.index1);
    return 1;
}

static int body_is_valid(lua_State *L)
{
    lbody *b = luaL_checkudata(L, 1, BODY_MT);
    lua_getiuservalue(L, 1, 1);
    lworld *lw = lua_touserdata(L, -1);
    lua_pushboolean(L, lw && lw->w && carom_body_is_valid(lw->w, b->id));
    return 1;
}

static int body_destroy(lua_State *L)
{
    lbody *b;
    carom_world *w = check_body(L, 1, &b);
    carom_status st = carom_body_destroy(w, b->id);
    if (st != CAROM_OK) return status_error(L, w, st, "destroy");
    /* forget it in the world's table unless the destroy was deferred */
    if (!carom_body_is_valid(w, b->id)) {
        lua_getiuservalue(L, 1, 1);
        lua_getiuservalue(L, -1, 1);
        lua_pushnil(L);
        lua_rawseti(L, -2, (lua_Integer)carom_body_id_pack(b->id));
    }
    return 0;
}

/* `local b <close> = world:add_body{...}` destroys the body at scope end. */
static int body_close(lua_State *L)
{
    lbody *b = luaL_checkudata(L, 1, BODY_MT);
    lua_getiuservalue(L, 1, 1);
    lworld *lw = lua_touserdata(L, -1);
    if (lw && lw->w && carom_body_is_valid(lw->w, b->id)) carom_body_destroy(lw->w, b->id);
    return 0;
}

static int body_tostring(lua_State *L)
{
    lbody *b = luaL_checkudata(L, 1, BODY_MT);
    lua_getiuservalue(L, 1, 1);
    lworld *lw = lua_touserdata(L, -1);
    if (!lw || !lw->w || !carom_body_is_valid(lw->w, b->id))
        lua_pushfstring(L, "carom.Body #%d (destroyed)", (int)b->id.index1);
    else {
        carom_vec3 p;
        carom_body_get_position(lw->w, b->id, &p);
        lua_pushfstring(L, "carom.Body #%d at (%f, %f, %f)", (int)b->id.index1, p.x, p.y, p.z);
    }
    return 1;
}

static int body_eq(lua_State *L)
{
    lbody *a = luaL_testudata(L, 1, BODY_MT), *b = luaL_testudata(L, 2, BODY_MT);
    int same = 0;
    if (a && b && carom_body_id_equal(a->id, b->id)) {
        lua_getiuservalue(L, 1, 1);
        lua_getiuservalue(L, 2, 1);
        same = lua_rawequal(L, -1, -2);
    }
    lua_pushboolean(L, same);
    return 1;
}

static int l_clock(lua_State *L)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    lua_pushnumber(L, (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9);
    return 1;
}

static const luaL_Reg world_methods[] = {
    {"add_body", world_add_body}, {"step", world_step}, {"advance", world_advance},
    {"energy", world_energy}, {"momentum", world_momentum}, {"events", world_events},
    {"stats", world_stats}, {"ray_cast", world_ray_cast}, {"query_aabb", world_query_aabb},
    {"bodies", world_bodies}, {"body_count", world_body_count}, {"configure", world_configure},
    {"set_contact_callback", world_set_contact_callback}, {"destroy", world_destroy}, {NULL, NULL}};

static const luaL_Reg world_meta[] = {
    {"__gc", world_destroy}, {"__close", world_destroy}, {"__tostring", world_tostring}, {NULL, NULL}};

static const luaL_Reg body_methods[] = {
    {"position", body_position}, {"velocity", body_velocity}, {"angular_velocity", body_angular_velocity},
    {"orientation", body_orientation}, {"center_of_mass", body_center_of_mass},
    {"set_position", body_set_position}, {"set_velocity", body_set_velocity},
    {"set_angular_velocity", body_set_angular_velocity}, {"set_orientation", body_set_orientation},
    {"apply_impulse", body_apply_impulse}, {"apply_force", body_apply_force}, {"mass", body_mass},
    {"set_mass", body_set_mass}, {"kinetic_energy", body_kinetic_energy}, {"friction", body_friction},
    {"set_friction", body_set_friction}, {"restitution", body_restitution},
    {"set_restitution", body_set_restitution}, {"type", body_type}, {"set_type", body_set_type},
    {"is_awake", body_is_awake}, {"set_awake", body_set_awake}, {"data", body_data},
    {"set_data", body_set_data}, {"is_valid", body_is_valid}, {"id", body_id}, {"destroy", body_destroy}, {NULL, NULL}};

static const luaL_Reg body_meta[] = {
    {"__close", body_close}, {"__tostring", body_tostring}, {"__eq", body_eq}, {NULL, NULL}};

static const luaL_Reg module_functions[] = {
    {"world", l_world}, {"sphere", l_sphere}, {"box", l_box}, {"capsule", l_capsule},
    {"cylinder", l_cylinder}, {"hull", l_hull}, {"plane", l_plane}, {"clock", l_clock}, {NULL, NULL}};

static void new_class(lua_State *L, const char *name, const luaL_Reg *meta, const luaL_Reg *methods)
{
    luaL_newmetatable(L, name);
    luaL_setfuncs(L, meta, 0);
    if (methods) {
        lua_newtable(L);
        luaL_setfuncs(L, methods, 0);
        lua_setfield(L, -2, "__index");
    }
    lua_pop(L, 1);
}

CAROM_LUA_EXPORT int luaopen_carom(lua_State *L)
{
    static const luaL_Reg shape_meta[] = {{"__gc", shape_gc}, {"__tostring", shape_tostring}, {NULL, NULL}};
    new_class(L, WORLD_MT, world_meta, world_methods);
    new_class(L, BODY_MT, body_meta, body_methods);
    new_class(L, SHAPE_MT, shape_meta, NULL);
    luaL_newlib(L, module_functions);
    lua_pushstring(L, carom_version());
    lua_setfield(L, -2, "version");
    return 1;
}
