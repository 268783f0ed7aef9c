-- chart.lua - log-scale scatter charts drawn by gnuplot (Debian's
-- gnuplot-nox), written as PNG (for README viewers) and SVG (for zooming).
-- The canvas and plot area are fixed, so the labels can be placed here, in
-- pixels, where they overlap neither each other nor a point.
local M = {}

local W, H = 1180, 600                    -- canvas, px
local PL, PR, PT, PB = 110, 700, 60, 530  -- plot area, px from the top left
local FONT, CHAR_W, LINE_H = 12, 7.6, 16  -- Sans 12 at pngcairo's 72 dpi (approx.)
M.plot_right = PR

local function log10(v) return math.log(v, 10) end

-- Tick values for a log axis over [lo, hi]: decades, else 1-2-5, else 1..9,
-- so that even a range of less than a decade has at least three ticks.
function M.log_ticks(lo, hi)
  for _, mantissas in ipairs{ { 1 }, { 1, 2, 5 }, { 1, 2, 3, 4, 5, 6, 7, 8, 9 } } do
    local t = {}
    for e = math.floor(log10(lo)) - 1, math.ceil(log10(hi)) + 1 do
      for _, m in ipairs(mantissas) do
        local v = m * 10 ^ e
        if v >= lo * (1 - 1e-9) and v <= hi * (1 + 1e-9) then t[#t + 1] = v end
      end
    end
    if #t > 9 then -- many decades: every k-th one, at most nine ticks
      local k, thin = math.ceil(#t / 9), {}
      for i = 1, #t, k do thin[#thin + 1] = t[i] end
      t = thin
    end
    if #t >= 3 then return t end
  end
  return { lo, math.sqrt(lo * hi), hi }
end

local function tick_text(v)
  local s = string.format("%.3g", v)
  if s:find("e") then s = string.format("%g", v) end
  return s
end

-- An axis: {lo, hi, log = bool, ticks = {values}, names = {[value] = text}}.
local function to_px(axis, v, p0, p1)
  local f
  if axis.log then f = (log10(v) - log10(axis.lo)) / (log10(axis.hi) - log10(axis.lo))
  else f = (v - axis.lo) / (axis.hi - axis.lo) end
  return p0 + f * (p1 - p0)
end

-- Places each label (text at point x, y) at the first of several spots around
-- its point that is inside the plot and clear of the other labels and points.
local function place(chart)
  local boxes = {}
  local function clear(b)
    if b[1] < PL + 2 or b[3] > PR - 2 or b[2] < PT + 2 or b[4] > PB - 2 then return false end
    for _, o in ipairs(boxes) do
      if b[1] < o[3] and o[1] < b[3] and b[2] < o[4] and o[2] < b[4] then return false end
    end
    return true
  end
  for _, s in ipairs(chart.series) do
    local last
    for _, p in ipairs(s.points) do
      local x, y = to_px(chart.x, p[1], PL, PR), to_px(chart.y, p[2], PB, PT)
      boxes[#boxes + 1] = { x - 6, y - 6, x + 6, y + 6 }
      if s.lines and last then -- the line from the last point: keep labels off it too
        local n = math.ceil(math.sqrt((x - last[1]) ^ 2 + (y - last[2]) ^ 2) / 4)
        for i = 1, n - 1 do
          local cx, cy = last[1] + (x - last[1]) * i / n, last[2] + (y - last[2]) * i / n
          boxes[#boxes + 1] = { cx - 2, cy - 2, cx + 2, cy + 2 }
        end
      end
      last = { x, y }
    end
  end
  -- the first clear box for text near (x, y), no farther than the last distance
  local function find_spot(x, y, text, distances)
    local w, h = #text * CHAR_W, LINE_H
    for _, d in ipairs(distances) do
      for _, c in ipairs{ { d, -h / 2 }, { -w - d, -h / 2 }, { d, -h - 2 }, { d, 2 }, { -w - d, -h - 2 },
                          { -w - d, 2 }, { -w / 2, -h - d }, { -w / 2, d } } do
        local b = { x + c[1], y + c[2], x + c[1] + w, y + c[2] + h }
        if clear(b) then return b end
      end
    end
  end
  -- Every label right next to its point if they all fit; else each point
  -- gets a number there and its text goes in the list beside the plot (a
  -- label farther away could be read as another point's).
  local function attempt(numbered)
    local saved = #boxes
    local placed = {}
    for n, l in ipairs(chart.labels) do
      local x, y = to_px(chart.x, l.x, PL, PR), to_px(chart.y, l.y, PB, PT)
      local text = numbered and tostring(n) or l.text
      local spot = find_spot(x, y, text, numbered and { 3, 8, 14, 22, 32 } or { 5, 10 })
      if not spot then
        if not numbered then
          for k = #boxes, saved + 1, -1 do boxes[k] = nil end
          return nil
        end
        placed[#placed + 1] = { unplaced = l }
      else
        boxes[#boxes + 1] = spot
        local ex, ey = math.max(spot[1], math.min(x, spot[3])), math.max(spot[2], math.min(y, spot[4]))
        placed[#placed + 1] = { text = text, color = l.color, left = spot[1], middle = (spot[2] + spot[4]) / 2,
                                leader = { x, y, ex, ey }, near = (ex - x) ^ 2 + (ey - y) ^ 2 < 16 ^ 2,
                                listed = numbered and ("[" .. text .. "] " .. l.text) or nil, x = l.x, y = l.value or l.y }
      end
    end
    return placed
  end
  local placed = attempt(false) or attempt(true)
  return placed
end

local function quote(s) return '"' .. s:gsub('\\', '\\\\'):gsub('"', '\\"') .. '"' end

local function axis_commands(name, axis)
  local c = {}
  if axis.log then c[#c + 1] = "set logscale " .. name else c[#c + 1] = "unset logscale " .. name end
  c[#c + 1] = string.format("set %srange [%.10g:%.10g]", name, axis.lo, axis.hi)
  local t = {}
  for _, v in ipairs(axis.ticks) do t[#t + 1] = string.format("%s %.10g", quote(axis.names and axis.names[v] or tick_text(v)), v) end
  c[#c + 1] = string.format("set %stics (%s) nomirror out", name, table.concat(t, ", "))
  c[#c + 1] = string.format("set %slabel %s", name, quote(axis.title))
  return table.concat(c, "\n")
end

-- chart = { title, x = axis, y = axis, series = {{name, points = {{x, y}...},
-- style = gnuplot "with ..." text}}, labels = {{x, y, text, color, value = the y to list, if not y}},
-- notes = {text} }
-- Writes base .. ".png" and base .. ".svg"; returns the labels it could not place.
function M.render(chart, base)
  local placed = place(chart)
  local g = {}
  local function w(s) g[#g + 1] = s end
  w("set encoding utf8")
  w(string.format("set lmargin at screen %.6f", PL / W))
  w(string.format("set rmargin at screen %.6f", PR / W))
  w(string.format("set tmargin at screen %.6f", 1 - PT / H))
  w(string.format("set bmargin at screen %.6f", 1 - PB / H))
  w("set title " .. quote(chart.title) .. " offset 0,0.5")
  w(axis_commands("x", chart.x))
  w(axis_commands("y", chart.y))
  w("set grid xtics ytics lc rgb '#dddddd'")
  w("set border 3 lc rgb '#444444'")
  w(string.format("set key at screen %.6f, screen %.6f left top Left reverse spacing 1.3 box lc rgb '#bbbbbb'",
                  (PR + 25) / W, 1 - PT / H))
  local unplaced = {}
  for i, p in ipairs(placed) do
    if p.unplaced then unplaced[#unplaced + 1] = p.unplaced else
      w(string.format("set label %d %s at screen %.6f, screen %.6f left tc rgb %s front", i, quote(p.text),
                      p.left / W, 1 - p.middle / H, quote(p.color or "#222222")))
      if not p.near then
        w(string.format("set arrow %d from screen %.6f, screen %.6f to screen %.6f, screen %.6f nohead lc rgb %s lw 0.8 back",
                        i, p.leader[3] / W, 1 - p.leader[4] / H, p.leader[1] / W, 1 - p.leader[2] / H,
                        quote(p.color or "#222222")))
      end
    end
  end
  -- what could not be placed goes in a list under the key
  local notes = {}
  for _, n in ipairs(chart.notes or {}) do notes[#notes + 1] = n end
  for _, p in ipairs(placed) do
    if p.listed then notes[#notes + 1] = string.format("%s: %.3g ms, %.3g", p.listed, p.x, p.y) end
  end
  for _, l in ipairs(unplaced) do notes[#notes + 1] = string.format("%s: %.3g ms, %.3g", l.text, l.x, l.value or l.y) end
  -- each note wrapped to the width right of the plot, continuation lines indented
  local width = math.floor((W - PR - 35) / (1.1 * CHAR_W))
  local lines = {}
  for _, n in ipairs(notes) do
    local line = ""
    for word in n:gmatch("%S+") do
      if line ~= "" and #line + 1 + #word > width then lines[#lines + 1] = line; line = "    " .. word
      else line = line == "" and word or (line .. " " .. word) end
    end
    lines[#lines + 1] = line
  end
  for i, n in ipairs(lines) do
    w(string.format("set label %d %s at screen %.6f, screen %.6f left tc rgb '#333333'", 900 + i, quote(n),
                    (PR + 25) / W, 1 - (PT + 200 + i * LINE_H * 1.1) / H))
  end
  local plots = {}
  for i, s in ipairs(chart.series) do
    local rows = {}
    for _, p in ipairs(s.points) do rows[#rows + 1] = string.format("%.10g %.10g", p[1], p[2]) end
    w(string.format("$s%d << EOD\n%s\nEOD", i, table.concat(rows, "\n")))
    plots[#plots + 1] = string.format("$s%d using 1:2 %s title %s", i, s.style, quote(s.name))
  end
  local plot = "plot " .. table.concat(plots, ", \\\n  ")
  w(string.format("set terminal pngcairo noenhanced size %d,%d font 'Sans,%d' background rgb 'white'", W, H, FONT))
  w("set output " .. quote(base .. ".png"))
  w(plot)
  w(string.format("set terminal svg noenhanced size %d,%d font 'Sans,%d' background rgb 'white'", W, H, FONT))
  w("set output " .. quote(base .. ".svg"))
  w(plot)
  w("set output")
  local script = base .. ".gp"
  local f = assert(io.open(script, "w"))
  f:write(table.concat(g, "\n"), "\n")
  f:close()
  local ok = os.execute("gnuplot " .. quote(script))
  if not ok then error("gnuplot failed on " .. script .. " (apt-get install gnuplot-nox)") end
  os.remove(script)
  return unplaced
end

return M
