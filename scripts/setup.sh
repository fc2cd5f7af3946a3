#!/usr/bin/env bash
# Installs what limn needs to build and run, from Debian 12 packages. Safe to run again: it
# installs only what is missing. Uses sudo when not root.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libembree-dev libosd-dev libopenimageio-dev openimageio-tools libboost-dev rapidjson-dev
  libtinyobjloader-dev libegl1-mesa-dev libgl1-mesa-dri libgles-dev libgl-dev
  libgtest-dev libgmock-dev libbenchmark-dev libxxhash-dev libspdlog-dev curl
  # the quality gates: clang with its sanitizer runtimes and libFuzzer (scripts/sanitize.sh,
  # scripts/fuzz.sh), Prometheus' text-format parser and a JSON Schema validator (the /metrics and
  # OpenAPI tests), the load generator
  clang-14 libclang-rt-14-dev libfuzzer-14-dev python3-prometheus-client python3-jsonschema wrk
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
echo "setup: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
