"""Small input validators that raise :class:`ConfigError` / :class:`ShapeError`.

Besides the number and vector validators: :class:`StrChoice`, the base of tubekit's
str-valued enums (a member compares equal to, hashes like and prints as its string, so
TOML and JSON keep plain strings), :func:`choice`, the one explicit mapping of user
text to a member, and :func:`duration_seconds`, the one "duration > 0" rule.
"""

from __future__ import annotations

import enum
import math
import tomllib
from dataclasses import fields, is_dataclass, replace
from pathlib import Path
from typing import Any, Mapping, TypeVar

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError

__all__ = ["as_vector", "is_number", "bounded_int", "positive", "nonnegative", "finite", "interval", "positive_triple",
           "nonnegative_triple", "StrChoice", "choice", "duration_seconds", "replace_fields", "text", "period_count",
           "ticks_per_period", "speed_bound", "MAX_PERIODS", "MAX_TICKS_PER_PERIOD", "MAX_SPEED",
           "gain", "MAX_GAIN", "read_toml"]

_E = TypeVar("_E", bound="StrChoice")

#: Most periods a run may have (duration / dt); beyond, counts overflow memory and time.
MAX_PERIODS = 1e9
#: Most ticks of a fast law per period (rate x dt).
MAX_TICKS_PER_PERIOD = 1e6
#: Largest speed accepted anywhere (m/s, a current): beyond, no bound derived from it is worth using.
MAX_SPEED = 1e6
#: Largest ancillary gain sigma accepted (1/s): beyond, sigma x tick overflows every bound of the tube.
MAX_GAIN = 1e6


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
    try:
        seconds = finite(field, value)
    except ConfigError:
        raise ConfigError(field, "a number of seconds > 0", value) from None
    if seconds <= 0:
        raise ConfigError(field, "a number of seconds > 0", value)
    return seconds


def is_number(value: Any) -> bool:
    """Whether ``value`` is a real number: an int or float (numpy's too); never a bool, a string or None."""
    kind = type(value)
    if kind is float or kind is int:  # the common case, first (a bool's type is bool, not int)
        return True
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def finite(field: str, value: Any) -> float:
    """Return ``value`` as a finite float or raise :class:`ConfigError`.

    Types are strict: a string (``"100"``), a boolean or None is not a number.
    """
    if type(value) is float and math.isfinite(value):  # the common case, first
        return value
    if not is_number(value):
        raise ConfigError(field, "a finite number", value)
    try:
        x = float(value)
    except OverflowError:  # an int beyond the float range
        raise ConfigError(field, "a finite number", value) from None
    if not math.isfinite(x):
        raise ConfigError(field, "a finite number", value)
    return x


def bounded_int(field: str, value: Any, lo: int, hi: int) -> int:
    """``value`` as an int in [lo, hi] (a bool or a float is not an int), else :class:`ConfigError`."""
    if not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_)) or not lo <= value <= hi:
        raise ConfigError(field, f"an integer in [{lo}, {hi}]", value)
    return int(value)


def text(field: str, value: Any) -> str:
    """``value`` if it is a string, else :class:`ConfigError`."""
    if not isinstance(value, str):
        raise ConfigError(field, "a string", value)
    return value


def period_count(field: str, duration: float, dt: float) -> float:
    """``duration / dt`` (periods), refused past :data:`MAX_PERIODS` before any count is made an int."""
    periods = duration / dt
    if not periods <= MAX_PERIODS:
        raise ConfigError(field, f"at most {MAX_PERIODS:g} FHOCP periods of {dt:g} s ({MAX_PERIODS * dt:.6g} s)",
                          duration)
    return periods


def ticks_per_period(rate_field: str, rate: float, dt_field: str, dt: float) -> int:
    """Ticks of a ``rate`` (Hz) law per period ``dt`` (s): a whole number in [1, :data:`MAX_TICKS_PER_PERIOD`].

    A period shorter than one tick names ``dt_field``; too many ticks, or not a whole number, ``rate_field``.
    """
    ratio = rate * dt
    if ratio < 1 - 1e-9:
        raise ConfigError(dt_field, f"at least one tick 1/{rate_field.rsplit('.', 1)[-1]} = {1 / rate:g} s", dt)
    if ratio > MAX_TICKS_PER_PERIOD:
        raise ConfigError(rate_field, f"at most {MAX_TICKS_PER_PERIOD:g} ticks per period (rate x dt)", rate)
    if abs(ratio - round(ratio)) > 1e-9:
        raise ConfigError(rate_field, "a positive multiple of 1/dt", rate)
    return round(ratio)


def gain(field: str, value: Any) -> float:
    """An ancillary gain sigma (1/s): a number in (0, :data:`MAX_GAIN`], else :class:`ConfigError`."""
    sigma = positive(field, value)
    if sigma > MAX_GAIN:
        raise ConfigError(field, f"a gain in (0, {MAX_GAIN:g}] 1/s", value)
    return sigma


def speed_bound(field: str, magnitude: float, value: Any) -> None:
    """Refuse a speed ``magnitude`` (m/s) beyond :data:`MAX_SPEED` (``value``: what the user gave)."""
    if not magnitude <= MAX_SPEED:
        raise ConfigError(field, f"a speed of magnitude <= {MAX_SPEED:g} m/s", value)


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
    if isinstance(value, (list, tuple)) and not all(is_number(v) for v in value):
        raise ConfigError(name, f"{size} numbers", value)
    if isinstance(value, np.ndarray) and value.dtype.kind not in "iuf":
        raise ConfigError(name, f"{size} numbers", value)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
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


def read_toml(path: str | Path, field: str) -> dict:
    """The table of a TOML file; every failure is a :class:`ConfigError` naming ``field`` (e.g. ``CONFIG``)."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(field, "a path to an existing TOML file", str(p))
    try:
        return tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(field, "valid TOML", str(p), str(exc)) from None
    except UnicodeDecodeError:
        raise ConfigError(field, "a UTF-8 text (TOML) file", str(p), "It is binary or not UTF-8.") from None
    except OSError as exc:
        raise ConfigError(field, "a readable file", str(p), exc.strerror or str(exc)) from None
