-- wrap_game_test.lua - lua/wrap_game.c: the Lua side of filtering and
-- queries (issue "what a game script needs"): add_body's category/mask/group, set_filter, every
-- query with a mask and with a filter function, and their errors. Values are
-- the geometry worked by hand. Run by `make check` with carom-run --test.
local carom = require "carom"
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test, near, raises = T.test, T.near, T.raises

local function ground_and_ball(ground_keys, ball_keys)
  local w = carom.world{}
  local g = { type = "static", shape = carom.box{ half_extents = {5, 5, 0.5} }, position = {0, 0, -0.5} }
  for k, v in pairs(ground_keys or {}) do g[k] = v end
  local b = { shape = carom.sphere{ radius = 0.25 }, position = {0, 0, 0.5} }
  for k, v in pairs(ball_keys or {}) do b[k] = v end
  return w, w:add_body(g), w:add_body(b)
end

local function lands(ground_keys, ball_keys)
  local w, _, ball = ground_and_ball(ground_keys, ball_keys)
  w:step(1/60, 60)
  local _, _, z = ball:position()
  return math.abs(z - 0.25) < 0.01
end

test("category and mask at creation, both directions", function()
  assert(lands({}, {}))
  assert(not lands({ category = 2 }, { mask = 1 }))
  assert(not lands({ mask = 1 }, { category = 2 }))
  assert(lands({ category = 2 }, { mask = 3 }))
  assert(lands({ category = 1 << 63 }, { mask = -1 }), "the top bit and -1 = every bit")
end)

test("groups: negative never, positive always, over the bits", function()
  assert(not lands({ group = -2 }, { group = -2 }))
  assert(lands({ group = 2, mask = 0 }, { group = 2, mask = 0 }))
  assert(not lands({ group = 2, mask = 0 }, { group = 3 }))
end)

test("set_filter at runtime on a sleeping body", function()
  local w, g, ball = ground_and_ball({}, { position = {0, 0, 0.26} })
  w:step(1/60, 120)
  assert(not ball:is_awake())
  ball:set_filter{ mask = 2 }
  local f = ball:filter()
  assert(f.category == 1 and f.mask == 2 and f.group == 0)
  w:step(1/60, 20)
  local _, _, z = ball:position()
  assert(z < 0.2, "it fell: " .. z)
  raises("mask must be an integer", ball.set_filter, ball, { mask = 1.5 })
  raises("unknown", ball.set_filter, ball, { colour = 1 })
  ball:destroy()
  raises("destroyed", ball.set_filter, ball, { mask = 1 })
end)

local function row()
  local w = carom.world{ gravity = {0, 0, 0} }
  local bodies = {}
  for i = 1, 4 do
    bodies[i] = w:add_body{ type = "static", shape = carom.sphere{ radius = 0.5 }, position = {2 * i, 0, 0},
                            category = i % 2 == 0 and 2 or 1 }
  end
  return w, bodies
end

test("ray_cast_all: nearest first, with a mask and a function", function()
  local w, b = row()
  local hits = w:ray_cast_all({0, 0, 0}, {10, 0, 0})
  assert(#hits == 4)
  for i = 1, 4 do
    assert(hits[i].body == b[i])
    near(hits[i].point[1], 2 * i - 0.5, 1e-12, "hit x")
    near(hits[i].fraction, (2 * i - 0.5) / 10, 1e-12, "fraction")
    near(hits[i].normal[1], -1, 1e-12, "normal")
  end
  hits = w:ray_cast_all({0, 0, 0}, {10, 0, 0}, 2)
  assert(#hits == 2 and hits[1].body == b[2] and hits[2].body == b[4])
  hits = w:ray_cast_all({0, 0, 0}, {10, 0, 0}, function(body) return body ~= b[3] end)
  assert(#hits == 3 and hits[3].body == b[4])
  -- the ray convention: from inside, a hit at fraction 0 against the ray
  hits = w:ray_cast_all({2, 0, 0}, {10, 0, 0})
  assert(#hits == 4 and hits[1].fraction == 0 and hits[1].normal[1] == -1)
end)

test("shape_cast, overlap, distance", function()
  local w, b = row()
  local body, fraction, point, normal = w:shape_cast(carom.sphere{ radius = 0.25 }, {0, 0, 0}, nil, {10, 0, 0})
  assert(body == b[1])
  near(fraction, 1.25 / 10, 1e-9, "fraction")
  near(point[1], 1.5, 1e-9, "point")
  near(normal[1], -1, 1e-9, "normal")
  body = w:shape_cast(carom.sphere{ radius = 0.25 }, {0, 0, 0}, {1, 0, 0, 0}, {10, 0, 0}, 2)
  assert(body == b[2])
  assert(w:shape_cast(carom.box{ half_extents = {0.1, 0.1, 0.1} }, {0, 0, 3}, nil, {10, 0, 0}) == nil)
  local over = w:overlap(carom.box{ half_extents = {1.2, 0.2, 0.2} }, {2.5, 0, 0})
  assert(#over == 2 and over[1] == b[1] and over[2] == b[2])
  -- the box's corner region near a sphere's bounds but not its surface: not an overlap
  over = w:overlap(carom.box{ half_extents = {0.2, 0.2, 0.2} }, {2.6, 0.6, 0})
  assert(#over == 0)
  local d, pa, pb = w:distance(b[1], b[2])
  near(d, 1.0, 1e-12, "distance")
  near(pa[1], 2.5, 1e-12, "point on a")
  near(pb[1], 3.5, 1e-12, "point on b")
end)

test("query errors name the argument and leave the world as it was", function()
  local w, b = row()
  raises("bad argument #4 to 'ray_cast_all'", w.ray_cast_all, w, {0, 0, 0}, {1, 0, 0}, "all")
  raises("bad argument #2 to 'shape_cast'", w.shape_cast, w, {}, {0, 0, 0}, nil, {1, 0, 0})
  raises("finite", w.shape_cast, w, carom.sphere{ radius = 1 }, {0 / 0, 0, 0}, nil, {1, 0, 0})
  raises("plane", w.overlap, w, carom.plane{}, {0, 0, 0})
  raises("same body", w.distance, w, b[1], b[1])
  local other = carom.world{}
  local stranger = other:add_body{ shape = carom.sphere{ radius = 1 } }
  raises("another world", w.distance, w, b[1], stranger)
  b[4]:destroy()
  raises("destroyed", w.distance, w, b[1], b[4])
  -- a filter function that raises: the query raises it (a table keeps its value)
  local ok, err = pcall(w.ray_cast_all, w, {0, 0, 0}, {10, 0, 0}, function() error({ code = 3 }) end)
  assert(not ok and type(err) == "table" and err.code == 3)
  ok, err = pcall(w.overlap, w, carom.sphere{ radius = 9 }, {0, 0, 0}, nil, function() error("no way") end)
  assert(not ok and tostring(err):find("no way", 1, true))
  -- one that destroys bodies is refused
  ok, err = pcall(w.overlap, w, carom.sphere{ radius = 9 }, {0, 0, 0}, nil, function(body) body:destroy() end)
  assert(not ok and tostring(err):find("locked", 1, true) or tostring(err):find("callback", 1, true), tostring(err))
  assert(w:body_count() == 3 and b[1]:is_valid())
  w:step(1/60)
end)

test("body calls: angular impulse, damping, frames, shape, previous pose", function()
  local w = carom.world{ gravity = {0, 0, 0} }
  local m, hx, hy, hz = 2, 0.5, 0.25, 0.125
  local b = w:add_body{ shape = carom.box{ half_extents = {hx, hy, hz} }, mass = m, sleep = false }
  b:apply_angular_impulse(0, 0, 1)
  local _, _, wz = b:angular_velocity()
  near(wz, 1 / (m * (hx * hx + hy * hy) / 3), 1e-12, "spin = L / I")
  b:set_damping(0.5, 0.25)
  local lin, ang = b:damping()
  assert(lin == 0.5 and ang == 0.25)
  raises("bad argument #3 to 'set_damping'", b.set_damping, b, 0, -1)
  raises("bad argument #2 to 'set_damping'", b.set_damping, b, 0 / 0, 1)
  b:set_position(1, 2, 3)
  local x, y, z = b:world_point(1, 0, 0)
  assert(x == 2 and y == 2 and z == 3)
  x, y, z = b:local_point(2, 2, 3)
  assert(x == 1 and y == 0 and z == 0)
  x, y, z = b:world_vector{0, 1, 0}
  assert(x == 0 and y == 1 and z == 0)
  x, y, z = b:local_vector(0, 0, 1)
  assert(z == 1)
  local s = b:shape()
  assert(s.type == "box" or tostring(s):find("box"), tostring(s))
  local twin = w:add_body{ shape = s, mass = m, position = {5, 0, 0} }
  near(twin:mass(), m, 0, "same shape, same mass")
  local hull = w:add_body{ shape = carom.hull{ {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1} }, position = {9, 0, 0} }
  local copy = w:add_body{ shape = hull:shape(), position = {12, 0, 0} }
  near(copy:mass(), hull:mass(), 1e-9 * hull:mass(), "hull copied")
  -- the pose at the start of the last step
  local ball = w:add_body{ shape = carom.sphere{ radius = 0.5 }, position = {0, 5, 0}, velocity = {1, 0, 0} }
  w:step(0.5)
  local px = ball:previous_position()
  local cx = ball:position()
  assert(px == 0 and math.abs(cx - 0.5) < 1e-12, px .. " " .. cx)
  local qw = ball:previous_orientation()
  assert(qw == 1)
  b:destroy()
  raises("destroyed", b.previous_position, b)
end)

test("velocity changes inside a contact callback take effect once, after it", function()
  local w = carom.world{ gravity = {0, 0, 0} }
  local a = w:add_body{ shape = carom.sphere{ radius = 0.5 }, position = {-0.55, 0, 0}, velocity = {1, 0, 0}, sleep = false }
  local b = w:add_body{ shape = carom.sphere{ radius = 0.5 }, position = {0.55, 0, 0}, velocity = {-1, 0, 0}, sleep = false }
  local by = w:add_body{ shape = carom.sphere{ radius = 0.5 }, position = {0, 10, 0}, sleep = false }
  local calls = 0
  w:set_contact_callback(function(e)
    if e.type == "begin" then
      calls = calls + 1
      by:apply_impulse(0, 2, 0)
      by:set_velocity(by:velocity()) -- read before the queued impulse: (0, 0, 0), applied after it
      by:apply_impulse(0, 0, 3)
    end
  end)
  w:step(1/60, 30)
  assert(calls == 1)
  local vx, vy, vz = by:velocity()
  near(vy, 0, 0, "set_velocity ran after the first impulse")
  near(vz, 3 / by:mass(), 1e-15, "the last impulse, once")
  raises("finite", function()
    w:set_contact_callback(function(e) by:apply_impulse(0 / 0, 0, 0) end)
    w:add_body{ shape = carom.sphere{ radius = 0.5 }, position = {3, 0, 0}, velocity = {-3, 0, 0} }
    w:add_body{ shape = carom.sphere{ radius = 0.5 }, position = {1.9, 0, 0} }
    w:step(1/60, 30)
  end)
end)

test("sensors: sensor_begin / sensor_end with sensor and other, no response", function()
  local w = carom.world{}
  local zone = w:add_body{ type = "static", sensor = true, shape = carom.box{ half_extents = {1, 1, 0.5} }, position = {0, 0, 5} }
  local ball = w:add_body{ shape = carom.sphere{ radius = 0.25 }, position = {0, 0, 8} }
  assert(zone:is_sensor() and not ball:is_sensor())
  local seen = {}
  w:set_contact_callback(function(e)
    if e.type == "sensor_begin" or e.type == "sensor_end" then
      assert(e.sensor == zone and e.other == ball)
      seen[#seen + 1] = e.type
    end
  end)
  w:step(1/60, 90)
  assert(#seen == 2 and seen[1] == "sensor_begin" and seen[2] == "sensor_end", table.concat(seen, ","))
  -- free fall through it: z = 8 - g t^2 / 2 to the integrator's O(dt)
  local _, _, z = ball:position()
  local t = 1.5
  assert(math.abs(z - (8 - 9.81 * t * t / 2)) < 0.2, z)
  local hits = w:ray_cast_all({0, 0, 10}, {0, 0, -20})
  for _, h in ipairs(hits) do assert(h.body ~= zone, "queries do not see sensors") end
end)

test("pre-solve: a one-way platform", function()
  local w = carom.world{}
  w:add_body{ type = "static", shape = carom.box{ half_extents = {5, 5, 0.5} }, position = {0, 0, -0.5} }
  local plat = w:add_body{ type = "static", shape = carom.box{ half_extents = {2, 2, 0.1} }, position = {0, 0, 2} }
  local ball = w:add_body{ shape = carom.sphere{ radius = 0.25 }, position = {0, 0, 0.25}, velocity = {0, 0, 8}, sleep = false }
  local calls = 0
  w:set_pre_solve(function(a, b, m)
    calls = calls + 1
    assert(m.normal and #m.points >= 1 and #m.separations == #m.points)
    local other = a == plat and b or a
    if a ~= plat and b ~= plat then return true end
    local _, _, z = other:position()
    return z - 0.25 >= 2.05 -- false while it comes up through
  end)
  w:step(1/60, 240)
  local _, _, z = ball:position()
  near(z, 2.35, 0.01, "resting on the platform")
  assert(calls > 0)
  local cs = ball:contacts()
  assert(#cs == 1 and cs[1].other == plat and math.abs(cs[1].normal[3] + 1) < 1e-9)
  near(cs[1].impulse, ball:mass() * 9.81 / 60, 0.01 * ball:mass() * 9.81 / 60, "m g dt")
  -- an error in it is raised by step, a table as itself
  w:set_pre_solve(function() error({ why = "no" }) end)
  local ok, err = pcall(w.step, w, 1/60)
  assert(not ok and type(err) == "table" and err.why == "no")
  w:set_pre_solve(nil)
  w:step(1/60)
  raises("function or nil", w.set_pre_solve, w, 3)
end)

test("set_pair_filter: contacts and continuous collision, errors raised by step", function()
  local w, g, ball = ground_and_ball({}, { position = {0, 0, 1} })
  local calls = 0
  w:set_pair_filter(function(a, b)
    calls = calls + 1
    assert((a == g and b == ball) or (a == ball and b == g))
    return false
  end)
  w:step(1/60, 60)
  local _, _, z = ball:position()
  assert(z < 0 and calls > 0, "refused: it falls through the ground")
  w:set_pair_filter(nil)
  ball:set_position(0, 0, 1)
  ball:set_velocity(0, 0, 0)
  w:step(1/60, 90)
  _, _, z = ball:position()
  near(z, 0.25, 0.01, "allowed again: it lands")
  -- a bullet through a thin wall the filter refuses (continuous collision asks it too)
  local space = carom.world{ gravity = {0, 0, 0} }
  local wall = space:add_body{ type = "static", shape = carom.box{ half_extents = {0.05, 2, 2} }, position = {5, 0, 0} }
  local bullet = space:add_body{ shape = carom.sphere{ radius = 0.1 }, velocity = {300, 0, 0}, bullet = true }
  space:set_pair_filter(function(a, b) return a ~= wall and b ~= wall end)
  space:step(1/60, 10)
  assert(bullet:position() > 40)
  -- errors: a table keeps its value; destroying inside is refused with an error
  local w2, _, b2 = ground_and_ball({}, { position = {0, 0, 1} })
  w2:set_pair_filter(function() error({ why = "filter" }) end)
  local ok, err = pcall(w2.step, w2, 1/60, 60)
  assert(not ok and type(err) == "table" and err.why == "filter")
  w2:set_pair_filter(function(a) a:destroy(); return true end)
  b2:set_position(3, 0, 1)
  ok, err = pcall(w2.step, w2, 1/60, 60)
  assert(not ok and tostring(err):find("destroy", 1, true), tostring(err))
  assert(#w2:bodies() == 2, "nothing destroyed")
  raises("function or nil", w2.set_pair_filter, w2, 5)
  w2:set_pair_filter(nil)
  w2:step(1/60)
end)

test("the part hit, 1-based: ray_cast_all, shape_cast, overlap and contacts name compound children", function()
  local w = carom.world{ gravity = {0, 0, 0} }
  -- three spheres of radius 0.25 at x = -1, 0, 1 (children 1, 2, 3)
  local function spheres(at)
    local c = {}
    for i = 1, 3 do c[i] = { shape = carom.sphere{ radius = 0.25 }, position = {i - 2, 0, 0} } end
    return w:add_body{ type = "static", shape = carom.compound(c), position = at }
  end
  local a, b = spheres{0, 0, 0}, spheres{2, 5, 0}
  local plain = w:add_body{ type = "static", shape = carom.sphere{ radius = 0.25 }, position = {1, 8, 0} }
  -- along +y at x = 1: a's child 3, b's child 1 (at x = 2 - 1), the plain sphere
  local hits = w:ray_cast_all({1, -3, 0}, {0, 12, 0})
  assert(#hits == 3, #hits .. " hits")
  assert(hits[1].body == a and hits[1].child == 3, "a: child " .. tostring(hits[1].child))
  assert(hits[2].body == b and hits[2].child == 1, "b: child " .. tostring(hits[2].child))
  assert(hits[3].body == plain and hits[3].child == nil, "a sphere has no parts")
  near(hits[2].fraction, 7.75 / 12, 1e-12, "b's fraction")
  -- a ball swept along +x touches a's child 1 first (at x = -1.5: fraction 1.5 / 6);
  -- down at x = 0.6 it passes child 2 and lands on child 3 (0.3 above its centre)
  local ball = carom.sphere{ radius = 0.25 }
  local body, fraction, _, _, child = w:shape_cast(ball, {-3, 0, 0}, nil, {6, 0, 0})
  assert(body == a and child == 1, "swept along +x: child " .. tostring(child))
  near(fraction, 0.25, 1e-9, "along +x")
  body, fraction, _, _, child = w:shape_cast(ball, {0.6, 0, 3}, nil, {0, 0, -6})
  assert(body == a and child == 3, "swept down: child " .. tostring(child))
  near(fraction, 2.7 / 6, 1e-9, "down")
  body, _, _, _, child = w:shape_cast(ball, {1, 8, 3}, nil, {0, 0, -6})
  assert(body == plain and child == nil)
  -- overlap: the second table names the lowest part overlapped, nil for one-part bodies
  local bodies, children = w:overlap(carom.box{ half_extents = {0.3, 0.3, 0.3} }, {0.5, 0, 0})
  assert(#bodies == 1 and bodies[1] == a and children[1] == 2, "children 2 and 3 overlapped: " .. tostring(children[1]))
  bodies, children = w:overlap(carom.box{ half_extents = {0.3, 4.5, 0.3} }, {1, 4, 0})
  assert(#bodies == 3 and bodies[1] == a and bodies[2] == b and bodies[3] == plain)
  assert(children[1] == 3 and children[2] == 1 and children[3] == nil)
  bodies, children = w:overlap(carom.box{ half_extents = {0.3, 0.3, 0.3} }, {0, 0, 5})
  assert(#bodies == 0 and next(children) == nil)

  -- contacts: a floor of two boxes (child 1 under x > 0, child 2 under x < 0),
  -- a compound (child 1 a ball on top, child 2 a slab) on child 1, a ball on child 2
  local g = carom.world{}
  local floor = g:add_body{ type = "static", shape = carom.compound{
    { shape = carom.box{ half_extents = {1, 1, 0.5} }, position = {1, 0, -0.5} },
    { shape = carom.box{ half_extents = {1, 1, 0.5} }, position = {-1, 0, -0.5} } } }
  local slab = g:add_body{ shape = carom.compound{
    { shape = carom.sphere{ radius = 0.2 }, position = {0, 0, 0.3} },
    { shape = carom.box{ half_extents = {0.3, 0.3, 0.1} } } }, position = {1, 0, 0.1} }
  local lone = g:add_body{ shape = carom.sphere{ radius = 0.25 }, position = {-1, 0, 0.25} }
  g:step(1 / 60, 30)
  local cs = slab:contacts()
  assert(#cs >= 1)
  for _, c in ipairs(cs) do
    assert(c.other == floor and c.child == 2 and c.other_child == 1,
           "slab: " .. tostring(c.child) .. " on " .. tostring(c.other_child))
  end
  cs = lone:contacts()
  assert(#cs == 1 and cs[1].other == floor and cs[1].child == nil and cs[1].other_child == 2)
  local under_slab, under_ball = 0, 0
  for _, c in ipairs(floor:contacts()) do
    if c.other == slab then
      under_slab = under_slab + 1
      assert(c.child == 1 and c.other_child == 2)
    else
      under_ball = under_ball + 1
      assert(c.other == lone and c.child == 2 and c.other_child == nil)
    end
  end
  assert(under_slab == #slab:contacts() and under_ball == 1)
end)

T.finish()
