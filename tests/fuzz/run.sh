#!/usr/bin/env bash
# Runs the libFuzzer targets for a bounded time each, on their committed corpus.
#   tests/fuzz/run.sh [SECONDS] [TARGET...]     (default 30 s; all targets)
# Env: AMSCR_FUZZ_SECONDS (default for SECONDS), AMSCR_FUZZ_JOBS (targets run at once,
# default: the number of cores, at most 2), AMSCR_FUZZ_BUILD (default build-fuzz).
# The committed corpus tests/fuzz/corpus/<t>/ is only read (seeds and regressions are all
# replayed first); new inputs go to build-fuzz/corpus/<t>/, crashes to
# build-fuzz/artifacts/<t>/, logs to build-fuzz/logs/<t>.log. Exit status non-zero when any
# target found a crash, leak, timeout or out-of-memory: the line names the input to commit
# as tests/fuzz/corpus/<t>/regress-<what> once the bug is fixed.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${AMSCR_FUZZ_BUILD:-build-fuzz}
SECS=${1:-${AMSCR_FUZZ_SECONDS:-30}}
[ $# -gt 0 ] && shift
ALL=(text pgm png mask register dbload contours index subpixel manifest)
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=("${ALL[@]}")
JOBS=${AMSCR_FUZZ_JOBS:-$(nproc 2>/dev/null || echo 1)}
[ "$JOBS" -gt 2 ] && [ -z "${AMSCR_FUZZ_JOBS:-}" ] && JOBS=2

tests/fuzz/build.sh || exit 1

maxlen() {
  case $1 in
    text|register|manifest) echo 4096 ;;
    pgm|png|mask|subpixel|contours) echo 8192 ;;
    dbload) echo 16384 ;;
    index) echo 131072 ;; # its seeds: up to 81 KB
  esac
}

run_one() {
  local t=$1
  local dict=()
  [ -f "tests/fuzz/dict/$t.dict" ] && dict=(-dict="tests/fuzz/dict/$t.dict")
  mkdir -p "$OUT/corpus/$t" "$OUT/artifacts/$t" "$OUT/logs"
  local log="$OUT/logs/$t.log"
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1} \
  UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1} \
  OPENBLAS_NUM_THREADS=1 \
    "$OUT/fuzz_$t" -max_total_time="$SECS" -timeout=30 -rss_limit_mb=2560 -max_len="$(maxlen "$t")" \
      -print_final_stats=1 -artifact_prefix="$OUT/artifacts/$t/" "${dict[@]}" \
      "$OUT/corpus/$t" "tests/fuzz/corpus/$t" >"$log" 2>&1
  local rc=$?
  local execs
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  local cov
  cov=$(grep -E '^#[0-9]+.*cov:' "$log" | tail -1 | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
  if [ $rc -eq 0 ]; then
    printf 'fuzz %-9s OK    %4ss %10s execs  cov %s\n' "$t" "$SECS" "${execs:-?}" "${cov:-?}"
  else
    local art
    art=$(grep -o "Test unit written to .*" "$log" | tail -1 | sed 's/Test unit written to //')
    printf 'fuzz %-9s FAIL  (exit %s) %s execs; input: %s; log: %s\n' "$t" "$rc" "${execs:-?}" "${art:-?}" "$log"
    grep -m1 -E "ERROR: |property violated|runtime error" "$log" | sed 's/^/    /'
  fi
  return $rc
}

export -f run_one maxlen
export OUT SECS
printf '%s\n' "${TARGETS[@]}" | xargs -P "$JOBS" -I{} bash -c 'run_one "$@"' _ {}
