-- bounce_ladder.lua - five balls with restitution e = 0, 0.25, 0.5, 0.75, 1
-- dropped from 1 m: the first rebound rises e^2 h. 8 sub-steps (the arc of a
-- semi-implicit Euler step flies low by v h / 2).
local carom = require "carom"
local M = { steps = 150, world = { substeps = 8, sleep = false } }
local balls, apex, rising = {}, {}, {}
local E = {0, 0.25, 0.5, 0.75, 1}

function M.load(world)
  world:add_body{ type = "static", shape = carom.plane{}, friction = 0, restitution = 0 }
  for i, e in ipairs(E) do
    balls[i] = world:add_body{ position = {i, 0, 1.1}, shape = carom.sphere{ radius = 0.1 }, restitution = e, friction = 0 }
    apex[i], rising[i] = 0, 0
  end
end

function M.update(world)
  for i, b in ipairs(balls) do
    local _, _, vz = b:velocity()
    local _, _, z = b:position()
    if rising[i] == 0 and vz > 0 then rising[i] = 1 end
    if rising[i] == 1 then
      apex[i] = math.max(apex[i], z - 0.1)
      if vz < 0 then rising[i] = 2 end
    end
  end
end

function M.report()
  print("restitution ladder (dropped from 1 m; first rebound apex e^2 h):")
  for i, e in ipairs(E) do
    print(string.format("  e = %.2f   apex %.4f m   expected %.4f m", e, apex[i], e * e))
  end
end

return M
