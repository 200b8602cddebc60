"""The terminal condition of an accepted plan: the backup's safe set, where it ends, is safe.

With p* the nominal end position of a plan, (R_f, H_f) = ``backup.footprint(vehicle_radius)`` and the
cylinder C = {‖q_xy − p*_xy‖ <= R_f, |q_z − p*_z| <= H_f} (the safe set S inflated by the vehicle
ball), the plan meets the terminal condition when

* (a) C is clear of every known obstacle o:
  hypot(max(0, ‖o_xy − p*_xy‖ − R_f), max(0, |o_z − p*_z| − H_f)) > o.radius
  (the distance from o's centre to C exceeds its radius, so the vehicle ball at any point of S misses o);
* (b) C is inside the workspace box (if any);
* (c) S is inside the region already sensed from p_k, the measured position at acceptance:
  hypot(‖p*_xy − p_k,xy‖ + c, |p*_z − p_k,z| + Z) <= sensing_range − vehicle_radius (c = S's radius,
  Z its depth): an obstacle unseen at p_k has its surface farther than the sensing range from p_k, so
  it cannot reach a vehicle ball centred within sensing_range − vehicle_radius of p_k.

Then the shifted plan followed by the backup law is always a safe candidate
(``docs/verify.md``). :func:`terminal_condition` is the one place the condition is computed;
:func:`tubekit.loop.plan_check.check_plan` applies it to every plan when the tightening has a backup.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupPlan
from tubekit.scenario import Obstacle
from tubekit.validation import as_vector, nonnegative, positive

__all__ = ["TerminalCheck", "terminal_condition", "cylinder_distance"]


@dataclass(frozen=True)
class TerminalCheck:
    """Outcome of :func:`terminal_condition`: ``ok``, the smallest slack (m) and which part it is."""

    ok: bool
    slack: float
    reason: str


def cylinder_distance(point: np.ndarray, anchor: np.ndarray, radius: float, half_height: float) -> float:
    """Distance (m) from ``point`` (3,) to the vertical cylinder of ``radius``, ``half_height`` about ``anchor``."""
    horizontal = max(0.0, float(np.hypot(point[0] - anchor[0], point[1] - anchor[1])) - radius)
    vertical = max(0.0, abs(float(point[2] - anchor[2])) - half_height)
    return math.hypot(horizontal, vertical)


def _workspace_slack(anchor: np.ndarray, r_f: float, h_f: float,
                     workspace: tuple[Sequence[float], Sequence[float]]) -> float:
    """Smallest distance (m) from the cylinder's faces to the workspace walls (>= 0: inside)."""
    lo = as_vector("workspace[0]", workspace[0], 3)
    hi = as_vector("workspace[1]", workspace[1], 3)
    pad = np.array([r_f, r_f, h_f])
    return float(min(np.min(anchor - pad - lo), np.min(hi - anchor - pad)))


def terminal_condition(anchor: Sequence[float], backup: BackupPlan, vehicle_radius: float,
                       known_obstacles: Sequence[Obstacle],
                       workspace: tuple[Sequence[float], Sequence[float]] | None,
                       sensed_at: Sequence[float], sensing_range: float) -> TerminalCheck:
    """Check the terminal condition (module doc) of a plan ending at ``anchor`` (m).

    Parameters
    ----------
    anchor : (3,)
        p*, the plan's nominal end position (m).
    backup : BackupPlan
        The certified backup (its safe set and footprint).
    vehicle_radius : float
        Radius of the vehicle ball (m).
    known_obstacles : sequence of Obstacle
        The obstacles known at acceptance.
    workspace : (lower (3,), upper (3,)) or None
        The workspace box (m); None: no walls.
    sensed_at : (3,)
        p_k, the measured position at acceptance (m).
    sensing_range : float
        R̄ (m).

    Returns
    -------
    TerminalCheck
        ``ok`` when all three parts hold; ``slack`` the smallest margin (m), ``reason`` its part
        ("obstacle i", "workspace", "sensed region").

    Raises
    ------
    ConfigError
        A non-finite anchor or sensing position, a ``backup`` that is not a BackupPlan, a negative
        vehicle radius, a sensing range that is not positive, or an obstacle that is not an Obstacle.
    """
    p = as_vector("terminal.anchor", anchor, 3)
    pk = as_vector("terminal.sensed_at", sensed_at, 3)
    if not isinstance(backup, BackupPlan):
        raise ConfigError("tightening.backup", "a tubekit.model.backup.BackupPlan", type(backup).__name__)
    rv = nonnegative("scenario.vehicle_radius", vehicle_radius)
    reach = positive("scenario.sensing_range", sensing_range)
    r_f, h_f = backup.footprint(rv)
    slacks: dict[str, float] = {}
    for i, o in enumerate(known_obstacles):
        if not isinstance(o, Obstacle):
            raise ConfigError(f"known_obstacles[{i}]", "a tubekit.Obstacle", type(o).__name__)
        slacks[f"obstacle {i}"] = cylinder_distance(np.asarray(o.center), p, r_f, h_f) - o.radius
    if workspace is not None:
        slacks["workspace"] = _workspace_slack(p, r_f, h_f, workspace)
    safe = backup.safe_set
    horizontal = float(np.hypot(p[0] - pk[0], p[1] - pk[1]))
    spread = math.hypot(horizontal + safe.radius, abs(float(p[2] - pk[2])) + safe.depth)
    slacks["sensed region"] = reach - rv - spread
    reason, worst = min(slacks.items(), key=lambda kv: kv[1])
    obstacles_clear = all(v > 0.0 for k, v in slacks.items() if k.startswith("obstacle"))
    ok = obstacles_clear and worst >= 0.0 and math.isfinite(worst)
    return TerminalCheck(ok=bool(ok), slack=float(worst), reason=reason)
