-- cradle.lua - Newton's cradle without strings: five touching elastic balls,
-- no friction, no gravity, hit by a sixth at 2 m/s. Ideally the last ball
-- leaves at 2 m/s and the rest stand still; sequential impulses spread the
-- momentum over the row instead. Prints both, and that momentum is kept.
local carom = require "carom"
local M = { steps = 90, world = { gravity = {0, 0, 0}, friction = false, restitution_threshold = 0, sleep = false } }
local balls = {}

function M.load(world)
  balls[1] = world:add_body{ position = {-0.6, 0, 0}, velocity = {2, 0, 0}, shape = carom.sphere{ radius = 0.1 }, mass = 1, restitution = 1 }
  for i = 0, 4 do
    balls[#balls + 1] = world:add_body{ position = {0.2 * i, 0, 0}, shape = carom.sphere{ radius = 0.1 }, mass = 1, restitution = 1 }
  end
end

function M.report(world)
  local parts = {}
  for i, b in ipairs(balls) do parts[i] = string.format("%.3f", (b:velocity())) end
  local px = world:momentum()
  local ke = world:energy()
  print("cradle: ball speeds after " .. M.steps .. " steps: " .. table.concat(parts, " ") .. " m/s (ideal: 0 0 0 0 0 2)")
  print(string.format("cradle: momentum %.6f kg m/s (2 at start), kinetic energy %.4f J (2 at start)", px, ke))
end

return M
