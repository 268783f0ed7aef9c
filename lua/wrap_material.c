/* wrap_material.c - carom.material{...} (an immutable, checked material),
 * the material and force_threshold body keys' setters and getters, and the
 * force calls: body:apply_torque(t), body:apply_force(f [, world_point]). */
#include <string.h>
#include "carom_lua.h"

static const char *const combine_names[] = {"default", "average", "geometric_mean", "min", "multiply", "max", NULL};

const carom_material *clua_check_material(lua_State *L, int arg, const char *fname)
{
    const carom_material *m = luaL_testudata(L, arg, CLUA_MATERIAL_MT);
    if (!m) clua_type_error(L, arg, fname, "carom.Material (made by carom.material{...})");
    return m;
}

/* carom.material{friction = 0.6, restitution = 0, rolling_resistance = 0, combine = "default"} */
static int l_material(lua_State *L)
{
    static const char *const keys[] = {"friction", "restitution", "rolling_resistance", "combine", NULL};
    clua_check_table(L, 1, "material");
    clua_check_keys(L, 1, "material", keys);
    carom_material m = carom_material_default();
    clua_field_number(L, 1, "material", "friction", &m.friction);
    clua_field_number(L, 1, "material", "restitution", &m.restitution);
    clua_field_number(L, 1, "material", "rolling_resistance", &m.rolling_resistance);
    int combine;
    if (clua_field_option(L, 1, "material", "combine", combine_names, &combine)) m.combine = (carom_combine_mode)combine;
    char msg[160];
    if (carom_material_check(&m, msg, sizeof msg) != CAROM_OK) return clua_arg_error(L, 1, "material", "%s", msg);
    carom_material *u = lua_newuserdatauv(L, sizeof *u, 0);
    *u = m;
    luaL_setmetatable(L, CLUA_MATERIAL_MT);
    return 1;
}

static void push_material(lua_State *L, const carom_material *m)
{
    carom_material *u = lua_newuserdatauv(L, sizeof *u, 0);
    *u = *m;
    luaL_setmetatable(L, CLUA_MATERIAL_MT);
}

/* m.friction, m.restitution, m.rolling_resistance, m.combine (read only) */
static int material_index(lua_State *L)
{
    const carom_material *m = clua_check_material(L, 1, "material");
    const char *key = luaL_checkstring(L, 2);
    if (strcmp(key, "friction") == 0) lua_pushnumber(L, m->friction);
    else if (strcmp(key, "restitution") == 0) lua_pushnumber(L, m->restitution);
    else if (strcmp(key, "rolling_resistance") == 0) lua_pushnumber(L, m->rolling_resistance);
    else if (strcmp(key, "combine") == 0) lua_pushstring(L, combine_names[m->combine]);
    else lua_pushnil(L);
    return 1;
}

static int material_newindex(lua_State *L)
{
    return luaL_error(L, "a carom.Material cannot be changed: make a new one with carom.material{...}");
}

static int material_tostring(lua_State *L)
{
    const carom_material *m = clua_check_material(L, 1, "tostring");
    lua_pushfstring(L, "carom.Material (friction %f, restitution %f, rolling_resistance %f, combine %s)", m->friction,
                    m->restitution, m->rolling_resistance, combine_names[m->combine]);
    return 1;
}

/* ---- body calls --------------------------------------------------------------------- */

static int status_result(lua_State *L, carom_world *w, carom_status st, int arg, const char *fname)
{
    if (st == CAROM_OK) return 0;
    char buf[256];
    const char *msg = clua_copy_error(w, buf, sizeof buf);
    if (st == CAROM_ERROR_INVALID_ARGUMENT && arg > 0) return clua_arg_error(L, arg, fname, "%s", msg);
    if (st == CAROM_ERROR_LOCKED) return luaL_error(L, "%s: cannot change a body inside a contact callback (%s)", fname, msg);
    return luaL_error(L, "%s: %s", fname, msg);
}

/* body:apply_torque(t): for the next step (deferred inside a callback). */
static int body_apply_torque(lua_State *L)
{
    carom_body_id id;
    clua_check_body_id(L, 1, "apply_torque", &id);
    carom_vec3 t;
    clua_check_vec3(L, 2, "apply_torque", &t);
    carom_world *w = clua_check_body_id(L, 1, "apply_torque", &id); /* again: the checks may have run a finalizer */
    return status_result(L, w, carom_body_apply_torque(w, id, t), 2, "apply_torque");
}

/* body:apply_force(f [, world_point]): for the next step; at a point it
 * also turns the body by (point - centre of mass) x f. */
static int body_apply_force(lua_State *L)
{
    carom_body_id id;
    clua_check_body_id(L, 1, "apply_force", &id);
    carom_vec3 f, p;
    int next = clua_check_vec3(L, 2, "apply_force", &f);
    int at_point = !lua_isnoneornil(L, next);
    if (at_point) clua_check_vec3(L, next, "apply_force", &p);
    carom_world *w = clua_check_body_id(L, 1, "apply_force", &id);
    carom_status st = at_point ? carom_body_apply_force_at_point(w, id, f, p) : carom_body_apply_force(w, id, f);
    return status_result(L, w, st, 2, "apply_force");
}

/* body:applied_force(): the force and torque queued for the next step. */
static int body_applied_force(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "applied_force", &id);
    carom_vec3 f = {0, 0, 0}, t = {0, 0, 0};
    carom_body_get_applied_force(w, id, &f, &t);
    clua_push_vec3_table(L, f);
    clua_push_vec3_table(L, t);
    return 2;
}

static int body_set_force_threshold(lua_State *L)
{
    carom_body_id id;
    clua_check_body_id(L, 1, "set_force_threshold", &id);
    double v = clua_check_number(L, 2, "set_force_threshold");
    carom_world *w = clua_check_body_id(L, 1, "set_force_threshold", &id);
    return status_result(L, w, carom_body_set_force_threshold(w, id, v), 2, "set_force_threshold");
}

static int body_force_threshold(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "force_threshold", &id);
    double v = 0;
    carom_body_get_force_threshold(w, id, &v);
    lua_pushnumber(L, v);
    return 1;
}

static int body_set_material(lua_State *L)
{
    carom_body_id id;
    clua_check_body_id(L, 1, "set_material", &id);
    const carom_material *m = clua_check_material(L, 2, "set_material");
    carom_world *w = clua_check_body_id(L, 1, "set_material", &id);
    return status_result(L, w, carom_body_set_material(w, id, m), 2, "set_material");
}

static int body_material(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "material", &id);
    carom_material m = carom_material_default();
    carom_body_get_material(w, id, &m);
    push_material(L, &m);
    return 1;
}

void clua_read_material_keys(lua_State *L, int arg, const char *fname, carom_body_def *d)
{
    clua_field_number(L, arg, fname, "force_threshold", &d->force_threshold);
    if (clua_rawfield(L, arg, "material") != LUA_TNIL) {
        const carom_material *m = luaL_testudata(L, -1, CLUA_MATERIAL_MT);
        if (!m) clua_arg_error(L, arg, fname, "material must be made by carom.material{...}, got %s", luaL_typename(L, -1));
        d->material = m; /* the table at arg holds it while the body is made */
    }
    lua_pop(L, 1);
}

void clua_open_material(lua_State *L)
{
    static const luaL_Reg meta[] = {{"__index", material_index}, {"__newindex", material_newindex},
                                    {"__tostring", material_tostring}, {NULL, NULL}};
    static const luaL_Reg body_methods[] = {{"apply_torque", body_apply_torque}, {"apply_force", body_apply_force},
                                            {"applied_force", body_applied_force},
                                            {"set_force_threshold", body_set_force_threshold},
                                            {"force_threshold", body_force_threshold},
                                            {"set_material", body_set_material}, {"material", body_material},
                                            {NULL, NULL}};
    luaL_newmetatable(L, CLUA_MATERIAL_MT);
    luaL_setfuncs(L, meta, 0);
    lua_pushliteral(L, "carom.Material");
    lua_setfield(L, -2, "__name");
    lua_pop(L, 1);
    lua_pushcfunction(L, l_material);
    lua_setfield(L, -2, "material");
    luaL_getmetatable(L, CLUA_BODY_MT);
    lua_getfield(L, -1, "__index"); /* a closure over the methods table */
    lua_getupvalue(L, -1, 1);
    luaL_setfuncs(L, body_methods, 0);
    lua_pop(L, 3);
}
