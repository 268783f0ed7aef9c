-- docs_examples_test.lua - runs every example in docs/lua.md (fenced lua
-- blocks whose first line is "-- example: ..."), so the docs cannot rot.
-- Run by `make check` from the repository root with carom-run --test.
local root = os.getenv("CAROM_ROOT") or "."
local f = assert(io.open(root .. "/docs/lua.md", "r"))
local text = f:read("a")
f:close()
local ran, failed = 0, 0
for block in text:gmatch("```lua\n(.-)```") do
  local title = block:match("^%-%- example: ([^\n]*)")
  if title then
    local chunk, err = load(block, "=docs/lua.md: " .. title)
    local ok = chunk ~= nil
    if ok then ok, err = pcall(chunk) end
    ran = ran + 1
    if not ok then failed = failed + 1; print("FAIL " .. title .. ": " .. tostring(err)) end
  end
end
assert(ran > 0, "no examples found in docs/lua.md")
print(string.format("%d passed, %d failed", ran - failed, failed))
if failed > 0 then os.exit(1) end
