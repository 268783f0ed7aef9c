-- plot_scaling.lua - time per step against body count (log-log) with the
-- fitted power law (slope 1 = linear), drawn by gnuplot as out.png and out.svg.
-- Usage: lua5.4 bench/plot_scaling.lua scaling.csv out   (writes out.png, out.svg)
-- Given scaling.sh's pyramid-grid CSV (header engine,preset,workers,...) it
-- draws instead ms/step and us per body-step against bodies, one series per
-- engine and preset (one worker): out_ms.png/.svg and out_us.png/.svg.
local here = arg[0]:match("^(.*)/[^/]*$") or "."
package.path = here .. "/?.lua;" .. package.path
local chart = require "chart"

local src, dst = arg[1], arg[2]
assert(src and dst, "usage: lua5.4 plot_scaling.lua scaling.csv out")
dst = dst:gsub("%.svg$", ""):gsub("%.png$", "")
local first = io.open(src):read("l") or ""
if first:match("^engine,") then
  local rows, order = {}, {}
  for line in io.lines(src) do
    local e, preset, workers, n, ms, us = line:match("^(%w+),(%w+),(%d+),(%d+),([%d.]+),([%d.]+)")
    if e and tonumber(workers) == 1 then
      local name = e == "carom" and ("carom " .. preset) or e
      if not rows[name] then rows[name] = {}; order[#order + 1] = name end
      table.insert(rows[name], { n = tonumber(n), ms = tonumber(ms), us = tonumber(us) })
    end
  end
  local colors = { "#1f3f66", "#4f7fb0", "#9ab8d8", "#cc0000", "#2a8a2a", "#aa7700" }
  for _, what in ipairs{ { key = "ms", title = "ms per step (median wall time, log scale)", file = "_ms" },
                         { key = "us", title = "us per body-step (log scale)", file = "_us" } } do
    local nmin, nmax, vmin, vmax = math.huge, 0, math.huge, 0
    local series = {}
    for i, name in ipairs(order) do
      local pts = {}
      table.sort(rows[name], function(a, b) return a.n < b.n end)
      for _, r in ipairs(rows[name]) do
        pts[#pts + 1] = { r.n, r[what.key] }
        nmin, nmax = math.min(nmin, r.n), math.max(nmax, r.n)
        vmin, vmax = math.min(vmin, r[what.key]), math.max(vmax, r[what.key])
      end
      series[#series + 1] = { name = name, points = pts, lines = true,
                              style = string.format("with linespoints pt 7 ps 1.1 lw 2 lc rgb '%s'", colors[(i - 1) % #colors + 1]) }
    end
    assert(#series > 0, "no one-worker rows in " .. src)
    local x = { lo = nmin / 1.5, hi = nmax * 1.5, log = true, title = "bodies in the pyramid grid (log scale)" }
    x.ticks = chart.log_ticks(x.lo, x.hi)
    local y = { lo = vmin / 2, hi = vmax * 2, log = true, title = what.title }
    y.ticks = chart.log_ticks(y.lo, y.hi)
    chart.render({ title = "pyramid grid (base-10 pyramids, mu 0.6): " .. what.title:gsub(" %(.*", ""),
                   x = x, y = y, labels = {}, series = series }, dst .. what.file)
  end
  print(string.format("scaling: pyramid grid plots %s_ms and %s_us (%d series)", dst, dst, #order))
  return
end
local pts = {}
for line in io.lines(src) do
  local n, ms = line:match("^(%d+),([%d.]+)")
  if n then pts[#pts + 1] = { n = tonumber(n), ms = tonumber(ms) } end
end
assert(#pts >= 2, "need at least two rows")
-- least squares on logs: log ms = a + b log n
local sx, sy, sxx, sxy = 0, 0, 0, 0
for _, p in ipairs(pts) do
  local x, y = math.log(p.n, 10), math.log(p.ms, 10)
  sx, sy, sxx, sxy = sx + x, sy + y, sxx + x * x, sxy + x * y
end
local k = #pts
local b = (k * sxy - sx * sy) / (k * sxx - sx * sx)
local a = (sy - b * sx) / k
local nmin, nmax, mmin, mmax = math.huge, 0, math.huge, 0
for _, p in ipairs(pts) do
  nmin, nmax = math.min(nmin, p.n), math.max(nmax, p.n)
  mmin, mmax = math.min(mmin, p.ms), math.max(mmax, p.ms)
end
local x = { lo = nmin / 2, hi = nmax * 2.5, log = true, title = "bodies in the pile (log scale)" }
x.ticks = chart.log_ticks(x.lo, x.hi)
local y = { lo = mmin / 3, hi = mmax * 3, log = true, title = "ms per step (median wall time, log scale)" }
y.ticks = chart.log_ticks(y.lo, y.hi)
local measured, fit, labels = {}, {}, {}
for _, p in ipairs(pts) do
  measured[#measured + 1] = { p.n, p.ms }
  labels[#labels + 1] = { x = p.n, y = p.ms, text = string.format("%.3g ms", p.ms), color = "#1f3f66" }
end
for _, n in ipairs{ nmin, nmax } do fit[#fit + 1] = { n, 10 ^ (a + b * math.log(n, 10)) } end
local unplaced = chart.render({
  title = string.format("pile: time per step against bodies, fitted slope %.2f (1 = linear)", b),
  x = x, y = y, labels = labels,
  series = {
    { name = "measured", points = measured, style = "with points pt 7 ps 1.2 lc rgb '#35577a'" },
    { name = string.format("power law, slope %.2f", b), points = fit, lines = true,
      style = "with lines dt 2 lw 2 lc rgb '#cc0000'" },
  },
}, dst)
print(string.format("scaling: slope %.2f (time ~ bodies^%.2f) over %d..%d bodies%s", b, b, nmin, nmax,
                    #unplaced > 0 and string.format(" (%d labels listed beside the plot)", #unplaced) or ""))
