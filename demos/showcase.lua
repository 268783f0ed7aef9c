-- showcase.lua - a 30-second tour of carom (make demo). Each part builds its
-- own world, runs it, and prints what it shows.
local carom = require "carom"
local dir = (debug.getinfo(1, "S").source:match("^@(.*/)") or "./")

local function play(file, steps)
  local scene = dofile(dir .. file)
  local world = carom.world(scene.world or {})
  if scene.contact then world:set_contact_callback(scene.contact) end
  if scene.load then scene.load(world) end
  local t0 = carom.clock()
  for _ = 1, steps or scene.steps or 600 do
    if scene.update then scene.update(world, 1/60) end
    world:step(1/60)
  end
  local ms = (carom.clock() - t0) * 1000 / (steps or scene.steps or 600)
  if scene.report then scene.report(world) end
  return ms
end

local M = { steps = 1 }

function M.report()
  print("carom " .. carom.version .. ": rigid bodies that stack, bounce by the book and do not tunnel\n")
  print("1. The seed's worked examples, through the whole engine (seed/DIGEST.md):")
  play("seed.lua", 1)
  print("\n2. The peers' 210-box pyramid, 10 s at 60 Hz (ODE's collapses at 10 iterations):")
  local ms = play("pyramid.lua", 600)
  print(string.format("   %.3f ms per step on this machine", ms))
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
    print(string.format("   stopped at x = %.4f m (wall face at 1.000): %s; impact impulse %.3f N s, average force %.0f N over the step",
                        x, x < 1.05 and "no tunnelling" or "TUNNELLED", hit and hit.impulse or 0, hit and hit.force or 0))
  end
  print("\n4. 1000 kg on 1 kg (ODE, Bullet and Box3D all lose it):")
  do
    local w = carom.world{ sleep = false }
    w:add_body{ type = "static", shape = carom.plane{} }
    local light = w:add_body{ position = {0, 0, 0.5}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} }, mass = 1 }
    local heavy = w:add_body{ position = {0, 0, 1.5}, shape = carom.box{ half_extents = {0.5, 0.5, 0.5} }, mass = 1000 }
    w:step(1/60, 600)
    local _, _, zh = heavy:position()
    local _, _, zl = light:position()
    print(string.format("   after 10 s: heavy box at z = %.4f m (1.5 expected), light box at %.4f m", zh, zl))
  end
  print("\n5. Restitution by the book:")
  play("bounce_ladder.lua", 150)
  print("\nMore: demos/*.lua (pile, cradle, planar) with build/carom-run; make bench compares with ODE and Bullet.")
end

return M
