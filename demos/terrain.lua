-- terrain.lua - a 64 x 64 m height field of rolling hills with a hole, a
-- scatter of boulders (hulls and compounds) resting on it, and a ball rolling
-- down the slopes. Prints where the ball went and whether anything sank.
-- carom-run demos/terrain.lua
local carom = require "carom"
local M = { steps = 600 }

local N, CELL = 65, 1.0
local function height(x, y) return 1.5 * math.sin(0.15 * x) * math.cos(0.11 * y) + 0.02 * x end

function M.load(world)
  local heights = {}
  for r = 0, N - 1 do
    for c = 0, N - 1 do
      heights[#heights + 1] = height((c - (N - 1) / 2) * CELL, (r - (N - 1) / 2) * CELL)
    end
  end
  -- a pit: four cells without ground near the middle
  local holes = {}
  for r = 31, 32 do for c = 40, 41 do holes[#holes + 1] = r * (N - 1) + c + 1 end end
  M.ground = world:add_body{ type = "static", shape = carom.heightfield{ heights = heights, rows = N, columns = N,
                                                                          cell = {CELL, CELL}, holes = holes } }
  local state = 7
  local function rand01() state = (state * 1664525 + 1013904223) % 4294967296; return (state >> 8) / 16777216 end
  M.boulders = {}
  for i = 1, 40 do
    local x, y = -25 + 50 * rand01(), -25 + 50 * rand01()
    local shape
    if i % 2 == 0 then
      local pts = {}
      for k = 1, 12 do pts[k] = {0.6 * (rand01() - 0.5), 0.6 * (rand01() - 0.5), 0.5 * (rand01() - 0.5)} end
      shape = carom.hull{ points = pts }
    else
      shape = carom.compound{ { shape = carom.sphere{ radius = 0.3 } },
                              { shape = carom.box{ half_extents = {0.25, 0.2, 0.15} }, position = {0.3, 0, 0.1} } }
    end
    M.boulders[#M.boulders + 1] = world:add_body{ shape = shape, position = {x, y, height(x, y) + 1.0} }
  end
  M.ball = world:add_body{ shape = carom.sphere{ radius = 0.4 }, position = {-20, 0, height(-20, 0) + 0.45} }
end

function M.report(world)
  local x, y, z = M.ball:position()
  local sunk = 0
  for _, b in ipairs(M.boulders) do
    local bx, by, bz = b:position()
    -- below the ground by more than the look-ahead (and not over the pit)
    if bz < height(bx, by) - 0.5 and math.abs(bx - 8.5) > 2 then sunk = sunk + 1 end
  end
  print(string.format("terrain: the ball rolled to (%.2f, %.2f, %.2f); %d of %d boulders below the ground", x, y, z,
                      sunk, #M.boulders))
end

return M
