"""Exception hierarchy: one base class, narrow subclasses that also subclass built-ins."""

from __future__ import annotations

__all__ = [
    "TubekitError",
    "ConfigError",
    "ShapeError",
    "SolverError",
    "NotAvailableError",
]


class TubekitError(Exception):
    """Base class of every error raised by tubekit and verify."""


class ConfigError(TubekitError, ValueError):
    """A user-supplied value is invalid (names the field, what was expected, what came)."""

    def __init__(self, field: str, expected: str, received: object, hint: str = "") -> None:
        self.field = field
        self.expected = expected
        self.received = received
        msg = f"{field}: expected {expected}, received {received!r}"
        if hint:
            msg += f". {hint}"
        super().__init__(msg)


class ShapeError(TubekitError, ValueError):
    """An array has the wrong shape."""

    def __init__(self, name: str, expected: str, received: tuple[int, ...]) -> None:
        self.name = name
        self.expected = expected
        self.received = received
        super().__init__(f"{name}: expected shape {expected}, received shape {received}")


class SolverError(TubekitError, RuntimeError):
    """A numerical solver failed and no safe fallback exists."""


class NotAvailableError(TubekitError, RuntimeError):
    """An optional capability (e.g. an optional dependency) is not available."""
