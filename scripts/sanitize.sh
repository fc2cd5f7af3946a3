#!/usr/bin/env bash
# The quality-gate build: every target compiled by clang with AddressSanitizer and
# UndefinedBehaviorSanitizer (and libFuzzer's coverage instrumentation, so that the fuzz
# targets come from the same tree) into build-sanitize/, then the quick test suite run in it.
# Usage: scripts/sanitize.sh [ctest arguments...]   (default: -LE 'slow|heavy': the quick suite
# less the programs of many full renders, whose engine code the unit tests run sanitized)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs="${LIMN_JOBS:-$(nproc)}"
# bench/ is left out: benchmarks under sanitizers measure nothing.
modules="render/core;render/mesh;render/subdiv;render/normalmap;render/rules;render/tessellate"
modules+=";render/patches"
modules+=";render/implicit"
modules+=";render/silhouette;render/image;render/raster;render/metrics;render/oracle"
modules+=";render/pipeline;formats;api;batch;tests/support;server;tests/integration;fuzz"
# -O1 with line tables only: about half the compile time of RelWithDebInfo, and still every
# frame of a sanitizer report named with its file and line.
cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=Sanitize \
  "-DCMAKE_CXX_FLAGS_SANITIZE=-O1 -gline-tables-only" "-DCMAKE_C_FLAGS_SANITIZE=-O1 -gline-tables-only" \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DLIMN_SANITIZE=ON -DLIMN_FUZZ=ON "-DLIMN_MODULES=$modules" >/dev/null
cmake --build build-sanitize -j "$jobs"

# No LeakSanitizer here: Mesa's driver, loaded and unloaded by EGL in every test that draws,
# leaves allocations whose stacks LSan can no longer attribute ("<unknown module>"), so no
# suppression can name them. The fuzz targets (scripts/fuzz.sh), which never load Mesa, run
# with leak detection on.
# handle_segv=0: a worker that segfaults dies of SIGSEGV as in production (worker_isolation_test
# kills one with it and checks the signal named), not of ASan's abort.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:strict_string_checks=1:handle_segv=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
[ $# -eq 0 ] && set -- -LE 'slow|heavy'
cd build-sanitize
ctest --output-on-failure -j "${LIMN_TEST_JOBS:-1}" "$@"
