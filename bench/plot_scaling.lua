-- plot_scaling.lua - time per step against body count (log-log) with the
-- fitted power law (slope 1 = linear), drawn by gnuplot as out.png and out.svg.
-- Usage: lua5.4 bench/plot_scaling.lua scaling.csv out   (writes out.png, out.svg)
local here = arg[0]:match("^(.*)/[^/]*$") or "."
package.path = here .. "/?.lua;" .. package.path
local chart = require "chart"

local src, dst = arg[1], arg[2]
assert(src and dst, "usage: lua5.4 plot_scaling.lua scaling.csv out")
dst = dst:gsub("%.svg$", ""):gsub("%.png$", "")
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
