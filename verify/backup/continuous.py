"""The continuous yaw law's level-set proof, in Arb (issue 22).

The law (:class:`tubekit.model.backup.StationKeeping` with ``yaw_law="continuous"``) turns with
r = −k ρ(φ) G, ρ π-periodic, Lipschitz 1/χ_0, with a stable zero at χ = 0 and an unstable zero at
χ_u ∈ (0, χ_c), χ_c = acos √(ω̄_xy/u_b): inside the cone |χ| < χ_c surge alone closes in. Since ρ has the
same sign on both sides of abeam, the command is continuous: no ridge.

Lift the axis angle to x ∈ [0, π] (x = φ mod π; x and x − π are the same axis). Held over a tick,
φ' = φ + δ with |δ| <= Δ, and every product of two π-antiperiodic functions of φ, φ' is π-periodic, so

    ḋ = −u_b cos x' cos x + ω_r,   ẋ = −k ρ(x') + ε_r + (u_b cos x' sin x − ω_t) / d,   x' ∈ [x − Δ, x + Δ]

(fades and ramp are 1 at the tick starts that matter: ``backup_fade``, ``backup_ramp``). With
V = d + β a(x), a of :func:`tubekit.model.backup.axis_shape` (0 at x = 0 and π, 1 on [χ_p, χ_u], a' of
the sign of ρ or 0), the supremum over ‖ω_xy‖ <= ω̄_xy and |ε_r| <= E_r of V̇ on V = c is

    −u_b cos x' cos x + ω̄_xy √(1 + (β a'/d)²) + β a' (−k ρ(x') + u_b cos x' sin x / d) + β |a'| E_r,

with d = c − β a(x) on the level set. :func:`continuous_rate_bound` bounds it over x ∈ [0, π] (the whole
circle: no mirror symmetry) by Arb bisection. On the plateau [χ_p, χ_u] (a' = 0), near χ_u and near 0,
V̇ is ḋ < 0 because cos² χ_u > ω̄_xy/u_b (``backup_unstable``); elsewhere β a' ẋ < 0 dominates. The
ridge condition of the ridge law disappears.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from flint import arb, ctx

from tubekit.model.backup import SafeSet, StationKeeping
from verify.theorem.design import Condition
from verify.kernel.intervals import bisect_sup, enclose, lower, upper

__all__ = ["continuous_rate_bound", "continuous_rate_sampled", "continuous_rate_sampled_shapes",
           "continuous_held_rate_sampled", "continuous_best_shape", "COARSE_STRIDE", "unstable_condition",
           "cone_angle", "shape_enclosure", "yaw_shape_enclosure"]

_PI_UP = math.nextafter(math.pi, math.inf)


def cone_angle(surge: float, omega_xy: float) -> float:
    """χ_c = acos √(ω̄_xy/u_b) (rad), a float <= the true value: inside |χ| < χ_c surge alone closes in."""
    if omega_xy >= surge:
        return 0.0
    return max(0.0, lower((arb(omega_xy) / arb(surge)).sqrt().acos()))


def unstable_condition(law: StationKeeping, omega_xy: float) -> Condition:
    """``backup_unstable``: u_b cos² χ_u > ω̄_xy (0 < χ_u < χ_c), so the radial speed is negative at χ_u."""
    closing = lower(arb(law.surge) * arb(law.unstable).cos() ** 2)
    return Condition("backup_unstable", "ω̄_xy < u_b cos² χ_u (0 < χ_u < χ_c)", omega_xy, closing,
                     omega_xy < closing, f"χ_u {law.unstable:.4g} rad, χ_c {cone_angle(law.surge, omega_xy):.4g} rad")


@functools.lru_cache(maxsize=64)
def _arc_ends(unstable: float, prec: int) -> tuple[tuple[int, int, float, float], ...]:
    """(shift, arc, lo, hi) of the arcs [0, χ_u] + kπ, [χ_u, π] + kπ, k = −1, 0, 1 (rad, rounded outward):
    fixed by the law, so computed once per χ_u and working precision, not once per bisection interval."""
    pi, cut = arb.pi(), arb(unstable)
    return tuple((shift, arc, lower(start + shift * pi), upper(stop + shift * pi))
                 for shift in (-1, 0, 1) for arc, start, stop in ((0, arb(0), cut), (1, cut, pi)))


def _pieces(lo: float, hi: float, cut: arb) -> list[tuple[arb, int]]:
    """Split [lo, hi] ⊂ [−π, 2π] (rad) into balls on one arc each, shifted by a multiple of π into [0, π]:
    (ball, arc), arc 0 = [0, χ_u] (ρ >= 0), arc 1 = [χ_u, π] (ρ <= 0). ``cut`` = arb(χ_u), an exact float."""
    pi = arb.pi()
    out = []
    for shift, arc, start, stop in _arc_ends(float(cut), ctx.prec):
        a, b = max(lo, start), min(hi, stop)
        if a <= b:
            out.append((enclose(a, b) - shift * pi, arc))
    return out


def _arc_clip(x: arb, arc: int, cut: arb) -> arb:
    """``x`` intersected with its arc (the shift by π may push it out by a rounding)."""
    lo, hi = (arb(0), cut) if arc == 0 else (cut, arb.pi())
    return enclose(max(lower(x), lower(lo)), max(min(upper(x), upper(hi)), max(lower(x), lower(lo))))


def yaw_shape_enclosure(law: StationKeeping, lo: float, hi: float) -> arb:
    """An arb containing ρ(x) for every x ∈ [lo, hi] (rad, lifted axis angle; any real interval in [−π, 2π])."""
    band, cut = arb(law.yaw_band), arb(law.unstable)
    low, high = math.inf, -math.inf
    for x, arc in _pieces(lo, hi, cut):
        x = _arc_clip(x, arc, cut)
        ends = (x / band, (cut - x) / band) if arc == 0 else ((x - cut) / band, (arb.pi() - x) / band)
        small = min(1.0, lower(ends[0]), lower(ends[1]))  # min of increasing / decreasing pieces
        large = min(1.0, upper(ends[0]), upper(ends[1]))
        small, large = max(small, 0.0), max(large, 0.0)
        if arc == 1:
            small, large = -large, -small
        low, high = min(low, small), max(high, large)
    return enclose(low, high)


def shape_enclosure(law: StationKeeping, lo: float, hi: float) -> tuple[arb, arb]:
    """Arbs containing a(x) and a'(x) for every x ∈ [lo, hi] ⊂ [−π, 2π] (the lifted axis angle, rad)."""
    cut, pi, top = arb(law.unstable), arb.pi(), law.plateau
    parts = []
    for x, arc in _pieces(lo, hi, cut):
        x = _arc_clip(x, arc, cut)
        if arc == 1:
            scale = pi / (pi - cut)
            arg = scale * (pi - x)
            parts.append(((1 - arg.cos()) / 2, -scale / 2 * arg.sin()))
            continue
        low, high = lower(x), upper(x)  # a = (1 − cos(π min(x, χ_p)/χ_p))/2 on [0, χ_u]
        scale = pi / arb(top)
        arg = scale * enclose(min(low, top), min(high, top))
        slope = scale / 2 * arg.sin() if low < top else arb(0)
        if high >= top:
            slope = enclose(min(0.0, lower(slope)), max(0.0, upper(slope)))
        parts.append(((1 - arg.cos()) / 2, slope))
    a = enclose(min(lower(p[0]) for p in parts), max(upper(p[0]) for p in parts))
    da = enclose(min(lower(p[1]) for p in parts), max(upper(p[1]) for p in parts))
    return enclose(max(0.0, lower(a)), min(1.0, upper(a))), da


def _rate_upper(law: StationKeeping, safe: SafeSet, omega_xy: float, delta: float, a: float, b: float,
                yaw_err: float) -> float:
    """An upper bound (m/s) of V̇ over x ∈ [a, b] on the level set, every held x' within Δ and every ω."""
    x = enclose(a, b)
    beta, ub = arb(safe.shape), arb(law.surge)
    shape, slope = shape_enclosure(law, a, b)
    d = arb(safe.level) - beta * shape
    g = beta * slope
    held = enclose(a - delta, b + delta)
    held_cos = held.cos()
    rho = yaw_shape_enclosure(law, a - delta, b + delta)
    rate = (-ub * held_cos * x.cos() + arb(omega_xy) * (1 + (g / d) ** 2).sqrt()
            + g * (-arb(law.yaw_rate) * rho + ub * held_cos * x.sin() / d) + abs(g) * arb(yaw_err))
    return upper(rate)


def continuous_rate_bound(law: StationKeeping, safe: SafeSet, omega_xy: float, delta: float, max_boxes: int,
                          yaw_rate_error: float = 0.0) -> tuple[float, int]:
    """(bound, intervals): an upper bound (m/s) of V̇ on V = c over the lifted circle x ∈ [0, π], by bisection.

    ``delta`` is the tick drift Δ (rad) of the axis angle; an interval is split until its bound is
    negative or the budget ``max_boxes`` is spent (then the bound returned is the largest in the cover).
    """
    return bisect_sup(lambda a, b: _rate_upper(law, safe, omega_xy, delta, a, b, yaw_rate_error),
                      0.0, _PI_UP, max_boxes)


def _profiles(law: StationKeeping, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(a, a', ρ) at lifted angles ``x`` ∈ [0, π] (rad), in floats (the design's filter)."""
    cut, band, top = law.unstable, law.yaw_band, law.plateau
    first = x <= cut
    s0, s1 = math.pi / top, math.pi / (math.pi - cut)
    arg = np.where(first, s0 * np.minimum(x, top), s1 * (math.pi - x))
    slope = np.where(first, 0.5 * s0 * np.sin(arg), -0.5 * s1 * np.sin(arg))
    rho = np.where(first, np.minimum(1.0, np.minimum(x, cut - x) / band),
                   -np.minimum(1.0, np.minimum(x - cut, math.pi - x) / band))
    return 0.5 * (1.0 - np.cos(arg)), slope, rho


def _sampled_terms(law: StationKeeping, n: int) -> tuple[np.ndarray, ...]:
    """(a, a', −u_b cos²x, −k ρ, u_b cos x sin x) at the n sampled x ∈ [0, π] (the design's filter)."""
    x = np.linspace(0.0, math.pi, n)
    a, slope, rho = _profiles(law, x)
    cos = np.cos(x)
    return a, slope, -law.surge * cos ** 2, -law.yaw_rate * rho, law.surge * cos * np.sin(x)


def _rates_at(terms: tuple[np.ndarray, ...], level: float, shapes: np.ndarray, omega_xy: float,
              yaw_err: float) -> np.ndarray:
    """V̇ (m/s) of :func:`continuous_rate_sampled_shapes` for every shape (rows) and sample of ``terms`` (columns)."""
    a, slope, radial, turn, along = terms
    beta = np.asarray(shapes, dtype=float)[:, None]
    d = level - beta * a                       # (shapes, n)
    g = beta * slope
    ratio = g / d
    rate = along / d
    rate += turn
    rate *= g
    np.abs(g, out=g)
    g *= yaw_err
    rate += g
    np.multiply(ratio, ratio, out=ratio)
    ratio += 1.0
    np.sqrt(ratio, out=ratio)
    ratio *= omega_xy
    rate += ratio
    rate += radial
    return rate


def continuous_rate_sampled_shapes(law: StationKeeping, level: float, shapes: np.ndarray, omega_xy: float,
                                   n: int = 1441, yaw_err: float = 0.0) -> np.ndarray:
    """The largest V̇ (m/s) at sampled x ∈ [0, π] with the input of the same instant (no hold) and the worst ω, for
    every shape β of ``shapes`` at the level ``level`` (m), at once (the design's filter):
    −u_b cos²x + ω̄_xy √(1 + (g/d)²) + g (−k ρ + u_b cos x sin x / d) + |g| E_r, d = c − β a, g = β a'."""
    return _rates_at(_sampled_terms(law, n), level, shapes, omega_xy, yaw_err).max(axis=1)


#: Every COARSE_STRIDE-th sample is evaluated for every shape first (:func:`continuous_best_shape`).
COARSE_STRIDE = 16


def continuous_best_shape(law: StationKeeping, level: float, shapes: np.ndarray, omega_xy: float,
                          n: int = 1441, yaw_err: float = 0.0) -> tuple[int, float]:
    """(i, m): the first index of the smallest value m of :func:`continuous_rate_sampled_shapes`, the same
    numbers, with the full grid evaluated only for the shapes that can attain it.

    The maximum over every :data:`COARSE_STRIDE`-th sample is a lower bound of the maximum over all of them
    (the same floats: the terms are computed once and indexed). The shape with the smallest coarse value gives
    an attained maximum M; a shape whose coarse value exceeds M cannot attain the minimum, so only the shapes
    with coarse value <= M are evaluated on every sample.
    """
    terms = _sampled_terms(law, n)
    shapes = np.asarray(shapes, dtype=float)
    coarse = _rates_at(tuple(t[::COARSE_STRIDE] for t in terms), level, shapes, omega_xy, yaw_err).max(axis=1)
    first = int(np.argmin(coarse))
    bound = float(_rates_at(terms, level, shapes[first:first + 1], omega_xy, yaw_err).max())
    keep = np.flatnonzero(coarse <= bound)
    full = _rates_at(terms, level, shapes[keep], omega_xy, yaw_err).max(axis=1)
    j = int(np.argmin(full))
    return int(keep[j]), float(full[j])


def continuous_rate_sampled(law: StationKeeping, safe: SafeSet, omega_xy: float, n: int = 1441,
                            yaw_err: float = 0.0) -> float:
    """:func:`continuous_rate_sampled_shapes` (m/s) for the shape of ``safe``."""
    return float(continuous_rate_sampled_shapes(law, safe.level, np.array([safe.shape]), omega_xy, n, yaw_err)[0])


def continuous_held_rate_sampled(law: StationKeeping, safe: SafeSet, omega_xy: float, delta: float, n: int = 1441,
                                 yaw_err: float = 0.0) -> float:
    """The largest V̇ (m/s) at sampled x ∈ [0, π] (where d > 0) with the input held from x' = x − Δ or x + Δ and the
    worst ω: −u_b cos x' cos x + ω̄_xy √(1 + (g/d)²) + g (−k ρ(x') + u_b cos x' sin x / d) + |g| E_r.

    Each is a value of the expression :func:`_rate_upper` encloses on every interval [a, b] holding x (its held
    angles [a − Δ, b + Δ] hold x', ρ π-periodic), so the bisection's bound is at least each of them: a positive
    one means :func:`continuous_rate_bound` cannot be negative (the search's refutation, before the bisection)."""
    x = np.linspace(0.0, math.pi, n)
    a, slope, _ = _profiles(law, x)
    d = safe.level - safe.shape * a
    g = safe.shape * slope
    inside = d > 0.0
    x, d, g = x[inside], d[inside], g[inside]
    base = omega_xy * np.sqrt(1.0 + (g / d) ** 2) + np.abs(g) * yaw_err
    best = -math.inf
    for held in (x - delta, x + delta):
        _, _, rho = _profiles(law, np.mod(held, math.pi))
        surge = law.surge * np.cos(held)
        rate = base - surge * np.cos(x) + g * (-law.yaw_rate * rho + surge * np.sin(x) / d)
        best = max(best, float(rate.max(initial=-math.inf)))
    return best
