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
local begin_mark = "<!-- presets table: written by make bench (bench/publish.lua) -->"
local end_mark = "<!-- end of presets table -->"
local f = assert(io.open(readme, "rb"))
local text = f:read("a"); f:close()
local a, b = text:find(begin_mark, 1, true)
local c, d = text:find(end_mark, 1, true)
assert(a and c and c > b, "publish: " .. readme .. " has no presets table markers")
text = text:sub(1, b) .. "\n" .. table.concat(lines, "\n") .. "\n" .. text:sub(c)
f = assert(io.open(readme, "wb"))
f:write(text); f:close()
print(("publish: %s/ refreshed, %s presets table rewritten (%d sweep rows)"):format(docs, readme, #rows))
