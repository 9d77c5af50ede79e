#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz/ with clang (-fsanitize=fuzzer,address,undefined)
# into build-fuzz/ (or $AMSCR_FUZZ_BUILD). The library and tool sources are compiled
# directly (no Meson), once, and rebuilt only when a source or header is newer.
#   tests/fuzz/build.sh            build every target
# Needs clang and libclang-rt-<version>-dev (Debian: apt-get install clang libclang-rt-14-dev);
# scripts/hardening.sh installs them.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${AMSCR_FUZZ_BUILD:-build-fuzz}
CC=${FUZZ_CC:-clang}
command -v "$CC" >/dev/null || { echo "fuzz/build.sh: $CC not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 1; }

SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CFLAGS="-std=c99 -g -O1 -Wall -Wno-unused-parameter -D_POSIX_C_SOURCE=200809L -DAMSCR_HAVE_THREAD_LOCAL_KEYWORD
        -Iinclude -Isrc/base -Isrc/numeric -Isrc/shape -Isrc/register -Isrc/retrieval -Itools/cli -Itests/fuzz"
LIBS="$(pkg-config --libs lapacke 2>/dev/null || echo -llapacke) $(pkg-config --libs openblas 2>/dev/null || true) -lm -lpthread"
TOOL_DEFS=""
if pkg-config --exists libpng; then
  TOOL_DEFS="-DAMSCR_TOOL_HAVE_PNG=1 $(pkg-config --cflags libpng)"
  LIBS="$LIBS $(pkg-config --libs libpng)"
fi
mkdir -p "$OUT/obj"

HEADERS="include/amscr.h src/*/*.h tools/cli/image.h tools/cli/image_codec.h tools/cli/util.h tools/cli/collection.h tests/fuzz/fuzz_common.h tests/fuzz/fuzz_image.h"
newest_header=$(ls -t $HEADERS | head -1)

# compile SRC OBJ EXTRA_FLAGS...: only when the object is missing or older than SRC or a header.
compile() {
  local src=$1 obj=$2; shift 2
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ "$newest_header" -nt "$obj" ] || [ "$0" -nt "$obj" ]; then
    # shellcheck disable=SC2086
    $CC $CFLAGS $SAN "$@" -c "$src" -o "$obj"
  fi
}

# Objects: two compilers at a time; any failure stops the script.
pids=()
throttle() {
  while [ "$(jobs -rp | wc -l)" -ge "${AMSCR_FUZZ_BUILD_JOBS:-2}" ]; do sleep 0.05; done
}
lib_objs=()
for src in src/*/*.c; do
  obj="$OUT/obj/lib_$(basename "${src%.c}").o"
  throttle
  compile "$src" "$obj" -fsanitize=fuzzer-no-link -DAMSCR_BUILDING -DAMSCR_STATIC &
  pids+=($!)
  lib_objs+=("$obj")
done
tool_objs=()
for src in tools/cli/image.c tools/cli/image_codec.c tools/cli/image_pgm.c tools/cli/image_png.c tools/cli/util.c tools/cli/collection.c; do
  obj="$OUT/obj/tool_$(basename "${src%.c}").o"
  throttle
  # shellcheck disable=SC2086
  compile "$src" "$obj" -fsanitize=fuzzer-no-link $TOOL_DEFS &
  pids+=($!)
  tool_objs+=("$obj")
done
fail=0
for p in "${pids[@]}"; do wait "$p" || fail=1; done
[ $fail = 0 ] || { echo "fuzz/build.sh: compilation failed" >&2; exit 1; }

targets=(text pgm png mask register dbload contours index subpixel manifest)
for t in "${targets[@]}"; do
  src=tests/fuzz/fuzz_$t.c
  extra=()
  case $t in pgm|png|manifest) extra=("${tool_objs[@]}") ;; esac
  exe="$OUT/fuzz_$t"
  rebuild=0
  [ -f "$exe" ] || rebuild=1
  for dep in "$src" "${lib_objs[@]}" "${extra[@]}"; do [ "$dep" -nt "$exe" ] && rebuild=1; done
  if [ $rebuild = 1 ]; then
    # shellcheck disable=SC2086
    $CC $CFLAGS $SAN -fsanitize=fuzzer $TOOL_DEFS "$src" "${extra[@]}" "${lib_objs[@]}" $LIBS -o "$exe"
  fi
done
echo "fuzz/build.sh: built ${targets[*]} in $OUT/" >&2
