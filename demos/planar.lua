-- planar.lua - the seed's real-time 2D sample simulation: every body is
-- locked to the x-z plane (lock_to_plane), so the 3D engine plays a 2D
-- game: a cue ball breaks a triangle of balls on a tilted table with walls.
local carom = require "carom"
local M = { steps = 300, world = { gravity = {0, 0, 0}, restitution_threshold = 0.05 } }
local balls = {}

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
  local maxy = 0
  for _, b in ipairs(balls) do
    local _, y = b:position()
    maxy = math.max(maxy, math.abs(y))
  end
  local ke = world:energy()
  print(string.format("planar break: %d balls, largest distance from the plane %.2e m, kinetic energy left %.4f J",
                      #balls, maxy, ke))
end

return M
