#!/usr/bin/env bash
# Saturation with a mix of small and heavy requests (wrk, from Debian): 70% small renders (a
# cube at 256^2), 10% contour searches, 10% heavy renders (a 512-face torus at 1024^2 with its
# exact reference and metrics), 10% invalid meshes (422), from CLIENTS connections for
# DURATION, against a limn server this script starts on a free loopback port. While it runs,
# the server's resident memory and /metrics' queue depth are sampled every 0.5 s. Prints wrk's
# summary with the answers by status, peak and idle RSS, the deepest queue seen, and fails
# (exit 1) when any answer is not 200, 422, 429 (with Retry-After) or 504, when the queue
# exceeded its bound, or when the server died.
#
#   bench/load_mix.sh [DURATION] [CLIENTS] [extra limn serve flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
duration="${1:-60s}"
clients="${2:-16}"
shift $(( $# > 2 ? 2 : $# ))
command -v wrk >/dev/null || { echo "wrk is not installed (apt-get install wrk)" >&2; exit 1; }
export LIMN_LOAD_DIR
LIMN_LOAD_DIR=$(mktemp -d)
port=$(( 20000 + RANDOM % 20000 ))
config="$LIMN_LOAD_DIR/config.json"
echo '{"queueDepth": 16, "requestTimeoutMs": 4000, "logLevel": "warn"}' > "$config"
build/bin/limn serve --listen "127.0.0.1:$port" --config "$config" "$@" 2>"$LIMN_LOAD_DIR/server.log" &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null || true; rm -rf "$LIMN_LOAD_DIR"' EXIT
for _ in $(seq 100); do curl -sf "127.0.0.1:$port/readyz" >/dev/null && break; sleep 0.1; done

/usr/bin/python3 bench/load/requests.py "$LIMN_LOAD_DIR"

pid_rss() { awk '/VmRSS/ {print $2}' "/proc/$server/status" 2>/dev/null || echo 0; }
echo "idle RSS before: $(( $(pid_rss) / 1024 )) MiB"
samples="$LIMN_LOAD_DIR/samples"
( while kill -0 $server 2>/dev/null; do
    depth=$(curl -sf --max-time 1 "127.0.0.1:$port/metrics" | awk '$1 == "limn_queue_depth" {print $2}')
    echo "$(pid_rss) ${depth:-0}"
    sleep 0.5
  done > "$samples" ) &
sampler=$!
report="$LIMN_LOAD_DIR/wrk.txt"
wrk -t 2 -c "$clients" -d "$duration" --timeout 30s -s bench/load/mix.lua \
  "http://127.0.0.1:$port" | tee "$report"
kill $sampler 2>/dev/null || true
wait $sampler 2>/dev/null || true
kill -0 $server || { echo "FAIL: the server died under load" >&2; exit 1; }
sleep 5
capacity=$(curl -sf "127.0.0.1:$port/metrics" | awk '$1 == "limn_queue_capacity" {print $2}')
peak_rss=$(awk 'BEGIN {m = 0} $1 > m {m = $1} END {print m}' "$samples")
deepest=$(awk 'BEGIN {m = 0} $2 > m {m = $2} END {print m}' "$samples")
echo "peak RSS: $(( peak_rss / 1024 )) MiB; idle RSS 5 s after: $(( $(pid_rss) / 1024 )) MiB"
echo "deepest queue seen: $deepest of $capacity"
status=0
bad=$(grep '^statuses:' "$report" | tr ' ' '\n' | grep '=' | grep -Ev '^(200|422|429|504)=' || true)
[ -z "$bad" ] || { echo "FAIL: unexpected answers: $bad" >&2; status=1; }
grep -q '^429 without Retry-After: 0$' "$report" || { echo "FAIL: a 429 without Retry-After" >&2; status=1; }
[ "$deepest" -le "$capacity" ] || { echo "FAIL: queue over its bound" >&2; status=1; }
curl -sf "127.0.0.1:$port/healthz" >/dev/null || { echo "FAIL: /healthz after the load" >&2; status=1; }
exit $status
