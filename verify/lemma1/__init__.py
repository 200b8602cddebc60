"""The paper's continuous-time Lemma 1: L1, L2, J_lower, ξ̄ and the σ and tube radius they give (a reference).

The names below are imported on first use (PEP 562): the polar model is sympy, the bounds and the route
of the built-in laws are not (:mod:`verify.kernel.compiled`).
"""

from __future__ import annotations

import importlib
from typing import Any

#: Public name -> the module that defines it.
_LAZY: dict[str, str] = {
    "compute_bounds": "verify.lemma1.bounds", "Bounds": "verify.lemma1.bounds",
    "BoundResult": "verify.lemma1.bounds", "BOUND_NAMES": "verify.lemma1.bounds",
    "PolarModel": "verify.lemma1.polar", "polar_model": "verify.lemma1.polar", "law_gain": "verify.lemma1.polar",
    "paper_route": "verify.lemma1.route", "PaperRoute": "verify.lemma1.route", "RouteQuantity": "verify.lemma1.route",
    "ROUTE_NAMES": "verify.lemma1.route", "ROUTE_BUDGET": "verify.lemma1.route",
}

__all__ = list(_LAZY)


def __getattr__(name: str) -> Any:
    """Import a public name's module on first use."""
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'verify.lemma1' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
