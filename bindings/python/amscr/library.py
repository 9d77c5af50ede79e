"""The loaded C library: its path, ABI and version, and the features it was built with."""
from __future__ import annotations

from ._lib import API_MODE, LIBRARY_PATH, SOVERSION, ffi, lib

__all__ = ['API_MODE', 'LIBRARY_PATH', 'SOVERSION', 'library_version', 'has_threads']


def library_version() -> str:
    """The version of the loaded C library.

    Returns:
        the version string "M.m.p" (the package's is ``amscr.__version__``).
    """
    return ffi.string(lib.amscr_version_string()).decode()


def has_threads() -> bool:
    """Whether the loaded library was built with threads.

    Returns:
        True when batch calls (:class:`Collection`) run on POSIX threads.
    """
    return bool(lib.amscr_has_feature(lib.AMSCR_FEATURE_THREADS))
