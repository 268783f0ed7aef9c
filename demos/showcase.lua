-- showcase.lua - a 30-second tour of carom (make demo). Each part builds its
-- own world, runs it and prints what it shows; the last line sums up.
-- carom-run demos/showcase.lua
local carom = require "carom"
local dir = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"

-- Plays another demo the way carom-run does; returns the scene and ms per step.
local function play(file, steps)
  local scene = dofile(dir .. file)
  local world = carom.world(scene.world or {})
  if scene.contact then world:set_contact_callback(scene.contact) end
  if scene.load then scene.load(world) end
  steps = steps or scene.steps or math.floor((scene.seconds or 10) * 60 + 0.5)
  local t0 = carom.clock()
  for _ = 1, steps do
    if scene.update then scene.update(world, 1/60) end
    world:step(1/60)
  end
  local ms = (carom.clock() - t0) * 1000 / steps
  if scene.report then scene.report(world) end
  return scene, ms
end

local M = { steps = 1 }
local verdicts = {}

function M.report()
  print("carom " .. carom.version .. ": rigid bodies that stack, bounce by the book and do not tunnel\n")

  print("1. The seed's worked examples, through the whole engine (docs/physics.md, section 9):")
  local seed = play("seed.lua", 1)
  verdicts[#verdicts + 1] = seed.all_match

  print("\n2. The peers' 210-box pyramid, 10 s at 60 Hz (ODE's collapses at 10 iterations):")
  local pyramid, ms = play("pyramid.lua", 600)
  print(string.format("   %.3f ms per step on this machine", ms))
  verdicts[#verdicts + 1] = pyramid.max_disp and pyramid.max_disp < 0.1

  print("\n3. A 10 g bullet at 750 m/s against a 5 cm wall (Box3D's passes through):")
  do
    local w = carom.world{}
    w:add_body{ type = "static", position = {1.025, 0, 2}, shape = carom.box{ half_extents = {0.025, 2, 2} } }
    local b = w:add_body{ position = {0, 0, 2}, velocity = {750, 0, 0}, shape = carom.sphere{ radius = 0.01 },
                          mass = 0.01, bullet = true }
    local hit
    for _ = 1, 60 do
      w:step(1/60)
      for _, e in ipairs(w:events()) do if e.type == "hit" then hit = e end end
    end
    local x = b:position()
    local stopped = x < 1.0
    print(string.format("   stopped at x = %.4f m (wall face at 1.000): %s; impact impulse %.3f N s (m v = 7.5), average force %.0f N over the step",
                        x, stopped and "no tunnelling" or "TUNNELLED", hit and hit.impulse or 0, hit and hit.force or 0))
    verdicts[#verdicts + 1] = stopped and hit and math.abs(hit.impulse - 7.5) < 0.01
  end

  print("\n4. 1000 kg resting on 1 kg (ODE, Bullet and Box3D all lose it):")
  do
    local w = carom.world{ sleep = false }
    w:add_body{ type = "static", shape = carom.plane{} }
    local light = w:add_body{ position = {0, 0, 0.5}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} }, mass = 1 }
    local heavy = w:add_body{ position = {0, 0, 1.5}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} }, mass = 1000 }
    w:step(1/60, 600)
    local _, _, zh = heavy:position()
    local _, _, zl = light:position()
    print(string.format("   after 10 s: heavy box at z = %.4f m (1.5 expected), light box at %.4f m (0.5 expected)", zh, zl))
    verdicts[#verdicts + 1] = math.abs(zh - 1.5) < 0.01 and math.abs(zl - 0.5) < 0.01
  end

  print("\n5. Restitution by the book:")
  play("bounce_ladder.lua", 150)

  print("\nMore: demos/planar.lua (the seed's 2D sample), cradle.lua, pile.lua; make bench compares with ODE and Bullet.")
  local all = true
  for i = 1, 4 do all = all and verdicts[i] and true or false end
  print(all and "showcase: every check above holds" or "showcase: a check FAILED (see above)")
end

return M
