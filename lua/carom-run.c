/* carom-run - plays a Lua scene headless at a fixed step.
 *
 *   carom-run scene.lua [--steps N | --seconds S] [--dt DT] [--substeps K] [--threads N]
 *                       [--bench] [--record FILE.csv] [--quiet]
 *   carom-run --test script.lua
 *   carom-run --version
 *
 * A scene is a Lua file returning a table:
 *   { world = {options for carom.world}, steps = N (or seconds = S), dt = DT,
 *     load = function(world) end, update = function(world, dt) end,
 *     contact = function(event) end, report = function(world) end }
 * (every field optional; any other key is an error). The runner makes the world, calls load, then for
 * each step update and world:step(dt) (contact is the world's contact
 * callback), then report. --record writes every body's pose after each step
 * as CSV; --bench prints the median time per step and the accuracy probes.
 * --test runs a script plainly (it prints "N passed, M failed" and fails by
 * raising an error or calling os.exit(1)).
 *
 * Exit status: 0 success, 1 the scene or script failed, 2 bad command line.
 * The module "carom" is linked in (package.preload), so no carom.so is needed
 * and the runner runs under the sanitizers. Scripts see the usual global
 * `arg` (arg[0] the script, arg[-1] this program). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <lua.h>
#include <lauxlib.h>
#include <lualib.h>
#include <carom/carom.h>

int luaopen_carom(lua_State *L);

/* The fixed-step loop, in Lua so that scenes and runner share one language.
 * Receives the options table built from the command line. */
static const char driver_setup[] =
    "local carom = require 'carom'\n"
    "local opts = ...\n"
    /* errors about the scene file itself: one line, no traceback (see message_handler) */
    "local function fail(msg) error({ runner_message = msg }) end\n"
    "local chunk, err = loadfile(opts.scene)\n"
    "if not chunk then fail(err) end\n"
    "local scene = chunk()\n"
    "if type(scene) ~= 'table' then\n"
    "  fail(opts.scene .. ': a scene must return a table {load = ..., update = ..., report = ...}, got ' .. type(scene))\n"
    "end\n"
    "local valid = { 'contact', 'dt', 'load', 'report', 'seconds', 'steps', 'update', 'world' }\n"
    "local is_valid = {}\n"
    "for _, k in ipairs(valid) do is_valid[k] = true end\n"
    "for k in pairs(scene) do\n"
    "  if not is_valid[k] then\n"
    "    fail(string.format('%s: unknown key %s in the scene table (valid keys: %s)', opts.scene,\n"
    "      type(k) == 'string' and string.format('%q', k) or '[' .. tostring(k) .. ']', table.concat(valid, ', ')))\n"
    "  end\n"
    "end\n"
    "for _, k in ipairs{'load', 'update', 'contact', 'report'} do\n"
    "  if scene[k] ~= nil and type(scene[k]) ~= 'function' then\n"
    "    fail(opts.scene .. ': scene.' .. k .. ' must be a function, got ' .. type(scene[k]))\n"
    "  end\n"
    "end\n"
    "if scene.world ~= nil and type(scene.world) ~= 'table' then fail(opts.scene .. ': scene.world must be a table of world options') end\n"
    "local function positive_number(v, what, integer)\n"
    "  if v == nil then return nil end\n"
    "  if type(v) ~= 'number' or v ~= v or v <= 0 or v == math.huge or (integer and v % 1 ~= 0) then\n"
    "    fail(opts.scene .. ': scene.' .. what .. ' must be a positive ' .. (integer and 'integer' or 'number'))\n"
    "  end\n"
    "  return v\n"
    "end\n"
    "local wopts = {}\n"
    "for k, v in pairs(scene.world or {}) do wopts[k] = v end\n"
    "if opts.substeps then wopts.substeps = opts.substeps end\n"
    "if opts.threads then wopts.threads = opts.threads end\n"
    "local made, world = pcall(carom.world, wopts)\n"
    "if not made then\n"
    "  local why = tostring(world):gsub('^bad argument #1 to \\'[%w.]*\\' %((.*)%)$', '%1')\n"
    "  fail(opts.scene .. ': scene.world: ' .. why)\n"
    "end\n"
    "local dt = opts.dt or positive_number(scene.dt, 'dt') or 1/60\n"
    "if dt > 1 then fail(opts.scene .. ': scene.dt must be at most 1 s') end\n"
    "local function steps_in(seconds) return math.max(1, math.floor(seconds / dt + 0.5)) end\n"
    "local steps = opts.steps or (opts.seconds and steps_in(opts.seconds))\n"
    "  or positive_number(scene.steps, 'steps', true)\n"
    "  or (positive_number(scene.seconds, 'seconds') and steps_in(scene.seconds)) or 600\n"
    "steps = math.tointeger(steps)\n"
    "local rec\n"
    "if opts.record then\n"
    "  local f, why = io.open(opts.record, 'w')\n"
    "  if not f then fail('cannot write the record file ' .. why) end\n"
    "  rec = f\n"
    "  rec:write('step,t,body,x,y,z,qw,qx,qy,qz\\n')\n"
    "end\n"
    "if scene.contact then world:set_contact_callback(scene.contact) end\n"
    "if scene.load then scene.load(world) end\n"
    "local fmt = '%d,%.9g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\\n'\n"
    "local function record(s)\n"
    "  for _, b in ipairs(world:bodies()) do\n"
    "    local x, y, z = b:position()\n"
    "    local qw, qx, qy, qz = b:orientation()\n"
    "    rec:write(string.format(fmt, s, s * dt, b:id(), x, y, z, qw, qx, qy, qz))\n"
    "  end\n"
    "end\n"
    "if rec then record(0) end\n"
    ;

/* (two strings: C99 compilers need only support literals of 4095 characters) */
static const char driver_loop[] =
    "local clock = carom.clock\n"
    "local window = math.max(1, steps // 50)\n"
    "local windows, wstart = {}, clock()\n"
    "local t0 = clock()\n"
    "local last_print = t0\n"
    "local update = scene.update\n"
    "for s = 1, steps do\n"
    "  if update then update(world, dt) end\n"
    "  world:step(dt)\n"
    "  if rec then record(s) end\n"
    "  if s % window == 0 then\n"
    "    local now = clock()\n"
    "    windows[#windows + 1] = (now - wstart) * 1000 / window\n"
    "    wstart = now\n"
    "  end\n"
    "  if not opts.quiet and s < steps and clock() - last_print >= 2 then\n"
    "    last_print = clock()\n"
    "    io.stderr:write(string.format('carom-run: step %d of %d (%.0f%%), %.3f ms/step\\n', s, steps, 100 * s / steps,\n"
    "      (last_print - t0) * 1000 / s))\n"
    "  end\n"
    "end\n"
    "local wall = clock() - t0\n"
    "if rec then rec:close() end\n"
    "if scene.report then scene.report(world) end\n"
    "if opts.bench then\n"
    "  table.sort(windows)\n"
    "  local median = #windows > 0 and windows[(#windows + 1) // 2] or wall * 1000 / steps\n"
    "  local st = world:stats()\n"
    "  local ke, pe = world:energy()\n"
    "  local px, py, pz, lx, ly, lz = world:momentum()\n"
    "  print(string.format('bench: %d steps of %.6g s: %.4f ms/step (median of %d windows of %d steps), %.3f s in all',\n"
    "    steps, dt, median, #windows, window, wall))\n"
    "  print(string.format('bench: stages (last step, ms): broadphase %.4f narrowphase %.4f solver %.4f continuous %.4f islands %.4f',\n"
    "    st.ms_broadphase, st.ms_narrowphase, st.ms_solver, st.ms_continuous, st.ms_islands))\n"
    "  print(string.format('probes: bodies %d (awake %d), contacts %d (%d points), max penetration %.6f m (now %.6f m)',\n"
    "    st.bodies, st.awake_bodies, st.contacts, st.contact_points, st.max_penetration, world:measure_penetration()))\n"
    "  print(string.format('probes: kinetic energy %.9g J, potential energy %.9g J, total %.9g J', ke, pe, ke + pe))\n"
    "  print(string.format('probes: momentum (%.6g, %.6g, %.6g) kg m/s, angular momentum (%.6g, %.6g, %.6g) kg m^2/s',\n"
    "    px, py, pz, lx, ly, lz))\n"
    "end\n";

static void usage(FILE *f)
{
    fprintf(f, "usage: carom-run scene.lua [--steps N | --seconds S] [--dt DT] [--substeps K] [--threads N]\n"
               "                           [--bench] [--record FILE.csv] [--quiet]\n"
               "       carom-run --test script.lua | --version | --help\n"
               "  --steps N      run N steps (default: the scene's `steps`, else 600)\n"
               "  --seconds S    run S seconds of simulated time\n"
               "  --dt DT        the fixed step in seconds, 0 < DT <= 1 (default: the scene's `dt`, else 1/60)\n"
               "  --substeps K   sub-steps per step, 1..64 (overrides the scene's world options)\n"
               "  --threads N    step on N threads, 1..64 (the reference pool; same results)\n"
               "  --bench        print the median ms/step and the accuracy probes at the end\n"
               "  --record FILE  write every body's pose after every step as CSV\n"
               "                 (step,t,body,x,y,z,qw,qx,qy,qz)\n"
               "  --quiet        no progress lines\n"
               "  --test FILE    run a test script (exit status 1 if it fails)\n"
               "  --version      print the version\n"
               "exit status: 0 success, 1 the scene or script failed, 2 bad command line\n");
}

static int bad_usage(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "carom-run: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(carom-run --help for usage)\n");
    va_end(ap);
    return 2;
}

/* Errors the runner raises about the scene file (a table {runner_message =
 * "..."}) print as one line; a message that carries its own traceback (a
 * contact callback's, taken where it failed) gets no second one. */
static int message_handler(lua_State *L)
{
    if (lua_istable(L, 1) && lua_getfield(L, 1, "runner_message") == LUA_TSTRING) return 1;
    const char *msg = lua_tostring(L, 1);
    if (msg && strstr(msg, "\nstack traceback:")) return 1;
    if (!msg) {
        if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) msg = lua_tostring(L, -1);
        else msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    }
    luaL_traceback(L, L, msg, 1);
    return 1;
}

/* A whole-string number; 0 if s is not one. */
static int parse_number(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end != '\0' || !isfinite(v)) return 0;
    *out = v;
    return 1;
}

/* Sets the global `arg` as the standalone interpreter does. */
static void set_arg(lua_State *L, const char *program, const char *script)
{
    lua_createtable(L, 1, 1);
    lua_pushstring(L, program);
    lua_rawseti(L, -2, -1);
    lua_pushstring(L, script);
    lua_rawseti(L, -2, 0);
    lua_setglobal(L, "arg");
}

int main(int argc, char **argv)
{
    const char *scene = NULL, *record = NULL, *test = NULL;
    /* NAN: not given on the command line */
    double steps = NAN, seconds = NAN, dt = NAN, substeps = NAN, threads = NAN;
    int bench = 0, quiet = 0, scene_options = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        double *target = NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "--version")) {
            printf("carom-run %s\n", carom_version());
            return 0;
        } else if (!strcmp(a, "--steps")) target = &steps;
        else if (!strcmp(a, "--seconds")) target = &seconds;
        else if (!strcmp(a, "--dt")) target = &dt;
        else if (!strcmp(a, "--substeps")) target = &substeps;
        else if (!strcmp(a, "--threads")) target = &threads;
        else if (!strcmp(a, "--bench")) {
            bench = scene_options = 1;
            continue;
        } else if (!strcmp(a, "--quiet")) {
            quiet = 1;
            continue;
        } else if (!strcmp(a, "--record") || !strcmp(a, "--test")) {
            if (i + 1 >= argc || argv[i + 1][0] == '\0') return bad_usage("%s needs a file name", a);
            if (!strcmp(a, "--record")) {
                if (record) return bad_usage("%s given twice", a);
                record = argv[++i];
                scene_options = 1;
            } else {
                if (test) return bad_usage("%s given twice", a);
                test = argv[++i];
            }
            continue;
        } else if (a[0] == '-' && a[1] != '\0') {
            return bad_usage("unknown option %s", a);
        } else if (!scene) {
            scene = a;
            continue;
        } else {
            return bad_usage("one scene at a time (got a second: %s)", a);
        }
        if (!isnan(*target)) return bad_usage("%s given twice", a);
        if (i + 1 >= argc) return bad_usage("%s needs a number", a);
        if (!parse_number(argv[i + 1], target)) return bad_usage("%s needs a number, got '%s'", a, argv[i + 1]);
        i++;
        scene_options = 1;
    }
    if (test && (scene || scene_options)) return bad_usage("--test runs a script plainly: give no scene and no scene options with it");
    if (!test && !scene) {
        usage(stderr);
        return 2;
    }
    if (!isnan(steps) && !isnan(seconds)) return bad_usage("give --steps or --seconds, not both");
    if (!isnan(steps) && !(steps >= 1 && steps <= 1e9 && steps == floor(steps)))
        return bad_usage("--steps must be a whole number from 1 to 1e9");
    if (!isnan(seconds) && !(seconds > 0 && seconds <= 1e7)) return bad_usage("--seconds must be positive (at most 1e7)");
    if (!isnan(dt) && !(dt > 0 && dt <= 1)) return bad_usage("--dt must be in (0, 1] seconds");
    if (!isnan(seconds) && seconds / (isnan(dt) ? 1.0 / 60.0 : dt) > 1e9) return bad_usage("--seconds / --dt is more than 1e9 steps");
    if (!isnan(substeps) && !(substeps >= 1 && substeps <= 64 && substeps == floor(substeps)))
        return bad_usage("--substeps must be a whole number from 1 to 64");
    if (!isnan(threads) && !(threads >= 1 && threads <= 64 && threads == floor(threads)))
        return bad_usage("--threads must be a whole number from 1 to 64");

    lua_State *L = luaL_newstate();
    if (!L) {
        fprintf(stderr, "carom-run: cannot create a Lua state (out of memory)\n");
        return 1;
    }
    luaL_openlibs(L);
    luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
    lua_pushcfunction(L, luaopen_carom);
    lua_setfield(L, -2, "carom");
    lua_pop(L, 1);
    set_arg(L, argv[0], test ? test : scene);
    lua_pushcfunction(L, message_handler);
    int status;
    if (test) {
        status = luaL_loadfile(L, test);
        if (status == LUA_OK) status = lua_pcall(L, 0, 0, 1);
    } else {
        luaL_Buffer code;
        luaL_buffinit(L, &code);
        luaL_addstring(&code, driver_setup);
        luaL_addstring(&code, driver_loop);
        luaL_pushresult(&code);
        size_t length;
        const char *text = lua_tolstring(L, -1, &length);
        status = luaL_loadbuffer(L, text, length, "=carom-run");
        lua_remove(L, -2); /* the source text */
        if (status == LUA_OK) {
            lua_createtable(L, 0, 8);
            lua_pushstring(L, scene);
            lua_setfield(L, -2, "scene");
            if (record) {
                lua_pushstring(L, record);
                lua_setfield(L, -2, "record");
            }
            if (!isnan(steps)) {
                lua_pushinteger(L, (lua_Integer)steps);
                lua_setfield(L, -2, "steps");
            }
            if (!isnan(seconds)) {
                lua_pushnumber(L, seconds);
                lua_setfield(L, -2, "seconds");
            }
            if (!isnan(dt)) {
                lua_pushnumber(L, dt);
                lua_setfield(L, -2, "dt");
            }
            if (!isnan(substeps)) {
                lua_pushinteger(L, (lua_Integer)substeps);
                lua_setfield(L, -2, "substeps");
            }
            if (!isnan(threads)) {
                lua_pushinteger(L, (lua_Integer)threads);
                lua_setfield(L, -2, "threads");
            }
            lua_pushboolean(L, bench);
            lua_setfield(L, -2, "bench");
            lua_pushboolean(L, quiet);
            lua_setfield(L, -2, "quiet");
            status = lua_pcall(L, 1, 0, 1);
        }
    }
    if (status != LUA_OK) {
        const char *msg = lua_tostring(L, -1);
        fflush(stdout);
        fprintf(stderr, "carom-run: %s\n", msg ? msg : "(error object is not a string)");
    }
    lua_close(L);
    return status == LUA_OK ? 0 : 1;
}
