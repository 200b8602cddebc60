"""tubekit.loop.terminal: the terminal condition of an accepted plan (cylinder clear, inside, sensed).

Hand geometry: the backup's safe set has radius c = 0.8 m, shape β = 0.45, depth Z = 0.1 m; with a
vehicle radius of 0.2 m its footprint is R_f = 1.0 m, H_f = 0.3 m about the anchor p* = (0, 0, 0).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.loop.terminal import TerminalCheck, anchor_candidates, cylinder_distance, terminal_condition
from tubekit.model.backup import BackupPlan, SafeSet, StationKeeping
from tubekit.scenario import Obstacle

BACKUP = BackupPlan(StationKeeping(0.2, 0.5, 0.05, 0.3, 0.05), SafeSet(0.8, 0.45, 0.1), handover=(0.35, 0.1))
P = (0.0, 0.0, 0.0)
WIDE = ((-10.0, -10.0, -5.0), (10.0, 10.0, 5.0))


def _check(obstacles=(), workspace=WIDE, sensed_at=P, sensing_range=5.0, anchor=P) -> TerminalCheck:
    return terminal_condition(anchor, BACKUP, 0.2, obstacles, workspace, sensed_at, sensing_range)


def test_an_obstacle_beside_the_cylinder_is_measured_from_its_side():
    # centre 1.5 m away horizontally, same depth: distance to the cylinder 0.5 m, radius 0.4 -> slack 0.1
    res = _check([Obstacle((1.5, 0.0, 0.0), 0.4)])
    assert res.ok and res.reason == "obstacle 0" and res.slack == pytest.approx(0.1)


def test_an_obstacle_off_the_corner_is_measured_to_the_rim():
    # 0.3 m beyond the rim horizontally, 0.4 m beyond the top: distance 0.5 m (3-4-5), radius 0.6 -> -0.1
    res = _check([Obstacle((1.3, 0.0, 0.7), 0.6)])
    assert not res.ok and res.reason == "obstacle 0" and res.slack == pytest.approx(-0.1)


def test_touching_an_obstacle_fails_the_strict_inequality():
    res = _check([Obstacle((0.0, 1.5, 0.0), 0.5)])
    assert res.slack == pytest.approx(0.0, abs=1e-12) and not res.ok


def test_the_cylinder_must_fit_the_workspace():
    res = _check(workspace=((-10.0, -10.0, -5.0), (0.9, 10.0, 5.0)))   # R_f = 1.0 over a wall 0.9 m away
    assert not res.ok and res.reason == "workspace" and res.slack == pytest.approx(-0.1)
    res = _check(workspace=((-10.0, -10.0, -0.25), (10.0, 10.0, 5.0)))  # H_f = 0.3 under a floor 0.25 m down
    assert not res.ok and res.reason == "workspace" and res.slack == pytest.approx(-0.05)
    assert _check(workspace=None).ok


def test_the_safe_set_must_lie_in_the_sensed_region():
    # sensed from (0.3, 0.4, 0.2): hypot(0.5 + 0.8, 0.2 + 0.1) = hypot(1.3, 0.3); bound R - r_v
    need = math.hypot(1.3, 0.3) + 0.2
    at = (0.3, 0.4, 0.2)
    res = _check(sensed_at=at, sensing_range=need)
    assert res.ok and res.reason == "sensed region" and res.slack == pytest.approx(0.0, abs=1e-12)
    res = _check(sensed_at=at, sensing_range=need - 0.01)
    assert not res.ok and res.reason == "sensed region" and res.slack == pytest.approx(-0.01)


def test_the_smallest_slack_names_its_part():
    res = _check([Obstacle((3.0, 0.0, 0.0), 0.4)], sensing_range=1.35)
    assert res.ok and res.reason == "sensed region" and res.slack == pytest.approx(1.35 - 0.2 - math.hypot(0.8, 0.1))


@pytest.mark.parametrize("kwargs, field, match", [
    ({"anchor": (0.0, math.nan, 0.0)}, "terminal.anchor", "finite"),
    ({"sensed_at": "here"}, "terminal.sensed_at", "3 numbers"),
    ({"backup": None}, "tightening.backup", "BackupPlan"),
    ({"vehicle_radius": -0.1}, "scenario.vehicle_radius", ">= 0"),
    ({"sensing_range": 0.0}, "scenario.sensing_range", "> 0"),
    ({"known_obstacles": [((1.0, 0.0, 0.0), 0.4)]}, "known_obstacles[0]", "Obstacle"),
])
def test_bad_arguments_are_refused(kwargs, field, match):
    args = dict(anchor=P, backup=BACKUP, vehicle_radius=0.2, known_obstacles=(), workspace=WIDE, sensed_at=P,
                sensing_range=5.0)
    args.update(kwargs)
    with pytest.raises(ConfigError, match=match) as info:
        terminal_condition(**args)
    assert field in str(info.value)


def test_an_anchor_of_the_wrong_shape_is_refused():
    with pytest.raises(ShapeError, match=r"terminal.anchor.*\(3,\)"):
        _check(anchor=(0.0, 0.0))


@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3))
def test_cylinder_distance_is_the_distance_to_its_nearest_point(x, y, z):
    """Property: cylinder_distance equals the distance to the nearest of many points sampled in the cylinder,
    up to the sampling resolution, and is 0 inside it."""
    r, h = 1.0, 0.3
    ang = np.linspace(0.0, 2.0 * np.pi, 361)
    rad = np.linspace(0.0, r, 41)
    hz = np.linspace(-h, h, 25)
    a, rr, zz = np.meshgrid(ang, rad, hz, indexing="ij")
    pts = np.stack([rr * np.cos(a), rr * np.sin(a), zz], axis=-1).reshape(-1, 3)
    nearest = float(np.min(np.linalg.norm(pts - np.array([x, y, z]), axis=1)))
    d = cylinder_distance(np.array([x, y, z]), np.zeros(3), r, h)
    assert d <= nearest + 1e-12 and nearest - d <= 0.02


# ----------------------------------------------------------------------------------- the anchor's reach
# The same safe set proved for an anchor up to 0.2 m from the plan's end (hand-over 0.35 m = margin 0.15 + 0.2).
MOVABLE = BackupPlan(BACKUP.law, BACKUP.safe_set, handover=(0.35, 0.1), anchor_reach=0.2)


def test_an_obstacle_the_fixed_anchor_touches_is_cleared_by_moving_the_anchor_away():
    # centre 1.3 m from p*: about p* the footprint (R_f 1.0) leaves 0.3 < 0.4 -> refused; the anchor moved 0.2 m
    # away leaves 1.5 - 1.0 - 0.4 = 0.1 m (the sensed region, 5 - 0.2 - hypot(0.2 + 0.8, 0.1) = 3.79 m, is slack)
    obstacle = [Obstacle((1.3, 0.0, 0.0), 0.4)]
    assert not _check(obstacle).ok
    res = terminal_condition(P, MOVABLE, 0.2, obstacle, WIDE, P, 5.0)
    assert res.ok and res.reason == "obstacle 0" and res.slack == pytest.approx(0.1)
    assert res.anchor == pytest.approx((-0.2, 0.0, 0.0))


def test_an_obstacle_beyond_the_reach_is_still_refused():
    # centre 1.15 m from p*: even 0.2 m away the footprint leaves 1.35 - 1.0 = 0.35 < 0.4
    res = terminal_condition(P, MOVABLE, 0.2, [Obstacle((1.15, 0.0, 0.0), 0.4)], WIDE, P, 5.0)
    assert not res.ok and res.slack == pytest.approx(-0.05)


def test_two_obstacles_on_either_side_leave_the_anchor_nowhere_to_go():
    # each alone is cleared by moving away from it; together, moving away from one moves toward the other
    pair = [Obstacle((1.3, 0.0, 0.0), 0.4), Obstacle((-1.3, 0.0, 0.0), 0.4)]
    res = terminal_condition(P, MOVABLE, 0.2, pair, WIDE, P, 5.0)
    assert not res.ok and res.reason.startswith("obstacle")


def test_without_reach_the_anchor_is_the_plans_end():
    res = _check([Obstacle((1.5, 0.0, 0.0), 0.4)], anchor=(1.0, 2.0, 0.5), sensed_at=(1.0, 2.0, 0.5))
    assert res.anchor == (1.0, 2.0, 0.5)
    assert anchor_candidates(np.array([1.0, 2.0, 0.5]), 0.0, [], np.zeros(3)).tolist() == [[1.0, 2.0, 0.5]]


def test_the_sensed_region_pulls_the_anchor_toward_the_vehicle():
    # p* 3.5 m ahead of p_k, R_bar 4.4: about p* hypot(3.5 + 0.8, 0.1) = 4.3012 > 4.4 - 0.2 -> refused;
    # 0.2 m toward p_k, hypot(4.1, 0.1) = 4.1012 <= 4.2
    assert not terminal_condition((3.5, 0.0, 0.0), BACKUP, 0.2, [], WIDE, P, 4.4).ok
    res = terminal_condition((3.5, 0.0, 0.0), MOVABLE, 0.2, [], WIDE, P, 4.4)
    assert res.ok and res.reason == "sensed region" and res.anchor == pytest.approx((3.3, 0.0, 0.0))
    assert res.slack == pytest.approx(4.2 - math.hypot(4.1, 0.1))


@settings(derandomize=True, max_examples=60, deadline=None)
@given(end=st.tuples(*[st.floats(-3.0, 3.0)] * 2), reach=st.floats(0.0, 0.5),
       centres=st.lists(st.tuples(st.floats(-4.0, 4.0), st.floats(-4.0, 4.0), st.floats(-1.0, 1.0),
                                  st.floats(0.1, 0.8)), max_size=4))
def test_an_accepted_anchor_is_within_reach_and_meets_every_part_about_itself(end, reach, centres):
    """Property: whatever the obstacles, an ``ok`` check names an anchor at p*'s depth within the reach of p*
    about which the footprint clears each obstacle, stays in the walls and the safe set is sensed (recomputed
    here from the cylinder's geometry), and the reported slack is the smallest of those margins."""
    plan = BackupPlan(BACKUP.law, BACKUP.safe_set, handover=(0.35, 0.1), anchor_reach=reach)
    end3 = (end[0], end[1], 0.2)
    obstacles = [Obstacle((x, y, z), r) for x, y, z, r in centres]
    res = terminal_condition(end3, plan, 0.2, obstacles, WIDE, (0.0, 0.0, 0.0), 6.0)
    a = np.asarray(res.anchor)
    assert a[2] == end3[2] and math.hypot(a[0] - end3[0], a[1] - end3[1]) <= reach * (1 + 1e-12) + 1e-12
    if not res.ok:
        return
    parts = [cylinder_distance(np.asarray(o.center), a, 1.0, 0.3) - o.radius for o in obstacles]
    assert all(p > 0.0 for p in parts)
    parts += [float(min(np.min(a - (1.0, 1.0, 0.3) - WIDE[0]), np.min(WIDE[1] - a - (1.0, 1.0, 0.3))))]
    parts += [6.0 - 0.2 - math.hypot(math.hypot(a[0], a[1]) + 0.8, abs(a[2]) + 0.1)]
    assert min(parts) >= 0.0 and res.slack == pytest.approx(min(parts))
