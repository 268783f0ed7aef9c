-- seed.lua - the seed's worked examples (docs/physics.md, section 9) played through the
-- whole engine: bodies, contacts, solver, restitution, friction, events.
-- Imperial units as in the text (ft, slug, s); no gravity during the impacts.
-- carom-run demos/seed.lua
local carom = require "carom"

local M = { steps = 1 }
local results = {}

local function line(what, got, want)
  local ok = math.abs(got - want) <= 5e-4 * math.max(math.abs(want), 1e-9) + 1e-9
  results[#results + 1] = string.format("  %-34s %12.4f   expected %12.4f   %s", what, got, want, ok and "OK" or "MISMATCH")
  return ok
end

local function impact_world()
  return carom.world{ gravity = {0, 0, 0}, restitution_threshold = 0, ccd = false, sleep = false }
end

-- Two spheres touching along unit normal n (from body 1 to body 2), stepped once.
local function collide_spheres(r1, m1, v1, r2, m2, v2, n, e, mu)
  local w = impact_world()
  local a = w:add_body{ position = {0, 0, 0}, velocity = v1, shape = carom.sphere{ radius = r1 },
                        mass = m1, restitution = e, friction = mu or 0 }
  local d = r1 + r2
  local b = w:add_body{ position = {d * n[1], d * n[2], 0}, velocity = v2, shape = carom.sphere{ radius = r2 },
                        mass = m2, restitution = e, friction = mu or 0 }
  local impulse = 0
  w:set_contact_callback(function(ev) if ev.type == "hit" then impulse = ev.impulse end end)
  w:step(1/600)
  return a, b, impulse
end

function M.report()
  local all = true
  -- Billiard balls: e = 0.9, equal masses, ball 1 at 20 ft/s, n = (sqrt3/2, -1/2)
  do
    local r = 1.125 / 12
    local n = { math.sqrt(3) / 2, -0.5 }
    local a, b = collide_spheres(r, 0.0106, {20, 0, 0}, r, 0.0106, {0, 0, 0}, n, 0.9)
    local v1x, v1y = a:velocity()
    local v2x, v2y = b:velocity()
    results[#results + 1] = "billiard balls (oblique, e = 0.9):"
    all = line("ball 1 v+ x (ft/s)", v1x, 5.7500) and all
    all = line("ball 1 v+ y (ft/s)", v1y, 8.2272) and all
    all = line("ball 2 v+ x (ft/s)", v2x, 14.2500) and all
    all = line("ball 2 v+ y (ft/s)", v2y, -8.2272) and all
    local ke0 = 0.5 * 0.0106 * 400
    local ke1 = 0.5 * 0.0106 * (v1x ^ 2 + v1y ^ 2 + v2x ^ 2 + v2y ^ 2)
    all = line("kinetic energy kept (fraction)", ke1 / ke0, 0.92875) and all
  end
  -- Baseball and bat: e = 0.46, bat 36 oz at +103 ft/s, ball 5.125 oz at -132 ft/s
  do
    local r1, r2 = 1.375 / 12, 1.47 / 12
    local rs = r1 + r2
    local n = { math.sqrt(rs * rs - r1 * r1) / rs, r1 / rs }
    local a, b, J = collide_spheres(r1, 0.069932, {103, 0, 0}, r2, 0.0099556, {-132, 0, 0}, n, 0.46)
    local v1x, v1y = a:velocity()
    local v2x, v2y = b:velocity()
    results[#results + 1] = "baseball and bat (e = 0.46):"
    all = line("bat v+ x (ft/s)", v1x, 70.230) and all
    all = line("bat v+ y (ft/s)", v1y, -18.091) and all
    all = line("ball v+ x (ft/s)", v2x, 98.188) and all
    all = line("ball v+ y (ft/s)", v2y, 127.078) and all
    all = line("impulse on the ball (lb s)", J, 2.6177) and all
  end
  -- Bullet: 150 g = 0.010278 slug leaves a 0.008 s barrel at 2480 ft/s. Both
  -- ways through the engine, with steps of dt = 0.008 s: the average force
  -- applied for one step gives the muzzle speed (impulse = F t), and a wall
  -- that stops the bullet in one step reports the impulse m v and the
  -- average force J / dt in its hit event.
  do
    local m, v, dt = 0.010278, 2480, 0.008
    results[#results + 1] = "bullet (impulse and average force, steps of 0.008 s):"
    local barrel = impact_world()
    local shot = barrel:add_body{ shape = carom.sphere{ radius = 0.02 }, mass = m }
    shot:apply_force(3186, 0, 0)
    barrel:step(dt)
    all = line("muzzle speed from F = 3186 lb (ft/s)", (shot:velocity()), v) and all
    local w = impact_world()
    w:configure{ ccd = true }
    w:add_body{ type = "static", position = {10.1, 0, 0}, shape = carom.box{ half_extents = {0.1, 3, 3} } }
    local b = w:add_body{ position = {0, 0, 0}, velocity = {v, 0, 0}, shape = carom.sphere{ radius = 0.02 },
                          mass = m, bullet = true }
    local hit
    for _ = 1, 3 do
      w:step(dt)
      for _, ev in ipairs(w:events()) do if ev.type == "hit" then hit = ev end end
    end
    all = line("hit event impulse (lb s)", hit and hit.impulse or 0, 25.49) and all
    all = line("hit event force J / dt (lb)", hit and hit.force or 0, 3186) and all
    all = line("bullet front at the wall face (ft)", select(1, b:position()) + 0.02, 10.0) and all
  end
  -- Golf: a ball meets a fixed 45-degree face and leaves spinning: w+ = J mu r / I
  do
    local w = impact_world()
    local m, r, mu, e, v = 0.0031, 0.07, 0.1, 0.8, 130
    local c = math.sqrt(0.5)
    w:add_body{ type = "static", shape = carom.plane{ normal = {c, 0, c}, offset = 0 }, friction = mu, restitution = e }
    local ball = w:add_body{ position = {r * c, 0, r * c}, velocity = {-v, 0, 0}, shape = carom.sphere{ radius = r },
                             mass = m, friction = mu, restitution = e }
    w:step(1/600)
    local J = (1 + e) * m * v * c       -- normal impulse
    local I = 0.4 * m * r * r
    local wx, wy, wz = ball:angular_velocity()
    results[#results + 1] = "golf ball spin from friction (mu = 0.1, e = 0.8):"
    all = line("spin |w+| (rad/s)", math.sqrt(wx * wx + wy * wy + wz * wz), J * mu * r / I) and all
  end
  for _, l in ipairs(results) do print(l) end
  print(all and "seed examples: all values match docs/physics.md" or "seed examples: MISMATCH (see above)")
  M.all_match = all
end

return M
