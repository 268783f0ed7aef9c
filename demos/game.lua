-- game.lua - a small game level: balls launched from below pass up through a
-- one-way platform and land on it (which feels their weight through force
-- events), crates fall into a trigger zone that counts them, a kinematic
-- paddle sweeps balls along the floor, and a ray gun knocks crates out of
-- the zone. Runs headless and prints what happened (tests/game_demo_test.lua
-- checks it).
-- carom-run demos/game.lua
local carom = require "carom"
local M = { steps = 480 } -- 8 s at 60 Hz

local G = 9.81
local ball_shape = carom.sphere{ radius = 0.2 }
local crate_shape = carom.box{ half_extents = {0.3, 0.3, 0.3} }
local log = {
  launched = {}, zone_entries = 0, zone_exits = 0, inside = 0, most_inside = 0,
  paddle_hits = 0, shots = 0, hits = 0, platform_force = 0,
}

local platform, zone, paddle
local names = {}
local function named(body, name) names[body] = name; return body end
local function name_of(body) return names[body] or tostring(body) end

function M.load(world)
  world:add_body{ type = "static", shape = carom.box{ half_extents = {20, 5, 0.5} }, position = {0, 0, -0.5} }
  -- the one-way platform: solid from above only
  platform = named(world:add_body{ type = "static", shape = carom.box{ half_extents = {2, 2, 0.1} },
                                     position = {0, 0, 3}, force_threshold = 0.1 }, "platform")
  world:set_pre_solve(function(a, b)
    if a ~= platform and b ~= platform then return true end
    local other = a == platform and b or a
    local _, _, vz = other:velocity()
    local _, _, z = other:position()
    return vz <= 0 and z - 0.2 >= 3.1 - 0.05 -- falling onto its top: solid; else pass through
  end)
  -- the trigger zone (a sensor: no response, just sensor_begin / sensor_end)
  zone = named(world:add_body{ type = "static", sensor = true, shape = carom.box{ half_extents = {1.5, 2, 1} },
                                 position = {6, 0, 1} }, "zone")
  -- the paddle, swept to and fro along x by update()
  paddle = named(world:add_body{ type = "kinematic", shape = carom.box{ half_extents = {0.2, 1.5, 0.5} },
                                   position = {-9, 0, 0.5} }, "paddle")
  -- balls on the floor in the paddle's way
  for i = 1, 3 do
    named(world:add_body{ shape = ball_shape, position = {-7 + 1.2 * i, 0, 0.2} }, "floor ball " .. i)
  end
  -- a stack of crates dropped into the zone
  for i = 1, 3 do
    named(world:add_body{ shape = crate_shape, mass = 5, position = {6, 0, 0.4 + 0.65 * i} }, "crate " .. i)
  end
end

local t = 0
local next_launch, next_shot = 0.25, 2.5
function M.update(world, dt)
  t = t + dt
  -- launch a ball straight up from under the platform every 0.5 s for 2 s
  if t >= next_launch and #log.launched < 4 then
    next_launch = next_launch + 0.5
    local x = -1.2 + 0.8 * #log.launched
    local b = named(world:add_body{ shape = ball_shape, mass = 1, position = {x, 0, 0.3}, velocity = {0, 0, 9},
                                    sleep = false }, -- awake, so the platform keeps reporting their weight
                    "launched ball " .. (#log.launched + 1))
    log.launched[#log.launched + 1] = b
  end
  -- the paddle: 4 m/s, turning every 1.5 s
  local dir = (math.floor(t / 1.5) % 2 == 0) and 1 or -1
  paddle:set_velocity(4 * dir, 0, 0)
  -- the ray gun at the side of the zone fires across it (-y) every second from t = 2.5 s
  if t >= next_shot then
    next_shot = next_shot + 1
    log.shots = log.shots + 1
    local body, point = world:ray_cast({6, 4.5, 0.3}, {0, -9, 0}) -- (queries do not see the sensor)
    if body and body:type() == "dynamic" then
      log.hits = log.hits + 1
      body:apply_impulse({0, -30, 0}, point)
      print(string.format("  t = %.2f s: the gun hits %s at (%.2f, %.2f, %.2f)", t, name_of(body), point[1], point[2],
                          point[3]))
    else
      print(string.format("  t = %.2f s: the gun misses", t))
    end
  end
end

function M.contact(e)
  if e.type == "sensor_begin" and e.sensor == zone then
    log.zone_entries = log.zone_entries + 1
    log.inside = log.inside + 1
    if log.inside > log.most_inside then log.most_inside = log.inside end
  elseif e.type == "sensor_end" and e.sensor == zone then
    log.zone_exits = log.zone_exits + 1
    log.inside = log.inside - 1
  elseif e.type == "begin" and (e.a == paddle or e.b == paddle) then
    local other = e.a == paddle and e.b or e.a
    if other:type() == "dynamic" then log.paddle_hits = log.paddle_hits + 1 end
  elseif e.type == "force" and (e.a == platform or e.b == platform) then
    log.platform_force = log.platform_force + e.force -- summed over this step's pairs; reset below
  end
end

function M.report(world)
  -- one more step, to read the platform's load from this step's force events alone
  log.platform_force = 0
  world:step(1/60)
  local on_platform = 0
  for _, b in ipairs(log.launched) do
    local _, _, z = b:position()
    if math.abs(z - (3.1 + 0.2)) < 0.02 then on_platform = on_platform + 1 end
  end
  log.on_platform = on_platform
  local weight = on_platform * 1 * G
  print(string.format("one-way platform: %d of %d balls launched from below went up through it and rest on it",
                      on_platform, #log.launched))
  print(string.format("  it carries %.2f N (their weight: %.2f N)", log.platform_force, weight))
  print(string.format("trigger zone: %d entries, %d exits, %d inside now (at most %d)", log.zone_entries,
                      log.zone_exits, log.inside, log.most_inside))
  print(string.format("paddle: hit %d balls", log.paddle_hits))
  print(string.format("ray gun: %d shots, %d hits", log.shots, log.hits))
end

return M
