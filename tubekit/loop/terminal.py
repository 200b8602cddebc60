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

The anchor need not be p*: the backup was proved for a hand-over up to ``backup.anchor_reach`` farther
from its anchor than the last arc's margin (``docs/verify.md`` step 12), so the condition holds when some
anchor a within that reach of p* (same depth) meets (a)–(c) about a. :func:`terminal_condition` keeps p*
when it passes; otherwise it tries points at the reach and half of it away from each known obstacle, toward
p_k and on a ring (:func:`anchor_candidates`), keeps the passing one with the largest smallest slack and
returns it: the loop anchors the backup there.

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
from tubekit.model.backup import ANCHOR_DIRECTIONS, BackupPlan
from tubekit.scenario import Obstacle
from tubekit.validation import as_vector, nonnegative, positive

__all__ = ["TerminalCheck", "terminal_condition", "cylinder_distance", "anchor_candidates"]


@dataclass(frozen=True)
class TerminalCheck:
    """Outcome of :func:`terminal_condition`: ``ok``, the smallest slack (m), which part it is, and the anchor
    (3,) (m) the slacks are taken about (the backup's anchor when the plan is accepted)."""

    ok: bool
    slack: float
    reason: str
    anchor: tuple[float, float, float] | None = None


def cylinder_distance(point: np.ndarray, anchor: np.ndarray, radius: float, half_height: float) -> float:
    """Distance (m) from ``point`` (3,) to the vertical cylinder of ``radius``, ``half_height`` about ``anchor``."""
    horizontal = max(0.0, float(np.hypot(point[0] - anchor[0], point[1] - anchor[1])) - radius)
    vertical = max(0.0, abs(float(point[2] - anchor[2])) - half_height)
    return math.hypot(horizontal, vertical)


def anchor_candidates(end: np.ndarray, reach: float, obstacles: Sequence[Obstacle],
                      sensed_at: np.ndarray) -> np.ndarray:
    """Anchors (K, 3) (m) tried by :func:`terminal_condition`: p* = ``end`` first, then, at the horizontal
    distance ``reach`` (m) and at half of it, the points away from each obstacle, toward ``sensed_at`` and on a
    ring of :data:`tubekit.model.backup.ANCHOR_DIRECTIONS` (the FHOCP's, :class:`tubekit.fhocp.rows.BackupTerminal`);
    every one at p*'s depth. Only p* when ``reach`` is 0."""
    p = np.asarray(end, dtype=float)[:3]
    if reach <= 0.0:
        return p[None, :].copy()
    centres = np.array([o.center for o in obstacles], dtype=float).reshape(-1, 3)
    toward = np.asarray(sensed_at, dtype=float)[None, :2] - p[None, :2]
    dirs = np.concatenate([p[None, :2] - centres[:, :2], toward, ANCHOR_DIRECTIONS])
    norms = np.hypot(dirs[:, 0], dirs[:, 1])
    units = dirs[norms > 0.0] / norms[norms > 0.0, None]
    out = np.repeat(p[None, :], 2 * len(units) + 1, axis=0)
    out[1:, :2] += np.concatenate([reach * units, 0.5 * reach * units])
    return out


def _slacks(anchors: np.ndarray, backup: BackupPlan, rv: float, obstacles: Sequence[Obstacle],
            walls: tuple[np.ndarray, np.ndarray] | None, pk: np.ndarray,
            sensing: float) -> tuple[list[str], np.ndarray]:
    """Each part's name and slack (m) at every anchor, (K, parts): (a) per obstacle, (b) the walls, (c) the sensed
    region."""
    r_f, h_f = backup.footprint(rv)
    names = [f"obstacle {i}" for i in range(len(obstacles))]
    cols = []
    if obstacles:
        obs = np.array([(*o.center, o.radius) for o in obstacles], dtype=float)
        horizontal = np.maximum(0.0, np.hypot(obs[None, :, 0] - anchors[:, None, 0],
                                              obs[None, :, 1] - anchors[:, None, 1]) - r_f)
        vertical = np.maximum(0.0, np.abs(obs[None, :, 2] - anchors[:, None, 2]) - h_f)
        cols.append(np.hypot(horizontal, vertical) - obs[None, :, 3])
    if walls is not None:
        lo, hi = walls
        pad = np.array([r_f, r_f, h_f])
        names.append("workspace")
        cols.append(np.minimum((anchors - pad - lo).min(axis=1), (hi - anchors - pad).min(axis=1))[:, None])
    safe = backup.safe_set
    horizontal = np.hypot(anchors[:, 0] - pk[0], anchors[:, 1] - pk[1])
    names.append("sensed region")
    spread = np.hypot(horizontal + safe.radius, np.abs(anchors[:, 2] - pk[2]) + safe.depth)
    cols.append((sensing - rv - spread)[:, None])
    table = np.concatenate(cols, axis=1)
    return names, np.where(np.isnan(table), -np.inf, table)


def _passing(table: np.ndarray, n_obstacles: int) -> np.ndarray:
    """Per row (anchor) of ``table`` (its first ``n_obstacles`` columns the obstacles'): every obstacle's slack
    > 0 and every other part's >= 0 (finite)."""
    worst = table.min(axis=1)
    ok = np.isfinite(worst) & (worst >= 0.0)
    return ok & (table[:, :n_obstacles].min(axis=1) > 0.0) if n_obstacles else ok


def _end_check(p: np.ndarray, backup: BackupPlan, rv: float, obstacles: Sequence[Obstacle],
               walls: tuple[np.ndarray, np.ndarray] | None, pk: np.ndarray,
               sensing: float) -> TerminalCheck:
    """The three parts about p* itself, on floats (the common path: a plan whose end needs no other anchor)."""
    r_f, h_f = backup.footprint(rv)
    slacks: dict[str, float] = {}
    for i, o in enumerate(obstacles):
        slacks[f"obstacle {i}"] = cylinder_distance(np.asarray(o.center), p, r_f, h_f) - o.radius
    if walls is not None:
        pad = (r_f, r_f, h_f)
        slacks["workspace"] = min(min(float(p[j] - walls[0][j]) - pad[j], float(walls[1][j] - p[j]) - pad[j])
                                  for j in range(3))
    safe = backup.safe_set
    spread = math.hypot(math.hypot(float(p[0] - pk[0]), float(p[1] - pk[1])) + safe.radius,
                        abs(float(p[2] - pk[2])) + safe.depth)
    slacks["sensed region"] = sensing - rv - spread
    reason, worst = min(slacks.items(), key=lambda kv: kv[1])
    ok = (math.isfinite(worst) and worst >= 0.0
          and all(v > 0.0 for k, v in slacks.items() if k.startswith("obstacle")))
    return TerminalCheck(ok=bool(ok), slack=float(worst), reason=reason,
                         anchor=(float(p[0]), float(p[1]), float(p[2])))


def terminal_condition(anchor: Sequence[float], backup: BackupPlan, vehicle_radius: float,
                       known_obstacles: Sequence[Obstacle],
                       workspace: tuple[Sequence[float], Sequence[float]] | None,
                       sensed_at: Sequence[float], sensing_range: float) -> TerminalCheck:
    """Check the terminal condition (module doc) of a plan ending at ``anchor`` (m), the backup's anchor placed
    within ``backup.anchor_reach`` of it.

    Parameters
    ----------
    anchor : (3,)
        p*, the plan's nominal end position (m).
    backup : BackupPlan
        The certified backup (its safe set, footprint and anchor reach).
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
        ``ok`` when all three parts hold about the chosen anchor (p* when it passes, else of
        :func:`anchor_candidates` the passing one with the largest smallest slack, else the one with the largest
        smallest slack); ``slack`` the smallest margin (m) there, ``reason`` its part ("obstacle i",
        "workspace", "sensed region"), ``anchor`` the chosen anchor.

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
    sensing = positive("scenario.sensing_range", sensing_range)
    walls = None if workspace is None else (as_vector("workspace[0]", workspace[0], 3),
                                            as_vector("workspace[1]", workspace[1], 3))
    for i, o in enumerate(known_obstacles):
        if not isinstance(o, Obstacle):
            raise ConfigError(f"known_obstacles[{i}]", "a tubekit.Obstacle", type(o).__name__)
    at_end = _end_check(p, backup, rv, known_obstacles, walls, pk, sensing)
    if at_end.ok or backup.anchor_reach <= 0.0:
        return at_end
    anchors = anchor_candidates(p, backup.anchor_reach, known_obstacles, pk)
    names, table = _slacks(anchors, backup, rv, known_obstacles, walls, pk, sensing)
    passing = _passing(table, len(known_obstacles))
    score = np.where(passing, table.min(axis=1), -np.inf) if passing.any() else table.min(axis=1)
    best = int(np.argmax(score))
    row = table[best]
    j = int(np.argmin(row))
    chosen = (float(anchors[best, 0]), float(anchors[best, 1]), float(anchors[best, 2]))
    return TerminalCheck(ok=bool(passing[best]), slack=float(row[j]), reason=names[j], anchor=chosen)
