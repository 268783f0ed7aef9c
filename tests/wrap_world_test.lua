-- wrap_world_test.lua - lua/wrap_world.c's snapshot, restore and threads option.
-- w:snapshot() and carom.restore(s): a mixed scene snapshotted at step 137
-- and restored continues bit for bit for 500 steps (the two worlds'
-- snapshots are equal strings after every step, and their events equal); a
-- restored world's snapshot is the string it came from; truncated,
-- corrupted and foreign strings raise a clear error.
-- The world option threads = N (the reference thread pool): a pile stepped
-- on 1, 3 and 2 threads (switched by configure midway) gives equal
-- snapshots after every step; bad values raise clear errors; carom-run
-- --threads N records the same poses as one thread.
-- Run by `make check` as `carom-run --test tests/wrap_world_test.lua`.
local carom = require "carom"
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local test, raises = T.test, T.raises
local RUNNER = arg and arg[-1]

-- ---- snapshot and restore (was snapshot_test.lua) ----

local function mixed_scene(preset)
  local w = carom.world{ preset = preset }
  w:add_body{ type = "static", shape = carom.plane{} }
  w:add_body{ type = "static", shape = carom.box{ half_extents = {0.2, 3, 1} }, position = {3, 0, 1} }
  local shapes = {
    carom.sphere{ radius = 0.2 }, carom.box{ half_extents = {0.2, 0.15, 0.1} },
    carom.capsule{ radius = 0.1, half_height = 0.2 }, carom.cylinder{ radius = 0.15, half_height = 0.1 },
    carom.hull{ {0, 0, 0}, {0.4, 0, 0}, {0, 0.4, 0}, {0, 0, 0.4}, {0.3, 0.3, 0.3} },
  }
  local doomed = {}
  for i = 0, 29 do
    local b = w:add_body{
      shape = shapes[i % 5 + 1],
      position = {-1.5 + 0.5 * (i % 6), -1 + 0.6 * (i // 6 % 4), 0.3 + 0.5 * (i // 24) + 0.05 * (i % 3)},
      velocity = {0.3 * (i % 4) - 0.4, 0.2 * (i % 3) - 0.2, -0.5 * (i % 2)},
      angular_velocity = {0.5 * (i % 3), -0.3 * (i % 2), 0.2},
      restitution = (i % 4) * 0.25, friction = 0.2 + 0.1 * (i % 7), density = 500 + 100 * (i % 5),
      lock_rotation = i == 7, bullet = i == 13,
    }
    if i % 9 == 4 then doomed[#doomed + 1] = b end
  end
  w:add_body{ shape = carom.box{ half_extents = {0.3, 0.3, 0.3} }, position = {-6, 6, 0.3} }
  w:add_body{ shape = carom.box{ half_extents = {0.3, 0.3, 0.3} }, position = {-6, -6, 0.3}, awake = false }
  w:add_body{ type = "kinematic", shape = carom.box{ half_extents = {0.1, 1.5, 0.2} }, position = {-3, 0, 0.25},
              velocity = {0.8, 0, 0}, angular_velocity = {0, 0, 0.3} }
  w:add_body{ shape = carom.sphere{ radius = 0.05 }, position = {0, 2, 1.5}, velocity = {60, 0, 0}, restitution = 0.8 }
  for _ = 1, 40 do w:step(1 / 60) end
  for _, b in ipairs(doomed) do b:destroy() end
  return w
end

local function same_events(a, b, step)
  local ea, eb = a:events(), b:events()
  assert(#ea == #eb, ("step %d: %d events against %d"):format(step, #ea, #eb))
  for i = 1, #ea do
    for k, v in pairs(ea[i]) do
      local u = eb[i][k]
      if type(v) == "userdata" then v, u = v:id(), u:id() end
      if type(v) == "table" then
        for j = 1, #v do assert(v[j] == u[j], ("step %d: event %d field %s differs"):format(step, i, k)) end
      else
        assert(v == u, ("step %d: event %d field %s differs"):format(step, i, k))
      end
    end
  end
end

for _, preset in ipairs{ "fast", "default", "accurate" } do
  test("restored at step 137 continues bit for bit for 500 steps (" .. preset .. ")", function()
    local a = mixed_scene(preset)
    for _ = 41, 137 do a:step(1 / 60) end
    local s = a:snapshot()
    assert(type(s) == "string" and #s > 1000)
    local b = carom.restore(s)
    assert(b:snapshot() == s, "the snapshot of the restored world is not the snapshot")
    assert(b:body_count() == a:body_count() and #b:bodies() == a:body_count())
    local hits = 0
    for step = 138, 137 + 500 do
      a:step(1 / 60)
      b:step(1 / 60)
      same_events(a, b, step)
      for _, e in ipairs(a:events()) do if e.type == "hit" then hits = hits + 1 end end
      assert(a:snapshot() == b:snapshot(), "snapshots differ after step " .. step)
    end
    assert(hits > 0, "the scene raised no hit events")
  end)
end

test("a restored world's bodies are its own: positions, destroy, callbacks", function()
  local a = mixed_scene("default")
  local b = carom.restore(a:snapshot())
  local ba, bb = a:bodies(), b:bodies()
  assert(#ba == #bb)
  for i = 1, #ba do
    local pa, pb = {ba[i]:position()}, {bb[i]:position()}
    for k = 1, 3 do assert(pa[k] == pb[k]) end
  end
  local calls = 0
  b:set_contact_callback(function() calls = calls + 1 end)
  for _ = 1, 30 do b:step(1 / 60) end
  assert(calls > 0, "the restored world's callback never ran")
  bb[5]:destroy()
  assert(b:body_count() == #bb - 1)
end)

test("world:restore(s) makes a world the snapshot's, again and again, and refuses bad strings", function()
  local a = mixed_scene("default")
  for _ = 41, 137 do a:step(1 / 60) end
  local s = a:snapshot()
  local other = mixed_scene("fast"):snapshot()
  local b = mixed_scene("fast")
  local calls = 0
  b:set_contact_callback(function() calls = calls + 1 end)
  local kept = b:bodies()[4]
  kept.user_data = "kept"
  for round = 1, 3 do
    assert(b:restore(round == 2 and other or s) == b)
    assert(b:snapshot() == (round == 2 and other or s))
  end
  assert(b:body_count() == a:body_count() and #b:bodies() == a:body_count())
  assert(kept.user_data == "kept", "the user_data of a body in both states was lost")
  for _, bad in ipairs{ other:sub(1, #other - 1), "hello", other:sub(1, 8) .. "\9" .. other:sub(10) } do
    raises("snapshot: ", b.restore, b, bad)
    assert(b:snapshot() == s, "a refused snapshot changed the world")
  end
  raises("string (from world:snapshot()) expected, got number", b.restore, b, 42)
  for step = 138, 237 do
    a:step(1 / 60)
    b:step(1 / 60)
    same_events(a, b, step)
    assert(a:snapshot() == b:snapshot(), "snapshots differ after step " .. step)
  end
  assert(calls > 0, "the kept contact callback never ran")
end)

test("bad snapshots raise a clear error", function()
  local s = mixed_scene("fast"):snapshot()
  raises("string (from world:snapshot()) expected, got number", carom.restore, 42)
  raises("not a carom snapshot", carom.restore, "hello")
  for _, n in ipairs{ 0, 1, 31, 32, 33, 100, #s // 2, #s - 1 } do raises("snapshot: ", carom.restore, s:sub(1, n)) end
  raises("truncated or padded", carom.restore, s .. "x")
  local flipped = s:sub(1, 200) .. string.char((s:byte(201) + 1) % 256) .. s:sub(202)
  raises("checksum", carom.restore, flipped)
  raises("version 9", carom.restore, s:sub(1, 8) .. "\9" .. s:sub(10))
end)


-- ---- the threads option (was threads_test.lua) ----

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
