"""galpha's exceptions: one class per status code, carrying the code and the server's message.

Both backends raise these: the network client from the gRPC status, the in-process module from the
engine's absl::Status (the two use the same code numbers). Catch :class:`GalphaError` for all.
"""

from __future__ import annotations

from typing import Dict, Type

__all__ = [
    "GalphaError",
    "InvalidInput",
    "NotFound",
    "ResourceExhausted",
    "DeadlineExceeded",
    "Cancelled",
    "Unauthenticated",
    "PermissionDenied",
    "Unavailable",
    "OutOfRange",
    "FailedPrecondition",
    "Internal",
    "error_for_code",
]


class GalphaError(Exception):
    """A failed galpha call. ``code`` is the status code's name (e.g. ``"INVALID_ARGUMENT"``),
    ``code_number`` its number (gRPC's and absl's), ``message`` the text naming the problem."""

    code = "UNKNOWN"
    code_number = 2

    def __init__(self, message: str, *, code: str | None = None, code_number: int | None = None) -> None:
        super().__init__(message)
        self.message = message
        if code is not None:
            self.code = code
        if code_number is not None:
            self.code_number = code_number

    def __str__(self) -> str:
        return f"{self.code}: {self.message}"


class InvalidInput(GalphaError, ValueError):
    """Bad input: a point outside the input domain, a bad threshold or option (INVALID_ARGUMENT)."""

    code, code_number = "INVALID_ARGUMENT", 3


class DeadlineExceeded(GalphaError, TimeoutError):
    code, code_number = "DEADLINE_EXCEEDED", 4


class NotFound(GalphaError, KeyError):
    """An unknown, released or evicted handle: build again (handles are content-derived)."""

    code, code_number = "NOT_FOUND", 5

    def __str__(self) -> str:  # KeyError quotes its argument; keep the plain message
        return GalphaError.__str__(self)


class PermissionDenied(GalphaError, PermissionError):
    code, code_number = "PERMISSION_DENIED", 7


class ResourceExhausted(GalphaError):
    """A limit: points per build, bytes in flight, queued builds, memory."""

    code, code_number = "RESOURCE_EXHAUSTED", 8


class FailedPrecondition(GalphaError):
    code, code_number = "FAILED_PRECONDITION", 9


class Cancelled(GalphaError):
    code, code_number = "CANCELLED", 1


class OutOfRange(GalphaError, IndexError):
    """A rank outside 0..K."""

    code, code_number = "OUT_OF_RANGE", 11


class Internal(GalphaError):
    code, code_number = "INTERNAL", 13


class Unavailable(GalphaError, ConnectionError):
    """No server at the address, or it is draining: retry elsewhere or later."""

    code, code_number = "UNAVAILABLE", 14


class Unauthenticated(GalphaError, PermissionError):
    """A missing or unknown bearer token."""

    code, code_number = "UNAUTHENTICATED", 16


_BY_NUMBER: Dict[int, Type[GalphaError]] = {
    cls.code_number: cls
    for cls in (
        InvalidInput,
        DeadlineExceeded,
        NotFound,
        PermissionDenied,
        ResourceExhausted,
        FailedPrecondition,
        Cancelled,
        OutOfRange,
        Internal,
        Unavailable,
        Unauthenticated,
    )
}
# OUT_OF_RANGE aside, absl's and gRPC's code numbers and names agree; these have no own class.
_NAMES = {0: "OK", 2: "UNKNOWN", 6: "ALREADY_EXISTS", 10: "ABORTED", 12: "UNIMPLEMENTED", 15: "DATA_LOSS"}


def error_for_code(code_number: int, message: str) -> GalphaError:
    """The exception for a status code number (gRPC's or absl's) and its message."""
    cls = _BY_NUMBER.get(code_number)
    if cls is not None:
        return cls(message)
    return GalphaError(message, code=_NAMES.get(code_number, f"CODE_{code_number}"), code_number=code_number)
