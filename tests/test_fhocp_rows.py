"""The FHOCP's extra rows: the command-rate rows, their projection and the rate penalty (hand-made plans)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.fhocp.rows import RATE_MARGIN, rate_penalty_cost, rate_project, rate_violation

J = np.array([0.03, 0.03, 0.1])
VMAX = np.array([0.4, 0.3, 0.5])


# steps u: 0.02 (from v_last), 0.01, 0.025, r: 0.05 each; last node 0.025 <= J_u, 0.05 <= J_r; node k within (N - k) J
OK_PLAN = np.array([[0.06, 0.0, 0.15], [0.05, 0.0, 0.1], [0.025, 0.0, 0.05]])
OK_LAST = [0.08, 0.0, 0.2]


def test_a_plan_inside_every_row_has_no_violation():
    assert rate_violation(OK_PLAN, J, v_last=OK_LAST, rest=True) == {
        "between nodes": 0.0, "first node": 0.0, "terminal rest": 0.0}


@pytest.mark.parametrize("plan, v_last, rest, row, amount", [
    # u jumps by 0.05 between nodes 0 and 1: 0.02 over J_u = 0.03
    ([[0.1, 0.0, 0.0], [0.15, 0.0, 0.0]], None, False, "between nodes", 0.02),
    # r starts 0.3 away from the last command: 0.2 over J_r = 0.1
    ([[0.0, 0.0, 0.3], [0.0, 0.0, 0.3]], [0.0, 0.0, 0.0], False, "first node", 0.2),
    # the last node's w is 0.05: 0.02 over the rest bound J_w = 0.03
    ([[0.0, 0.05, 0.0], [0.0, 0.05, 0.0]], None, True, "terminal rest", 0.02),
])
def test_each_row_reports_its_own_violation(plan, v_last, rest, row, amount):
    got = rate_violation(np.array(plan), J, v_last, rest)
    assert got[row] == pytest.approx(amount, abs=1e-15)
    assert all(v == 0.0 for k, v in got.items() if k != row)


def test_rows_without_v_last_or_rest_are_not_reported():
    assert set(rate_violation(np.zeros((3, 3)), J)) == {"between nodes"}


def test_the_rate_penalty_by_hand():
    # u: steps 0.1, -0.2 and v_0 - v_last = 0.3; w: none; r: step 0.5
    plan = np.array([[0.3, 0.0, 0.0], [0.4, 0.0, 0.5], [0.2, 0.0, 0.5]])
    weight = np.array([2.0, 7.0, 0.1])
    by_hand = 2.0 * (0.01 + 0.04) + 0.1 * 0.25
    assert rate_penalty_cost(plan, weight) == pytest.approx(by_hand, rel=1e-14)
    assert rate_penalty_cost(plan, weight, v_last=[0.0, 0.0, 0.0]) == pytest.approx(by_hand + 2.0 * 0.09, rel=1e-14)


def test_projection_keeps_a_feasible_plan_and_clamps_forward():
    assert np.array_equal(rate_project(OK_PLAN, J, VMAX, v_last=OK_LAST, rest=True), OK_PLAN)
    # from v_last u = 0 the plan asks 0.4 at once: the clamp climbs by J_u per node
    up = rate_project(np.full((3, 3), [0.4, 0.0, 0.0]), J, VMAX, v_last=[0.0, 0.0, 0.0])
    assert np.allclose(up[:, 0], [0.03, 0.06, 0.09], atol=1e-15)


@given(v_last=st.tuples(*[st.floats(-b, b) for b in VMAX]),
       plan=st.lists(st.tuples(*[st.floats(-b, b) for b in VMAX]), min_size=8, max_size=8))
def test_projection_meets_every_row_when_rest_is_reachable(v_last, plan):
    """Property: any plan inside V projected from a v_last with |v_last| <= (N + 1) J meets (a)-(c)."""
    big_j = np.array([0.06, 0.05, 0.1])   # (N + 1) J covers V: rest is always reachable
    v = rate_project(np.array(plan), big_j, VMAX, v_last=np.array(v_last), rest=True)
    assert max(rate_violation(v, big_j, np.array(v_last), rest=True).values()) <= 1e-15
    assert np.all(np.abs(v) <= VMAX)


def test_the_margin_leaves_room_below_j():
    assert 0.0 < RATE_MARGIN <= 1e-3


def test_projection_meets_the_rest_where_the_envelopes_touch_up_to_rounding():
    """Counterexample found by hypothesis in CI: 0.15 - 0.05 rounds above the rest envelope 2 x 0.05 = 0.1,
    and the step bound used to win, leaving the terminal node at 0.15 > J."""
    big_j = np.array([0.06, 0.05, 0.1])
    plan = np.zeros((8, 3))
    plan[3:, 1] = 0.25
    v = rate_project(plan, big_j, VMAX, v_last=np.zeros(3), rest=True)
    assert max(rate_violation(v, big_j, np.zeros(3), rest=True).values()) <= 1e-15
    assert v[-1, 1] <= big_j[1] and np.allclose(v[3:, 1], [0.05, 0.1, 0.15, 0.1, 0.05])


FLOOR = np.array([0.1, -0.3, -0.5])          # a surge floor: the box's lower corner
LOITER = np.array([0.25, 0.0, 0.0])          # the loiter's hand-over command (u_l, 0, 0)


def test_the_terminal_row_is_about_the_target_command():
    plan = np.tile([0.25, 0.0, 0.0], (3, 1))   # ends at u_l: 0.25 from rest
    assert rate_violation(plan, J, rest=True)["terminal rest"] == pytest.approx(0.25 - 0.03)
    assert rate_violation(plan, J, rest=True, target=LOITER)["terminal rest"] == 0.0
    assert rate_violation(plan, J, rest=True, target=[0.3, 0.0, 0.0])["terminal rest"] == pytest.approx(0.05 - 0.03)


@given(v_last=st.tuples(*[st.floats(lo, hi) for lo, hi in zip(FLOOR, VMAX)]),
       plan=st.lists(st.tuples(*[st.floats(-b, b) for b in VMAX]), min_size=8, max_size=8))
def test_projection_keeps_the_floor_and_meets_the_rest_about_the_target(v_last, plan):
    """Property: any plan (backing up included) projected from a v_last in the floored box lies in
    [FLOOR, VMAX] and meets (a)-(c) with the terminal rest about the loiter's command."""
    big_j = np.array([0.06, 0.05, 0.1])   # (N + 1) J covers V: the command is always reachable
    v = rate_project(np.array(plan), big_j, VMAX, v_last=np.array(v_last), rest=True, v_min=FLOOR, target=LOITER)
    assert np.all(v >= FLOOR) and np.all(v <= VMAX)
    assert max(rate_violation(v, big_j, np.array(v_last), rest=True, target=LOITER).values()) <= 1e-15
