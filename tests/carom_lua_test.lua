-- carom_lua_test.lua - every line of the Lua contract (docs/lua.md, "The
-- contract") and every error path of the bindings. Values are checked against
-- hand computations (free fall, impulse / mass, inertia of a box ...), never
-- against what the code printed. Run by `make check` as
-- `carom-run --test tests/carom_lua_test.lua`; ends with "N passed, M failed".
local carom = require "carom"
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test, near, raises = T.test, T.near, T.raises

local G = 9.81
local function sphere(r) return carom.sphere{ radius = r or 0.5 } end
local function cube(h) h = h or 0.5; return carom.box{ half_extents = {h, h, h} } end
local function zero_g(opts)
  opts = opts or {}
  opts.gravity = {0, 0, 0}
  return carom.world(opts)
end

---------------------------------------------------------------------------
-- the contract, line by line
---------------------------------------------------------------------------

test("carom.world with the contract's options; settings() reads them back", function()
  local world = carom.world{ gravity = {0,0,-9.81}, substeps = 4, iterations = 1,
                             ccd = true, sleep = true, contact_model = "impulse", preset = "default" }
  local s = world:settings()
  near(s.gravity[3], -9.81, 0, "gravity z")
  assert(s.substeps == 4 and s.iterations == 1, "substeps/iterations")
  assert(s.ccd == true and s.sleep == true and s.contact_model == "impulse")
  local w2 = carom.world{ ccd = false, sleep = false, contact_model = "penalty", position_correction = "baumgarte",
                          hertz = 60, damping_ratio = 2, warm_starting = false, shock_propagation = false,
                          friction = false, restitution = false, restitution_threshold = 0.5, relax_iterations = 2,
                          hit_event_threshold = 0.25 }
  local s2 = w2:settings()
  assert(s2.ccd == false and s2.sleep == false and s2.contact_model == "penalty")
  assert(s2.position_correction == "baumgarte" and s2.warm_starting == false and s2.shock_propagation == false)
  assert(s2.friction == false and s2.restitution == false and s2.relax_iterations == 2)
  near(s2.hertz, 60, 0, "hertz"); near(s2.damping_ratio, 2, 0, "damping_ratio")
  near(s2.restitution_threshold, 0.5, 0, "restitution_threshold")
  near(s2.hit_event_threshold, 0.25, 0, "hit_event_threshold")
  assert(carom.world():settings().substeps == 4, "no options: the defaults")
end)

test("presets change the solver; explicit keys win over the preset", function()
  local default = carom.world{ preset = "default" }:settings()
  local fast = carom.world{ preset = "fast" }:settings()
  local accurate = carom.world{ preset = "accurate" }:settings()
  local function cost(s) return s.substeps * (s.iterations + s.relax_iterations) end
  assert(cost(fast) < cost(default) and cost(default) < cost(accurate),
         string.format("fast %d < default %d < accurate %d", cost(fast), cost(default), cost(accurate)))
  local mixed = carom.world{ preset = "accurate", substeps = 3, iterations = 2 }:settings()
  assert(mixed.substeps == 3 and mixed.iterations == 2, "explicit substeps/iterations win")
  assert(mixed.relax_iterations == accurate.relax_iterations, "the rest from the preset")
end)

test("add_body with every contract key; static plane; types", function()
  local world = carom.world{}
  local ground = world:add_body{ type = "static", shape = carom.plane{ normal = {0,0,1}, offset = 0 } }
  local ball = world:add_body{ type = "dynamic", position = {0,0,1}, velocity = {1,0,0},
      orientation = {1,0,0,0}, angular_velocity = {0,0,0}, shape = carom.sphere{ radius = 0.1 },
      mass = 1.0, restitution = 0.5, friction = 0.3, bullet = false, lock_rotation = false }
  assert(ground:type() == "static" and ball:type() == "dynamic")
  assert(ground:shape_type() == "plane" and ball:shape_type() == "sphere")
  near(ball:mass(), 1, 0, "mass"); near(ground:mass(), 0, 0, "a static body's mass")
  near(ball:restitution(), 0.5, 0, "restitution"); near(ball:friction(), 0.3, 0, "friction")
  local x, y, z = ball:position()
  assert(x == 0 and y == 0 and z == 1)
  local kin = world:add_body{ type = "kinematic", shape = cube(), position = {5, 0, 3}, velocity = {0, 1, 0} }
  world:step(1/60, 60)
  local kx, ky, kz = kin:position()
  near(ky, 1, 1e-9, "a kinematic body moves at its velocity"); near(kz, 3, 0, "and ignores gravity")
end)

test("density: mass = density x volume", function()
  local world = carom.world{}
  near(world:add_body{ shape = cube(0.5), density = 1000 }:mass(), 1000, 1e-9, "unit cube of water")
  near(world:add_body{ shape = sphere(0.5), position = {3, 0, 0}, density = 2 }:mass(),
       2 * 4 / 3 * math.pi * 0.125, 1e-12, "sphere")
  near(world:add_body{ shape = sphere(0.5), position = {6, 0, 0} }:mass(), 1000 * 4 / 3 * math.pi * 0.125, 1e-9,
       "default density 1000")
end)

test("step(dt): free fall matches v = g t; step(dt, n) equals n single steps bit for bit", function()
  local function drop()
    local w = carom.world{}
    return w, w:add_body{ position = {0, 0, 10}, velocity = {1, 0, 0}, shape = sphere(0.1), mass = 1 }
  end
  local w1, b1 = drop()
  local w2, b2 = drop()
  w1:step(1/60, 30)
  for _ = 1, 30 do w2:step(1/60) end
  local x1, y1, z1 = b1:position()
  local x2, y2, z2 = b2:position()
  assert(x1 == x2 and y1 == y2 and z1 == z2, "same states")
  local vx, vy, vz = b1:velocity()
  near(vx, 1, 1e-12, "vx unchanged in free flight")
  near(vz, -G * 0.5, 1e-9, "vz = -g t")
  near(x1, 0.5, 1e-9, "x = vx t")
  -- semi-implicit Euler falls a little further than g t^2 / 2; the excess is below g t dt
  local drop_z = 10 - z1
  assert(drop_z >= 0.5 * G * 0.25 - 1e-9 and drop_z <= 0.5 * G * 0.25 + G * 0.5 / 60, "fall " .. drop_z)
  w1:step(1/60, 0) -- zero steps: nothing happens
  local _, _, z3 = b1:position()
  assert(z3 == z1)
end)

test("orientation: unit quaternion, w first; spin about z integrates to the angle", function()
  local world = zero_g()
  local b = world:add_body{ shape = cube(), angular_velocity = {0, 0, 2} }
  local qw, qx, qy, qz = b:orientation()
  assert(qw == 1 and qx == 0 and qy == 0 and qz == 0, "identity at the start")
  world:step(1/60, 60) -- 1 s at 2 rad/s: a rotation of 2 rad about z
  qw, qx, qy, qz = b:orientation()
  near(qw * qw + qx * qx + qy * qy + qz * qz, 1, 1e-12, "unit")
  near(qw, math.cos(1), 1e-3, "qw = cos(angle / 2)")
  near(qz, math.sin(1), 1e-3, "qz = sin(angle / 2)")
  local wx, wy, wz = b:angular_velocity()
  near(wz, 2, 1e-9, "a free cube keeps spinning about a principal axis")
  b:set_orientation(math.cos(0.25), 0, math.sin(0.25), 0)
  qw, qx, qy, qz = b:orientation()
  near(qy, math.sin(0.25), 1e-12, "set_orientation with four numbers")
  b:set_orientation{1, 0, 0, 0}
  assert(select(1, b:orientation()) == 1, "set_orientation with a table")
end)

test("setters take three numbers or a table", function()
  local world = zero_g()
  local b = world:add_body{ shape = sphere() }
  b:set_position(1, 2, 3)
  local x, y, z = b:position()
  assert(x == 1 and y == 2 and z == 3)
  b:set_position{4, 5, 6}
  x, y, z = b:position()
  assert(x == 4 and y == 5 and z == 6)
  b:set_position{ x = 7, y = 8, z = 9 }
  x, y, z = b:position()
  assert(x == 7 and y == 8 and z == 9, "named components")
  b:set_velocity(1, 0, 0)
  b:set_velocity{0, 2, 0}
  assert(select(2, b:velocity()) == 2)
  b:set_angular_velocity(0, 0, 3)
  assert(select(3, b:angular_velocity()) == 3)
end)

test("apply_impulse: dv = J / m at the centre; dw = I^-1 (r x J) at a point", function()
  local world = zero_g()
  local b = world:add_body{ shape = sphere(0.5), mass = 2 }
  b:apply_impulse(4, 0, 0)
  near(select(1, b:velocity()), 2, 1e-12, "J / m")
  b:apply_impulse({0, 0, 2})
  near(select(3, b:velocity()), 1, 1e-12, "table form")
  local c = world:add_body{ position = {10, 0, 0}, shape = sphere(0.5), mass = 1 } -- I = 2/5 m r^2 = 0.1
  c:apply_impulse(0, 1, 0, 10.5, 0, 0) -- r = (0.5, 0, 0): r x J = (0, 0, 0.5)
  local wx, wy, wz = c:angular_velocity()
  near(wz, 5, 1e-9, "spin from an off-centre impulse")
  near(select(2, c:velocity()), 1, 1e-12, "and the centre moves by J / m")
  c:apply_impulse({0, -1, 0}, {10.5, 0, 0})
  near(select(3, c:angular_velocity()), 0, 1e-9, "impulse and point as tables")
end)

test("apply_force acts for one step: dv = F dt / m", function()
  local world = zero_g()
  local b = world:add_body{ shape = sphere(), mass = 2 }
  b:apply_force(6, 0, 0)
  world:step(0.5)
  near(select(1, b:velocity()), 1.5, 1e-9, "F dt / m")
  world:step(0.5)
  near(select(1, b:velocity()), 1.5, 1e-9, "gone after the step")
end)

test("mass, set_mass, inertia of a box, kinetic energy", function()
  local world = zero_g()
  local b = world:add_body{ shape = carom.box{ half_extents = {0.5, 1, 1.5} }, mass = 12 }
  local I = b:inertia() -- m/3 (b^2 + c^2) with half extents: 13, 10, 5
  near(I[1][1], 13, 1e-9, "Ixx"); near(I[2][2], 10, 1e-9, "Iyy"); near(I[3][3], 5, 1e-9, "Izz")
  near(I[1][2], 0, 1e-12, "no products of inertia")
  b:set_velocity(1, 0, 0)
  b:set_angular_velocity(0, 0, 2)
  near(b:kinetic_energy(), 0.5 * 12 * 1 + 0.5 * 5 * 4, 1e-9, "1/2 m v^2 + 1/2 w.I.w")
  b:set_mass(24)
  near(b:mass(), 24, 1e-12, "set_mass")
  near(b:inertia()[3][3], 10, 1e-9, "inertia scales with the mass")
  local cx, cy, cz = b:center_of_mass()
  assert(cx == 0 and cy == 0 and cz == 0)
  assert(select(1, b:local_center()) == 0)
end)

test("world:energy() = kinetic, potential (m g z); world:momentum() = p, then L about the origin", function()
  local world = carom.world{}
  local b = world:add_body{ position = {0, 0, 1}, velocity = {3, 0, 0}, shape = sphere(0.1), mass = 2 }
  world:add_body{ type = "static", shape = carom.plane{} }
  local ke, pe = world:energy()
  near(ke, 0.5 * 2 * 9, 1e-12, "kinetic")
  near(pe, 2 * G * 1, 1e-12, "potential relative to z = 0")
  local px, py, pz, lx, ly, lz = world:momentum()
  near(px, 6, 1e-12, "px"); near(py, 0, 0, "py"); near(pz, 0, 0, "pz")
  near(ly, 6, 1e-12, "L = r x p = (0, 0, 1) x (6, 0, 0)")
  near(lx, 0, 1e-12, "lx"); near(lz, 0, 1e-12, "lz")
end)

test("is_valid and destroy; every method of a destroyed body raises 'body has been destroyed'", function()
  local world = carom.world{}
  local b = world:add_body{ shape = sphere() }
  assert(b:is_valid())
  b:destroy()
  assert(not b:is_valid())
  local calls = {
    {"position"}, {"orientation"}, {"velocity"}, {"angular_velocity"}, {"center_of_mass"}, {"local_center"},
    {"set_position", 1, 2, 3}, {"set_orientation", 1, 0, 0, 0}, {"set_velocity", 1, 2, 3},
    {"set_angular_velocity", 1, 2, 3}, {"apply_impulse", 1, 0, 0}, {"apply_force", 1, 0, 0}, {"mass"},
    {"set_mass", 2}, {"inertia"}, {"kinetic_energy"}, {"friction"}, {"set_friction", 0.1}, {"restitution"},
    {"set_restitution", 0.1}, {"set_gravity_scale", 1}, {"set_bullet", true}, {"type"}, {"set_type", "static"},
    {"shape_type"}, {"is_awake"}, {"set_awake", true}, {"data"}, {"set_data", 1}, {"destroy"},
  }
  for _, c in ipairs(calls) do
    local m = c[1]
    raises("body has been destroyed", b[m], b, table.unpack(c, 2))
    raises("to '" .. m .. "'", b[m], b, table.unpack(c, 2))
  end
  raises("body has been destroyed", function() return b.user_data end)
  raises("body has been destroyed", function() b.user_data = 1 end)
  assert(tostring(b):find("destroyed"), "tostring still works")
  assert(b:id() >= 1, "the id is still readable")
  assert(world:body_count() == 0)
end)

test("world:events(): a hit with impulse m v, force J / dt, speed, point, normal; a and b are the script's bodies", function()
  local world = zero_g()
  local wall = world:add_body{ type = "static", position = {1.025, 0, 0}, shape = carom.box{ half_extents = {0.025, 2, 2} } }
  local ball = world:add_body{ velocity = {10, 0, 0}, shape = sphere(0.05), mass = 0.5 }
  local hit, kinds = nil, {}
  for _ = 1, 30 do
    world:step(1/60)
    for _, e in ipairs(world:events()) do
      kinds[e.type] = true
      if e.type == "hit" then hit = e end
    end
  end
  assert(hit, "a hit event")
  assert(kinds.begin, "a begin event")
  assert((hit.a == ball and hit.b == wall) or (hit.a == wall and hit.b == ball), "a and b are the two bodies")
  assert(rawequal(hit.a, ball) or rawequal(hit.b, ball), "the very same userdata as the script holds")
  near(hit.impulse, 0.5 * 10, 0.05, "impulse stops the ball (e = 0)")
  near(hit.force, hit.impulse * 60, 1e-6, "force = J / dt")
  near(hit.speed, 10, 0.05, "approach speed")
  assert(#hit.point == 3 and #hit.normal == 3)
  near(math.abs(hit.normal[1]), 1, 1e-9, "normal along x")
  near(hit.point[1], 1.0, 0.06, "the contact point is on the wall's face")
  assert(type(hit.tangent_impulse) == "number")
  world:step(1/60)
  assert(type(world:events()) == "table")
end)

test("world:stats(): bodies, pairs, contacts, max_penetration, ms per stage", function()
  local world = carom.world{}
  world:add_body{ type = "static", shape = carom.plane{} }
  world:add_body{ position = {0, 0, 0.5}, shape = cube() }
  world:step(1/60, 10)
  local st = world:stats()
  assert(st.bodies == 2 and st.pairs >= 1 and st.contacts == 1 and st.contact_points == 4,
         string.format("bodies %d pairs %d contacts %d points %d", st.bodies, st.pairs, st.contacts, st.contact_points))
  assert(st.max_penetration >= 0 and st.max_penetration < 0.02, "max_penetration " .. st.max_penetration)
  for _, k in ipairs{"ms_broadphase", "ms_narrowphase", "ms_solver", "ms_continuous", "ms_islands", "ms_total"} do
    assert(type(st[k]) == "number" and st[k] >= 0, "stats." .. k)
  end
  assert(st.steps == 10, "step count")
  assert(world:measure_penetration() < 0.02)
end)

test("world:advance(frame_dt): fixed steps from an accumulator, alpha, and a cap on the backlog", function()
  local world = carom.world{ dt = 0.01, max_steps = 5 }
  local steps, alpha = world:advance(0.025)
  assert(steps == 2, "two whole steps in 25 ms"); near(alpha, 0.5, 1e-9, "alpha")
  steps, alpha = world:advance(0.006)
  assert(steps == 1, "the remainder carries over"); near(alpha, 0.1, 1e-9, "alpha")
  steps, alpha = world:advance(0)
  assert(steps == 0); near(alpha, 0.1, 1e-9, "alpha unchanged")
  steps, alpha = world:advance(1.0) -- 100 steps behind: only max_steps run, the rest is dropped
  assert(steps == 5, "capped at max_steps")
  assert(alpha >= 0 and alpha < 1, "alpha in [0, 1)")
  steps = world:advance(0.01)
  assert(steps <= 2, "no spiral of death: the backlog was dropped")
  assert(world:stats().steps == 3 + 5 + steps)
  local default = carom.world{}
  steps = default:advance(1 / 30 + 1e-9)
  assert(steps == 2, "default fixed dt is 1/60")
  world:configure{ dt = 0.02 }
  assert(world:settings().dt == 0.02)
end)

test("ray_cast and query_aabb", function()
  local world = zero_g()
  local box = world:add_body{ position = {5, 0, 0}, shape = carom.box{ half_extents = {1, 1, 1} } }
  local body, point, normal, fraction = world:ray_cast({0, 0, 0}, {10, 0, 0})
  assert(body == box and rawequal(body, box), "the ray hits the box")
  near(point[1], 4, 1e-9, "hit point x"); near(normal[1], -1, 1e-9, "normal"); near(fraction, 0.4, 1e-9, "fraction")
  body = world:ray_cast(0, 0, 0, 10, 0, 0)
  assert(body == box, "six numbers")
  assert(world:ray_cast({0, 0, 0}, {0, 10, 0}) == nil, "a miss is nil")
  local found = world:query_aabb({3.5, -0.5, -0.5}, {4.5, 0.5, 0.5})
  assert(#found == 1 and found[1] == box)
  assert(#world:query_aabb(-1, -1, -1, 1, 1, 1) == 0)
  raises("lower corner", world.query_aabb, world, {1, 1, 1}, {0, 0, 0})
end)

test("bodies() lists the live bodies in id order, also after their userdata were collected", function()
  local world = zero_g()
  for i = 1, 50 do world:add_body{ position = {3 * i, 0, 0}, shape = sphere(), user_data = i } end
  collectgarbage("collect")
  local all = world:bodies()
  assert(#all == 50)
  for i = 2, #all do assert(all[i - 1]:id() < all[i]:id(), "id order") end
  for i, b in ipairs(all) do assert(b.user_data == i, "user data kept while no Lua value held the body") end
  all[10]:destroy()
  assert(#world:bodies() == 49 and world:body_count() == 49)
end)

test("user data: add_body{user_data} or {data}, body.user_data, data()/set_data()", function()
  local world = zero_g()
  local t = { name = "ball" }
  local a = world:add_body{ shape = sphere(), user_data = t }
  local b = world:add_body{ shape = sphere(), position = {5, 0, 0}, data = 42 }
  assert(a.user_data == t and a:data() == t and b.user_data == 42)
  a.user_data = "x"
  assert(a:data() == "x")
  b:set_data(nil)
  assert(b.user_data == nil)
  raises("cannot set field 'colour'", function() a.colour = "red" end)
  raises("not both", world.add_body, world, { shape = sphere(), data = 1, user_data = 2 })
  assert(a.no_such_method == nil)
  -- the same userdata comes back from queries, with its data
  local q = world:query_aabb({-1, -1, -1}, {1, 1, 1})[1]
  assert(rawequal(q, a) and q.user_data == "x")
  a:destroy()
  local c = world:add_body{ shape = sphere() }
  assert(c.user_data == nil, "a new body does not inherit a destroyed one's data")
end)

test("planar lock and rotation lock", function()
  local world = carom.world{}
  world:add_body{ type = "static", shape = carom.plane{} }
  local p = world:add_body{ position = {0, 0, 1}, velocity = {1, 3, 0}, angular_velocity = {1, 2, 3},
                            shape = cube(), lock_to_plane = true, plane_normal = {0, 1, 0} }
  local r = world:add_body{ position = {3, 0, 1}, angular_velocity = {1, 2, 3}, shape = cube(), lock_rotation = true }
  world:step(1/60, 60)
  local _, y = p:position()
  near(y, 0, 1e-12, "stays in the x-z plane")
  local _, vy = p:velocity()
  near(vy, 0, 1e-12, "no velocity out of the plane")
  local wx, _, wz = p:angular_velocity()
  near(wx, 0, 1e-12, "rotates only about the plane normal"); near(wz, 0, 1e-12, "wz")
  assert(select(1, r:orientation()) == 1, "a particle never rotates")
end)

test("gravity_scale, damping, bullet, sleep and awake", function()
  local world = carom.world{}
  local float = world:add_body{ shape = sphere(), gravity_scale = 0 }
  local damped = world:add_body{ position = {5, 0, 0}, shape = sphere(), gravity_scale = 0, velocity = {1, 0, 0}, damping = 1 }
  local fast = world:add_body{ position = {10, 0, 0}, shape = sphere(0.01), bullet = true, sleep = false }
  world:step(1/60, 60)
  assert(select(3, float:velocity()) == 0, "gravity_scale 0 floats")
  local vx = damped:velocity()
  assert(vx < 0.5 and vx > 0.2, "damping 1/s leaves about e^-1 after 1 s: " .. vx)
  float:set_gravity_scale(2)
  world:step(0.1)
  near(select(3, float:velocity()), -2 * G * 0.1, 1e-9, "gravity_scale 2")
  fast:set_bullet(false)
  local sleeper = world:add_body{ position = {20, 0, 0}, shape = sphere(), gravity_scale = 0, awake = false }
  assert(not sleeper:is_awake(), "awake = false")
  sleeper:set_awake(true); assert(sleeper:is_awake())
  sleeper:set_awake(false); assert(not sleeper:is_awake())
  sleeper:apply_impulse(1, 0, 0)
  assert(sleeper:is_awake(), "an impulse wakes a body")
end)

test("set_type, set_friction, set_restitution", function()
  local world = carom.world{}
  local b = world:add_body{ shape = sphere() }
  b:set_type("kinematic"); assert(b:type() == "kinematic"); near(b:mass(), 0, 0, "kinematic mass 0")
  b:set_type("static"); assert(b:type() == "static")
  b:set_type("dynamic"); assert(b:type() == "dynamic"); assert(b:mass() > 0)
  b:set_friction(0.2); near(b:friction(), 0.2, 0, "friction")
  b:set_restitution(0.7); near(b:restitution(), 0.7, 0, "restitution")
end)

---------------------------------------------------------------------------
-- shapes
---------------------------------------------------------------------------

test("every shape, by name and by position; tostring, fields, __eq, immutable", function()
  local world = carom.world{}
  world:add_body{ type = "static", shape = carom.plane{ normal = {0, 0, 1} } }
  local shapes = {
    carom.sphere{ radius = 0.3 }, carom.box{ half_extents = {0.2, 0.3, 0.4} },
    carom.capsule{ radius = 0.2, half_height = 0.3 }, carom.cylinder{ radius = 0.3, half_height = 0.2 },
    carom.hull{ points = {{0,0,0},{1,0,0},{0,1,0},{0,0,1},{0.2,0.2,0.2}} },
  }
  local bodies = {}
  for i, s in ipairs(shapes) do bodies[i] = world:add_body{ position = {2 * i, 0, 1}, shape = s, mass = 2 } end
  world:step(1/60, 120)
  for i, b in ipairs(bodies) do
    local _, _, z = b:position()
    assert(z > -0.01 and z < 1, "shape " .. i .. " rests on the ground, z = " .. z)
  end
  assert(carom.sphere{0.3} == shapes[1], "positional radius")
  assert(carom.box{{0.2, 0.3, 0.4}} == shapes[2], "positional half extents")
  assert(carom.capsule{0.2, 0.3} == shapes[3] and carom.cylinder{0.3, 0.2} == shapes[4])
  assert(carom.hull{{0,0,0},{1,0,0},{0,1,0},{0,0,1},{0.2,0.2,0.2}} == shapes[5], "points given directly")
  assert(carom.plane{{0, 1, 0}, 2} == carom.plane{ normal = {0, 1, 0}, offset = 2 })
  assert(carom.sphere{0.3} ~= carom.sphere{0.4} and shapes[1] ~= shapes[2])
  assert(tostring(shapes[1]) == "carom.sphere{radius = 0.3}", tostring(shapes[1]))
  assert(tostring(shapes[5]) == "carom.hull{5 points}")
  assert(tostring(carom.plane()) == "carom.plane{normal = {0, 0, 1}, offset = 0}", "plane() defaults to z = 0")
  assert(shapes[1].type == "sphere" and shapes[1].radius == 0.3)
  assert(shapes[2].half_extents[3] == 0.4 and shapes[3].half_height == 0.3 and shapes[5].point_count == 5)
  assert(shapes[1].half_extents == nil)
  raises("immutable", function() shapes[1].radius = 2 end)
  -- one descriptor, many bodies
  local s = sphere(0.25)
  for i = 1, 3 do world:add_body{ shape = s, position = {20 + i, 0, 1} } end
end)

---------------------------------------------------------------------------
-- error paths
---------------------------------------------------------------------------

test("mass = 0 means 'use density', as in C", function()
  local world = carom.world{}
  local b = world:add_body{ shape = carom.sphere{ radius = 0.5 }, mass = 0, density = 1000 }
  near(b:mass(), 1000 * 4 / 3 * math.pi * 0.125, 1e-9, "mass from density")
end)

test("argument errors name the function and the argument (self is #1)", function()
  local world = carom.world{}
  -- the same message whether called as a method or through pcall
  local m1 = raises("bad argument #2 to 'add_body' (mass must be finite and >= 0", world.add_body, world,
                    { shape = sphere(), mass = -1 })
  local ok, m2 = pcall(function() return world:add_body{ shape = sphere(), mass = -1 } end)
  -- called from Lua code, the message is prefixed with the caller's position, as luaL_argerror does
  assert(not ok and tostring(m2):sub(-#m1) == m1 and tostring(m2):find("carom_lua_test.lua:", 1, true), tostring(m2))
  raises("bad argument #1 to 'sphere' (sphere radius -1 is outside [1e-6, 1e6] m)", carom.sphere, { radius = -1 })
  raises("bad argument #2 to 'step' (dt must be in [1e-6, 1] seconds (got -1))", world.step, world, -1)
  raises("bad argument #1 to 'step' (carom.World expected, got number)", world.step, 5, 1/60)
  local b = world:add_body{ shape = sphere() }
  raises("bad argument #1 to 'position' (carom.Body expected, got carom.World)", b.position, world)
  raises("bad argument #3 to 'set_position' (number (vector component) expected, got string)", b.set_position, b, 1, "y", 3)
end)

test("shape errors: missing, negative, zero, NaN, inf, wrong types, unknown keys", function()
  raises("sphere radius 0 is outside [1e-6, 1e6] m", carom.sphere, { radius = 0 })
  raises("sphere radius 2e+06 is outside", carom.sphere, { radius = 2e6 })
  raises("radius must be finite", carom.sphere, { radius = 0/0 })
  raises("radius must be finite", carom.sphere, { radius = math.huge })
  raises("radius is required", carom.sphere, {})
  raises("radius must be a number, got string", carom.sphere, { radius = "big" })
  raises("table of options expected, got number", carom.sphere, 1)
  raises("table of options expected, got no value", carom.sphere)
  raises("unknown option 'radius'", carom.box, { radius = 1, half_extents = {1, 1, 1} })
  raises("half_extents is required", carom.box, {})
  raises("box half extents (1, -1, 1) must each be in [1e-6, 1e6] m", carom.box, { half_extents = {1, -1, 1} })
  raises("box half extents (1, 0, 1) must each be in", carom.box, { half_extents = {1, 0, 1} })
  raises("half_extents must be finite", carom.box, { half_extents = {1, 0/0, 1} })
  raises("half_extents must be a vector", carom.box, { half_extents = {1, 1} })
  raises("half_extents must be a vector", carom.box, { half_extents = 1 })
  raises("capsule half_height -1 is outside", carom.capsule, { radius = 1, half_height = -1 })
  raises("half_height is required", carom.cylinder, { radius = 1 })
  raises("given twice", carom.capsule, { 0.1, 0.2, radius = 0.1 })
  raises("too many values", carom.sphere, { 1, 2 })
  raises("option names must be strings", carom.sphere, { [true] = 1 })
  raises("a hull needs 4..100000 points (got 1)", carom.hull, { points = {{0,0,0}} })
  raises("hull point 3 has coordinate 2e+06", carom.hull, { points = {{0,0,0}, {1,0,0}, {0,1,0}, {0,0,2e6}} })
  raises("point 2 is not a vector", carom.hull, { points = {{0,0,0}, 5, {0,1,0}, {0,0,1}} })
  raises("point 3 is not finite", carom.hull, { points = {{0,0,0}, {1,0,0}, {0,0/0,0}, {0,0,1}} })
  raises("points must be a table", carom.hull, { points = "many" })
  raises("plane normal must be finite with length >= 1e-12", carom.plane, { normal = {0,0,0} })
  raises("plane offset 1e+13 is outside [-1e12, 1e12] m", carom.plane, { offset = 1e13 })
  raises("offset must be finite", carom.plane, { offset = 1/0 })
end)

test("add_body errors: each key, the world's own checks, and an unchanged world", function()
  local world = carom.world{}
  local s = sphere()
  local cases = {
    { "shape is required", {} },
    { "shape must be made by carom.sphere", { shape = "ball" } },
    { "shape must be made by carom.sphere", { shape = world } },
    { "unknown option 'colour'", { shape = s, colour = "red" } },
    { "type must be \"static\", \"kinematic\" or \"dynamic\"", { shape = s, type = "floaty" } },
    { "position must be finite", { shape = s, position = {0/0, 0, 0} } },
    { "position must be a vector", { shape = s, position = {0, 0} } },
    { "velocity must be finite", { shape = s, velocity = {1/0, 0, 0} } },
    { "orientation must be a quaternion", { shape = s, orientation = {1, 0, 0} } },
    { "orientation", { shape = s, orientation = {2, 0, 0, 0} } },
    { "mass must be finite and >= 0", { shape = s, mass = -1 } },
    { "mass must be finite", { shape = s, mass = 0/0 } },
    { "density must be finite and >= 0", { shape = s, density = -5 } },
    { "restitution", { shape = s, restitution = 2 } },
    { "restitution", { shape = s, restitution = -0.1 } },
    { "friction", { shape = s, friction = -1 } },
    { "bullet must be a boolean, got number", { shape = s, bullet = 1 } },
    { "lock_rotation must be a boolean", { shape = s, lock_rotation = "yes" } },
    { "plane_normal", { shape = s, lock_to_plane = true, plane_normal = {0, 0, 0} } },
    { "a plane can only be a static body", { shape = carom.plane{} } },
    { "coplanar", { shape = carom.hull{ points = {{0,0,0},{1,0,0},{0,1,0},{1,1,0}} } } },
    { "option names must be strings", { shape = s, [1] = 2 } },
  }
  for _, c in ipairs(cases) do
    local msg = raises(c[1], world.add_body, world, c[2])
    assert(msg:find("bad argument #2 to 'add_body'", 1, true), msg)
  end
  raises("bad argument #2 to 'add_body' (table of options expected, got number)", world.add_body, world, 42)
  assert(world:body_count() == 0, "no body was made by a rejected call")
end)

test("world option errors", function()
  raises("bad argument #1 to 'world' (substeps", carom.world, { substeps = 0 })
  raises("substeps must be an integer", carom.world, { substeps = 1.5 })
  raises("preset must be \"fast\", \"default\" or \"accurate\"", carom.world, { preset = "turbo" })
  raises("contact_model must be \"impulse\" or \"penalty\"", carom.world, { contact_model = "springy" })
  raises("position_correction must be", carom.world, { position_correction = 1 })
  raises("unknown option 'gravitee'", carom.world, { gravitee = 1 })
  raises("gravity must be finite", carom.world, { gravity = {0, 0, 0/0} })
  raises("ccd must be a boolean", carom.world, { ccd = 1 })
  raises("dt must be in (0, 1]", carom.world, { dt = 0 })
  raises("max_steps must be in", carom.world, { max_steps = 0 })
  raises("table of options expected, got string", carom.world, "big")
  local w = carom.world{}
  raises("bad argument #2 to 'configure' (unknown option 'colour')", w.configure, w, { colour = 1 })
  raises("bad argument #2 to 'configure'", w.configure, w, { iterations = -3 })
  assert(w:settings().iterations == 1, "a rejected configure changes nothing")
  w:configure{ substeps = 8, gravity = {0, 0, -1} }
  assert(w:settings().substeps == 8 and w:settings().gravity[3] == -1)
end)

test("method argument errors: wrong types, NaN, inf, out of range", function()
  local world = carom.world{}
  local b = world:add_body{ shape = sphere() }
  raises("dt must be in", world.step, world, 0)
  raises("number must be finite", world.step, world, 0/0)
  raises("number expected, got string", world.step, world, "fast")
  raises("number expected, got no value", world.step, world)
  raises("bad argument #3 to 'step' (number must be an integer)", world.step, world, 1/60, 1.5)
  raises("bad argument #3 to 'step' (must be in 0..", world.step, world, 1/60, -1)
  raises("frame time must not be negative", world.advance, world, -1)
  raises("number must be finite", world.advance, world, 1/0)
  raises("vector (3 numbers or {x, y, z}) expected, got string", b.set_position, b, "x", 0, 0)
  raises("vector components must be finite", b.set_velocity, b, 1/0, 0, 0)
  raises("vector components must be finite", b.set_velocity, b, {0, 0/0, 0})
  raises("expected a vector {x, y, z} of 3 numbers", b.set_angular_velocity, b, {1, 2})
  raises("mass must be positive", b.set_mass, b, -3)
  raises("mass must be positive", b.set_mass, b, 0)
  raises("number must be finite", b.set_mass, b, 0/0)
  raises("restitution must be in [0, 1]", b.set_restitution, b, 3)
  raises("friction must not be negative", b.set_friction, b, -0.5)
  raises("expected a quaternion {w, x, y, z}", b.set_orientation, b, {1, 2})
  raises("bad argument #2 to 'set_orientation'", b.set_orientation, b, 2, 0, 0, 0) -- not unit
  raises("expected \"static\", \"kinematic\" or \"dynamic\", got rocket", b.set_type, b, "rocket")
  raises("boolean expected, got number", b.set_awake, b, 1)
  raises("boolean expected, got nil", b.set_bullet, b, nil)
  raises("bad argument #5 to 'apply_impulse'", b.apply_impulse, b, 1, 0, 0, "here")
  raises("function or nil expected, got number", world.set_contact_callback, world, 3)
  raises("bad argument #3 to 'ray_cast' (vector (3 numbers or {x, y, z}) expected, got string)", world.ray_cast, world, {0, 0, 0}, "up")
  assert(world:body_count() == 1)
  local x, y, z = b:position()
  assert(x == 0 and y == 0 and z == 0, "rejected calls changed nothing")
end)

test("metatables are locked", function()
  local world = carom.world{}
  local b = world:add_body{ shape = sphere() }
  assert(getmetatable(world) == "locked" and getmetatable(b) == "locked" and getmetatable(sphere()) == "locked")
end)

---------------------------------------------------------------------------
-- callbacks
---------------------------------------------------------------------------

local function resting_scene()
  local world = carom.world{ sleep = false }
  world:add_body{ type = "static", shape = carom.plane{} }
  local ball = world:add_body{ position = {0, 0, 0.6}, velocity = {0, 0, -3}, shape = sphere(0.5) }
  return world, ball
end

test("contact callback: called per event with the same tables as events()", function()
  local world, ball = resting_scene()
  local seen = {}
  world:set_contact_callback(function(e) seen[#seen + 1] = e end)
  world:step(1/60, 10)
  assert(#seen > 0, "called")
  local hits = 0
  for _, e in ipairs(seen) do
    assert(e.type == "begin" or e.type == "end" or e.type == "hit")
    assert(e.a == ball or e.b == ball)
    if e.type == "hit" then hits = hits + 1 end
  end
  assert(hits == 1, "one impact")
  world:set_contact_callback(nil)
  local before = #seen
  world:step(1/60, 10)
  assert(#seen == before, "nil removes the callback")
end)

test("inside a callback: creating raises, setters raise (velocity changes are deferred), destroys are deferred, stepping and destroying the world raise", function()
  local world, ball = resting_scene()
  local results = {}
  world:set_contact_callback(function(e)
    if results.create then return end
    results.create = select(2, pcall(world.add_body, world, { shape = sphere(1), position = {9, 9, 9} }))
    results.set = select(2, pcall(ball.set_position, ball, 0, 0, 1))
    results.velocity = pcall(ball.set_velocity, ball, 0, 0, 0) -- velocity changes are deferred, not refused
    results.step = select(2, pcall(world.step, world, 1/60))
    results.advance = select(2, pcall(world.advance, world, 1/60))
    results.destroy_world = select(2, pcall(world.destroy, world))
    results.configure = select(2, pcall(world.configure, world, { substeps = 2 }))
    results.read = { ball:position() } -- reading is fine
  end)
  world:step(1/60, 5)
  assert(tostring(results.create):find("cannot create a body inside a contact callback", 1, true), tostring(results.create))
  assert(tostring(results.set):find("inside a contact callback", 1, true), tostring(results.set))
  assert(results.velocity == true)
  assert(tostring(results.step):find("inside its own contact callback", 1, true), tostring(results.step))
  assert(tostring(results.advance):find("inside its own contact callback", 1, true))
  assert(tostring(results.destroy_world):find("inside its own step", 1, true))
  assert(tostring(results.configure):find("inside a contact callback", 1, true))
  assert(#results.read == 3)
  assert(world:body_count() == 2 and world:is_valid(), "nothing was created; the world lives")
  -- a destroy inside the callback happens at the end of the step
  local victim = world:add_body{ position = {3, 0, 0.55}, velocity = {0, 0, -2}, shape = sphere(0.5), user_data = "v" }
  local valid_inside
  world:set_contact_callback(function(e)
    if e.a == victim or e.b == victim then
      if victim:is_valid() then victim:destroy(); valid_inside = victim:is_valid() end
    end
  end)
  world:step(1/60, 5)
  assert(valid_inside == true, "still valid until the step ends")
  assert(not victim:is_valid(), "destroyed after the step")
  assert(world:body_count() == 2)
  for _, b in ipairs(world:bodies()) do assert(b ~= victim, "gone from bodies()") end
end)

test("an error in a callback is raised by step after the step, with a traceback; the world stays usable", function()
  local world, ball = resting_scene()
  local other = world:add_body{ position = {6, 0, 0.6}, velocity = {0, 0, -3}, shape = sphere(0.5) }
  local calls = 0
  world:set_contact_callback(function(e) calls = calls + 1; error("boom from callback") end)
  local ok, err = pcall(world.step, world, 1/60, 20)
  assert(not ok and tostring(err):find("boom from callback", 1, true), tostring(err))
  assert(tostring(err):find("traceback", 1, true), "with a traceback")
  assert(calls == 1, "no more events are delivered in the failing step")
  local steps = world:stats().steps
  assert(steps < 20, "step(dt, n) stops at the failing step (" .. steps .. ")")
  -- later steps deliver events again (a third ball lands), and fail again
  world:add_body{ position = {12, 0, 0.7}, velocity = {0, 0, -3}, shape = sphere(0.5) }
  calls = 0
  raises("boom from callback", world.step, world, 1/60, 30)
  assert(calls == 1)
  world:set_contact_callback(function(e) error({ code = 7 }) end) -- a non-string error
  world:add_body{ position = {18, 0, 0.7}, velocity = {0, 0, -3}, shape = sphere(0.5) }
  local ok, err = pcall(world.step, world, 1/60, 30)
  assert(not ok and type(err) == "table" and err.code == 7, "a table thrown keeps its value: " .. tostring(err))
  world:set_contact_callback(nil)
  world:step(1/60, 30)
  local _, _, z = ball:position()
  assert(z > 0.4 and z < 0.6, "the ball rests on the ground: " .. z)
  assert(other:is_valid() and ball:is_valid())
  raises("dt must be in", world.step, world, -1)
end)

test("advance raises a callback's error too, with the accumulator consistent", function()
  local world = resting_scene()
  world:set_contact_callback(function() error("in advance") end)
  raises("in advance", world.advance, world, 1/60 * 3)
  world:set_contact_callback(nil)
  local steps = world:advance(0)
  assert(steps >= 0)
end)

---------------------------------------------------------------------------
-- lifetime: __gc, __close, __tostring, __eq
---------------------------------------------------------------------------

test("__eq and __tostring", function()
  local world = carom.world{}
  local a = world:add_body{ shape = sphere() }
  local b = world:add_body{ shape = sphere(), position = {5, 0, 0} }
  assert(a == world:query_aabb({-1, -1, -1}, {1, 1, 1})[1] and a ~= b)
  local other = carom.world{}
  local c = other:add_body{ shape = sphere() }
  assert(a ~= c, "same id, different worlds")
  assert(tostring(a):find("carom.Body #1 (dynamic sphere at 0, 0, 0)", 1, true), tostring(a))
  assert(tostring(world):find("carom.World", 1, true) and tostring(world):find("(2 bodies)", 1, true))
end)

test("__close destroys a body or a world at the end of its scope", function()
  local world = carom.world{}
  local keep = world:add_body{ shape = sphere() }
  do
    local tmp <close> = world:add_body{ position = {5, 0, 0}, shape = sphere() }
    assert(world:body_count() == 2)
  end
  assert(world:body_count() == 1, "__close destroyed the body")
  do
    local closed <close> = world:add_body{ position = {9, 0, 0}, shape = sphere() }
    closed:destroy() -- already gone: __close leaves it alone
  end
  local escaped
  do
    local w2 <close> = carom.world{}
    escaped = w2:add_body{ shape = sphere() }
  end
  assert(not escaped:is_valid())
  raises("the body's world has been destroyed", escaped.position, escaped)
  assert(keep:is_valid())
end)

test("__gc under full collections: worlds, bodies and shapes are freed; a body keeps its world alive", function()
  local before = collectgarbage("count")
  for _ = 1, 50 do
    local w = carom.world{}
    for i = 1, 20 do
      w:add_body{ position = {i * 3, 0, 0}, shape = carom.hull{ points = {{0,0,0},{1,0,0},{0,1,0},{0,0,1}} },
                  user_data = { i } }
    end
    w:step(1/60)
  end
  collectgarbage("collect")
  collectgarbage("collect")
  local after = collectgarbage("count")
  assert(after - before < 200, string.format("Lua memory came back: %.0f KB -> %.0f KB", before, after))
  local orphan
  do
    local w = carom.world{ gravity = {0, 0, 0} }
    orphan = w:add_body{ position = {1, 2, 3}, shape = sphere() }
  end
  collectgarbage("collect")
  assert(orphan:is_valid(), "the world is alive while a body refers to it")
  local x, y, z = orphan:position()
  assert(x == 1 and y == 2 and z == 3)
  local w3 = carom.world{}
  local b3 = w3:add_body{ shape = sphere() }
  w3:destroy()
  w3:destroy() -- twice is harmless
  assert(not w3:is_valid())
  raises("world has been destroyed", b3.position, b3)
  raises("bad argument #1 to 'step' (world has been destroyed)", w3.step, w3, 1/60)
  raises("world has been destroyed", w3.add_body, w3, { shape = sphere() })
  assert(tostring(w3):find("destroyed", 1, true))
end)

test("a world collected while its bodies' userdata are unreachable too (cycle)", function()
  do
    local w = carom.world{}
    local b = w:add_body{ shape = sphere(), user_data = {} }
    b.user_data.self = b -- a cycle through the user data
    w:set_contact_callback(function() return w, b end) -- and through the callback
  end
  collectgarbage("collect")
  collectgarbage("collect")
end)

test("finalizers that destroy or step a world in the middle of a call cannot crash the host", function()
  -- A collector that runs at almost every allocation, and garbage whose
  -- finalizers destroy or step the world, made just before each call: they run
  -- inside the call, e.g. while events() builds its tables from the world's
  -- event buffer, which a step or a destroy replaces. (Before the bindings
  -- copied that buffer, ASan caught a use after free here.)
  collectgarbage("incremental", 1, 1000)
  local ran, inside, calls = 0, 0, 0
  local in_call = false
  local probes = {
    function(w, b) return w:events() end,
    function(w, b) return w:add_body{ shape = sphere(0.1), position = { x = 3, y = 0, z = 0 }, user_data = {} } end,
    function(w, b) return b:set_position{ x = 1, y = 2, z = 3 } end,
    function(w, b) return b:apply_impulse({ x = 1, y = 0, z = 0 }, { x = 1, y = 2, z = 3 }) end,
    function(w, b) return w:configure{ substeps = 2, gravity = { x = 0, y = 0, z = -1 } } end,
    function(w, b) return w:step(1/60, 2) end,
    function(w, b) return w:query_aabb({ x = -50, y = -5, z = -5 }, { x = 50, y = 5, z = 5 }) end,
    function(w, b) return w:ray_cast({ x = -5, y = 0, z = 0 }, { x = 100, y = 0, z = 0 }) end,
    function(w, b) return w:bodies() end,
    function(w, b) return w:advance(0.05) end,
    function(w, b) return tostring(b), w:stats(), w:settings() end,
  }
  for how = 1, 3 do
    for _, probe in ipairs(probes) do
      for _ = 1, 20 do
        local w = carom.world{ gravity = {0, 0, 0} }
        local b
        for i = 1, 8 do -- overlapping pairs: events in every step
          b = w:add_body{ position = {3 * i, 0, 0}, shape = sphere(0.5), velocity = {1, 0, 0} }
          w:add_body{ position = {3 * i + 0.9, 0, 0}, shape = sphere(0.5), velocity = {-1, 0, 0} }
        end
        w:step(1/60)
        for _ = 1, 3 do
          setmetatable({}, { __gc = function()
            ran = ran + 1
            if in_call then inside = inside + 1 end
            if how == 1 then pcall(w.destroy, w) elseif how == 2 then pcall(w.step, w, 1/60) else pcall(b.destroy, b) end
          end })
        end
        in_call = true
        pcall(probe, w, b)
        in_call = false
        calls = calls + 1
      end
    end
  end
  collectgarbage("collect")
  collectgarbage("incremental", 200, 100) -- Lua 5.4's defaults
  assert(ran == calls * 3, string.format("every finalizer ran: %d of %d", ran, calls * 3))
  assert(inside > calls / 4, string.format("finalizers ran inside the calls: %d times in %d calls", inside, calls))
end)

test("argument tables are read raw: their metamethods never run", function()
  local world = carom.world{}
  local touched = false
  local trap = { __index = function() touched = true end, __len = function() touched = true; return 3 end,
                 __pairs = function() touched = true; return next, {}, nil end }
  local b = world:add_body(setmetatable({ shape = sphere() }, trap))
  b:set_position(setmetatable({ 1, 2, 3 }, trap))
  raises("expected a vector", b.set_velocity, b, setmetatable({}, trap))
  carom.hull{ points = setmetatable({{0,0,0},{1,0,0},{0,1,0},{0,0,1}}, trap) }
  world:configure(setmetatable({}, trap))
  assert(not touched, "a metamethod ran")
  assert(select(3, b:position()) == 3)
end)

test("the module: version, clock", function()
  assert(type(carom.version) == "string" and carom.version:match("^%d+%.%d+%.%d+$"), tostring(carom.version))
  local t0 = carom.clock()
  assert(type(t0) == "number" and carom.clock() >= t0)
end)

test("range errors print the offending numbers (C's %g, not Lua's formatter)", function()
  raises("half extents (2e+07, 1, 1)", carom.box, { half_extents = {2e7, 1, 1} })
  raises("offset 1e+13", carom.plane, { normal = {0, 0, 1}, offset = 1e13 })
end)

T.finish()
