-- bounce_ladder.lua - five balls with restitution e = 0, 0.25, 0.5, 0.75, 1
-- dropped from 1 m onto a floor: the first rebound rises e^2 h (the
-- coefficient of restitution scales the speed by e, the height by e^2).
-- The shortfall is the time step's (gravity acts during the impact step) and
-- shrinks in proportion to dt: try --dt 0.001.
-- carom-run demos/bounce_ladder.lua [--dt DT]
local carom = require "carom"
local M = { seconds = 2.5, world = { substeps = 8, sleep = false } }
local balls, apex, rising = {}, {}, {}
local E = {0, 0.25, 0.5, 0.75, 1}
local H, R = 1.0, 0.1
local step_dt = 1 / 60

function M.load(world)
  world:add_body{ type = "static", shape = carom.plane{}, friction = 0, restitution = 0 }
  for i, e in ipairs(E) do
    balls[i] = world:add_body{ position = {i, 0, H + R}, shape = carom.sphere{ radius = R }, restitution = e, friction = 0 }
    apex[i], rising[i] = 0, 0
  end
end

-- called before each step: track the highest point of the first rebound
function M.update(world, dt)
  step_dt = dt
  for i, b in ipairs(balls) do
    local _, _, vz = b:velocity()
    local _, _, z = b:position()
    if rising[i] == 0 and vz > 0 then rising[i] = 1 end
    if rising[i] == 1 then
      apex[i] = math.max(apex[i], z - R)
      if vz < 0 then rising[i] = 2 end
    end
  end
end

function M.report(world)
  print(string.format("restitution ladder: balls dropped from %.0f m rebound to e^2 h (steps of %.4g s):", H, step_dt))
  for i, e in ipairs(E) do
    local want = e * e * H
    print(string.format("  e = %.2f   apex %.4f m   expected %.4f m   %s", e, apex[i], want,
                        want > 0 and string.format("(%+.1f%%)", 100 * (apex[i] - want) / want) or ""))
  end
end

return M
