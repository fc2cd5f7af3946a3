#!/usr/bin/env bash
# Smoke test of a running limn, for containerised CI and deployments: health, readiness, one
# render of a shipped example with its exact reference and a bound on its silhouette error, one
# bad request with its JSON error, a one-row job through the job store, and /metrics counters
# that moved. Needs curl and python3.
#
#   scripts/smoke.sh [URL]          (default http://127.0.0.1:8080)
#   LIMN_AUTH_TOKEN=...             sent as a bearer token when set
# Exits 0 when every check passes, 1 at the first that fails (saying which).
set -euo pipefail
cd "$(dirname "$0")/.."
url="${1:-http://127.0.0.1:8080}"
url="${url%/}"
auth=()
[ -n "${LIMN_AUTH_TOKEN:-}" ] && auth=(-H "Authorization: Bearer $LIMN_AUTH_TOKEN")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

fail() { echo "smoke: FAIL: $*" >&2; exit 1; }
pass() { echo "smoke: ok: $*"; }

# status_of PATH [curl args...]: the HTTP status; the body goes to $work/body.
status_of() {
  local path=$1
  shift
  : >"$work/body"
  curl -s -o "$work/body" -w '%{http_code}' --max-time 120 "$@" "$url$path" || echo 000
}

metric() {  # the value of one exact series in /metrics (0 when absent)
  curl -s --max-time 10 "$url/metrics" | awk -v name="$1" '$1 == name {print $2; found = 1}
    END {if (!found) print 0}'
}

[ "$(status_of /healthz)" = 200 ] || fail "/healthz is not 200: $(head -c 300 "$work/body")"
/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["status"] == "ok", d' \
  "$work/body" || fail "/healthz does not say ok: $(head -c 300 "$work/body")"
pass "/healthz ok ($(/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["renderer"], "-", d["readyWorkers"], "workers")' "$work/body"))"
[ "$(status_of /readyz)" = 200 ] || fail "/readyz is not 200: $(head -c 300 "$work/body")"
pass "/readyz ready"

before=$(metric 'limn_requests_total{path="/v1/render",status="200"}')

# The creased torus shipped in examples/, adaptive at 256^2 with its exact reference.
/usr/bin/python3 - "$work/render.json" <<'PY'
import json, sys
obj = open("examples/torus_creased.obj").read()
json.dump({"mesh": {"format": "obj", "data": obj}, "camera": {"width": 256, "height": 256},
           "method": "adaptive", "outputs": ["color"], "reference": True}, open(sys.argv[1], "w"))
PY
status=$(status_of /v1/render -X POST -H 'Content-Type: application/json' "${auth[@]}" \
  --data-binary @"$work/render.json")
[ "$status" = 200 ] || fail "render answered $status: $(head -c 300 "$work/body")"
/usr/bin/python3 - "$work/body" <<'PY' || fail "the render's answer is not what it should be"
import base64, json, sys
answer = json.load(open(sys.argv[1]))
png = base64.b64decode(answer["images"]["color"]["data"])
assert png[:8] == b"\x89PNG\r\n\x1a\n", "the colour image is not a PNG"
silhouette = answer["metrics"]["silhouette"]
# Adaptive at dicing rate 1 is within a pixel of the exact outline (docs/engine.md).
assert silhouette["outlineHausdorffPx"] < 1.0, silhouette
assert silhouette["iou"] > 0.99, silhouette
print(f"smoke: ok: render of examples/torus_creased.obj: {answer['stats']['triangles']} triangles, "
      f"outline Hausdorff {silhouette['outlineHausdorffPx']:.3f} px, IoU {silhouette['iou']:.4f}, "
      f"{answer['timings']['totalMs']:.0f} ms")
PY

status=$(status_of /v1/render -X POST -H 'Content-Type: application/json' "${auth[@]}" \
  --data-binary '{"mesh": {"format": "obj", "data": "v 0 0 0\nv 1 0 0\nf 1 2 3\n"}}')
[ "$status" = 422 ] || fail "a face naming a missing vertex answered $status, not 422"
/usr/bin/python3 -c 'import json,sys; e=json.load(open(sys.argv[1]))["error"]; assert e["code"] == "invalid_mesh" and "line 3" in e["message"], e' \
  "$work/body" || fail "the 422 does not name the line: $(head -c 300 "$work/body")"
pass "bad mesh refused: $(head -c 160 "$work/body")"

# A one-row job through the job store (the image's SQLite file on its volume, or PostgreSQL):
# accepted, computed, and its rows downloadable as CSV.
/usr/bin/python3 -c 'import json,sys
obj = open(sys.argv[1]).read()
print(json.dumps({"meshes": [{"name": "cube", "mesh": {"format": "obj", "data": obj}}],
                  "methods": ["coarse"], "cameras": ["front"], "size": 32}))' \
  examples/cube.obj >"$work/job.json"
status=$(status_of /v1/jobs -X POST -H 'Content-Type: application/json' "${auth[@]}" \
  --data-binary @"$work/job.json")
[ "$status" = 202 ] || fail "POST /v1/jobs answered $status: $(head -c 300 "$work/body")"
job=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["id"])' "$work/body")
state=queued
for _ in $(seq 600); do
  status=$(status_of "/v1/jobs/$job" "${auth[@]}")
  [ "$status" = 200 ] || fail "GET /v1/jobs/$job answered $status: $(head -c 300 "$work/body")"
  state=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["state"])' "$work/body")
  [ "$state" = queued ] || [ "$state" = running ] || break
  sleep 0.1
done
[ "$state" = done ] || fail "the job ended $state: $(head -c 300 "$work/body")"
status=$(status_of "/v1/jobs/$job/results.csv" "${auth[@]}")
[ "$status" = 200 ] && [ "$(wc -l <"$work/body")" -eq 2 ] ||
  fail "results.csv answered $status with $(wc -l <"$work/body") lines"
pass "a one-row job through the job store: done, results.csv has its row"

after=$(metric 'limn_requests_total{path="/v1/render",status="200"}')
[ "${after%.*}" -gt "${before%.*}" ] || fail "/metrics did not count the render ($before -> $after)"
refused=$(metric 'limn_requests_total{path="/v1/render",status="422"}')
[ "${refused%.*}" -ge 1 ] || fail "/metrics did not count the 422"
pass "/metrics counted the render ($before -> $after) and the 422"
echo "smoke: passed against $url"
