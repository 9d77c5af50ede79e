#!/usr/bin/env bash
# Sets up (installs what is missing, builds, installs the amscr package into the project's
# virtual environment .venv/) and runs every test: the ABI checks, the tool and Python tests,
# the fuzz-corpus replays (through `meson test`; the Python suite runs in .venv against the
# INSTALLED package, not this source tree), the hardening pass (scripts/hardening.sh), then
# the master Check runner (every per-area Check suite, which `meson test` alone also runs one
# by one), whose closing line ("100%: Checks: N, Failures: 0, Errors: 0") ends the output.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# every suite but the Check areas', which check_all runs at the end (one process, its closing
# line last); oom_register is not a Check suite
meson test -C build --no-suite all --no-suite unit --print-errorlogs --num-processes 2
meson test -C build --no-rebuild oom_register --print-errorlogs
# sanitizers (ASan+UBSan, TSan), valgrind, ABI diff against the committed baseline, a short
# fuzz pass (AMSCR_FUZZ_SECONDS, default 20 s a target); AMSCR_NO_HARDENING=1 skips it
[ -n "${AMSCR_NO_HARDENING:-}" ] || scripts/hardening.sh
# the Python package for distribution: sdist + wheel, manylinux repair, a clean install of it
# (scripts/wheel.sh, about a minute); AMSCR_NO_WHEEL=1 skips it
[ -n "${AMSCR_NO_WHEEL:-}" ] || { echo "== wheel =="; scripts/wheel.sh; }
echo "== check_all =="
build/tests/check_all
