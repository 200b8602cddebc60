"""Rows the FHOCP adds to the plain NLP: the backup's terminal rows (:class:`BackupTerminal`), the
command-rate rows (issue 22, design (1)) and the rate penalty (issue 24 item 8).

With J = ``scenario.limits.rate`` * dt (per component, m/s, m/s, rad/s) every plan v_0..v_{N-1} meets

* (a) |v_{k+1} - v_k| <= J between consecutive nodes;
* (b) |v_0 - v_last| <= J, v_last the command applied in the last tick before the plan starts;
* (c) |v_{N-1} - c| <= J (terminal rest) when the tightening gates plans by a certified backup that does not blend
  (``Tightening.terminal_rest``; a ramped backup blends from the last applied command instead), c its hand-over
  command ``Tightening.terminal_command``: 0 for station keeping (the plan ends at rest), (u_l, 0, 0) for the loiter.

Every plan also lies in the nominal box [v_min, v_max] (``Tightening.v_low``: -v_max unless the scenario has a
minimum surge, ``limits.u_min``).

The FHOCP imposes them with J (1 - :data:`RATE_MARGIN`) (room for the solver's tolerance);
:func:`rate_project` removes what the solver's tolerance leaves over; the exact plan check
(:func:`tubekit.loop.plan_check.check_rates`) reads J itself. The rate penalty (weight lambda, s)
is :func:`rate_penalty_cost`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import cvxpy as cp
import numpy as np

from tubekit.model.backup import anchor_offsets
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

__all__ = ["RATE_MARGIN", "rate_violation", "rate_project", "rate_penalty_cost", "BackupTerminal", "backup_rows"]

#: The FHOCP imposes J (1 - RATE_MARGIN): room for the solver's tolerance below the J the exact check reads.
RATE_MARGIN = 1e-4


def rate_violation(inputs: np.ndarray, jump: np.ndarray, v_last: np.ndarray | None = None,
                   rest: bool = False, *, target: np.ndarray | None = None) -> dict[str, float]:
    """Largest violation (>= 0, input units) of each rate row of ``inputs`` (N, 3) against ``jump`` J (3,).

    Keys ``"between nodes"`` (|v_{k+1} - v_k| <= J), ``"first node"`` (|v_0 - v_last| <= J; only with
    ``v_last``) and ``"terminal rest"`` (|v_{N-1} - c| <= J; only with ``rest``), c = ``target`` (3,) (m/s, m/s,
    rad/s; None: 0, the plan ends at rest).
    """
    v = np.asarray(inputs, dtype=float)
    j = np.asarray(jump, dtype=float)
    steps = (np.abs(v[1:] - v[:-1]) - j).max() if len(v) > 1 else 0.0
    out = {"between nodes": max(0.0, float(steps))}
    if v_last is not None:
        out["first node"] = max(0.0, float((np.abs(v[0] - v_last) - j).max()))
    if rest:
        end = v[-1] if target is None else v[-1] - np.asarray(target, dtype=float)
        out["terminal rest"] = max(0.0, float((np.abs(end) - j).max()))
    return out


#: Rounding forgiven where the rest envelope (N − k) J meets the step bound v_{k−1} ± J: the two are sums of
#: the same J in another order, so equal bounds may differ by a few ulps.
REST_ROUNDING = 1e-12


def rate_project(inputs: np.ndarray, jump: np.ndarray, v_max: np.ndarray, v_last: np.ndarray | None = None,
                 rest: bool = False, *, v_min: np.ndarray | None = None,
                 target: np.ndarray | None = None) -> np.ndarray:
    """``inputs`` (N, 3) made to meet the rate rows (forward clamp), inside the box [``v_min``, ``v_max``].

    Node k is clipped to [v_{k-1} - J, v_{k-1} + J] (v_{-1} = ``v_last``; none without it), to the box
    (``v_min`` (3,): its lower corner, m/s, m/s, rad/s; None: -``v_max``) and, with ``rest``, to
    |v_k - c| <= (N - k) J (c = ``target``, None: 0), which keeps the terminal rest reachable; when the rest
    bound and the step bound do not meet (v_last too far from c) the step bound wins. A plan that already
    meets every row comes back unchanged. Returns a new array.
    """
    v = np.array(inputs, dtype=float)
    upper = np.asarray(v_max, dtype=float)
    lower = -upper if v_min is None else np.asarray(v_min, dtype=float)
    if (max(rate_violation(v, jump, v_last, rest, target=target).values()) <= 0.0
            and ((v >= lower) & (v <= upper)).all()):
        return v
    n = v.shape[0]
    rows = v.tolist()  # plain floats: N x 3 scalars clamp faster than numpy calls per node
    js, vm, vl = [float(x) for x in jump], [float(x) for x in upper], [float(x) for x in lower]
    tc = [0.0, 0.0, 0.0] if target is None else [float(x) for x in target]
    prev = None if v_last is None else [float(x) for x in v_last]
    for k in range(n):
        for c in range(3):
            lo, hi = vl[c], vm[c]
            if prev is not None:
                lo, hi = max(lo, prev[c] - js[c]), min(hi, prev[c] + js[c])
            if rest:
                reach = (n - k) * js[c]
                r_lo, r_hi = max(lo, tc[c] - reach), min(hi, tc[c] + reach)
                if r_lo <= r_hi + REST_ROUNDING * max(1.0, reach):  # they meet, up to the rounding of the sums
                    lo, hi = min(r_lo, r_hi), r_hi
            rows[k][c] = min(max(rows[k][c], lo), hi)
        prev = rows[k]
    return np.array(rows, dtype=float)


def rate_penalty_cost(inputs: np.ndarray, weight: np.ndarray, v_last: np.ndarray | None = None) -> float:
    """sum_c weight_c (sum_k (v_k,c - v_{k-1},c)^2 + (v_0,c - v_last,c)^2) (the last term only with ``v_last``).

    ``weight`` (3,) is lambda R (the rate penalty times the input weights).
    """
    v = np.asarray(inputs, dtype=float)
    d = v[1:] - v[:-1]
    total = float(np.einsum("kc,kc,c->", d, d, weight))
    if v_last is not None:
        d0 = v[0] - np.asarray(v_last, dtype=float)
        total += float(np.einsum("c,c,c->", d0, d0, weight))
    return total


@dataclass(frozen=True)
class BackupTerminal:
    """The backup's terminal condition as the FHOCP carries it at the last node (module doc).

    Attributes
    ----------
    sphere : float
        hypot(R_f, H_f) (m): added to each obstacle radius about the anchor a = p_N + offset (no obstacle margin:
        p_N is the plan's exact nominal end, the point the exact check reads).
    footprint : (float, float)
        (R_f, H_f) (m): the workspace box shrunk by it holds the anchor.
    safe : (float, float)
        (c, Z) (m): the safe set's radius and depth, for the sensed-region row about the anchor.
    sensed_bound : float
        R_bar - vehicle radius (m).
    reach : float
        ρ_a (m), the backup's anchor reach: each solve places the anchor at one offset of
        :func:`tubekit.model.backup.anchor_offsets` (:meth:`best_offset` at the linearisation's end), and every
        row holds about that one anchor, so a plan that meets them meets the exact check
        (:func:`tubekit.loop.terminal.terminal_condition`, which tries the same offsets).
    """

    sphere: float
    footprint: tuple[float, float]
    safe: tuple[float, float]
    sensed_bound: float
    reach: float = 0.0

    @classmethod
    def of(cls, scenario: Scenario, tightening: Tightening) -> "BackupTerminal | None":
        """The terminal rows of ``tightening.terminal_backup`` on ``scenario`` (None without a certified backup)."""
        backup = tightening.terminal_backup
        if backup is None:
            return None
        r_f, h_f = backup.footprint(scenario.vehicle_radius)
        return cls(sphere=math.hypot(r_f, h_f), footprint=(r_f, h_f),
                   safe=(backup.safe_set.radius, backup.safe_set.depth),
                   sensed_bound=scenario.sensing_range - scenario.vehicle_radius, reach=backup.anchor_reach)

    def _violations(self, p0: np.ndarray, anchors: np.ndarray, obstacles: np.ndarray,
                    workspace: np.ndarray | None) -> np.ndarray:
        """Largest signed violation (m; < 0: the smallest slack) of the rows about each anchor (K, 3), sensed
        from ``p0``."""
        worst = np.full(len(anchors), -np.inf)
        if len(obstacles):
            dist = np.linalg.norm(obstacles[None, :, :3] - anchors[:, None, :], axis=2)
            worst = np.maximum(worst, np.max(obstacles[None, :, 3] + self.sphere - dist, axis=1))
        if workspace is not None:
            pad = np.array([self.footprint[0], self.footprint[0], self.footprint[1]])
            worst = np.maximum(worst, np.max(np.maximum(workspace[0] + pad - anchors, anchors - workspace[1] + pad),
                                             axis=1))
        spread = np.hypot(np.hypot(anchors[:, 0] - p0[0], anchors[:, 1] - p0[1]) + self.safe[0],
                          np.abs(anchors[:, 2] - p0[2]) + self.safe[1])
        return np.maximum(worst, spread - self.sensed_bound)

    def _violation_at(self, p0: np.ndarray, anchor: np.ndarray, obstacles: np.ndarray,
                      workspace: np.ndarray | None) -> float:
        """:meth:`_violations` of one anchor (3,), on floats (the common path: no offset needed)."""
        ax, ay, az = float(anchor[0]), float(anchor[1]), float(anchor[2])
        worst = -math.inf
        for cx, cy, cz, radius in obstacles.tolist():
            worst = max(worst, radius + self.sphere - math.sqrt((cx - ax) ** 2 + (cy - ay) ** 2 + (cz - az) ** 2))
        if workspace is not None:
            pad = (self.footprint[0], self.footprint[0], self.footprint[1])
            for a, lo, hi, d in zip((ax, ay, az), workspace[0], workspace[1], pad):
                worst = max(worst, float(lo) + d - a, a - float(hi) + d)
        spread = math.hypot(math.hypot(ax - float(p0[0]), ay - float(p0[1])) + self.safe[0],
                            abs(az - float(p0[2])) + self.safe[1])
        return max(worst, spread - self.sensed_bound)

    def best_offset(self, p0: np.ndarray, pn: np.ndarray, obstacles: np.ndarray,
                    workspace: np.ndarray | None) -> np.ndarray:
        """The offset (3,) (m) of :func:`tubekit.model.backup.anchor_offsets` whose anchor pn + offset leaves the
        rows the most room (the smallest signed violation; none first among equals)."""
        offsets = anchor_offsets(self.reach)
        if len(offsets) == 1:
            return offsets[0]
        return offsets[int(np.argmin(self._violations(p0, pn[None, :] + offsets, obstacles, workspace)))]

    def violation(self, p0: np.ndarray, pn: np.ndarray, obstacles: np.ndarray,
                  workspace: np.ndarray | None) -> float:
        """Largest violation (m, >= 0) of the rows at the end position ``pn`` sensed from ``p0``, about the best
        anchor of :meth:`best_offset` (the end itself first: no offset is tried when it meets the rows)."""
        at_end = self._violation_at(p0, pn, obstacles, workspace)
        if at_end <= 0.0 or self.reach <= 0.0:
            return max(0.0, at_end)
        offsets = anchor_offsets(self.reach)
        return max(0.0, float(np.min(self._violations(p0, pn[None, :] + offsets, obstacles, workspace))))


def backup_rows(bt: BackupTerminal, end: tuple[cp.Expression, cp.Expression, cp.Expression],
                normals: list[tuple[cp.Expression, cp.Expression, cp.Expression]],
                par: Callable[[str, int], cp.Parameter], walls: bool) -> tuple[list, cp.Variable]:
    """The backup's terminal rows at the last node p_N = ``end`` (x, y, z relative to the measured position) and
    their shared slack sig_B: per obstacle slot j the half-space ``normals[j]`` · p_N + sig_B >= rt_j (rt_j
    carries the sphere about the anchor, :meth:`ConvexSubproblem._write_backup_obstacles`), the walls' box wT about the
    anchor (``walls``), and the sensed region hypot(‖p_N,xy + aT‖ + c, |z_N| + Z) <= R_bar − r_bar + sig_B with
    aT the anchor's offset (:meth:`BackupTerminal.best_offset`). ``par(name, size)`` makes a Parameter."""
    x, y, z = end
    sig_b = cp.Variable(name="slack_backup")
    cons = [sig_b >= 0]
    for j, (ox, oy, oz) in enumerate(normals):
        cons.append(ox * x + oy * y + oz * z + sig_b >= par(f"rt{j}", 1))
    if walls:
        wt = par("wT", 6)
        cons += [x + sig_b >= wt[0], y + sig_b >= wt[1], z + sig_b >= wt[2],
                 x - sig_b <= wt[3], y - sig_b <= wt[4], z - sig_b <= wt[5]]
    spread = cp.Variable(2, name="backup_spread")
    at = par("aT", 2)
    cons += [cp.SOC(spread[0] - bt.safe[0], cp.hstack([x + at[0], y + at[1]])),
             spread[1] >= z + bt.safe[1], spread[1] >= -z + bt.safe[1],
             cp.SOC(bt.sensed_bound + sig_b, spread)]
    return cons, sig_b
