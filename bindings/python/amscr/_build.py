"""API-mode builder of the ``amscr._amscr`` extension (used by setup.py through cffi_modules).

Where the C library is looked for, first match wins:

1. ``AMSCR_INCLUDE_DIR`` / ``AMSCR_LIB_DIR`` (explicit settings beat discovery);
2. ``pkg-config amscr`` (an installed library, or the build folder's ``meson-uninstalled``
   ``.pc`` file when ``PKG_CONFIG_PATH`` points there);
3. the in-tree layout: this package sits in ``bindings/python`` of the repository, whose
   ``include/amscr.h`` and Meson build folder ``build/`` (or ``AMSCR_BUILD_DIR``) are used.

``AMSCR_USE_SYSTEM=1`` skips the in-tree layout (packagers: only the installed library counts).
The extension gets an rpath to the library folder unless that is a system folder, so it loads
without ``LD_LIBRARY_PATH``.

Run directly (``python amscr/_build.py``) to build the extension in place for development.
"""
import os
import shlex
import shutil
import subprocess
import sys
from typing import Optional

from cffi import FFI

HERE = os.path.dirname(os.path.abspath(__file__))  # bindings/python/amscr
PKG_ROOT = os.path.dirname(HERE)  # bindings/python
REPO_ROOT = os.path.normpath(os.path.join(PKG_ROOT, '..', '..'))
SOVERSION = '0'  # keep equal to amscr/_lib.py and meson.build's amscr_soversion

_SYSTEM_LIB_DIRS = {'/lib', '/usr/lib', '/lib64', '/usr/lib64', '/usr/local/lib'}


class NotFound(Exception):
    """The C library or its header could not be located."""


def _read_cdef():
    with open(os.path.join(HERE, '_cdef.h'), encoding='utf-8') as f:
        return f.read()


def _pkg_config():
    exe = shutil.which(os.environ.get('PKG_CONFIG', 'pkg-config'))
    if not exe:
        return None
    try:
        cflags = subprocess.run([exe, '--cflags', 'amscr'], check=True, capture_output=True, text=True).stdout
        libs = subprocess.run([exe, '--libs', 'amscr'], check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    cfg = {'include_dirs': [], 'library_dirs': [], 'libraries': [], 'extra_compile_args': [],
           'extra_link_args': [], 'origin': 'pkg-config'}
    for tok in shlex.split(cflags):
        if tok.startswith('-I'):
            cfg['include_dirs'].append(tok[2:])
        else:
            cfg['extra_compile_args'].append(tok)
    for tok in shlex.split(libs):
        if tok.startswith('-L'):
            cfg['library_dirs'].append(tok[2:])
        elif tok.startswith('-l'):
            cfg['libraries'].append(tok[2:])
        else:
            cfg['extra_link_args'].append(tok)
    if 'amscr' not in cfg['libraries']:
        cfg['libraries'].append('amscr')
    return cfg


def _has_header(d):
    return os.path.isfile(os.path.join(d, 'amscr.h'))


def _has_lib(d):
    return any(os.path.exists(os.path.join(d, n)) for n in ('libamscr.so', 'libamscr.dylib', 'amscr.lib'))


def _plain(inc, lib, origin):
    return {'include_dirs': [inc], 'library_dirs': [lib], 'libraries': ['amscr'], 'extra_compile_args': [],
            'extra_link_args': [], 'origin': origin}


def in_tree_build_dir():
    """The Meson build folder of the repository this package sits in (may not exist)."""
    return os.environ.get('AMSCR_BUILD_DIR') or os.path.join(REPO_ROOT, 'build')


def find_library_config():
    """Returns the compile/link settings for the extension, or raises NotFound (with the places tried)."""
    tried = []
    inc, lib = os.environ.get('AMSCR_INCLUDE_DIR'), os.environ.get('AMSCR_LIB_DIR')
    if inc or lib:
        if not (inc and _has_header(inc)):
            raise NotFound('AMSCR_INCLUDE_DIR=%r has no amscr.h' % inc)
        if not (lib and _has_lib(lib)):
            raise NotFound('AMSCR_LIB_DIR=%r has no libamscr' % lib)
        return _plain(inc, lib, 'AMSCR_INCLUDE_DIR/AMSCR_LIB_DIR')
    tried.append('AMSCR_INCLUDE_DIR/AMSCR_LIB_DIR (unset)')
    cfg = _pkg_config()
    if cfg is not None:
        return cfg
    tried.append('pkg-config amscr')
    if os.environ.get('AMSCR_USE_SYSTEM', '') not in ('', '0'):
        raise NotFound('AMSCR_USE_SYSTEM is set and the system has no amscr; tried: ' + ', '.join(tried))
    inc, lib = os.path.join(REPO_ROOT, 'include'), in_tree_build_dir()
    if _has_header(inc) and _has_lib(lib):
        return _plain(inc, lib, 'in-tree')
    tried.append('in-tree %s + %s' % (inc, lib))
    raise NotFound('libamscr not found; tried: ' + ', '.join(tried))


def _rpath_args(library_dirs):
    if sys.platform.startswith('win'):
        return []
    out = []
    for d in library_dirs:
        d = os.path.abspath(d)
        if d not in _SYSTEM_LIB_DIRS and not d.startswith('/usr/lib/'):
            out.append('-Wl,-rpath,' + d)
    return out


def make_ffibuilder(cfg=None):
    if cfg is None:
        cfg = find_library_config()
    ffibuilder = FFI()
    ffibuilder.cdef(_read_cdef())
    ffibuilder.set_source(
        'amscr._amscr', '#include <amscr.h>',
        include_dirs=cfg['include_dirs'],
        library_dirs=cfg['library_dirs'],
        libraries=cfg['libraries'],
        extra_compile_args=cfg['extra_compile_args'],
        extra_link_args=cfg['extra_link_args'] + _rpath_args(cfg['library_dirs']))
    ffibuilder.amscr_config = cfg
    return ffibuilder


ffibuilder: Optional[FFI]
NOT_FOUND_REASON: Optional[str]
try:
    ffibuilder = make_ffibuilder()
    NOT_FOUND_REASON = None
except NotFound as _e:  # setup.py then skips the extension (ABI mode at import)
    ffibuilder = None
    NOT_FOUND_REASON = str(_e)

if __name__ == '__main__':
    if ffibuilder is None:
        sys.exit('amscr/_build.py: %s' % NOT_FOUND_REASON)
    os.chdir(PKG_ROOT)
    ffibuilder.compile(verbose=True)
