#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to every test: installs what is missing, builds,
# and runs the unit, integration (the real server on 127.0.0.1) and browser tests through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
cd build
# --quick: everything but the programs labelled slow (the corpus at 1024^2), for development.
if [ "${1:-}" = "--quick" ]; then
  shift
  set -- -LE slow "$@"
fi
ctest --output-on-failure -j "${LIMN_TEST_JOBS:-1}" "$@"
