-- harness.lua - the one test harness of the Lua test files. A test file
-- loads it with
--   local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
-- and ends with T.finish(), which prints "N passed, M failed" and exits 1 on
-- any failure (what make check and carom-run --test read).
local T = { passed = 0, failed = 0 }

-- Runs fn as one test; an error fails it (with its traceback).
function T.test(name, fn)
  local ok, err = xpcall(fn, debug.traceback)
  if ok then T.passed = T.passed + 1 else T.failed = T.failed + 1; print("FAIL " .. name .. ": " .. tostring(err)) end
end

-- A check counted on its own (no traceback): cond true passes.
function T.check(cond, what)
  if cond then T.passed = T.passed + 1 else T.failed = T.failed + 1; print("FAIL " .. what) end
end

-- got is a number within tol of want.
function T.near(got, want, tol, what)
  if type(got) ~= "number" or not (math.abs(got - want) <= tol) then
    error(string.format("%s: got %s, expected %.12g (tolerance %g)", what or "value", tostring(got), want, tol), 2)
  end
end

-- fn(...) raises, and the message contains `text` (plain text, not a pattern);
-- returns the message.
function T.raises(text, fn, ...)
  local ok, err = pcall(fn, ...)
  if ok then error("expected an error containing '" .. text .. "', but the call succeeded", 2) end
  if not tostring(err):find(text, 1, true) then
    error("the error '" .. tostring(err) .. "' does not contain '" .. text .. "'", 2)
  end
  return tostring(err)
end

function T.finish()
  print(string.format("%d passed, %d failed", T.passed, T.failed))
  if T.failed > 0 then os.exit(1) end
end

return T
