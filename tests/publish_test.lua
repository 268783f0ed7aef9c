-- publish_test.lua - bench/publish.lua, the last phase of make bench, writes
-- the README's generated blocks from a run's result files. Fed synthetic
-- results whose answers are known (a pile whose ms/step is exactly
-- c * bodies^1.5, an envelope with one failing case), it must write those
-- answers between the markers and leave the rest of the README alone.
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")

local dir = os.tmpname()
os.remove(dir)
assert(os.execute("mkdir -p '" .. dir .. "/out' '" .. dir .. "/docs'"))
local function write(name, text)
  local f = assert(io.open(dir .. "/" .. name, "wb"))
  f:write(text); f:close()
end
local function read(name)
  local f = assert(io.open(dir .. "/" .. name, "rb"))
  local s = f:read("a"); f:close()
  return s
end

-- a pile whose cost is 2e-4 * n^1.5 ms: the fitted exponent must be 1.50
local pile = { "bodies,ms_step,contacts" }
for _, n in ipairs{ 100, 1000, 10000, 50000 } do pile[#pile + 1] = string.format("%d,%.17g,%d", n, 2e-4 * n ^ 1.5, n) end
write("out/scaling.csv", table.concat(pile, "\n") .. "\n")
write("out/pyramids.csv", table.concat({
  "engine,preset,workers,bodies,ms_step,us_body_step,first_step_ms,first_step_clamp_ms,peak_kb,kb_per_body,cpu_ms_step",
  "carom,default,1,1000,4,4,8,10,16000,16,4",
  "carom,default,1,50000,400,8,600,640,600000,12,400",
  "carom,default,2,50000,240,4.8,400,400,600000,12,480",
  "box3d,default,1,50000,320,6.4,,,180000,3.6,",
}, "\n") .. "\n")
local ext = {}
for _, p in ipairs{ "fast", "default", "accurate" } do
  ext[#ext + 1] = string.format("preset=%s case=mass_ratio_1000 holds=yes error=0.0004 m (heavy box height error)", p)
  ext[#ext + 1] = string.format("preset=%s case=dt_1/15 holds=%s error=%s m (top of a 5-box stack)", p,
                                p == "fast" and "NO" or "yes", p == "fast" and "6.2" or "0.031")
end
write("out/extremes.txt", table.concat(ext, "\n") .. "\n")
write("out/narrowphase.txt", "bench=narrowphase pair=sphere-sphere ns_per_pair=74 points_per_pair=0.73\n" ..
                             "bench=narrowphase pair=hull-hull ns_per_pair=7921 points_per_pair=1.43\n")
write("out/terrain.txt", "terrain: line one\nfast mesh line two\n")
write("out/sweep.csv", "scene,knob,value,ms_step,error\n")
local blocks = {}
for _, name in ipairs{ "presets table", "peers table", "envelope table", "scaling figures", "terrain figures", "snapshot figures" } do
  blocks[#blocks + 1] = "<!-- " .. name .. ": written by make bench (bench/publish.lua) -->\nold " .. name ..
                        "\n<!-- end of " .. name .. " -->"
end
local readme = "# title\n\n" .. table.concat(blocks, "\n\nprose between\n\n") .. "\n\ntail\n"
write("README.md", readme)

local ok = os.execute("lua5.4 bench/publish.lua '" .. dir .. "/out' '" .. dir .. "/docs' '" .. dir .. "/README.md' >/dev/null 2>&1")
T.check(ok, "publish.lua runs on a partial set of results")
local got = read("README.md")

T.test("the pile's exponent is fitted, not copied", function()
  assert(got:find("bodies^1.50 (least squares over 4 sizes)", 1, true), got)
  assert(got:find("from 100 to 50,000 bodies", 1, true))
end)
T.test("the grid's figures come from the rows", function()
  assert(got:find("4.00 us per body-step at 1,000 bodies, 8.00 at 50,000 (x2.00; slope 1.18)", 1, true), got)
  assert(got:find("peak memory 12.0 KB per body at 50,000", 1, true))
  assert(got:find("costs up to 2.50x a settled step", 1, true)) -- 10 / 4 at 1,000 bodies
  assert(got:find("2 workers take x0.60 of one worker's time", 1, true))
  assert(got:find("carom takes 400 ms per step, Box3D 320 ms (x1.25); 12.0 against 3.6 KB per body", 1, true))
end)
T.test("the envelope marks a failing case", function()
  assert(got:find("| 5-box stack at dt 1/1000, 1/120, 1/30, 1/15 s (top, < 10 cm) | - / - / - / **no** (620 cm) |", 1, true), got)
  assert(got:find("yes (0.40 mm)", 1, true))
end)
T.test("narrowphase and quoted blocks", function()
  assert(got:find("sphere-sphere 74, hull-hull 7,921.", 1, true))
  assert(got:find("```\nterrain: line one\nfast mesh line two\n```", 1, true))
end)
T.test("blocks without results and the prose stay as they were", function()
  assert(got:find("old snapshot figures", 1, true))   -- no snapshot.txt in this run
  assert(got:find("old presets table", 1, true))      -- a sweep without rows
  assert(not got:find("old scaling figures", 1, true))
  local n = 0
  for _ in got:gmatch("prose between") do n = n + 1 end
  assert(n == 5 and got:sub(1, 9) == "# title\n\n" and got:sub(-6) == "tail\n\n" or got:sub(-5) == "tail\n")
end)

os.execute("rm -rf '" .. dir .. "'")
T.finish()
