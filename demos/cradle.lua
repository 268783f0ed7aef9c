-- cradle.lua - Newton's cradle without strings: five elastic balls (e = 1,
-- no friction, no gravity) in a row, hit by a sixth at 2 m/s. Ideally the
-- first ball stops and the last leaves at 2 m/s, keeping momentum (2 kg m/s)
-- and energy (2 J).
--   a) touching balls: the impacts arrive together; resolved pair by pair
--      until none approaches (docs/physics.md, section 4.3), the momentum
--      runs down the row as in the experiment;
--   b) balls 5 cm apart: one impact after another, each exact.
-- carom-run demos/cradle.lua
local carom = require "carom"
local M = { steps = 90, world = { gravity = {0, 0, 0}, friction = false, restitution_threshold = 0, sleep = false } }
local rows = {}

local function row(world, gap)
  local balls = {}
  balls[1] = world:add_body{ position = {-0.6, 0, 0}, velocity = {2, 0, 0}, shape = carom.sphere{ radius = 0.1 },
                             mass = 1, restitution = 1 }
  for i = 0, 4 do
    balls[#balls + 1] = world:add_body{ position = {(0.2 + gap) * i, 0, 0}, shape = carom.sphere{ radius = 0.1 },
                                        mass = 1, restitution = 1 }
  end
  return balls
end

local function describe(label, world, balls)
  local parts = {}
  for i, b in ipairs(balls) do parts[i] = string.format("%6.3f", (b:velocity())) end
  local px = world:momentum()
  local ke = world:energy()
  print(string.format("  %-22s speeds %s m/s   momentum %.6f   energy %.4f J", label, table.concat(parts, " "), px, ke))
end

function M.load(world)
  rows.touching = row(world, 0)
end

function M.report(world)
  print(string.format("Newton's cradle after %d steps (ideal: speeds 0 0 0 0 0 2, momentum 2, energy 2 J):", M.steps))
  describe("a) touching", world, rows.touching)
  local apart = carom.world(M.world)
  local balls = row(apart, 0.05)
  apart:step(1/60, M.steps)
  describe("b) 5 cm apart", apart, balls)
  local last = balls[#balls]:velocity()
  print(string.format("cradle: with gaps the last ball leaves at %.4f m/s (2 expected): %s", last,
                      math.abs(last - 2) < 1e-6 and "OK" or "MISMATCH"))
end

return M
