"""Entrywise bounds of an ancillary law's gain K(e) and closed-loop gain G = J(e) K(e) over R.

The sampled-data tube (:mod:`verify.sampled`) needs, over the region R,
sup |K_jl| (the input the law can ask for) and the range of G_jl (how one
zero-order-hold tick moves ρ). J is the derived Jacobian in polar form,
J = [[c, 0, 0], [0, 1, 0], [-e_o c / e_d, 0, c]] with c = s sqrt(1 - e_o²)
(s = -1 toward the target, +1 away; :func:`polar_jacobian`, pinned against
:mod:`tubekit.model.derivation` by the tests). Each entry is a function of (e_d, e_o)
only; its sup is certified by :func:`verify.intervals.maximise` (Arb
branch-and-bound, budget in boxes). Entries that simplify to a constant are
taken exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from tubekit.model.ancillary import get_law
from tubekit.exceptions import ConfigError

from verify.intervals import Case, compile_arb, compile_numpy, enclose, maximise, upper
from verify.parts import flag, matrix, numbers
from verify.region import Region

__all__ = ["GainBounds", "GainProof", "gain_bounds", "gain_entries", "polar_jacobian", "prove_gain_bounds"]

_ED, _EO = sp.symbols("e_d e_o", real=True)
#: Relative gap the gain bounds aim for (they enter the tube linearly).
GAIN_GAP = 0.01


def polar_jacobian(sign: int) -> sp.Matrix:
    """J(e_d, e_o) in the hemisphere cos(ψ - θ) = sign · sqrt(1 - e_o²)."""
    c = sign * sp.sqrt(1 - _EO ** 2)
    return sp.Matrix([[c, 0, 0], [0, 1, 0], [-_EO * c / _ED, 0, c]])


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
    lw = get_law(law)
    if lw.symbolic_gain is None:
        raise ConfigError("law", "a law with a symbolic gain (symbolic_gain, needed to bound K(e) over R)", law)
    J = polar_jacobian(sign)
    K = sp.Matrix(lw.symbolic_gain(J))
    if K.shape != (3, 3):
        raise ConfigError("law.symbolic_gain", "a 3x3 sympy Matrix", K.shape)
    G = (J * K).applyfunc(sp.cancel)  # cancel, not simplify: the same entries here, 50x faster cold
    return tuple(sp.cancel(k) for k in K), tuple(G)


def _sup(exprs: list[sp.Expr], region: Region, max_boxes: int) -> tuple[float, bool]:
    """Certified sup of expr over the region box, over all (hemisphere) variants given."""
    consts = [e for e in exprs if not e.free_symbols]
    cases = []
    for i, e in enumerate(x for x in exprs if x.free_symbols):
        f_arb = compile_arb([e], [_ED, _EO])
        f_np = compile_numpy([e], [_ED, _EO])
        cases.append(Case(label=str(i), names=("e_d", "e_o"), lo=np.array([region.e_d[0], region.e_o[0]]),
                          hi=np.array([region.e_d[1], region.e_o[1]]),
                          interval=lambda b, f=f_arb: f(*b)[0],
                          point=lambda X, f=f_np: np.asarray(f(X[:, 0], X[:, 1]), dtype=float).reshape(-1)))
    best = max((float(c) for c in consts), default=-np.inf)
    if not cases:
        return best, True
    res = maximise(cases, gap=GAIN_GAP, max_boxes=max_boxes)
    return max(best, res.bound), res.converged


def gain_bounds(law: str, region: Region, max_boxes: int = 4000) -> GainBounds:
    """Certified entry bounds of K and G = J K for ``law`` over ``region`` (both hemispheres if 'both')."""
    signs = region.hemisphere_signs
    per = [gain_entries(law, s) for s in signs]
    conv = True
    k_abs, g_off = [[0.0] * 3 for _ in range(3)], [[0.0] * 3 for _ in range(3)]
    g_lo, g_hi = [0.0] * 3, [0.0] * 3
    for j in range(3):
        for l in range(3):
            idx = 3 * j + l
            k_abs[j][l], ok1 = _sup([sp.Abs(K[idx]) for K, _ in per], region, max_boxes)
            if j == l:
                g_hi[j], ok2 = _sup([G[idx] for _, G in per], region, max_boxes)
                neg, ok3 = _sup([-G[idx] for _, G in per], region, max_boxes)
                g_lo[j] = -neg
                conv = conv and ok2 and ok3
            else:
                g_off[j][l], ok2 = _sup([sp.Abs(G[idx]) for _, G in per], region, max_boxes)
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


@lru_cache(maxsize=256)
def _compiled(expr: sp.Expr):
    return compile_arb([expr], [_ED, _EO]), compile_numpy([expr], [_ED, _EO])


def _prove_at_most(exprs: list[sp.Expr], region: Region, limit: float, max_boxes: int) -> tuple[str, float, int]:
    """Prove sup expr <= ``limit`` over R for every expr: Arb on a bisection of the box (the split rule of
    :func:`verify.intervals.maximise`, so a bound ``gain_bounds`` reached is re-proved within its budget)."""
    lo0, hi0 = np.array([region.e_d[0], region.e_o[0]]), np.array([region.e_d[1], region.e_o[1]])
    scale = np.where(hi0 > lo0, hi0 - lo0, 1.0)
    grid = np.meshgrid(np.linspace(lo0[0], hi0[0], 33), np.linspace(lo0[1], hi0[1], 33))
    worst, boxes = -math.inf, 0
    for e in exprs:
        if not e.free_symbols:
            worst = max(worst, float(e))
            continue
        f_arb, f_np = _compiled(e)
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
    per = [gain_entries(law, s) for s in region.hemisphere_signs]
    out: list[GainProof] = []
    for j in range(3):
        for l in range(3):
            idx = 3 * j + l
            items = [(f"gains.k_abs[{j}][{l}]", [sp.Abs(K[idx]) for K, _ in per], gains.k_abs[j][l], 1.0)]
            if j == l:
                items += [(f"gains.g_hi[{j}]", [G[idx] for _, G in per], gains.g_hi[j], 1.0),
                          (f"gains.g_lo[{j}]", [-G[idx] for _, G in per], -gains.g_lo[j], -1.0)]
            else:
                items.append((f"gains.g_off[{j}][{l}]", [sp.Abs(G[idx]) for _, G in per], gains.g_off[j][l], 1.0))
            for name, exprs, limit, sign in items:
                status, worst, boxes = _prove_at_most(exprs, region, float(limit), max_boxes)
                out.append(GainProof(name, sign * float(limit), status, sign * worst, boxes))
    return out
