#!/usr/bin/env bash
# Sets up (installs what is missing, builds) and runs every test: the per-area Check suites,
# the ABI checks, the tool and Python tests (all through `meson test`), then the master Check
# runner, whose closing line ("100%: Checks: N, Failures: 0, Errors: 0") ends the output.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
meson test -C build --no-suite all --print-errorlogs --num-processes 2
echo "== check_all =="
build/tests/check_all
