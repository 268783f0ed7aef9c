-- carom_run_test.lua - carom-run (lua/carom-run.c) from the outside: argument checking and exit
-- statuses, the scene protocol (load, update, contact, report, world, steps,
-- dt), --steps/--seconds/--dt/--substeps, --record's CSV and --bench's lines.
-- Runs the very binary that runs this script (arg[-1]), so `make check` tests
-- the sanitizer build under SAN=1 too. Ends with "N passed, M failed".
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test = T.test
local RUNNER = arg and arg[-1]
assert(RUNNER and RUNNER:find("carom%-run"), "run me with carom-run --test (arg[-1] is the runner)")

local temporaries = {}
local function temp(contents)
  local name = os.tmpname()
  temporaries[#temporaries + 1] = name
  if contents then
    local f = assert(io.open(name, "w"))
    f:write(contents)
    f:close()
  end
  return name
end

local function quote(s) return "'" .. s:gsub("'", "'\\''") .. "'" end

-- runs carom-run with the given argument list; returns exit status, output (stdout and stderr)
local function run(...)
  local parts = { quote(RUNNER) }
  for _, a in ipairs{ ... } do parts[#parts + 1] = quote(a) end
  local out = temp()
  local _, _, code = os.execute(table.concat(parts, " ") .. " >" .. quote(out) .. " 2>&1")
  local f = assert(io.open(out))
  local text = f:read("a")
  f:close()
  return code, text
end

local function expect(code_wanted, text_wanted, ...)
  local code, text = run(...)
  if code ~= code_wanted or not text:find(text_wanted, 1, true) then
    error(string.format("carom-run %s: exit %s (wanted %d), output:\n%s\n(wanted it to contain '%s')",
                        table.concat({ ... }, " "), tostring(code), code_wanted, text, text_wanted), 2)
  end
  return text
end

-- A scene that reports what the runner did with it.
local probe_scene = temp([[
local carom = require "carom"
local M = { steps = 7, world = { gravity = {0, 0, -10}, substeps = 3 } }
local loads, updates, contacts, last_dt = 0, 0, 0, nil
local ball
function M.load(world)
  loads = loads + 1
  world:add_body{ type = "static", shape = carom.plane{} }
  ball = world:add_body{ position = {0, 0, 0.55}, shape = carom.sphere{ radius = 0.5 } }
end
function M.update(world, dt) updates = updates + 1; last_dt = dt end
function M.contact(event) contacts = contacts + 1 end
function M.report(world)
  local s = world:settings()
  local x, y, z = ball:position()
  print(string.format("RESULT loads=%d updates=%d dt=%.17g substeps=%d gz=%g contacts=%d steps=%d z=%.17g",
    loads, updates, last_dt or -1, s.substeps, s.gravity[3], contacts, world:stats().steps, z))
end
return M
]])

local function result(text)
  local r = {}
  local line = text:match("RESULT ([^\n]*)")
  assert(line, "no RESULT line in:\n" .. text)
  for k, v in line:gmatch("(%w+)=(%S+)") do r[k] = tonumber(v) end
  return r
end

test("--help and no arguments", function()
  expect(0, "usage: carom-run scene.lua", "--help")
  expect(2, "usage: carom-run scene.lua")
end)

test("bad command lines exit 2 with a message", function()
  expect(2, "unknown option --fast", probe_scene, "--fast")
  expect(2, "--steps needs a number", probe_scene, "--steps")
  expect(2, "--steps needs a number, got 'many'", probe_scene, "--steps", "many")
  expect(2, "--steps must be a whole number", probe_scene, "--steps", "0")
  expect(2, "--steps must be a whole number", probe_scene, "--steps", "1.5")
  expect(2, "--steps must be a whole number", probe_scene, "--steps", "-3")
  expect(2, "give --steps or --seconds, not both", probe_scene, "--steps", "5", "--seconds", "1")
  expect(2, "--seconds must be positive", probe_scene, "--seconds", "0")
  expect(2, "--dt must be in (0, 1]", probe_scene, "--dt", "2")
  expect(2, "--dt must be in (0, 1]", probe_scene, "--dt", "0")
  expect(2, "--dt needs a number, got 'nan'", probe_scene, "--dt", "nan")
  expect(2, "--substeps must be a whole number from 1 to 64", probe_scene, "--substeps", "0")
  expect(2, "--substeps must be a whole number from 1 to 64", probe_scene, "--substeps", "65")
  expect(2, "--steps given twice", probe_scene, "--steps", "5", "--steps", "6")
  expect(2, "one scene at a time", probe_scene, probe_scene)
  expect(2, "--record needs a file name", probe_scene, "--record")
  expect(2, "--test runs a script plainly", "--test", probe_scene, "--steps", "3")
end)

-- the whole output is one line "carom-run: ...", naming the file
local function one_line(text, file)
  local first = text:match("^[^\n]*\n?")
  assert(first == text, "one line, no traceback:\n" .. text)
  assert(text:find("carom-run: ", 1, true) == 1, "starts with carom-run: " .. text)
  assert(text:find(file, 1, true), "names " .. file .. ": " .. text)
end

test("broken scenes exit 1 with one line naming the file", function()
  one_line(expect(1, "cannot open /nonexistent/scene.lua", "/nonexistent/scene.lua"), "/nonexistent/scene.lua")
  for _, case in ipairs{
    { "a scene must return a table", "return 42" },
    { "scene.update must be a function", "return { update = 5 }" },
    { "scene.world must be a table", "return { world = 'big' }" },
    { "scene.steps must be a positive integer", "return { steps = 2.5 }" },
    -- world options: reported against the scene, not the runner's own code
    { "scene.world: unknown option 'colour'", "return { world = { colour = 1 } }" },
    { "scene.world: gravity must be a vector", "return { world = { gravity = {0, 0, 'x'} } }" },
    { "unexpected symbol", "return {" },
    -- a misspelt key is not ignored
    { 'unknown key "stpes" in the scene table (valid keys: contact, dt, load, report, seconds, steps, update, world)',
      "return { stpes = 10 }" },
    { "unknown key [1] in the scene table", "return { function() end }" },
  } do
    local file = temp(case[2])
    local text = expect(1, case[1], file)
    one_line(text, file)
    assert(not text:find("carom-run:%d"), "no position in the runner's code: " .. text)
  end
  local text = expect(1, "load failed here", temp("return { load = function() error('load failed here') end }"))
  assert(text:find("traceback", 1, true), "with a traceback")
  -- an error in the contact hook surfaces through world:step, with one traceback (the hook's)
  local hook = temp([[
local carom = require "carom"
return { steps = 30,
  load = function(w) w:add_body{ type = "static", shape = carom.plane{} }
                     w:add_body{ position = {0, 0, 0.6}, velocity = {0, 0, -2}, shape = carom.sphere{ radius = 0.5 } } end,
  contact = function(e) error("contact hook failed") end }
]])
  text = expect(1, "contact hook failed", hook)
  local _, tracebacks = text:gsub("stack traceback:", "")
  assert(tracebacks == 1, "one traceback, got " .. tracebacks .. ":\n" .. text)
  assert(text:find(hook .. ":5:", 1, true), "the traceback shows the hook's line: " .. text)
  text = expect(1, "cannot write the record file /nonexistent/dir/out.csv", probe_scene, "--record", "/nonexistent/dir/out.csv")
  one_line(text, "/nonexistent/dir/out.csv")
  assert(not text:find("RESULT", 1, true), "the scene did not run")
end)

test("--version prints the library's version", function()
  local text = expect(0, "carom-run ", "--version")
  assert(text == "carom-run " .. require("carom").version .. "\n", text)
  assert(text:match("^carom%-run %d+%.%d+%.%d+\n$"), text)
end)

test("the scene protocol: load once, update and step per step, contact per event, report at the end", function()
  local r = result(expect(0, "RESULT", probe_scene, "--quiet"))
  assert(r.loads == 1 and r.updates == 7 and r.steps == 7, "the scene's own steps (7)")
  assert(r.dt == 1 / 60, "default dt 1/60")
  assert(r.substeps == 3 and r.gz == -10, "the scene's world options")
  assert(r.contacts >= 1, "the contact hook saw the ball land")
end)

test("--steps, --seconds, --dt, --substeps", function()
  local r = result(expect(0, "RESULT", probe_scene, "--steps", "12", "--quiet"))
  assert(r.updates == 12 and r.steps == 12)
  r = result(expect(0, "RESULT", probe_scene, "--seconds", "0.5", "--dt", "0.01", "--quiet"))
  assert(r.steps == 50 and r.dt == 0.01, "0.5 s at 10 ms is 50 steps")
  r = result(expect(0, "RESULT", probe_scene, "--substeps", "9", "--steps", "1"))
  assert(r.substeps == 9, "--substeps overrides the scene")
  r = result(expect(0, "RESULT", temp((io.open(probe_scene):read("a"):gsub("steps = 7, ", ""))), "--quiet"))
  assert(r.steps == 600, "600 steps when neither the scene nor the command line says")
  r = result(expect(0, "RESULT", temp((io.open(probe_scene):read("a"):gsub("steps = 7, ", "seconds = 0.25, "))), "--quiet"))
  assert(r.steps == 15, "the scene's seconds (0.25 s at 1/60 s)")
end)

test("--record writes every body's pose after every step", function()
  local csv = temp()
  local r = result(expect(0, "RESULT", probe_scene, "--record", csv, "--steps", "20", "--quiet"))
  local lines = {}
  for line in io.lines(csv) do lines[#lines + 1] = line end
  assert(lines[1] == "step,t,body,x,y,z,qw,qx,qy,qz", "header: " .. tostring(lines[1]))
  assert(#lines == 1 + 21 * 2, "21 poses (step 0 to 20) of 2 bodies, got " .. (#lines - 1) .. " rows")
  local last = {}
  for v in lines[#lines]:gmatch("[^,]+") do last[#last + 1] = tonumber(v) end
  assert(#last == 10, "10 columns")
  assert(last[1] == 20 and math.abs(last[2] - 20 / 60) < 1e-9 and last[3] == 2, "step, t, body id")
  assert(last[6] == r.z, string.format("the recorded z %.17g is the body's z %.17g", last[6], r.z))
  assert(math.abs(last[7] ^ 2 + last[8] ^ 2 + last[9] ^ 2 + last[10] ^ 2 - 1) < 1e-9, "a unit quaternion")
end)

test("--bench prints the median ms/step and the probes", function()
  local text = expect(0, "ms/step (median of", probe_scene, "--bench", "--steps", "100", "--quiet")
  assert(text:find("probes: bodies 2", 1, true), text)
  assert(text:find("max penetration", 1, true) and text:find("kinetic energy", 1, true) and text:find("momentum", 1, true))
  assert(text:find("RESULT", 1, true), "the scene's report too")
end)

test("--test: exit 0 when the script passes, 1 when it raises or exits 1", function()
  expect(0, "1 passed, 0 failed", "--test", temp("print('1 passed, 0 failed')"))
  expect(1, "bad thing", "--test", temp("error('bad thing')"))
  local code = run("--test", temp("print('0 passed, 1 failed') os.exit(1)"))
  assert(code == 1)
  expect(0, "carom " .. require("carom").version, "--test", temp("print('carom ' .. require('carom').version)"))
end)

test("the module as a shared library: require 'carom' from the stand-alone lua5.4", function()
  local dir = RUNNER:match("^(.*)/[^/]*$") or "."
  local so = dir .. "/lua/carom.so"
  -- how to start lua5.4: make check-lua sets it (under SAN=1 with the ASan runtime preloaded)
  local lua = os.getenv("CAROM_LUA") or "lua5.4"
  local have_lua = os.execute("command -v lua5.4 >/dev/null 2>&1")
  local f = io.open(so)
  if not have_lua or not f then
    if f then f:close() end
    -- make check-lua always builds the module and names lua5.4: a skip there would hide a broken build
    assert(not os.getenv("CAROM_LUA"), "no lua5.4 or no " .. so .. " for this build, under make check")
    print("(skipped: no lua5.4 or no " .. so .. " for this build; run from make check-lua)")
    return
  end
  f:close()
  local script = temp(string.format([[
package.cpath = %q
local carom = require "carom"
local w = carom.world{}
w:add_body{ type = "static", shape = carom.plane{} }
local ball = w:add_body{ position = {0, 0, 1}, shape = carom.sphere{ radius = 0.1 }, mass = 1 }
w:step(1/60, 120)
local _, _, z = ball:position()
print(string.format("module %%s: ball at z = %%.3f", carom.version, z))
]], dir .. "/lua/?.so"))
  local out = temp()
  local _, _, code = os.execute(lua .. " " .. quote(script) .. " >" .. quote(out) .. " 2>&1")
  local text = io.open(out):read("a")
  assert(code == 0 and text:find("module " .. require("carom").version .. ": ball at z = 0.100", 1, true), text)
end)

for _, name in ipairs(temporaries) do os.remove(name) end
T.finish()
