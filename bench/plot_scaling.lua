-- plot_scaling.lua - log-log SVG of time per step against body count, with
-- the slope of the fitted power law (1 = linear).
-- Usage: lua5.4 bench/plot_scaling.lua scaling.csv out.svg
local src, dst = arg[1], arg[2]
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
local W, H, L, R, T, B = 640, 420, 70, 20, 40, 55
local x0, x1 = math.log(pts[1].n, 10) - 0.2, math.log(pts[#pts].n, 10) + 0.2
local ymin, ymax = math.huge, -math.huge
for _, p in ipairs(pts) do ymin = math.min(ymin, p.ms); ymax = math.max(ymax, p.ms) end
local y0, y1 = math.log(ymin, 10) - 0.3, math.log(ymax, 10) + 0.3
local function X(n) return L + (math.log(n, 10) - x0) / (x1 - x0) * (W - L - R) end
local function Y(ms) return H - B - (math.log(ms, 10) - y0) / (y1 - y0) * (H - T - B) end
local o = {}
o[#o + 1] = ('<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="11">'):format(W, H)
o[#o + 1] = ('<rect width="%d" height="%d" fill="white"/>'):format(W, H)
o[#o + 1] = ('<text x="%d" y="22" font-size="15">pile: ms per step against bodies (log-log), fitted slope %.2f</text>'):format(L, b)
o[#o + 1] = ('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="#444"/>'):format(L, T, W - L - R, H - T - B)
for e = math.ceil(x0), math.floor(x1) do
  o[#o + 1] = ('<line x1="%.1f" y1="%d" x2="%.1f" y2="%d" stroke="#ddd"/><text x="%.1f" y="%d" text-anchor="middle">%g</text>'):format(X(10 ^ e), T, X(10 ^ e), H - B, X(10 ^ e), H - B + 16, 10 ^ e)
end
for e = math.ceil(y0), math.floor(y1) do
  o[#o + 1] = ('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#ddd"/><text x="%d" y="%.1f" text-anchor="end">%g</text>'):format(L, Y(10 ^ e), W - R, Y(10 ^ e), L - 6, Y(10 ^ e) + 4, 10 ^ e)
end
o[#o + 1] = ('<text x="%d" y="%d" text-anchor="middle">bodies</text>'):format((W + L) // 2, H - 18)
o[#o + 1] = ('<text x="16" y="%d" transform="rotate(-90 16 %d)" text-anchor="middle">ms per step (median)</text>'):format(H // 2, H // 2)
local n0, n1 = pts[1].n, pts[#pts].n
o[#o + 1] = ('<line x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f" stroke="#c00" stroke-dasharray="4 3"/>'):format(X(n0), Y(10 ^ (a + b * math.log(n0, 10))), X(n1), Y(10 ^ (a + b * math.log(n1, 10))))
for _, p in ipairs(pts) do
  o[#o + 1] = ('<circle cx="%.1f" cy="%.1f" r="4" fill="#357"/><text x="%.1f" y="%.1f">%.2f ms</text>'):format(X(p.n), Y(p.ms), X(p.n) + 6, Y(p.ms) - 6, p.ms)
end
o[#o + 1] = "</svg>"
local f = assert(io.open(dst, "w"))
f:write(table.concat(o, "\n"), "\n")
f:close()
print(string.format("scaling: slope %.2f (time ~ bodies^%.2f) over %d..%d bodies", b, b, n0, n1))
