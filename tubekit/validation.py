"""Small input validators that raise :class:`ConfigError` / :class:`ShapeError`.

Besides the number and vector validators: :class:`StrChoice`, the base of tubekit's
str-valued enums (a member compares equal to, hashes like and prints as its string, so
TOML and JSON keep plain strings), :func:`choice`, the one explicit mapping of user
text to a member, and :func:`duration_seconds`, the one "duration > 0" rule.
"""

from __future__ import annotations

import enum
import math
from dataclasses import fields, is_dataclass, replace
from typing import Any, Mapping, TypeVar

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError

__all__ = ["as_vector", "positive", "nonnegative", "finite", "interval", "positive_triple", "nonnegative_triple",
           "StrChoice", "choice", "duration_seconds", "replace_fields"]

_E = TypeVar("_E", bound="StrChoice")


class StrChoice(str, enum.Enum):
    """A str-valued enum: ``Member == "value"``, ``str(Member) == f"{Member}" == "value"``."""

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)

    @classmethod
    def values(cls) -> tuple[str, ...]:
        """The allowed strings, in declaration order."""
        return tuple(m.value for m in cls)


def choice(field: str, kind: type[_E], value: Any) -> _E:
    """The member of ``kind`` whose value is ``value`` (a member or its string), else :class:`ConfigError`.

    The mapping is the explicit table value -> member; the error lists the allowed values.
    """
    table = {m.value: m for m in kind}
    member = table.get(value) if isinstance(value, str) else None
    if member is None:
        raise ConfigError(field, f"one of {kind.values()}", value)
    return member


def duration_seconds(field: str, value: Any) -> float:
    """``value`` as a finite number of seconds > 0 (booleans rejected), else :class:`ConfigError`."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value) or value <= 0:
        raise ConfigError(field, "a number of seconds > 0", value)
    return float(value)


def finite(field: str, value: Any) -> float:
    """Return ``value`` as a finite float or raise :class:`ConfigError` (booleans are not numbers)."""
    if isinstance(value, (bool, np.bool_)):
        raise ConfigError(field, "a finite number", value)
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ConfigError(field, "a finite number", value) from None
    if not math.isfinite(x):
        raise ConfigError(field, "a finite number", value)
    return x


def positive(field: str, value: Any) -> float:
    """Return ``value`` as a float > 0 or raise :class:`ConfigError`."""
    x = finite(field, value)
    if x <= 0.0:
        raise ConfigError(field, "a number > 0", value)
    return x


def nonnegative(field: str, value: Any) -> float:
    """Return ``value`` as a float >= 0 or raise :class:`ConfigError`."""
    x = finite(field, value)
    if x < 0.0:
        raise ConfigError(field, "a number >= 0", value)
    return x


def interval(field: str, value: Any) -> tuple[float, float]:
    """Return ``value`` as a non-empty interval ``(lo, hi)`` of finite floats, lo < hi."""
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise ConfigError(field, "a pair [lo, hi]", value) from None
    lo, hi = finite(f"{field}[0]", lo), finite(f"{field}[1]", hi)
    if not lo < hi:
        raise ConfigError(field, "lo < hi (a non-empty interval)", [lo, hi])
    return lo, hi


def _triple(field: str, value: Any, strict: bool) -> tuple[float, float, float]:
    """Three finite floats, each > 0 (``strict``) or >= 0; every failure a :class:`ConfigError`."""
    try:
        items = tuple(value)
    except TypeError:
        raise ConfigError(field, "three numbers", value) from None
    if len(items) != 3:
        raise ConfigError(field, "three numbers", value)
    out = tuple(finite(f"{field}[{i}]", x) for i, x in enumerate(items))
    if any((x <= 0) if strict else (x < 0) for x in out):
        raise ConfigError(field, "three numbers > 0" if strict else "three numbers >= 0", list(out))
    return out  # type: ignore[return-value]


def positive_triple(field: str, value: Any) -> tuple[float, float, float]:
    """Return ``value`` as a tuple of three floats > 0 or raise :class:`ConfigError`."""
    return _triple(field, value, strict=True)


def nonnegative_triple(field: str, value: Any) -> tuple[float, float, float]:
    """Return ``value`` as a tuple of three floats >= 0 or raise :class:`ConfigError`."""
    return _triple(field, value, strict=False)


def as_vector(name: str, value: Any, size: int) -> np.ndarray:
    """Return ``value`` as a finite float vector of length ``size``."""
    if isinstance(value, (list, tuple)) and any(isinstance(v, (bool, np.bool_)) for v in value):
        raise ConfigError(name, f"{size} numbers", value)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(name, f"{size} numbers", value) from None
    if arr.shape != (size,):
        raise ShapeError(name, f"({size},)", arr.shape)
    if not np.all(np.isfinite(arr)):
        raise ConfigError(name, "finite numbers", value)
    return arr


def replace_fields(obj: Any, changes: Mapping[str, Any], prefix: str = "") -> Any:
    """A copy of the dataclass ``obj`` with ``changes`` applied; ``"a.b"`` reaches into field ``a``.

    Each changed object is rebuilt by ``dataclasses.replace``, so its own validation runs again.
    An unknown name, or a dotted name into a field that is not a dataclass, is a
    :class:`ConfigError` naming it in full (``prefix`` + name).
    """
    names = [f.name for f in fields(obj) if f.init]
    whole: dict[str, Any] = {}
    parts: dict[str, dict[str, Any]] = {}
    for name, value in changes.items():
        head, dot, rest = str(name).partition(".")
        if head not in names:
            raise ConfigError(f"{prefix}{name}", f"a field of {type(obj).__name__}, one of {names}", name)
        if dot:
            parts.setdefault(head, {})[rest] = value
        else:
            whole[head] = value
    for head, sub in parts.items():
        if head in whole:
            raise ConfigError(f"{prefix}{head}", "the whole field or dotted parts of it, not both", sorted(sub))
        inner = getattr(obj, head)
        if not is_dataclass(inner):
            raise ConfigError(f"{prefix}{head}.{next(iter(sub))}", f"no dotted part ({prefix}{head} is a "
                              f"{type(inner).__name__})", next(iter(sub)))
        whole[head] = replace_fields(inner, sub, f"{prefix}{head}.")
    return replace(obj, **whole)
