#!/usr/bin/env bash
# Builds limn's container image (docker/Dockerfile) with podman and smoke-tests it the way a
# cluster runs it: as its non-root user, read-only root filesystem with a tmpfs /tmp, no init.
#   1. podman, runc, debootstrap and podman-compose from Debian packages when missing;
#   2. a Debian 12 base image made with debootstrap from the mirror apt already uses, imported
#      once and kept (no container registry is needed);
#   3. the image, with podman's layer cache and the build stage's ccache (a second build with
#      no change takes seconds, one after a source change recompiles what changed);
#   4. no compiler in the image, a HEALTHCHECK, a non-root user, STOPSIGNAL SIGTERM;
#   5. a container on a free host port, then the same through docker/compose.yaml
#      (podman-compose): scripts/smoke.sh against each, its HEALTHCHECK through `podman
#      healthcheck run` (there is no systemd timer here), SIGTERM ending it promptly with exit
#      status 0.
# Prints the build time and the image size. Needs root (podman as set up here, apt).
#
#   scripts/container-smoke.sh                 build and test localhost/limn:dev
#   LIMN_IMAGE=NAME LIMN_JOBS=N ...            another tag; compile jobs (default: all cores)
#   LIMN_SMOKE_REPORT=1 ...                    also build the `report` stage and check it
set -euo pipefail
cd "$(dirname "$0")/.."
image="${LIMN_IMAGE:-localhost/limn:dev}"
base="${LIMN_BASE_IMAGE:-localhost/limn-debian:bookworm}"
jobs="${LIMN_JOBS:-$(nproc)}"
start=$SECONDS
say() { echo "container-smoke: $*"; }
fail() { echo "container-smoke: FAIL: $*" >&2; exit 1; }

if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
missing=()
for tool in podman runc debootstrap podman-compose; do
  command -v "$tool" >/dev/null || missing+=("$tool")
done
if [ ${#missing[@]} -gt 0 ]; then
  say "installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  # The lock timeout: other builds on a shared machine may be installing packages too.
  $sudo apt-get -o DPkg::Lock::Timeout=600 update -qq
  $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

work=$(mktemp -d)
container="limn-smoke-$$"
project="limn-smoke-compose-$$"
compose=(podman-compose -p "$project" -f docker/compose.yaml)
cleanup() {
  podman rm -f -t 0 "$container" >/dev/null 2>&1 || true
  "${compose[@]}" down -v -t 0 >/dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT

# runc, not crun: crun fails on these machines (rlimits under hybrid cgroups). Explicit
# ulimits, because the defaults podman would pass on are the host's, which runc cannot set in
# every sandbox. CONTAINERS_CONF replaces the system's file for this script only.
cat >"$work/containers.conf" <<'EOF'
[containers]
default_ulimits = ["nofile=20000:20000", "nproc=32768:32768"]

[engine]
runtime = "runc"
EOF
export CONTAINERS_CONF="$work/containers.conf"

# --- the base image --------------------------------------------------------------------------
# Debian 12 from the mirror apt uses on this machine (its sources, both one-line and deb822
# formats), with the same suites (updates, security) so the image gets the same fixes.
debian_sources() {
  /usr/bin/python3 - <<'PY'
import glob, re
entries = []
def add(uri, suites, components):
    for suite in suites:
        if suite.startswith("bookworm"):
            entries.append((uri.rstrip("/"), suite, components or ["main"]))
for path in ["/etc/apt/sources.list"] + sorted(glob.glob("/etc/apt/sources.list.d/*.list")):
    try:
        lines = open(path).read().splitlines()
    except OSError:
        continue
    for line in lines:
        line = re.sub(r"\[[^]]*\]", "", line.split("#", 1)[0]).split()
        if len(line) >= 3 and line[0] == "deb":
            add(line[1], [line[2]], line[3:])
for path in sorted(glob.glob("/etc/apt/sources.list.d/*.sources")):
    for stanza in re.split(r"\n\s*\n", open(path).read()):
        fields = {}
        for line in stanza.splitlines():
            if line.startswith("#") or ":" not in line or line[0].isspace():
                continue
            key, value = line.split(":", 1)
            fields[key.strip().lower()] = value.split()
        if "deb" in fields.get("types", []) and fields.get("enabled", ["yes"]) != ["no"]:
            for uri in fields.get("uris", []):
                add(uri, fields.get("suites", []), fields.get("components", []))
for uri, suite, components in dict.fromkeys((u, s, tuple(c)) for u, s, c in entries):
    print(f"deb {uri} {suite} {' '.join(components)}")
PY
}

if podman image exists "$base"; then
  say "base image $base exists"
else
  sources=$(debian_sources)
  mirror=$(awk '$3 == "bookworm" {print $2; exit}' <<<"$sources")
  [ -n "$mirror" ] || fail "no Debian bookworm mirror in /etc/apt/sources.list or sources.list.d"
  say "making $base with debootstrap (minbase, bookworm) from the mirror apt uses"
  t=$SECONDS
  rootfs="$work/rootfs"
  nice -n 10 debootstrap --variant=minbase bookworm "$rootfs" "$mirror" >"$work/debootstrap.log" 2>&1 ||
    { tail -20 "$work/debootstrap.log" >&2; fail "debootstrap failed"; }
  printf '%s\n' "$sources" >"$rootfs/etc/apt/sources.list"
  # As Debian's slim registry images: no package lists or downloads, documentation, manual
  # pages or translations (licences kept), and dpkg told to leave them out from now on. Files
  # deleted in a later layer would still weigh in this one.
  rm -rf "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/cache/apt/archives/*.deb \
    "$rootfs"/var/cache/apt/*.bin "$rootfs"/usr/share/man/* "$rootfs"/usr/share/locale/* \
    "$rootfs"/usr/share/info/*
  find "$rootfs/usr/share/doc" -mindepth 1 -not -name copyright -not -type d -delete
  printf '%s\n' 'path-exclude /usr/share/doc/*' 'path-include /usr/share/doc/*/copyright' \
    'path-exclude /usr/share/man/*' 'path-exclude /usr/share/locale/*' \
    'path-exclude /usr/share/info/*' >"$rootfs/etc/dpkg/dpkg.cfg.d/01-slim"
  tar -C "$rootfs" --numeric-owner -c . | podman import - "$base" >/dev/null 2>&1
  rm -rf "$rootfs"
  say "base image made in $(( SECONDS - t )) s ($(podman image inspect --format '{{.Size}}' "$base" | awk '{printf "%.0f MB", $1 / 1e6}'))"
fi

# --- the image -------------------------------------------------------------------------------
# --format docker: the OCI format has no HEALTHCHECK and podman would drop it. --pull=never:
# the base exists here, and no registry is to be asked.
build() {  # build TARGET TAG
  nice -n 10 podman build --format docker --pull=never --layers \
    --build-arg "BASE_IMAGE=$base" --build-arg "LIMN_JOBS=$jobs" \
    --target "$1" -f docker/Dockerfile -t "$2" . >"$work/build-$1.log" 2>&1 ||
    { tail -40 "$work/build-$1.log" >&2; fail "podman build --target $1 failed"; }
}
t=$SECONDS
build service "$image"
build_s=$(( SECONDS - t ))
size=$(podman image inspect --format '{{.Size}}' "$image")
say "image $image built in $build_s s, $(awk -v b="$size" 'BEGIN {printf "%.0f MB", b / 1e6}')"

health=$(podman image inspect --format '{{json .Config.Healthcheck}}' "$image")
grep -q healthz <<<"$health" || fail "the image has no HEALTHCHECK on /healthz: $health"
user=$(podman image inspect --format '{{.Config.User}}' "$image")
case "$user" in "" | 0 | 0:* | root | root:*) fail "the image runs as root ($user)" ;; esac
stopsignal=$(podman image inspect --format '{{.Config.StopSignal}}' "$image")
[ "$stopsignal" = SIGTERM ] || fail "the image's STOPSIGNAL is '$stopsignal', not SIGTERM"
compilers=$(podman run --rm --entrypoint /bin/sh "$image" -c \
  'for c in cc gcc g++ c++ clang cmake ninja make; do command -v $c; done; true' 2>"$work/run.log") ||
  { cat "$work/run.log" >&2; fail "podman run $image"; }
[ -z "$compilers" ] || fail "the runtime image has build tools: $compilers"
say "ok: HEALTHCHECK on /healthz, user $user, STOPSIGNAL SIGTERM, no compiler or build tool"

# --- the container ---------------------------------------------------------------------------
free_port() {  # a free port on the host's loopback: another limn (or anything) may hold 8080
  /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

wait_ready() {  # wait_ready URL CONTAINER
  for _ in $(seq 120); do
    curl -fs --max-time 2 "$1/readyz" >/dev/null 2>&1 && return 0
    [ "$(podman inspect --format '{{.State.Running}}' "$2" 2>/dev/null)" = true ] ||
      { podman logs "$2" >&2 || true; fail "container $2 is not running"; }
    sleep 0.5
  done
  fail "$1/readyz did not answer 200 within a minute"
}

# smoke_and_stop CONTAINER URL STOP...: scripts/smoke.sh, the health check, then STOP (a
# command that sends SIGTERM and waits up to 15 s) must end it promptly with exit status 0.
smoke_and_stop() {
  local name=$1 url=$2 t stop_s code
  shift 2
  wait_ready "$url" "$name"
  say "$name on $url: $(podman logs "$name" 2>&1 | grep -m1 'render workers' || true)"
  scripts/smoke.sh "$url" || { podman logs --tail 30 "$name" >&2; fail "scripts/smoke.sh against $name"; }
  podman healthcheck run "$name" >"$work/health.out" 2>&1 ||
    { cat "$work/health.out" >&2; fail "podman healthcheck run $name: unhealthy"; }
  say "ok: podman healthcheck run $name: healthy"
  t=$SECONDS
  "$@" >/dev/null 2>&1
  stop_s=$(( SECONDS - t ))
  code=$(podman inspect --format '{{.State.ExitCode}}' "$name")
  [ "$code" = 0 ] || { podman logs --tail 20 "$name" >&2; fail "$name: exit status $code after SIGTERM"; }
  # 15 s is the limit before SIGKILL; an idle limn drains at once.
  [ "$stop_s" -lt 10 ] || fail "SIGTERM took $stop_s s to stop an idle $name"
  podman logs "$name" 2>&1 | grep -q "limn: stopped" || fail "$name: no 'limn: stopped' in its log"
  say "ok: SIGTERM stopped $name in $stop_s s with exit status 0"
}

# As a cluster runs it: read-only root, a tmpfs /tmp, no init.
port=$(free_port)
# (podman's complaint that there is no systemd to schedule the health check goes to the log.)
podman run -d --name "$container" -p "127.0.0.1:$port:8080" \
  --read-only --tmpfs /tmp:rw,size=256m,mode=1777 "$image" >"$work/run.log" 2>&1 ||
  { cat "$work/run.log" >&2; fail "podman run"; }
smoke_and_stop "$container" "http://127.0.0.1:$port" podman stop -t 15 "$container"

# docker/compose.yaml, as a developer runs it (its configuration file mounted, its health check).
port=$(free_port)
LIMN_IMAGE="$image" LIMN_PORT="$port" "${compose[@]}" up -d --no-build >"$work/compose.log" 2>&1 ||
  { cat "$work/compose.log" >&2; fail "podman-compose up"; }
smoke_and_stop "${project}_limn_1" "http://127.0.0.1:$port" "${compose[@]}" stop -t 15
"${compose[@]}" down -t 0 >/dev/null 2>&1

if [ "${LIMN_SMOKE_REPORT:-0}" = 1 ]; then
  t=$SECONDS
  build report "$image-report"
  podman run --rm --read-only --tmpfs /tmp --entrypoint /usr/bin/python3 "$image-report" \
    -c 'import matplotlib; matplotlib.use("Agg"); import matplotlib.pyplot as plt; plt.plot([0, 1]); plt.savefig("/tmp/x.png")' \
    >"$work/run.log" 2>&1 || { cat "$work/run.log" >&2; fail "the report image cannot draw with matplotlib"; }
  say "ok: report image $image-report built in $(( SECONDS - t )) s, $(podman image inspect --format '{{.Size}}' "$image-report" | awk '{printf "%.0f MB", $1 / 1e6}'), matplotlib draws"
fi
say "passed in $(( SECONDS - start )) s (image build $build_s s, size $(awk -v b="$size" 'BEGIN {printf "%.0f MB", b / 1e6}'))"
