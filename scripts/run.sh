#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a running service:
# installs what is missing, builds, and serves on 127.0.0.1:8080 with built-in defaults.
# Extra arguments go to `limn serve` (e.g. --listen 127.0.0.1:9000 --config configs/default.json).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
exec build/bin/limn serve "$@"
