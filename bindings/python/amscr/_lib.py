"""Loads libamscr: API mode first (the compiled ``amscr._amscr``), ABI mode as the fallback.

An installed package carries its own library: ``libamscr.so.<SOVERSION>`` sits beside this file,
and the extension finds it through its ``$ORIGIN`` run path (a repaired manylinux wheel also
carries OpenBLAS, LAPACKE and libpng in ``amscr.libs/``). Nothing points into a source tree.

API mode is skipped when ``AMSCR_FORCE_ABI=1``. ABI mode ``dlopen``s, first match wins:

1. ``AMSCR_LIBRARY`` when set (a path or a soname; nothing else is tried then);
2. unless ``AMSCR_USE_SYSTEM=1``: the library bundled in the package, then the folder
   ``AMSCR_BUILD_DIR`` (a Meson build folder, for running the package from a source tree);
3. the versioned soname ``libamscr.so.<SOVERSION>`` (``libamscr.<SOVERSION>.dylib`` on macOS,
   ``amscr-<SOVERSION>.dll`` on Windows) through the system's search path.

Then the runtime version is checked against the header the bindings were generated from: the
major must be equal and the minor at least as new (symbols are only ever added within a
soversion), else ``ImportError``.
"""
import importlib
import importlib.util
import os
import sys
import warnings

__all__ = ['ffi', 'lib', 'API_MODE', 'SOVERSION', 'LIBRARY_PATH', 'API_IMPORT_ERROR']

#: The soversion of libamscr this package loads; equal to meson.build's ``amscr_soversion``
#: (a test checks it). The one constant not taken from the library itself.
SOVERSION = 0

_HERE = os.path.dirname(os.path.abspath(__file__))


def _flag(name):
    return os.environ.get(name, '') not in ('', '0')


def _soname():
    if sys.platform == 'darwin':
        return 'libamscr.%d.dylib' % SOVERSION
    if sys.platform.startswith('win'):
        return 'amscr-%d.dll' % SOVERSION
    return 'libamscr.so.%d' % SOVERSION


def _candidate_dirs():
    dirs = [_HERE]
    if os.environ.get('AMSCR_BUILD_DIR'):
        dirs.append(os.path.normpath(os.environ['AMSCR_BUILD_DIR']))
    return dirs


def _load_abi():
    from cffi import FFI

    ffi = FFI()
    with open(os.path.join(_HERE, '_cdef.h'), encoding='utf-8') as f:
        ffi.cdef(f.read())
    explicit = os.environ.get('AMSCR_LIBRARY')
    if explicit:
        candidates = [explicit]
    else:
        candidates = []
        if not _flag('AMSCR_USE_SYSTEM'):
            candidates += [os.path.join(d, _soname()) for d in _candidate_dirs()
                           if os.path.exists(os.path.join(d, _soname()))]
        candidates.append(_soname())
    errors = []
    for c in candidates:
        try:
            return ffi, ffi.dlopen(c), c
        except OSError as e:
            errors.append('%s: %s' % (c, e))
    hint = ('reinstall the package (`pip install ./bindings/python` builds the library into it), '
            'or set AMSCR_LIBRARY to the path of libamscr.so.%d' % SOVERSION)
    if not explicit and not _flag('AMSCR_USE_SYSTEM'):
        errors.append('%s in: %s (not there)' % (_soname(), ', '.join(_candidate_dirs())))
    raise ImportError('amscr: cannot load the C library (%s). Tried:\n  %s' % (hint, '\n  '.join(errors)))


def _load():
    api_error = None
    if not _flag('AMSCR_FORCE_ABI'):
        name = __package__ + '._amscr'
        if importlib.util.find_spec(name) is None:
            api_error = ImportError('the API-mode extension %s was not built' % name)
        else:
            try:
                _amscr = importlib.import_module(name)  # API mode
            except ImportError as e:  # built, but it does not load (library moved or too old)
                api_error = e
                warnings.warn('amscr: the compiled extension does not load (%s); falling back to ABI mode' % e,
                              RuntimeWarning, stacklevel=3)
            else:
                return _amscr.ffi, _amscr.lib, True, getattr(_amscr, '__file__', None), None
    ffi, lib, path = _load_abi()
    return ffi, lib, False, path, api_error


ffi, lib, API_MODE, LIBRARY_PATH, API_IMPORT_ERROR = _load()


def _check_version():
    expected = (lib.AMSCR_VERSION_MAJOR, lib.AMSCR_VERSION_MINOR)
    try:
        number = lib.amscr_version_number()
    except AttributeError as e:
        raise ImportError('amscr: %s is not libamscr (no amscr_version_number): %s' % (LIBRARY_PATH, e))
    got = (number // 10000, number // 100 % 100)
    if got[0] != expected[0] or got[1] < expected[1]:
        raise ImportError(
            'amscr: incompatible C library: the Python package needs libamscr %d.%d (same major, minor >= %d) '
            'but %s is %d.%d.%d. Rebuild/reinstall the package against the matching library, or point '
            'AMSCR_LIBRARY at it.' % (expected[0], expected[1], expected[1], LIBRARY_PATH or 'the loaded library',
                                      got[0], got[1], number % 100))
    return number


VERSION_NUMBER = _check_version()
