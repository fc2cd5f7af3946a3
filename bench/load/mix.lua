-- wrk script for bench/load_mix.sh: a mix of small and heavy requests, chosen at random per
-- request with fixed weights, and a count of answers by status (and of 429s without a
-- Retry-After header) reported when the run ends.
local dir = os.getenv("LIMN_LOAD_DIR")
local kinds = {
  -- name, weight (percent), path, body file
  {"small", 70, "/v1/render", "small.json"},
  {"silhouette", 10, "/v1/silhouette", "small.json"},
  {"heavy", 10, "/v1/render", "heavy.json"},
  {"invalid", 10, "/v1/render", "invalid.json"},
}
local requests = {}

function init(args)
  math.randomseed(os.time() + tonumber(tostring({}):match("0x(%x+)"), 16))
  for _, k in ipairs(kinds) do
    local f = assert(io.open(dir .. "/" .. k[4], "rb"))
    local body = f:read("*a")
    f:close()
    k.request = wrk.format("POST", k[3], {["Content-Type"] = "application/json"}, body)
  end
  statuses = {}
  noRetryAfter = 0
end

function request()
  local r = math.random(100)
  for _, k in ipairs(kinds) do
    r = r - k[2]
    if r <= 0 then return k.request end
  end
  return kinds[1].request
end

function response(status, headers, body)
  statuses[status] = (statuses[status] or 0) + 1
  if status == 429 and headers["Retry-After"] == nil then noRetryAfter = noRetryAfter + 1 end
end

local threads = {}
function setup(thread) table.insert(threads, thread) end

function done(summary, latency, requests)
  local total = {}
  local missing = 0
  for _, t in ipairs(threads) do
    for status, n in pairs(t:get("statuses")) do total[status] = (total[status] or 0) + n end
    missing = missing + t:get("noRetryAfter")
  end
  io.write("statuses:")
  for status, n in pairs(total) do io.write(string.format(" %d=%d", status, n)) end
  io.write(string.format("\n429 without Retry-After: %d\n", missing))
  io.write(string.format("requests/s: %.1f\n", summary.requests / (summary.duration / 1e6)))
  for _, p in ipairs({50, 90, 99}) do
    io.write(string.format("p%d ms: %.1f\n", p, latency:percentile(p) / 1000))
  end
  io.write(string.format("max ms: %.1f\nsocket errors: connect %d read %d write %d timeout %d\n",
    latency.max / 1000, summary.errors.connect, summary.errors.read, summary.errors.write,
    summary.errors.timeout))
end
