-- plot.lua - error against cost per scene from sweep.csv, with the Pareto
-- front (no other point is both faster and more accurate) and the three
-- presets marked; drawn by gnuplot as outdir/pareto_<scene>.png and .svg.
-- Usage: lua5.4 bench/plot.lua sweep.csv outdir [scene ...]
local here = arg[0]:match("^(.*)/[^/]*$") or "."
package.path = here .. "/?.lua;" .. package.path
local chart = require "chart"

local csv_path, outdir = arg[1], arg[2]
assert(csv_path and outdir, "usage: lua5.4 plot.lua sweep.csv outdir [scene ...]")
local wanted = {}
for i = 3, #arg do wanted[arg[i]] = true end

local sweep = require "sweep_rows"
local rows, by_scene, order = sweep.read(csv_path)

-- what each knob's value means, in words
local knob_words = {
  relax = { off = "no relax iterations" },
  correction = { baumgarte = "Baumgarte correction", none = "no position correction" },
  warm_start = { off = "no warm starting" },
  model = { penalty_implicit = "penalty springs, implicit", penalty_explicit = "penalty springs, explicit" },
  ccd = { off = "no continuous collision" },
  shock = { off = "no shock propagation" },
  friction = { off = "no friction" },
  sleep = { on = "sleeping on" },
  reuse = { ["0"] = "no contact reuse", ["1mm"] = "contact reuse 1 mm" },
}
local function label(r)
  if r.knob == "grid" then
    return string.format("%s substep%s, %s iteration%s", r.substeps, r.substeps == "1" and "" or "s",
                         r.iterations, r.iterations == "1" and "" or "s")
  end
  if r.knob == "preset" then return "preset " .. r.value end
  return knob_words[r.knob] and knob_words[r.knob][r.value] or (r.knob .. " " .. r.value)
end

-- the error metrics, with their units
local error_words = {
  max_disp_m = "largest displacement of a box (m)",
  max_pen_m = "deepest penetration after 10 s (m)",
  heavy_err_m = "height error of the heavy box (m)",
  tunneled = "the bullet went through the wall",
  restitution_rel_err = "bounce height, relative error",
  stop_dist_rel_err = "stopping distance, relative error",
  accel_rel_err = "acceleration down the slope, relative error",
  roll_speed_rel_err = "rolling speed, relative error",
  cradle_speed_rel_err = "speed of the last ball, relative error",
  energy_drift_rel = "energy drift over the run, relative",
  tumble_energy_drift_rel = "energy drift of the free box over 20 s, relative",
  oblique_spin_rel_err = "spin after the oblique impact, relative error",
  break_energy_rel_err = "energy after the break, relative error",
}

local function pareto(points)
  local front = {}
  for _, p in ipairs(points) do
    local dominated = false
    for _, q in ipairs(points) do
      if q ~= p and q.ms_step <= p.ms_step and q.error <= p.error and (q.ms_step < p.ms_step or q.error < p.error) then
        dominated = true; break
      end
    end
    if not dominated then front[#front + 1] = p; p.front = true end
  end
  table.sort(front, function(a, b) return a.ms_step < b.ms_step end)
  return front
end

local find_default = sweep.find_default

for _, scene in ipairs(order) do
  if next(wanted) == nil or wanted[scene] then
    local pts = by_scene[scene]
    local front = pareto(pts)
    local default = find_default(pts)
    local presets = {}
    for _, p in ipairs(pts) do if p.knob == "preset" then presets[p.value] = p end end
    presets.default = presets.default or default
    local binary = pts[1].error_name == "tunneled"
    -- exact answers (error 0) sit on the bottom edge of a log axis, at `floor`
    local positive = math.huge
    for _, p in ipairs(pts) do if p.error > 0 then positive = math.min(positive, p.error) end end
    local floor = positive < math.huge and positive / 30 or 1e-6
    local function Y(p) return binary and p.error or math.max(p.error, floor) end
    local xmin, xmax, ymin, ymax = math.huge, -math.huge, math.huge, -math.huge
    for _, p in ipairs(pts) do
      local y = Y(p)
      xmin, xmax = math.min(xmin, p.ms_step), math.max(xmax, p.ms_step)
      ymin, ymax = math.min(ymin, y), math.max(ymax, y)
    end
    xmin = math.max(xmin, 1e-4)
    local x = { lo = xmin / 1.6, hi = xmax * 1.6, log = true, title = "ms per step (median wall time, log scale)" }
    x.ticks = chart.log_ticks(x.lo, x.hi)
    local y
    if binary then
      y = { lo = -0.25, hi = 1.25, ticks = { 0, 1 }, names = { [0] = "no", [1] = "yes" }, title = error_words.tunneled }
    else
      y = { lo = ymin / 3, hi = ymax * 3, log = true,
            title = (error_words[pts[1].error_name] or pts[1].error_name) .. ", log scale" }
      y.ticks = chart.log_ticks(y.lo, y.hi)
      if positive == math.huge or ymin <= floor then
        y.names = {}
        -- "exact" alone at the bottom: no ordinary tick next to it
        local kept = {}
        for _, t in ipairs(y.ticks) do if t > floor * 2.5 then kept[#kept + 1] = t end end
        y.ticks = kept
        y.ticks[#y.ticks + 1] = floor
        table.sort(y.ticks)
        y.names[floor] = "exact"
      end
    end
    local function xy(list)
      local out = {}
      for _, p in ipairs(list) do out[#out + 1] = { math.max(p.ms_step, xmin), Y(p) } end
      return out
    end
    local series = {
      { name = "other settings", points = xy(pts), style = "with points pt 7 ps 0.6 lc rgb '#6f8fb0'" },
      { name = "Pareto front", points = xy(front), lines = true, style = "with linespoints lw 2 pt 7 ps 1.0 lc rgb '#cc0000'" },
    }
    local marks = {
      { "fast", "pt 9 ps 2.2 lc rgb '#e08000'" }, { "default", "pt 5 ps 1.8 lc rgb '#008a3e'" },
      { "accurate", "pt 13 ps 2.2 lc rgb '#6a2ca0'" },
    }
    for _, m in ipairs(marks) do
      local p = presets[m[1]]
      if p then series[#series + 1] = { name = "preset " .. m[1], points = xy{ p }, style = "with points " .. m[2] } end
    end
    local labels, seen = {}, {}
    for _, p in ipairs(front) do
      local text = label(p)
      if p == default then text = text .. " (default)" end
      labels[#labels + 1] = { x = math.max(p.ms_step, xmin), y = Y(p), value = p.error, text = text, color = "#990000" }
      seen[p] = true
    end
    for _, m in ipairs(marks) do
      local p = presets[m[1]]
      if p and not seen[p] then
        local text = p.knob == "preset" and label(p) or label(p) .. " (default)"
        labels[#labels + 1] = { x = math.max(p.ms_step, xmin), y = Y(p), value = p.error, text = text, color = "#333333" }
      end
    end
    local unplaced = chart.render({
      title = string.format("%s: error against cost, %d settings", scene, #pts),
      x = x, y = y, series = series, labels = labels,
    }, outdir .. "/pareto_" .. scene)
    io.write(("%s: %d points, front:"):format(scene, #pts))
    for _, p in ipairs(front) do io.write((" %s (%.3f ms, %.3g)"):format(label(p), p.ms_step, p.error)) end
    if default then io.write((" | default: %s (%.3f ms, %.3g)"):format(label(default), default.ms_step, default.error)) end
    if #unplaced > 0 then io.write((" | %d labels listed beside the plot"):format(#unplaced)) end
    io.write("\n")
  end
end
