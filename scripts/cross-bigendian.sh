#!/usr/bin/env bash
# A big-endian trial: the library, the tool and the C suites cross-built for s390x with clang
# against a sysroot of Debian's s390x packages, the suites run under qemu-user. The packages are
# unpacked into the sysroot, never installed (another architecture's -dev packages could replace
# this machine's own). Not part of scripts/test.sh: under emulation the suites run 10 to 30 times
# slower. What the trial showed: docs/c-api.md ("A big-endian trial").
#   scripts/cross-bigendian.sh [SUITE...]   the Check suites to run (default: db index inner
#                                           contour_io: the suites that craft files), `all` for every one
# Work folder: build-s390x/ (debs/, sysroot/, s390x.ini, build/). Debian only; root or sudo for
# apt-get (qemu-user, clang, binutils-s390x-linux-gnu, and the s390x package lists: the s390x
# architecture is added to dpkg for the download and removed again if it was not there).
set -euo pipefail
cd "$(dirname "$0")/.."
W=$PWD/build-s390x
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
suites=("$@")
[ ${#suites[@]} -gt 0 ] || suites=(db index inner contour_io)

# ------------------------------------------------------------------ tools of this machine
tools=(qemu-user clang binutils-s390x-linux-gnu pkg-config meson ninja-build locales)
if $SUDO apt-get install -s -y --no-install-recommends "${tools[@]}" | grep -q '^Remv '; then
  echo "cross-bigendian: installing ${tools[*]} would remove packages; stopping" >&2
  exit 1
fi
$SUDO apt-get install -y -qq --no-install-recommends "${tools[@]}" >/dev/null

# ------------------------------------------------------------------ the s390x sysroot
debs=(libc6 libc6-dev linux-libc-dev libgcc-12-dev libgcc-s1 libstdc++6 libstdc++-12-dev libgfortran5
      libgomp1 libatomic1 liblapacke liblapacke-dev liblapack3 libblas3 libtmglib3 libtmglib-dev libopenblas0
      libopenblas0-pthread libopenblas-dev libopenblas-pthread-dev libpng16-16 libpng-dev zlib1g zlib1g-dev
      check libsubunit0 libsubunit-dev)
if [ ! -f "$W/sysroot/.done" ]; then
  rm -rf "$W/debs" "$W/sysroot"
  mkdir -p "$W/debs" "$W/sysroot"
  added=0
  if ! dpkg --print-foreign-architectures | grep -qx s390x; then
    $SUDO dpkg --add-architecture s390x
    added=1
  fi
  restore() {
    if [ "$added" = 1 ]; then
      $SUDO dpkg --remove-architecture s390x
      $SUDO apt-get update -qq >/dev/null || true
    fi
  }
  trap restore EXIT
  $SUDO apt-get update -qq >/dev/null
  (cd "$W/debs" && apt-get download -qq "${debs[@]/%/:s390x}")
  restore
  trap - EXIT
  for d in "$W"/debs/*.deb; do dpkg-deb -x "$d" "$W/sysroot"; done
  lib=$W/sysroot/usr/lib/s390x-linux-gnu
  # what the packages' alternatives would link: BLAS, LAPACK and OpenBLAS from openblas-pthread
  for f in libblas.so.3 liblapack.so.3 libopenblas.so.0 libopenblas.so libblas.so liblapack.so; do
    [ -e "$lib/openblas-pthread/$f" ] && ln -sfn "openblas-pthread/$f" "$lib/$f"
  done
  for f in openblas blas lapack; do
    [ -e "$lib/openblas-pthread/pkgconfig/$f.pc" ] && ln -sfn "../openblas-pthread/pkgconfig/$f.pc" "$lib/pkgconfig/$f.pc"
  done
  # absolute links (libm.so -> /lib/...) made relative, so they stay inside the sysroot
  (cd "$W/sysroot" && find . -type l -lname '/*' | while read -r l; do
     up=""
     for _ in $(seq 1 "$(dirname "$l" | tr -cd / | wc -c)"); do up+="../"; done
     t=$(readlink "$l")
     ln -sfn "${up:-./}${t#/}" "$l"
   done)
  touch "$W/sysroot/.done"
fi

# ------------------------------------------------------------------ cross file, build, suites
S=$W/sysroot
libs=$S/usr/lib/s390x-linux-gnu:$S/lib/s390x-linux-gnu:$S/usr/lib/s390x-linux-gnu/openblas-pthread
cat > "$W/s390x.ini" <<EOF
[binaries]
c = ['clang', '--target=s390x-linux-gnu', '--sysroot=$S']
cpp = ['clang++', '--target=s390x-linux-gnu', '--sysroot=$S']
ar = 's390x-linux-gnu-ar'
strip = 's390x-linux-gnu-strip'
pkgconfig = 'pkg-config'
exe_wrapper = ['qemu-s390x', '-L', '$S', '-E', 'LD_LIBRARY_PATH=$libs']
[properties]
sys_root = '$S'
pkg_config_libdir = ['$S/usr/lib/s390x-linux-gnu/pkgconfig', '$S/usr/share/pkgconfig']
[host_machine]
system = 'linux'
cpu_family = 's390x'
cpu = 's390x'
endian = 'big'
EOF
[ -d "$W/build" ] || meson setup "$W/build" --cross-file "$W/s390x.ini" -Dbench=false >/dev/null
ninja -C "$W/build" >/dev/null
if [ "${suites[*]}" = all ]; then
  mapfile -t suites < <(meson test -C "$W/build" --list --suite unit 2>/dev/null | sed -n 's|^.*:unit / ||p')
fi
# Check's own per-case limits do not follow meson's multiplier: emulation needs its own
CK_TIMEOUT_MULTIPLIER=30 meson test -C "$W/build" --no-rebuild --timeout-multiplier 30 \
  --print-errorlogs --num-processes 2 "${suites[@]}"
