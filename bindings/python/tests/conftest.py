"""pytest setup: use the installed amscr if there is one, else the source tree.

* installed (``pip install ./bindings/python``; ``meson test`` and ``scripts/test.sh`` run the suite
  in .venv with AMSCR_TEST_INSTALLED=1, which makes an amscr imported from this source tree an
  error): nothing to do;
* not installed, or AMSCR_TEST_SOURCE=1: bindings/python goes first on sys.path and, unless
  already set, AMSCR_LIBRARY points at the repository's build/libamscr.so.0 (or AMSCR_BUILD_DIR's),
  so ABI mode finds it.
"""
import importlib.util
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
PKG_ROOT = os.path.dirname(HERE)  # bindings/python
REPO_ROOT = os.path.normpath(os.path.join(PKG_ROOT, '..', '..'))
BUILD_DIR = os.environ.get('AMSCR_BUILD_DIR') or os.path.join(REPO_ROOT, 'build')


def _installed():
    spec = importlib.util.find_spec('amscr')
    if spec is None or spec.origin is None:
        return False
    return os.path.dirname(os.path.dirname(os.path.abspath(spec.origin))) != PKG_ROOT


if os.environ.get('AMSCR_TEST_INSTALLED', '') not in ('', '0'):
    if not _installed():
        raise RuntimeError('AMSCR_TEST_INSTALLED is set but amscr is not installed in %s (scripts/setup.sh '
                           'installs it into .venv: pip install ./bindings/python)' % sys.executable)
elif os.environ.get('AMSCR_TEST_SOURCE', '') not in ('', '0') or not _installed():
    if PKG_ROOT not in sys.path:
        sys.path.insert(0, PKG_ROOT)
    lib = os.path.join(BUILD_DIR, 'libamscr.so.0')
    if 'AMSCR_LIBRARY' not in os.environ and os.path.exists(lib):
        os.environ['AMSCR_LIBRARY'] = lib

import amscr  # noqa: E402


def pytest_report_header(config):
    return 'amscr %s from %s, %s mode, library %s (%s)' % (
        amscr.__version__, os.path.dirname(amscr.__file__), 'API' if amscr.API_MODE else 'ABI',
        amscr.library_version(), amscr.LIBRARY_PATH)


@pytest.fixture(scope='module')
def family_bench():
    """bench/registration_traced.py set up as --families sets it (family_pairs.py; OpenCV and
    scikit-image needed: the callers skip without them)."""
    import family_pairs
    return family_pairs.bench()
