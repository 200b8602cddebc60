"""Pre-derived symbolic forms of the Lemma-1 objectives, shipped so that no simplification runs at run time.

Deriving the polar-form model (:func:`verify.lemma1.polar.polar_model`) and simplifying the
objective matrices (Gram matrices AᵀA, symmetric parts, J K) takes seconds of sympy time per
process. :mod:`verify.lemma1._generated_forms` stores their results (``sympy.srepr`` text),
written by ``python -m verify.lemma1.generate``:

* ``POLAR``: the polar model of each hemisphere, used only when its ``POLAR_HASH`` equals
  :func:`verify.lemma1.polar.polar_hash` (the derivation and the polar rewriting are unchanged);
* ``SIMPLIFIED``: ``key(kind, M) -> simplified M``, keyed by the sha-256 of the *input* matrix, so a
  stored result is only ever used for exactly the expression it was computed from (an input
  that changed misses the table and is simplified on the spot).

``tests/test_verify_lemma1_forms.py`` regenerates both and checks they equal the shipped module.
"""

from __future__ import annotations

import hashlib
from functools import lru_cache
from typing import Callable

import sympy as sp

__all__ = ["stored_polar", "simplified", "matrix_key", "recording", "POLAR_FIELDS"]

#: The sympy matrices of a :class:`verify.lemma1.polar.PolarModel`, in order.
POLAR_FIELDS = ("J", "zeta", "xi", "dh_de", "dzeta_de", "dzeta_dtheta", "dxi_domega")

_STATE: dict = {"use_stored": True, "record": None}


def matrix_key(kind: str, M: sp.Matrix) -> str:
    """Table key of ``kind`` applied to ``M``: sha-256 of ``kind`` and ``srepr(M)`` (24 hex digits)."""
    return hashlib.sha256(f"{kind}:{sp.srepr(sp.ImmutableMatrix(M))}".encode()).hexdigest()[:24]


_NAMESPACE: dict = {}


def _parse(text: str) -> sp.ImmutableMatrix:
    """A matrix from its ``srepr`` (text of the shipped module only, never user input)."""
    if not _NAMESPACE:
        _NAMESPACE.update(vars(sp))
    return sp.ImmutableMatrix(eval(text, _NAMESPACE))  # noqa: S307 - srepr printed by the generator


@lru_cache(maxsize=1)
def _module():
    """The shipped module, or None when it is absent."""
    try:
        from verify.lemma1 import _generated_forms
    except ImportError:
        return None
    return _generated_forms


def stored_polar(s: int, expected_hash: str) -> dict[str, object] | None:
    """The stored polar model fields of hemisphere ``s`` (matrices and ``zeta_rotation_form``), or None
    when the table is absent, disabled, or was generated from another derivation (``POLAR_HASH`` differs
    from ``expected_hash``)."""
    mod = _module()
    if not _STATE["use_stored"] or mod is None or mod.POLAR_HASH != expected_hash:
        return None
    entry = mod.POLAR.get(s)
    if entry is None:
        return None
    out: dict[str, object] = {name: _parse(entry[name]) for name in POLAR_FIELDS}
    out["zeta_rotation_form"] = bool(entry["zeta_rotation_form"])
    return out


def simplified(kind: str, M: sp.Matrix, compute: Callable[[sp.Matrix], sp.Matrix]) -> sp.Matrix:
    """``compute(M)`` — read from the table when it holds this exact input, else computed (and recorded
    while :func:`recording` is on)."""
    key = matrix_key(kind, M)
    mod = _module()
    if _STATE["use_stored"] and mod is not None and key in mod.SIMPLIFIED:
        return _parse(mod.SIMPLIFIED[key])
    out = compute(M)
    if _STATE["record"] is not None:
        _STATE["record"][key] = sp.srepr(sp.ImmutableMatrix(out))
    return out


def recording(on: bool) -> dict[str, str]:
    """Switch the generator's mode: stored forms unused and every computed form recorded (``on``), or back.

    Returns the record (key -> srepr) collected so far.
    """
    record = _STATE["record"] or {}
    _STATE["use_stored"] = not on
    _STATE["record"] = {} if on else None
    return record
