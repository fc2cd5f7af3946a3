#!/usr/bin/env bash
# Small requests against heavy ones (issue 25), measured in one run on this build: 8 clients of
# small renders (a cube at 256^2, adaptive dicingRate 2, colour only) and 2 clients of heavy
# renders (a 5,000-face torus at 1024^2, adaptive, with the exact reference), each group its own
# wrk, against `limn serve` with its defaults (2 workers) on a free loopback port. Three runs:
# small alone, heavy alone, both together. Prints one Markdown table: per group requests/s,
# p50/p90/p99 latency, 429s, time-outs, other errors; and /metrics' cost-estimate ratios.
#
#   bench/lanes_bench.sh [DURATION] [extra limn serve flags...]     (default 60s)
#   LIMN_BENCH_CONFIG='"reservedInteractiveWorkers": 0, "heavyRequestMs": 1000000000'
#       adds configuration keys (that one: one FIFO lane, as limn was before lanes)
#   LIMN_BENCH_RUNS="mixed"   only the mixed run (default: "small heavy mixed")
#   ANTIALIAS=1               every request drawn with one sample per pixel (default: 4)
set -euo pipefail
cd "$(dirname "$0")/.."
duration="${1:-60s}"
shift $(( $# > 0 ? 1 : 0 ))
command -v wrk >/dev/null || { echo "wrk is not installed (apt-get install wrk)" >&2; exit 1; }
work=$(mktemp -d)
server=0
trap 'kill $server 2>/dev/null || true; rm -rf "$work"' EXIT

# The 5,000-face torus: 100 x 50 quads.
/usr/bin/python3 bench/load/requests.py "$work" 100 50
# ANTIALIAS=N: every request's "antialias" (default: the server's, 4).
if [ -n "${ANTIALIAS:-}" ]; then
  for kind in small heavy; do
    /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); r["antialias"] = int(sys.argv[2]); json.dump(r, open(sys.argv[1], "w"))' \
      "$work/$kind.json" "$ANTIALIAS"
  done
fi

for kind in small heavy; do
  cat > "$work/$kind.lua" <<LUA
local f = assert(io.open("$work/$kind.json", "rb"))
wrk.method = "POST"
wrk.body = f:read("*a")
wrk.headers["Content-Type"] = "application/json"
f:close()
done = function(summary, latency)
  io.write(string.format("ROW %.1f %.0f %.0f %.0f %d %d %d\n", summary.requests / (summary.duration / 1e6),
    latency:percentile(50) / 1000, latency:percentile(90) / 1000, latency:percentile(99) / 1000,
    summary.errors.status, summary.errors.timeout, summary.errors.connect + summary.errors.read + summary.errors.write))
end
LUA
done

start_server() {
  printf '{"port": 0, "logLevel": "off"%s}' "${LIMN_BENCH_CONFIG:+, $LIMN_BENCH_CONFIG}" > "$work/config.json"
  build/bin/limn serve --config "$work/config.json" --job-store sqlite::memory: "$@" > "$work/out" 2> "$work/err" &
  server=$!
  for _ in $(seq 300); do grep -q "listening on" "$work/out" && break; sleep 0.05; done
  url=$(grep -o 'http://[^ ]*' "$work/out")
  # Warm-up: the workers' first frames, and the speed the estimates learn.
  for _ in 1 2 3; do curl -s -o /dev/null -X POST --data-binary @"$work/small.json" "$url/v1/render"; done
  curl -s -o /dev/null -X POST --data-binary @"$work/heavy.json" "$url/v1/render"
}
stop_server() { kill -TERM $server; wait $server || true; }

# wrk KIND CONNECTIONS -> "ROW rps p50 p90 p99 non2xx timeouts errors" in $work/KIND.row
run_wrk() {
  wrk -t1 -c"$2" -d"$duration" --timeout 10s -s "$work/$1.lua" "$url/v1/render" | grep '^ROW' > "$work/$1.row"
}

print_row() {  # SETUP GROUP
  read -r _ rps p50 p90 p99 non2xx timeouts errors < "$work/$2.row"
  echo "| $1 | $2 | $rps | $p50 | $p90 | $p99 | $non2xx | $timeouts | $errors |"
}

echo "| setup | clients | requests/s | p50 ms | p90 ms | p99 ms | non-2xx (429) | time-outs | errors |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
runs="${LIMN_BENCH_RUNS:-small heavy mixed}"
if [[ " $runs " == *" small "* ]]; then
  start_server "$@"; run_wrk small 8; print_row "small alone" small; stop_server
fi
if [[ " $runs " == *" heavy "* ]]; then
  start_server "$@"; run_wrk heavy 2; print_row "heavy alone" heavy; stop_server
fi
[[ " $runs " == *" mixed "* ]] || exit 0
start_server "$@"
run_wrk small 8 & small_pid=$!
run_wrk heavy 2
wait $small_pid
print_row "mixed" small
print_row "mixed" heavy
echo
echo "Cost estimate, measured over estimated run time (limn_cost_estimate_ratio, mixed run):"
curl -s "$url/metrics" | grep -E '^limn_cost_estimate_ratio_(bucket|count)|^limn_cost_speed_factor|^limn_admission_refusals_total|^limn_admissions_total'
stop_server
