"""Entrywise bounds of an ancillary law's gain K(e) and closed-loop gain G = J(e) K(e) over R.

The sampled-data tube (:mod:`verify.theorem.sampled`) needs, over the region R,
sup |K_jl| (the input the law can ask for) and the range of G_jl (how one
zero-order-hold tick moves ρ). J is the derived Jacobian in polar form,
J = [[c, 0, 0], [0, 1, 0], [-e_o c / e_d, 0, c]] with c = s sqrt(1 - e_o²)
(s = -1 toward the target, +1 away; :func:`polar_jacobian`, pinned against
:mod:`tubekit.model.derivation` by the tests). Each entry is a function of (e_d, e_o)
only; its sup is certified by :func:`verify.kernel.intervals.maximise` (Arb
branch-and-bound, budget in boxes). Entries that simplify to a constant are
taken exactly.

The objectives |K_jl|, G_jj, -G_jj and |G_jl| of the built-in laws ship compiled
(:mod:`verify.kernel.compiled`, printed from :func:`gain_objectives`), so a certificate
needs no sympy; any other law is derived and compiled on the spot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from tubekit.model.ancillary import get_law
from tubekit.exceptions import ConfigError

from verify.kernel.compiled import Term, gain_terms
from verify.kernel.intervals import Case, compile_arb, compile_numpy, enclose, maximise, upper
from verify.kernel.parts import flag, matrix, numbers
from verify.kernel.region import Region

if TYPE_CHECKING:  # sympy is imported only to derive a law's objectives (the built-in ones ship compiled)
    import sympy as sp

__all__ = ["GainBounds", "GainProof", "gain_bounds", "gain_entries", "gain_objectives", "polar_jacobian",
           "polar_symbols", "prove_gain_bounds", "GAIN_KEYS"]

#: Relative gap the gain bounds aim for (they enter the tube linearly).
GAIN_GAP = 0.01
#: The objectives bounded per hemisphere: |K_jl| for every entry, G_jj and -G_jj on the diagonal, |G_jl| off it
#: (keyed by kind and row-major index 3 j + l).
GAIN_KEYS: tuple[tuple[str, int], ...] = (
    tuple(("k_abs", i) for i in range(9)) + tuple((kind, 4 * j) for j in range(3) for kind in ("g", "neg_g"))
    + tuple(("g_abs", 3 * j + l) for j in range(3) for l in range(3) if j != l))


@lru_cache(maxsize=1)
def polar_symbols() -> tuple[sp.Symbol, sp.Symbol]:
    """The sympy symbols e_d, e_o (real)."""
    import sympy as sp

    return sp.symbols("e_d e_o", real=True)


def polar_jacobian(sign: int) -> sp.Matrix:
    """J(e_d, e_o) in the hemisphere cos(ψ - θ) = sign · sqrt(1 - e_o²)."""
    import sympy as sp

    ed, eo = polar_symbols()
    c = sign * sp.sqrt(1 - eo ** 2)
    return sp.Matrix([[c, 0, 0], [0, 1, 0], [-eo * c / ed, 0, c]])


@dataclass(frozen=True)
class GainBounds:
    """sup |K_jl|, range of G_jj and sup |G_jl| (l != j) over R (dimensionless, 1/m or m as the entry)."""

    k_abs: tuple[tuple[float, float, float], ...]
    g_lo: tuple[float, float, float]
    g_hi: tuple[float, float, float]
    g_off: tuple[tuple[float, float, float], ...]
    converged: bool

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return {"k_abs": [list(r) for r in self.k_abs], "g_lo": list(self.g_lo), "g_hi": list(self.g_hi),
                "g_off": [list(r) for r in self.g_off], "converged": self.converged}

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.gains") -> "GainBounds":
        """Inverse of :meth:`to_dict`."""
        return cls(k_abs=matrix(d, "k_abs", where), g_lo=numbers(d, "g_lo", where, 3, none=None),
                   g_hi=numbers(d, "g_hi", where, 3, none=None), g_off=matrix(d, "g_off", where),
                   converged=bool(flag(d, "converged", where)))


@lru_cache(maxsize=32)
def gain_entries(law: str, sign: int) -> tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]]:
    """Simplified K and G = J K entries (row-major) of ``law`` in one hemisphere."""
    import sympy as sp

    lw = get_law(law)
    if lw.symbolic_gain is None:
        raise ConfigError("law", "a law with a symbolic gain (symbolic_gain, needed to bound K(e) over R)", law)
    J = polar_jacobian(sign)
    K = sp.Matrix(lw.symbolic_gain(J))
    if K.shape != (3, 3):
        raise ConfigError("law.symbolic_gain", "a 3x3 sympy Matrix", K.shape)
    G = (J * K).applyfunc(sp.cancel)  # cancel, not simplify: the same entries here, 50x faster cold
    return tuple(sp.cancel(k) for k in K), tuple(G)


def gain_objectives(law: str, sign: int) -> dict[tuple[str, int], sp.Expr]:
    """The objectives of :data:`GAIN_KEYS` for ``law`` in hemisphere ``sign``: |K_i|, G_i, -G_i, |G_i| (sympy)."""
    import sympy as sp

    K, G = gain_entries(law, sign)
    out = {}
    for kind, i in GAIN_KEYS:
        if kind == "k_abs":
            out[(kind, i)] = sp.Abs(K[i])
        elif kind == "g":
            out[(kind, i)] = G[i]
        elif kind == "neg_g":
            out[(kind, i)] = -G[i]
        else:
            out[(kind, i)] = sp.Abs(G[i])
    return out


@lru_cache(maxsize=32)
def _derived_terms(law: str, sign: int) -> dict[tuple[str, int], Term]:
    """:func:`gain_objectives` compiled now (a constant taken exactly as a float)."""
    args = list(polar_symbols())
    return {key: Term(constant=float(e)) if not e.free_symbols else
            Term(arb=compile_arb([e], args), numpy=compile_numpy([e], args))
            for key, e in gain_objectives(law, sign).items()}


def _terms(law: str, sign: int) -> dict[tuple[str, int], Term]:
    """The objectives of ``law`` in hemisphere ``sign``: shipped compiled (:mod:`verify.kernel.compiled`) or derived."""
    shipped = gain_terms(law, sign)
    return shipped if shipped is not None else _derived_terms(law, sign)


def _sup(terms: list[Term], region: Region, max_boxes: int) -> tuple[float, bool]:
    """Certified sup of the objectives over the region box, over all (hemisphere) variants given."""
    consts = [t.constant for t in terms if t.constant is not None]
    cases = []
    for i, t in enumerate(x for x in terms if x.constant is None):
        cases.append(Case(label=str(i), names=("e_d", "e_o"), lo=np.array([region.e_d[0], region.e_o[0]]),
                          hi=np.array([region.e_d[1], region.e_o[1]]),
                          interval=lambda b, f=t.arb: f(*b)[0],
                          point=lambda X, f=t.numpy: np.asarray(f(X[:, 0], X[:, 1]), dtype=float).reshape(-1)))
    best = max((float(c) for c in consts), default=-np.inf)
    if not cases:
        return best, True
    res = maximise(cases, gap=GAIN_GAP, max_boxes=max_boxes)
    return max(best, res.bound), res.converged


def gain_bounds(law: str, region: Region, max_boxes: int = 4000) -> GainBounds:
    """Certified entry bounds of K and G = J K for ``law`` over ``region`` (both hemispheres if 'both')."""
    signs = region.hemisphere_signs
    per = [_terms(law, s) for s in signs]
    conv = True
    k_abs, g_off = [[0.0] * 3 for _ in range(3)], [[0.0] * 3 for _ in range(3)]
    g_lo, g_hi = [0.0] * 3, [0.0] * 3
    for j in range(3):
        for l in range(3):
            idx = 3 * j + l
            k_abs[j][l], ok1 = _sup([T[("k_abs", idx)] for T in per], region, max_boxes)
            if j == l:
                g_hi[j], ok2 = _sup([T[("g", idx)] for T in per], region, max_boxes)
                neg, ok3 = _sup([T[("neg_g", idx)] for T in per], region, max_boxes)
                g_lo[j] = -neg
                conv = conv and ok2 and ok3
            else:
                g_off[j][l], ok2 = _sup([T[("g_abs", idx)] for T in per], region, max_boxes)
                conv = conv and ok2
            conv = conv and ok1
    return GainBounds(k_abs=tuple(map(tuple, k_abs)), g_lo=tuple(g_lo), g_hi=tuple(g_hi),
                      g_off=tuple(map(tuple, g_off)), converged=conv)


# --------------------------------------------------------------------------- re-proof of stored bounds
@dataclass(frozen=True)
class GainProof:
    """One stored gain bound re-proved: ``status`` 'proved', 'refuted' (``witness`` > ``stored``) or 'unresolved'."""

    name: str
    stored: float
    status: str
    witness: float
    boxes: int


def _prove_at_most(terms: list[Term], region: Region, limit: float, max_boxes: int) -> tuple[str, float, int]:
    """Prove sup f <= ``limit`` over R for every objective f: Arb on a bisection of the box (the split rule of
    :func:`verify.kernel.intervals.maximise`, so a bound ``gain_bounds`` reached is re-proved within its budget)."""
    lo0, hi0 = np.array([region.e_d[0], region.e_o[0]]), np.array([region.e_d[1], region.e_o[1]])
    scale = np.where(hi0 > lo0, hi0 - lo0, 1.0)
    grid = np.meshgrid(np.linspace(lo0[0], hi0[0], 33), np.linspace(lo0[1], hi0[1], 33))
    worst, boxes = -math.inf, 0
    for t in terms:
        if t.constant is not None:
            worst = max(worst, t.constant)
            continue
        f_arb, f_np = t.arb, t.numpy
        vals = np.asarray(f_np(grid[0], grid[1]), dtype=float)
        worst = max(worst, float(np.nanmax(vals)) if np.any(np.isfinite(vals)) else -math.inf)
        stack = [(lo0.copy(), hi0.copy())]
        while stack and worst <= limit:
            lo, hi = stack.pop()
            boxes += 1
            ub = upper(f_arb(enclose(lo[0], hi[0]), enclose(lo[1], hi[1]))[0])
            if ub <= limit:
                continue
            if boxes >= max_boxes:
                return "unresolved", worst, boxes
            k = int(np.argmax((hi - lo) / scale))
            m = 0.5 * (lo[k] + hi[k])
            h1, l2 = hi.copy(), lo.copy()
            h1[k], l2[k] = m, m
            centre = 0.5 * (lo + hi)
            worst = max(worst, float(np.asarray(f_np(centre[0], centre[1]), dtype=float).reshape(-1)[0]))
            stack += [(l2, hi), (lo, h1)]
    if worst > limit:
        return "refuted", worst, boxes
    return "proved", worst, boxes


def prove_gain_bounds(law: str, region: Region, gains: GainBounds, max_boxes: int = 1500) -> list[GainProof]:
    """Re-prove every stored entry bound of ``gains`` for ``law`` over ``region`` in Arb.

    Each bound b is proved as sup f <= b (for ``g_lo``: sup(-G_jj) <= -b) by bisection with Arb
    enclosures; a sampled value above b refutes it. ``max_boxes`` is the budget per entry (boxes).
    """
    per = [_terms(law, s) for s in region.hemisphere_signs]
    out: list[GainProof] = []
    for j in range(3):
        for l in range(3):
            idx = 3 * j + l
            items = [(f"gains.k_abs[{j}][{l}]", [T[("k_abs", idx)] for T in per], gains.k_abs[j][l], 1.0)]
            if j == l:
                items += [(f"gains.g_hi[{j}]", [T[("g", idx)] for T in per], gains.g_hi[j], 1.0),
                          (f"gains.g_lo[{j}]", [T[("neg_g", idx)] for T in per], -gains.g_lo[j], -1.0)]
            else:
                items.append((f"gains.g_off[{j}][{l}]", [T[("g_abs", idx)] for T in per], gains.g_off[j][l], 1.0))
            for name, exprs, limit, sign in items:
                status, worst, boxes = _prove_at_most(exprs, region, float(limit), max_boxes)
                out.append(GainProof(name, sign * float(limit), status, sign * worst, boxes))
    return out
