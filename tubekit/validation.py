"""Small input validators that raise :class:`ConfigError` / :class:`ShapeError`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError

__all__ = ["as_vector", "positive", "nonnegative", "finite", "interval", "positive_triple", "nonnegative_triple"]


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
