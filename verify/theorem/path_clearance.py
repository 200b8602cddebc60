"""The obstacle and workspace part of the tracking theorem: a condition on the target's path.

A completion arc of the candidate (``verify.theorem.terminal``) keeps the vehicle within ``reach`` (m)
horizontally and ``rise`` (m) vertically of the target p_d(t), and ends, in X_f, within d_hi and z_f of it. So

* its vehicle ball (r̄ + M_pos,N−1 + the check's pad) misses obstacle o when the cylinder of radius
  ``reach`` and half-height ``rise`` about p_d(t) lies farther than r_o + r̄ + M_pos,N−1 + pad from o's centre;
* the backup's footprint (R_f, H_f) about the completion's end (the terminal condition, step 11 (a)) misses o
  when the cylinder (R_f + d_hi, H_f + z_f) about p_d(t) lies farther than r_o from o's centre.

With X_f's bearing face (step 17b: the completion starts with its bearing within Φ_0 = φ_f + asin(D_xy / d_lo) of
behind the target and ends within φ_f), the vehicle lies, at the completion's start and end, in the sector of
half-angle Φ_0 behind the target's horizontal velocity and radius d_hi + D_xy (start) or d_hi (end), and in
between within the half-run (ū + P) δ / 2 of one of them, so each cylinder's horizontal disc is narrowed to that
sector, inflated by the same pads (:func:`_sector_distance`). The sector turns with the target's velocity, at most
A / P_min rad/s, which adds (radius) (A / P_min) h / 2 to the allowance.

:func:`path_clearance` checks both for every t ∈ [0, T_end] on a dense sample of :data:`PATH_SAMPLES` points:
each distance is 1-Lipschitz in p_d, so between samples it changes by at most v̄ h / 2 (v̄ the target's speed
bound, h the spacing), which is subtracted (with a relative 1e-9 for the float evaluation). Its lhs is the
smallest clearance (m) left beyond what is needed; ``detail`` gives the time and the path's distance from
the obstacle's centre, and, when a failing clearance is a depth face's (the obstacle within the footprint's horizontal
extent, where the signed distance is the nearer face's), the largest horizontal overlap along the path.
:func:`path_workspace` does the same for the workspace walls.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tubekit.scenario import Scenario

from verify.theorem.design import Condition

__all__ = ["PathFootprint", "contains", "PathSamples", "path_samples", "path_clearance", "path_workspace", "horizon_end",
           "PATH_SAMPLES"]

#: Sample count of the target's path over [0, T_end].
PATH_SAMPLES = 20001


@dataclass(frozen=True)
class PathFootprint:
    """What must clear the obstacles about the target (m): the completion arc's cylinder (``reach``, ``rise``)
    carrying a ball of ``ball``, and the backup footprint's cylinder (``outer``, ``outer_height``) about it.

    With a bearing face (``cone`` < π, rad: the completion keeps the vehicle's bearing from behind the target within
    it, step 17b) each cylinder is narrowed to the sector of half-angle ``cone`` behind the target's horizontal
    velocity, of radius ``cone_reach`` (arc) or ``cone_outer`` (end), inflated by the rest of ``reach`` or ``outer``;
    ``turn_rate`` (rad/s) bounds how fast the target's velocity turns (the sector's Lipschitz allowance)."""

    reach: float
    rise: float
    ball: float
    outer: float
    outer_height: float
    cone: float = math.pi
    cone_reach: float = 0.0
    cone_outer: float = 0.0
    turn_rate: float = 0.0


def contains(big: PathFootprint, small: PathFootprint) -> bool:
    """True when ``big`` holds ``small`` about every point of the path: every extent at least as large (the
    sector's half-angle and radii included, π standing for the disc) and the same turn allowance or more. Then
    every clearance of :func:`path_clearance` is no larger for ``big`` (a search shortcut of
    :func:`verify.theorem.terminal.design_terminal`, never a proof step)."""
    sizes = [(big.rise, small.rise), (big.ball, small.ball), (big.outer_height, small.outer_height),
             (big.cone, small.cone), (big.turn_rate, small.turn_rate)]
    for which in ("reach", "outer"):  # the sector's radius and the pad about it, each no smaller
        sizes += [(_sector_radius(big, which), _sector_radius(small, which)),
                  (getattr(big, which) - _sector_radius(big, which), getattr(small, which) - _sector_radius(small, which))]
    return all(a >= b for a, b in sizes)


def _sector_radius(foot: PathFootprint, which: str) -> float:
    """The sector's radius of the arc (``reach``) or the end (``outer``): the whole extent for the disc."""
    if foot.cone >= math.pi:
        return foot.reach if which == "reach" else foot.outer
    return foot.cone_reach if which == "reach" else foot.cone_outer


@dataclass(frozen=True)
class PathSamples:
    """The target's path over [0, t_end] (s): ``times`` (n,), ``positions`` (n, 3) (m), the Lipschitz
    ``allowance`` v̄ h / 2 (m) between samples and ``backward`` (n, 2), the unit horizontal direction opposite the
    target's velocity (None where it may stop); built once (:func:`path_samples`) for every set tried."""

    times: np.ndarray
    positions: np.ndarray
    allowance: float
    backward: np.ndarray | None = None


def path_samples(scenario: Scenario, t_end: float) -> PathSamples:
    """:data:`PATH_SAMPLES` samples of the target's path over [0, ``t_end``] (s)."""
    t = np.linspace(0.0, t_end, PATH_SAMPLES)
    p = np.asarray(scenario.trajectory.position(t), dtype=float)
    speed = float(np.linalg.norm(np.asarray(scenario.trajectory.velocity_bound(), dtype=float)))
    vel = np.asarray(scenario.trajectory.velocity(t), dtype=float)[:, :2]
    norm = np.linalg.norm(vel, axis=1)
    backward = -vel / norm[:, None] if np.all(norm > 0.0) else None
    return PathSamples(t, p, speed * (t_end / (PATH_SAMPLES - 1)) / 2.0, backward)


def _samples(scenario: Scenario, path: PathSamples | float) -> PathSamples:
    """``path``, or the samples up to the end time ``path`` (s)."""
    return path if isinstance(path, PathSamples) else path_samples(scenario, float(path))


def _cylinder_distance(centre: np.ndarray, p: np.ndarray, radius: float, half: float) -> np.ndarray:
    """Signed distance (m) from ``centre`` (3,) to the cylinders (``radius``, ``half``) about each row of ``p``
    (n, 3): the distance when outside, minus the depth of penetration (the nearer face) when inside; 1-Lipschitz
    in each row of ``p``."""
    h = np.hypot(p[:, 0] - centre[0], p[:, 1] - centre[1]) - radius
    v = np.abs(p[:, 2] - centre[2]) - half
    outside = np.hypot(np.maximum(0.0, h), np.maximum(0.0, v))
    return np.where((h <= 0.0) & (v <= 0.0), np.maximum(h, v), outside)


def _sector_distance(centre: np.ndarray, p: np.ndarray, back: np.ndarray, cone: float, radius: float,
                     half: float) -> np.ndarray:
    """Signed distance (m) from ``centre`` (3,) to the sectors of half-angle ``cone`` (rad, <= π) and ``radius``
    about each row of ``p`` (n, 3) around the horizontal unit directions ``back`` (n, 2), extruded to half-height
    ``half``: outside the angular range the nearer edge segment, inside it beyond the radius |w| − radius, and within
    the sector minus the distance to its nearest side (the arc or an edge; the arc alone for the disc, ``cone`` π)."""
    w = centre[:2][None, :] - p[:, :2]
    dist = np.hypot(w[:, 0], w[:, 1])
    cos_in = np.einsum("ij,ij->i", w, back)
    inside = cos_in >= dist * math.cos(cone)
    edges = []
    for sign in (1.0, -1.0):
        c, s = math.cos(sign * cone), math.sin(sign * cone)
        e = np.stack([c * back[:, 0] - s * back[:, 1], s * back[:, 0] + c * back[:, 1]], axis=1)
        along = np.clip(np.einsum("ij,ij->i", w, e), 0.0, radius)
        edges.append(np.hypot(w[:, 0] - along * e[:, 0], w[:, 1] - along * e[:, 1]))
    beside = np.minimum(*edges)
    within = dist - radius if cone >= math.pi else np.maximum(dist - radius, -beside)  # -(nearest side) inside
    h = np.where(inside, within, beside)
    v = np.abs(p[:, 2] - centre[2]) - half
    outside = np.hypot(np.maximum(0.0, h), np.maximum(0.0, v))
    return np.where((h <= 0.0) & (v <= 0.0), np.maximum(h, v), outside)


def _sectors(foot: PathFootprint, c: np.ndarray, radius: float, p: np.ndarray, back: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """(arc, end): the clearances of :class:`PathFootprint`'s sectors from the obstacle (centre ``c``, ``radius``)
    at the samples ``p``, ``back``."""
    arc = _sector_distance(c, p, back, foot.cone, foot.cone_reach, foot.rise) - (foot.reach - foot.cone_reach)
    end = _sector_distance(c, p, back, foot.cone, foot.cone_outer, foot.outer_height) - (foot.outer - foot.cone_outer)
    return arc - (radius + foot.ball), end - radius


def _footprints(foot: PathFootprint, path: PathSamples, c: np.ndarray, radius: float
                ) -> tuple[np.ndarray, np.ndarray, float]:
    """(arc, end, extra allowance): the clearances of :func:`path_clearance` from the obstacle (centre ``c``,
    ``radius``) at every sample, the cylinders' or, with a bearing face, the sectors' (:class:`PathFootprint`; the
    disc where the target may stop, which a bearing face excludes)."""
    t, p, back = path.times, path.positions, path.backward
    arc = _cylinder_distance(c, p, foot.reach, foot.rise) - (radius + foot.ball)
    end = _cylinder_distance(c, p, foot.outer, foot.outer_height) - radius
    if foot.cone >= math.pi or back is None:
        return arc, end, 0.0
    # the sector lies in the disc of the same reach, so the disc's clearance bounds the sector's from below: the
    # sector is measured where that bound is below the sector's value at the bound's smallest (the rest cannot bind)
    lower = np.minimum(arc, end)
    first = int(np.argmin(lower))
    at_first = _sectors(foot, c, radius, p[first:first + 1], back[first:first + 1])
    near = np.flatnonzero(lower <= min(float(at_first[0][0]), float(at_first[1][0])))
    arc[near], end[near] = _sectors(foot, c, radius, p[near], back[near])
    spacing = float(t[1] - t[0]) if t.size > 1 else 0.0
    return arc, end, foot.turn_rate * max(foot.cone_reach, foot.cone_outer) * spacing / 2.0


def path_clearance(scenario: Scenario, foot: PathFootprint, t_end: PathSamples | float, *,
                   explain: bool = False) -> tuple[Condition, ...]:
    """``path_clearance[i]`` for each obstacle (module doc); ``t_end``: the end time (s) or its samples. ``explain``:
    a failing condition's detail also names the horizontal overlap where the depth face caps its shortfall (another
    pass over the path: for the conditions a certificate reports, not for every set a search refuses)."""
    path = _samples(scenario, t_end)
    t, p, allowance = path.times, path.positions, path.allowance
    out = []
    for i, o in enumerate(scenario.obstacles):
        c = np.asarray(o.center, dtype=float)
        arc, end, turning = _footprints(foot, path, c, o.radius)
        both = np.minimum(arc, end)
        k = int(np.argmin(both))
        slack = float(both[k]) - allowance - turning - 1e-9 * (1.0 + abs(float(both[k])))
        part = "the completion arc's ball" if arc[k] <= end[k] else "the backup's footprint at the completion's end"
        has = float(np.hypot(p[k, 0] - c[0], p[k, 1] - c[1]))
        need = (foot.reach + o.radius + foot.ball) if arc[k] <= end[k] else (foot.outer + o.radius)
        head = (f"needs {need:.3g} m, has {has:.3g} m" if foot.cone >= math.pi else
                f"the sector within {foot.cone:.3g} rad of behind the target short by {max(0.0, -slack):.3g} m, "
                f"the path {has:.3g} m from the obstacle's centre")
        out.append(Condition(
            f"path_clearance[{i}]", "smallest clearance of the candidate's completion from the obstacle over the "
            "target's path, minus the Lipschitz allowance, > 0", slack, 0.0, slack > 0.0,
            f"{head} at t = {t[k]:.1f} s (the target's horizontal distance from the obstacle's centre; binding: "
            f"{part}; X_f reaches {foot.reach:.3g} m, footprint {foot.outer:.3g} m)"
            + (_depth_note(foot, path, c, o.radius, float(both[k])) if explain and not slack > 0.0 else "")))
    return tuple(out)


def _depth_note(foot: PathFootprint, path: PathSamples, centre: np.ndarray, radius: float, clearance: float) -> str:
    """Where the smallest clearance (m) is a depth face's (the obstacle lies within the footprint's horizontal
    extent), the largest horizontal overlap along the path and its time: what the footprint must lose sideways, which
    a shortfall capped by the depth face does not show. Empty otherwise."""
    flat = dataclasses.replace(foot, rise=math.inf, outer_height=math.inf)  # no depth face: the horizontal clearance
    arc, end, _ = _footprints(flat, path, centre, radius)
    across = np.minimum(arc, end)
    k = int(np.argmin(across))
    if not float(across[k]) < clearance - 1e-9:
        return ""
    return (f"; horizontally it lies up to {-float(across[k]):.3g} m inside the footprint (t = {path.times[k]:.1f} "
            f"s): the shortfall shown is the depth face's")


def path_workspace(scenario: Scenario, foot: PathFootprint, t_end: PathSamples | float) -> tuple[Condition, ...]:
    """``path_workspace``: both cylinders about p_d(t) inside the workspace box for t ∈ [0, t_end] (module doc);
    empty without a workspace."""
    if scenario.workspace is None:
        return ()
    path = _samples(scenario, t_end)
    t, p, allowance = path.times, path.positions, path.allowance
    lo, hi = (np.asarray(b, dtype=float) for b in scenario.workspace)
    horizontal = max(foot.reach + foot.ball, foot.outer)
    vertical = max(foot.rise + foot.ball, foot.outer_height)
    pad = np.array([horizontal, horizontal, vertical])
    room = np.minimum(p - pad - lo, hi - p - pad).min(axis=1)
    k = int(np.argmin(room))
    slack = float(room[k]) - allowance - 1e-9 * (1.0 + abs(float(room[k])))
    return (Condition("path_workspace", "smallest distance of the candidate's completion (and the backup's "
                      "footprint at its end) from the workspace walls over the target's path > 0", slack, 0.0,
                      slack > 0.0, f"tightest at t = {t[k]:.1f} s"),)


def horizon_end(scenario: Scenario) -> float:
    """T_end = duration + N δ (s): the last time a candidate's completion reaches."""
    ctrl = scenario.controller
    return float(scenario.duration) + ctrl.horizon_steps * ctrl.dt
