#!/usr/bin/env bash
# Throughput of small requests: a cube at 256^2, method adaptive (dicingRate 2), colour only, no
# reference, from 8 concurrent clients for 20 s (hey, from Debian), against a limn server this
# script starts on a free loopback port and stops afterwards. Prints hey's summary.
# ANTIALIAS=N sets the request's "antialias" (default: the server's, 4).
#
#   [ANTIALIAS=N] bench/load_small.sh [DURATION] [CLIENTS] [extra limn serve flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
duration="${1:-20s}"
clients="${2:-8}"
shift $(( $# > 2 ? 2 : $# ))
command -v hey >/dev/null || { echo "hey is not installed (apt-get install hey)" >&2; exit 1; }
port=$(( 20000 + RANDOM % 20000 ))
build/bin/limn serve --listen "127.0.0.1:$port" "$@" 2>/tmp/limn-load.log &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null || true' EXIT
for _ in $(seq 100); do curl -sf "127.0.0.1:$port/readyz" >/dev/null && break; sleep 0.1; done
body=$(mktemp)
cat > "$body" <<'JSON'
{"mesh": {"format": "obj", "data": "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n"},
 "camera": {"width": 256, "height": 256}, "method": "adaptive", "params": {"dicingRate": 2},
 "outputs": ["color"]}
JSON
if [ -n "${ANTIALIAS:-}" ]; then
  sed -i "s/\"outputs\": \[\"color\"\]/\"outputs\": [\"color\"], \"antialias\": $ANTIALIAS/" "$body"
fi
curl -sf -X POST --data-binary @"$body" "127.0.0.1:$port/v1/render" | python3 -c \
  'import json,sys; t=json.load(sys.stdin)["timings"]; print("one request:", {k: round(v, 2) for k, v in t.items() if isinstance(v, float)})'
hey -z "$duration" -c "$clients" -m POST -T application/json -D "$body" \
  "http://127.0.0.1:$port/v1/render" | grep -v '|' | grep -v '^ *$'
rm -f "$body"
