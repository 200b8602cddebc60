"""The discretised NLP: exact step, rollout, linearisations, obstacle selection, nonlinear violations."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tubekit.fhocp.nlp import BackupTerminal, FhocpNlp, discrete_step, obstacle_array, rollout, select_obstacles
from tubekit.model.kinematics import dsinc, nominal_kinematics, sinc
from tubekit.exceptions import ConfigError
from tubekit.scenario import Obstacle, paper_scenario
from tubekit.tightening import Tightening

from .fhocp_cases import backup_plan, tightening

SC = paper_scenario()
TIGHT = Tightening(v_max=np.array([0.3, 0.2, 0.4]), e_d_min=0.3, e_o_max=0.8, e_z_max=0.9, e_d_max=2.9,
                   obstacle_margin=0.05, sigma=10.0)
NLP = FhocpNlp.from_scenario(SC, TIGHT, terminal="off")


def test_rollout_is_repeated_discrete_step():
    rng = np.random.default_rng(0)
    s0 = np.array([0.5, -1.0, 0.2, 0.3])
    v = rng.uniform(-0.3, 0.3, (NLP.n, 3))
    s = rollout(s0, v, NLP.dt)
    x = s0
    for k in range(NLP.n):
        x = discrete_step(x, v[k], NLP.dt)
        assert np.allclose(s[k + 1], x, atol=1e-12)


def test_obstacle_violation_is_the_penetration_depth():
    """A stationary plan at distance d from an obstacle centre violates by r + r_bar + margin - d."""
    ob = Obstacle((1.0, 0.0, 0.0), 0.4)
    s0 = np.array([1.3, 0.0, 0.0, 0.0])            # 0.3 m from the centre
    v = np.zeros((NLP.n, 3))
    states = rollout(s0, v, NLP.dt)
    ref = np.tile([1.3, -1.0, 0.0], (NLP.n + 1, 1))  # target 1 m away: e_d constraint inactive
    ev = NLP.evaluate(states, v, ref, obstacle_array([ob]))
    assert ev.violations["obstacle"] == pytest.approx(0.4 + SC.vehicle_radius + 0.05 - 0.3)
    assert ev.violations["e_d_min"] == 0.0


def test_e_d_and_input_violations():
    s0 = np.array([0.0, 0.1, 0.0, 0.0])
    v = np.zeros((NLP.n, 3))
    v[0, 0] = 0.5                                     # 0.2 above V-bar_u = 0.3
    states = rollout(s0, np.clip(v, -TIGHT.v_max, TIGHT.v_max), NLP.dt)
    ref = np.zeros((NLP.n + 1, 3))                    # target at the origin, e_d ~ 0.1 < 0.3
    ev = NLP.evaluate(states, v, ref, np.zeros((0, 4)))
    assert ev.violations["input"] == pytest.approx(0.2)
    e_d = np.hypot(states[1:, 0], states[1:, 1])
    assert ev.violations["e_d_min"] == pytest.approx(np.max(0.3 - e_d))


def test_the_input_box_has_a_lower_corner_from_the_tightening():
    """v_min defaults to -v_max (the symmetric box) and comes from ``Tightening.v_low``: a surge below the floor is
    an input violation by the shortfall, a surge backing up to -v_max is none without the floor."""
    assert np.array_equal(NLP.v_min, -TIGHT.v_max) and np.array_equal(NLP.terminal_command, np.zeros(3))
    floored = FhocpNlp.from_scenario(SC, dataclasses.replace(TIGHT, v_min=[0.1, -0.2, -0.4]), terminal="off")
    assert np.array_equal(floored.v_min, [0.1, -0.2, -0.4])
    s0 = np.array([0.0, 1.0, 0.0, 0.0])
    v = np.zeros((NLP.n, 3))
    v[:, 0] = 0.1                                     # on the floor
    v[2, 0] = 0.04                                    # 0.06 below it
    v[3, 0] = -0.3                                    # backing up at -V-bar_u: 0.4 below it
    ref = np.tile([0.0, 4.0, 0.0], (NLP.n + 1, 1))
    states = rollout(s0, v, NLP.dt)
    assert floored.evaluate(states, v, ref, np.zeros((0, 4))).violations["input"] == pytest.approx(0.4)
    assert NLP.evaluate(states, v, ref, np.zeros((0, 4))).violations["input"] == 0.0
    np.testing.assert_array_equal(floored.clip(v)[:, 0], np.maximum(v[:, 0], 0.1))


@pytest.mark.parametrize("v_min", [[0.31, -0.2, -0.4], [-0.31, -0.2, -0.4], [math.nan, -0.2, -0.4]])
def test_a_lower_corner_outside_the_box_is_refused(v_min):
    with pytest.raises(ConfigError, match="v_min"):
        dataclasses.replace(NLP, v_min=np.array(v_min))


def test_select_obstacles_by_surface_distance_nearest_first():
    obs = [Obstacle((5.0, 0, 0), 0.5), Obstacle((2.0, 0, 0), 0.4), Obstacle((1.5, 0, 3.0), 0.4)]
    kept, dropped = select_obstacles(np.zeros(4), obs, sensing_range=1.6, max_count=1)
    # surface distances: 4.5, 1.6, ~2.95 -> only the second is in range
    assert kept.shape == (1, 4) and np.allclose(kept[0], [2.0, 0, 0, 0.4]) and dropped == 0
    kept, dropped = select_obstacles(np.zeros(4), obs, sensing_range=10.0, max_count=2)
    assert np.allclose(kept[:, 0], [2.0, 1.5]) and dropped == 1


# ------------------------------------------------------------------ discretisation
def test_exact_step_matches_fine_rk4():
    rng = np.random.default_rng(0)
    for _ in range(6):
        s = rng.normal(size=4)
        v = rng.uniform(-1, 1, 3) * np.array([0.4, 0.3, 0.5])
        x = s.copy()
        h = 0.1 / 2000
        for _ in range(2000):
            k1 = nominal_kinematics(x, v)
            k2 = nominal_kinematics(x + h / 2 * k1, v)
            k3 = nominal_kinematics(x + h / 2 * k2, v)
            k4 = nominal_kinematics(x + h * k3, v)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        assert np.allclose(discrete_step(s, v, 0.1), x, atol=1e-12, rtol=0)  # RK4 error ~1e-15


def test_rollout_is_repeated_step():
    rng = np.random.default_rng(1)
    v = rng.uniform(-1, 1, (8, 3)) * np.array([0.4, 0.3, 3.0])
    s = rollout(np.array([1.0, -2.0, 0.3, 5.0]), v, 0.1)
    assert np.max(np.abs(s[1:] - discrete_step(s[:-1], v, 0.1))) < 1e-14


def test_sinc_and_derivative_near_zero():
    a = np.array([0.0, 1e-12, -1e-5, 0.05, -0.099, 0.101, 0.7])
    safe = np.where(a == 0, 1.0, a)
    exact = np.where(a == 0, 1.0, np.sin(safe) / safe)
    assert np.allclose(sinc(a), exact, rtol=1e-15, atol=0)
    h = 1e-6
    fd = (np.sin(a + h) / (a + h) - np.sin(a - h) / (a - h)) / (2 * h)
    assert np.allclose(dsinc(a[1:]), fd[1:], atol=1e-9)
    assert dsinc(np.array([0.0]))[0] == 0.0


# ---- the backup's terminal rows (issue 21) ----------------------------------------------------------------

def test_the_backup_terminal_rows_come_from_the_tightenings_backup():
    assert FhocpNlp.from_scenario(SC, tightening()).backup_terminal is None
    bt = FhocpNlp.from_scenario(SC, dataclasses.replace(tightening(), backup=backup_plan())).backup_terminal
    # footprint (0.8 + 0.2, 0.1 + 0.2); sphere hypot(1.0, 0.3) (no obstacle margin at the exact end); R_bar - r = 1.3
    assert bt.footprint == pytest.approx((1.0, 0.3)) and bt.sphere == pytest.approx(math.hypot(1.0, 0.3))
    assert bt.safe == pytest.approx((0.8, 0.1)) and bt.sensed_bound == pytest.approx(1.3)


def test_the_backup_terminal_rows_hold_about_one_anchor_within_the_reach():
    """With an anchor that may move 0.25 m from the plan's end, the rows keep the whole footprint (1.0, 0.3) and the
    safe set (0.8, 0.1) about one anchor p_N + offset, the offset one of the shared ring's (or none): an obstacle
    1.3 m from p_N (needs 1.0 + 0.4 from the anchor) is cleared by the offset pointing away from it."""
    from tubekit.model.backup import ANCHOR_DIRECTIONS
    movable = dataclasses.replace(backup_plan(), anchor_reach=0.25)
    bt = FhocpNlp.from_scenario(SC, dataclasses.replace(tightening(), backup=movable)).backup_terminal
    assert bt.footprint == pytest.approx((1.0, 0.3)) and bt.sphere == pytest.approx(math.hypot(1.0, 0.3))
    assert bt.safe == pytest.approx((0.8, 0.1)) and bt.reach == 0.25
    p0, pn = np.array([0.9, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])   # sensed 0.1 m behind p_N
    obstacle = np.array([[2.3, 0.0, 0.0, 0.4]])                  # 1.3 m ahead of p_N
    offset = bt.best_offset(p0, pn, obstacle, None)
    assert offset == pytest.approx(np.append(-0.25 * ANCHOR_DIRECTIONS[0], 0.0))   # straight away from it
    # about p_N + offset: 1.55 m from the centre, needs 0.4 + hypot(1.0, 0.3) = 1.444 m; sensed hypot(0.95, 0.1) < 1.3
    assert bt.violation(p0, pn, obstacle, None) == 0.0
    fixed = dataclasses.replace(bt, reach=0.0)
    assert fixed.violation(p0, pn, obstacle, None) == pytest.approx(0.4 + math.hypot(1.0, 0.3) - 1.3)


def test_the_backup_terminal_violation_is_the_worst_row():
    bt = BackupTerminal(sphere=1.0, footprint=(0.9, 0.2), safe=(0.5, 0.1), sensed_bound=2.0)
    p0, pn = np.zeros(3), np.array([1.0, 0.0, 0.0])
    assert bt.violation(p0, pn, np.zeros((0, 4)), None) == 0.0   # spread hypot(1.5, 0.1) < 2
    obstacle = np.array([[2.5, 0.0, 0.0, 0.6]])                  # 1.5 m away, needs 1.6
    assert bt.violation(p0, pn, obstacle, None) == pytest.approx(0.1)
    walls = np.array([[-5.0, -5.0, -5.0], [1.8, 5.0, 5.0]])     # x <= 1.8 - 0.9 = 0.9
    assert bt.violation(p0, pn, np.zeros((0, 4)), walls) == pytest.approx(0.1)
    far = np.array([2.0, 0.0, 0.4])                              # hypot(2.5, 0.5) - 2
    assert bt.violation(p0, far, np.zeros((0, 4)), None) == pytest.approx(math.hypot(2.5, 0.5) - 2.0)


def test_the_last_node_is_narrowed_to_the_terminal_set_only_with_the_tracking_theorem():
    """``node_bounds``: the tightened sets at every node; with a tightening that proves tracking (tracking tier and
    its terminal law) the last node is X_f shrunk by 1 % of its widths (a plan ending on a face to the solver's
    tolerance still passes the exact check): 0.6 + 0.003 <= e_d <= 0.9 - 0.003, |e_o| <= 0.99 sin(α_f),
    |e_z| <= 0.99 z_f."""
    from tubekit.model.terminal_law import TerminalLaw
    from tubekit.tiers import Tiers
    law = TerminalLaw(d_lo=0.6, d_hi=0.9, d_star=0.75, alpha_max=0.1, z_max=0.5, gain_d=1.0, gain_z=0.2, turn=0.5)
    plain = NLP.node_bounds()
    assert all(np.all(v == v[0]) for v in plain.values()) and plain["e_d_lo"][0] == 0.3
    proving = dataclasses.replace(TIGHT, terminal_law=law, tiers=Tiers(True, True), margins=np.zeros((8, 4)))
    nb = FhocpNlp.from_scenario(SC, proving, terminal="off").node_bounds()
    assert nb["e_d_lo"][-1] == pytest.approx(0.603) and nb["e_d_hi"][-1] == pytest.approx(0.897)
    assert nb["e_z"][-1] == pytest.approx(0.495) and nb["e_o"][-1] == pytest.approx(0.99 * math.sin(0.1))
    assert nb["e_d_lo"][0] == 0.3 and nb["e_o"][0] == 0.8
    unproven = dataclasses.replace(proving, tiers=Tiers(True, False))
    assert FhocpNlp.from_scenario(SC, unproven, terminal="off").tracking_terminal is None


def test_the_last_row_box_is_the_law_s_row_within_the_faces_less_their_pad():
    """With a tracking theorem whose X_f has row faces, the NLP carries the law (``terminal_rows``) and its last
    row's box is the law's row at the end state ± (1 − ROW_FACE_PAD) S; without the faces, no box."""
    from tubekit.fhocp.nlp import ROW_FACE_PAD
    from tubekit.model.terminal_law import TerminalLaw
    from tubekit.tiers import Tiers
    law = TerminalLaw(d_lo=0.6, d_hi=0.9, d_star=0.75, alpha_max=0.1, z_max=0.5, gain_d=1.0, gain_z=0.2, turn=0.5,
                      row_u=0.01, row_w=0.002, row_r=0.03)
    proving = dataclasses.replace(TIGHT, terminal_law=law, tiers=Tiers(True, True), margins=np.zeros((8, 4)))
    nlp = FhocpNlp.from_scenario(SC, proving, terminal="off")
    end, p_end, v_end = np.array([-1.0, 0.0, 0.1, 0.0]), np.zeros(3), np.array([0.2, 0.0, 0.0])
    lo, hi = nlp.last_row_box(end, p_end, v_end)
    row = law.command(end, p_end, v_end, SC.controller.dt)
    np.testing.assert_allclose(0.5 * (lo + hi), row, atol=1e-15)
    np.testing.assert_allclose(0.5 * (hi - lo), (1 - ROW_FACE_PAD) * np.array([0.01, 0.002, 0.03]), atol=1e-15)
    assert NLP.terminal_rows is None
    with pytest.raises(ValueError, match="no row faces"):
        NLP.last_row_box(end, p_end, v_end)


def test_the_lookahead_margins_grow_along_the_horizon_to_a_share_of_the_footprint():
    """lambda_f (k/N) of the footprint's extent beyond the clearance at node k = 1..N; zeros when off or without a
    backup; a negative lookahead is refused by name."""
    with_backup = dataclasses.replace(tightening(), backup=backup_plan())
    nlp = FhocpNlp.from_scenario(SC.with_changes(**{"controller.lookahead": 1.5}), with_backup)
    extent = nlp.backup_terminal.sphere - nlp.clearance
    n = nlp.horizon_steps
    np.testing.assert_allclose(nlp.lookahead_margins(), [1.5 * extent * k / n for k in range(1, n + 1)])
    assert not FhocpNlp.from_scenario(SC, with_backup).lookahead_margins().any()
    assert not FhocpNlp.from_scenario(SC.with_changes(**{"controller.lookahead": 1.5}),
                                      tightening()).lookahead_margins().any()
    with pytest.raises(ConfigError, match="lookahead"):
        dataclasses.replace(nlp, lookahead=-0.1)
