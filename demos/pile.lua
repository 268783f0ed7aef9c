-- pile.lua - the peers' pile: 1000 spheres and 1000 cubes dropped into a
-- walled 20 x 20 m box. Prints the settled kinetic energy and deepest overlap.
-- carom-run demos/pile.lua --bench
local carom = require "carom"
local M = { steps = 600, world = { sleep = false } }

function M.load(world)
  world:add_body{ type = "static", shape = carom.plane{}, friction = 0.5 }
  local walls = { {{10.5, 0, 7.5}, {0.5, 11, 7.5}}, {{-10.5, 0, 7.5}, {0.5, 11, 7.5}},
                  {{0, 10.5, 7.5}, {10, 0.5, 7.5}}, {{0, -10.5, 7.5}, {10, 0.5, 7.5}} }
  for _, w in ipairs(walls) do
    world:add_body{ type = "static", position = w[1], shape = carom.box{ half_extents = w[2] }, friction = 0.5 }
  end
  local state = 12345
  local function rand01() state = (state * 1664525 + 1013904223) % 4294967296; return (state >> 8) / 16777216 end
  local k, layer = 0, 0
  while k < 2000 do
    for j = 0, 15 do
      for i = 0, 15 do
        if k < 2000 then
          local x = -9 + 1.2 * i + 0.1 * (rand01() - 0.5)
          local y = -9 + 1.2 * j + 0.1 * (rand01() - 0.5)
          local shape = (i + j + layer) % 2 == 0 and carom.sphere{ radius = 0.5 } or carom.box{ half_extents = {0.5, 0.5, 0.5} }
          world:add_body{ position = {x, y, 2 + 1.5 * layer}, shape = shape, mass = 1, friction = 0.5 }
          k = k + 1
        end
      end
    end
    layer = layer + 1
  end
end

function M.report(world)
  local ke = world:energy()
  local st = world:stats()
  print(string.format("pile of %d bodies: kinetic energy %.3f J, deepest overlap %.4f m, %d contacts", st.bodies - 5, ke,
                      st.max_penetration, st.contacts))
end

return M
