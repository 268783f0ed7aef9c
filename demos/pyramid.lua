-- pyramid.lua - the peers' pyramid: 20 rows of unit cubes in the x-z plane
-- (210 boxes, mu 0.6). Prints how far any box moved after the run.
-- carom-run demos/pyramid.lua [--bench]
local carom = require "carom"
local M = { steps = 600, world = { sleep = false } }
local boxes, start = {}, {}

function M.load(world)
  world:add_body{ type = "static", shape = carom.plane{ normal = {0, 0, 1} }, friction = 0.6 }
  local base = M.base or 20
  for r = 0, base - 1 do
    for i = 0, base - r - 1 do
      local x, z = i - 0.5 * (base - r - 1), 0.5 + r
      boxes[#boxes + 1] = world:add_body{ position = {x, 0, z}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} },
                                          mass = 1, friction = 0.6 }
      start[#start + 1] = {x, 0, z}
    end
  end
end

function M.report(world)
  local worst = 0
  for i, b in ipairs(boxes) do
    local x, y, z = b:position()
    local d = math.sqrt((x - start[i][1]) ^ 2 + (y - start[i][2]) ^ 2 + (z - start[i][3]) ^ 2)
    worst = math.max(worst, d)
  end
  local _, _, top = boxes[#boxes]:position()
  print(string.format("pyramid of %d boxes: largest displacement %.4f m, top box moved %+.4f m vertically: %s",
                      #boxes, worst, top - start[#start][3], math.abs(top - start[#start][3]) <= 0.1 and "stands" or "COLLAPSED"))
  M.max_disp = worst
end

return M
