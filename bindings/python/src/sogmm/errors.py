"""Exceptions raised by the sogmm package.

Every failing call of the C library (a non-zero ``sogmm_status``) raises a
subclass of :class:`SogmmError` that carries the status code and the message
of ``sogmm_last_error()``. Input problems found in Python before calling C
(wrong shape, wrong dtype) raise the same classes, so callers can catch one
family. The subclasses also derive from the matching built-in exception
(ValueError, OSError, ...), so generic ``except ValueError`` code works too.
"""

from __future__ import annotations

__all__ = [
    "SogmmError",
    "NullArgumentError",
    "InvalidArgumentError",
    "InvalidDataError",
    "NumericError",
    "SogmmIOError",
    "FormatError",
    "LimitError",
    "SogmmMemoryError",
    "BufferTooSmallError",
    "NotFoundError",
    "InternalError",
    "MapBusyError",
    "NotFittedError",
    "error_for_status",
]


class SogmmError(Exception):
    """Base class of every error of the sogmm package.

    Attributes:
        status: the C status code (negative int), or None for errors raised by
            the Python layer without a C call.
        message: the library's message (``sogmm_last_error()``) or the Python
            layer's own message.
    """

    status: int | None = None

    def __init__(self, message: str, status: int | None = None):
        super().__init__(message)
        self.message = message
        if status is not None:
            self.status = status

    def __str__(self) -> str:  # keep the message only, as Python exceptions do
        return self.message


class NullArgumentError(SogmmError, ValueError):
    status = -1


class InvalidArgumentError(SogmmError, ValueError):
    status = -2


class InvalidDataError(SogmmError, ValueError):
    status = -3


class NumericError(SogmmError, ArithmeticError):
    status = -4


class SogmmIOError(SogmmError, OSError):
    status = -5

    def __init__(self, message: str, status: int | None = None):
        SogmmError.__init__(self, message, status)

    def __str__(self) -> str:
        return self.message


class FormatError(SogmmError, ValueError):
    status = -6


class LimitError(SogmmError, ValueError):
    status = -7


class SogmmMemoryError(SogmmError, MemoryError):
    status = -8


class BufferTooSmallError(SogmmError, ValueError):
    status = -9


class NotFoundError(SogmmError, LookupError):
    status = -10


class InternalError(SogmmError, RuntimeError):
    status = -11


class CancelledError(SogmmError):
    """The progress callback stopped the call (it returned a true value)."""

    status = -12


class MapBusyError(SogmmError, RuntimeError):
    """Another call is using the :class:`sogmm.Map` ("map busy: ..."): a call
    from another thread while one runs, or a call (``close()`` included) from
    the progress callback of a call on the same map. Nothing was changed;
    retry once that call has returned."""

    status = -13


class NotFittedError(SogmmError, AttributeError):
    """A fitted attribute or method was used before ``fit``."""


_BY_STATUS = {
    cls.status: cls
    for cls in (
        NullArgumentError,
        InvalidArgumentError,
        InvalidDataError,
        NumericError,
        SogmmIOError,
        FormatError,
        LimitError,
        SogmmMemoryError,
        BufferTooSmallError,
        NotFoundError,
        InternalError,
        CancelledError,
        MapBusyError,
    )
}


def error_for_status(status: int, message: str) -> SogmmError:
    """The exception object for a C status code (unknown codes -> SogmmError)."""
    cls = _BY_STATUS.get(status, SogmmError)
    return cls(message, status)
