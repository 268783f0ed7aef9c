-- publish.lua - the last phase of make bench: copies the results the README
-- shows from bench/out/ to docs/bench/ and rewrites the README's presets
-- table (between its "presets table" markers) from the same run's sweep.csv,
-- so one `make bench` refreshes every figure the README points at.
-- Usage: lua5.4 bench/publish.lua bench/out docs/bench README.md
local here = arg[0]:match("^(.*)/[^/]*$") or "."
package.path = here .. "/?.lua;" .. package.path
local sweep = require "sweep_rows"

local out, docs, readme = arg[1], arg[2], arg[3]
assert(out and docs and readme, "usage: lua5.4 publish.lua bench/out docs/bench README.md")

local function copy(name)
  local src = io.open(out .. "/" .. name, "rb")
  if not src then io.stderr:write("publish: no " .. out .. "/" .. name .. " (skipped)\n"); return end
  local data = src:read("a"); src:close()
  local dst = assert(io.open(docs .. "/" .. name, "wb"))
  dst:write(data); dst:close()
end
for _, name in ipairs{ "peers.txt", "broadphase.txt", "narrowphase.txt", "extremes.txt", "pareto.txt",
                       "terrain.txt", "snapshot.txt", "scaling.csv", "scaling.png", "scaling.svg",
                       "pyramids.csv", "pyramids_switches.csv", "pyramids_ms.png", "pyramids_ms.svg",
                       "pyramids_us.png", "pyramids_us.svg" } do
  copy(name)
end
local rows, by_scene = sweep.read(out .. "/sweep.csv")
for scene in pairs(by_scene) do copy("pareto_" .. scene .. ".png"); copy("pareto_" .. scene .. ".svg") end

-- the presets table
local function preset_row(scene, name)
  local pts = by_scene[scene]
  if not pts then return nil end
  if name == "default" then return sweep.find_default(pts) end
  for _, p in ipairs(pts) do if p.knob == "preset" and p.value == name then return p end end
end
local function plural(n, word) return n .. " " .. word .. (n == "1" and "" or "s") end
local lines = {
  "| preset | settings | pyramid 210 | pile 2000 | stack 10 | 1000:1 (height error) | elastic gas (10 s) |",
  "|---|---|---|---|---|---|---|",
}
for _, name in ipairs{ "fast", "default", "accurate" } do
  local s = preset_row("pyramid", name)
  local function cell(scene, f)
    local p = preset_row(scene, name)
    return p and f(p) or "-"
  end
  local settings = "-"
  if s then
    local reuse = tonumber(s.reuse_mm or "")
    settings = plural(s.substeps, "sub-step") .. ", " .. plural(s.iterations, "iteration") .. ", " ..
               (s.relax == "0" and "no relax pass" or plural(s.relax, "relax iteration")) ..
               (s.hertz and (", " .. s.hertz .. " Hz") or "") ..
               (reuse and (reuse > 0 and (", manifolds kept to " .. s.reuse_mm .. " mm") or ", every manifold every step") or "")
  end
  lines[#lines + 1] = string.format("| `%s` | %s | %s | %s | %s | %s | %s |", name, settings,
    cell("pyramid", function(p) return string.format("%.2f ms, %.2g m", p.ms_step, p.error) end),
    cell("pile", function(p) return string.format("%.2f ms, pen %.2g m", p.ms_step, p.error) end),
    cell("stack", function(p) return string.format("%.2g m", p.error) end),
    cell("mass_ratio", function(p) return string.format("%.2g mm", 1000 * p.error) end),
    cell("gas", function(p) return string.format("energy %+.2f %%", 100 * (tonumber(p.extra) - 1)) end))
end
-- the canonical scenes beside the peers, from the same run's peers.txt
local function peers_table(path)
  local f = io.open(path, "rb")
  if not f then return nil end
  local cells, engines, seen, machine, load = {}, {}, {}, "?", nil
  for line in f:lines() do
    machine = line:match("^machine: (.*)") or machine
    load = line:match("^load average %(1 min%) before / after the rounds: (.*)") or load
    local engine, scene, ms, metrics = line:match("^| (%S+)%s*| (%S+)%s*|%s*%d+ |%s*%d+ |%s*([%d.]+) | %S+%s*| (.*)$")
    if engine and engine ~= "engine" then
      local m = {}
      for k, v in metrics:gmatch("(%S+)=(%S+)") do m[k] = v end
      m.ms = tonumber(ms)
      cells[engine .. "/" .. scene] = m
      if not seen[engine] then seen[engine] = true; engines[#engines + 1] = engine end
    end
  end
  f:close()
  local order, names = { "carom_fast", "carom", "ode", "bullet", "box3d", "jolt" },
    { carom_fast = "carom `fast`", carom = "carom default", ode = "ODE", bullet = "Bullet", box3d = "Box3D", jolt = "Jolt" }
  local cols = {}
  for _, e in ipairs(order) do if seen[e] then cols[#cols + 1] = e end end
  local function ms(m) return m.ms < 0.1 and string.format("%.3f ms", m.ms) or string.format("%.2f ms", m.ms) end
  local describe = {
    pyramid = function(m) return (m.stands == "yes" and "stands" or "**collapses**") .. string.format(" (max_disp %.3g m)", m.max_disp_m) end,
    pile = function(m) return string.format("KE %.2g J, pen %.2g m", m.final_ke_J, m.max_pen_m) ..
      (m.escaped ~= "0" and (", " .. m.escaped .. " escaped") or "") end,
    stack = function(m) return (m.stands == "yes" and "" or "**falls**, ") .. string.format("max_disp %.3g m", m.max_disp_m) end,
    mass_ratio = function(m) return (m.holds == "yes" and "holds" or "**fails**") .. string.format(" (heavy at %.4f m of 1.5)", m.heavy_z_m) end,
    bullet = function(m) return m.tunneled == "no" and string.format("stops (x %.4f)", m.final_x_m) or "**tunnels**" end,
  }
  local labels = { pyramid = "pyramid, 210 boxes", pile = "pile, 2000 bodies", stack = "stack, 10 boxes",
                   mass_ratio = "mass ratio 1000:1", bullet = "bullet, 750 m/s" }
  local head, rule = { "| scene |" }, { "|---|" }
  for _, e in ipairs(cols) do head[#head + 1] = " " .. names[e] .. " |"; rule[#rule + 1] = "---|" end
  local out = { table.concat(head), table.concat(rule) }
  for _, scene in ipairs{ "pyramid", "pile", "stack", "mass_ratio", "bullet" } do
    local row = { "| " .. labels[scene] .. " |" }
    for _, e in ipairs(cols) do
      local m = cells[e .. "/" .. scene]
      row[#row + 1] = m and (" " .. ms(m) .. ", " .. describe[scene](m) .. " |") or " - |"
    end
    out[#out + 1] = table.concat(row)
  end
  -- ratios against the faster of the peers measured in this run
  local ratio = {}
  for _, scene in ipairs{ "pyramid", "pile" } do
    local best, who
    for _, e in ipairs(cols) do
      local m = cells[e .. "/" .. scene]
      if m and not e:match("^carom") and (not best or m.ms < best) then best, who = m.ms, e end
    end
    for _, e in ipairs{ "carom_fast", "carom" } do
      local m = cells[e .. "/" .. scene]
      if m and best then ratio[#ratio + 1] = string.format("%s %s %.2fx %s", scene, names[e], m.ms / best, names[who]) end
    end
  end
  out[#out + 1] = ""
  out[#out + 1] = "Machine: " .. machine .. (load and (", load average " .. load) or "") .. ". Median ms/step of the run's rounds; sleeping off in every engine." ..
    (#ratio > 0 and (" Against the faster peer in this run: " .. table.concat(ratio, "; ") .. ".") or "")
  return out
end

local function replace_between(text, begin_mark, end_mark, body)
  local a, b = text:find(begin_mark, 1, true)
  local c = text:find(end_mark, 1, true)
  assert(a and c and c > b, "publish: " .. readme .. " lacks the markers " .. begin_mark)
  return text:sub(1, b) .. "\n" .. table.concat(body, "\n") .. "\n" .. text:sub(c)
end
local f = assert(io.open(readme, "rb"))
local text = f:read("a"); f:close()
text = replace_between(text, "<!-- presets table: written by make bench (bench/publish.lua) -->",
                       "<!-- end of presets table -->", lines)
local peers = peers_table(out .. "/peers.txt")
if peers then
  text = replace_between(text, "<!-- peers table: written by make bench (bench/publish.lua) -->",
                         "<!-- end of peers table -->", peers)
end
f = assert(io.open(readme, "wb"))
f:write(text); f:close()
print(("publish: %s/ refreshed, %s presets table rewritten (%d sweep rows)"):format(docs, readme, #rows))
