"""The loaded C library: its path, ABI and version, and the features it was built with."""
from __future__ import annotations

from ._lib import API_MODE, LIBRARY_PATH, SOVERSION, ffi, lib

__all__ = ['API_MODE', 'LIBRARY_PATH', 'SOVERSION', 'library_version', 'has_threads']


def library_version() -> str:
    """Version string of the loaded C library ("M.m.p")."""
    return ffi.string(lib.amscr_version_string()).decode()


def has_threads() -> bool:
    """True when the loaded library runs batch calls on POSIX threads."""
    return bool(lib.amscr_has_feature(lib.AMSCR_FEATURE_THREADS))
