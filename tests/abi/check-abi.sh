#!/usr/bin/env bash
# ABI guard (STYLE.md §1.8): compares libamscr.so with the committed abidw baseline
# tests/abi/amscr-<version>.abi and fails on any incompatible change.
#   tests/abi/check-abi.sh [LIB]            check (LIB default: build-abi/libamscr.so, built here)
#   tests/abi/check-abi.sh --update [LIB]   regenerate the baseline (at a release, or when a
#                                           0.1 signature is changed ON PURPOSE before 0.1 ships)
# LIB must carry DWARF (-g): the default build-abi/ is a debugoptimized build of the library
# alone, configured and built on demand (about 10 s).
# Policy (abidiff exit status, abigail-tools >= 2.2): 0 passes. Added functions never fail
# (--no-added-syms), nor do added enumerators or changes inside the opaque structs
# (--drop-private-types: only types from include/ count). A changed parameter or return type,
# a changed enumerator value or a changed public type sets bit 4 (ABI change), a removed
# function bit 8 (incompatible): both fail, as does any abidiff error (bits 1, 2).
set -euo pipefail
cd "$(dirname "$0")/../.."

update=0
if [ "${1:-}" = "--update" ]; then update=1; shift; fi
lib=${1:-}
for tool in abidw abidiff; do
  command -v $tool >/dev/null || { echo "check-abi: $tool not found (apt-get install abigail-tools)" >&2; exit 2; }
done
version=$(python3 scripts/version.py include/amscr.h)
series=${version%.*}                       # 0.1.0 -> 0.1
baseline=tests/abi/amscr-$series.abi

if [ -z "$lib" ]; then
  if [ ! -f build-abi/build.ninja ]; then
    meson setup build-abi --buildtype=debugoptimized -Dtests=disabled >/dev/null
  else  # a version bump renames the library's target: regenerate first
    meson setup --reconfigure build-abi >/dev/null
  fi
  meson compile -C build-abi amscr:shared_library >/dev/null
  lib=build-abi/libamscr.so
fi
[ -f "$lib" ] || { echo "check-abi: $lib not found" >&2; exit 2; }
if ! readelf -S "$lib" | grep '\.debug_info' >/dev/null; then  # not -q: an early exit would SIGPIPE readelf under pipefail
  echo "check-abi: $lib has no debug info (build with -g, e.g. --buildtype=debugoptimized)" >&2
  exit 2
fi

if [ $update = 1 ]; then
  abidw --headers-dir include --drop-private-types --drop-undefined-syms --no-corpus-path --no-comp-dir-path \
        --no-elf-needed --short-locs --type-id-style hash --out-file "$baseline" "$lib"
  echo "check-abi: wrote $baseline from $lib ($(grep -c '<elf-symbol' "$baseline") symbols)"
  exit 0
fi
[ -f "$baseline" ] || { echo "check-abi: no baseline $baseline (run: $0 --update)" >&2; exit 2; }

# Every committed baseline, this series' and every earlier release's: the ABI only grows.
failed=0
for base in tests/abi/amscr-*.abi; do
  set +e
  report=$(abidiff --headers-dir2 include --drop-private-types --no-added-syms "$base" "$lib" 2>&1)
  rc=$?
  set -e
  if [ $rc -eq 0 ]; then
    echo "check-abi: OK: $lib is ABI-compatible with $base (added functions allowed)"
    continue
  fi
  echo "$report"
  what="ABI change"
  [ $((rc & 8)) -ne 0 ] && what="INCOMPATIBLE ABI change (removed symbol)"
  [ $((rc & 3)) -ne 0 ] && what="abidiff error"
  echo "check-abi: FAIL ($what, abidiff exit $rc) against $base." >&2
  failed=1
done
if [ $failed -ne 0 ]; then
  echo "  A released signature never changes: add amscr_x_2() instead (STYLE.md §1.8). Before $series ships," >&2
  echo "  an intended change to its new symbols is recorded with: tests/abi/check-abi.sh --update" >&2
  exit 1
fi
