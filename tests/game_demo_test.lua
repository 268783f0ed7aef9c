-- game_demo_test.lua - runs demos/game.lua headless with carom-run (the very
-- binary running this test, arg[-1]) and checks what it reports: every
-- launched ball passed up through the one-way platform and rests on it, the
-- platform's force events carry their weight (within 1 %), the trigger zone
-- counted crates in and out, the paddle hit balls and the gun hit bodies.
local RUNNER = arg and arg[-1]
assert(RUNNER and RUNNER:find("carom%-run"), "run me with carom-run --test (arg[-1] is the runner)")
local root = os.getenv("CAROM_ROOT") or "."
local out = os.tmpname()
local ok = os.execute(string.format("'%s' '%s/demos/game.lua' --quiet >'%s' 2>&1", RUNNER, root, out))
local f = assert(io.open(out))
local text = f:read("a")
f:close()
os.remove(out)
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local check = T.check
check(ok, "carom-run demos/game.lua exits 0:\n" .. text)
local rest, launched = text:match("one%-way platform: (%d+) of (%d+) balls launched from below went up through it and rest on it")
check(rest and rest == launched and tonumber(launched) >= 3, "every launched ball rests on the platform")
local carried, weight = text:match("it carries ([%d.]+) N %(their weight: ([%d.]+) N%)")
carried, weight = tonumber(carried), tonumber(weight)
check(carried and weight and weight > 0 and math.abs(carried - weight) <= 0.01 * weight, "the platform carries their weight")
local entries, exits, inside = text:match("trigger zone: (%d+) entries, (%d+) exits, (%d+) inside now")
entries, exits, inside = tonumber(entries), tonumber(exits), tonumber(inside)
check(entries and entries >= 3 and exits >= 1 and inside == entries - exits, "the zone counts bodies in and out")
local paddle = tonumber(text:match("paddle: hit (%d+) balls"))
check(paddle and paddle >= 1, "the paddle hits balls")
local shots, hits = text:match("ray gun: (%d+) shots, (%d+) hits")
check(tonumber(shots) and tonumber(hits) >= 1, "the gun hits")
if T.failed > 0 then print(text) end
T.finish()
