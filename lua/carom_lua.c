/* carom_lua.c - the Lua 5.4 module "carom": argument checking shared by the
 * wrap_*.c files, and luaopen_carom. Every failure is a Lua error naming the
 * function and the bad argument; nothing a script passes reaches the C API
 * unchecked, so a script cannot crash its host. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "carom_lua.h"

#if defined(__GNUC__)
#define CLUA_EXPORT __attribute__((visibility("default")))
#else
#define CLUA_EXPORT
#endif

/* ---- errors ---------------------------------------------------------------- */

int clua_arg_error(lua_State *L, int arg, const char *fname, const char *fmt, ...)
{
    /* C's formatter, not lua_pushvfstring: range messages print doubles with %g,
     * which Lua's own formatter does not know. */
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return luaL_error(L, "bad argument #%d to '%s' (%s)", arg, fname, msg);
}

static const char *type_name(lua_State *L, int arg)
{
    if (lua_isnone(L, arg)) return "no value";
    int t = luaL_getmetafield(L, arg, "__name");
    if (t == LUA_TSTRING) {
        const char *n = lua_tostring(L, -1);
        lua_pop(L, 1);
        return n; /* still referenced by the metatable */
    }
    if (t != LUA_TNIL) lua_pop(L, 1);
    return luaL_typename(L, arg);
}

int clua_type_error(lua_State *L, int arg, const char *fname, const char *expected)
{
    return clua_arg_error(L, arg, fname, "%s expected, got %s", expected, type_name(L, arg));
}

int clua_rawfield(lua_State *L, int t, const char *key)
{
    t = lua_absindex(L, t);
    lua_pushstring(L, key);
    return lua_rawget(L, t);
}

const char *clua_copy_error(const carom_world *world, char *buf, size_t size)
{
    snprintf(buf, size, "%s", carom_world_last_error_reason(world));
    return buf;
}

/* ---- plain arguments ------------------------------------------------------- */

double clua_check_number(lua_State *L, int arg, const char *fname)
{
    if (lua_type(L, arg) != LUA_TNUMBER) clua_type_error(L, arg, fname, "number");
    double v = lua_tonumber(L, arg);
    if (!isfinite(v)) clua_arg_error(L, arg, fname, "number must be finite");
    return v;
}

lua_Integer clua_check_integer(lua_State *L, int arg, const char *fname, lua_Integer lo, lua_Integer hi)
{
    if (lua_type(L, arg) != LUA_TNUMBER) clua_type_error(L, arg, fname, "integer");
    lua_Integer v;
    if (lua_isinteger(L, arg)) v = lua_tointeger(L, arg);
    else {
        double d = lua_tonumber(L, arg);
        if (!(d == floor(d) && d >= -9e15 && d <= 9e15)) clua_arg_error(L, arg, fname, "number must be an integer");
        v = (lua_Integer)d;
    }
    if (v < lo || v > hi) clua_arg_error(L, arg, fname, "must be in %lld..%lld", (long long)lo, (long long)hi);
    return v;
}

int clua_check_boolean(lua_State *L, int arg, const char *fname)
{
    if (lua_type(L, arg) != LUA_TBOOLEAN) clua_type_error(L, arg, fname, "boolean");
    return lua_toboolean(L, arg);
}

/* "\"a\", \"b\" or \"c\"" into buf */
static void list_names(const char *const *names, char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; names[i] && used + 1 < size; i++) {
        const char *sep = i == 0 ? "" : names[i + 1] ? ", " : " or ";
        int n = snprintf(buf + used, size - used, "%s\"%s\"", sep, names[i]);
        if (n < 0) break;
        used += (size_t)n;
    }
}

static int find_name(const char *s, const char *const *names)
{
    for (int i = 0; names[i]; i++)
        if (strcmp(s, names[i]) == 0) return i;
    return -1;
}

int clua_check_option(lua_State *L, int arg, const char *fname, const char *const *names)
{
    char list[160];
    list_names(names, list, sizeof list);
    int i = lua_type(L, arg) == LUA_TSTRING ? find_name(lua_tostring(L, arg), names) : -1;
    if (i < 0) clua_arg_error(L, arg, fname, "expected %s, got %s", list, lua_type(L, arg) == LUA_TSTRING ? lua_tostring(L, arg) : type_name(L, arg));
    return i;
}

/* ---- vectors --------------------------------------------------------------- */

/* The n numbers of the table at index t: t[1..n], or the named fields when
 * t[1] is absent. Returns 0 if they are not all numbers. */
static int table_numbers(lua_State *L, int t, int n, const char *const *named, double *out)
{
    t = lua_absindex(L, t);
    int by_name = lua_rawgeti(L, t, 1) == LUA_TNIL;
    lua_pop(L, 1);
    for (int i = 0; i < n; i++) {
        int type = by_name ? clua_rawfield(L, t, named[i]) : lua_rawgeti(L, t, i + 1);
        if (type != LUA_TNUMBER) { lua_pop(L, 1); return 0; }
        out[i] = lua_tonumber(L, -1);
        lua_pop(L, 1);
    }
    return 1;
}

static const char *const xyz[] = {"x", "y", "z"};
static const char *const wxyz[] = {"w", "x", "y", "z"};

int clua_check_vec3(lua_State *L, int arg, const char *fname, carom_vec3 *out)
{
    double c[3];
    int next;
    if (lua_type(L, arg) == LUA_TTABLE) {
        if (!table_numbers(L, arg, 3, xyz, c)) clua_arg_error(L, arg, fname, "expected a vector {x, y, z} of 3 numbers");
        next = arg + 1;
    } else {
        if (lua_type(L, arg) != LUA_TNUMBER) clua_type_error(L, arg, fname, "vector (3 numbers or {x, y, z})");
        for (int i = 0; i < 3; i++) {
            if (lua_type(L, arg + i) != LUA_TNUMBER) clua_type_error(L, arg + i, fname, "number (vector component)");
            c[i] = lua_tonumber(L, arg + i);
        }
        next = arg + 3;
    }
    if (!(isfinite(c[0]) && isfinite(c[1]) && isfinite(c[2]))) clua_arg_error(L, arg, fname, "vector components must be finite");
    out->x = c[0]; out->y = c[1]; out->z = c[2];
    return next;
}

int clua_check_quat(lua_State *L, int arg, const char *fname, carom_quat *out)
{
    double c[4];
    int next;
    if (lua_type(L, arg) == LUA_TTABLE) {
        if (!table_numbers(L, arg, 4, wxyz, c)) clua_arg_error(L, arg, fname, "expected a quaternion {w, x, y, z} of 4 numbers");
        next = arg + 1;
    } else {
        if (lua_type(L, arg) != LUA_TNUMBER) clua_type_error(L, arg, fname, "quaternion (4 numbers or {w, x, y, z})");
        for (int i = 0; i < 4; i++) {
            if (lua_type(L, arg + i) != LUA_TNUMBER) clua_type_error(L, arg + i, fname, "number (quaternion component)");
            c[i] = lua_tonumber(L, arg + i);
        }
        next = arg + 4;
    }
    for (int i = 0; i < 4; i++)
        if (!isfinite(c[i])) clua_arg_error(L, arg, fname, "quaternion components must be finite");
    out->w = c[0]; out->x = c[1]; out->y = c[2]; out->z = c[3];
    return next;
}

void clua_push_vec3_table(lua_State *L, carom_vec3 v)
{
    lua_createtable(L, 3, 0);
    lua_pushnumber(L, v.x); lua_rawseti(L, -2, 1);
    lua_pushnumber(L, v.y); lua_rawseti(L, -2, 2);
    lua_pushnumber(L, v.z); lua_rawseti(L, -2, 3);
}

int clua_return_vec3(lua_State *L, carom_vec3 v)
{
    lua_pushnumber(L, v.x);
    lua_pushnumber(L, v.y);
    lua_pushnumber(L, v.z);
    return 3;
}

/* ---- options tables -------------------------------------------------------- */

void clua_check_table(lua_State *L, int arg, const char *fname)
{
    if (lua_type(L, arg) != LUA_TTABLE) clua_type_error(L, arg, fname, "table of options");
}

void clua_check_option_keys(lua_State *L, int arg, const char *fname, const char *const *allowed, int positions)
{
    arg = lua_absindex(L, arg);
    int odd_type = LUA_NUMTYPES; /* lowest type of a key that is neither a name nor a position */
    int out_of_range = 0;
    lua_pushnil(L); /* the alphabetically first unknown name */
    int unknown = lua_gettop(L);
    lua_pushnil(L);
    while (lua_next(L, arg)) {
        lua_pop(L, 1);
        int t = lua_type(L, -1);
        if (t == LUA_TSTRING) {
            const char *k = lua_tostring(L, -1);
            if (find_name(k, allowed) < 0 && (lua_isnil(L, unknown) || strcmp(k, lua_tostring(L, unknown)) < 0)) {
                lua_pushvalue(L, -1);
                lua_replace(L, unknown);
            }
        } else if (positions > 0 && lua_isinteger(L, -1)) {
            lua_Integer i = lua_tointeger(L, -1);
            if (i < 1 || i > positions) out_of_range = 1;
        } else if (t < odd_type) {
            odd_type = t;
        }
    }
    if (odd_type != LUA_NUMTYPES) clua_arg_error(L, arg, fname, "option names must be strings, got a %s key", lua_typename(L, odd_type));
    if (out_of_range) clua_arg_error(L, arg, fname, "too many values (%s takes %d)", fname, positions);
    if (!lua_isnil(L, unknown)) clua_arg_error(L, arg, fname, "unknown option '%s'", lua_tostring(L, unknown));
    lua_pop(L, 1);
}

void clua_check_keys(lua_State *L, int arg, const char *fname, const char *const *allowed)
{
    clua_check_option_keys(L, arg, fname, allowed, 0);
}

/* Pushes t[key]; returns 0 (and pushes nothing) when it is nil. */
static int get_field(lua_State *L, int arg, const char *key)
{
    if (clua_rawfield(L, arg, key) != LUA_TNIL) return 1;
    lua_pop(L, 1);
    return 0;
}

int clua_field_number(lua_State *L, int arg, const char *fname, const char *key, double *out)
{
    if (!get_field(L, arg, key)) return 0;
    if (lua_type(L, -1) != LUA_TNUMBER) clua_arg_error(L, arg, fname, "%s must be a number, got %s", key, luaL_typename(L, -1));
    double v = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (!isfinite(v)) clua_arg_error(L, arg, fname, "%s must be finite", key);
    *out = v;
    return 1;
}

int clua_field_int(lua_State *L, int arg, const char *fname, const char *key, int *out)
{
    double v;
    if (!clua_field_number(L, arg, fname, key, &v)) return 0;
    if (v != floor(v) || v < -1e9 || v > 1e9) clua_arg_error(L, arg, fname, "%s must be an integer", key);
    *out = (int)v;
    return 1;
}

int clua_field_bool(lua_State *L, int arg, const char *fname, const char *key, int *out)
{
    if (!get_field(L, arg, key)) return 0;
    if (lua_type(L, -1) != LUA_TBOOLEAN) clua_arg_error(L, arg, fname, "%s must be a boolean, got %s", key, luaL_typename(L, -1));
    *out = lua_toboolean(L, -1);
    lua_pop(L, 1);
    return 1;
}

int clua_field_vec3(lua_State *L, int arg, const char *fname, const char *key, carom_vec3 *out)
{
    if (!get_field(L, arg, key)) return 0;
    double c[3];
    if (lua_type(L, -1) != LUA_TTABLE || !table_numbers(L, -1, 3, xyz, c))
        clua_arg_error(L, arg, fname, "%s must be a vector {x, y, z} of 3 numbers", key);
    lua_pop(L, 1);
    if (!(isfinite(c[0]) && isfinite(c[1]) && isfinite(c[2]))) clua_arg_error(L, arg, fname, "%s must be finite", key);
    out->x = c[0]; out->y = c[1]; out->z = c[2];
    return 1;
}

int clua_field_quat(lua_State *L, int arg, const char *fname, const char *key, carom_quat *out)
{
    if (!get_field(L, arg, key)) return 0;
    double c[4];
    if (lua_type(L, -1) != LUA_TTABLE || !table_numbers(L, -1, 4, wxyz, c))
        clua_arg_error(L, arg, fname, "%s must be a quaternion {w, x, y, z} of 4 numbers", key);
    lua_pop(L, 1);
    for (int i = 0; i < 4; i++)
        if (!isfinite(c[i])) clua_arg_error(L, arg, fname, "%s must be finite", key);
    out->w = c[0]; out->x = c[1]; out->y = c[2]; out->z = c[3];
    return 1;
}

int clua_field_option(lua_State *L, int arg, const char *fname, const char *key, const char *const *names, int *out)
{
    if (!get_field(L, arg, key)) return 0;
    int i = lua_type(L, -1) == LUA_TSTRING ? find_name(lua_tostring(L, -1), names) : -1;
    if (i < 0) {
        char list[160];
        list_names(names, list, sizeof list);
        clua_arg_error(L, arg, fname, "%s must be %s", key, list);
    }
    lua_pop(L, 1);
    *out = i;
    return 1;
}

int clua_traceback(lua_State *L)
{
    if (lua_type(L, 1) != LUA_TSTRING && lua_type(L, 1) != LUA_TNUMBER) {
        /* an error object (a table, say) is the script's value: pass it through */
        lua_settop(L, 1);
        return 1;
    }
    const char *msg = lua_tostring(L, 1);
    if (!msg) {
        if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) msg = lua_tostring(L, -1);
        else msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    }
    luaL_traceback(L, L, msg, 1);
    return 1;
}

/* ---- the module ------------------------------------------------------------ */

/* carom.clock(): monotonic seconds, for timing scenes. */
static int l_clock(lua_State *L)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    lua_pushnumber(L, (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9);
    return 1;
}

CLUA_EXPORT int luaopen_carom(lua_State *L)
{
    lua_newtable(L);
    clua_open_shapes(L);
    clua_open_world(L);
    clua_open_body(L);
    clua_open_game(L);
    clua_open_material(L);
    lua_pushcfunction(L, l_clock);
    lua_setfield(L, -2, "clock");
    lua_pushstring(L, carom_version());
    lua_setfield(L, -2, "version");
    return 1;
}
