-- docs_examples_test.lua - runs every example in docs/lua.md (fenced lua
-- blocks whose first line is "-- example: ..."), so the docs cannot rot.
-- Run by `make check` from the repository root with carom-run --test.
local root = os.getenv("CAROM_ROOT") or "."
local f = assert(io.open(root .. "/docs/lua.md", "r"))
local text = f:read("a")
f:close()
local T = dofile((arg[0]:match("^(.*[/\\])") or "") .. "harness.lua")
local ran = 0
for block in text:gmatch("```lua\n(.-)```") do
  local title = block:match("^%-%- example: ([^\n]*)")
  if title then
    ran = ran + 1
    T.test(title, function() assert(load(block, "=docs/lua.md: " .. title))() end)
  end
end
assert(ran > 0, "no examples found in docs/lua.md")
T.finish()
