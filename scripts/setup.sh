#!/usr/bin/env bash
# Installs what limn needs to build and run, from Debian 12 packages. Safe to run again: it
# installs only what is missing. Uses sudo when not root.
#
#   scripts/setup.sh                          everything: build, tests, browser tests, quality gates
#   LIMN_SETUP_PROFILE=build scripts/setup.sh only what compiling limn needs (docker/Dockerfile's
#                                             build stage: no chromium, node, clang or test tools)
set -euo pipefail

profile="${LIMN_SETUP_PROFILE:-full}"
case "$profile" in
  full | build) ;;
  *) echo "setup: LIMN_SETUP_PROFILE must be full or build, not $profile" >&2; exit 1 ;;
esac

# What configuring and compiling every target needs (render/implicit needs muparser). CMake
# requires GoogleTest even when only the limn executable is built, and OpenImageIO's CMake
# package refuses to load without its command-line tools (openimageio-tools: it checks that
# /usr/bin/iconvert exists).
packages=(
  cmake ninja-build g++ pkg-config
  libembree-dev libosd-dev libopenimageio-dev openimageio-tools libboost-dev rapidjson-dev
  libtinyobjloader-dev libegl1-mesa-dev libgl1-mesa-dri libgles-dev libgl-dev
  libgtest-dev libgmock-dev libbenchmark-dev libxxhash-dev libspdlog-dev libmuparser-dev
  libcli11-dev
  # the job store's two backends (batch/job_store.h)
  libsqlite3-dev libpq-dev
  # mesh files in: glTF, PLY, STL, FBX, COLLADA, 3DS, OFF (formats/assimp_import.h)
  libassimp-dev
)
if [ "$profile" = full ]; then
  packages+=(
    curl
    # the quality gates: clang with its sanitizer runtimes and libFuzzer (scripts/sanitize.sh,
    # scripts/fuzz.sh), Prometheus' text-format parser and a JSON Schema validator (the /metrics
    # and OpenAPI tests), the load generator
    clang-14 libclang-rt-14-dev libfuzzer-14-dev python3-prometheus-client python3-jsonschema wrk
    # the implicit-surface benchmark's baseline (bench/implicit_vs_peers.py, which installs
    # python3-vtk9 itself: no test needs VTK)
    python3-skimage
    # limn batch's plots (scripts/batch_plots.py, run by /usr/bin/python3)
    python3-matplotlib
    # the job store tests start throwaway PostgreSQL servers (tests/support/postgres_cluster.h)
    postgresql
  )
  # The browser tests (tests/browser): Debian's chromium, and node + npm unless a node is there.
  packages+=(chromium)
  command -v node >/dev/null || packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  # The postgresql package starts a default server when it is installed; limn's tests start
  # their own (tests/support/postgres_cluster.h), and a machine without an init system may fail
  # that start. Debian's policy-rc.d (exit 101: "not allowed") keeps any service from starting
  # during this install; one that was there already is left alone.
  policy=/usr/sbin/policy-rc.d
  made_policy=""
  if [ ! -e "$policy" ]; then
    printf '#!/bin/sh\nexit 101\n' | $sudo tee "$policy" >/dev/null
    $sudo chmod 755 "$policy"
    made_policy=1
    trap '$sudo rm -f "$policy"' EXIT
  fi
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  if [ -n "$made_policy" ]; then
    $sudo rm -f "$policy"
    trap - EXIT
  fi
fi

[ "$profile" = build ] && exit 0

# playwright-core for the browser tests, exactly as tests/browser/package-lock.json pins it,
# into build/browser-tests (again only when the lockfile changed). A machine where npm cannot
# fetch it warns here; the browser test then reports what is missing (tests/browser/run.sh).
cd "$(dirname "$0")/.."
tools=build/browser-tests
if ! cmp -s tests/browser/package-lock.json "$tools/package-lock.json" ||
   [ ! -f "$tools/node_modules/playwright-core/package.json" ]; then
  mkdir -p "$tools"
  cp tests/browser/package.json tests/browser/package-lock.json "$tools/"
  if ! (cd "$tools" && timeout 300 npm ci --silent --no-audit --no-fund >/dev/null 2>&1); then
    rm -f "$tools/package-lock.json"
    echo "setup: WARNING: npm ci of tests/browser/package-lock.json failed; browser tests cannot run" >&2
  fi
fi
