-- level.lua - a mesh level: a floor, a ramp, a flight of stairs and a bowl
-- made of triangles, with balls and boxes thrown in. Prints where each ends.
-- carom-run demos/level.lua
local carom = require "carom"
local M = { steps = 600 }

-- appends a quad (counter-clockwise from the front) to the vertex and triangle lists
local function quad(v, t, a, b, c, d)
  local n = #v
  v[n + 1], v[n + 2], v[n + 3], v[n + 4] = a, b, c, d
  t[#t + 1] = {n + 1, n + 2, n + 3}
  t[#t + 1] = {n + 1, n + 3, n + 4}
end

function M.load(world)
  local v, t = {}, {}
  -- floor 40 x 40 m in 2 m squares
  for j = -10, 9 do
    for i = -10, 9 do
      quad(v, t, {2 * i, 2 * j, 0}, {2 * i + 2, 2 * j, 0}, {2 * i + 2, 2 * j + 2, 0}, {2 * i, 2 * j + 2, 0})
    end
  end
  -- a ramp rising 2 m over 8 m along +x, then a 4 m deck, at y in [-12, -8]
  quad(v, t, {0, -12, 0.001}, {8, -12, 2}, {8, -8, 2}, {0, -8, 0.001})
  quad(v, t, {8, -12, 2}, {12, -12, 2}, {12, -8, 2}, {8, -8, 2})
  -- stairs: 8 steps of 0.2 m rise, 0.4 m run along -x from x = -4, y in [8, 12]
  for s = 0, 7 do
    local x0, z0 = -4 - 0.4 * s, 0.2 * s
    quad(v, t, {x0, 8, z0}, {x0, 12, z0}, {x0, 12, z0 + 0.2}, {x0, 8, z0 + 0.2})               -- riser, facing +x
    quad(v, t, {x0 - 0.4, 8, z0 + 0.2}, {x0, 8, z0 + 0.2}, {x0, 12, z0 + 0.2}, {x0 - 0.4, 12, z0 + 0.2}) -- tread
  end
  world:add_body{ type = "static", shape = carom.mesh{ vertices = v, triangles = t } }
  -- a bowl (a spherical cap of radius 4 m, 24 x 8 facets, two-sided) at (10, 10)
  local bv, bt = {}, {}
  local R, rings, sectors = 4, 8, 24
  bv[1] = {0, 0, 0}
  for r = 1, rings do
    local a = r / rings * 1.0
    for s = 0, sectors - 1 do
      local p = s / sectors * 2 * math.pi
      bv[#bv + 1] = {R * math.sin(a) * math.cos(p), R * math.sin(a) * math.sin(p), R * (1 - math.cos(a))}
    end
  end
  for s = 0, sectors - 1 do bt[#bt + 1] = {1, 2 + s, 2 + (s + 1) % sectors} end
  for r = 1, rings - 1 do
    for s = 0, sectors - 1 do
      local a, b = 2 + (r - 1) * sectors + s, 2 + (r - 1) * sectors + (s + 1) % sectors
      local c, d = a + sectors, b + sectors
      bt[#bt + 1] = {a, c, d}
      bt[#bt + 1] = {a, d, b}
    end
  end
  world:add_body{ type = "static", position = {10, 10, 0.01}, shape = carom.mesh{ vertices = bv, triangles = bt, two_sided = true } }
  M.things = {
    world:add_body{ shape = carom.sphere{ radius = 0.3 }, position = {-2, -10, 0.3}, velocity = {8, 0, 0} },   -- up the ramp
    world:add_body{ shape = carom.box{ half_extents = {0.3, 0.3, 0.3} }, position = {-1, 10, 0.3}, velocity = {-3, 0, 0} }, -- at the stairs
    world:add_body{ shape = carom.sphere{ radius = 0.25 }, position = {12.5, 10, 3} },                          -- into the bowl
    world:add_body{ shape = carom.capsule{ radius = 0.15, half_height = 0.3 }, position = {8, 8.5, 2} },
  }
end

function M.report(world)
  for i, b in ipairs(M.things) do
    local x, y, z = b:position()
    print(string.format("level: body %d (%s) ends at (%.2f, %.2f, %.2f)", i, b:shape_type(), x, y, z))
  end
end

return M
