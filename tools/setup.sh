#!/usr/bin/env bash
# Installs what the build needs when it is missing (idempotent, fast when all is there), then
# configures and builds into ./build. Debian/Ubuntu packages via apt-get; Python packages via pip.
#   tools/setup.sh            build only
#   AMSCR_NO_INSTALL=1 ...    never install, just build
set -euo pipefail
cd "$(dirname "$0")/.."

debs=(gcc g++ meson ninja-build pkg-config liblapacke-dev libopenblas-dev libpng-dev check python3 python3-pip)
missing=()
if command -v dpkg-query >/dev/null 2>&1; then
  for p in "${debs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
fi
if [ ${#missing[@]} -gt 0 ] && [ -z "${AMSCR_NO_INSTALL:-}" ]; then
  echo "setup: installing Debian packages: ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq >/dev/null
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Python side (tests and bindings): numpy, cffi, pytest, scipy (test cross-checks only) and
# dask[distributed] (the optional amscr.distributed, issue 9).
PY=${PYTHON:-python3}
pypkgs=(numpy cffi pytest scipy "dask[distributed]>=2023")
if [ -z "${AMSCR_NO_INSTALL:-}" ] && ! "$PY" -c 'import numpy, cffi, pytest, scipy, distributed' >/dev/null 2>&1; then
  echo "setup: installing Python packages: ${pypkgs[*]}" >&2
  "$PY" -m pip install -q "${pypkgs[@]}" 2>/dev/null \
    || "$PY" -m pip install -q --break-system-packages "${pypkgs[@]}"
fi

log=$(mktemp)
trap 'rm -f "$log"' EXIT
if [ ! -f build/build.ninja ]; then
  if ! meson setup build --buildtype=release >"$log" 2>&1; then
    cat "$log" >&2
    echo "setup: meson setup failed (full log: build/meson-logs/meson-log.txt)" >&2
    exit 1
  fi
fi
if ! meson compile -C build >"$log" 2>&1; then
  cat "$log" >&2
  echo "setup: build failed" >&2
  exit 1
fi
echo "setup: built into ./build" >&2
