"""verify.theorem.path_clearance: the candidate's footprint along the target's path, against obstacles and walls."""

from __future__ import annotations

import math

import pytest

import verify
from tubekit import load_scenario
from tubekit.model.trajectory import Line
from tubekit.scenario import Obstacle
from verify.theorem.path_clearance import PathFootprint, horizon_end, path_clearance, path_workspace

BASE = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
FOOT = PathFootprint(reach=1.0, rise=0.5, ball=0.3, outer=1.5, outer_height=0.8)


def _line(offset: float, z: float = 0.0, radius: float = 0.4):
    """A target on the x axis at 0.2 m/s for 100 s; one obstacle ``offset`` m to its side at x = 5, depth ``z``."""
    return BASE.with_changes(trajectory=Line(start=(0.0, 0.0, 0.0), direction_velocity=(0.2, 0.0, 0.0)),
                             obstacles=(Obstacle((5.0, offset, z), radius), Obstacle((-30.0, 30.0, 0.0), 0.4)))


@pytest.mark.parametrize("offset, ok", [(2.0, True), (1.85, False), (1.0, False), (3.0, True)])
def test_the_binding_distance_is_the_footprint_plus_the_radius(offset, ok):
    """By hand: the footprint needs max(reach + ball, outer) + r_o = max(1.3, 1.5) + 0.4 = 1.9 m of horizontal
    distance between path and centre (same depth); the slack is the distance minus 1.9, less the sampling
    allowance (0.2 m/s x spacing / 2 <= 5e-4 m)."""
    sc = _line(offset)
    cond = path_clearance(sc, FOOT, horizon_end(sc))[0]
    assert cond.ok is ok and cond.condition == "path_clearance[0]"
    assert cond.lhs == pytest.approx(offset - 1.9, abs=6e-4) and cond.lhs <= offset - 1.9
    assert "needs 1.9 m" in cond.detail and f"has {offset:.3g} m" in cond.detail and "t = 25.0 s" in cond.detail


def test_an_obstacle_deep_below_the_path_is_clear():
    """Vertically the footprint reaches max(rise + ball, outer_height) = 0.8 m: an obstacle 1.3 m below the
    path's depth with radius 0.4 clears it by hypot(0, 1.3 − 0.8) − 0.4 = 0.1 m, though it lies under it."""
    cond = path_clearance(_line(0.0, z=1.3), FOOT, 100.0)[0]
    assert cond.ok and cond.lhs == pytest.approx(0.1, abs=6e-4)


def test_the_workspace_walls_by_hand():
    sc = _line(10.0).with_changes(workspace=((-3.0, -2.0, -5.0), (40.0, 2.0, 5.0)))
    cond = path_workspace(sc, FOOT, horizon_end(sc))[0]
    # the wall 2 m to each side, the footprint reaches max(1.0 + 0.3, 1.5) = 1.5 m: 0.5 m left (x: 3 and 40 − 20.8)
    assert cond.ok and cond.lhs == pytest.approx(0.5, abs=6e-4)
    assert path_workspace(sc.with_changes(workspace=None), FOOT, 10.0) == ()


def test_the_horizon_end_is_the_duration_plus_a_horizon():
    assert horizon_end(BASE) == pytest.approx(BASE.duration + BASE.controller.horizon_steps * BASE.controller.dt)
    assert math.isfinite(horizon_end(BASE))
