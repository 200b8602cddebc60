"""Typed parts of a certificate (σ choice, Ē) and the strict readers every ``from_dict`` uses.

A certificate's JSON is read back block by block; each reader raises
:class:`tubekit.exceptions.ConfigError` naming the full key (``certificate.tube.rho``)
and what it expected, never a ``KeyError`` or ``TypeError``. In the JSON a non-finite
number is ``null`` (:func:`tubekit.jsonable.to_jsonable`); the readers of upper bounds
read ``null`` back as ``+inf`` (:func:`bound`), so a round trip is exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from tubekit.exceptions import ConfigError

__all__ = ["SigmaTrial", "SigmaChoice", "EBar", "item", "block", "number", "bound", "numbers", "matrix",
           "flag", "text", "integer", "texts"]


def item(d: Any, key: str, where: str) -> Any:
    """``d[key]``; ConfigError ``where.key`` when ``d`` is not a dict or the key is missing."""
    if not isinstance(d, dict):
        raise ConfigError(where, "a JSON object", type(d).__name__)
    if key not in d:
        raise ConfigError(f"{where}.{key}", "present", "missing")
    return d[key]


def block(d: Any, key: str, where: str) -> dict:
    """``d[key]`` as a JSON object."""
    v = item(d, key, where)
    if not isinstance(v, dict):
        raise ConfigError(f"{where}.{key}", "a JSON object", type(v).__name__)
    return v


def _float(v: Any, name: str, none: float | None) -> float:
    if v is None and none is not None:
        return none
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ConfigError(name, "a number", v)
    return float(v)


def number(d: Any, key: str, where: str) -> float:
    """A finite JSON number."""
    x = _float(item(d, key, where), f"{where}.{key}", None)
    if not math.isfinite(x):
        raise ConfigError(f"{where}.{key}", "a finite number", x)
    return x


def bound(d: Any, key: str, where: str, none: float = math.inf) -> float:
    """A JSON number or ``null`` (read as ``none``, +inf by default: no finite bound)."""
    return _float(item(d, key, where), f"{where}.{key}", none)


def numbers(d: Any, key: str, where: str, n: int | None = None, none: float | None = math.inf) -> tuple[float, ...]:
    """A list of numbers (``null`` read as ``none``), of length ``n`` when given."""
    v = item(d, key, where)
    name = f"{where}.{key}"
    if not isinstance(v, list) or (n is not None and len(v) != n):
        raise ConfigError(name, f"a list of {n if n is not None else 'some'} numbers", v)
    return tuple(_float(x, f"{name}[{i}]", none) for i, x in enumerate(v))


def matrix(d: Any, key: str, where: str) -> tuple[tuple[float, ...], ...]:
    """A 3 x 3 list of lists of numbers."""
    v = item(d, key, where)
    if not isinstance(v, list) or len(v) != 3:
        raise ConfigError(f"{where}.{key}", "3 rows of 3 numbers", v)
    return tuple(_row(row, f"{where}.{key}[{i}]") for i, row in enumerate(v))


def _row(row: Any, name: str) -> tuple[float, ...]:
    if not isinstance(row, list) or len(row) != 3:
        raise ConfigError(name, "3 numbers", row)
    return tuple(_float(x, f"{name}[{i}]", math.inf) for i, x in enumerate(row))


def flag(d: Any, key: str, where: str, allow_none: bool = False) -> bool | None:
    """A JSON boolean (or ``null`` when ``allow_none``)."""
    v = item(d, key, where)
    if v is None and allow_none:
        return None
    if not isinstance(v, bool):
        raise ConfigError(f"{where}.{key}", "true or false", v)
    return v


def text(d: Any, key: str, where: str) -> str:
    """A JSON string."""
    v = item(d, key, where)
    if not isinstance(v, str):
        raise ConfigError(f"{where}.{key}", "a string", v)
    return v


def texts(d: Any, key: str, where: str) -> tuple[str, ...]:
    """A list of strings."""
    v = item(d, key, where)
    if not isinstance(v, list) or not all(isinstance(s, str) for s in v):
        raise ConfigError(f"{where}.{key}", "a list of strings", v)
    return tuple(v)


def integer(d: Any, key: str, where: str) -> int:
    """A JSON integer."""
    v = item(d, key, where)
    if isinstance(v, bool) or not isinstance(v, int):
        raise ConfigError(f"{where}.{key}", "an integer", v)
    return v


@dataclass(frozen=True)
class SigmaTrial:
    """One σ evaluated by :func:`verify.certify`: σ (1/s), its verdict, slack score (None: no tube), failures."""

    sigma: float
    certified: bool
    score: float | None
    failed: tuple[str, ...]

    def to_dict(self) -> dict:
        """``{sigma, certified, score, failed}``."""
        return {"sigma": self.sigma, "certified": self.certified, "score": self.score, "failed": list(self.failed)}

    @classmethod
    def from_dict(cls, d: Any, where: str = "certificate.sigma.tried[]") -> "SigmaTrial":
        """Inverse of :meth:`to_dict`."""
        score = item(d, "score", where)
        return cls(sigma=number(d, "sigma", where), certified=bool(flag(d, "certified", where)),
                   score=None if score is None else number(d, "score", where), failed=texts(d, "failed", where))


@dataclass(frozen=True)
class SigmaChoice:
    """The σ of the certificate (1/s), why it was chosen, and every σ tried."""

    value: float
    source: str
    tried: tuple[SigmaTrial, ...]

    def to_dict(self) -> dict:
        """``{value, source, tried}``."""
        return {"value": self.value, "source": self.source, "tried": [t.to_dict() for t in self.tried]}

    @classmethod
    def from_dict(cls, d: Any, where: str = "certificate.sigma") -> "SigmaChoice":
        """Inverse of :meth:`to_dict`."""
        tried = item(d, "tried", where)
        if not isinstance(tried, list):
            raise ConfigError(f"{where}.tried", "a list", type(tried).__name__)
        return cls(value=number(d, "value", where), source=text(d, "source", where),
                   tried=tuple(SigmaTrial.from_dict(t, f"{where}.tried[{i}]") for i, t in enumerate(tried)))


@dataclass(frozen=True)
class EBar:
    """Ē on the last arc: R shrunk by the largest margin, per axis ``(lo, hi)`` (m, m, -)."""

    e_d: tuple[float, float]
    e_z: tuple[float, float]
    e_o: tuple[float, float]

    def to_dict(self) -> dict:
        """``{e_d: [lo, hi], e_z: [...], e_o: [...]}``."""
        return {"e_d": list(self.e_d), "e_z": list(self.e_z), "e_o": list(self.e_o)}

    @classmethod
    def from_dict(cls, d: Any, where: str = "certificate.e_bar") -> "EBar":
        """Inverse of :meth:`to_dict` (a lost bound, ``null``, reads as the empty side: lo +inf, hi -inf)."""
        return cls(*(_pair_with_none(d, k, where) for k in ("e_d", "e_z", "e_o")))


def _pair_with_none(d: Any, key: str, where: str) -> tuple[float, float]:
    v = item(d, key, where)
    if not isinstance(v, list) or len(v) != 2:
        raise ConfigError(f"{where}.{key}", "[lo, hi]", v)
    lo = math.inf if v[0] is None else _float(v[0], f"{where}.{key}[0]", None)
    hi = -math.inf if v[1] is None else _float(v[1], f"{where}.{key}[1]", None)
    return lo, hi
