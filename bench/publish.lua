-- publish.lua - the last phase of make bench: copies the results the README
-- shows from build/bench/out/ to docs/bench/ and rewrites the README's presets
-- table (between its "presets table" markers) from the same run's sweep.csv,
-- so one `make bench` refreshes every figure the README points at.
-- Usage: lua5.4 bench/publish.lua build/bench/out docs/bench README.md
local here = arg[0]:match("^(.*)/[^/]*$") or "."
package.path = here .. "/?.lua;" .. package.path
local sweep = require "sweep_rows"

local out, docs, readme = arg[1], arg[2], arg[3]
assert(out and docs and readme, "usage: lua5.4 publish.lua build/bench/out docs/bench README.md")

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

-- read a published result file's lines (nil when this run did not make it)
local function lines_of(name)
  local f = io.open(out .. "/" .. name, "rb")
  if not f then return nil end
  local t = {}
  for line in f:lines() do t[#t + 1] = line end
  f:close()
  return t
end
local function mm(x) return string.format(x < 0.01 and "%.2f" or "%.1f", 1000 * x) end
local function cm_or_mm(x) return x >= 0.1 and string.format("%.0f cm", 100 * x) or (mm(x) .. " mm") end

-- the envelope table, from bench/extremes.c's lines
local function envelope_table()
  local t = lines_of("extremes.txt")
  if not t then return nil end
  local r = {}
  for _, line in ipairs(t) do
    local preset, case, holds, err = line:match("^preset=(%S+) case=(%S+) holds=(%S+) error=(%S+)")
    if preset then r[preset .. "/" .. case] = { holds = holds == "yes", err = tonumber(err) } end
  end
  local presets = { "fast", "default", "accurate" }
  local function row(label, cases, fmt)
    local cells = { "| " .. label .. " |" }
    for _, p in ipairs(presets) do
      local parts = {}
      for _, c in ipairs(cases) do
        local v = r[p .. "/" .. c]
        parts[#parts + 1] = v and fmt(v) or "-"
      end
      cells[#cells + 1] = " " .. table.concat(parts, " / ") .. " |"
    end
    return table.concat(cells)
  end
  local function held(v, text) return (v.holds and "yes" or "**no**") .. (text and (" (" .. text .. ")") or "") end
  return {
    "| case | fast | default | accurate |",
    "|---|---|---|---|",
    row("heavy box on 1 kg box, 1e3 / 1e6 / 1e9 : 1 (height error)", { "mass_ratio_1000", "mass_ratio_1e+06", "mass_ratio_1e+09" },
        function(v) return held(v, mm(v.err) .. " mm") end),
    row("1 cm sphere at 100 / 1000 / 3000 m/s into a 5 cm wall (face at x = 1 m)", { "speed_100m/s", "speed_1000m/s", "speed_3000m/s" },
        function(v) return held(v, string.format("x %.4g", v.err)) end),
    row("box at rest, 1 mm / 1 cm / 100 m / 1 km (10 s; within 1 % of size or 6 mm)", { "size_0.001m", "size_0.01m", "size_100m", "size_1000m" },
        function(v) return held(v, string.format("%.3g mm", 1000 * v.err)) end),
    row("5-box stack at 1e5 m and 1e7 m from the origin (top, < 3 cm)", { "stack_at_1e5m", "stack_at_1e7m" },
        function(v) return held(v, mm(v.err) .. " mm") end),
    row("5-box stack at dt 1/1000, 1/120, 1/30, 1/15 s (top, < 10 cm)", { "dt_1/1000", "dt_1/120", "dt_1/30", "dt_1/15" },
        function(v) return held(v, cm_or_mm(v.err)) end),
    row("1,000,000-step soak (e = 0.9 room)", { "soak_1000000_steps" }, function(v) return held(v) end),
  }
end

-- least-squares slope of log(y) against log(x)
local function loglog_slope(xs, ys)
  local n, sx, sy, sxx, sxy = #xs, 0, 0, 0, 0
  for i = 1, n do
    local x, y = math.log(xs[i]), math.log(ys[i])
    sx, sy, sxx, sxy = sx + x, sy + y, sxx + x * x, sxy + x * y
  end
  return (n * sxy - sx * sy) / (n * sxx - sx * sx)
end
local function csv(name)
  local t = lines_of(name)
  if not t then return nil end
  local header, rows = {}, {}
  for k in (t[1] .. ","):gmatch("([^,]*),") do header[#header + 1] = k end
  for i = 2, #t do
    local r, j = {}, 1
    for v in (t[i] .. ","):gmatch("([^,]*),") do r[header[j]] = tonumber(v) or v; j = j + 1 end
    rows[#rows + 1] = r
  end
  return rows
end
local function thousands(n)
  local s = string.format("%d", n)
  repeat local k; s, k = s:gsub("^(%d+)(%d%d%d)", "%1,%2") until k == 0
  return s
end

-- the scaling and detection figures, from scaling.csv, pyramids.csv,
-- broadphase.txt and narrowphase.txt
local function scaling_figures()
  local body = {}
  local pile = csv("scaling.csv")
  if pile and #pile >= 2 then
    local xs, ys = {}, {}
    for _, r in ipairs(pile) do xs[#xs + 1] = r.bodies; ys[#ys + 1] = r.ms_step end
    local a, b = pile[1], pile[#pile]
    body[#body + 1] = string.format("- **Pile, one thread:** time per step grows as bodies^%.2f (least squares over %d sizes) from %s to %s bodies: %.2f ms to %.0f ms, %.2f to %.2f us per body-step.",
      loglog_slope(xs, ys), #pile, thousands(a.bodies), thousands(b.bodies), a.ms_step, b.ms_step,
      1000 * a.ms_step / a.bodies, 1000 * b.ms_step / b.bodies)
  end
  local grid = csv("pyramids.csv")
  if grid then
    local function pick(engine, preset, workers)
      local t = {}
      for _, r in ipairs(grid) do
        if r.engine == engine and r.preset == preset and r.workers == workers then t[#t + 1] = r end
      end
      table.sort(t, function(x, y) return x.bodies < y.bodies end)
      return t
    end
    local c, one = pick("carom", "default", 1), nil
    if #c >= 2 then
      local a, b = c[1], c[#c]
      one = b
      local xs, ys = {}, {}
      for _, r in ipairs(c) do xs[#xs + 1] = r.bodies; ys[#ys + 1] = r.ms_step end
      local first = 0
      for _, r in ipairs(c) do
        local settled = r.ms_step
        first = math.max(first, tonumber(r.first_step_ms) and r.first_step_ms / settled or 0,
                         tonumber(r.first_step_clamp_ms) and r.first_step_clamp_ms / settled or 0)
      end
      body[#body + 1] = string.format("- **Pyramid grid, default preset, one thread:** %.2f us per body-step at %s bodies, %.2f at %s (x%.2f; slope %.2f); peak memory %.1f KB per body at %s; the first step after adding every body (with or without one at the speed clamp) costs up to %.2fx a settled step.",
        a.us_body_step, thousands(a.bodies), b.us_body_step, thousands(b.bodies), b.us_body_step / a.us_body_step,
        loglog_slope(xs, ys), b.kb_per_body, thousands(b.bodies), first)
    end
    local two = pick("carom", "default", 2)
    if one and #two > 0 and two[#two].bodies == one.bodies then
      body[#body + 1] = string.format("- **Threads:** at %s bodies the reference pool's 2 workers take x%.2f of one worker's time.",
        thousands(one.bodies), two[#two].ms_step / one.ms_step)
    end
    for _, peer in ipairs{ { "box3d", "Box3D" }, { "jolt", "Jolt" } } do
      local p = pick(peer[1], "default", 1)
      if one and #p > 0 and p[#p].bodies == one.bodies then
        body[#body + 1] = string.format("- **Beside %s in the same run:** at %s bodies carom takes %.0f ms per step, %s %.0f ms (x%.2f); %.1f against %.1f KB per body.",
          peer[2], thousands(one.bodies), one.ms_step, peer[2], p[#p].ms_step, one.ms_step / p[#p].ms_step, one.kb_per_body, p[#p].kb_per_body)
      end
    end
  end
  local bp = lines_of("broadphase.txt")
  if bp then
    local tree, brute = {}, {}
    for _, line in ipairs(bp) do
      local kind, n = line:match("^bench=(%S+) bodies=(%d+)")
      if kind == "broadphase" then
        tree[#tree + 1] = { n = tonumber(n), update = tonumber(line:match("ms_update=(%S+)")),
                            move = tonumber(line:match("ms_move=(%S+)")), height = line:match("height=(%d+)") }
      elseif kind == "brute_force" then brute[#brute + 1] = { n = tonumber(n), update = tonumber(line:match("ms_update=(%S+)")) } end
    end
    local u, m, h, bn, bu = {}, {}, {}, {}, {}
    for _, r in ipairs(tree) do u[#u + 1] = string.format("%.2g", r.update); m[#m + 1] = string.format("%.2g", r.move); h[#h + 1] = r.height end
    for _, r in ipairs(brute) do bn[#bn + 1] = thousands(r.n); bu[#bu + 1] = string.format("%.3g", r.update) end
    local ns = {}
    for _, r in ipairs(tree) do ns[#ns + 1] = thousands(r.n) end
    if #tree > 0 then
      body[#body + 1] = "- **Broadphase pair finding** (`bench/bench_broadphase.c`, ~1 m boxes, about 14 % re-inserted per step) at " ..
        table.concat(ns, " / ") .. " bodies: `update_pairs` " .. table.concat(u, " / ") .. " ms per step plus " ..
        table.concat(m, " / ") .. " ms of re-insertion; tree height " .. table.concat(h, " / ") ..
        (#brute > 0 and ("; brute force " .. table.concat(bu, " / ") .. " ms at " .. table.concat(bn, " / ") .. " bodies") or "") .. "."
    end
  end
  local np = lines_of("narrowphase.txt")
  if np and #np > 0 then
    local parts = {}
    for _, line in ipairs(np) do
      local pair, ns = line:match("pair=(%S+) ns_per_pair=(%S+)")
      if pair then parts[#parts + 1] = pair .. " " .. thousands(tonumber(ns)) end
    end
    body[#body + 1] = "- **Narrowphase, ns per pair near contact** (`bench/bench_narrowphase.c`, fresh manifolds, no kept ones): " ..
      table.concat(parts, ", ") .. "."
  end
  return #body > 0 and body or nil
end

-- terrain and snapshot lines, quoted from their own benches
local function quoted(name)
  local t = lines_of(name)
  if not t or #t == 0 then return nil end
  local body = { "```" }
  for _, line in ipairs(t) do body[#body + 1] = line end
  body[#body + 1] = "```"
  return body
end

local function replace_between(text, begin_mark, end_mark, body)
  local a, b = text:find(begin_mark, 1, true)
  local c = text:find(end_mark, 1, true)
  assert(a and c and c > b, "publish: " .. readme .. " lacks the markers " .. begin_mark)
  return text:sub(1, b) .. "\n" .. table.concat(body, "\n") .. "\n" .. text:sub(c)
end
local f = assert(io.open(readme, "rb"))
local text = f:read("a"); f:close()
if #rows > 0 then
  text = replace_between(text, "<!-- presets table: written by make bench (bench/publish.lua) -->",
                         "<!-- end of presets table -->", lines)
else
  io.stderr:write("publish: " .. out .. "/sweep.csv has no rows: the presets table is left as it was\n")
end
for _, block in ipairs{ { "envelope table", envelope_table() }, { "scaling figures", scaling_figures() },
                        { "terrain figures", quoted("terrain.txt") }, { "snapshot figures", quoted("snapshot.txt") } } do
  if block[2] then
    text = replace_between(text, "<!-- " .. block[1] .. ": written by make bench (bench/publish.lua) -->",
                           "<!-- end of " .. block[1] .. " -->", block[2])
  end
end
local peers = peers_table(out .. "/peers.txt")
if peers then
  text = replace_between(text, "<!-- peers table: written by make bench (bench/publish.lua) -->",
                         "<!-- end of peers table -->", peers)
end
f = assert(io.open(readme, "wb"))
f:write(text); f:close()
print(("publish: %s/ refreshed, %s presets table rewritten (%d sweep rows)"):format(docs, readme, #rows))
