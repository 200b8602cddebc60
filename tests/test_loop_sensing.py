"""Sensing: an obstacle joins the FHOCP only once its surface is within R-bar of the vehicle centre."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from tubekit import ConfigError, Obstacle, paper_scenario
from tubekit.loop.closed_loop import run_closed_loop
from tubekit.loop.sensing import ObstacleMap, detected_obstacles, surface_distance

OBS = Obstacle((3.0, 0.0, 0.0), 0.4)


@pytest.mark.parametrize("gap, seen", [(-1e-6, True), (0.0, True), (1e-6, False)])
def test_rule_is_surface_within_range(gap, seen):
    # vehicle on the x axis, surface distance = 1.5 + gap
    p = np.array([3.0 - 0.4 - 1.5 - gap, 0.0, 0.0])
    assert (detected_obstacles(p, [OBS], 1.5) == (OBS,)) is seen


def test_distance_is_three_dimensional():
    # horizontally at the centre, 1.95 m below: surface 1.55 m away -> not seen with R = 1.5
    assert detected_obstacles([3.0, 0.0, -1.95], [OBS], 1.5) == ()
    assert detected_obstacles([3.0, 0.0, -1.85], [OBS], 1.5) == (OBS,)
    assert surface_distance([3.0, 0.0, -1.95], [OBS])[0] == pytest.approx(1.55)


def test_full_state_accepted_and_order_kept():
    other = Obstacle((-3.0, 0.0, 0.0), 0.4)
    both = detected_obstacles([0.0, 0.0, 0.0, 1.0], [other, OBS], 3.0)
    assert both == (other, OBS)
    assert detected_obstacles([0.0, 0.0, 0.0], [], 1.5) == ()


def test_inside_an_obstacle_is_detected():
    assert surface_distance([3.1, 0.0, 0.0], [OBS])[0] == pytest.approx(-0.3)
    assert detected_obstacles([3.1, 0.0, 0.0], [OBS], 0.1) == (OBS,)


def test_bad_range_names_field():
    with pytest.raises(ConfigError, match="sensing_range"):
        detected_obstacles([0.0, 0.0, 0.0], [OBS], -1.0)


def test_map_remembers_static_obstacles():
    m = ObstacleMap([OBS], 1.5)
    assert m.update([0.0, 0.0, 0.0]) == ()
    assert m.update([1.2, 0.0, 0.0]) == (OBS,)
    assert m.update([-5.0, 0.0, 0.0]) == (OBS,)  # out of range again, still known
    forgetful = ObstacleMap([OBS], 1.5, remember=False)
    assert forgetful.update([1.2, 0.0, 0.0]) == (OBS,)
    assert forgetful.update([-5.0, 0.0, 0.0]) == ()


class _Recorder:
    """A stand-in FHOCP (pure pursuit of the target) that records what it is given."""

    def __init__(self, scenario, tightening):
        self.sc, self.calls = scenario, []

    def solve(self, t, state, obstacles):
        self.calls.append((t, np.array(state), tuple(obstacles)))
        pd = self.sc.trajectory.position(t + 1.0)
        bearing = math.atan2(pd[1] - state[1], pd[0] - state[0])
        err = math.atan2(math.sin(bearing - state[3]), math.cos(bearing - state[3]))
        v = np.array([0.3, 0.0, float(np.clip(1.5 * err, -0.5, 0.5))])
        n = self.sc.controller.horizon_steps
        return SimpleNamespace(states=np.zeros((n + 1, 4)), inputs=np.tile(v, (n, 1)), first_input=v, cost=0.0,
                               iterations=1, solve_time_s=1e-5, max_violation=0.0, fallback=False, status="ok")


def test_closed_loop_hands_fhocp_only_sensed_obstacles():
    sc = paper_scenario().with_changes(duration=20.0)
    holder = {}

    def factory(s, tg):
        holder["solver"] = _Recorder(s, tg)
        return holder["solver"]

    res = run_closed_loop(sc, tube=False, solver_factory=factory, progress=False)
    calls = holder["solver"].calls
    assert len(calls) == sc.steps
    seen_before: set = set()
    first_seen = {}
    for k, (t, state, obs) in enumerate(calls):
        d = {o: np.linalg.norm(np.subtract(state[:3], o.center)) - o.radius for o in sc.obstacles}
        in_range = {o for o in sc.obstacles if d[o] <= sc.sensing_range}
        assert set(obs) == in_range | seen_before  # exactly: what is in range now, plus what was seen
        for o in in_range - seen_before:
            first_seen[o] = t
        seen_before |= in_range
        assert res.n_detected[k * res.ticks_per_step] == len(obs)
    # the run passes the obstacle at (3, 0, 0) around t = 12.5 s, so it must be sensed, and not at t = 0
    assert OBS in first_seen and 0.0 < first_seen[OBS] < 12.5
    assert calls[0][2] == ()
