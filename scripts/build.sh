#!/usr/bin/env bash
# Configures and builds limn into build/ (RelWithDebInfo). Jobs: LIMN_JOBS, or all cores.
#   scripts/build.sh            every target (limn, tests, benchmarks)
#   scripts/build.sh limn ...   only the named targets (the container image needs only limn)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${LIMN_JOBS:-$(nproc)}"
# -U resets a module list a developer may have narrowed in this build folder.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -U LIMN_MODULES >/dev/null
cmake --build build -j "$jobs" ${1:+--target "$@"}
