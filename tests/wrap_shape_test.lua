-- wrap_shape_test.lua - lua/wrap_shape.c's level geometry: carom.mesh,
-- carom.heightfield and carom.compound from Lua: a ball rolls on each field
-- as on a plane (the same path, computed in the same run), ray casts hit
-- them where the geometry says, and every bad input is refused naming the
-- field. Run by `make check` as `carom-run --test tests/wrap_shape_test.lua`.
local carom = require "carom"
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test, raises = T.test, T.raises

-- an n x n grid of 1 m cells centred on the origin at z = 0
local function grid(n)
  local vertices, triangles = {}, {}
  for j = 0, n do
    for i = 0, n do vertices[#vertices + 1] = {i - n / 2, j - n / 2, 0} end
  end
  for j = 0, n - 1 do
    for i = 0, n - 1 do
      local a = j * (n + 1) + i + 1
      local b, c, d = a + 1, a + n + 2, a + n + 1
      triangles[#triangles + 1] = {a, b, c}
      triangles[#triangles + 1] = {a, c, d}
    end
  end
  return vertices, triangles
end

-- the ball's path on a floor shape, 3 s at 60 Hz
local function roll(floor)
  local world = carom.world{}
  world:add_body{ type = "static", shape = floor }
  local ball = world:add_body{ shape = carom.sphere{ radius = 0.3 }, position = {-2, -1.5, 0.3},
                               velocity = {0.8, 0.5, 0}, angular_velocity = {-0.5 / 0.3, 0.8 / 0.3, 0} }
  local path = {}
  for i = 1, 180 do
    world:step(1 / 60)
    path[i] = {ball:position()}
  end
  return path
end

local function largest_gap(p, q)
  local gap = 0
  for i = 1, #p do
    local dx, dy, dz = p[i][1] - q[i][1], p[i][2] - q[i][2], p[i][3] - q[i][3]
    gap = math.max(gap, math.sqrt(dx * dx + dy * dy + dz * dz))
  end
  return gap
end

test("a ball rolls on a mesh and on a height field as on a plane", function()
  local plane = roll(carom.plane{})
  local v, t = grid(10)
  local on_mesh = roll(carom.mesh{ vertices = v, triangles = t })
  local heights = {}
  for i = 1, 11 * 11 do heights[i] = 0 end
  local on_field = roll(carom.heightfield{ heights = heights, rows = 11, columns = 11, cell = {1, 1} })
  assert(largest_gap(plane, on_mesh) < 1e-3, "mesh path off the plane's by " .. largest_gap(plane, on_mesh))
  assert(largest_gap(plane, on_field) < 1e-3, "height field path off the plane's by " .. largest_gap(plane, on_field))
  -- it did move: about 0.94 m/s for 3 s
  assert(math.abs(on_mesh[180][1] - plane[1][1]) > 1.5)
end)

test("flat number lists, two-sided meshes, descriptors", function()
  local m = carom.mesh{ vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0}, triangles = {1, 2, 3}, two_sided = true }
  assert(m.type == "mesh")
  assert(tostring(m) == "carom.mesh{3 vertices, 1 triangles}", tostring(m))
  assert(m == m)
  local h = carom.heightfield{ heights = {0, 0, 0, 0}, rows = 2, columns = 2, cell = 2, holes = {} }
  assert(h.type == "heightfield")
  local world = carom.world{}
  local b = world:add_body{ type = "static", shape = m }
  assert(b:shape_type() == "mesh")
  -- two-sided: a ray from below hits it
  local hit = world:ray_cast({0.2, 0.2, -1}, {0, 0, 2})
  assert(hit == b, "two-sided mesh hit from below")
end)

test("ray casts hit a height field where its heights are, and miss its holes", function()
  -- 3 x 3 points, 1 m cells: heights rise along x; cell 1 (lower left) is a hole
  local world = carom.world{}
  local field = world:add_body{ type = "static", shape = carom.heightfield{
    heights = {0, 0.5, 1,  0, 0.5, 1,  0, 0.5, 1}, rows = 3, columns = 3, cell = {1, 1}, holes = {1} } }
  -- over cell 2 (x in [0, 1]): height 0.5 + 0.5 x
  local hit, point, normal = world:ray_cast({0.5, -0.5, 5}, {0, 0, -10})
  assert(hit == field)
  assert(math.abs(point[3] - 0.75) < 1e-12, "height " .. tostring(point[3]))
  -- the slope's normal: (-0.5, 0, 1) / |.|
  assert(math.abs(normal[1] + 0.5 / math.sqrt(1.25)) < 1e-12 and math.abs(normal[3] - 1 / math.sqrt(1.25)) < 1e-12)
  assert(world:ray_cast({-0.5, -0.5, 5}, {0, 0, -10}) == nil, "a hole has no ground")
end)

test("bad input is refused naming the field", function()
  raises("vertices[1]: coordinates must be finite (within 1e6 m; vertex 2 counting from 1)", carom.mesh, { vertices = {{0, 0, 0}, {0 / 0, 0, 0}, {0, 1, 0}}, triangles = {{1, 2, 3}} })
  raises("vertex 2 counting from 1", carom.mesh, { vertices = {{0, 0, 0}, {math.huge, 0, 0}, {0, 1, 0}}, triangles = {{1, 2, 3}} })
  raises("triangles[1]: index 4", carom.mesh, { vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, triangles = {{1, 2, 4}} })
  raises("triangles[1]: index 0", carom.mesh, { vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, triangles = {{0, 1, 2}} })
  raises("triangles: need at least 1", carom.mesh, { vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, triangles = {} })
  raises("vertices[1] is not a list of 3 numbers", carom.mesh, { vertices = {{0, 0}}, triangles = {{1, 2, 3}} })
  raises("unknown option", carom.mesh, { vertices = {}, triangles = {}, colour = 1 })
  local world = carom.world{}
  -- the library's rules apply when the descriptor is made (carom_mesh_def_check)
  raises("triangles[0]: repeats vertex 1 (triangle 1, vertex 2 counting from 1)", carom.mesh, { vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, triangles = {{1, 2, 2}} })
  local flat = carom.mesh{ vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, triangles = {{1, 2, 3}} }
  raises("zero area", world.add_body, world, { type = "static", shape = flat })
  local ok = carom.mesh{ vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, triangles = {{1, 2, 3}} }
  raises("static or kinematic", world.add_body, world, { shape = ok })
  raises("heights[1]: must be finite (within 1e6 m; height 2 counting from 1)", carom.heightfield, { heights = {0, 0 / 0, 0, 0}, rows = 2, columns = 2 })
  raises("heights: need rows x columns = 4", carom.heightfield, { heights = {0, 0, 0}, rows = 2, columns = 2 })
  raises("rows and columns: need at least 2 each (got 1 x 2)", carom.heightfield, { heights = {0, 0}, rows = 1, columns = 2 })
  raises("rows must be an integer", carom.heightfield, { heights = {0, 0}, rows = 1.5, columns = 2 })
  raises("holes[1]: 2 is not an integer in 1..1", carom.heightfield, { heights = {0, 0, 0, 0}, rows = 2, columns = 2, holes = {2} })
  raises("holes: all 1 cells are holes", carom.heightfield, { heights = {0, 0, 0, 0}, rows = 2, columns = 2, holes = {1, 1} })
  raises("cell: sizes must be in [1e-6, 1e6] m (got 0, 1)", carom.heightfield, { heights = {0, 0, 0, 0}, rows = 2, columns = 2, cell = {0, 1} })
  assert(world:body_count() == 0, "the world is unchanged")
end)

test("compound: mass, a table standing on a mesh, the child in ray casts and events", function()
  local world = carom.world{}
  local v, t = grid(6)
  world:add_body{ type = "static", shape = carom.mesh{ vertices = v, triangles = t } }
  local children = { { shape = carom.box{ half_extents = {0.6, 0.4, 0.03} }, position = {0, 0, 0.73}, density = 600 } }
  for i = 0, 3 do
    children[#children + 1] = { shape = carom.box{ half_extents = {0.03, 0.03, 0.35} },
                                position = {(i % 2 == 1) and 0.55 or -0.55, (i >= 2) and 0.35 or -0.35, 0.35},
                                friction = 0.8 }
  end
  local table_shape = carom.compound(children)
  assert(table_shape.type == "compound" and tostring(table_shape) == "carom.compound{5 children}")
  local tbl = world:add_body{ shape = table_shape, position = {0.2, 0.1, 0} }
  -- mass: 600 * 1.2 * 0.8 * 0.06 + 4 * 1000 * 0.06 * 0.06 * 0.7
  local m = 600 * 1.2 * 0.8 * 0.06 + 4 * 1000 * 0.06 * 0.06 * 0.7
  assert(math.abs(tbl:mass() - m) < 1e-9 * m, "mass " .. tbl:mass())
  local x0, y0, z0 = tbl:position()
  world:step(1 / 60, 600)
  local x, y, z = tbl:position()
  local moved = math.sqrt((x - x0) ^ 2 + (y - y0) ^ 2 + (z - z0) ^ 2)
  assert(moved < 1e-3, "the table moved " .. moved)
  -- a ray down through the top names child 1, one down a leg's corner child 3 (x > 0, y < 0)
  local hit, point, normal, fraction, child = world:ray_cast({0.2, 0.1, 3}, {0, 0, -5})
  assert(hit == tbl and child == 1, "top: child " .. tostring(child))
  -- a ray starting inside the top names it too, at fraction 0
  local ihit, _, _, ifraction, ichild = world:ray_cast({x, y, z + 0.73}, {0, 0, 2})
  assert(ihit == tbl and ifraction == 0 and ichild == 1, "inside the top: child " .. tostring(ichild))
  local events = {}
  local w2 = carom.world{}
  w2:add_body{ type = "static", shape = carom.plane{} }
  local bell = w2:add_body{ shape = carom.compound{ { shape = carom.sphere{ radius = 0.1 }, position = {-0.5, 0, 0} },
                                                    { shape = carom.sphere{ radius = 0.1 }, position = {0.5, 0, 0} } },
                            position = {0, 0, 1}, orientation = {math.cos(0.05), 0, math.sin(0.05), 0} }
  for i = 1, 60 do
    w2:step(1 / 60)
    for _, e in ipairs(w2:events()) do if e.type ~= "end" then events[#events + 1] = e end end
  end
  assert(#events > 0, "the dumbbell landed")
  local e = events[1]
  local mine = (e.a == bell) and e.child_a or e.child_b
  assert(mine == 2, "the +x sphere lands first (tilted down at +x): child " .. tostring(mine))
  -- bad children
  raises("a compound needs children (got 0)", carom.compound, {})
  raises("child 1: shape must be convex", carom.compound, { { shape = carom.plane{} } })
  raises("child 2 is not a table", carom.compound, { { shape = carom.sphere{ radius = 1 } }, 3 })
  raises("density must be in", carom.compound, { { shape = carom.sphere{ radius = 1 }, density = 0 } })
  raises("unknown option", carom.compound, { { shape = carom.sphere{ radius = 1 }, colour = 1 } })
end)

test("the part of level geometry in ray_cast_all, shape_cast and overlap: triangle and cell, 1-based", function()
  local world = carom.world{ gravity = {0, 0, 0} }
  -- a 2 x 2 grid of 1 m cells at z = 1 (cells from x, y = -1): cell (i, j)'s triangle
  -- below its diagonal is 2 (2 j + i) + 1 in the list, the one above it the next
  local v, t = grid(2)
  local mesh = world:add_body{ type = "static", shape = carom.mesh{ vertices = v, triangles = t }, position = {0, 0, 1} }
  -- 3 rows x 4 columns of 1 m cells centred on the origin at z = 0: cell (column c, row r)
  -- is 3 r + c + 1, its lower half 2 (3 r + c) + 1, its upper half the next
  local field = world:add_body{ type = "static", shape = carom.heightfield{ heights = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
                                                                         rows = 3, columns = 4, cell = {1, 1} } }
  -- at (0.7, -0.9): the mesh's cell (1, 0) below its diagonal (0.7, 0.1 into the cell), 3; the field's
  -- column 2, row 0 (x in [0.5, 1.5]: 0.2, 0.1 into the cell), its lower half, 2 (3 * 0 + 2) + 1 = 5
  local hits = world:ray_cast_all({0.7, -0.9, 5}, {0, 0, -10})
  assert(#hits == 2 and hits[1].body == mesh and hits[2].body == field)
  assert(hits[1].child == 3, "triangle " .. tostring(hits[1].child))
  assert(hits[2].child == 5, "field part " .. tostring(hits[2].child))
  local _, _, _, _, child = world:ray_cast({0.7, -0.9, 5}, {0, 0, -10})
  assert(child == 3)
  -- at (0.3, -0.1): the field's column 1, row 0, upper half (0.8, 0.9 into the cell), 2 (3 * 0 + 1) + 2 = 4
  hits = world:ray_cast_all({0.3, -0.1, 5}, {0, 0, -10})
  assert(#hits == 2 and hits[2].child == 4, "field part " .. tostring(hits[2].child))
  -- a small ball swept down at (-0.7, 0.8): the mesh's cell (0, 1) above its diagonal, 2 * 2 + 2 = 6
  local body, _, _, _, part = world:shape_cast(carom.sphere{ radius = 0.05 }, {-0.7, 0.8, 5}, nil, {0, 0, -10})
  assert(body == mesh and part == 6, "swept onto triangle " .. tostring(part))
  -- a flat box over the mesh's cell (1, 1): triangles 7 and 8, the lower named
  local bodies, children = world:overlap(carom.box{ half_extents = {0.4, 0.4, 0.05} }, {0.5, 0.5, 1})
  assert(#bodies == 1 and bodies[1] == mesh and children[1] == 7, "overlap: " .. tostring(children[1]))
  -- a ball touching the mesh at (0.7, -0.9): its contact names triangle 3 as other_child
  local ball = world:add_body{ shape = carom.sphere{ radius = 0.25 }, position = {0.7, -0.9, 1.249} }
  world:step(1 / 60)
  local cs = ball:contacts()
  assert(#cs == 1 and cs[1].other == mesh and cs[1].child == nil and cs[1].other_child == 3,
         "contact: " .. tostring(cs[1] and cs[1].other_child))
  cs = mesh:contacts()
  assert(#cs == 1 and cs[1].child == 3 and cs[1].other_child == nil)
end)

T.finish()
