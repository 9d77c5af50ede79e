"""Build script: metadata is in pyproject.toml; this file only adds the optional cffi extension.

``pip install ./bindings/python`` must succeed whether or not libamscr can be found at build time:

* library found (env ``AMSCR_INCLUDE_DIR``/``AMSCR_LIB_DIR``, ``pkg-config amscr``, or the
  repository's ``include/`` + ``build/``): the API-mode extension ``amscr._amscr`` is compiled,
  with an rpath to the library folder;
* not found, or the compile fails (no compiler, old library...): a warning is printed and the
  package is installed without the extension; at import it loads ``libamscr.so.0`` in ABI mode.

``AMSCR_REQUIRE_API=1`` turns both cases into hard errors (CI, packagers).
``AMSCR_NO_API=1`` never builds the extension.
"""
import importlib.util
import os
import sys

from setuptools import setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))


def _flag(name):
    return os.environ.get(name, '') not in ('', '0')


def _load_builder_module():
    spec = importlib.util.spec_from_file_location('_amscr_build', os.path.join(HERE, 'amscr', '_build.py'))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _warn(msg):
    bar = '*' * 78
    sys.stderr.write('\n%s\namscr: %s\namscr: installing without the API-mode extension; the package will load '
                     'libamscr.so.0 at import (ABI mode).\n%s\n\n' % (bar, msg, bar))


_builder = _load_builder_module()
cffi_modules = []
if _flag('AMSCR_NO_API'):
    pass
elif _builder.ffibuilder is None:
    if _flag('AMSCR_REQUIRE_API'):
        raise SystemExit('amscr: AMSCR_REQUIRE_API is set but ' + _builder.NOT_FOUND_REASON)
    _warn(_builder.NOT_FOUND_REASON)
else:
    cffi_modules = ['amscr/_build.py:ffibuilder']


class OptionalBuildExt(build_ext):
    """Compiles the cffi extension when it can; a failure is a warning unless AMSCR_REQUIRE_API is set."""

    def run(self):
        try:
            super().run()
        except Exception as e:  # CCompilerError, DistutilsError, PlatformError, OSError...
            if _flag('AMSCR_REQUIRE_API'):
                raise
            _warn('building the extension failed: %s' % e)

    def build_extension(self, ext):
        try:
            super().build_extension(ext)
        except Exception as e:
            if _flag('AMSCR_REQUIRE_API'):
                raise
            _warn('building %s failed: %s' % (ext.name, e))


class BuildPyWithInfo(build_py):
    """Records where the library was at build time, for the ABI-mode loader of an installed package."""

    def run(self):
        super().run()
        dirs = []
        if _builder.ffibuilder is not None:
            dirs += [os.path.abspath(d) for d in _builder.ffibuilder.amscr_config['library_dirs']]
        if not _flag('AMSCR_USE_SYSTEM'):
            intree = os.path.abspath(_builder.in_tree_build_dir())
            if intree not in dirs:
                dirs.append(intree)
        target = os.path.join(self.build_lib, 'amscr', '_buildinfo.py')
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, 'w', encoding='utf-8') as f:
            f.write('"""Written by setup.py at build time."""\nLIBRARY_DIRS = %r\n' % (dirs,))


setup(cffi_modules=cffi_modules, cmdclass={'build_ext': OptionalBuildExt, 'build_py': BuildPyWithInfo})
