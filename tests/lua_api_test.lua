-- lua_api_test.lua - every line of the Lua contract (DESIGN.md) and every
-- error path. Run by `make check` through carom-run --test.
local carom = require "carom"
local passed, failed = 0, 0

local function check(name, fn)
  local ok, err = xpcall(fn, debug.traceback)
  if ok then passed = passed + 1 else failed = failed + 1; print("FAIL " .. name .. ": " .. tostring(err)) end
end

local function near(a, b, tol, what)
  if not (math.abs(a - b) <= tol) then error(string.format("%s: got %.6f expected %.6f", what or "value", a, b), 2) end
end

-- raises, and the message mentions `pattern`
local function raises(pattern, fn, ...)
  local ok, err = pcall(fn, ...)
  if ok then error("expected an error matching '" .. pattern .. "'", 2) end
  if not tostring(err):find(pattern, 1, true) then error("error '" .. tostring(err) .. "' does not mention '" .. pattern .. "'", 2) end
end

local function contract_world()
  return carom.world{ gravity = {0,0,-9.81}, substeps = 4, iterations = 1, ccd = true, sleep = true,
                      contact_model = "impulse", preset = "default" }
end

check("contract: world, static plane, dynamic ball", function()
  local world = contract_world()
  local ground = world:add_body{ type = "static", shape = carom.plane{ normal = {0,0,1}, offset = 0 } }
  local ball = world:add_body{ type = "dynamic", position = {0,0,1}, velocity = {1,0,0},
      orientation = {1,0,0,0}, angular_velocity = {0,0,0}, shape = carom.sphere{ radius = 0.1 },
      mass = 1.0, restitution = 0.5, friction = 0.3, bullet = false, lock_rotation = false }
  local dense = world:add_body{ position = {3,0,1}, shape = carom.box{ half_extents = {0.5,0.5,0.5} }, density = 1000 }
  near(dense:mass(), 1000, 1e-9, "density 1000 unit cube")
  assert(ground:type() == "static" and ball:type() == "dynamic")
  world:step(1/60)
  world:step(1/60, 10)
  local x, y, z = ball:position()
  assert(x > 0 and z < 1, "ball moved")
  local qw, qx, qy, qz = ball:orientation()
  near(qw * qw + qx * qx + qy * qy + qz * qz, 1, 1e-9, "unit quaternion")
  local vx, vy, vz = ball:velocity()
  near(vx, 1, 1e-9, "vx unchanged in free flight")
  near(vz, -9.81 * 11 / 60, 1e-9, "vz after 11 steps of free fall")
  local wx, wy, wz = ball:angular_velocity()
  assert(wx == 0 and wy == 0 and wz == 0)
  ball:set_position(0, 0, 2)
  ball:set_velocity({0, 0, 0})
  ball:apply_impulse(2, 0, 0)
  near(select(1, ball:velocity()), 2, 1e-12, "impulse / mass")
  ball:apply_impulse(0, 1, 0, 0.1, 0, 2)  -- at a point: spins
  assert(select(3, ball:angular_velocity()) ~= 0)
  near(ball:mass(), 1, 0, "mass")
  assert(ball:is_valid())
  local ke, pe = world:energy()
  assert(ke > 0 and pe ~= 0)
  local px, py, pz, L = world:momentum()
  near(px, 2, 1e-9, "momentum x")
  assert(type(L) == "table" and #L == 3)
  local st = world:stats()
  for _, k in ipairs{"bodies", "pairs", "contacts", "max_penetration", "ms_total", "ms_solver", "ms_narrowphase"} do
    assert(st[k] ~= nil, "stats." .. k)
  end
  assert(st.bodies == 3)
  local steps, alpha = world:advance(1/60 * 2.5)
  assert(steps == 2, "advance steps")
  near(alpha, 0.5, 1e-9, "advance alpha")
  ball:destroy()
  assert(not ball:is_valid())
  raises("body has been destroyed", ball.position, ball)
  raises("body has been destroyed", ball.set_velocity, ball, 1, 2, 3)
end)

check("every shape", function()
  local world = carom.world{}
  world:add_body{ type = "static", shape = carom.plane{ normal = {0,0,1} } }
  local shapes = {
    carom.sphere{ radius = 0.3 }, carom.box{ half_extents = {0.2, 0.3, 0.4} },
    carom.capsule{ radius = 0.2, half_height = 0.3 }, carom.cylinder{ radius = 0.3, half_height = 0.2 },
    carom.hull{ points = {{0,0,0},{1,0,0},{0,1,0},{0,0,1},{0.2,0.2,0.2}} },
  }
  local bodies = {}
  for i, s in ipairs(shapes) do
    bodies[i] = world:add_body{ position = {2 * i, 0, 1}, shape = s, mass = 2 }
    assert(tostring(s):find("carom."))
  end
  world:step(1/60, 120)
  for i, b in ipairs(bodies) do
    local _, _, z = b:position()
    assert(z > -0.01 and z < 1, "shape " .. i .. " rests on the ground, z = " .. z)
  end
end)

check("events: hit with impulse and force = J/dt", function()
  local world = carom.world{ gravity = {0, 0, 0} }
  world:add_body{ type = "static", position = {1.025, 0, 0}, shape = carom.box{ half_extents = {0.025, 2, 2} } }
  local b = world:add_body{ position = {0, 0, 0}, velocity = {10, 0, 0}, shape = carom.sphere{ radius = 0.05 }, mass = 0.5 }
  local hit
  for _ = 1, 30 do
    world:step(1/60)
    for _, e in ipairs(world:events()) do if e.type == "hit" then hit = e end end
  end
  assert(hit, "a hit event")
  assert(hit.b == b or hit.a == b, "event bodies map back to the same Lua body")
  near(hit.impulse, 0.5 * 10, 0.05, "impulse stops the ball (e = 0)")
  near(hit.force, hit.impulse * 60, 1e-6, "average force J/dt")
  near(hit.speed, 10, 0.05, "approach speed")
  assert(#hit.point == 3 and #hit.normal == 3)
end)

check("contact callback; mutation inside is refused; errors surface after the step", function()
  local world = carom.world{}
  world:add_body{ type = "static", shape = carom.plane{} }
  local ball = world:add_body{ position = {0, 0, 0.6}, shape = carom.sphere{ radius = 0.5 } }
  local seen, create_err = 0, nil
  world:set_contact_callback(function(e)
    seen = seen + 1
    local ok, err = pcall(world.add_body, world, { shape = carom.sphere{ radius = 1 } })
    if not ok then create_err = err end
  end)
  world:step(1/60, 10)
  assert(seen > 0, "callback ran")
  assert(create_err and tostring(create_err):find("callback"), "create inside callback refused: " .. tostring(create_err))
  -- a destroy inside the callback is deferred to the end of the step
  local victim = world:add_body{ position = {3, 0, 0.52}, shape = carom.sphere{ radius = 0.5 } }
  world:set_contact_callback(function(e) if e.a == victim or e.b == victim then victim:destroy() end end)
  world:step(1/60, 5)
  assert(not victim:is_valid(), "deferred destroy happened")
  -- an error thrown by the callback is raised by step, and the world goes on
  local other = world:add_body{ position = {6, 0, 0.5}, shape = carom.sphere{ radius = 0.5 } }
  world:set_contact_callback(function(e) error("boom from callback") end)
  local ok, err = pcall(world.step, world, 1/60)
  assert(not ok and tostring(err):find("boom from callback"), "callback error raised: " .. tostring(err))
  assert(tostring(err):find("traceback"), "with a traceback")
  world:set_contact_callback(nil)
  world:step(1/60, 5)
  assert(ball:is_valid() and other:is_valid())
  raises("dt must be in", world.step, world, -1) -- still validating after a callback error
end)

check("argument errors name the argument", function()
  local world = carom.world{}
  raises("radius must be positive", carom.sphere, { radius = -1 })
  raises("radius must be positive", carom.sphere, { radius = 0 })
  raises("radius is required", carom.sphere, {})
  raises("half_extents must be positive", carom.box, { half_extents = {1, -1, 1} })
  raises("must be finite", carom.box, { half_extents = {1, 0/0, 1} })
  raises("unknown option 'radius'", carom.box, { radius = 1, half_extents = {1, 1, 1} })
  raises("half_height must be positive", carom.capsule, { radius = 1, half_height = -1 })
  raises("hull needs", carom.hull, { points = {{0,0,0}} })
  raises("coplanar", world.add_body, world, { shape = carom.hull{ points = {{0,0,0},{1,0,0},{0,1,0},{1,1,0}} } })
  raises("normal must not be zero", carom.plane, { normal = {0,0,0} })
  raises("bad argument #2 to 'add_body'", world.add_body, world, { shape = carom.sphere{ radius = 1 }, mass = -1 })
  raises("mass", world.add_body, world, { shape = carom.sphere{ radius = 1 }, mass = -1 })
  raises("shape is required", world.add_body, world, {})
  raises("unknown option 'colour'", world.add_body, world, { shape = carom.sphere{ radius = 1 }, colour = "red" })
  raises("orientation", world.add_body, world, { shape = carom.sphere{ radius = 1 }, orientation = {2, 0, 0, 0} })
  raises("position must be finite", world.add_body, world, { shape = carom.sphere{ radius = 1 }, position = {0/0, 0, 0} })
  raises("a plane can only be a static body", world.add_body, world, { shape = carom.plane{} })
  raises("type must be", world.add_body, world, { shape = carom.sphere{ radius = 1 }, type = "floaty" })
  raises("restitution", world.add_body, world, { shape = carom.sphere{ radius = 1 }, restitution = 2 })
  raises("table expected", world.add_body, world, 42)
  raises("substeps", carom.world, { substeps = 0 })
  raises("preset must be", carom.world, { preset = "turbo" })
  raises("contact_model", carom.world, { contact_model = "springy" })
  raises("unknown option 'gravitee'", carom.world, { gravitee = 1 })
  raises("dt must be in", world.step, world, 0)
  raises("dt must be in", world.step, world, 0/0)
  raises("number expected", world.step, world, "fast")
  local b = world:add_body{ shape = carom.sphere{ radius = 1 } }
  raises("number expected", b.set_position, b, "x", 0, 0)
  raises("must be finite", b.set_velocity, b, 1/0, 0, 0)
  raises("mass must be positive", b.set_mass, b, -3)
  raises("restitution must be in", b.set_restitution, b, 3)
  raises("carom.Body expected", b.position, world)
  raises("quaternion", b.set_orientation, b, {1, 2})
  raises("set_orientation", b.set_orientation, b, 2, 0, 0, 0)
  -- a world is unchanged by rejected calls
  assert(world:body_count() == 1)
end)

check("presets by name and explicit keys win", function()
  local w = carom.world{ preset = "accurate", substeps = 3 }
  assert(w)
  carom.world{ preset = "fast" }
  carom.world{ preset = "default", contact_model = "penalty", position_correction = "baumgarte" }
end)

check("ray cast and AABB query", function()
  local world = carom.world{ gravity = {0, 0, 0} }
  local box = world:add_body{ position = {5, 0, 0}, shape = carom.box{ half_extents = {1, 1, 1} } }
  local body, point, normal, fraction = world:ray_cast({0, 0, 0}, {10, 0, 0})
  assert(body == box, "ray hits the box")
  near(point[1], 4, 1e-9, "hit point x")
  near(normal[1], -1, 1e-9, "hit normal")
  near(fraction, 0.4, 1e-9, "fraction")
  assert(world:ray_cast({0, 0, 0}, {0, 10, 0}) == nil, "a miss returns nil")
  local found = world:query_aabb({3.5, -0.5, -0.5}, {4.5, 0.5, 0.5})
  assert(#found == 1 and found[1] == box)
  assert(#world:query_aabb(-1, -1, -1, 1, 1, 1) == 0)
end)

check("user data, awake, type, friction setters", function()
  local world = carom.world{}
  local b = world:add_body{ shape = carom.sphere{ radius = 1 }, data = { name = "ball" } }
  assert(b:data().name == "ball")
  b:set_data(42); assert(b:data() == 42)
  b:set_friction(0.2); near(b:friction(), 0.2, 0)
  b:set_restitution(0.7); near(b:restitution(), 0.7, 0)
  b:set_type("kinematic"); assert(b:type() == "kinematic")
  b:set_type("dynamic")
  b:set_awake(false); assert(not b:is_awake())
  b:set_awake(true); assert(b:is_awake())
  assert(b:kinetic_energy() == 0)
  b:set_mass(3); near(b:mass(), 3, 1e-12)
  b:set_orientation(math.cos(0.5), 0, 0, math.sin(0.5))
  b:set_angular_velocity(0, 0, 2)
  b:apply_force(0, 0, 10)
end)

check("__eq, __tostring, __close, __gc under a full collection", function()
  local world = carom.world{}
  local a = world:add_body{ shape = carom.sphere{ radius = 1 } }
  local same = world:query_aabb({-2, -2, -2}, {2, 2, 2})[1]
  assert(same == a, "__eq by id")
  assert(tostring(a):find("carom.Body"))
  assert(tostring(world):find("carom.World"))
  do
    local tmp <close> = world:add_body{ position = {5, 0, 0}, shape = carom.sphere{ radius = 1 } }
    assert(world:body_count() == 2)
  end
  assert(world:body_count() == 1, "__close destroyed the body")
  do
    local w2 <close> = carom.world{}
    w2:add_body{ shape = carom.sphere{ radius = 1 } }
  end
  for _ = 1, 50 do
    local w = carom.world{}
    for i = 1, 20 do w:add_body{ position = {i * 3, 0, 0}, shape = carom.hull{ points = {{0,0,0},{1,0,0},{0,1,0},{0,0,1}} } } end
    w:step(1/60)
  end
  collectgarbage("collect")
  collectgarbage("collect")
  -- a body outliving its world's Lua reference keeps the world alive
  local orphan
  do
    local w = carom.world{}
    orphan = w:add_body{ shape = carom.sphere{ radius = 1 } }
  end
  collectgarbage("collect")
  assert(orphan:is_valid())
  local x = orphan:position()
  assert(x == 0)
  local w3 = carom.world{}
  local b3 = w3:add_body{ shape = carom.sphere{ radius = 1 } }
  w3:destroy()
  raises("world has been destroyed", b3.position, b3)
  raises("world has been destroyed", w3.step, w3, 1/60)
end)

check("planar lock and rotation lock", function()
  local world = carom.world{}
  world:add_body{ type = "static", shape = carom.plane{} }
  local p = world:add_body{ position = {0, 0, 1}, velocity = {1, 3, 0}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} },
                            lock_to_plane = true, plane_normal = {0, 1, 0} }
  local r = world:add_body{ position = {3, 0, 1}, angular_velocity = {1, 2, 3}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} },
                            lock_rotation = true }
  world:step(1/60, 60)
  local _, y = p:position()
  near(y, 0, 1e-12, "stays in the x-z plane")
  local qw = r:orientation()
  assert(qw == 1, "particle never rotates")
end)

print(string.format("%d passed, %d failed", passed, failed))
if failed > 0 then os.exit(1) end
