-- planar.lua - the seed's real-time 2D sample simulation: the 3D engine
-- playing a 2D game, every body locked to the x-z plane (lock_to_plane), so
-- it moves in x and z and turns only about y.
--   1. The seed's impulse for rotating rigid bodies (docs/physics.md, section 2) in
--      2D: a puck hits a resting craft (a box) off-centre; the craft leaves
--      moving and turning, checked against the formula.
--   2. A break: a cue ball into a triangle of ten balls inside four walls,
--      seen from above (no gravity), for 5 s.
-- carom-run demos/planar.lua
local carom = require "carom"
local M = { steps = 300, world = { gravity = {0, 0, 0}, restitution_threshold = 0.05 } }
local balls = {}

local function line(what, got, want)
  local ok = math.abs(got - want) <= 1e-6 * math.max(1, math.abs(want))
  print(string.format("  %-34s %10.5f   expected %10.5f   %s", what, got, want, ok and "OK" or "MISMATCH"))
  return ok
end

-- 1. Eccentric impact: puck (mass m1, radius r) at speed v along +x meets
-- the craft's left face (x = -a) at height d above its centre. With r2 the
-- contact point from the craft's centre and n = +x, the seed's formula gives
--   J = (1 + e) v / (1/m1 + 1/m2 + n.((I2^-1 (r2 x n)) x r2)) = (1 + e) v / (1/m1 + 1/m2 + d^2 / Iyy)
-- and then v1+ = v - J/m1, v2+ = J/m2, w2+ = I2^-1 (r2 x J n) = J d / Iyy about y.
local function eccentric_impact()
  local w = carom.world{ gravity = {0, 0, 0}, restitution_threshold = 0, friction = false, sleep = false }
  local a, c, d = 0.5, 1.0, 0.6        -- craft half width and half height; offset of the hit
  local m1, m2, v, e, r = 0.5, 2, 4, 0.8, 0.1
  local craft = w:add_body{ shape = carom.box{ half_extents = {a, 0.25, c} }, mass = m2, restitution = e,
                            friction = 0, lock_to_plane = true, plane_normal = {0, 1, 0} }
  local puck = w:add_body{ position = {-a - r, 0, d}, velocity = {v, 0, 0}, shape = carom.sphere{ radius = r },
                           mass = m1, restitution = e, friction = 0, lock_to_plane = true, plane_normal = {0, 1, 0} }
  local impulse = 0
  w:set_contact_callback(function(ev) if ev.type == "hit" then impulse = ev.impulse end end)
  w:step(1/600)
  local Iyy = m2 / 3 * (a * a + c * c)
  local J = (1 + e) * v / (1 / m1 + 1 / m2 + d * d / Iyy)
  print("1. A puck hits a craft off-centre (e = 0.8, no friction): the seed's rigid-body impulse in 2D")
  local all = true
  all = line("impulse J (N s)", impulse, J) and all
  all = line("puck v+ x (m/s)", (puck:velocity()), v - J / m1) and all
  all = line("craft v+ x (m/s)", (craft:velocity()), J / m2) and all
  all = line("craft spin w+ about y (rad/s)", select(2, craft:angular_velocity()), J * d / Iyy) and all
  local sep = (craft:velocity()) + select(2, craft:angular_velocity()) * d - (puck:velocity())
  all = line("separation speed / approach (e)", sep / v, e) and all
  w:step(1/60, 60)
  local _, y1 = puck:position()
  local _, y2 = craft:position()
  local wx, _, wz = craft:angular_velocity()
  all = line("drift out of the plane in 1 s", math.abs(y1) + math.abs(y2) + math.abs(wx) + math.abs(wz), 0) and all
  return all
end

-- 2. The break.
function M.load(world)
  local walls = { {{0, 0, -0.05}, {1.5, 1, 0.05}}, {{0, 0, 2.05}, {1.5, 1, 0.05}},
                  {{-1.45, 0, 1}, {0.05, 1, 1}}, {{1.45, 0, 1}, {0.05, 1, 1}} }
  for _, w in ipairs(walls) do
    world:add_body{ type = "static", position = w[1], shape = carom.box{ half_extents = w[2] }, restitution = 0.9, friction = 0 }
  end
  local r = 0.05
  local function ball(x, z, vx, vz)
    balls[#balls + 1] = world:add_body{ position = {x, 0, z}, velocity = {vx, 0, vz}, shape = carom.sphere{ radius = r },
                                        mass = 0.17, restitution = 0.95, friction = 0, lock_to_plane = true,
                                        plane_normal = {0, 1, 0}, linear_damping = 0.2 }
  end
  ball(-0.8, 1.0, 3.0, 0.05)
  for row = 0, 3 do
    for k = 0, row do ball(0.3 + row * 0.0867, 1.0 + (k - row / 2) * 0.1, 0, 0) end
  end
end

function M.report(world)
  local ok = eccentric_impact()
  local off_plane, inside, moved = 0, 0, 0
  for i, b in ipairs(balls) do
    local x, y, z = b:position()
    off_plane = math.max(off_plane, math.abs(y))
    if math.abs(x) < 1.4 and z > 0 and z < 2 then inside = inside + 1 end
    if i > 1 and (b:velocity()) ~= 0 then moved = moved + 1 end
  end
  local ke = world:energy()
  print(string.format("2. A break in 2D, %d s: %d of %d balls still on the table, %d of the 10 racked balls set moving,",
                      M.steps // 60, inside, #balls, moved))
  print(string.format("   largest distance from the plane %.1e m, kinetic energy %.4f J of %.4f J at the start",
                      off_plane, ke, 0.5 * 0.17 * (3.0 ^ 2 + 0.05 ^ 2)))
  print(ok and "planar: the 2D impact matches the seed's formula" or "planar: MISMATCH (see above)")
  M.all_match = ok
end

return M
