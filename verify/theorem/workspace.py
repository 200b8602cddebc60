"""Designs empty by construction: a start ball or a target path outside the workspace (conditions with numbers).

Two conditions of the tracking tier (``docs/verify.md``, section 3):

* ``initial_workspace`` (:func:`initial_workspace`) — the vehicle ball at the initial position,
  inflated by the first arc's position margin, lies inside the workspace box;
* ``target_in_workspace`` (:func:`target_in_workspace`) — the target position p_d(t) stays in the
  workspace box for every t ∈ [0, duration]. Circle, helix and line are evaluated analytically (the
  extremes of a sine over an angle interval, of a linear function at the ends); any other trajectory
  on a dense sample of n points with the Lipschitz bound |p_j(t) − p_j(t_i)| <= v̄_j h / 2 between
  samples (v̄ = ``velocity_bound()``, h the spacing).

Each lhs is the largest excursion (m) beyond the box (<= 0 inside); rhs is 0.
"""

from __future__ import annotations

import math

import numpy as np
from flint import arb

from tubekit.model.trajectory import Circle, Helix, Line
from tubekit.scenario import Scenario

from verify.theorem.design import Condition
from verify.kernel.intervals import lower, upper

__all__ = ["initial_workspace", "target_in_workspace", "target_range", "TARGET_SAMPLES"]

#: Sample count of the Lipschitz route (trajectories with no analytic range).
TARGET_SAMPLES = 20001


def _sin_range(a0: float, a1: float) -> tuple[float, float]:
    """(lo, hi) enclosing sin over the angle interval [a0, a1] (rad), outward rounded."""
    def hits(centre: float) -> bool:  # does [a0, a1] (widened) contain centre + 2πk for some k?
        lo_k = math.ceil((a0 - centre) / (2 * math.pi) - 1e-9)
        return lo_k <= math.floor((a1 - centre) / (2 * math.pi) + 1e-9)
    ends = [arb(a0).sin(), arb(a1).sin()]
    hi = 1.0 if hits(math.pi / 2) else max(upper(e) for e in ends)
    lo = -1.0 if hits(-math.pi / 2) else min(lower(e) for e in ends)
    return lo, hi


def target_range(scenario: Scenario) -> tuple[np.ndarray, np.ndarray, str]:
    """(lower, upper) (3,) enclosing p_d(t) over [0, duration] (m), and how they were obtained."""
    tr, T = scenario.trajectory, float(scenario.duration)
    if isinstance(tr, Circle):
        a0, a1 = sorted((tr.phase, tr.phase + tr.rate * T))
        sx, cx = _sin_range(a0, a1), _sin_range(a0 + math.pi / 2, a1 + math.pi / 2)
        c, r = tr.center, tr.radius
        lo = [lower(arb(c[0]) + arb(r) * arb(sx[0])), lower(arb(c[1]) + arb(r) * arb(cx[0])), c[2]]
        hi = [upper(arb(c[0]) + arb(r) * arb(sx[1])), upper(arb(c[1]) + arb(r) * arb(cx[1])), c[2]]
        how = "analytic (circle)"
        if isinstance(tr, Helix):
            zs = (arb(c[2]), arb(c[2]) + arb(tr.climb) * arb(T))
            lo[2], hi[2] = min(lower(z) for z in zs), max(upper(z) for z in zs)
            how = "analytic (helix)"
        return np.array(lo), np.array(hi), how
    if isinstance(tr, Line):
        ends = [[arb(s) + arb(v) * arb(t) for s, v in zip(tr.start, tr.direction_velocity)] for t in (0.0, T)]
        lo = np.array([min(lower(e[j]) for e in ends) for j in range(3)])
        hi = np.array([max(upper(e[j]) for e in ends) for j in range(3)])
        return lo, hi, "analytic (line)"
    t = np.linspace(0.0, T, TARGET_SAMPLES)
    p = np.asarray(tr.position(t), dtype=float)
    slack = np.asarray(tr.velocity_bound(), dtype=float) * (T / (TARGET_SAMPLES - 1)) / 2 * (1 + 1e-9)
    return (p.min(axis=0) - slack, p.max(axis=0) + slack,
            f"sampled at {TARGET_SAMPLES} points + Lipschitz bound v_bar h / 2 (v_bar = velocity_bound())")


def _excursion(lo: np.ndarray, hi: np.ndarray, box: tuple) -> float:
    """Largest distance (m) by which [lo, hi] sticks out of the box (<= 0 inside)."""
    blo, bhi = np.asarray(box[0], dtype=float), np.asarray(box[1], dtype=float)
    return float(max(np.max(blo - lo), np.max(hi - bhi)))


def target_in_workspace(scenario: Scenario) -> Condition:
    """``target_in_workspace``: p_d(t) in the workspace box for t ∈ [0, duration] (module doc)."""
    name = "target_in_workspace"
    ineq = "max over t in [0, duration] of the target's excursion beyond the workspace <= 0"
    if scenario.workspace is None:
        return Condition(name, ineq, None, 0.0, True, "no workspace")
    lo, hi, how = target_range(scenario)
    out = _excursion(lo, hi, scenario.workspace)
    return Condition(name, ineq, out, 0.0, out <= 0.0,
                     f"target range [{', '.join(f'{x:.4g}' for x in lo)}] .. [{', '.join(f'{x:.4g}' for x in hi)}] "
                     f"m over {scenario.duration:g} s, {how}; tracking is impossible once the target leaves")


def initial_workspace(scenario: Scenario, margin: float) -> Condition:
    """``initial_workspace``: the start ball (vehicle radius + ``margin`` m) inside the workspace box."""
    name, ineq = "initial_workspace", "start ball (r_bar + M_pos,0) beyond the workspace by <= 0"
    if scenario.workspace is None:
        return Condition(name, ineq, None, 0.0, True, "no workspace")
    p0 = np.asarray(scenario.initial_state[:3], dtype=float)
    r = upper(arb(scenario.vehicle_radius) + arb(margin))
    out = _excursion(p0 - r, p0 + r, scenario.workspace)
    return Condition(name, ineq, out, 0.0, out <= 0.0,
                     f"start [{', '.join(f'{x:.4g}' for x in p0)}] m, ball radius {r:.4g} m")
