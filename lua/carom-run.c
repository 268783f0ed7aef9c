/* carom-run - plays a Lua scene headless at a fixed step.
 *   carom-run scene.lua [--steps N | --seconds S] [--dt DT] [--substeps K]
 *                       [--bench] [--record FILE.csv] [--quiet]
 *   carom-run --test script.lua      (runs a test script; exit status 1 if it fails)
 * A scene module returns { world = {options}, steps = N, load = function(world),
 * update = function(world, dt), contact = function(event), report = function(world) }.
 * The loop itself is the Lua chunk below, so scenes and the runner share one
 * language; the module "carom" is linked in. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <lua.h>
#include <lauxlib.h>
#include <lualib.h>

int luaopen_carom(lua_State *L);

static const char driver[] =
    "local carom = require 'carom'\n"
    "local opts = ...\n"
    "local ok_load, scene = pcall(dofile, opts.scene)\n"
    "if not ok_load then error(scene, 0) end\n"
    "if type(scene) ~= 'table' then error(opts.scene .. ': a scene must return a table', 0) end\n"
    "local wopts = {}\n"
    "for k, v in pairs(scene.world or {}) do wopts[k] = v end\n"
    "if opts.substeps then wopts.substeps = opts.substeps end\n"
    "local world = carom.world(wopts)\n"
    "local dt = opts.dt or scene.dt or 1/60\n"
    "local steps = opts.steps or (opts.seconds and math.floor(opts.seconds / dt + 0.5)) or scene.steps or 600\n"
    "if scene.contact then world:set_contact_callback(scene.contact) end\n"
    "if scene.load then scene.load(world) end\n"
    "local rec\n"
    "if opts.record then\n"
    "  rec = assert(io.open(opts.record, 'w'))\n"
    "  rec:write('step,t,body,x,y,z,qw,qx,qy,qz\\n')\n"
    "end\n"
    "local function record(s)\n"
    "  local bodies = world:bodies()\n"
    "  table.sort(bodies, function(a, b) return a:id() < b:id() end)\n"
    "  for _, b in ipairs(bodies) do\n"
    "    local x, y, z = b:position()\n"
    "    local qw, qx, qy, qz = b:orientation()\n"
    "    rec:write(string.format('%d,%.6f,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\\n', s, s * dt, b:id(), x, y, z, qw, qx, qy, qz))\n"
    "  end\n"
    "end\n"
    "if rec then record(0) end\n"
    "local times, window, wstart = {}, math.max(1, steps // 20), carom.clock()\n"
    "local last_print, t0 = carom.clock(), carom.clock()\n"
    "for s = 1, steps do\n"
    "  if scene.update then scene.update(world, dt) end\n"
    "  world:step(dt)\n"
    "  if rec then record(s) end\n"
    "  if s % window == 0 then local now = carom.clock(); times[#times + 1] = (now - wstart) * 1000 / window; wstart = now end\n"
    "  if not opts.quiet and carom.clock() - last_print > 2 then\n"
    "    last_print = carom.clock()\n"
    "    io.write(string.format('  step %d/%d (%.0f%%)\\n', s, steps, 100 * s / steps)); io.flush()\n"
    "  end\n"
    "end\n"
    "local wall = carom.clock() - t0\n"
    "if rec then rec:close() end\n"
    "if scene.report then scene.report(world) end\n"
    "if opts.bench then\n"
    "  table.sort(times)\n"
    "  local med = #times > 0 and times[(#times + 1) // 2] or wall * 1000 / math.max(steps, 1)\n"
    "  local st = world:stats()\n"
    "  local ke, pe = world:energy()\n"
    "  local px, py, pz = world:momentum()\n"
    "  print(string.format('bench: %d steps of %.5f s, %.4f ms/step (median of %d windows), %.3f s wall', steps, dt, med, #times, wall))\n"
    "  print(string.format('probes: bodies %d awake %d contacts %d points %d max_penetration %.5f m KE %.6g J PE %.6g J momentum (%.4g, %.4g, %.4g)',\n"
    "    st.bodies, st.awake_bodies, st.contacts, st.contact_points, st.max_penetration, ke, pe, px, py, pz))\n"
    "end\n";

static void usage(FILE *f)
{
    fprintf(f, "usage: carom-run scene.lua [--steps N | --seconds S] [--dt DT] [--substeps K] [--bench] [--record FILE.csv] [--quiet]\n"
               "       carom-run --test script.lua\n");
}

static int report(lua_State *L, int status)
{
    if (status != LUA_OK) {
        const char *msg = lua_tostring(L, -1);
        fprintf(stderr, "carom-run: %s\n", msg ? msg : "(error object is not a string)");
    }
    return status;
}

static int traceback(lua_State *L)
{
    const char *msg = lua_tostring(L, 1);
    luaL_traceback(L, L, msg ? msg : "(error object is not a string)", 1);
    return 1;
}

static int parse_number(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end != '\0') return 0;
    *out = v;
    return 1;
}

int main(int argc, char **argv)
{
    const char *scene = NULL, *record = NULL, *test = NULL;
    double steps = -1, seconds = -1, dt = -1, substeps = -1;
    int bench = 0, quiet = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        double *target = NULL;
        if (!strcmp(a, "--steps")) target = &steps;
        else if (!strcmp(a, "--seconds")) target = &seconds;
        else if (!strcmp(a, "--dt")) target = &dt;
        else if (!strcmp(a, "--substeps")) target = &substeps;
        else if (!strcmp(a, "--bench")) { bench = 1; continue; }
        else if (!strcmp(a, "--quiet")) { quiet = 1; continue; }
        else if (!strcmp(a, "--record") || !strcmp(a, "--test")) {
            if (i + 1 >= argc) { fprintf(stderr, "carom-run: %s needs a file\n", a); return 2; }
            if (!strcmp(a, "--record")) record = argv[++i];
            else test = argv[++i];
            continue;
        } else if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        else if (a[0] == '-') { fprintf(stderr, "carom-run: unknown option %s\n", a); usage(stderr); return 2; }
        else if (!scene) { scene = a; continue; }
        else { fprintf(stderr, "carom-run: more than one scene given\n"); return 2; }
        if (i + 1 >= argc || !parse_number(argv[i + 1], target)) {
            fprintf(stderr, "carom-run: %s needs a number\n", a);
            return 2;
        }
        i++;
    }
    if (steps >= 0 && seconds >= 0) { fprintf(stderr, "carom-run: give --steps or --seconds, not both\n"); return 2; }
    if ((steps >= 0 && (steps < 1 || steps > 1e9 || steps != (long long)steps)) ||
        (seconds >= 0 && !(seconds > 0 && seconds < 1e7)) || (dt >= 0 && !(dt > 0 && dt <= 1)) ||
        (substeps >= 0 && !(substeps >= 1 && substeps <= 64 && substeps == (int)substeps))) {
        fprintf(stderr, "carom-run: --steps must be a positive integer, --seconds positive, --dt in (0, 1], --substeps 1..64\n");
        return 2;
    }
    if (!scene && !test) { usage(stderr); return 2; }

    lua_State *L = luaL_newstate();
    if (!L) { fprintf(stderr, "carom-run: cannot create a Lua state\n"); return 1; }
    luaL_openlibs(L);
    luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
    lua_pushcfunction(L, luaopen_carom);
    lua_setfield(L, -2, "carom");
    lua_pop(L, 1);
    lua_pushcfunction(L, traceback);
    int status;
    if (test) {
        status = luaL_loadfile(L, test);
        if (status == LUA_OK) status = lua_pcall(L, 0, 0, 1);
    } else {
        status = luaL_loadbuffer(L, driver, sizeof driver - 1, "=carom-run");
        if (status == LUA_OK) {
            lua_createtable(L, 0, 8);
            lua_pushstring(L, scene); lua_setfield(L, -2, "scene");
            if (record) { lua_pushstring(L, record); lua_setfield(L, -2, "record"); }
            if (steps >= 0) { lua_pushinteger(L, (lua_Integer)steps); lua_setfield(L, -2, "steps"); }
            if (seconds >= 0) { lua_pushnumber(L, seconds); lua_setfield(L, -2, "seconds"); }
            if (dt >= 0) { lua_pushnumber(L, dt); lua_setfield(L, -2, "dt"); }
            if (substeps >= 0) { lua_pushinteger(L, (lua_Integer)substeps); lua_setfield(L, -2, "substeps"); }
            lua_pushboolean(L, bench); lua_setfield(L, -2, "bench");
            lua_pushboolean(L, quiet); lua_setfield(L, -2, "quiet");
            status = lua_pcall(L, 1, 0, 1);
        }
    }
    status = report(L, status);
    lua_close(L);
    return status == LUA_OK ? 0 : 1;
}
