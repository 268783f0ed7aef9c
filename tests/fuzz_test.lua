-- fuzz_test.lua - 10,000 random calls into the carom module with random,
-- often invalid, arguments (wrong types, NaN, inf, huge and negative numbers,
-- destroyed bodies, destroyed worlds, callbacks that throw, mutate, step or
-- destroy). Each call runs under pcall and must end in success or a Lua error
-- with a string message, never a crash; `make check` runs this under ASan and
-- UBSan too. Afterwards every surviving world and body must still be usable
-- and finite. Fixed seed; the failing call is printed with its number.
local carom = require "carom"
-- CAROM_FUZZ_SEED and CAROM_FUZZ_CALLS override the defaults for longer hunts.
local SEED = math.tointeger(tonumber(os.getenv("CAROM_FUZZ_SEED") or "")) or 20261122
local CALLS = math.tointeger(tonumber(os.getenv("CAROM_FUZZ_CALLS") or "")) or 10000

-- a local xorshift generator, so the sequence is the same on every Lua 5.4
local state = SEED & 0xffffffff
if state == 0 then state = 1 end
local function rand() -- [0, 1)
  state = state ~ (state << 13) & 0xffffffff
  state = state ~ (state >> 17)
  state = state ~ (state << 5) & 0xffffffff
  return state / 4294967296
end
local function R(a, b) -- integer in [a, b], or [1, a]
  if not b then a, b = 1, a end
  return a + math.floor(rand() * (b - a + 1))
end
local function pick(t) return t[R(#t)] end

local specials = { 0, -0.0, -1, 1, 0.5, -0.5, 1e308, -1e308, 1 / 0, -1 / 0, 0 / 0, 1e-300, 3, 42, 1e9, -7, 2 ^ 53, 0.1 }
local function rnum()
  if rand() < 0.5 then return pick(specials) end
  return (rand() - 0.5) * 10 ^ R(-3, 3)
end
local function rvec()
  local r = rand()
  if r < 0.05 then return { rnum(), "x" } end
  if r < 0.1 then return { rnum() } end
  if r < 0.15 then return { x = rnum(), y = rnum(), z = rnum() } end
  if r < 0.6 then return { (rand() - 0.5) * 20, (rand() - 0.5) * 20, rand() * 10 } end
  return { rnum(), rnum(), rnum() }
end

local worlds, bodies, shapes = {}, {}, {}
local junk = { "junk", true, false, {}, function() end, coroutine.create(function() end), tostring }

local function rany()
  local k = R(10)
  if k == 1 then return rnum()
  elseif k == 2 then return rvec()
  elseif k == 3 then return pick(junk)
  elseif k == 4 then return nil
  elseif k == 5 then return bodies[R(math.max(#bodies, 1))]
  elseif k == 6 then return worlds[R(math.max(#worlds, 1))]
  elseif k == 7 then return shapes[R(math.max(#shapes, 1))]
  elseif k == 8 then return pick{ "static", "kinematic", "dynamic", "sphere", "", "impulse" }
  elseif k == 9 then return R(-2, 5)
  end
  return rand() < 0.5
end

local shape_makers = { "sphere", "box", "capsule", "cylinder", "hull", "plane" }
local function matching_args(maker)
  local function size() return rand() < 0.8 and 0.05 + rand() or rnum() end
  if maker == "sphere" then return { radius = size() }
  elseif maker == "box" then return { half_extents = rand() < 0.8 and { size(), size(), size() } or rvec() }
  elseif maker == "capsule" or maker == "cylinder" then return { size(), size() }
  elseif maker == "plane" then return { normal = rand() < 0.8 and { 0, 0, 1 } or rvec(), offset = rand() < 0.8 and 0 or rnum() }
  end
  local pts = {}
  for i = 1, R(3, 12) do pts[i] = rand() < 0.95 and { rand(), rand(), rand() } or rvec() end
  return { points = pts }
end

local function rshape_args(maker)
  if rand() < 0.6 then return matching_args(maker) end
  local k = R(8)
  if k == 1 then return { radius = rnum(), half_height = rnum() }
  elseif k == 2 then return { half_extents = rvec() }
  elseif k == 3 then
    local pts = {}
    for i = 1, R(0, 10) do pts[i] = rand() < 0.9 and { rand(), rand(), rand() } or rvec() end
    return rand() < 0.5 and { points = pts } or pts
  elseif k == 4 then return { normal = rvec(), offset = rnum() }
  elseif k == 5 then return { rnum(), rnum() }
  elseif k == 6 then
    local key = rany()
    if key == nil or key ~= key then key = 1 end -- nil and NaN cannot be table keys
    return { [key] = rany() }
  elseif k == 7 then return rany()
  end
  return { radius = rand() + 0.05, half_height = rand() + 0.05, half_extents = { rand() + 0.05, rand() + 0.05, rand() + 0.05 } }
end

local world_keys = { "gravity", "substeps", "iterations", "relax_iterations", "ccd", "sleep", "friction",
                     "restitution", "contact_model", "preset", "hertz", "damping_ratio", "warm_starting",
                     "position_correction", "shock_propagation", "restitution_threshold", "dt", "max_steps",
                     "penalty_stiffness", "linear_slop", "speculative_distance", "bogus" }
local body_keys = { "type", "shape", "position", "velocity", "orientation", "angular_velocity", "mass", "density",
                    "restitution", "friction", "bullet", "lock_rotation", "lock_to_plane", "plane_normal",
                    "gravity_scale", "damping", "linear_damping", "angular_damping", "sleep", "awake", "user_data",
                    "data", "colour" }
local world_methods = { "add_body", "step", "advance", "energy", "momentum", "events", "stats", "ray_cast",
                        "query_aabb", "bodies", "body_count", "configure", "settings", "set_contact_callback",
                        "measure_penetration", "is_valid", "destroy" }
local body_methods = { "position", "velocity", "angular_velocity", "orientation", "center_of_mass", "local_center",
                       "set_position", "set_velocity", "set_angular_velocity", "set_orientation", "apply_impulse",
                       "apply_force", "mass", "set_mass", "inertia", "kinetic_energy", "friction", "set_friction",
                       "restitution", "set_restitution", "set_gravity_scale", "set_bullet", "type", "set_type",
                       "shape_type", "is_awake", "set_awake", "data", "set_data", "is_valid", "id", "destroy" }

local function world_options()
  local opts = {}
  for _ = 1, R(0, 4) do
    local k = pick(world_keys)
    local r = rand()
    if k == "substeps" or k == "iterations" or k == "relax_iterations" or k == "max_steps" then opts[k] = R(-1, 6)
    elseif k == "preset" then opts[k] = pick{ "fast", "default", "accurate", "bogus" }
    elseif k == "contact_model" then opts[k] = pick{ "impulse", "penalty", 7 }
    elseif k == "position_correction" then opts[k] = pick{ "soft", "baumgarte", "none", "hard" }
    elseif r < 0.3 then opts[k] = rand() < 0.5
    elseif r < 0.6 then opts[k] = rnum()
    else opts[k] = rany() end
  end
  return opts
end

local function body_def()
  local def = { shape = rand() < 0.85 and shapes[R(math.max(#shapes, 1))] or rany() }
  for _ = 1, R(0, 5) do
    local k = pick(body_keys)
    local r = rand()
    if k == "position" or k == "velocity" or k == "angular_velocity" or k == "plane_normal" then def[k] = rvec()
    elseif k == "orientation" then def[k] = rand() < 0.5 and { 1, 0, 0, 0 } or { rnum(), rnum(), rnum(), rnum() }
    elseif k == "type" then def[k] = pick{ "static", "kinematic", "dynamic", "ghost" }
    elseif r < 0.5 then def[k] = rnum()
    elseif r < 0.7 then def[k] = rand() < 0.5
    else def[k] = rany() end
  end
  return def
end

-- a callback that does something random, often something forbidden
local function random_callback(w)
  local mode = R(8)
  return function(e)
    local r = rand()
    if mode == 1 and r < 0.3 then error("fuzz callback error") end
    if mode == 2 and r < 0.2 then error(setmetatable({}, { __tostring = function() return "table error" end })) end
    if mode == 3 and #bodies > 0 then local b = pick(bodies); pcall(b.destroy, b) end
    if mode == 4 then pcall(w.add_body, w, { shape = carom.sphere{ radius = 1 } }) end
    if mode == 5 then pcall(w.step, w, 1 / 60) end
    if mode == 6 then pcall(w.destroy, w) end
    if mode == 7 and e.a then pcall(e.a.set_velocity, e.a, rnum(), rnum(), rnum()); local _ = tostring(e.b) end
    if mode == 8 then collectgarbage("collect") end -- finalizers run inside world:step
  end
end

-- Script code that runs at awkward moments: finalizers and metamethods on
-- argument tables (which the bindings must never call). The automatic
-- collector is stopped so that finalizers run only at the explicit full
-- collections below (between calls, and inside contact callbacks, i.e. inside
-- world:step): an incremental collector's timing depends on memory addresses,
-- and the run must be the same every time. (carom_lua_test.lua lets finalizers
-- run at arbitrary allocations inside calls.)
local function hostile_action(w, b)
  local action = R(10)
  return function()
    if action == 1 and w then pcall(w.destroy, w)
    elseif action == 2 and w then pcall(w.step, w, 1 / 60)
    elseif action == 3 and b then pcall(b.destroy, b)
    elseif action == 4 and w then pcall(w.add_body, w, { shape = carom.sphere{ radius = 0.5 } })
    elseif action == 5 and b then pcall(b.set_position, b, 1, 2, 3) end
  end
end
local function hostile_garbage()
  for _ = 1, R(3) do
    setmetatable({}, { __gc = hostile_action(worlds[R(math.max(#worlds, 1))], bodies[R(math.max(#bodies, 1))]) })
  end
end
local function hostile_table(t)
  local act = hostile_action(worlds[R(math.max(#worlds, 1))], bodies[R(math.max(#bodies, 1))])
  return setmetatable(t, { __index = function() act(); return 1 end, __len = function() act(); return 3 end,
                           __newindex = function() act() end, __pairs = function() act(); return next, {}, nil end })
end

local ok_calls, error_calls, bad_errors = 0, 0, 0
local call_number = 0
local function try(what, f, ...)
  call_number = call_number + 1
  local ok, err = pcall(f, ...)
  if ok then ok_calls = ok_calls + 1
  elseif type(err) == "string" then error_calls = error_calls + 1
  elseif type(err) == "table" and tostring(err) == "table error" then
    error_calls = error_calls + 1 -- a callback's thrown table arrives as itself
  else
    bad_errors = bad_errors + 1
    print(string.format("call %d (%s): the error is a %s, not a message", call_number, what, type(err)))
  end
  return ok, err
end

local function keep(list, v, limit)
  list[#list + 1] = v
  if #list > limit then table.remove(list, R(#list)) end
end

local iteration = 0
collectgarbage("stop")
while call_number < CALLS do
  iteration = iteration + 1
  local op = R(22)
  -- mostly live worlds (a destroyed one stays until it is drawn here)
  local wi = R(math.max(#worlds, 1))
  if worlds[wi] and not worlds[wi]:is_valid() and rand() < 0.9 then table.remove(worlds, wi) end
  local bi = R(math.max(#bodies, 1))
  if bodies[bi] and not bodies[bi]:is_valid() and rand() < 0.7 then table.remove(bodies, bi) end
  if rand() < 0.05 then hostile_garbage() end
  if op == 1 or #worlds == 0 then
    local ok, w = try("world", carom.world, rand() < 0.9 and world_options() or rany())
    if ok then keep(worlds, w, 6) end
  elseif op <= 4 then
    local maker = pick(shape_makers)
    local ok, s = try(maker, carom[maker], rshape_args(maker))
    if ok then keep(shapes, s, 40) end
  elseif op <= 8 then
    local w = pick(worlds)
    local ok, b = try("add_body", w.add_body, w, rand() < 0.9 and body_def() or rany())
    if ok then keep(bodies, b, 250) end
  elseif op <= 13 and #bodies > 0 then
    local b = pick(bodies)
    local m = pick(body_methods)
    local f = b[m]
    if m == "destroy" and rand() < 0.7 then f = b.position end
    try(m, f, rand() < 0.95 and b or rany(), rany(), rany(), rany(), rany(), rany(), rany())
  elseif op == 14 and #bodies > 0 then
    local b = pick(bodies)
    local k = R(5)
    if k == 1 then try("user_data", function() b.user_data = rany(); return b.user_data end)
    elseif k == 2 then try("tostring", tostring, b)
    elseif k == 3 then try("__eq", function() return b == pick(bodies) end)
    elseif k == 4 then try("newindex", function() b[rany() or "x"] = 1 end)
    else try("__close", function() local closing <close> = b end) end
  elseif op == 15 then
    local w = pick(worlds)
    if rand() < 0.5 then try("set_contact_callback", w.set_contact_callback, w, random_callback(w)) end
    local n = rand() < 0.9 and R(1, 3) or rany()
    if type(n) == "number" and n > 10 then n = 10 end -- the fuzz is about arguments, not run time
    try("step", w.step, w, rand() < 0.9 and 1 / 60 or rany(), n)
  elseif op == 16 then
    local w = pick(worlds)
    local frame = rand() < 0.8 and rand() * 0.1 or rany()
    try("advance", w.advance, w, frame)
  elseif op == 17 then
    local w = pick(worlds)
    try("coroutine step", function()
      local co = coroutine.create(function() w:set_contact_callback(function() coroutine.yield() end); w:step(1 / 60) end)
      local ok, err = coroutine.resume(co)
      w:set_contact_callback(nil)
      if not ok then error(err, 0) end
    end)
  elseif op >= 21 then
    local w = pick(worlds)
    local k = R(4)
    if k == 1 then
      local ok, b = try("add_body (hostile table)", w.add_body, w, hostile_table(body_def()))
      if ok then keep(bodies, b, 250) end
    elseif k == 2 then try("configure (hostile table)", w.configure, w, hostile_table(world_options()))
    elseif k == 3 and #bodies > 0 then
      local b = pick(bodies)
      try("set_velocity (hostile vector)", b.set_velocity, b, hostile_table({}))
    else try("hull (hostile points)", carom.hull, hostile_table({ points = hostile_table({}) })) end
  else
    local w = pick(worlds)
    local m = pick(world_methods)
    if m == "destroy" and rand() < 0.9 then m = "stats" end
    if m == "step" or m == "advance" then m = "energy" end
    if m == "configure" and rand() < 0.8 then
      try(m, w.configure, w, world_options())
    else
      try(m, w[m], rand() < 0.95 and w or rany(), rany(), rany(), rany(), rany(), rany(), rany())
    end
  end
  if iteration % 50 == 0 then collectgarbage("collect") end
end

collectgarbage("restart")
print(string.format("fuzz (seed %d): %d calls, %d succeeded, %d raised Lua errors", SEED, call_number, ok_calls, error_calls))

local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local check = T.check
local function finite(...)
  for i = 1, select("#", ...) do
    local v = select(i, ...)
    if type(v) ~= "number" or v ~= v or v == math.huge or v == -math.huge then return false end
  end
  return true
end

check(ok_calls + error_calls == call_number and bad_errors == 0, "every call ended in success or an error message")
check(ok_calls > 1000 and error_calls > 1000, "the fuzz exercised both paths")
-- every surviving world steps on, and every surviving body is finite
for wi, w in ipairs(worlds) do
  if w:is_valid() then
    w:set_contact_callback(nil)
    check(pcall(w.step, w, 1 / 60), "world " .. wi .. " steps after the fuzz")
    local st = w:stats()
    check(st.bodies == w:body_count() and st.bodies == #w:bodies(), "world " .. wi .. " body counts agree")
    -- (energy and momentum may overflow to inf with the fuzz's huge masses, so only their types are checked)
    check(select("#", w:energy()) == 2 and select("#", w:momentum()) == 6, "world " .. wi .. " probes answer")
  end
end
for bi, b in ipairs(bodies) do
  if b:is_valid() then
    check(finite(b:position()) and finite(b:orientation()) and finite(b:velocity()) and finite(b:angular_velocity()),
          "body " .. bi .. " (" .. tostring(b) .. ") is finite")
  else
    check(not pcall(b.position, b), "destroyed body " .. bi .. " raises")
  end
end
worlds, bodies, shapes = nil, nil, nil
collectgarbage("collect")
T.finish()
