"""Small input validators that raise :class:`ConfigError` / :class:`ShapeError`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .exceptions import ConfigError, ShapeError

__all__ = ["as_vector", "positive", "nonnegative", "finite"]


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
