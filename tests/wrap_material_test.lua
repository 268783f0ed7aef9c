-- wrap_material_test.lua - lua/wrap_material.c: the Lua side of torques,
-- forces at a point, contact force events and materials (issue "what a game script needs"):
-- answers worked from first principles (L = tau t, p = F t, a resting box
-- presses with m g, a rolling ball slows at c g), and the errors of every
-- new call. Run by `make check` with carom-run --test.
local carom = require "carom"
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test, near, raises = T.test, T.near, T.raises

test("apply_torque: a sphere spins up at tau / I", function()
  local w = carom.world{ gravity = {0, 0, 0} }
  local r, m = 0.5, 2
  local b = w:add_body{ shape = carom.sphere{ radius = r }, mass = m, sleep = false }
  for _ = 1, 30 do b:apply_torque{0, 0, 0.4}; w:step(1/60) end
  local _, _, wz = b:angular_velocity()
  near(wz, 0.4 * 0.5 / (0.4 * m * r * r), 1e-9, "w = tau t / I")
  local vx, vy, vz = b:velocity()
  assert(vx == 0 and vy == 0 and vz == 0)
end)

test("apply_force at a point: linear and angular", function()
  local w = carom.world{ gravity = {0, 0, 0} }
  local m = 3
  local b = w:add_body{ shape = carom.box{ half_extents = {0.5, 0.5, 0.5} }, mass = m, sleep = false }
  b:apply_force({0, 6, 0}, {0.5, 0, 0})
  local f, t = b:applied_force()
  assert(f[2] == 6 and t[3] == 3, "torque (0.5, 0, 0) x (0, 6, 0) = (0, 0, 3)")
  w:step(1/60)
  local _, vy = b:velocity()
  near(vy, 6 / 60 / m, 1e-12, "v = F dt / m")
  local I = m * (0.25 + 0.25) / 3
  local _, _, wz = b:angular_velocity()
  near(wz, 3 / 60 / I, 1e-9, "w = (r x F) dt / I")
  f, t = b:applied_force()
  assert(f[2] == 0 and t[3] == 0, "for one step only")
  -- the centre-of-mass form still works
  b:apply_force(0, 0, 1)
  f = b:applied_force()
  assert(f[3] == 1)
end)

local function resting_box(mass, threshold, dt)
  local w = carom.world{}
  local ground = w:add_body{ type = "static", shape = carom.plane{ normal = {0, 0, 1}, offset = 0 } }
  local box = w:add_body{ shape = carom.box{ half_extents = {0.25, 0.25, 0.25} }, position = {0, 0, 0.25},
                          mass = mass, sleep = false, force_threshold = threshold }
  w:step(dt, math.floor(1 / dt + 0.5))
  return w, ground, box
end

test("force events: a resting box presses with m g", function()
  for _, dt in ipairs{1/15, 1/60, 1/240} do
    for _, m in ipairs{0.5, 10, 200} do
      local w, ground, box = resting_box(m, 1e-3, dt)
      w:step(dt)
      local forces = {}
      for _, e in ipairs(w:events()) do if e.type == "force" then forces[#forces + 1] = e end end
      assert(#forces == 1, "one force event a step")
      local e = forces[1]
      assert((e.a == box and e.b == ground) or (e.a == ground and e.b == box))
      near(e.force, m * 9.81, 0.01 * m * 9.81, string.format("force at m %g dt %.4f", m, dt))
      near(math.abs(e.normal[3]), 1, 1e-9, "normal")
      near(e.point[1], 0, 1e-3, "centre of pressure x")
      assert(box:force_threshold() == 1e-3)
      box:set_force_threshold(2 * m * 9.81)
      w:step(dt)
      for _, ev in ipairs(w:events()) do assert(ev.type ~= "force", "below the threshold: no event") end
    end
  end
end)

test("force events reach the contact callback", function()
  local w, _, box = resting_box(1, 1, 1/60)
  local seen = 0
  w:set_contact_callback(function(e) if e.type == "force" then seen = seen + 1; assert(e.a == box or e.b == box) end end)
  w:step(1/60, 3)
  assert(seen == 3)
end)

test("materials: keys, combine and the motion they give", function()
  local ice = carom.material{ friction = 0.05, combine = "min" }
  assert(ice.friction == 0.05 and ice.restitution == 0 and ice.rolling_resistance == 0 and ice.combine == "min")
  raises("cannot be changed", function() ice.friction = 1 end)
  local w = carom.world{}
  w:add_body{ type = "static", shape = carom.plane{ normal = {0, 0, 1}, offset = 0 }, friction = 1 }
  local b = w:add_body{ shape = carom.box{ half_extents = {0.25, 0.25, 0.25} }, position = {0, 0, 0.25},
                        velocity = {3, 0, 0}, material = ice, sleep = false }
  w:step(1/60, 6)
  local v1 = b:velocity()
  w:step(1/60, 30)
  local v2 = b:velocity()
  near((v1 - v2) / 0.5, 0.05 * 9.81, 0.01 * 0.05 * 9.81, "slides at min(0.05, 1) g")
  local m = b:material()
  assert(m.friction == 0.05 and m.combine == "min")
  b:set_material(carom.material{ friction = 0.3, restitution = 0.2, combine = "multiply" })
  assert(b:friction() == 0.3 and b:restitution() == 0.2 and b:material().combine == "multiply")
  -- a compound child's own material
  local c = carom.compound{ { shape = carom.sphere{ radius = 0.2 }, material = ice },
                            { shape = carom.sphere{ radius = 0.2 }, position = {1, 0, 0} } }
  assert(w:add_body{ shape = c, position = {0, 3, 1} })
end)

test("rolling resistance: a rolling ball slows at c g", function()
  for _, c in ipairs{0.05, 0.2} do
    for _, r in ipairs{0.1, 1} do
      local w = carom.world{}
      w:add_body{ type = "static", shape = carom.plane{ normal = {0, 0, 1}, offset = 0 },
                  material = carom.material{ friction = 1, rolling_resistance = c } }
      local v0 = 3
      local b = w:add_body{ shape = carom.sphere{ radius = r }, position = {0, 0, r}, velocity = {v0, 0, 0},
                            angular_velocity = {0, v0 / r, 0}, friction = 1, sleep = false }
      local t_stop = v0 / (c * 9.81)
      local n1, n2 = math.floor(0.1 * t_stop * 60) + 2, math.floor(0.6 * t_stop * 60) + 2
      w:step(1/60, n1)
      local v1 = b:velocity()
      w:step(1/60, n2 - n1)
      local v2 = b:velocity()
      near((v1 - v2) / ((n2 - n1) / 60), c * 9.81, 0.01 * c * 9.81, string.format("c %g r %g", c, r))
    end
  end
end)

test("bad input is refused, naming the argument, the body unchanged", function()
  raises("friction", carom.material, { friction = -1 })
  raises("restitution", carom.material, { restitution = 2 })
  raises("rolling_resistance", carom.material, { rolling_resistance = 0/0 })
  raises("combine", carom.material, { combine = "sum" })
  raises("unknown", carom.material, { frction = 1 })
  raises("table", carom.material, 3)
  local w = carom.world{ gravity = {0, 0, 0} }
  local b = w:add_body{ shape = carom.sphere{ radius = 0.5 }, sleep = false, friction = 0.4 }
  raises("apply_torque", b.apply_torque, b, {0/0, 0, 0})
  raises("apply_torque", b.apply_torque, b, "up")
  raises("apply_force", b.apply_force, b, {1, 0, 0}, {0/0, 0, 0})
  raises("apply_force", b.apply_force, b, {1, 0, 0}, "there")
  raises("set_force_threshold", b.set_force_threshold, b, -1)
  raises("set_force_threshold", b.set_force_threshold, b, "big")
  raises("set_material", b.set_material, b, { friction = 1 })
  raises("carom.Material", b.set_material, b, nil)
  raises("material must be made by carom.material", w.add_body, w, { shape = carom.sphere{ radius = 1 }, material = {} })
  raises("force_threshold", w.add_body, w, { shape = carom.sphere{ radius = 1 }, force_threshold = -3 })
  raises("material must be made", carom.compound, { { shape = carom.sphere{ radius = 1 }, material = 5 } })
  local f, t = b:applied_force()
  assert(f[1] == 0 and t[1] == 0 and b:friction() == 0.4 and b:force_threshold() == 0, "unchanged")
  local n = #w:bodies()
  assert(n == 1, "no body made by the refused add_body calls")
  b:destroy()
  raises("destroyed", b.apply_torque, b, {1, 0, 0})
  raises("destroyed", b.apply_force, b, {1, 0, 0}, {0, 0, 0})
  raises("destroyed", b.set_material, b, carom.material{})
  raises("destroyed", b.force_threshold, b)
end)

test("torques and forces from a callback apply once, after it", function()
  local w, ground, box = resting_box(1, 1, 1/60)
  local calls = 0
  w:set_contact_callback(function(e)
    if e.type == "force" and calls == 0 then
      calls = calls + 1
      box:apply_torque{0, 0, 1}
      box:apply_force({0, 0, 0}, {0, 0, 0})
    end
  end)
  w:step(1/60)
  local f, t = box:applied_force()
  assert(calls == 1 and t[3] == 1, "queued for the next step")
  w:set_contact_callback(nil)
  w:step(1/60)
  -- the box rests on the ground: about z nothing resists it but friction, and the
  -- turn of one step is tiny, so the spin is that of one step of the torque
  local _, _, wz = box:angular_velocity()
  local I = 1 * (0.25 ^ 2 + 0.25 ^ 2) / 3 -- m (a^2 + b^2) / 3 with half extents a = b = 0.25
  assert(wz > 0 and wz <= (1 / 60) / I + 1e-12, "at most one step of the torque")
  local f2, t2 = box:applied_force()
  assert(f2[1] == 0 and t2[3] == 0, "applied once, then cleared")
  _ = ground
end)

test("a force event's callback that errors or destroys the body", function()
  local w, _, box = resting_box(1, 1, 1/60)
  w:set_contact_callback(function(e) if e.type == "force" then error({ pressed = e.force }) end end)
  local ok, err = pcall(w.step, w, 1/60)
  assert(not ok and type(err) == "table" and math.abs(err.pressed - 9.81) < 0.1, "a table keeps its value")
  w:set_contact_callback(function(e) if e.type == "force" then (e.a == box and e.a or e.b):destroy() end end)
  w:step(1/60)
  assert(not box:is_valid(), "destroyed at the end of the step")
  w:step(1/60)
  for _, e in ipairs(w:events()) do assert(e.type ~= "force") end
  -- a sleeping pair raises none
  local w2 = carom.world{}
  w2:add_body{ type = "static", shape = carom.plane() }
  local b2 = w2:add_body{ shape = carom.box{ half_extents = {0.25, 0.25, 0.25} }, position = {0, 0, 0.25},
                          force_threshold = 1 }
  w2:step(1/60, 120)
  assert(not b2:is_awake())
  for _, e in ipairs(w2:events()) do assert(e.type ~= "force", "asleep: no force events") end
end)

T.finish()
