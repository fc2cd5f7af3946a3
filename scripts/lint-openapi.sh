#!/usr/bin/env bash
# Lints api/openapi.json with Redocly's CLI (from npm, installed once into build/tools) under
# its recommended rules; fails on errors, prints warnings.
set -euo pipefail
cd "$(dirname "$0")/.."
tools=build/tools
version=2.77.0
# The linter comes from the npm registry: a machine that cannot reach it skips the lint with a
# warning rather than failing the build; a lint that runs and finds errors fails.
if [ ! -x "$tools/node_modules/.bin/redocly" ]; then
  mkdir -p "$tools"
  if ! command -v npm >/dev/null ||
     ! timeout 300 npm install --prefix "$tools" --silent --no-audit --no-fund \
       "@redocly/cli@$version" >/dev/null 2>&1; then
    echo "lint-openapi: WARNING: could not install @redocly/cli $version with npm; lint skipped" >&2
    exit 0
  fi
fi
set +e
output=$("$tools/node_modules/.bin/redocly" lint api/openapi.json --format stylish 2>&1)
status=$?
set -e
# Redocly's boxed banners (a Node.js deprecation notice) are not findings.
printf '%s\n' "$output" | grep -v '[║╔╚]' || true
exit "$status"
