#!/usr/bin/env bash
# What render worker processes cost against worker threads, both measured in this one run on
# this build (workerIsolation "process", the default, and "thread", the way limn ran before):
#   - small-request throughput: a cube at 256^2, adaptive (dicingRate 2), colour only, 8 wrk
#     connections for DURATION, the two modes alternated ROUNDS times;
#   - one request at a time (sequential curl): small, and a large answer (a 4096^2 coarse
#     render with colour, depth and normal, about 60 MB of JSON), whose difference between
#     the modes is the inter-process cost per request.
#
#   bench/worker_isolation_bench.sh [DURATION] [ROUNDS]      (default 15s, 2)
set -euo pipefail
cd "$(dirname "$0")/.."
duration="${1:-15s}"
rounds="${2:-2}"
work=$(mktemp -d)
trap 'kill $server 2>/dev/null || true; rm -rf "$work"' EXIT
server=0
cube='v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n'
printf '{"mesh": {"format": "obj", "data": "%s"}, "camera": {"width": 256, "height": 256}, "method": "adaptive", "params": {"dicingRate": 2}, "outputs": ["color"]}' "$cube" > "$work/small.json"
printf '{"mesh": {"format": "obj", "data": "%s"}, "camera": {"width": 4096, "height": 4096}, "method": "coarse", "outputs": ["color", "depth", "normal"], "imageFormat": "exr"}' "$cube" > "$work/large.json"
cat > "$work/post.lua" <<LUA
local f = assert(io.open("$work/small.json", "rb"))
wrk.method = "POST"
wrk.body = f:read("*a")
wrk.headers["Content-Type"] = "application/json"
f:close()
statuses = {}
function response(status) statuses[status] = (statuses[status] or 0) + 1 end
done = function(summary, latency)
  io.write(string.format("ROW %.1f %.1f %.1f %.1f %d\n", summary.requests / (summary.duration / 1e6),
    latency:percentile(50) / 1000, latency:percentile(90) / 1000, latency:percentile(99) / 1000,
    summary.errors.status + summary.errors.connect + summary.errors.timeout))
end
LUA

start_server() {  # $1 = process | thread
  printf '{"port": 0, "workers": 2, "workerIsolation": "%s", "logLevel": "off"}' "$1" > "$work/config.json"
  build/bin/limn serve --config "$work/config.json" > "$work/out" 2> "$work/err" &
  server=$!
  for _ in $(seq 300); do grep -q "listening on" "$work/out" && break; sleep 0.05; done
  url=$(grep -o 'http://[^ ]*' "$work/out")
  curl -sf -X POST --data-binary @"$work/small.json" "$url/v1/render" > /dev/null  # warm up
}
stop_server() { kill -TERM $server; wait $server 2>/dev/null || true; }

# Mean wall time of N sequential requests of a body, in ms.
sequential() {  # $1 body, $2 count
  local total=0
  for _ in $(seq "$2"); do
    t=$(curl -s -o /dev/null -w '%{time_total}' -X POST --data-binary @"$1" "$url/v1/render")
    total=$(python3 -c "print($total + $t)")
  done
  python3 -c "print(round($total / $2 * 1000, 1))"
}

echo "| mode | round | requests/s | p50 ms | p90 ms | p99 ms | errors |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for round in $(seq "$rounds"); do
  for mode in thread process; do
    start_server "$mode"
    row=$(wrk -t2 -c8 -d"$duration" -s "$work/post.lua" "$url/v1/render" | grep '^ROW')
    read -r _ rps p50 p90 p99 errors <<< "$row"
    echo "| $mode | $round | $rps | $p50 | $p90 | $p99 | $errors |"
    stop_server
  done
done
echo
echo "| mode | small request, sequential mean ms (200) | 4096² colour+depth+normal EXR answer, mean ms (5) | answer MB |"
echo "|---|---:|---:|---:|"
for mode in thread process; do
  start_server "$mode"
  small=$(sequential "$work/small.json" 200)
  large=$(sequential "$work/large.json" 5)
  bytes=$(curl -s -X POST --data-binary @"$work/large.json" "$url/v1/render" | wc -c)
  echo "| $mode | $small | $large | $(python3 -c "print(round($bytes / 1e6, 1))") |"
  stop_server
done
