/* fuzz_lua.c - libFuzzer harness for the Lua module: the input picks
 * statements from a grammar of what a careless or hostile script does
 * (wrong types, NaN and huge numbers, destroyed worlds and bodies, contact
 * callbacks that raise, destroy, step or yield, coroutines, snapshots and
 * damaged snapshots, the collector running at odd moments) and runs each in
 * a pcall. Errors are expected; the invariant is no crash and no sanitizer
 * report. Memory and instructions are capped per input. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <lua.h>
#include <lauxlib.h>
#include <lualib.h>
#include "fuzz_input.h"

int luaopen_carom(lua_State *L);

typedef struct budget { size_t used, limit; } budget;

static void *limited_alloc(void *ud, void *ptr, size_t osize, size_t nsize)
{
    budget *b = ud;
    if (!ptr) osize = 0;
    if (nsize == 0) {
        free(ptr);
        b->used -= osize;
        return NULL;
    }
    if (nsize > osize && b->used + (nsize - osize) > b->limit) return NULL;
    void *p = realloc(ptr, nsize);
    if (p) b->used = b->used - osize + nsize;
    return p;
}

static void stop_runaway(lua_State *L, lua_Debug *ar)
{
    (void)ar;
    luaL_error(L, "instruction budget spent");
}

static const char *const numbers[] = {
    "0", "-0.0", "1", "-1", "0.5", "1/60", "1e-6", "1e6", "1e-7", "1e7", "1e15", "1e16", "1e-9", "1e12", "4000",
    "1e9", "1e300", "-1e300", "1/0", "-1/0", "0/0", "2^53", "4.9e-324", "'3'", "'x'", "nil", "true", "{}", "{1,2}",
    "math.huge", "-7", "1e-324", "100", "0.1", "9.81"};
static const char *const shapes[] = {
    "carom.sphere{radius = %N}", "carom.box{half_extents = {%N, %N, %N}}", "carom.capsule{%N, %N}",
    "carom.cylinder{radius = %N, half_height = %N}", "carom.plane{normal = {%N, %N, %N}, offset = %N}",
    "carom.hull{{0,0,0},{%N,0,0},{0,%N,0},{0,0,%N}}", "carom.sphere{radius = 0.3}", "carom.box{half_extents = {0.5,0.5,0.5}}",
    "carom.hull{points = {{0,0,0},{1,0,0},{0,1,0}}}", "carom.sphere(%N)"};
static const char *const statements[] = {
    "W = carom.world{}",
    "W = carom.world{preset = 'fast', gravity = {%N, %N, %N}, substeps = %N}",
    "W2 = carom.world{preset = 'accurate', sleep = false, ccd = %B}",
    "B[%I] = W:add_body{shape = %S, position = {%N, %N, %N}}",
    "B[%I] = W:add_body{shape = %S, position = {0, 0, %N}, velocity = {%N, %N, %N}, mass = %N}",
    "B[%I] = W:add_body{type = 'static', shape = carom.plane{}}",
    "B[%I] = W:add_body{type = 'kinematic', shape = %S, velocity = {1, 0, 0}, angular_velocity = {0, 0, %N}}",
    "B[%I] = W:add_body{shape = %S, density = %N, friction = %N, restitution = %N, user_data = B}",
    "B[%I] = W2:add_body{shape = %S, position = {0, 0, %N}}",
    "W:step(%N)", "W:step()", "W:advance(%N)", "W2:step(1/60)", "for i = 1, 20 do W:step(1/60) end",
    "B[%I]:destroy()", "W:destroy()", "W2:destroy()",
    "B[%I]:set_velocity(%N, %N, %N)", "B[%I]:set_angular_velocity(%N, %N, %N)", "B[%I]:set_position(%N, %N, %N)",
    "B[%I]:apply_impulse(%N, %N, %N)", "B[%I]:apply_force(%N, %N, %N)", "B[%I]:set_mass(%N)",
    "B[%I]:set_type(%T)", "B[%I]:set_friction(%N)", "B[%I]:set_orientation(%N, %N, %N, %N)",
    "B[%I]:set_awake(%B)", "B[%I].user_data = %N", "local x = B[%I]:position()", "local x = B[%I]:inertia()",
    "W:set_contact_callback(function(e) error('boom') end)",
    "W:set_contact_callback(function(e) if e.a then e.a:destroy() end end)",
    "W:set_contact_callback(function(e) W:step(1/60) end)",
    "W:set_contact_callback(function(e) W:add_body{shape = carom.sphere{radius = 1}} end)",
    "W:set_contact_callback(function(e) W:destroy() end)",
    "W:set_contact_callback(function(e) B[%I]:set_velocity(1, 2, 3); collectgarbage() end)",
    "W:set_contact_callback(function(e) S = W:snapshot() end)",
    "W:set_contact_callback(function(e) coroutine.yield() end)",
    "W:set_contact_callback(nil)", "W:set_contact_callback(%N)",
    "CO = coroutine.wrap(function() W:step(1/60); coroutine.yield(); W:step(1/60) end); CO()", "CO()",
    "CO = coroutine.create(function() for i = 1, 5 do W:step(1/60) end end); coroutine.resume(CO)",
    "S = W:snapshot()", "W = carom.restore(S)", "W2 = carom.restore(S)", "carom.restore(S:sub(1, %N))",
    "carom.restore(S:sub(1, 40) .. 'x' .. S:sub(42))", "carom.restore(%N)",
    "local h = W:ray_cast({%N, %N, %N}, {0, 0, -10})", "local q = W:query_aabb({%N,%N,%N}, {%N,%N,%N})",
    "local e = W:events()", "local s = W:stats()", "local e = W:energy()", "W:configure{hertz = %N, substeps = %N}",
    "local bs = W:bodies()", "B = {}; collectgarbage()", "collectgarbage()", "W = nil; collectgarbage()",
    "local x = W:measure_penetration()", "W.step(B[%I])", "B[%I].destroy(W)", "local t = tostring(B[%I]) .. tostring(W)",
    "local b <close> = W:add_body{shape = carom.sphere{radius = 0.2}}",
    "local w <close> = carom.world{}; w:add_body{shape = carom.sphere{radius = 0.2}}; w:step(1/60)"};

static void append(luaL_Buffer *b, fuzz_input *in, const char *tmpl, int depth)
{
    for (const char *p = tmpl; *p; p++) {
        if (p[0] != '%' || !p[1]) { luaL_addchar(b, *p); continue; }
        p++;
        switch (*p) {
        case 'N': luaL_addstring(b, numbers[fz_below(in, sizeof numbers / sizeof numbers[0])]); break;
        case 'B': luaL_addstring(b, fz_bool(in) ? "true" : "false"); break;
        case 'I': { char n[8]; snprintf(n, sizeof n, "%u", 1 + fz_below(in, 6)); luaL_addstring(b, n); break; }
        case 'T': {
            static const char *const t[] = {"'static'", "'kinematic'", "'dynamic'", "'x'", "3"};
            luaL_addstring(b, t[fz_below(in, 5)]);
            break;
        }
        case 'S':
            if (depth < 2) append(b, in, shapes[fz_below(in, sizeof shapes / sizeof shapes[0])], depth + 1);
            else luaL_addstring(b, "nil");
            break;
        default: luaL_addchar(b, *p);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_input in = {data, size, 0};
    budget mem = {0, 64u << 20};
    lua_State *L = lua_newstate(limited_alloc, &mem);
    if (!L) return 0;
    luaL_openlibs(L);
    luaL_requiref(L, "carom", luaopen_carom, 1);
    lua_pop(L, 1);
    lua_sethook(L, stop_runaway, LUA_MASKCOUNT, 2000000);
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    luaL_addstring(&b, "B = {}; S = ''; W = carom.world{}; W2 = carom.world{}\n");
    for (int i = 0; i < 40 && !fz_done(&in); i++) {
        luaL_addstring(&b, "pcall(function() ");
        append(&b, &in, statements[fz_below(&in, sizeof statements / sizeof statements[0])], 0);
        luaL_addstring(&b, " end)\n");
    }
    luaL_pushresult(&b);
    const char *script = lua_tostring(L, -1);
    if (getenv("CAROM_FUZZ_PRINT")) fprintf(stderr, "%s", script);
    if (luaL_loadstring(L, script) == LUA_OK) lua_pcall(L, 0, 0, 0);
    lua_close(L);
    return 0;
}
