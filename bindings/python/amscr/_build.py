"""cffi builder of the API-mode extension ``amscr._amscr`` (not installed with the package).

The package's Meson build (bindings/python/meson.build) runs ``python _build.py OUT.c`` to write
the extension's C source from the committed declarations ``_cdef.h``; Meson then compiles it
against the Limited API and links it with libamscr, which sits beside it in the package.

``make_ffibuilder(include_dirs, library_dirs)`` gives the same builder with compile settings, for
tests that build the extension against a library of their own.
"""
import os
import sys

from cffi import FFI

HERE = os.path.dirname(os.path.abspath(__file__))  # bindings/python/amscr


def _read_cdef():
    with open(os.path.join(HERE, '_cdef.h'), encoding='utf-8') as f:
        return f.read()


def make_ffibuilder(include_dirs=(), library_dirs=()):
    """The cffi builder of ``amscr._amscr``; the folders are used only by ``ffibuilder.compile``."""
    ffibuilder = FFI()
    ffibuilder.cdef(_read_cdef())
    ffibuilder.set_source('amscr._amscr', '#include <amscr.h>',
                          include_dirs=list(include_dirs), library_dirs=list(library_dirs),
                          libraries=['amscr'],
                          extra_link_args=['-Wl,-rpath,' + os.path.abspath(d) for d in library_dirs])
    return ffibuilder


def main(argv):
    if len(argv) != 2:
        sys.exit('usage: python _build.py OUTPUT.c   (writes the C source of amscr._amscr)')
    make_ffibuilder().emit_c_code(argv[1])


if __name__ == '__main__':
    main(sys.argv)
