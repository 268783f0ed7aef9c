-- sweep_rows.lua - reads bench/sweep.c's CSV (rows by scene) and finds the
-- default settings' row; shared by plot.lua and publish.lua.
local M = {}

function M.read(path)
  local rows, by_scene, order, header = {}, {}, {}, nil
  for line in io.lines(path) do
    local f = {}
    for v in (line .. ","):gmatch("([^,]*),") do f[#f + 1] = v end
    if not header then header = f else
      local r = {}
      for i, k in ipairs(header) do r[k] = f[i] end
      r.ms_step, r.error = tonumber(r.ms_step), tonumber(r.error)
      rows[#rows + 1] = r
      if not by_scene[r.scene] then by_scene[r.scene] = {}; order[#order + 1] = r.scene end
      table.insert(by_scene[r.scene], r)
    end
  end
  return rows, by_scene, order
end

-- The default settings: the preset row if the sweep has one, else the grid
-- point with the same solver columns as the one-knob-off-default rows.
function M.find_default(pts)
  for _, p in ipairs(pts) do if p.knob == "preset" and p.value == "default" then return p end end
  local ref
  for _, p in ipairs(pts) do if p.knob == "sleep" or p.knob == "reuse" then ref = p; break end end
  if not ref then return nil end
  for _, p in ipairs(pts) do
    if p.knob == "grid" then
      local same = true
      for _, k in ipairs{ "substeps", "iterations", "relax", "correction", "warm", "model", "ccd", "friction" } do
        if p[k] ~= ref[k] then same = false end
      end
      if same then return p end
    end
  end
end

return M
