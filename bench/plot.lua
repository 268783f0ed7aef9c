-- plot.lua - error against cost per scene from sweep.csv, as SVG, with the
-- Pareto front (no other point is both faster and more accurate) marked.
-- Usage: lua5.4 bench/plot.lua sweep.csv outdir [scene ...]
local csv_path, outdir = arg[1], arg[2]
assert(csv_path and outdir, "usage: lua5.4 plot.lua sweep.csv outdir [scene ...]")
local wanted = {}
for i = 3, #arg do wanted[arg[i]] = true end

local rows, header = {}, nil
for line in io.lines(csv_path) do
  local f = {}
  for v in (line .. ","):gmatch("([^,]*),") do f[#f + 1] = v end
  if not header then header = f else
    local r = {}
    for i, k in ipairs(header) do r[k] = f[i] end
    r.ms_step, r.error = tonumber(r.ms_step), tonumber(r.error)
    rows[#rows + 1] = r
  end
end

local function label(r)
  if r.knob == "grid" then return r.value end
  return r.knob .. "=" .. r.value
end

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

local function esc(s) return (s:gsub("&", "&amp;"):gsub("<", "&lt;")) end

local by_scene, order = {}, {}
for _, r in ipairs(rows) do
  if not by_scene[r.scene] then by_scene[r.scene] = {}; order[#order + 1] = r.scene end
  table.insert(by_scene[r.scene], r)
end

for _, scene in ipairs(order) do
  if next(wanted) == nil or wanted[scene] then
    local pts = by_scene[scene]
    local front = pareto(pts)
    local W, H, L, R, T, B = 760, 480, 80, 20, 40, 60
    local xmin, xmax, ymin, ymax = math.huge, -math.huge, math.huge, -math.huge
    local floor = 1e-6
    for _, p in ipairs(pts) do
      local y = math.max(p.error, floor)
      xmin, xmax = math.min(xmin, p.ms_step), math.max(xmax, p.ms_step)
      ymin, ymax = math.min(ymin, y), math.max(ymax, y)
    end
    local lx0, lx1 = math.log(xmin * 0.8, 10), math.log(xmax * 1.25, 10)
    local ly0, ly1 = math.log(ymin * 0.5, 10), math.log(ymax * 2, 10)
    if ly1 - ly0 < 1 then ly0 = ly0 - 0.5; ly1 = ly1 + 0.5 end
    local function X(v) return L + (math.log(v, 10) - lx0) / (lx1 - lx0) * (W - L - R) end
    local function Y(v) return H - B - (math.log(math.max(v, floor), 10) - ly0) / (ly1 - ly0) * (H - T - B) end
    local out = {}
    local function w(s) out[#out + 1] = s end
    w(('<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="11">'):format(W, H))
    w(('<rect width="%d" height="%d" fill="white"/>'):format(W, H))
    w(('<text x="%d" y="22" font-size="15">%s: error (%s) against cost, Pareto front in red</text>'):format(L, esc(scene), esc(pts[1].error_name)))
    w(('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="#444"/>'):format(L, T, W - L - R, H - T - B))
    for e = math.ceil(lx0), math.floor(lx1) do
      local x = X(10 ^ e)
      w(('<line x1="%.1f" y1="%d" x2="%.1f" y2="%d" stroke="#ddd"/><text x="%.1f" y="%d" text-anchor="middle">%g</text>'):format(x, T, x, H - B, x, H - B + 16, 10 ^ e))
    end
    for e = math.ceil(ly0), math.floor(ly1) do
      local y = Y(10 ^ e)
      w(('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#ddd"/><text x="%d" y="%.1f" text-anchor="end">%g</text>'):format(L, y, W - R, y, L - 6, y + 4, 10 ^ e))
    end
    w(('<text x="%d" y="%d" text-anchor="middle">ms per step (median, log scale)</text>'):format((W + L) // 2, H - 20))
    w(('<text x="16" y="%d" transform="rotate(-90 16 %d)" text-anchor="middle">%s (log scale; %g = exact)</text>'):format((H) // 2, H // 2, esc(pts[1].error_name), floor))
    local path = {}
    for i, p in ipairs(front) do path[#path + 1] = (i == 1 and "M" or "L") .. ("%.1f,%.1f"):format(X(p.ms_step), Y(p.error)) end
    w(('<path d="%s" fill="none" stroke="#c00" stroke-width="2"/>'):format(table.concat(path, " ")))
    for _, p in ipairs(pts) do
      local x, y = X(p.ms_step), Y(p.error)
      w(('<circle cx="%.1f" cy="%.1f" r="%d" fill="%s"/>'):format(x, y, p.front and 5 or 3, p.front and "#c00" or "#357"))
      if p.front or p.knob == "preset" then
        w(('<text x="%.1f" y="%.1f" fill="%s">%s</text>'):format(x + 6, y - 4, p.front and "#900" or "#357", esc(label(p))))
      end
    end
    w("</svg>")
    local f = assert(io.open(outdir .. "/pareto_" .. scene .. ".svg", "w"))
    f:write(table.concat(out, "\n"), "\n")
    f:close()
    io.write(("%s: %d points, front:"):format(scene, #pts))
    for _, p in ipairs(front) do io.write((" %s (%.3f ms, %.3g)"):format(label(p), p.ms_step, p.error)) end
    io.write("\n")
  end
end
