#!/usr/bin/env bash
# Hardening checks, run by CI after the normal tests; one entry point:
#   1. asan      build-asan/ (AddressSanitizer + UBSan, debugoptimized): every C suite (unit, abi),
#                the fuzz-corpus replays and the tool tests, with leak detection (the
#                dataset-scale runs left out: suite 'datasets')
#   2. abi       tests/abi/check-abi.sh: abidiff against tests/abi/amscr-<version>.abi
#   3. tsan      build-tsan/ (ThreadSanitizer): the threads and db suites
#   4. valgrind  build/ with `--setup valgrind`: the unit suites but the slow ones below, and the
#                fuzz-corpus replays
#   5. fuzz      tests/fuzz/run.sh: every libFuzzer target for AMSCR_FUZZ_SECONDS (default 20) each
# Prints one line per step and a summary; exits non-zero when any step fails (its log is shown).
#   scripts/hardening.sh                   everything
#   scripts/hardening.sh asan abi          only these steps
# Env: AMSCR_FUZZ_SECONDS (fuzzing time per target), AMSCR_NO_INSTALL=1 (never apt-get),
#      AMSCR_HARDENING_LOGS (default build-hardening/).
# Installs what it needs when missing (Debian/Ubuntu, quiet, idempotent): clang and its
# runtime (libFuzzer), abigail-tools, valgrind; scripts/setup.sh installs the rest and builds ./build.
set -uo pipefail
cd "$(dirname "$0")/.."
LOGS=${AMSCR_HARDENING_LOGS:-build-hardening}
mkdir -p "$LOGS"
ALL_STEPS=(asan abi tsan valgrind fuzz)
STEPS=("$@")
[ ${#STEPS[@]} -gt 0 ] || STEPS=("${ALL_STEPS[@]}")
for s in "${STEPS[@]}"; do
  case " ${ALL_STEPS[*]} " in *" $s "*) ;; *) echo "hardening: unknown step '$s' (steps: ${ALL_STEPS[*]})" >&2; exit 2 ;; esac
done
want() { case " ${STEPS[*]} " in *" $1 "*) return 0 ;; esac; return 1; }

# Valgrind runs every unit suite except these slow ones (20-50x slower than native there):
# accuracy (datasets: minutes), db and threads (about 70 s each: they run under ASan and
# ThreadSanitizer instead), robust, polish, index and pixel_grid (100-175 s each: many
# registrations; they run under ASan+UBSan, and the index loader's corpus replays under valgrind
# below). oom_register runs with every fifth allocation failed (AMSCR_OOM_STRIDE, tests/meson.build);
# oom_retrieval (200 s there even so) fails every allocation under ASan instead.
# fenv enables floating-point traps, which valgrind's CPU does not keep (it runs under ASan).
# New areas are included automatically.
VALGRIND_SKIP=(accuracy db threads robust polish index pixel_grid fenv oom_retrieval)

T0=$(date +%s)
summary=()
failed=0

# step NAME COMMAND...: runs the command with its output in $LOGS/NAME.log.
step() {
  local name=$1; shift
  local log="$LOGS/$name.log" t=$(date +%s)
  echo "hardening: $name ..."
  ( "$@" ) >"$log" 2>&1
  local rc=$? dt=$(( $(date +%s) - t ))
  if [ $rc -eq 0 ]; then
    summary+=("$(printf '  %-9s OK    %4ds' "$name" "$dt")")
  else
    failed=1
    summary+=("$(printf '  %-9s FAIL  %4ds  (exit %d, log: %s)' "$name" "$dt" "$rc" "$log")")
    echo "---- $name failed (exit $rc); last lines of $log:"
    tail -n 80 "$log"
    echo "----"
  fi
  # one-line digests from the log
  grep -E '^(fuzz |check-abi:|valgrind:)' "$log" | sed 's/^/    /' || true
  local counts
  counts=$(grep -E '^(Ok|Fail|Timeout): ' "$log" | tr -s ' ' | paste -sd' ')
  [ -z "$counts" ] || echo "    meson test: $counts"
}

# ------------------------------------------------------------------ install
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q 'install ok installed'; }
apt_install() {
  local SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "hardening: installing $*"
  if [ -z "${apt_updated:-}" ]; then
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get update -qq >/dev/null || return 1
    apt_updated=1
  fi
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}
install_missing() {
  [ -z "${AMSCR_NO_INSTALL:-}" ] && command -v dpkg-query >/dev/null 2>&1 || return 0
  local need=() missing=()
  want fuzz && need+=(clang)
  want abi && need+=(abigail-tools)
  want valgrind && need+=(valgrind)
  for p in "${need[@]}"; do installed "$p" || missing+=("$p"); done
  if [ ${#missing[@]} -gt 0 ]; then apt_install "${missing[@]}" || return 1; fi
  # libFuzzer lives in clang's runtime package, named after clang's major version
  # (Debian 12: clang 14, libclang-rt-14-dev).
  if want fuzz; then
    local rt
    rt=libclang-rt-$(clang -dumpversion | cut -d. -f1)-dev
    installed "$rt" || apt_install "$rt" || return 1
  fi
}
install_missing || { echo "hardening: installing the tools failed" >&2; exit 1; }
scripts/setup.sh >/dev/null 2>"$LOGS/setup.log" || { cat "$LOGS/setup.log"; echo "hardening: scripts/setup.sh failed" >&2; exit 1; }

# ------------------------------------------------------------------ 1. ASan + UBSan
asan() {
  # the benchmarks left out (-Dbench=false): a third of the build's objects, no test needs them
  if [ ! -f build-asan/build.ninja ]; then
    meson setup build-asan -Db_sanitize=address,undefined -Db_lundef=false --buildtype=debugoptimized \
      -Dbench=false || return 1
  else
    meson configure build-asan -Dbench=false >/dev/null || return 1
  fi
  meson compile -C build-asan || return 1
  # The python suite is left out: CPython itself is not instrumented (the tool suite is fine:
  # pytest launches the instrumented tool binary). So are the dataset-scale runs (suite
  # 'datasets': registration accuracy on the dataset contours, the tool on the datasets): the
  # normal build runs them; here they would take two thirds of the step for code paths the
  # other suites cover.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1 \
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    meson test -C build-asan --no-rebuild --suite unit --suite abi --suite fuzz --suite tool \
      --no-suite datasets --print-errorlogs --num-processes 2
}

# ------------------------------------------------------------------ 2. ABI
abi() { tests/abi/check-abi.sh; }

# ------------------------------------------------------------------ 3. ThreadSanitizer
tsan() {
  if [ ! -f build-tsan/build.ninja ]; then
    meson setup build-tsan -Db_sanitize=thread -Db_lundef=false --buildtype=debugoptimized || return 1
  fi
  meson compile -C build-tsan tests/check_threads tests/check_db || return 1
  # OpenBLAS single-threaded: its own worker threads hand work over in uninstrumented code, which
  # TSan reports as races wherever OpenBLAS picks its threaded kernels (it depends on the CPU);
  # the library's threads still call it concurrently, and those calls are what this step checks.
  OPENBLAS_NUM_THREADS=1 TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
    meson test -C build-tsan --no-rebuild threads db --print-errorlogs --num-processes 1
}

# ------------------------------------------------------------------ 4. valgrind
vg() {
  meson compile -C build || return 1
  local tests=() t
  for t in $(meson test -C build --no-rebuild --list --suite unit 2>/dev/null | sed -n 's|^.*:unit / ||p'); do
    case " ${VALGRIND_SKIP[*]} " in *" $t "*) ;; *) tests+=("$t") ;; esac
  done
  [ ${#tests[@]} -gt 0 ] || { echo "valgrind: no unit suites found"; return 1; }
  echo "valgrind: ${tests[*]} (skipped: ${VALGRIND_SKIP[*]})"
  meson test -C build --no-rebuild --setup valgrind "${tests[@]}" --print-errorlogs --num-processes 2 || return 1
  meson test -C build --no-rebuild --setup valgrind --suite fuzz --print-errorlogs --num-processes 2
}

# ------------------------------------------------------------------ 5. fuzzing
fz() { tests/fuzz/run.sh "${AMSCR_FUZZ_SECONDS:-20}"; }

want asan && step asan asan
want abi && step abi abi
want tsan && step tsan tsan
want valgrind && step valgrind vg
want fuzz && step fuzz fz

echo
echo "hardening summary ($(( $(date +%s) - T0 )) s; logs in $LOGS/):"
printf '%s\n' "${summary[@]}"
if [ $failed -ne 0 ]; then
  echo "hardening: FAILED"
  exit 1
fi
echo "hardening: all passed"
