-- fuzz_test.lua - 10,000 random API calls with random, often invalid,
-- arguments. Each must end in success or a Lua error, never a crash (make
-- check also runs this under ASan and UBSan). Fixed seed.
local carom = require "carom"
local seed = 20261122
math.randomseed(seed)
local R = math.random

local specials = { 0, -1, 1, 0.5, -0.5, 1e308, -1e308, 1/0, -1/0, 0/0, 1e-300, 3, 42, 1e9, -7 }
local function rnum() if R() < 0.6 then return specials[R(#specials)] end return (R() - 0.5) * 10 ^ R(-3, 4) end
local function rvec() if R() < 0.1 then return { rnum(), "x" } end return { rnum(), rnum(), rnum() } end
local worlds, bodies, shapes = {}, {}, {}

local function rshape()
  local k = R(7)
  local ok, s
  if k == 1 then ok, s = pcall(carom.sphere, { radius = rnum() })
  elseif k == 2 then ok, s = pcall(carom.box, { half_extents = rvec() })
  elseif k == 3 then ok, s = pcall(carom.capsule, { radius = rnum(), half_height = rnum() })
  elseif k == 4 then ok, s = pcall(carom.cylinder, { radius = rnum(), half_height = rnum() })
  elseif k == 5 then
    local pts = {}
    for i = 1, R(0, 12) do pts[i] = rvec() end
    ok, s = pcall(carom.hull, { points = pts })
  elseif k == 6 then ok, s = pcall(carom.plane, { normal = rvec(), offset = rnum() })
  else ok, s = true, ({ 1, "sphere", {}, false })[R(4)] end
  if ok then shapes[#shapes + 1] = s end
  return s
end

local function rany()
  local k = R(8)
  if k == 1 then return rnum() elseif k == 2 then return rvec() elseif k == 3 then return "junk"
  elseif k == 4 then return nil elseif k == 5 then return bodies[R(math.max(#bodies, 1))]
  elseif k == 6 then return worlds[R(math.max(#worlds, 1))] elseif k == 7 then return true end
  return shapes[R(math.max(#shapes, 1))]
end

local world_methods = { "add_body", "step", "advance", "energy", "momentum", "events", "stats", "ray_cast",
                        "query_aabb", "bodies", "body_count", "configure", "set_contact_callback", "destroy" }
local body_methods = { "position", "velocity", "angular_velocity", "orientation", "set_position", "set_velocity",
                       "set_angular_velocity", "set_orientation", "apply_impulse", "apply_force", "mass", "set_mass",
                       "kinetic_energy", "friction", "set_friction", "restitution", "set_restitution", "type",
                       "set_type", "is_awake", "set_awake", "data", "set_data", "is_valid", "destroy", "id" }

local ok_calls, err_calls = 0, 0
local function try(f, ...)
  local ok = pcall(f, ...)
  if ok then ok_calls = ok_calls + 1 else err_calls = err_calls + 1 end
end

for i = 1, 10000 do
  local op = R(10)
  if op == 1 or #worlds == 0 then
    local opts = {}
    if R() < 0.5 then opts.substeps = R(-1, 9) end
    if R() < 0.3 then opts.gravity = rvec() end
    if R() < 0.2 then opts.preset = ({ "fast", "default", "accurate", "bogus" })[R(4)] end
    if R() < 0.2 then opts.contact_model = ({ "impulse", "penalty", 7 })[R(3)] end
    if R() < 0.1 then opts.weird = 1 end
    local ok, w = pcall(carom.world, opts)
    if ok then worlds[#worlds + 1] = w; ok_calls = ok_calls + 1 else err_calls = err_calls + 1 end
  elseif op <= 4 then
    local w = worlds[R(#worlds)]
    local def = { shape = rshape(), position = R() < 0.8 and { (R() - 0.5) * 20, (R() - 0.5) * 20, R() * 10 } or rvec(),
                  velocity = R() < 0.3 and rvec() or nil, mass = R() < 0.3 and rnum() or nil,
                  type = R() < 0.2 and ({ "static", "kinematic", "dynamic", "x" })[R(4)] or nil,
                  orientation = R() < 0.1 and { rnum(), rnum(), rnum(), rnum() } or nil,
                  restitution = R() < 0.2 and rnum() or nil, friction = R() < 0.2 and rnum() or nil }
    local ok, b = pcall(w.add_body, w, def)
    if ok then bodies[#bodies + 1] = b; ok_calls = ok_calls + 1 else err_calls = err_calls + 1 end
  elseif op <= 6 and #bodies > 0 then
    local b = bodies[R(#bodies)]
    local m = body_methods[R(#body_methods)]
    try(b[m], b, rany(), rany(), rany(), rany())
  elseif op == 7 then
    local w = worlds[R(#worlds)]
    if R() < 0.3 then
      try(w.set_contact_callback, w, function(e)
        if R() < 0.3 then error("fuzz callback error") end
        if R() < 0.3 and #bodies > 0 then pcall(bodies[R(#bodies)].destroy, bodies[R(#bodies)]) end
        if R() < 0.3 then pcall(w.add_body, w, { shape = carom.sphere{ radius = 1 } }) end
      end)
    end
    try(w.step, w, R() < 0.9 and 1/60 or rany(), R() < 0.9 and R(1, 3) or rany())
  else
    local w = worlds[R(#worlds)]
    local m = world_methods[R(#world_methods)]
    if m == "destroy" and R() < 0.7 then m = "stats" end
    if m == "add_body" or m == "step" then m = "events" end
    try(w[m], w, rany(), rany(), rany(), rany(), rany(), rany())
  end
  if i % 2000 == 0 then collectgarbage("collect") end
  if #worlds > 8 then table.remove(worlds, 1) end
  if #bodies > 300 then table.remove(bodies, 1) end
end
collectgarbage("collect")
print(string.format("fuzz (seed %d): %d calls succeeded, %d raised Lua errors, no crash", seed, ok_calls, err_calls))
-- afterwards every surviving body is finite and usable
local passed, failed = 0, 0
for _, b in ipairs(bodies) do
  local ok, valid = pcall(b.is_valid, b)
  if ok and valid then
    local x, y, z = b:position()
    local fine = x == x and y == y and z == z and math.abs(x) < math.huge and math.abs(y) < math.huge and math.abs(z) < math.huge
    if fine then passed = passed + 1 else failed = failed + 1; print("non-finite body " .. tostring(b)) end
  end
end
print(string.format("%d passed, %d failed", passed, failed))
if failed > 0 then os.exit(1) end
