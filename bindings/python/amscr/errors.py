"""Exceptions raised by amscr: one class per C status code (``amscr_status``), all ``AmscrError``.

Each class also derives from the built-in exception a Python user would catch for that kind of
failure (``ValueError`` for bad input, ``OSError`` for files, ``MemoryError``...), so both
``except amscr.AmscrError`` and ``except ValueError`` work.
"""
import contextlib
import errno as _errno
import os
from typing import Dict, Iterator, Optional, Tuple, Type

from ._lib import ffi, lib

__all__ = [
    'AmscrError', 'Error', 'InvalidArgumentError', 'NoMemoryError', 'FileError', 'IOError_', 'FileNotFound',
    'FilePermissionError', 'FileIsADirectoryError', 'FormatError',
    'UnsupportedError', 'DegenerateError', 'NumericError', 'NumericalError', 'NotConvergedError',
    'NotFoundError', 'StateError', 'InternalError', 'CancelledError', 'LimitError', 'STATUS_EXCEPTIONS',
]


class AmscrError(Exception):
    """Base of every error reported by libamscr.

    Attributes:
        status: the C status code (an ``int``, ``amscr.errors.lib.AMSCR_E_*``); the class's own
            code also when the Python layer raises it (a validation error is AMSCR_E_INVALID_ARG);
            None only for a bare ``AmscrError`` made without one.
        detail: the C library's detail message for the failing call (may be empty).
        message: the full message (``strerror(status): detail`` for the library's errors; the
            detail alone for the Python layer's own).
    """

    status: Optional[int] = None

    def __init__(self, message: str, status: Optional[int] = None, detail: str = ''):
        super().__init__(message)
        self.message = message
        if status is not None:
            self.status = status
        self.detail = detail

    def __str__(self) -> str:
        return self.message


#: Alias: a shorter name for the base class (``amscr.Error``).
Error = AmscrError


class InvalidArgumentError(AmscrError, ValueError):
    """AMSCR_E_INVALID_ARG: NULL pointer, out-of-range value, bad option."""
    status = lib.AMSCR_E_INVALID_ARG


class NoMemoryError(AmscrError, MemoryError):
    """AMSCR_E_NOMEM: an allocation failed."""
    status = lib.AMSCR_E_NOMEM


class FileError(AmscrError, OSError):
    """AMSCR_E_IO: a file could not be opened, read or written."""
    status = lib.AMSCR_E_IO


IOError_ = FileError


class FileNotFound(FileError, FileNotFoundError):
    """AMSCR_E_IO for a file that does not exist: also a ``FileNotFoundError``."""


class FilePermissionError(FileError, PermissionError):
    """AMSCR_E_IO for a file the process may not read or write: also a ``PermissionError``."""


class FileIsADirectoryError(FileError, IsADirectoryError):
    """AMSCR_E_IO for a folder given as a file: also an ``IsADirectoryError``."""


#: errno -> the FileError subclass that is also the built-in OSError subclass for it.
_FILE_ERRORS: Dict[int, Type[FileError]] = {
    _errno.ENOENT: FileNotFound, _errno.EACCES: FilePermissionError, _errno.EPERM: FilePermissionError,
    _errno.EISDIR: FileIsADirectoryError,
}


class FormatError(AmscrError, ValueError):
    """AMSCR_E_FORMAT: malformed or unsupported file content."""
    status = lib.AMSCR_E_FORMAT


class UnsupportedError(AmscrError, NotImplementedError):
    """AMSCR_E_UNSUPPORTED: the feature is not compiled into this build of libamscr."""
    status = lib.AMSCR_E_UNSUPPORTED


class DegenerateError(AmscrError, ValueError):
    """AMSCR_E_DEGENERATE: too few points, zero area, collinear, singular."""
    status = lib.AMSCR_E_DEGENERATE


class NumericError(AmscrError, ArithmeticError):
    """AMSCR_E_NUMERIC: rank-deficient system, LAPACK failure, non-finite result."""
    status = lib.AMSCR_E_NUMERIC


NumericalError = NumericError


class NotConvergedError(AmscrError, RuntimeError):
    """AMSCR_E_NOT_CONVERGED: an iteration cap was reached without convergence."""
    status = lib.AMSCR_E_NOT_CONVERGED


class NotFoundError(AmscrError, LookupError):
    """AMSCR_E_NOT_FOUND: nothing found (empty mask, no Bayes crossing)."""
    status = lib.AMSCR_E_NOT_FOUND


class StateError(AmscrError, RuntimeError):
    """AMSCR_E_STATE: object used in the wrong state (e.g. not fitted)."""
    status = lib.AMSCR_E_STATE


class InternalError(AmscrError, RuntimeError):
    """AMSCR_E_INTERNAL: a bug in libamscr; please report it."""
    status = lib.AMSCR_E_INTERNAL


class CancelledError(AmscrError):
    """AMSCR_E_CANCELLED: a progress callback asked to stop."""
    status = lib.AMSCR_E_CANCELLED


class LimitError(AmscrError, ValueError):
    """AMSCR_E_LIMIT: the input exceeds a documented size limit."""
    status = lib.AMSCR_E_LIMIT


#: status code -> exception class, one to one.
STATUS_EXCEPTIONS: Dict[int, Type[AmscrError]] = {
    cls.status: cls for cls in (
        InvalidArgumentError, NoMemoryError, FileError, FormatError, UnsupportedError, DegenerateError,
        NumericError, NotConvergedError, NotFoundError, StateError, InternalError, CancelledError, LimitError)
}


def _decode(p) -> str:
    return ffi.string(p).decode('utf-8', 'replace') if p != ffi.NULL else ''


def _file_errno(detail: str) -> Tuple[Optional[int], str]:
    """(errno, its text) of a file error's detail, which ends in the system's message for it
    ("path: No such file or directory"); (None, '') when it names none."""
    for e in (_errno.ENOENT, _errno.EACCES, _errno.EPERM, _errno.EISDIR, _errno.ENOTDIR, _errno.ENOSPC,
              _errno.EROFS, _errno.EEXIST):
        text = os.strerror(e)
        if detail.endswith(': ' + text):
            return e, text
    return None, ''


def error_from_status(status: int, detail: str = '') -> AmscrError:
    """The exception for a non-zero status code, with the library's message and ``detail``. A
    file error whose detail names the system's reason carries its ``errno`` and ``strerror``,
    and is also ``FileNotFoundError``, ``PermissionError`` or ``IsADirectoryError`` when it is
    one of those."""
    status = int(status)
    message = _decode(lib.amscr_strerror(status))
    cls = STATUS_EXCEPTIONS.get(status, AmscrError)
    code, text = _file_errno(detail) if cls is FileError else (None, '')
    err = _FILE_ERRORS.get(code, cls)('%s: %s' % (message, detail) if detail else message, status, detail)
    if code is not None:
        err.errno, err.strerror = code, text  # type: ignore[attr-defined]
    return err


def _check(status: int) -> None:
    """Raises the exception for ``status`` unless it is AMSCR_OK.

    Call it right after the C call, on the same thread: the detail is the calling thread's
    (thread-local in the library) and is valid until the next amscr call on that thread.
    """
    if status:
        detail = _decode(lib.amscr_last_error_detail())
        raise error_from_status(status, detail)


@contextlib.contextmanager
def _reworded(*renames: Tuple[str, str]) -> Iterator[None]:
    """The library's errors raised in the block with the C names in their detail replaced by the
    Python layer's, ``(c_text, python_text)`` pairs: ``('amscr_topk: ', 'topk: ')``."""
    try:
        yield
    except AmscrError as e:
        detail = e.detail
        for old, new in renames:
            detail = detail.replace(old, new)
        if detail == e.detail or e.status is None:
            raise
        raise error_from_status(e.status, detail) from None
