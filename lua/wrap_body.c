/* wrap_body.c - carom.Body: world:add_body and the body methods.
 *
 * A body userdata holds only its id (index + generation), never a pointer,
 * and keeps its world's userdata alive through its user value. Every method
 * checks the id against the world first, so a destroyed body raises "body has
 * been destroyed" and a stale id can never reach another body. The world keeps
 * one userdata per body in a weak table, so the bodies in events and queries
 * are the very values the script holds (event.a == ball), and body.user_data
 * in a strong table keyed by id, so it survives the userdata being collected. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "carom_lua.h"

const char *const clua_body_type_names[] = {"static", "kinematic", "dynamic", NULL};

static lua_Integer id_key(carom_body_id id) { return (lua_Integer)carom_body_id_pack(id); }

void clua_push_body(lua_State *L, int world_index, carom_body_id id)
{
    world_index = lua_absindex(L, world_index);
    lua_getiuservalue(L, world_index, WORLD_UV_PROXIES);
    if (lua_rawgeti(L, -1, id_key(id)) == LUA_TUSERDATA) {
        lua_remove(L, -2);
        return;
    }
    lua_pop(L, 1);
    clua_body *b = lua_newuserdatauv(L, sizeof *b, BODY_UV_COUNT);
    b->id = id;
    luaL_setmetatable(L, CLUA_BODY_MT);
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, BODY_UV_WORLD);
    lua_pushvalue(L, -1);
    lua_rawseti(L, -3, id_key(id));
    lua_remove(L, -2);
}

static void clear_key(lua_State *L, int world_index, int uv, carom_body_id id)
{
    if (lua_getiuservalue(L, world_index, uv) == LUA_TTABLE) {
        lua_pushnil(L);
        lua_rawseti(L, -2, id_key(id));
    }
    lua_pop(L, 1);
}

void clua_forget_body(lua_State *L, int world_index, carom_body_id id)
{
    world_index = lua_absindex(L, world_index);
    clear_key(L, world_index, WORLD_UV_IDS, id);
    clear_key(L, world_index, WORLD_UV_DATA, id);
}

void clua_sweep_bodies(lua_State *L, int world_index)
{
    world_index = lua_absindex(L, world_index);
    clua_world *lw = lua_touserdata(L, world_index);
    if (!lw || !lw->world) return;
    for (int uv = WORLD_UV_IDS; uv <= WORLD_UV_DATA; uv++) {
        if (lua_getiuservalue(L, world_index, uv) != LUA_TTABLE) {
            lua_pop(L, 1);
            continue;
        }
        /* collect first: assigning nil during lua_next is allowed, but keep it simple */
        lua_newtable(L);
        int dead = 0;
        lua_pushnil(L);
        while (lua_next(L, -3)) {
            lua_pop(L, 1);
            if (!carom_body_is_valid(lw->world, carom_body_id_unpack((uint64_t)lua_tointeger(L, -1)))) {
                lua_pushvalue(L, -1);
                lua_rawseti(L, -3, ++dead);
            }
        }
        for (int i = 1; i <= dead; i++) {
            lua_rawgeti(L, -1, i);
            lua_pushnil(L);
            lua_rawset(L, -4);
        }
        lua_pop(L, 2);
    }
}

/* The live body at arg and its world; raises if either is gone. */
static carom_world *check_body(lua_State *L, int arg, const char *fname, clua_body **out)
{
    clua_body *b = luaL_testudata(L, arg, CLUA_BODY_MT);
    if (!b) clua_type_error(L, arg, fname, CLUA_BODY_MT);
    lua_getiuservalue(L, arg, BODY_UV_WORLD);
    clua_world *lw = luaL_testudata(L, -1, CLUA_WORLD_MT);
    lua_pop(L, 1);
    if (!lw || !lw->world) clua_arg_error(L, arg, fname, "the body's world has been destroyed");
    if (!carom_body_is_valid(lw->world, b->id)) clua_arg_error(L, arg, fname, "body has been destroyed");
    *out = b;
    return lw->world;
}

static clua_world *body_world(lua_State *L, int arg)
{
    lua_getiuservalue(L, arg, BODY_UV_WORLD);
    clua_world *lw = luaL_testudata(L, -1, CLUA_WORLD_MT);
    lua_pop(L, 1);
    return lw;
}

/* Raises for a failed call: the world's message without its "body_x: " prefix. */
static int status_error(lua_State *L, carom_world *w, carom_status st, int arg, const char *fname)
{
    if (st == CAROM_OK) return 0;
    char buf[256];
    const char *msg = clua_copy_error(w, buf, sizeof buf);
    if (st == CAROM_ERROR_INVALID_ARGUMENT && arg > 0) return clua_arg_error(L, arg, fname, "%s", msg);
    if (st == CAROM_ERROR_LOCKED) return luaL_error(L, "%s: cannot change a body inside a contact callback (%s)", fname, msg);
    return luaL_error(L, "%s: %s", fname, msg);
}

/* ---- world:add_body --------------------------------------------------------- */

static const char *const body_keys[] = {
    "type", "shape", "position", "velocity", "orientation", "angular_velocity", "mass", "density",
    "restitution", "friction", "bullet", "lock_rotation", "lock_to_plane", "plane_normal", "gravity_scale",
    "damping", "linear_damping", "angular_damping", "sleep", "awake", "user_data", "data",
    "category", "mask", "group", "sensor", "material", "force_threshold", NULL};

int clua_world_add_body(lua_State *L)
{
    const char *fname = "add_body";
    clua_world *lw = clua_check_world(L, 1, fname);
    clua_check_table(L, 2, fname);
    clua_check_keys(L, 2, fname, body_keys);
    lua_settop(L, 2);
    carom_body_def d = carom_body_def_default();
    int type;
    if (clua_field_option(L, 2, fname, "type", clua_body_type_names, &type)) d.type = (carom_body_type)type;
    if (clua_rawfield(L, 2, "shape") == LUA_TNIL) clua_arg_error(L, 2, fname, "shape is required (e.g. shape = carom.sphere{radius = 0.5})");
    clua_shape *s = luaL_testudata(L, -1, CLUA_SHAPE_MT);
    if (!s) clua_arg_error(L, 2, fname, "shape must be made by carom.sphere, box, capsule, cylinder, hull, plane, mesh, heightfield or compound, got %s", luaL_typename(L, -1));
    d.shape = s->def; /* s stays on the stack (so its hull points live) until the body is made */
    if (s->def.type == CAROM_SHAPE_MESH) d.mesh = &s->mesh;
    if (s->def.type == CAROM_SHAPE_HEIGHTFIELD) d.heightfield = &s->heightfield;
    if (s->def.type == CAROM_SHAPE_COMPOUND) { d.children = s->children; d.child_count = s->child_count; }
    clua_field_vec3(L, 2, fname, "position", &d.position);
    clua_field_vec3(L, 2, fname, "velocity", &d.linear_velocity);
    clua_field_vec3(L, 2, fname, "angular_velocity", &d.angular_velocity);
    clua_field_quat(L, 2, fname, "orientation", &d.orientation);
    clua_field_vec3(L, 2, fname, "plane_normal", &d.plane_normal);
    /* ranges are the C library's to check (mass 0: use density) */
    clua_field_number(L, 2, fname, "mass", &d.mass);
    clua_field_number(L, 2, fname, "density", &d.density);
    clua_field_number(L, 2, fname, "restitution", &d.restitution);
    clua_field_number(L, 2, fname, "friction", &d.friction);
    clua_field_number(L, 2, fname, "gravity_scale", &d.gravity_scale);
    double damping;
    if (clua_field_number(L, 2, fname, "damping", &damping)) d.linear_damping = d.angular_damping = damping;
    clua_field_number(L, 2, fname, "linear_damping", &d.linear_damping);
    clua_field_number(L, 2, fname, "angular_damping", &d.angular_damping);
    clua_field_bool(L, 2, fname, "bullet", &d.bullet);
    clua_field_bool(L, 2, fname, "lock_rotation", &d.lock_rotation);
    clua_field_bool(L, 2, fname, "lock_to_plane", &d.lock_to_plane);
    clua_field_bool(L, 2, fname, "sleep", &d.enable_sleep);
    clua_field_bool(L, 2, fname, "awake", &d.awake);
    clua_read_filter_keys(L, 2, fname, &d);
    clua_read_material_keys(L, 2, fname, &d);
    int has_user_data = clua_rawfield(L, 2, "user_data") != LUA_TNIL;
    int has_data = clua_rawfield(L, 2, "data") != LUA_TNIL;
    if (has_user_data && has_data) clua_arg_error(L, 2, fname, "give user_data or data (the same field), not both");
    if (!has_data) lua_pop(L, 1);
    else lua_remove(L, -2); /* the user data value is now on top */
    if (lw->stepping)
        return luaL_error(L, "add_body: cannot create a body inside a contact callback (the world is locked until the step ends)");

    /* everything that can fail in Lua is reserved before the body exists */
    lua_getiuservalue(L, 1, WORLD_UV_IDS);
    lua_getiuservalue(L, 1, WORLD_UV_DATA);
    if (!lua_checkstack(L, 8)) return luaL_error(L, "add_body: Lua stack overflow");
    lw = clua_check_world(L, 1, fname); /* a finalizer run by the checks above may have destroyed it */
    carom_body_id id;
    carom_status st = carom_body_try_create(lw->world, &d, &id);
    if (st != CAROM_OK) {
        char buf[256];
        const char *msg = clua_copy_error(lw->world, buf, sizeof buf);
        if (st != CAROM_ERROR_INVALID_ARGUMENT) return luaL_error(L, "add_body: %s", msg);
        return clua_arg_error(L, 2, fname, "%s", msg);
    }
    lua_pushboolean(L, 1);
    lua_rawseti(L, -3, id_key(id)); /* ids[id] = true */
    lua_pushvalue(L, -3);           /* the user data (or nil) */
    lua_rawseti(L, -2, id_key(id)); /* data[id] */
    clua_push_body(L, 1, id);
    return 1;
}

/* ---- getters and setters ------------------------------------------------------ */

#define BODY_VEC_GETTER(name, fn)                          \
    static int body_##name(lua_State *L)                   \
    {                                                      \
        clua_body *b;                                      \
        carom_world *w = check_body(L, 1, #name, &b);      \
        carom_vec3 v = {0, 0, 0};                          \
        fn(w, b->id, &v);                                  \
        return clua_return_vec3(L, v);                     \
    }
BODY_VEC_GETTER(position, carom_body_get_position)
BODY_VEC_GETTER(velocity, carom_body_get_linear_velocity)
BODY_VEC_GETTER(angular_velocity, carom_body_get_angular_velocity)
BODY_VEC_GETTER(center_of_mass, carom_body_get_center_of_mass)
BODY_VEC_GETTER(local_center, carom_body_get_local_center)

#define BODY_VEC_SETTER(name, fn)                                      \
    static int body_##name(lua_State *L)                               \
    {                                                                  \
        clua_body *b;                                                  \
        check_body(L, 1, #name, &b);                                   \
        carom_vec3 v;                                                  \
        clua_check_vec3(L, 2, #name, &v);                              \
        carom_world *w = check_body(L, 1, #name, &b);                  \
        return status_error(L, w, fn(w, b->id, v), 2, #name);          \
    }
BODY_VEC_SETTER(set_position, carom_body_set_position)
BODY_VEC_SETTER(set_velocity, carom_body_set_linear_velocity)
BODY_VEC_SETTER(set_angular_velocity, carom_body_set_angular_velocity)

#define BODY_NUMBER_GETTER(name, fn)                       \
    static int body_##name(lua_State *L)                   \
    {                                                      \
        clua_body *b;                                      \
        carom_world *w = check_body(L, 1, #name, &b);      \
        double v = 0;                                      \
        fn(w, b->id, &v);                                  \
        lua_pushnumber(L, v);                              \
        return 1;                                          \
    }
BODY_NUMBER_GETTER(mass, carom_body_get_mass)
BODY_NUMBER_GETTER(friction, carom_body_get_friction)
BODY_NUMBER_GETTER(restitution, carom_body_get_restitution)
BODY_NUMBER_GETTER(kinetic_energy, carom_body_get_kinetic_energy)

static int body_orientation(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "orientation", &b);
    carom_quat q = {1, 0, 0, 0};
    carom_body_get_orientation(w, b->id, &q);
    lua_pushnumber(L, q.w);
    lua_pushnumber(L, q.x);
    lua_pushnumber(L, q.y);
    lua_pushnumber(L, q.z);
    return 4;
}

static int body_set_orientation(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_orientation", &b);
    carom_quat q;
    clua_check_quat(L, 2, "set_orientation", &q);
    w = check_body(L, 1, "set_orientation", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_orientation(w, b->id, q), 2, "set_orientation");
}

/* body:apply_impulse(jx, jy, jz [, px, py, pz]) (or tables): at the centre of
 * mass, or at the world point p. */
static int body_apply_impulse(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "apply_impulse", &b);
    carom_vec3 j, p;
    int next = clua_check_vec3(L, 2, "apply_impulse", &j);
    int at_point = !lua_isnoneornil(L, next);
    if (at_point) clua_check_vec3(L, next, "apply_impulse", &p);
    w = check_body(L, 1, "apply_impulse", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_apply_impulse(w, b->id, j, at_point ? &p : NULL), 2, "apply_impulse");
}

static int body_set_mass(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_mass", &b);
    double m = clua_check_number(L, 2, "set_mass");
    w = check_body(L, 1, "set_mass", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_mass(w, b->id, m), 2, "set_mass");
}

/* body:inertia(): the 3x3 inertia tensor about the centre of mass, body axes, as rows. */
static int body_inertia(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "inertia", &b);
    double m[9] = {0};
    carom_body_get_inertia(w, b->id, m);
    lua_createtable(L, 3, 0);
    for (int r = 0; r < 3; r++) {
        lua_createtable(L, 3, 0);
        for (int c = 0; c < 3; c++) {
            lua_pushnumber(L, m[3 * r + c]);
            lua_rawseti(L, -2, c + 1);
        }
        lua_rawseti(L, -2, r + 1);
    }
    return 1;
}

static int body_set_friction(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_friction", &b);
    double v = clua_check_number(L, 2, "set_friction");
    if (v < 0) clua_arg_error(L, 2, "set_friction", "friction must not be negative");
    w = check_body(L, 1, "set_friction", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_friction(w, b->id, v), 2, "set_friction");
}

static int body_set_restitution(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_restitution", &b);
    double v = clua_check_number(L, 2, "set_restitution");
    w = check_body(L, 1, "set_restitution", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_restitution(w, b->id, v), 2, "set_restitution");
}

static int body_set_gravity_scale(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_gravity_scale", &b);
    double v = clua_check_number(L, 2, "set_gravity_scale");
    w = check_body(L, 1, "set_gravity_scale", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_gravity_scale(w, b->id, v), 2, "set_gravity_scale");
}

static int body_set_bullet(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_bullet", &b);
    int v = clua_check_boolean(L, 2, "set_bullet");
    w = check_body(L, 1, "set_bullet", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_bullet(w, b->id, v), 2, "set_bullet");
}

static int body_type(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "type", &b);
    carom_body_type t = CAROM_BODY_DYNAMIC;
    carom_body_get_type(w, b->id, &t);
    lua_pushstring(L, clua_body_type_names[t]);
    return 1;
}

static int body_set_type(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_type", &b);
    int t = clua_check_option(L, 2, "set_type", clua_body_type_names);
    w = check_body(L, 1, "set_type", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_type(w, b->id, (carom_body_type)t), 2, "set_type");
}

static int body_shape_type(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "shape_type", &b);
    carom_shape_type t = CAROM_SHAPE_SPHERE;
    carom_body_get_shape_type(w, b->id, &t);
    lua_pushstring(L, clua_shape_names[t]);
    return 1;
}

static int body_is_awake(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "is_awake", &b);
    lua_pushboolean(L, carom_body_is_awake(w, b->id) > 0);
    return 1;
}

static int body_set_awake(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "set_awake", &b);
    int awake = clua_check_boolean(L, 2, "set_awake");
    w = check_body(L, 1, "set_awake", &b); /* again: checking the arguments may have run a finalizer */
    return status_error(L, w, carom_body_set_awake(w, b->id, awake), 2, "set_awake");
}

/* ---- user data ------------------------------------------------------------------ */

static void push_user_data(lua_State *L, int arg)
{
    lua_getiuservalue(L, arg, BODY_UV_WORLD);
    lua_getiuservalue(L, -1, WORLD_UV_DATA);
    lua_rawgeti(L, -1, id_key(((clua_body *)lua_touserdata(L, arg))->id));
    lua_replace(L, -3);
    lua_pop(L, 1);
}

static void set_user_data(lua_State *L, int arg, int value)
{
    value = lua_absindex(L, value);
    lua_getiuservalue(L, arg, BODY_UV_WORLD);
    lua_getiuservalue(L, -1, WORLD_UV_DATA);
    lua_pushvalue(L, value);
    lua_rawseti(L, -2, id_key(((clua_body *)lua_touserdata(L, arg))->id));
    lua_pop(L, 2);
}

static int body_data(lua_State *L)
{
    clua_body *b;
    check_body(L, 1, "data", &b);
    push_user_data(L, 1);
    return 1;
}

static int body_set_data(lua_State *L)
{
    clua_body *b;
    check_body(L, 1, "set_data", &b);
    lua_settop(L, 2);
    set_user_data(L, 1, 2);
    return 0;
}

/* ---- identity and lifetime ------------------------------------------------------ */

static int body_id(lua_State *L)
{
    clua_body *b = luaL_testudata(L, 1, CLUA_BODY_MT);
    if (!b) clua_type_error(L, 1, "id", CLUA_BODY_MT);
    lua_pushinteger(L, (lua_Integer)b->id.index1);
    return 1;
}

static int body_is_valid(lua_State *L)
{
    clua_body *b = luaL_testudata(L, 1, CLUA_BODY_MT);
    if (!b) clua_type_error(L, 1, "is_valid", CLUA_BODY_MT);
    clua_world *lw = body_world(L, 1);
    lua_pushboolean(L, lw && lw->world && carom_body_is_valid(lw->world, b->id));
    return 1;
}

/* body:destroy(): at once, or at the end of the step inside a contact callback. */
static int body_destroy(lua_State *L)
{
    clua_body *b;
    carom_world *w = check_body(L, 1, "destroy", &b);
    clua_world *lw = body_world(L, 1);
    carom_status st = carom_body_destroy(w, b->id);
    if (st != CAROM_OK) return status_error(L, w, st, 0, "destroy");
    if (carom_body_is_valid(w, b->id)) lw->deferred_destroys = 1; /* swept after the step */
    else {
        lua_getiuservalue(L, 1, BODY_UV_WORLD);
        clua_forget_body(L, -1, b->id);
    }
    return 0;
}

/* `local b <close> = world:add_body{...}` destroys the body when b goes out of
 * scope; a body already destroyed (or whose world is gone) is left alone. */
static int body_close(lua_State *L)
{
    clua_body *b = luaL_checkudata(L, 1, CLUA_BODY_MT);
    clua_world *lw = body_world(L, 1);
    if (lw && lw->world && carom_body_is_valid(lw->world, b->id)) return body_destroy(L);
    return 0;
}

static int body_tostring(lua_State *L)
{
    clua_body *b = luaL_checkudata(L, 1, CLUA_BODY_MT);
    clua_world *lw = body_world(L, 1);
    char buf[160];
    if (!lw || !lw->world) snprintf(buf, sizeof buf, "carom.Body #%u (its world has been destroyed)", (unsigned)b->id.index1);
    else if (!carom_body_is_valid(lw->world, b->id)) snprintf(buf, sizeof buf, "carom.Body #%u (destroyed)", (unsigned)b->id.index1);
    else {
        carom_vec3 p = {0, 0, 0};
        carom_body_type t = CAROM_BODY_DYNAMIC;
        carom_shape_type s = CAROM_SHAPE_SPHERE;
        carom_body_get_position(lw->world, b->id, &p);
        carom_body_get_type(lw->world, b->id, &t);
        carom_body_get_shape_type(lw->world, b->id, &s);
        snprintf(buf, sizeof buf, "carom.Body #%u (%s %s at %.4g, %.4g, %.4g)", (unsigned)b->id.index1,
                 clua_body_type_names[t], clua_shape_names[s], p.x, p.y, p.z);
    }
    lua_pushstring(L, buf);
    return 1;
}

/* Same id in the same world (a body is also its own userdata, see clua_push_body). */
static int body_eq(lua_State *L)
{
    clua_body *a = luaL_testudata(L, 1, CLUA_BODY_MT), *b = luaL_testudata(L, 2, CLUA_BODY_MT);
    int same = a && b && carom_body_id_equal(a->id, b->id) && body_world(L, 1) == body_world(L, 2);
    lua_pushboolean(L, same);
    return 1;
}

/* Methods first; then the field body.user_data. */
static int body_index(lua_State *L)
{
    lua_pushvalue(L, 2);
    if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL) return 1;
    if (lua_type(L, 2) == LUA_TSTRING && strcmp(lua_tostring(L, 2), "user_data") == 0) {
        clua_body *b;
        check_body(L, 1, "user_data", &b);
        push_user_data(L, 1);
        return 1;
    }
    lua_pushnil(L);
    return 1;
}

static int body_newindex(lua_State *L)
{
    if (lua_type(L, 2) == LUA_TSTRING && strcmp(lua_tostring(L, 2), "user_data") == 0) {
        clua_body *b;
        check_body(L, 1, "user_data", &b);
        set_user_data(L, 1, 3);
        return 0;
    }
    return luaL_error(L, "cannot set field '%s' of a carom.Body (store your own values in body.user_data)",
                      lua_type(L, 2) == LUA_TSTRING ? lua_tostring(L, 2) : luaL_typename(L, 2));
}

void clua_open_body(lua_State *L)
{
    static const luaL_Reg methods[] = {
        {"position", body_position}, {"velocity", body_velocity}, {"angular_velocity", body_angular_velocity},
        {"orientation", body_orientation}, {"center_of_mass", body_center_of_mass},
        {"local_center", body_local_center}, {"set_position", body_set_position},
        {"set_velocity", body_set_velocity}, {"set_angular_velocity", body_set_angular_velocity},
        {"set_orientation", body_set_orientation}, {"apply_impulse", body_apply_impulse},
        {"mass", body_mass}, {"set_mass", body_set_mass},
        {"inertia", body_inertia}, {"kinetic_energy", body_kinetic_energy}, {"friction", body_friction},
        {"set_friction", body_set_friction}, {"restitution", body_restitution},
        {"set_restitution", body_set_restitution}, {"set_gravity_scale", body_set_gravity_scale},
        {"set_bullet", body_set_bullet}, {"type", body_type}, {"set_type", body_set_type},
        {"shape_type", body_shape_type}, {"is_awake", body_is_awake}, {"set_awake", body_set_awake},
        {"data", body_data}, {"set_data", body_set_data}, {"is_valid", body_is_valid}, {"id", body_id},
        {"destroy", body_destroy}, {NULL, NULL}};
    static const luaL_Reg meta[] = {{"__close", body_close}, {"__tostring", body_tostring}, {"__eq", body_eq},
                                    {"__newindex", body_newindex}, {NULL, NULL}};
    luaL_newmetatable(L, CLUA_BODY_MT);
    luaL_setfuncs(L, meta, 0);
    lua_newtable(L);
    luaL_setfuncs(L, methods, 0);
    lua_pushcclosure(L, body_index, 1);
    lua_setfield(L, -2, "__index");
    lua_pushliteral(L, "locked");
    lua_setfield(L, -2, "__metatable");
    lua_pop(L, 1);
}
