-- threads_test.lua - the world option threads = N (the reference thread
-- pool): a pile stepped on 1, 3 and 2 threads (switched by configure midway)
-- gives equal snapshots after every step; bad values raise clear errors;
-- carom-run --threads N records the same poses as one thread.
-- Run by `make check` as `carom-run --test tests/threads_test.lua`.
local carom = require "carom"
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test, raises = T.test, T.raises
local RUNNER = arg and arg[-1]

-- enough bodies and contacts that every stage hands its loops to the pool
local function pile(threads)
  local w = carom.world{ threads = threads, sleep = false }
  w:add_body{ type = "static", shape = carom.plane{} }
  local shapes = { carom.box{ half_extents = {0.2, 0.2, 0.2} }, carom.sphere{ radius = 0.2 },
                   carom.capsule{ radius = 0.1, half_height = 0.15 } }
  for i = 0, 399 do
    w:add_body{ shape = shapes[i % 3 + 1], friction = 0.5,
                position = {0.45 * (i % 10) + 0.02 * (i % 3), 0.45 * (i // 10 % 10), 0.25 + 0.45 * (i // 100)},
                angular_velocity = {0.3 * (i % 2), 0, 0.1} }
  end
  return w
end

test("1, 3 and 2 threads step bit for bit alike", function()
  local a, b = pile(1), pile(3)
  assert(a:settings().threads == 1 and b:settings().threads == 3, "settings report the thread count")
  for step = 1, 60 do
    if step == 30 then b:configure{ threads = 2 }; assert(b:settings().threads == 2) end
    a:step(1 / 60)
    b:step(1 / 60)
    if a:snapshot() ~= b:snapshot() then error("snapshots differ after step " .. step) end
  end
  b:configure{ threads = 1 }
  a:step(1 / 60)
  b:step(1 / 60)
  assert(a:snapshot() == b:snapshot(), "back on one thread")
  b:destroy()
end)

test("bad thread counts are refused", function()
  raises("threads: workers must be in 1..64 (got 0)", carom.world, { threads = 0 })
  raises("threads: workers must be in 1..64 (got 65)", carom.world, { threads = 65 })
  raises("threads must be an integer", carom.world, { threads = 1.5 })
  raises("threads must be a number", carom.world, { threads = "two" })
  local w = carom.world{ threads = 2 }
  raises("threads: workers must be in 1..64 (got -1)", w.configure, w, { threads = -1 })
  assert(w:settings().threads == 2, "a refused configure changes nothing")
end)

test("carom-run --threads records the same poses", function()
  assert(RUNNER and RUNNER:find("carom%-run"), "run me with carom-run --test")
  local dir = (arg[0]:match("^(.*[/\\])") or "") .. "../demos/pyramid.lua"
  local function record(extra)
    local out = os.tmpname()
    local cmd = string.format("'%s' '%s' --steps 40 --quiet --record '%s' %s >/dev/null 2>&1", RUNNER, dir, out, extra)
    local ok = os.execute(cmd)
    assert(ok, "carom-run failed: " .. cmd)
    local f = assert(io.open(out))
    local text = f:read("a")
    f:close()
    os.remove(out)
    return text
  end
  local one, two = record(""), record("--threads 2")
  assert(#one > 1000 and one == two, "the recorded poses differ")
  local code = select(3, os.execute(string.format("'%s' '%s' --threads 0 >/dev/null 2>&1", RUNNER, dir)))
  assert(code == 2 or code == 1, "--threads 0 refused")
end)

T.finish()
