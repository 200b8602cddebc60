"""The certificate's objectives compiled ahead of time from the sympy derivation (no sympy at run time).

:mod:`verify.theorem.gains` bounds the entries of K(e) and J(e) K(e), :mod:`verify.lemma1.bounds` the norms of
Lemma 1's matrices: functions of the error that sympy derives, simplifies and compiles (Arb for the
bound, numpy for the sampled value), half a second of sympy per process. ``python -m
verify.studies.generate_compiled`` prints those functions once, with the very printers the run-time compilation
uses (:func:`verify.kernel.intervals.arb_source` and ``sympy.lambdify``), into the shipped modules
:mod:`verify.kernel._generated_gains` and :mod:`verify.kernel._generated_route`.

They are used only while fresh: their ``SOURCE_HASH`` must equal :func:`source_hash`, the sha-256 of
the text of every module that decides them (:data:`SOURCES`, and the printing parts of
:mod:`verify.kernel.intervals`, :data:`PRINTER`), and only for the built-in laws
(:func:`tubekit.model.ancillary.is_builtin`). Otherwise the objectives are derived and compiled on the
spot: the same functions, so the same certificate, slower. ``tests/test_verify_studies_generate_compiled.py``
regenerates both modules and compares the text; ``tests/test_verify_kernel_compiled.py`` compares the shipped
functions with a fresh compilation, bit for bit.
"""

from __future__ import annotations

import hashlib
import importlib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from types import ModuleType
from typing import Callable

from tubekit.model.ancillary import is_builtin

from verify.kernel.intervals import vectorised

__all__ = ["Term", "Objective", "gain_terms", "route_objectives", "linear_in_speed", "source_hash", "fresh",
           "use", "SOURCES", "PRINTER", "GENERATED", "LAW_BOUNDS"]

#: Files (relative to the directory holding both packages) whose whole text decides the compiled objectives:
#: a change to one makes the shipped code stale.
SOURCES = ("tubekit/model/derivation.py", "tubekit/model/ancillary.py", "verify/theorem/gains.py", "verify/lemma1/polar.py",
           "verify/lemma1/forms.py", "verify/lemma1/_generated_forms.py", "verify/lemma1/objectives.py",
           "verify/studies/generate_compiled.py")
#: The top-level definitions of verify/kernel/intervals.py that print the code (its other parts do not change it).
PRINTER = ("class _ArbPrinter", "def arb_source", "def compile_numpy")
_ROOT = Path(__file__).resolve().parents[2]
#: The shipped modules: gains, route.
GENERATED = ("verify.kernel._generated_gains", "verify.kernel._generated_route")
#: Lemma-1 bounds whose objective depends on the ancillary law.
LAW_BOUNDS = ("J_lower", "JK_norm", "K_row_u", "K_row_w", "K_row_r")

_STATE = {"use": True}


@dataclass(frozen=True)
class Term:
    """One scalar objective of (e_d, e_o): a ``constant``, or its evaluators.

    ``arb(e_d, e_o) -> [arb]`` encloses it over balls; ``numpy(e_d, e_o) -> array (..., 1)`` samples it.
    """

    constant: float | None = None
    arb: Callable | None = None
    numpy: Callable | None = None


@dataclass(frozen=True)
class Objective:
    """One branch-and-bound case of a Lemma-1 bound: the norm or λ_min of a matrix A.

    Attributes
    ----------
    label : str
        Hemisphere and extreme point of the parameters (``toward u_max=+,w_max=-``).
    kind : str
        ``norm`` (||A||_2) or ``lmin`` (λ_min of (A + Aᵀ)/2).
    dims, pars : tuple of str
        The box dimensions (``e_d``, ``e_z``, ``e_o``, ``theta``, ``gamma``) and the fixed parameters.
    shape : tuple of int
        A's shape.
    arb : callable
        ``arb(*dims, *pars) -> [arb]``: the upper triangle (row-major) of AᵀA (norm) or (A + Aᵀ)/2 (lmin).
    numpy : callable
        ``numpy(*dims, *pars) -> array (..., rows * cols)``: A's entries, row-major.
    """

    label: str
    kind: str
    dims: tuple[str, ...]
    pars: tuple[str, ...]
    shape: tuple[int, int]
    arb: Callable
    numpy: Callable


def use(on: bool) -> bool:
    """Switch the shipped objectives on or off (off: always derive; the generators' mode); returns the old state."""
    old = _STATE["use"]
    _STATE["use"] = bool(on)
    return old


def _segment(text: str, header: str) -> str:
    """The top-level definition of ``text`` starting with ``header``, to the next top-level line ("" if none)."""
    lines = text.splitlines(keepends=True)
    start = next((i for i, ln in enumerate(lines) if ln.startswith(header)), None)
    if start is None:
        return ""
    end = start + 1
    while end < len(lines) and (not lines[end].strip() or lines[end][0] in " \t"):
        end += 1
    return "".join(lines[start:end])


def _text(rel: str) -> str:
    """The text of the source file ``rel`` ("" when absent)."""
    path = _ROOT / rel
    return path.read_text(encoding="utf-8") if path.is_file() else ""


@lru_cache(maxsize=1)
def source_hash() -> str:
    """sha-256 (hex) of the text of :data:`SOURCES` and of :data:`PRINTER` (no sympy: the files are read)."""
    h = hashlib.sha256()
    for rel in SOURCES:
        h.update(f"{rel}\n".encode() + _text(rel).encode() + b"\0")
    intervals = _text("verify/kernel/intervals.py")
    for header in PRINTER:
        h.update(_segment(intervals, header).encode() + b"\0")
    return h.hexdigest()


@lru_cache(maxsize=2)
def _module(name: str) -> ModuleType | None:
    """The shipped module ``name`` when present and fresh, else None."""
    try:
        mod = importlib.import_module(name)
    except ModuleNotFoundError:
        return None
    return mod if getattr(mod, "SOURCE_HASH", None) == source_hash() else None


def fresh() -> bool:
    """True when every shipped module is present and was generated from the current sources."""
    return all(_module(name) is not None for name in GENERATED)


def _shipped(name: str, law: str) -> ModuleType | None:
    """The shipped module when it may be used for ``law`` ("" for a law-free objective)."""
    if not _STATE["use"] or not (law == "" or is_builtin(law)):
        return None
    return _module(name)


def gain_terms(law: str, sign: int) -> dict[tuple[str, int], Term] | None:
    """The shipped gain objectives of ``law`` in hemisphere ``sign``, keyed (``k_abs``/``g``/``neg_g``/``g_abs``,
    row-major index), or None (not shipped for this law, stale or switched off)."""
    return None if _shipped(GENERATED[0], law) is None else _gain_terms(law, sign)


@lru_cache(maxsize=16)
def _gain_terms(law: str, sign: int) -> dict[tuple[str, int], Term] | None:
    """The shipped table of (law, sign) as :class:`Term` s (numpy evaluators wrapped by ``vectorised``)."""
    table = _module(GENERATED[0]).TERMS.get((law, sign))
    if table is None:
        return None
    return {key: Term(constant=v) if isinstance(v, float) else Term(arb=v[0], numpy=vectorised(v[1]))
            for key, v in table.items()}


def route_objectives(name: str, law: str, sign: int) -> tuple[Objective, ...] | None:
    """The shipped objectives of Lemma-1 bound ``name`` (``law`` is ignored unless in :data:`LAW_BOUNDS`), or None."""
    key_law = law if name in LAW_BOUNDS else ""
    return None if _shipped(GENERATED[1], key_law) is None else _route_objectives(name, key_law, sign)


@lru_cache(maxsize=64)
def _route_objectives(name: str, key_law: str, sign: int) -> tuple[Objective, ...] | None:
    """The shipped rows of (bound, law or "", sign) as :class:`Objective` s."""
    rows = _module(GENERATED[1]).OBJECTIVES.get((name, key_law, sign))
    if rows is None:
        return None
    return tuple(Objective(label=r[0], kind=r[1], dims=r[2], pars=r[3], shape=r[4], arb=r[5],
                           numpy=vectorised(r[6])) for r in rows)


def linear_in_speed(name: str, sign: int) -> bool | None:
    """The shipped answer of :func:`verify.lemma1.objectives.linear_in_speed`, or None."""
    mod = _shipped(GENERATED[1], "")
    return None if mod is None else mod.LINEAR_IN_SPEED.get((name, sign))
