"""Scenario families that attack the backup and the terminal condition (issue 21), from unit cubes.

Each builder maps ``u`` in [0, 1]^n to a variant of a base scenario (its obstacles replaced, or its
start moved) and is the deterministic core of a hypothesis strategy in
:mod:`verify.falsify.strategies` (the same maps serve local searches). Every result is a valid
:class:`~tubekit.scenario.Scenario`: obstacles satisfy the separation of eq. (obstacle_dis) by
construction, and an obstacle that would touch the vehicle ball at the start is left out (a start
inside an obstacle is refused by ``certify``, so it attacks nothing).

* :func:`beyond_sensing_from_unit` — an obstacle whose surface lies just beyond the sensing range of
  the start, on the way to the target;
* :func:`on_path_from_unit` — obstacles centred on the desired path;
* :func:`cluster_from_unit` — a tight hexagonal cluster on the path (gaps just above the separation);
* :func:`between_end_and_target_from_unit` — an obstacle between a plan's end and the target
  (the plan's end taken as the target at the end of the horizon plus the start's offset from it);
* :func:`blocked_start_from_unit` — an obstacle just ahead of the start, between it and the target, so
  no FHOCP plan (heading toward the target, clear of the obstacle) may exist at t = 0.
"""

from __future__ import annotations

import math
from typing import Iterable

import numpy as np

from tubekit.scenario import Obstacle, Scenario

__all__ = ["beyond_sensing_from_unit", "on_path_from_unit", "cluster_from_unit",
           "between_end_and_target_from_unit", "blocked_start_from_unit", "FAMILY_DIMS", "FAMILIES"]

#: Smallest clearance (m) from the start's vehicle ball that a family's obstacle keeps.
START_CLEARANCE = 0.02
#: Position margin M_pos (m) the separation allows for: certify requires
#: ‖p_i − p_j‖ > 2 (r̄ + M_pos) + r_i + r_j (the paper's certificates have M_pos <= 0.15 m).
SEPARATION_MARGIN = 0.15
#: Hexagonal cluster offsets (units of the lattice spacing): the centre and its six neighbours.
_HEX = [(0.0, 0.0)] + [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)]


def _lerp(lo: float, hi: float, u: float) -> float:
    return lo + (hi - lo) * float(u)


def _target(scenario: Scenario, t: float) -> np.ndarray:
    return np.asarray(scenario.trajectory.position(np.array([float(t)]))[0], dtype=float)


def _start(scenario: Scenario) -> np.ndarray:
    return np.asarray(scenario.initial_state[:3], dtype=float)


def _place(scenario: Scenario, candidates: Iterable[tuple[np.ndarray, float]]) -> Scenario:
    """The scenario with these obstacles (in order; each kept when clear of the start and separated from those
    kept by 2 (r̄ + :data:`SEPARATION_MARGIN`) + r_i + r_j)."""
    kept: list[Obstacle] = []
    start, rbar = _start(scenario), scenario.vehicle_radius
    for center, radius in candidates:
        if np.linalg.norm(center - start) - radius - rbar <= START_CLEARANCE:
            continue
        if all(np.linalg.norm(center - np.asarray(o.center)) > 2 * (rbar + SEPARATION_MARGIN) + radius + o.radius
               for o in kept):
            kept.append(Obstacle(tuple(float(x) for x in center), float(radius)))
    return scenario.with_changes(obstacles=tuple(kept))


def beyond_sensing_from_unit(scenario: Scenario, u: np.ndarray) -> Scenario:
    """One obstacle (radius 0.2–0.6 m) whose surface is 0–0.3 m beyond the sensing range of the start.

    ``u`` (3,): radius, gap beyond the range, and the time (0–20 s) of the target position that sets
    the direction from the start.
    """
    radius, gap = _lerp(0.2, 0.6, u[0]), _lerp(1e-3, 0.3, u[1])
    start = _start(scenario)
    way = _target(scenario, _lerp(0.0, 20.0, u[2])) - start
    way = way / (np.linalg.norm(way) or 1.0)
    return _place(scenario, [(start + (scenario.sensing_range + radius + gap) * way, radius)])


def on_path_from_unit(scenario: Scenario, u: np.ndarray) -> Scenario:
    """Up to three obstacles (radius 0.2–0.6 m) centred on the desired path at times within the run.

    ``u`` (6,): per obstacle a time in [0, duration] and a radius.
    """
    cands = [(_target(scenario, _lerp(0.0, scenario.duration, u[2 * k])), _lerp(0.2, 0.6, u[2 * k + 1]))
             for k in range(3)]
    return _place(scenario, cands)


def cluster_from_unit(scenario: Scenario, u: np.ndarray) -> Scenario:
    """A hexagonal cluster of 3–7 equal obstacles about a point near the path, gaps 1–20 % above the separation
    (:data:`SEPARATION_MARGIN` included).

    ``u`` (6,): count, radius (0.15–0.4 m), relative gap, cluster time on the path, lateral offset
    (±1 m), lattice rotation.
    """
    count = 3 + min(int(u[0] * 5), 4)
    radius = _lerp(0.15, 0.4, u[1])
    spacing = (2 * (scenario.vehicle_radius + SEPARATION_MARGIN) + 2 * radius) * (1.0 + _lerp(0.01, 0.2, u[2]))
    t = _lerp(0.0, scenario.duration, u[3])
    centre = _target(scenario, t)
    ahead = _target(scenario, t + 1.0) - centre
    normal = np.array([-ahead[1], ahead[0], 0.0]) / (math.hypot(ahead[0], ahead[1]) or 1.0)
    centre = centre + _lerp(-1.0, 1.0, u[4]) * normal
    turn = _lerp(0.0, math.pi / 3, u[5])
    offsets = [np.array([a * math.cos(turn) - b * math.sin(turn), a * math.sin(turn) + b * math.cos(turn), 0.0])
               for a, b in _HEX[:count]]
    return _place(scenario, [(centre + spacing * o, radius) for o in offsets])


def between_end_and_target_from_unit(scenario: Scenario, u: np.ndarray) -> Scenario:
    """One obstacle on the segment from a plan's end to the target at the end of the horizon.

    The plan's end at time s is taken as p_d(s + T) + (p_0 − p_d(0)) (T the horizon, p_0 the start):
    the start's offset from the target carried along. ``u`` (3,): s in [0, duration], the point on the
    segment (20–80 %), radius 0.15–0.5 m.
    """
    s = _lerp(0.0, scenario.duration, u[0])
    target = _target(scenario, s + scenario.controller.horizon)
    end = target + _start(scenario) - _target(scenario, 0.0)
    return _place(scenario, [(end + _lerp(0.2, 0.8, u[1]) * (target - end), _lerp(0.15, 0.5, u[2]))])


def blocked_start_from_unit(scenario: Scenario, u: np.ndarray) -> Scenario:
    """An obstacle just ahead of the start on the way to the target, the start heading at it.

    ``u`` (3,): radius (0.3–0.8 m), clearance of its surface from the vehicle ball (0.03–0.3 m),
    lateral angle of its centre off the line to the target (±0.3 rad).
    """
    radius, clear = _lerp(0.3, 0.8, u[0]), _lerp(0.03, 0.3, u[1])
    start = _start(scenario)
    way = _target(scenario, 0.0) - start
    bearing = math.atan2(way[1], way[0]) + _lerp(-0.3, 0.3, u[2])
    reach = scenario.vehicle_radius + clear + radius
    center = start + reach * np.array([math.cos(bearing), math.sin(bearing), 0.0])
    state = (*scenario.initial_state[:3], bearing)
    return _place(scenario.with_changes(initial_state=state), [(center, radius)])


#: Each family's builder and the length of the unit vector it reads.
FAMILIES = {"beyond_sensing": beyond_sensing_from_unit, "on_path": on_path_from_unit,
            "cluster": cluster_from_unit, "between_end_and_target": between_end_and_target_from_unit,
            "blocked_start": blocked_start_from_unit}
FAMILY_DIMS = {"beyond_sensing": 3, "on_path": 6, "cluster": 6, "between_end_and_target": 3, "blocked_start": 3}
