#!/usr/bin/env bash
# Lints api/openapi.json with Redocly's CLI (from npm, installed once into build/tools) under
# its recommended rules; fails on errors, prints warnings.
set -euo pipefail
cd "$(dirname "$0")/.."
tools=build/tools
version=2.77.0
if [ ! -x "$tools/node_modules/.bin/redocly" ]; then
  command -v npm >/dev/null || { echo "lint-openapi: npm is not installed" >&2; exit 1; }
  mkdir -p "$tools"
  npm install --prefix "$tools" --silent --no-audit --no-fund "@redocly/cli@$version" >/dev/null
fi
set +e
output=$("$tools/node_modules/.bin/redocly" lint api/openapi.json --format stylish 2>&1)
status=$?
set -e
# Redocly's boxed banners (a Node.js deprecation notice) are not findings.
printf '%s\n' "$output" | grep -v '[║╔╚]' || true
exit "$status"
