"""Metrics on hand-made trajectories whose answers are known independently."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tubekit import Circle, Line, Obstacle, paper_scenario
from tubekit.loop.metrics import (METRIC_KEYS, clearance, compute_metrics, encirclements, input_ratio, intervals_below,
                             obstacle_passes, read_trajectory_csv, tracking_rmse, sign_flips_per_s, command_jumps)
from tubekit.plant.kinematic import Plant


def _circle_xy(radius, angle):
    return np.column_stack([radius * np.sin(angle), radius * np.cos(angle), np.zeros_like(angle)])


@pytest.mark.parametrize("t_end, turns", [(50.0, 1.0), (100.0, 2.0), (25.0, 0.5), (125.0, 2.5)])
def test_perfect_circle_one_turn_per_period(t_end, turns):
    c = Circle(radius=3.0, rate=math.pi / 25)
    t = np.linspace(0, t_end, 5001)
    assert encirclements(c.position(t), (0.0, 0.0), c.rate) == pytest.approx(turns, abs=1e-9)


def test_encirclement_direction_and_centre():
    t = np.linspace(0, 50, 2001)
    cw = Circle(radius=2.0, rate=math.pi / 25, center=(1.0, -2.0, 0.0))
    ccw = Circle(radius=2.0, rate=-math.pi / 25, center=(1.0, -2.0, 0.0))
    assert encirclements(cw.position(t), (1.0, -2.0), cw.rate) == pytest.approx(1.0)
    assert encirclements(ccw.position(t), (1.0, -2.0), ccw.rate) == pytest.approx(1.0)
    # going the wrong way round counts negative
    assert encirclements(ccw.position(t), (1.0, -2.0), cw.rate) == pytest.approx(-1.0)
    # a path that swings back and forth but does not go round: zero turns
    a = 1.5 * np.sin(np.linspace(0, 6 * np.pi, 500))
    assert encirclements(_circle_xy(3.0, a), (0.0, 0.0), 1.0) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("t_end, want", [(100.0, [2, 2]), (60.0, [1, 1]), (30.0, [1, 0]), (10.0, [0, 0])])
def test_obstacle_passes_on_the_paper_circle(t_end, want):
    # obstacles at (3, 0) and (-3, 0); the target passes them at t = 12.5 + 50 n and 37.5 + 50 n
    c = Circle(radius=3.0, rate=math.pi / 25)
    t = np.linspace(0, t_end, 4001)
    obs = [Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((-3.0, 0.0, 0.0), 0.4)]
    assert obstacle_passes(c.position(t), (0.0, 0.0), c.rate, obs) == want
    # starting 0.5 m behind at (-0.5, 3) does not change the count
    p = c.position(t)
    p[0] = [-0.5, 3.0, 0.0]
    assert obstacle_passes(p, (0.0, 0.0), c.rate, obs) == want


def test_clearance_hand_values():
    obs = [Obstacle((2.0, 0.0, 0.0), 0.5), Obstacle((0.0, 0.0, 3.0), 1.0)]
    p = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.6], [0.0, 0.0, 1.5]])
    # 2 - 0.5 - 0.25 ; inside the first obstacle's inflated ball ; 1.5 - 1 - 0.25
    np.testing.assert_allclose(clearance(p, obs, 0.25), [1.25, 0.6 - 0.5 - 0.25, 0.25])
    assert np.all(np.isinf(clearance(p, [], 0.25)))


def test_input_ratio_and_rmse():
    v = np.array([[0.2, 0.0, 0.0], [0.0, -0.3, 0.1], [0.1, 0.1, -0.45]])
    np.testing.assert_allclose(input_ratio(v, [0.4, 0.3, 0.5]), [0.5, 1.0, 0.9])
    p = np.zeros((4, 3))
    d = np.array([[0.3, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, -0.3], [0.3, 0.0, 0.0]])
    assert tracking_rmse(p, d) == pytest.approx(0.3)
    assert tracking_rmse(p, np.array([[1.0, 0, 0], [0, 0, 0]] * 2)) == pytest.approx(math.sqrt(0.5))


def test_intervals_below():
    t = np.arange(8) * 0.5
    v = np.array([1.0, 0.05, 0.02, 1.0, 1.0, 0.08, 1.0, 0.09])
    got = intervals_below(t, v, 0.1)
    assert [(g["t_start"], g["t_end"], g["t_min"]) for g in got] == [(0.5, 1.0, 1.0), (2.5, 2.5, 2.5),
                                                                     (3.5, 3.5, 3.5)]
    assert got[0]["min"] == 0.02 and got[0]["depth"] == pytest.approx(0.08)
    assert intervals_below(t, v + 1.0, 0.1) == []


def _handmade_log():
    """Vehicle on the radius-3.5 circle concentric with the desired radius-3 one, same angle, 50 s."""
    rate = math.pi / 25
    n_steps, m = 500, 10
    t = np.arange(n_steps * m + 1) * 0.01
    a = rate * t
    p = _circle_xy(3.5, a)
    pd = _circle_xy(3.0, a)
    p[:, 2] = 0.1 * np.sin(a)  # e_z oscillates by 0.1 m
    step = np.minimum(np.arange(len(t)) // m, n_steps)
    u = np.full(len(t), 0.2)
    r = np.full(len(t), -0.3)
    w = np.zeros(len(t))
    sat = np.zeros(len(t))
    sat[[40, 41, 45, 90]] = 1  # ticks in steps 4, 4, 4, 9
    u[-1] = w[-1] = r[-1] = np.nan
    step_ms = np.full(len(t), np.nan)
    step_ms[0:-1:m] = np.arange(n_steps) % 10 + 1.0  # 1..10 repeated: median 5.5
    rho = np.zeros(len(t))
    rho[1234] = 0.07
    cols = {"t": t, "step": step, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2], "u": u, "w": w, "r": r,
            "x_d": pd[:, 0], "y_d": pd[:, 1], "z_d": pd[:, 2], "saturated": sat,
            "fallback": np.zeros(len(t)), "replaced": np.zeros(len(t)), "rho_norm": rho,
            "step_ms": step_ms, "solve_ms": step_ms / 2, "wall_s": np.linspace(0, 4.2, len(t))}
    return cols


def test_compute_metrics_on_handmade_log():
    sc = paper_scenario().with_changes(duration=50.0)
    m = compute_metrics(_handmade_log(), sc, rho_bound=None, extra={"law": "x"})
    for key in METRIC_KEYS:
        assert key in m
    assert m["duration_s"] == pytest.approx(50.0)
    assert m["steps"] == 500
    assert m["min_e_d"] == pytest.approx(0.5)
    # radius-3.5 circle passes 0.5 m (horizontally) from each obstacle centre, 0.1 m above/below it:
    # sqrt(0.5^2 + 0.1^2) - 0.4 - 0.2 < 0, a collision
    assert m["min_clearance"] == pytest.approx(math.hypot(0.5, 0.1) - 0.6, abs=1e-6)
    assert m["collision"] is True
    starts = [c["t_min"] for c in m["collisions"]]
    assert starts == pytest.approx([12.5, 37.5], abs=0.01)
    assert m["e_d_below_epsilon"] == []
    assert m["max_input_ratio"] == pytest.approx(0.6)
    assert m["saturated_steps"] == 2 and m["saturated_ticks"] == 4
    assert m["encirclements"] == pytest.approx(1.0) and m["desired_encirclements"] == pytest.approx(1.0)
    assert m["obstacle_passes"] == [1, 1]
    assert m["tracking_rmse"] == pytest.approx(math.sqrt(0.25 + 0.01 / 2), rel=1e-3)
    assert m["max_rho"] == 0.07 and m["rho_bound"] is None
    assert m["step_ms_median"] == pytest.approx(5.5)
    assert m["step_ms_p95"] == pytest.approx(10.0)
    assert m["wall_s"] == pytest.approx(4.2)
    assert m["law"] == "x"


def test_a_surge_below_u_min_is_outside_the_limits():
    """inputs_within_limits reads V's lower corner: the handmade log's surge 0.2 m/s is inside V, below a floor of
    0.25 m/s it is not (the ratio to the upper corner, 0.6, does not see it)."""
    sc = paper_scenario().with_changes(duration=50.0)
    assert compute_metrics(_handmade_log(), sc)["inputs_within_limits"]
    m = compute_metrics(_handmade_log(), sc.with_changes(**{"limits.u_min": 0.25}))
    assert not m["inputs_within_limits"] and m["max_input_ratio"] == pytest.approx(0.6)
    assert compute_metrics(_handmade_log(), sc.with_changes(**{"limits.u_min": 0.2}))["inputs_within_limits"]


def test_encirclements_null_for_non_circular_trajectories():
    sc = paper_scenario().with_changes(trajectory=Line(), obstacles=())
    m = compute_metrics(_handmade_log(), sc)
    assert m["encirclements"] is None and m["min_clearance"] is None and m["collision"] is False


def test_read_trajectory_csv(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("t,x,u\n0,1.5,nan\n0.01,2,0.25\n")
    cols = read_trajectory_csv(path)
    assert list(cols) == ["t", "x", "u"]
    np.testing.assert_array_equal(cols["x"], [1.5, 2.0])
    assert np.isnan(cols["u"][0])


def test_sway_max_from_the_log_and_sway_bound_recorded():
    sc = paper_scenario().with_changes(duration=50.0)
    cols = _handmade_log()
    m = compute_metrics(cols, sc, sway_bound=0.02)
    assert m["sway_max"] is None and m["sway_bound"] == 0.02  # no omega columns: nothing to measure
    t = cols["t"]
    psi = 0.3 * t
    current = Plant.of(sc).current(t)
    sway = 0.01 * np.sin(t)
    cols = {**cols, "psi": psi, "omega_1": current[:, 0] - sway * np.sin(psi),
            "omega_2": current[:, 1] + sway * np.cos(psi)}
    assert compute_metrics(cols, sc)["sway_max"] == pytest.approx(np.max(np.abs(sway)), abs=1e-12)
    dynamic = {**cols, "v_b": np.full(len(t), -0.03)}
    assert compute_metrics(dynamic, sc)["sway_max"] == pytest.approx(0.03)


def test_sign_flips_per_second_of_a_hand_made_signal():
    """r = 0.3 sin(2 pi t) on [0, 10] s crosses zero at 0.5, 1.0, ..., 9.5 s: 19 flips in 10 s; u keeps its
    sign; w flips every sample but stays below 1 % of w_max, so it is ignored; NaN samples are skipped."""
    t = np.linspace(0.0, 10.0, 1001)
    v = np.column_stack([0.2 + 0.1 * np.sin(t), 0.002 * (-1.0) ** np.arange(len(t)), 0.3 * np.sin(2 * np.pi * t)])
    v[-1] = np.nan
    got = sign_flips_per_s(t, v, [0.004, 0.003, 0.005])
    assert got == {"u": 0.0, "w": 0.0, "r": pytest.approx(1.9)}
    # a square wave switching at t = 0.1, 0.2, ..., 10.0 s (the last sample opens segment 100): 100 flips in 10 s
    square = np.where(np.floor(t / 0.1 + 1e-9) % 2 == 0, 1.0, -1.0)
    assert sign_flips_per_s(t, np.column_stack([square] * 3), [0.1] * 3)["r"] == pytest.approx(100 / 10)


def test_command_jumps_and_the_metrics_keys():
    v = np.array([[0.0, 0.0, 0.0], [0.1, -0.05, 0.0], [0.1, 0.05, -0.3], [np.nan, np.nan, np.nan]])
    assert command_jumps(v) == {"u": pytest.approx(0.1), "w": pytest.approx(0.1), "r": pytest.approx(0.3)}
    sc = paper_scenario().with_changes(duration=50.0)
    cols = _handmade_log()
    m = compute_metrics(cols, sc)
    assert m["sign_flips_per_s"] == {"u": 0.0, "w": 0.0, "r": 0.0} and m["command_jump_max"] is None
    cols.update(u_hat=cols["u"], w_hat=cols["w"], r_hat=cols["r"])
    assert compute_metrics(cols, sc)["command_jump_max"] == {"u": 0.0, "w": 0.0, "r": 0.0}
