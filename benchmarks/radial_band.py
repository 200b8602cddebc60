"""How narrow a band of distance behind the target any rate-limited controller can hold: the radial subproblem.

A study, not part of the certificate. X_f's row faces (``docs/verify.md`` step 17c) ask the memoryless terminal law
to change its surge by at most the plans' jump J = ρ δ per period; near a pier that is what fails
(``docs/plant.md`` section 4). This script asks what *any* controller could do on the radial part alone, with the
vehicle pointing at the target: per period δ, with x = d − d* (m) and s = u − P (m/s) the commanded closing speed,

    x_{k+1} = x_k − δ s_k + δ w_k,     s_k = s_{k−1} + Δ_k,   |Δ_k| <= J,   |w_k| <= ω̄,   s in [s_lo, s_hi],

the command chosen at each boundary from (x_k, s_{k−1}) within J of the last one, w the disturbance's mean over the
period (the certificate's ω̄ bounds it; it may reverse from one period to the next). The band |x| <= X can be held
for ever iff the largest robust control-invariant set inside it is not empty. That set is the limit of
C_{j+1} = C_j ∩ Pre(C_j), where Pre(C) = T⁻¹(C ⊖ W) ⊕ ({0} × [−J, J]):
- W = δ[−ω̄, ω̄] × {0}, the disturbance, is eroded;
- T(x, s) = (x − δ s, s);
- the vertical segment is the command's freedom.

Every set is a convex polygon (half-planes, scipy's half-space intersection and hull); this is float geometry, a
measurement, not a proof. :func:`smallest_band` bisects X. The continuous-time argument
(``docs/plant.md`` section 4) gives about ω̄²/ρ for the half-width.

Usage: ``python benchmarks/radial_band.py [--omega W] [--rate R] [--dt D] [--speed P] [--u-range LO HI]``
(defaults: ``examples/bluerov2_published_brisk.toml``'s certified ω̄_xy 0.1533 m/s, plans' surge rate 0.05 m/s²,
δ 0.1 s, P 0.2 m/s, u in [0, 0.4] m/s).
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection

__all__ = ["Polygon", "invariant_set", "smallest_band", "main"]

#: Polygons whose largest inscribed disc is below this (m or m/s) count as empty.
EMPTY = 1e-9
#: The iteration stops when no half-plane's offset moves by more than this.
SETTLED = 1e-10


class Polygon:
    """A convex polygon {z : A z <= b} in the (x, s) plane, kept irredundant (its hull's facets)."""

    def __init__(self, a: np.ndarray, b: np.ndarray) -> None:
        self.a, self.b = np.asarray(a, float), np.asarray(b, float)

    def vertices(self) -> np.ndarray | None:
        """The corners, or None when the polygon is empty (or thinner than :data:`EMPTY`)."""
        norms = np.linalg.norm(self.a, axis=1)
        cheb = linprog([0.0, 0.0, -1.0], A_ub=np.hstack([self.a, norms[:, None]]), b_ub=self.b,
                       bounds=[(None, None), (None, None), (0.0, None)], method="highs")
        if cheb.status != 0 or cheb.x[2] <= EMPTY:
            return None
        points = HalfspaceIntersection(np.hstack([self.a, -self.b[:, None]]), cheb.x[:2]).intersections
        return points[ConvexHull(points).vertices]

    @classmethod
    def hull(cls, points: np.ndarray) -> "Polygon":
        """The convex hull of ``points`` as half-planes (scipy's facet equations n z + c <= 0)."""
        eq = ConvexHull(points).equations
        return cls(eq[:, :2], -eq[:, 2])

    def intersect(self, other: "Polygon") -> "Polygon | None":
        """Both sets of half-planes, made irredundant through the corners; None when empty."""
        both = Polygon(np.vstack([self.a, other.a]), np.concatenate([self.b, other.b]))
        corners = both.vertices()
        return None if corners is None else Polygon.hull(corners)


def _pre(c: Polygon, dt: float, jump: float, omega: float) -> Polygon | None:
    """Pre(C) of the module doc."""
    eroded = c.b - np.abs(c.a[:, 0]) * dt * omega
    shear = np.array([[1.0, -dt], [0.0, 1.0]])  # T
    corners = Polygon(c.a @ shear, eroded).vertices()
    if corners is None:
        return None
    step = np.array([0.0, jump])
    return Polygon.hull(np.vstack([corners + step, corners - step]))


def invariant_set(band: float, s_range: tuple[float, float], dt: float, jump: float, omega: float,
                  max_rounds: int = 5000) -> Polygon | None:
    """The largest robust control-invariant set in |x| <= ``band`` (m), s in ``s_range`` (m/s); None when empty."""
    c = Polygon(np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]),
                np.array([band, band, s_range[1], -s_range[0]]))
    for _ in range(max_rounds):
        pre = _pre(c, dt, jump, omega)
        nxt = None if pre is None else c.intersect(pre)
        if nxt is None:
            return None
        if len(nxt.b) == len(c.b) and np.max(np.abs(_sorted(nxt) - _sorted(c))) < SETTLED:
            return nxt
        c = nxt
    raise RuntimeError(f"invariant_set: not settled after {max_rounds} rounds")


def _sorted(p: Polygon) -> np.ndarray:
    """The half-planes (unit normal, offset) in angle order, for comparing two polygons."""
    norms = np.linalg.norm(p.a, axis=1)
    rows = np.hstack([p.a / norms[:, None], (p.b / norms)[:, None]])
    return rows[np.argsort(np.arctan2(rows[:, 1], rows[:, 0]))]


def smallest_band(s_range: tuple[float, float], dt: float, jump: float, omega: float,
                  tolerance: float = 1e-3) -> float:
    """The smallest half-width X (m), to ``tolerance``, whose band holds a non-empty invariant set (bisection on
    X; a wider band holds whatever a narrower one does)."""
    lo, hi = 0.0, 1.0
    while invariant_set(hi, s_range, dt, jump, omega) is None:
        lo, hi = hi, 2.0 * hi
        if hi > 1e4:
            return math.inf
    while hi - lo > tolerance:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if invariant_set(mid, s_range, dt, jump, omega) is not None else (mid, hi)
    return hi


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--omega", type=float, default=0.1533, help="the disturbance bound ω̄ (m/s)")
    parser.add_argument("--rate", type=float, nargs="+", default=[0.05], help="plans' surge rates ρ (m/s²)")
    parser.add_argument("--dt", type=float, default=0.1, help="the period δ (s)")
    parser.add_argument("--speed", type=float, default=0.2, help="the target's speed P (m/s)")
    parser.add_argument("--u-range", type=float, nargs=2, default=[0.0, 0.4], help="the surge command's range")
    args = parser.parse_args(argv)
    values = [args.omega, args.dt, args.speed, *args.rate, *args.u_range]
    if not all(math.isfinite(x) for x in values) or min(args.omega, args.dt, *args.rate) <= 0:
        parser.error("omega, dt and the rates must be finite and > 0")
    if not args.u_range[0] < args.speed < args.u_range[1]:
        parser.error("--u-range must contain --speed")
    s_range = (args.u_range[0] - args.speed, args.u_range[1] - args.speed)
    print(f"omega {args.omega:g} m/s, dt {args.dt:g} s, P {args.speed:g} m/s, u in {args.u_range}")
    print("| rho (m/s²) | J (m/s) | smallest half-width X (m) | omega²/rho (m) |")
    print("|---|---|---|---|")
    for rho in args.rate:
        x = smallest_band(s_range, args.dt, rho * args.dt, args.omega)
        print(f"| {rho:g} | {rho * args.dt:g} | {x:.3f} | {args.omega ** 2 / rho:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
