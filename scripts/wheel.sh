#!/usr/bin/env bash
# Builds the Python package for distribution and checks what it built, in the project's .venv:
#   1. `python -m build bindings/python`: the sdist (meson dist: the COMMITTED sources, HEAD, with
#      a copy of the C sources in subprojects/amscr) and a wheel built from that sdist;
#   2. `auditwheel repair`: a manylinux wheel carrying its own OpenBLAS, LAPACKE and libpng
#      (amscr.libs/), then tagged cp38-abi3: meson-python names an abi3 wheel after the building
#      interpreter, but the extension is compiled for the Limited API of 3.8 (Py_LIMITED_API =
#      0x03080000), so one wheel serves every CPython >= 3.8;
#   3. the bundled libraries' licence notices added (scripts/wheel_licences.py: amscr.libs/LICENSES/);
#   4. `auditwheel show`, then the repaired wheel installed on its own into a temporary folder:
#      `import amscr` (API mode, from there) and its `amscr --version`.
# Output: dist/amscr-V.tar.gz, dist/amscr-V-cp3XX-abi3-linux_x86_64.whl,
#         dist/wheelhouse/amscr-V-cp38-abi3-manylinux_2_NN_x86_64.whl
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python3 ] || scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
git rev-parse --git-dir >/dev/null 2>&1 || { echo "wheel: not a git checkout (the sdist is made by git archive)" >&2; exit 1; }
[ -z "$(git status --porcelain -- bindings/python src include tools scripts meson.build meson_options.txt)" ] ||
  echo "wheel: note: uncommitted changes are not in the sdist (it holds HEAD)" >&2

rm -rf dist
log=$(mktemp)
tmp=$(mktemp -d)
trap 'rm -rf "$log" "$tmp"' EXIT
if ! python3 -m build --no-isolation --outdir dist bindings/python >"$log" 2>&1; then
  cat "$log" >&2; echo "wheel: python -m build failed" >&2; exit 1
fi
whl=$(ls dist/amscr-*.whl)
if ! auditwheel repair -w dist/wheelhouse "$whl" >"$log" 2>&1; then
  cat "$log" >&2; echo "wheel: auditwheel repair failed" >&2; exit 1
fi
python3 -m wheel tags --python-tag cp38 --remove dist/wheelhouse/amscr-*.whl >/dev/null
repaired=$(ls dist/wheelhouse/amscr-*.whl)
python3 scripts/wheel_licences.py "$repaired"
# the package's own licence as PEP 639 has it: License-Expression and License-File in the metadata,
# the file in the sdist's top folder and in the wheels' .dist-info/licenses/ (pyproject.toml's
# license-files: LICENSE, a link through subprojects/amscr to the repository's)
python3 - dist/*.tar.gz "$whl" "$repaired" <<'PY'
import sys, tarfile, zipfile
sdist, wheels = sys.argv[1], sys.argv[2:]
want = open('LICENSE', 'rb').read()
def check(where, meta, licence):
    fields = [l for l in meta.decode().splitlines() if l.startswith(('Metadata-Version:', 'License'))]
    assert 'License-Expression: MIT' in fields and 'License-File: LICENSE' in fields, (where, fields)
    assert licence == want, (where, 'LICENSE is not the repository\'s')
    print('wheel: %s: %s, LICENSE' % (where.split('/')[-1], ', '.join(fields)))
with tarfile.open(sdist) as t:
    top = t.getnames()[0].split('/')[0]
    names = t.getnames()
    assert top + '/LICENSE' in names, (sdist, 'no LICENSE at the top of the sdist')
    check(sdist, t.extractfile(top + '/PKG-INFO').read(), t.extractfile(top + '/LICENSE').read())
for whl in wheels:
    with zipfile.ZipFile(whl) as z:
        info = next(n.split('/')[0] for n in z.namelist() if n.split('/')[0].endswith('.dist-info'))
        assert info + '/licenses/LICENSE' in z.namelist(), (whl, 'no %s/licenses/LICENSE' % info)
        check(whl, z.read(info + '/METADATA'), z.read(info + '/licenses/LICENSE'))
PY
ls -l dist/*.tar.gz "$whl" "$repaired" | awk '{print "wheel: " $5 " bytes  " $NF}'
auditwheel show "$repaired"

pip install -q --no-deps --target "$tmp/site" "$repaired" >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
(cd "$tmp" && PYTHONPATH="$tmp/site" python3 -c '
import os, sys, amscr
here = os.path.join(sys.argv[1], "site")
assert amscr.__file__.startswith(here), amscr.__file__
assert amscr.API_MODE and amscr.LIBRARY_PATH.endswith(".abi3.so"), amscr.LIBRARY_PATH
libs = sorted(os.listdir(os.path.join(here, "amscr.libs")))
assert any("openblas" in n for n in libs) and any("lapacke" in n for n in libs) and any("png" in n for n in libs), libs
notices = os.listdir(os.path.join(here, "amscr.libs", "LICENSES"))
for want in ("libopenblas", "liblapacke", "libpng", "libgfortran"):
    assert any(n.startswith(want) and n.endswith(".copyright") for n in notices), (want, notices)
libs.remove("LICENSES")
print("wheel: installed on its own: import amscr %s (API mode), amscr.libs: %s" % (amscr.__version__, " ".join(libs)))
' "$tmp")
echo "wheel: amscr --version: $(cd "$tmp" && PYTHONPATH="$tmp/site" "$tmp/site/bin/amscr" --version)"
