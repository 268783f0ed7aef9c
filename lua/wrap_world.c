/* wrap_world.c - carom.World: settings, stepping (step, advance), contact
 * callbacks, events, probes and queries.
 *
 * Callbacks: the C world calls world_event_callback for each event at the end
 * of its step, while it is locked. The Lua function runs under lua_pcall with
 * a traceback handler; if it fails, the remaining events of that step are not
 * delivered, the step finishes normally (so the world stays consistent), and
 * world:step raises the error afterwards. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "carom_lua.h"

int clua_world_add_body(lua_State *L); /* wrap_body.c */

static const char *const contact_models[] = {"impulse", "penalty", NULL};
static const char *const corrections[] = {"soft", "baumgarte", "none", NULL};
static const char *const presets[] = {"fast", "default", "accurate", NULL};
static const char *const event_names[] = {"begin", "end", "hit", "sensor_begin", "sensor_end", "force"};

/* Plain numeric and boolean settings: Lua name -> field of carom_world_def. */
typedef struct world_field {
    const char *key;
    size_t offset;
    char kind; /* 'n' double, 'i' int, 'b' int used as a boolean */
} world_field;

#define FIELD(key, member, kind) {key, offsetof(carom_world_def, member), kind}
static const world_field world_fields[] = {
    FIELD("substeps", substeps, 'i'),
    FIELD("iterations", iterations, 'i'),
    FIELD("relax_iterations", relax_iterations, 'i'),
    FIELD("warm_starting", warm_starting, 'b'),
    FIELD("restitution_threshold", restitution_threshold, 'n'),
    FIELD("hit_event_threshold", hit_event_threshold, 'n'),
    FIELD("hertz", contact_hertz, 'n'),
    FIELD("damping_ratio", contact_damping_ratio, 'n'),
    FIELD("push_velocity", contact_push_max_velocity, 'n'),
    FIELD("baumgarte", baumgarte, 'n'),
    FIELD("linear_slop", linear_slop, 'n'),
    FIELD("speculative_distance", speculative_distance, 'n'),
    FIELD("reuse_distance", contact_reuse_distance, 'n'),
    FIELD("penalty_stiffness", penalty_stiffness, 'n'),
    FIELD("penalty_damping", penalty_damping, 'n'),
    FIELD("penalty_implicit", penalty_implicit, 'b'),
    FIELD("shock_propagation", shock_propagation, 'b'),
    FIELD("friction", enable_friction, 'b'),
    FIELD("restitution", enable_restitution, 'b'),
    FIELD("sleep", enable_sleep, 'b'),
    FIELD("ccd", enable_continuous, 'b'),
    FIELD("sleep_time", sleep_time, 'n'),
    FIELD("sleep_linear_velocity", sleep_linear_velocity, 'n'),
    FIELD("sleep_angular_velocity", sleep_angular_velocity, 'n'),
    FIELD("max_linear_speed", max_linear_speed, 'n'),
    FIELD("max_angular_speed", max_angular_speed, 'n'),
    FIELD("body_capacity", body_capacity, 'i'),
    {NULL, 0, 0}};
#undef FIELD

static const char *const world_keys[] = {
    "gravity", "preset", "contact_model", "position_correction", "dt", "max_steps",
    "substeps", "iterations", "relax_iterations", "warm_starting", "restitution_threshold", "hit_event_threshold", "hertz",
    "damping_ratio", "push_velocity", "baumgarte", "linear_slop", "speculative_distance",
    "reuse_distance", "penalty_stiffness", "penalty_damping", "penalty_implicit", "shock_propagation", "friction",
    "restitution", "sleep", "ccd", "sleep_time", "sleep_linear_velocity", "sleep_angular_velocity",
    "max_linear_speed", "max_angular_speed", "body_capacity", "threads", NULL};

#define DEFAULT_MAX_STEPS 8

clua_world *clua_check_world(lua_State *L, int arg, const char *fname)
{
    clua_world *lw = luaL_testudata(L, arg, CLUA_WORLD_MT);
    if (!lw) clua_type_error(L, arg, fname, CLUA_WORLD_MT);
    if (!lw->world) clua_arg_error(L, arg, fname, "world has been destroyed");
    return lw;
}

/* Reads the options table at arg over *def (preset first, then explicit keys,
 * which win) and the advance() settings; changes nothing on error. */
static void read_world_options(lua_State *L, int arg, const char *fname, carom_world_def *def, double *fixed_dt,
                               int *max_steps, int *threads)
{
    clua_check_table(L, arg, fname);
    clua_check_keys(L, arg, fname, world_keys);
    carom_world_def d = *def;
    int choice;
    if (clua_field_option(L, arg, fname, "preset", presets, &choice) &&
        carom_world_def_apply_preset(&d, presets[choice]) != CAROM_OK)
        clua_arg_error(L, arg, fname, "preset %s is not available", presets[choice]);
    clua_field_vec3(L, arg, fname, "gravity", &d.gravity);
    if (clua_field_option(L, arg, fname, "contact_model", contact_models, &choice))
        d.contact_model = (carom_contact_model)choice;
    if (clua_field_option(L, arg, fname, "position_correction", corrections, &choice))
        d.position_correction = (carom_position_correction)choice;
    for (const world_field *f = world_fields; f->key; f++) {
        char *p = (char *)&d + f->offset;
        if (f->kind == 'n') clua_field_number(L, arg, fname, f->key, (double *)(void *)p);
        else if (f->kind == 'i') clua_field_int(L, arg, fname, f->key, (int *)(void *)p);
        else clua_field_bool(L, arg, fname, f->key, (int *)(void *)p);
    }
    /* the ranges are the library's: advance()'s clock (carom_fixed_step, with
     * no frame time: dt and max_steps alone), the pool's worker count, the def */
    char msg[256];
    double dt = *fixed_dt, no_time = 0;
    int ms = *max_steps, no_steps;
    clua_field_number(L, arg, fname, "dt", &dt);
    clua_field_int(L, arg, fname, "max_steps", &ms);
    if (carom_fixed_step(dt, ms, 0, &no_time, &no_steps, msg, sizeof msg) != CAROM_OK)
        clua_arg_error(L, arg, fname, "%s", msg);
    int th = *threads;
    if (clua_field_int(L, arg, fname, "threads", &th) && carom_thread_pool_check(th, msg, sizeof msg) != CAROM_OK)
        clua_arg_error(L, arg, fname, "threads: %s", msg);
    if (carom_world_def_check(&d, msg, sizeof msg) != CAROM_OK) clua_arg_error(L, arg, fname, "%s", msg);
    *def = d;
    *fixed_dt = dt;
    *max_steps = ms;
    *threads = th;
}

/* The reference pool for threads = N (N > 1) attached to *def, or the hooks
 * cleared for 1; *pool is the new pool (NULL for 1). 0 when the threads
 * cannot be started. */
static int make_pool(int threads, carom_world_def *def, carom_thread_pool **pool)
{
    *pool = NULL;
    def->worker_count = 1;
    def->enqueue_task = NULL;
    def->finish_task = NULL;
    def->task_context = NULL;
    if (threads <= 1) return 1;
    *pool = carom_thread_pool_create(threads);
    return *pool && carom_thread_pool_attach(*pool, def) == CAROM_OK;
}

static void world_event_callback(void *context, const carom_contact_event *event);
static clua_world *push_world_userdata(lua_State *L, double fixed_dt, int max_steps);

/* carom.world{options}: a new world. */
static int l_world(lua_State *L)
{
    carom_world_def d = carom_world_def_default();
    double fixed_dt = 1.0 / 60.0;
    int max_steps = DEFAULT_MAX_STEPS, threads = 1;
    if (!lua_isnoneornil(L, 1)) read_world_options(L, 1, "world", &d, &fixed_dt, &max_steps, &threads);
    lua_settop(L, 0);
    clua_world *lw = push_world_userdata(L, fixed_dt, max_steps);
    d.event_callback = world_event_callback;
    d.event_context = lw;
    if (!make_pool(threads, &d, &lw->pool)) {
        carom_thread_pool_destroy(lw->pool);
        lw->pool = NULL;
        return luaL_error(L, "world: could not start %d threads", threads);
    }
    lw->world = carom_world_create(&d);
    if (!lw->world) {
        carom_thread_pool_destroy(lw->pool);
        lw->pool = NULL;
        return luaL_error(L, "world: could not create the world (out of memory)");
    }
    return 1;
}

/* The Lua side of a new world userdata (at the top of the stack): its tables. */
static clua_world *push_world_userdata(lua_State *L, double fixed_dt, int max_steps)
{
    clua_world *lw = lua_newuserdatauv(L, sizeof *lw, WORLD_UV_COUNT);
    memset(lw, 0, sizeof *lw);
    lw->fixed_dt = fixed_dt;
    lw->max_steps = max_steps;
    luaL_setmetatable(L, CLUA_WORLD_MT);
    int ud = lua_gettop(L);
    lua_newtable(L); /* proxies: weak values, so unused body userdata can be collected */
    lua_createtable(L, 0, 1);
    lua_pushliteral(L, "v");
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
    lua_setiuservalue(L, ud, WORLD_UV_PROXIES);
    lua_newtable(L);
    lua_setiuservalue(L, ud, WORLD_UV_IDS);
    lua_newtable(L);
    lua_setiuservalue(L, ud, WORLD_UV_DATA);
    return lw;
}

/* world:snapshot(): the world's complete state as a string (docs/snapshot.md).
 * Lua-side state is not in it: user_data, the contact callback, advance()'s
 * backlog. */
static int world_snapshot(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "snapshot");
    if (lw->stepping) return luaL_error(L, "snapshot: cannot snapshot a world inside its own contact callback");
    size_t n = carom_world_snapshot(lw->world, NULL, 0);
    if (n == 0) return luaL_error(L, "snapshot: %s", carom_world_last_error(lw->world));
    luaL_Buffer b;
    char *p = luaL_buffinitsize(L, &b, n);
    if (carom_world_snapshot(lw->world, p, n) != n) return luaL_error(L, "snapshot: the world changed while it was written");
    luaL_pushresultsize(&b, n);
    return 1;
}

/* Pushes a userdata array of every body id of the world and returns how
 * many it holds: a restored world's bodies, listed through the broadphase
 * (an all-space box), so that the binding learns the ids a snapshot made. */
static int push_all_body_ids(lua_State *L, carom_world *world, const carom_body_id **ids_out)
{
    int count = carom_world_body_count(world);
    carom_body_id *ids = lua_newuserdatauv(L, sizeof *ids * (size_t)(count > 0 ? count : 1), 0);
    carom_vec3 lo = {-1e300, -1e300, -1e300}, hi = {1e300, 1e300, 1e300};
    int found = carom_world_query_aabb(world, lo, hi, ids, count);
    *ids_out = ids;
    return found < count ? found : count;
}

/* carom.restore(s): a new world from world:snapshot()'s string; it continues
 * bit for bit as the snapshotted world would have. Raises on a string that
 * is not a whole snapshot of this version. */
static int l_restore(lua_State *L)
{
    size_t n;
    if (lua_type(L, 1) != LUA_TSTRING) return clua_type_error(L, 1, "restore", "string (from world:snapshot())");
    const char *data = lua_tolstring(L, 1, &n);
    lua_settop(L, 1);
    clua_world *lw = push_world_userdata(L, 1.0 / 60.0, DEFAULT_MAX_STEPS);
    char msg[256];
    lw->world = carom_world_restore(data, n, msg, sizeof msg);
    if (!lw->world) return clua_arg_error(L, 1, "restore", "%s", msg);
    carom_world_def d = carom_world_def_default();
    carom_world_get_def(lw->world, &d);
    d.event_callback = world_event_callback;
    d.event_context = lw;
    carom_world_set_def(lw->world, &d);
    /* every body becomes the world's (world:bodies lists them) */
    const carom_body_id *ids;
    int found = push_all_body_ids(L, lw->world, &ids);
    lua_getiuservalue(L, 2, WORLD_UV_IDS);
    for (int i = 0; i < found; i++) {
        lua_pushboolean(L, 1);
        lua_rawseti(L, -2, (lua_Integer)carom_body_id_pack(ids[i]));
    }
    lua_settop(L, 2);
    return 1;
}

/* world:restore(s): this world becomes the state in world:snapshot()'s
 * string (carom_world_restore_into), continuing bit for bit as the
 * snapshotted world would have; it keeps its contact callback, threads and
 * advance() settings, and the user_data of the bodies the snapshot also
 * holds (the same id). Raises on a string that is not a whole snapshot, and
 * the world is then unchanged. */
static int world_restore(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "restore");
    if (lw->stepping) return luaL_error(L, "restore: cannot restore a world inside its own contact callback");
    if (lua_type(L, 2) != LUA_TSTRING) return clua_type_error(L, 2, "restore", "string (from world:snapshot())");
    size_t n;
    const char *data = lua_tolstring(L, 2, &n);
    lua_settop(L, 2);
    lua_newtable(L); /* 3: the new ids (made before the world changes: memory errors raise first) */
    lua_newtable(L); /* 4: the new user data */
    if (carom_world_restore_into(lw->world, data, n) != CAROM_OK)
        return clua_arg_error(L, 2, "restore", "%s", carom_world_last_error_reason(lw->world));
    const carom_body_id *ids;
    int found = push_all_body_ids(L, lw->world, &ids); /* 5 */
    lua_getiuservalue(L, 1, WORLD_UV_DATA); /* 6: the old user data */
    for (int i = 0; i < found; i++) {
        lua_Integer key = (lua_Integer)carom_body_id_pack(ids[i]);
        lua_pushboolean(L, 1);
        lua_rawseti(L, 3, key);
        if (lua_rawgeti(L, 6, key) != LUA_TNIL) lua_rawseti(L, 4, key);
        else lua_pop(L, 1);
    }
    lua_pushvalue(L, 3);
    lua_setiuservalue(L, 1, WORLD_UV_IDS);
    lua_pushvalue(L, 4);
    lua_setiuservalue(L, 1, WORLD_UV_DATA);
    lua_settop(L, 1);
    return 1;
}

/* world:configure{options}: the same keys as carom.world, applied between steps. */
static int world_configure(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "configure");
    if (lw->stepping) return luaL_error(L, "configure: cannot change settings inside a contact callback");
    carom_world_def d = carom_world_def_default();
    carom_world_get_def(lw->world, &d);
    double fixed_dt = lw->fixed_dt;
    int max_steps = lw->max_steps;
    int old_threads = lw->pool ? carom_thread_pool_workers(lw->pool) : 1, threads = old_threads;
    read_world_options(L, 2, "configure", &d, &fixed_dt, &max_steps, &threads);
    d.event_callback = world_event_callback;
    d.event_context = lw;
    lw = clua_check_world(L, 1, "configure");
    if (lw->stepping) return luaL_error(L, "configure: cannot change settings inside a contact callback");
    carom_thread_pool *pool = lw->pool;
    if (threads != old_threads && !make_pool(threads, &d, &pool)) {
        carom_thread_pool_destroy(pool);
        return luaL_error(L, "configure: could not start %d threads", threads);
    }
    if (carom_world_set_def(lw->world, &d) != CAROM_OK) {
        if (pool != lw->pool) carom_thread_pool_destroy(pool);
        char buf[256];
        return luaL_error(L, "configure: %s", clua_copy_error(lw->world, buf, sizeof buf));
    }
    if (pool != lw->pool) {
        carom_thread_pool_destroy(lw->pool); /* the world no longer uses it */
        lw->pool = pool;
    }
    if (fixed_dt != lw->fixed_dt) lw->accumulator = 0;
    lw->fixed_dt = fixed_dt;
    lw->max_steps = max_steps;
    return 0;
}

/* world:settings(): the current settings, as a table of world options. */
static int world_settings(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "settings");
    carom_world_def d = carom_world_def_default();
    carom_world_get_def(lw->world, &d);
    lua_createtable(L, 0, 32);
    clua_push_vec3_table(L, d.gravity);
    lua_setfield(L, -2, "gravity");
    lua_pushstring(L, contact_models[d.contact_model]);
    lua_setfield(L, -2, "contact_model");
    lua_pushstring(L, corrections[d.position_correction]);
    lua_setfield(L, -2, "position_correction");
    for (const world_field *f = world_fields; f->key; f++) {
        const char *p = (const char *)&d + f->offset;
        if (f->kind == 'n') lua_pushnumber(L, *(const double *)(const void *)p);
        else if (f->kind == 'i') lua_pushinteger(L, *(const int *)(const void *)p);
        else lua_pushboolean(L, *(const int *)(const void *)p);
        lua_setfield(L, -2, f->key);
    }
    lua_pushnumber(L, lw->fixed_dt);
    lua_setfield(L, -2, "dt");
    lua_pushinteger(L, lw->max_steps);
    lua_setfield(L, -2, "max_steps");
    lua_pushinteger(L, lw->pool ? carom_thread_pool_workers(lw->pool) : 1);
    lua_setfield(L, -2, "threads");
    return 1;
}

static int world_destroy_impl(lua_State *L, const char *fname, int quiet)
{
    clua_world *lw = luaL_checkudata(L, 1, CLUA_WORLD_MT);
    if (!lw->world) return 0;
    if (lw->stepping) {
        if (quiet) return 0;
        return luaL_error(L, "%s: cannot destroy a world inside its own step (a contact callback)", fname);
    }
    carom_world_destroy(lw->world);
    lw->world = NULL;
    carom_thread_pool_destroy(lw->pool); /* after the world that used it */
    lw->pool = NULL;
    lw->has_callback = 0;
    /* the Lua side goes with it: bodies now report "world has been destroyed" */
    for (int uv = WORLD_UV_IDS; uv <= WORLD_UV_ERROR; uv++) {
        lua_pushnil(L);
        lua_setiuservalue(L, 1, uv);
    }
    return 0;
}

static int world_destroy(lua_State *L) { return world_destroy_impl(L, "destroy", 0); }
static int world_close(lua_State *L) { return world_destroy_impl(L, "__close", 0); }
static int world_gc(lua_State *L) { return world_destroy_impl(L, "__gc", 1); }

static int world_is_valid(lua_State *L)
{
    clua_world *lw = luaL_testudata(L, 1, CLUA_WORLD_MT);
    if (!lw) clua_type_error(L, 1, "is_valid", CLUA_WORLD_MT);
    lua_pushboolean(L, lw->world != NULL);
    return 1;
}

static int world_tostring(lua_State *L)
{
    clua_world *lw = luaL_checkudata(L, 1, CLUA_WORLD_MT);
    if (!lw->world) lua_pushfstring(L, "carom.World %p (destroyed)", (void *)lw);
    else lua_pushfstring(L, "carom.World %p (%d bodies)", (void *)lw, carom_world_body_count(lw->world));
    return 1;
}

/* ---- events and callbacks --------------------------------------------------- */

/* index: the event's place in the world's buffer (for its compound children). */
static void push_event(lua_State *L, int world_index, const carom_contact_event *e, int index)
{
    lua_createtable(L, 0, 9);
    lua_pushstring(L, event_names[e->type]);
    lua_setfield(L, -2, "type");
    clua_push_body(L, world_index, e->a);
    lua_setfield(L, -2, "a");
    clua_push_body(L, world_index, e->b);
    lua_setfield(L, -2, "b");
    clua_push_vec3_table(L, e->point);
    lua_setfield(L, -2, "point");
    clua_push_vec3_table(L, e->normal);
    lua_setfield(L, -2, "normal");
    lua_pushnumber(L, e->normal_impulse);
    lua_setfield(L, -2, "impulse");
    lua_pushnumber(L, e->tangent_impulse);
    lua_setfield(L, -2, "tangent_impulse");
    lua_pushnumber(L, e->approach_speed);
    lua_setfield(L, -2, "speed");
    lua_pushnumber(L, e->average_force);
    lua_setfield(L, -2, "force");
    /* compound children (1-based), when a or b is a compound */
    clua_world *lw = lua_touserdata(L, world_index);
    const carom_contact_event *all;
    int n = lw && lw->world ? carom_world_get_events(lw->world, &all) : 0;
    if (index >= 0 && index < n) {
        int ca = -1, cb = -1;
        carom_world_get_event_children(lw->world, index, &ca, &cb);
        if (ca >= 0) { lua_pushinteger(L, ca + 1); lua_setfield(L, -2, "child_a"); }
        if (cb >= 0) { lua_pushinteger(L, cb + 1); lua_setfield(L, -2, "child_b"); }
    }
    if (e->type == CAROM_EVENT_SENSOR_BEGIN || e->type == CAROM_EVENT_SENSOR_END) {
        lua_getfield(L, -1, "a");
        lua_setfield(L, -2, "sensor");
        lua_getfield(L, -1, "b");
        lua_setfield(L, -2, "other");
    }
}

/* Runs protected: 1 = world, 2 = the event (light userdata). Building the
 * event table can fail too (memory), so it happens inside the pcall. */
static int dispatch_event(lua_State *L)
{
    const carom_contact_event *e = lua_touserdata(L, 2);
    lua_getiuservalue(L, 1, WORLD_UV_CALLBACK);
    /* the callback is handed the world's own buffer entry */
    clua_world *lw = lua_touserdata(L, 1);
    const carom_contact_event *all;
    int n = lw && lw->world ? carom_world_get_events(lw->world, &all) : 0;
    push_event(L, 1, e, n > 0 && e >= all && e < all + n ? (int)(e - all) : -1);
    lua_call(L, 1, 0);
    return 0;
}

static void world_event_callback(void *context, const carom_contact_event *event)
{
    clua_world *lw = context;
    lua_State *L = lw->stepping;
    if (!L || !lw->has_callback || lw->callback_failed) return;
    int top = lua_gettop(L);
    if (!lua_checkstack(L, 6)) {
        lw->callback_failed = 1;
        lua_pushliteral(L, "contact callback: Lua stack overflow");
        lua_setiuservalue(L, 1, WORLD_UV_ERROR);
        return;
    }
    lua_pushcfunction(L, clua_traceback);
    lua_pushcfunction(L, dispatch_event);
    lua_pushvalue(L, 1);
    lua_pushlightuserdata(L, (void *)event);
    if (lua_pcall(L, 2, 0, top + 1) != LUA_OK) {
        lw->callback_failed = 1;
        lua_setiuservalue(L, 1, WORLD_UV_ERROR); /* raised by step once the step is over */
    }
    lua_settop(L, top);
}

/* One step of the world at index 1; raises a callback's error after it.
 * dt_arg: the argument dt came from (0: none), blamed when C refuses it. */
static void step_once(lua_State *L, clua_world *lw, double dt, int dt_arg)
{
    if (!lw->world) luaL_error(L, "step: the world has been destroyed (by a finalizer?)");
    lw->stepping = L;
    lw->callback_failed = 0;
    carom_status st = carom_world_step(lw->world, dt);
    lw->stepping = NULL;
    if (lw->deferred_destroys) {
        lw->deferred_destroys = 0;
        clua_sweep_bodies(L, 1);
    }
    if (lw->callback_failed) {
        lw->callback_failed = 0;
        lua_getiuservalue(L, 1, WORLD_UV_ERROR);
        lua_pushnil(L);
        lua_setiuservalue(L, 1, WORLD_UV_ERROR);
        lua_error(L);
    }
    if (st != CAROM_OK) {
        char buf[256];
        const char *msg = clua_copy_error(lw->world, buf, sizeof buf);
        if (st == CAROM_ERROR_INVALID_ARGUMENT && dt_arg > 0) clua_arg_error(L, dt_arg, "step", "%s", msg);
        luaL_error(L, "step: %s", msg);
    }
}

/* world:step(dt[, n]): n steps (default 1), looping in C. */
static int world_step(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "step");
    if (lw->stepping) return luaL_error(L, "step: cannot step a world from inside its own contact callback");
    double dt = clua_check_number(L, 2, "step"); /* its range: carom_world_step's */
    lua_Integer n = lua_isnoneornil(L, 3) ? 1 : clua_check_integer(L, 3, "step", 0, 100000000);
    lua_settop(L, 1);
    for (lua_Integer i = 0; i < n; i++) step_once(L, lw, dt, 2);
    return 0;
}

/* world:advance(frame_dt): fixed-step accumulator. Adds frame_dt, runs the
 * whole steps it holds (at most max_steps; a larger backlog is dropped rather
 * than chased, which would only fall further behind), returns the steps taken
 * and alpha in [0, 1): how far the real time is into the next step, for
 * interpolating poses when drawing. */
static int world_advance(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "advance");
    if (lw->stepping) return luaL_error(L, "advance: cannot step a world from inside its own contact callback");
    double frame = clua_check_number(L, 2, "advance");
    double after = lw->accumulator;
    int steps = 0;
    char msg[256];
    if (carom_fixed_step(lw->fixed_dt, lw->max_steps, frame, &after, &steps, msg, sizeof msg) != CAROM_OK)
        clua_arg_error(L, 2, "advance", "%s", msg);
    lua_settop(L, 1);
    /* The clock's accumulator counts down one step at a time while the steps
     * run (the same subtractions carom_fixed_step made), so a callback error
     * that stops the loop leaves the steps not taken in it. */
    lw->accumulator += frame;
    for (int i = 0; i < steps; i++) {
        lw->accumulator -= lw->fixed_dt;
        step_once(L, lw, lw->fixed_dt, 0);
    }
    lw->accumulator = after;
    lua_pushinteger(L, steps);
    lua_pushnumber(L, lw->accumulator / lw->fixed_dt);
    return 2;
}

/* world:set_contact_callback(fn or nil): fn(event) for each event of each step. */
static int world_set_contact_callback(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "set_contact_callback");
    if (!lua_isnil(L, 2) && lua_type(L, 2) != LUA_TFUNCTION) clua_type_error(L, 2, "set_contact_callback", "function or nil");
    lua_settop(L, 2);
    lw->has_callback = lua_isfunction(L, 2);
    lua_setiuservalue(L, 1, WORLD_UV_CALLBACK);
    return 0;
}

/* world:events(): the events of the last step. */
static int world_events(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "events");
    const carom_contact_event *events = NULL;
    int n = carom_world_get_events(lw->world, &events);
    if (n < 0) n = 0;
    /* a copy: building the tables may run a finalizer that steps or destroys the world */
    carom_contact_event *copy = lua_newuserdatauv(L, sizeof *copy * (size_t)(n > 0 ? n : 1), 0);
    lw = clua_check_world(L, 1, "events");
    int now = carom_world_get_events(lw->world, &events);
    if (now < n) n = now;
    if (n > 0) memcpy(copy, events, sizeof *copy * (size_t)n);
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        push_event(L, 1, &copy[i], i);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

/* ---- probes ------------------------------------------------------------------ */

static int world_energy(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "energy");
    double kinetic = 0, potential = 0;
    carom_world_get_energy(lw->world, &kinetic, &potential);
    lua_pushnumber(L, kinetic);
    lua_pushnumber(L, potential);
    return 2;
}

/* px, py, pz, then the angular momentum about the origin lx, ly, lz */
static int world_momentum(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "momentum");
    carom_vec3 p = {0, 0, 0}, l = {0, 0, 0};
    carom_world_get_momentum(lw->world, &p, &l);
    clua_return_vec3(L, p);
    clua_return_vec3(L, l);
    return 6;
}

static int world_stats(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "stats");
    carom_world_stats s = carom_world_stats_init();
    carom_world_get_stats(lw->world, &s);
    lua_createtable(L, 0, 18);
#define SET_INT(name, v) (lua_pushinteger(L, (lua_Integer)(v)), lua_setfield(L, -2, name))
#define SET_NUM(name, v) (lua_pushnumber(L, (v)), lua_setfield(L, -2, name))
    SET_INT("bodies", s.bodies);
    SET_INT("awake_bodies", s.awake_bodies);
    SET_INT("islands", s.islands);
    SET_INT("pairs", s.pairs);
    SET_INT("contacts", s.contacts);
    SET_INT("contact_points", s.contact_points);
    SET_NUM("max_penetration", s.max_penetration);
    SET_INT("clamped", s.clamped);
    SET_INT("toi_events", s.toi_events);
    SET_INT("non_finite", s.non_finite);
    SET_NUM("ms_broadphase", s.ms_broadphase);
    SET_NUM("ms_narrowphase", s.ms_narrowphase);
    SET_NUM("ms_solver", s.ms_solver);
    SET_NUM("ms_continuous", s.ms_continuous);
    SET_NUM("ms_islands", s.ms_islands);
    SET_NUM("ms_total", s.ms_total);
    SET_INT("steps", s.step_count);
#undef SET_INT
#undef SET_NUM
    return 1;
}

/* world:measure_penetration(): deepest overlap at the current poses (an extra
 * narrowphase pass, unlike stats().max_penetration from the last step). */
static int world_measure_penetration(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "measure_penetration");
    lua_pushnumber(L, carom_world_measure_max_penetration(lw->world));
    return 1;
}

/* ---- queries ----------------------------------------------------------------- */

/* world:ray_cast(origin, translation): body, point, normal, fraction, child (the
 * compound child, mesh triangle or height-field cell*2+half, 1-based; nil for
 * other shapes), or nil. */
static int world_ray_cast(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "ray_cast");
    carom_vec3 origin, translation;
    int next = clua_check_vec3(L, 2, "ray_cast", &origin);
    clua_check_vec3(L, next, "ray_cast", &translation);
    carom_ray_hit hit;
    lw = clua_check_world(L, 1, "ray_cast");
    int child = -1;
    int r = carom_world_ray_cast_child(lw->world, origin, translation, &hit, &child);
    char buf[256];
    if (r < 0) return clua_arg_error(L, next, "ray_cast", "%s", clua_copy_error(lw->world, buf, sizeof buf));
    if (r == 0) {
        lua_pushnil(L);
        return 1;
    }
    clua_push_body(L, 1, hit.body);
    clua_push_vec3_table(L, hit.point);
    clua_push_vec3_table(L, hit.normal);
    lua_pushnumber(L, hit.fraction);
    if (child >= 0) lua_pushinteger(L, child + 1);
    else lua_pushnil(L);
    return 5;
}

/* world:query_aabb(lo, hi): the bodies whose bounds overlap the box. */
static int world_query_aabb(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "query_aabb");
    carom_vec3 lo, hi;
    int next = clua_check_vec3(L, 2, "query_aabb", &lo);
    clua_check_vec3(L, next, "query_aabb", &hi);
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z)
        clua_arg_error(L, 2, "query_aabb", "the lower corner must not exceed the upper corner");
    lw = clua_check_world(L, 1, "query_aabb");
    int n = carom_world_query_aabb(lw->world, lo, hi, NULL, 0);
    char buf[256];
    if (n < 0) return clua_arg_error(L, 2, "query_aabb", "%s", clua_copy_error(lw->world, buf, sizeof buf));
    carom_body_id *ids = lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    lw = clua_check_world(L, 1, "query_aabb"); /* the allocation may have run a finalizer */
    int got = carom_world_query_aabb(lw->world, lo, hi, ids, n);
    if (got > n) got = n;
    lua_createtable(L, got > 0 ? got : 0, 0);
    for (int i = 0; i < got; i++) {
        clua_push_body(L, 1, ids[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int compare_ids(const void *a, const void *b)
{
    const carom_body_id *p = a, *q = b;
    return (p->index1 > q->index1) - (p->index1 < q->index1);
}

/* world:bodies(): every live body, in id order. */
static int world_bodies(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "bodies");
    lua_settop(L, 1);
    lua_getiuservalue(L, 1, WORLD_UV_IDS); /* 2 */
    lua_Integer count = 0;
    lua_pushnil(L);
    while (lua_next(L, 2)) {
        lua_pop(L, 1);
        count++;
    }
    carom_body_id *ids = lua_newuserdatauv(L, sizeof *ids * (size_t)(count > 0 ? count : 1), 0); /* 3 */
    int n = 0;
    lua_pushnil(L);
    while (lua_next(L, 2)) {
        lua_pop(L, 1);
        carom_body_id id = carom_body_id_unpack((uint64_t)lua_tointeger(L, -1));
        if (n < count && carom_body_is_valid(lw->world, id)) ids[n++] = id;
    }
    qsort(ids, (size_t)n, sizeof *ids, compare_ids);
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        clua_push_body(L, 1, ids[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int world_body_count(lua_State *L)
{
    clua_world *lw = clua_check_world(L, 1, "body_count");
    lua_pushinteger(L, carom_world_body_count(lw->world));
    return 1;
}

void clua_open_world(lua_State *L)
{
    static const luaL_Reg methods[] = {
        {"add_body", clua_world_add_body}, {"step", world_step}, {"advance", world_advance},
        {"energy", world_energy}, {"momentum", world_momentum}, {"events", world_events},
        {"stats", world_stats}, {"measure_penetration", world_measure_penetration},
        {"ray_cast", world_ray_cast}, {"query_aabb", world_query_aabb}, {"bodies", world_bodies},
        {"body_count", world_body_count}, {"configure", world_configure}, {"settings", world_settings},
        {"set_contact_callback", world_set_contact_callback}, {"is_valid", world_is_valid},
        {"destroy", world_destroy}, {"snapshot", world_snapshot}, {"restore", world_restore}, {NULL, NULL}};
    static const luaL_Reg meta[] = {{"__gc", world_gc}, {"__close", world_close}, {"__tostring", world_tostring},
                                    {NULL, NULL}};
    luaL_newmetatable(L, CLUA_WORLD_MT);
    luaL_setfuncs(L, meta, 0);
    lua_newtable(L);
    luaL_setfuncs(L, methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pushliteral(L, "locked");
    lua_setfield(L, -2, "__metatable");
    lua_pop(L, 1);
    lua_pushcfunction(L, l_world);
    lua_setfield(L, -2, "world");
    lua_pushcfunction(L, l_restore);
    lua_setfield(L, -2, "restore");
}
