#!/usr/bin/env bash
# Runs the browser tests (page.test.mjs) with node, against the limn binary in LIMN_BINARY.
# What they need is installed by scripts/setup.sh: node, chromium, and playwright-core
# (npm ci of tests/browser/package-lock.json into LIMN_NODE_MODULES' folder).
#
# A machine without one of them does not pass these tests silently: the run says loudly what is
# missing and exits 77, which CTest reports as "Skipped" (as scripts/lint-openapi.sh skips
# with a warning where it cannot install its linter). With LIMN_REQUIRE_BROWSER=1 (.ci/run sets
# it) a missing tool is a failure instead.
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
chromium="${LIMN_CHROMIUM:-/usr/bin/chromium}"
missing=()
command -v node >/dev/null || missing+=("node (Debian package nodejs)")
[ -x "$chromium" ] || missing+=("chromium at $chromium (Debian package chromium)")
[ -f "${LIMN_NODE_MODULES:-/nonexistent}/playwright-core/package.json" ] ||
  missing+=("playwright-core in ${LIMN_NODE_MODULES:-?} (scripts/setup.sh runs npm ci)")
if [ ${#missing[@]} -gt 0 ]; then
  {
    echo "================================================================"
    echo "browser tests NOT RUN: missing ${missing[*]}"
    echo "run scripts/setup.sh to install them"
    echo "================================================================"
  } >&2
  [ "${LIMN_REQUIRE_BROWSER:-0}" = "1" ] && exit 1
  exit 77
fi
exec node --test --test-reporter=spec --test-concurrency=1 "$here/page.test.mjs"
