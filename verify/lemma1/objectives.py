"""The symbolic objectives of the Lemma-1 bounds (sympy): each branch-and-bound case's matrix, compiled.

:mod:`verify.lemma1.bounds` maximises, over the error box, the norm (or λ_min of the symmetric part)
of a matrix of the polar model (:mod:`verify.lemma1.polar`) at each extreme point of the bound's
linear parameters (:func:`case_matrices`). This module builds those matrices and compiles them:
the Arb enclosure reads the simplified Gram matrix AᵀA (or (A + Aᵀ)/2, :func:`arb_entries`), the
sampled value A itself. For the built-in laws the same functions ship compiled (:mod:`verify.kernel.compiled`,
printed from :func:`case_matrices` by :mod:`verify.studies.generate_compiled`), so this module is imported only
for another law, when the shipped code is stale, or by the generators.
"""

from __future__ import annotations

import itertools
from functools import lru_cache
from typing import Callable

import sympy as sp

from tubekit.model.derivation import symbols
from tubekit.exceptions import ConfigError, TubekitError

from verify.kernel.compiled import Objective
from verify.kernel.intervals import compile_arb, compile_numpy
from verify.lemma1.forms import simplified
from verify.lemma1.polar import A_V, B_V, E_D, E_O, E_Z, GAMMA, H_XY, P_Z, R_M, THETA, U_M, W_M, law_gain, polar_model

__all__ = ["case_matrices", "arb_entries", "derived_objectives", "linear_in_speed", "OBJECTIVE_NAMES",
           "DIMENSIONS", "PARAMETERS"]

#: The bounds with an objective (every one of :data:`verify.lemma1.bounds.BOUND_NAMES`).
OBJECTIVE_NAMES = ("L1", "L2", "J_lower", "xi_bar", "zeta_theta", "K_row_u", "K_row_w", "K_row_r", "JK_norm")
#: The branch-and-bound dimensions, in the order of a case's arguments.
DIMENSIONS = (E_D, E_Z, E_O, THETA, GAMMA)
#: The parameters a bound's objective may hold (fixed per solve, after the dimensions, sorted by name).
PARAMETERS = {"L1": (U_M, W_M, R_M), "L2": (H_XY, P_Z), "zeta_theta": (H_XY, P_Z)}


def _gram(A: sp.Matrix) -> sp.Matrix:
    """A^T A, simplified (read from the shipped forms when they hold this A)."""
    return simplified("gram", A, lambda M: (M.T * M).applyfunc(sp.simplify))


def _sym_part(A: sp.Matrix) -> sp.Matrix:
    """(A + A^T) / 2, simplified (read from the shipped forms when they hold this A)."""
    return simplified("sym", A, lambda M: ((M + M.T) / 2).applyfunc(sp.simplify))


def _vertex_cases(A: sp.Matrix, box: dict[sp.Symbol, float]) -> list[tuple[sp.Matrix, str]]:
    """Substitute the vertices of a symmetric box {|x_k| <= box[x_k]} for the symbols A depends on.

    A is linear in these symbols (checked); ||A(-x)|| = ||A(x)||, so vertices
    are taken up to a global sign.
    """
    syms = [x for x in box if x in A.free_symbols]
    if not syms:
        return [(A, "")]
    zero = A.subs({x: 0 for x in syms})
    lin = A - zero
    if zero != sp.zeros(*A.shape) or any(lin.diff(x).diff(y) != sp.zeros(*A.shape) for x in syms for y in syms):
        raise TubekitError("bounds: the vertex rule needs an objective linear and homogeneous in the box variables")
    out = []
    for signs in itertools.product((1, -1), repeat=len(syms) - 1):
        signs = (1,) + signs
        sub = {x: sg * box[x] for x, sg in zip(syms, signs)}
        label = ",".join(f"{x}={'+' if sg > 0 else '-'}" for x, sg in zip(syms, signs))
        out.append((A.subs(sub), label))
    return out


def _velocity_cases(A: sp.Matrix) -> list[tuple[sp.Matrix, str]]:
    """Extreme points of the velocity set: circle of radius h_xy in (a, b), vertices +-p_z in zdot_d."""
    zd = symbols()["zdot_d"]
    has_a, has_b = A_V in A.free_symbols, B_V in A.free_symbols
    if has_a and has_b:
        A = A.subs({A_V: H_XY * sp.cos(GAMMA), B_V: H_XY * sp.sin(GAMMA)})
        box = {zd: P_Z}
    else:
        box = {A_V: H_XY, B_V: H_XY, zd: P_Z}
    if zd in A.free_symbols and (has_a and has_b):
        # circle x {+-p_z}: both signs of zdot_d are needed (the circle is already symmetric)
        return [(A.subs(zd, P_Z), "zdot_d=+"), (A.subs(zd, -P_Z), "zdot_d=-")]
    return _vertex_cases(A, box)


def _matrices(name: str, law: str, s: int) -> list[tuple[sp.Matrix, str]]:
    """(A, label) of every case of bound ``name`` in hemisphere ``s`` (extreme points of its parameters)."""
    pm = polar_model(s)
    hem = "toward" if s < 0 else "away"
    if name == "L1":
        sy = symbols()
        box = {sy["u"]: U_M, sy["w"]: W_M, sy["r"]: R_M}
        return [(A, f"{hem} {lab}".strip()) for A, lab in _vertex_cases(pm.dh_de, box)]
    if name in ("L2", "zeta_theta"):
        M = pm.dzeta_de if name == "L2" else pm.dzeta_dtheta
        return [(A, f"{hem} {lab}".strip()) for A, lab in _velocity_cases(M)]
    if name == "xi_bar":
        return [(pm.dxi_domega, hem)]
    if name in ("J_lower", "JK_norm"):
        return [(law_gain(law, s)[1], hem)]
    if name.startswith("K_row_") and name in OBJECTIVE_NAMES:
        i = "uwr".index(name[-1])
        return [(law_gain(law, s)[0][i, :].T, hem)]
    raise ConfigError("bound", f"one of {OBJECTIVE_NAMES}", name)


def case_matrices(name: str, law: str, s: int) -> list[tuple[str, str, sp.ImmutableMatrix, tuple, tuple]]:
    """(label, kind, A, dimension symbols, parameter symbols) of every case of bound ``name`` in hemisphere ``s``.

    ``kind`` is ``lmin`` for ``J_lower``, else ``norm``; ``law`` matters only for the law's bounds.
    """
    kind = "lmin" if name == "J_lower" else "norm"
    out = []
    for A, label in _matrices(name, law, s):
        A = sp.ImmutableMatrix(A)
        free = A.free_symbols
        dims = tuple(d for d in DIMENSIONS if d in free)
        pars = tuple(sorted((p for p in PARAMETERS.get(name, ()) if p in free), key=str))
        missing = free - set(dims) - set(pars)
        if missing:
            raise TubekitError(f"bounds: unexpected free symbols {sorted(map(str, missing))} in {label}")
        out.append((label, kind, A, dims, pars))
    return out


def arb_entries(kind: str, A: sp.Matrix) -> list[sp.Expr]:
    """The upper triangle (row-major) of AᵀA (``norm``) or (A + Aᵀ)/2 (``lmin``), simplified."""
    G = _gram(A) if kind == "norm" else _sym_part(A)
    m = G.shape[0]
    return [G[i, j] for i in range(m) for j in range(i, m)]


@lru_cache(maxsize=128)
def _compiled(kind: str, A: sp.ImmutableMatrix, dims: tuple, pars: tuple) -> tuple[Callable, Callable]:
    """(Arb evaluator of :func:`arb_entries`, numpy evaluator of A's entries), arguments dims then pars."""
    args = list(dims) + list(pars)
    return compile_arb(arb_entries(kind, A), args), compile_numpy(list(A), args)


def derived_objectives(name: str, law: str, s: int) -> tuple[Objective, ...]:
    """The cases of bound ``name`` in hemisphere ``s`` for ``law``, derived and compiled now."""
    out = []
    for label, kind, A, dims, pars in case_matrices(name, law, s):
        f_arb, f_np = _compiled(kind, A, dims, pars)
        out.append(Objective(label=label, kind=kind, dims=tuple(map(str, dims)), pars=tuple(map(str, pars)),
                             shape=tuple(A.shape), arb=f_arb, numpy=f_np))
    return tuple(out)


@lru_cache(maxsize=8)
def linear_in_speed(name: str, s: int) -> bool:
    """True if the L2 / zeta_theta objective is ||M|| with M linear in (a, b) and free of zdot_d.

    Then its sup over the disc of radius h is h times the sup over the unit disc.
    """
    pm = polar_model(s)
    M = pm.dzeta_de if name == "L2" else pm.dzeta_dtheta
    if symbols()["zdot_d"] in M.free_symbols:
        return False
    zero = M.subs({A_V: 0, B_V: 0})
    second = [M.diff(x).diff(y) for x in (A_V, B_V) for y in (A_V, B_V)]
    return zero == sp.zeros(*M.shape) and all(d == sp.zeros(*M.shape) for d in second)
