"""Packaging checks: the committed cdef is fresh and cffi-clean, the soversion and the versions agree;
an installed package is self-contained (its own library and tool, nothing pointing into a source tree),
its `amscr` command works, and the sdist gets the C sources."""
import importlib.util
import os
import re
import subprocess
import sys

import pytest

import amscr
from amscr import _lib, errors

from conftest import PKG_ROOT, REPO_ROOT

HEADER = os.path.join(REPO_ROOT, 'include', 'amscr.h')
CDEF = os.path.join(PKG_ROOT, 'amscr', '_cdef.h')
GEN = os.path.join(REPO_ROOT, 'scripts', 'gen_cdef.py')

in_tree = pytest.mark.skipif(not (os.path.exists(HEADER) and os.path.exists(GEN)),
                             reason='not run from the source tree (no include/amscr.h or scripts/gen_cdef.py)')


def _gen_module():
    spec = importlib.util.spec_from_file_location('gen_cdef', GEN)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@in_tree
def test_cdef_is_fresh():
    with open(HEADER, encoding='utf-8') as f:
        expected = _gen_module().generate(f.read())
    with open(CDEF, encoding='utf-8') as f:
        committed = f.read()
    assert committed == expected, ('bindings/python/amscr/_cdef.h is stale: run '
                                   'python3 scripts/gen_cdef.py -o bindings/python/amscr/_cdef.h')


@in_tree
def test_gen_cdef_check_mode():
    r = subprocess.run([sys.executable, GEN, '--check'], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_cdef_is_cffi_clean_abi():
    from cffi import FFI
    ffi = FFI()
    with open(CDEF, encoding='utf-8') as f:
        text = f.read()
    ffi.cdef(text)
    assert '...' not in re.sub(r'/\*.*?\*/', '', text, flags=re.S)
    # every enumerator has an explicit value
    for body in re.findall(r'enum\s+\w*\s*\{(.*?)\}', text, flags=re.S):
        for item in body.split(','):
            if item.strip():
                assert '=' in item, item


def test_every_header_function_is_declared():
    if not os.path.exists(HEADER):
        pytest.skip('no header')
    with open(HEADER, encoding='utf-8') as f:
        header_names = set(re.findall(r'AMSCR_API[^;(]*?\b(amscr_\w+)\s*\(', f.read()))
    with open(CDEF, encoding='utf-8') as f:
        cdef_names = set(re.findall(r'\b(amscr_\w+)\s*\(', f.read()))
    assert header_names and header_names <= cdef_names


def test_generator_handles_implicit_enums_and_macros():
    gen = _gen_module() if os.path.exists(GEN) else pytest.skip('no generator')
    out = gen.generate('#define X_H\n#define A 2u /* c */\n#define B (A * 3 + 1)\n#define F(x) x\n'
                       '#ifdef __cplusplus\nextern "C" {\n#endif\n'
                       'typedef enum e { E0, E1 = B, E2 } e; // x\n'
                       'AMSCR_API AMSCR_NODISCARD int f(const double m[6],\n  e v);\n'
                       '#ifdef __cplusplus\n}\n#endif\n')
    assert '#define A 2\n#define B 7\n' in out
    assert 'E0 = 0,' in out and 'E1 = 7,' in out and 'E2 = 8' in out
    assert 'int f(const double m[6], e v);' in out
    assert 'extern' not in out and 'AMSCR_API' not in out and 'F(' not in out
    from cffi import FFI
    FFI().cdef(out)


def test_soversion_matches_meson():
    meson = os.path.join(REPO_ROOT, 'meson.build')
    if not os.path.exists(meson):
        pytest.skip('no meson.build (not the source tree)')
    with open(meson, encoding='utf-8') as f:
        m = re.search(r"^amscr_soversion\s*=\s*'(\d+)'", f.read(), re.M)
    assert m, 'amscr_soversion not found in meson.build'
    assert amscr.SOVERSION == int(m.group(1))
    assert _lib.SOVERSION == int(m.group(1))


def test_versions_agree():
    major, minor, patch = (int(x) for x in amscr.__version__.split('.')[:3])
    assert (_lib.lib.AMSCR_VERSION_MAJOR, _lib.lib.AMSCR_VERSION_MINOR, _lib.lib.AMSCR_VERSION_PATCH) == \
        (major, minor, patch)
    n = _lib.lib.amscr_version_number()
    assert n // 10000 == major and n // 100 % 100 >= minor
    assert amscr.library_version() == '%d.%d.%d' % (n // 10000, n // 100 % 100, n % 100)


def test_errors_one_to_one():
    names = [n for n in dir(_lib.lib) if n.startswith('AMSCR_E_')]
    codes = {getattr(_lib.lib, n) for n in names}
    assert codes == set(errors.STATUS_EXCEPTIONS), 'every status code maps to exactly one class'
    assert len(set(errors.STATUS_EXCEPTIONS.values())) == len(codes)
    for code, cls in errors.STATUS_EXCEPTIONS.items():
        e = errors.error_from_status(code, 'some detail')
        assert type(e) is cls and e.status == code and e.detail == 'some detail'
        assert str(e).endswith(': some detail') and isinstance(e, amscr.AmscrError)
    assert issubclass(amscr.InvalidArgumentError, ValueError)
    assert issubclass(amscr.NoMemoryError, MemoryError)
    assert issubclass(amscr.FileError, OSError)
    assert amscr.Error is amscr.AmscrError


def test_version_mismatch_is_a_clear_import_error(tmp_path):
    """A library whose major differs makes `import amscr` fail with a clear ImportError."""
    # A fake libamscr reporting version 9.0.0 (built with the system compiler).
    import shutil
    cc = shutil.which('cc') or shutil.which('gcc')
    if not cc:
        pytest.skip('no C compiler')
    src = tmp_path / 'fake.c'
    src.write_text('int amscr_version_number(void) { return 90000; }\n')
    so = tmp_path / 'libamscr.so.0'
    subprocess.run([cc, '-shared', '-fPIC', '-o', str(so), str(src)], check=True)
    env = dict(os.environ, AMSCR_FORCE_ABI='1', AMSCR_LIBRARY=str(so),
               PYTHONPATH=os.pathsep.join([os.path.dirname(os.path.dirname(amscr.__file__))]))
    r = subprocess.run([sys.executable, '-c', 'import amscr'], env=env, capture_output=True, text=True)
    assert r.returncode != 0
    assert 'ImportError' in r.stderr and 'incompatible C library' in r.stderr and '9.0.0' in r.stderr


def test_missing_library_is_a_clear_import_error(tmp_path):
    env = dict(os.environ, AMSCR_FORCE_ABI='1', AMSCR_LIBRARY=str(tmp_path / 'nope.so'),
               PYTHONPATH=os.path.dirname(os.path.dirname(amscr.__file__)))
    r = subprocess.run([sys.executable, '-c', 'import amscr'], env=env, capture_output=True, text=True)
    assert r.returncode != 0 and 'cannot load the C library' in r.stderr and 'AMSCR_LIBRARY' in r.stderr


# ---------------------------------------------------------------- the installed package
PKG_DIR = os.path.dirname(os.path.abspath(amscr.__file__))
installed = pytest.mark.skipif(os.path.dirname(PKG_DIR) == PKG_ROOT,
                               reason='amscr is imported from the source tree, not installed')
EXAMPLES = os.path.join(REPO_ROOT, 'examples')


def _env_command():
    """The `amscr` command pip installed beside this interpreter (the environment's bin/)."""
    exe = os.path.join(os.path.dirname(sys.executable), 'amscr')
    return exe if os.path.isfile(exe) else None


@installed
def test_installed_package_carries_its_library_and_tool():
    soname = 'libamscr.so.%d' % _lib.SOVERSION
    assert os.path.isfile(os.path.join(PKG_DIR, soname))
    assert os.access(os.path.join(PKG_DIR, 'amscr'), os.X_OK), 'the bundled command-line tool'
    assert amscr.API_MODE, 'the compiled extension loads: %r' % (amscr._lib.API_IMPORT_ERROR,)
    assert os.path.basename(amscr.LIBRARY_PATH).endswith('.abi3.so'), 'Limited-API (abi3) extension'
    assert not os.path.exists(os.path.join(PKG_DIR, '_buildinfo.py'))


@installed
def test_installed_files_do_not_point_into_the_source_tree():
    # Run paths, recorded folders, anything: no file names a folder of the checkout (the checkout's
    # own path may appear: scripts/setup.sh keeps the environment in it, .venv/).
    repo = os.path.realpath(REPO_ROOT)
    needles = [os.path.join(repo, d).encode() for d in ('build', 'bindings', 'src', 'include', 'tools')]
    for root, _dirs, files in os.walk(PKG_DIR):
        for name in files:
            with open(os.path.join(root, name), 'rb') as f:
                data = f.read()
            for needle in needles:
                assert needle not in data, '%s refers to %s' % (name, needle.decode())


@installed
def test_abi_mode_loads_the_bundled_library():
    env = {k: v for k, v in os.environ.items() if k not in ('AMSCR_LIBRARY', 'AMSCR_BUILD_DIR')}
    env.update(AMSCR_FORCE_ABI='1')
    r = subprocess.run([sys.executable, '-c', 'import amscr; print(amscr.API_MODE, amscr.LIBRARY_PATH)'],
                       env=env, capture_output=True, text=True, cwd=os.path.dirname(PKG_DIR))
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ['False', os.path.join(PKG_DIR, 'libamscr.so.%d' % _lib.SOVERSION)]


@installed
def test_command_version_and_help_of_every_subcommand():
    exe = _env_command() or pytest.skip('no amscr command beside %s' % sys.executable)
    r = subprocess.run([exe, '--version'], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == amscr.library_version()
    for cmd in ('contour', 'register', 'search', 'matrix', 'eval'):
        r = subprocess.run([exe, cmd, '--help'], capture_output=True, text=True)
        assert r.returncode == 0 and cmd in (r.stdout + r.stderr), (cmd, r.stderr)
    r = subprocess.run([exe, 'no-such-command'], capture_output=True, text=True)
    assert r.returncode == 2 and r.stderr


@installed
def test_the_package_carries_its_licence():
    with open(os.path.join(PKG_DIR, 'LICENSE')) as f:
        text = f.read()
    assert text.startswith('MIT License')
    # and its distribution, as PEP 639 has it (scripts/wheel.sh checks the sdist and the wheels)
    from importlib import metadata
    dist = metadata.distribution('amscr')
    assert dist.metadata['License-Expression'] == 'MIT', dist.metadata.get_all('License')
    assert dist.metadata.get_all('License-File') == ['LICENSE']
    licence = [f for f in dist.files if f.as_posix().endswith('.dist-info/licenses/LICENSE')]
    assert len(licence) == 1 and licence[0].read_text() == text, dist.files


@installed
def test_python_m_amscr_runs_the_tool():
    """``python -m amscr`` is the ``amscr`` command (an environment whose bin/ is not on PATH)."""
    r = subprocess.run([sys.executable, '-m', 'amscr', '--version'], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == amscr.library_version(), r.stderr
    r = subprocess.run([sys.executable, '-m', 'amscr', 'no-such-command'], capture_output=True, text=True)
    assert r.returncode == 2 and 'no-such-command' in r.stderr


@installed
def test_command_registers_like_the_package(tmp_path):
    exe = _env_command() or pytest.skip('no amscr command beside %s' % sys.executable)
    src, tgt = os.path.join(EXAMPLES, 'pair-source.txt'), os.path.join(EXAMPLES, 'pair-target.txt')
    if not os.path.exists(src):
        pytest.skip('no examples/ (not the source tree)')
    r = subprocess.run([exe, 'register', src, tgt], capture_output=True, text=True, cwd=str(tmp_path))
    assert r.returncode == 0, r.stderr
    rows = re.findall(r'\[\s*([-0-9.eE+]+)\s+([-0-9.eE+]+)\s*\]', r.stdout)
    assert len(rows) >= 3, r.stdout  # A (two rows), B
    A = [[float(x) for x in row] for row in rows[:2]]
    np = __import__('numpy')
    res = amscr.register(np.loadtxt(src, ndmin=2), np.loadtxt(tgt, ndmin=2))
    assert np.allclose(A, res.A, atol=1e-4), (r.stdout, res.A)
    assert np.allclose([float(x) for x in rows[2]], res.B, atol=1e-3), (r.stdout, res.B)


def test_console_entry_reports_a_missing_tool(tmp_path, monkeypatch, capsys):
    from amscr import _console
    monkeypatch.setattr(_console, '_HERE', str(tmp_path))
    assert _console.main(['--version']) == 127
    assert 'reinstall' in capsys.readouterr().err


# ---------------------------------------------------------------- the sdist
@in_tree
def test_sdist_script_copies_the_c_sources(tmp_path):
    if subprocess.run(['git', '-C', REPO_ROOT, 'rev-parse'], capture_output=True).returncode != 0:
        pytest.skip('not a git checkout')
    os.makedirs(tmp_path / 'subprojects')
    os.symlink(os.path.join('..', '..', '..'), tmp_path / 'subprojects' / 'amscr')
    env = dict(os.environ, MESON_DIST_ROOT=str(tmp_path), MESON_SOURCE_ROOT=PKG_ROOT)
    r = subprocess.run([sys.executable, os.path.join(PKG_ROOT, 'vendor_sources.py')], env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    sub = tmp_path / 'subprojects' / 'amscr'
    assert not os.path.islink(sub)
    for f in ('meson.build', 'meson_options.txt', 'include/amscr.h', 'src/amscr.map', 'tools/meson.build',
              'scripts/version.py'):
        assert (sub / f).is_file(), f
    assert len(list((sub / 'src').glob('*/*.c'))) >= 10
    assert not (sub / 'bindings').exists() and not (sub / 'tests').exists()
    for f in ('meson.build', 'include/amscr.h'):  # as committed, as meson dist takes the rest
        head = subprocess.run(['git', '-C', REPO_ROOT, 'show', 'HEAD:' + f], capture_output=True, check=True).stdout
        assert (sub / f).read_bytes() == head, f


def _record_hash(data):
    import base64
    import hashlib
    return base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b'=').decode()


def _wheel_with_sbom(tmp_path, package):
    """A minimal repaired-looking wheel: one bundled library and an SBOM naming `package`."""
    import json
    import zipfile
    info = 'amscr-9.9.9.dist-info'
    files = {
        'amscr/__init__.py': b'',
        'amscr.libs/libdemo-0123abcd.so.1': b'\x7fELF',
        info + '/METADATA': b'Metadata-Version: 2.1\nName: amscr\nVersion: 9.9.9\n',
        info + '/WHEEL': b'Wheel-Version: 1.0\nGenerator: test\nRoot-Is-Purelib: false\nTag: cp38-abi3-linux_x86_64\n',
        info + '/sboms/auditwheel.cdx.json': json.dumps({'components': [
            {'name': 'amscr', 'version': '9.9.9', 'purl': 'pkg:pypi/amscr@9.9.9'},
            {'name': package, 'version': '1.0+x', 'purl': 'pkg:deb/debian/%s@1.0%%2Bx' % package}]}).encode(),
    }
    whl = tmp_path / 'amscr-9.9.9-cp38-abi3-linux_x86_64.whl'
    with zipfile.ZipFile(whl, 'w') as z:
        for name, data in files.items():
            z.writestr(name, data)
        z.writestr(info + '/RECORD', ''.join('%s,sha256=%s,%d\n' % (n, _record_hash(d), len(d)) for n, d in files.items())
                   + info + '/RECORD,,\n')
    return whl


@in_tree
def test_wheel_licences_adds_the_bundled_packages_notices(tmp_path):
    import zipfile
    pytest.importorskip('wheel')
    script = os.path.join(REPO_ROOT, 'scripts', 'wheel_licences.py')
    pkg = next((p for p in ('libpng16-16', 'libc6', 'base-files')
                if os.path.isfile('/usr/share/doc/%s/copyright' % p)), None)
    if pkg is None:
        pytest.skip('no Debian copyright file on this machine')
    whl = _wheel_with_sbom(tmp_path, pkg)
    r = subprocess.run([sys.executable, script, str(whl)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with zipfile.ZipFile(whl) as z:
        names = z.namelist()
        with open('/usr/share/doc/%s/copyright' % pkg, 'rb') as f:
            assert z.read('amscr.libs/LICENSES/%s.copyright' % pkg) == f.read()
        readme = z.read('amscr.libs/LICENSES/README').decode()
        record = z.read('amscr-9.9.9.dist-info/RECORD').decode()
    assert 'libdemo-0123abcd.so.1' in readme and '%s 1.0+x' % pkg in readme
    assert 'amscr.libs/LICENSES/%s.copyright,sha256=' % pkg in record
    assert 'amscr.libs/libdemo-0123abcd.so.1' in names
    # a package without a copyright file: an error, and the wheel is left as it was
    bad = _wheel_with_sbom(tmp_path, 'no-such-package-amscr')
    before = bad.read_bytes()
    r = subprocess.run([sys.executable, script, str(bad)], capture_output=True, text=True)
    assert r.returncode != 0 and 'no-such-package-amscr' in r.stderr
    assert bad.read_bytes() == before
