"""The numeric error geometry (:mod:`tubekit.model.errors`): e = [e_d, e_z, e_o], the bearing,
c = cos(psi - theta) and the generated J, zeta, xi, e_dot, at points worked out by hand.

With e_x = d cos(theta), e_y = d sin(theta): e_o = (e_x sin psi - e_y cos psi) / d = sin(psi - theta),
so e_o > 0 when the heading is turned counter-clockwise from the bearing, and c < 0 when the
vehicle heads toward the target. Along eq. (11) (x' = u cos psi + w_1, y' = u sin psi + w_2,
z' = w + w_3, psi' = r) the rates are d' = cos(theta) e_x' + sin(theta) e_y',
e_z' = w + w_3 - z_d', and e_o' = c (r - theta') with theta' = (cos(theta) e_y' - sin(theta) e_x') / d.
"""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.model.errors import bearing, error_coordinates, heading_cosine, numeric

SQRT2 = np.sqrt(2.0)
angles = st.floats(-np.pi, np.pi, allow_nan=False)
coords = st.floats(-5.0, 5.0, allow_nan=False)


def test_error_coordinates_definition():
    state = np.array([1.0, 1.0, 2.0, np.pi / 2])
    e = error_coordinates(state, np.zeros(3))
    assert e[0] == pytest.approx(np.sqrt(2))
    assert e[1] == pytest.approx(2.0)
    assert e[2] == pytest.approx(1 / np.sqrt(2))  # (e_x sin psi - e_y cos psi)/e_d


def test_numeric_is_vectorised():
    n = numeric()
    x = np.linspace(0.1, 1, 7)
    assert n.J(x, x, x).shape == (7, 3, 3)
    assert n.zeta(x, x, x, 1.0, 0.0, 0.0).shape == (7, 3)
    assert n.xi(x[:, None], x[None, :], 0.0, 0.1, 0.1, 0.1).shape == (7, 7, 3)
    assert n.J(1.0, 2.0, 0.3).shape == (3, 3)


# (state [x, y, z, psi], target [x_d, y_d, z_d], e by hand, c by hand); theta0 = atan2(4, 3)
THETA0 = np.arctan2(4.0, 3.0)
HAND_POINTS = [
    # heading straight away from the target: on the ray, e_o = 0, c = 1
    ([3.0, 4.0, 1.0, THETA0], [0.0, 0.0, 0.0], [5.0, 1.0, 0.0], 1.0),
    # heading a quarter turn counter-clockwise from the bearing: e_o = +1, c = 0
    ([3.0, 4.0, 1.0, THETA0 + np.pi / 2], [0.0, 0.0, 0.0], [5.0, 1.0, 1.0], 0.0),
    # a quarter turn clockwise: e_o = -1
    ([3.0, 4.0, 1.0, THETA0 - np.pi / 2], [0.0, 0.0, 0.0], [5.0, 1.0, -1.0], 0.0),
    # heading straight at the target: e_o = 0, c = -1 (the toward hemisphere)
    ([3.0, 4.0, 1.0, THETA0 + np.pi], [0.0, 0.0, 0.0], [5.0, 1.0, 0.0], -1.0),
    # north of a raised target, heading east: e_x = 0, e_y = 2, theta = pi/2, psi - theta = -pi/2
    ([0.0, 2.0, -1.0, 0.0], [0.0, 0.0, 0.5], [2.0, -1.5, -1.0], 0.0),
    # east of a shifted target, heading north-east: theta = 0, psi = pi/4
    ([3.0, -1.0, 0.0, np.pi / 4], [1.0, -1.0, 0.0], [2.0, 0.0, SQRT2 / 2], SQRT2 / 2),
]


@pytest.mark.parametrize("state, target, e_hand, c_hand", HAND_POINTS)
def test_error_coordinates_and_heading_cosine_at_hand_points(state, target, e_hand, c_hand):
    assert error_coordinates(np.array(state), np.array(target)) == pytest.approx(e_hand, abs=1e-12)
    assert heading_cosine(np.array(state), np.array(target)) == pytest.approx(c_hand, abs=1e-12)


def test_e_o_is_unchanged_by_whole_turns_of_the_heading():
    state = np.array([3.0, 4.0, 1.0, THETA0 + 0.7])
    turned = state + np.array([0.0, 0.0, 0.0, 4 * np.pi])
    assert error_coordinates(turned, np.zeros(3)) == pytest.approx(error_coordinates(state, np.zeros(3)))
    assert error_coordinates(state, np.zeros(3))[2] == pytest.approx(np.sin(0.7))


def test_error_coordinates_broadcast_states_against_targets():
    states = np.array([[3.0, 4.0, 1.0, THETA0], [0.0, 2.0, -1.0, 0.0]])
    targets = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [1.0, 0.0, 0.0]])
    grid = error_coordinates(states[:, None, :], targets[None, :, :])
    assert grid.shape == (2, 3, 3)
    for i, state in enumerate(states):
        for j, target in enumerate(targets):
            assert np.array_equal(grid[i, j], error_coordinates(state, target))
    # one target for many states, and one state for many targets
    assert error_coordinates(states, targets[0]).shape == (2, 3)
    assert error_coordinates(states[0], targets).shape == (3, 3)
    assert error_coordinates(states[0], targets)[1] == pytest.approx([np.hypot(3.0, 4.0), 0.5, 0.0], abs=1e-12)
    assert heading_cosine(states[:, None, :], targets[None, :, :]).shape == (2, 3)


def test_on_the_target_e_o_is_nan_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        e = error_coordinates(np.array([1.0, 2.0, 3.0, 0.4]), np.array([1.0, 2.0, 0.0]))
    assert e[0] == 0.0 and e[1] == 3.0 and np.isnan(e[2])


def test_a_floor_bounds_e_d_below_and_keeps_e_o_finite():
    """By hand: 5 mm from the target (e_x = 3 mm, e_y = 4 mm), psi = 0: e_o = -e_y / e_d = -0.8; with a
    1 cm floor e_d = 0.01 and e_o = -0.004 / 0.01 = -0.4; on the target e_o = 0 / floor = 0."""
    near = np.array([0.003, 0.004, 0.2, 0.0])
    assert error_coordinates(near, np.zeros(3)) == pytest.approx([0.005, 0.2, -0.8], abs=1e-12)
    assert error_coordinates(near, np.zeros(3), floor=0.01) == pytest.approx([0.01, 0.2, -0.4], abs=1e-12)
    on = error_coordinates(np.array([1.0, 2.0, 3.0, 0.4]), np.array([1.0, 2.0, 0.0]), floor=1e-6)
    assert on == pytest.approx([1e-6, 3.0, 0.0], abs=1e-15)
    far = np.array([3.0, 4.0, 1.0, THETA0 + 0.3])  # beyond the floor nothing changes
    assert np.array_equal(error_coordinates(far, np.zeros(3), floor=0.01), error_coordinates(far, np.zeros(3)))


def test_bearing_follows_atan2_from_the_target():
    assert bearing(1.0, 0.0) == 0.0
    assert bearing(0.0, 2.0) == pytest.approx(np.pi / 2)
    assert bearing(-3.0, 0.0) == pytest.approx(np.pi)
    assert bearing(0.0, -0.5) == pytest.approx(-np.pi / 2)
    assert bearing(1.0, -1.0) == pytest.approx(-np.pi / 4)
    grid = bearing(np.array([1.0, -1.0, 0.0])[:, None], np.array([0.0, 1.0])[None, :])
    assert grid.shape == (3, 2)
    assert grid == pytest.approx(np.array([[0.0, np.pi / 4], [np.pi, 3 * np.pi / 4], [0.0, np.pi / 2]]))


@given(d=st.floats(0.05, 20.0), theta=angles, psi=angles, target=st.tuples(coords, coords, coords))
def test_e_o_and_c_are_the_sine_and_cosine_of_one_angle(d, theta, psi, target):
    """Property: e_o = sin(psi - theta) and c = cos(psi - theta), so e_o^2 + c^2 = 1, and e_d = d."""
    p_d = np.array(target)
    state = np.array([p_d[0] + d * np.cos(theta), p_d[1] + d * np.sin(theta), 0.0, psi])
    e = error_coordinates(state, p_d)
    c = heading_cosine(state, p_d)
    assert e[0] == pytest.approx(d, rel=1e-12)
    assert e[2] == pytest.approx(np.sin(psi - theta), abs=1e-9)
    assert c == pytest.approx(np.cos(psi - theta), abs=1e-9)
    assert e[2] ** 2 + c ** 2 == pytest.approx(1.0, abs=1e-9)
    assert bearing(state[0] - p_d[0], state[1] - p_d[1]) == pytest.approx(np.arctan2(np.sin(theta), np.cos(theta)))


@given(d=st.floats(0.05, 20.0), theta=angles, psi=angles, shift=st.tuples(coords, coords, coords),
       turn=angles)
def test_the_error_is_invariant_under_moving_and_turning_the_scene(d, theta, psi, shift, turn):
    """Property: shifting vehicle and target together, or turning both (and the heading) about the
    target, leaves e unchanged."""
    state = np.array([d * np.cos(theta), d * np.sin(theta), 0.3, psi])
    e = error_coordinates(state, np.zeros(3))
    moved = error_coordinates(state + np.array([*shift, 0.0]), np.array(shift))
    turned_state = np.array([d * np.cos(theta + turn), d * np.sin(theta + turn), 0.3, psi + turn])
    turned = error_coordinates(turned_state, np.zeros(3))
    assert moved == pytest.approx(e, abs=1e-9)
    assert turned == pytest.approx(e, abs=1e-9)


# e_dot at e_x = 2, e_y = 0 (theta = 0, d = 2), psi = pi/4 (c = e_o = sqrt(2)/2), u = 1, w = 0, r = 0:
# e_x' = e_y' = sqrt(2)/2, so d' = sqrt(2)/2, theta' = (sqrt(2)/2) / 2 and e_o' = c (0 - theta') = -1/4.
def test_e_dot_at_a_hand_point_without_disturbance():
    rate = numeric().e_dot(2.0, 0.0, np.pi / 4, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert rate == pytest.approx([SQRT2 / 2, 0.0, -0.25], abs=1e-12)


def test_e_dot_at_a_hand_point_with_current_and_moving_target():
    """Same point, current w = (0, 0.5, 0.1), target moving at (0.2, 0, 0.3), heave w = 0.4, yaw rate r = 0.6.

    e_x' = sqrt(2)/2 - 0.2, e_y' = sqrt(2)/2 + 0.5: d' = e_x', e_z' = 0.4 + 0.1 - 0.3 = 0.2,
    theta' = e_y' / 2, e_o' = (sqrt(2)/2) (0.6 - e_y' / 2).
    """
    rate = numeric().e_dot(2.0, 0.0, np.pi / 4, 1.0, 0.4, 0.6, 0.0, 0.5, 0.1, 0.2, 0.0, 0.3)
    e_y_rate = SQRT2 / 2 + 0.5
    assert rate == pytest.approx([SQRT2 / 2 - 0.2, 0.2, SQRT2 / 2 * (0.6 - e_y_rate / 2)], abs=1e-12)


def test_the_split_at_the_hand_point():
    """J v, zeta and xi separately at the point above: J = [[c,0,0],[0,1,0],[-e_o c/d,0,c]],
    xi is the current's share (0, 0.1, c (-0.5/2)), zeta the target's (-0.2, -0.3, c (0/2))."""
    n, c = numeric(), SQRT2 / 2
    J = n.J(2.0, 0.0, np.pi / 4)
    assert J == pytest.approx(np.array([[c, 0.0, 0.0], [0.0, 1.0, 0.0], [-c * c / 2, 0.0, c]]), abs=1e-12)
    assert n.xi(2.0, 0.0, np.pi / 4, 0.0, 0.5, 0.1) == pytest.approx([0.0, 0.1, -c * 0.25], abs=1e-12)
    assert n.zeta(2.0, 0.0, np.pi / 4, 0.2, 0.0, 0.3) == pytest.approx([-0.2, -0.3, 0.0], abs=1e-12)


@given(e_x=coords, e_y=coords, psi=angles, v=st.tuples(coords, coords, coords),
       flow=st.tuples(coords, coords, coords))
def test_a_target_velocity_acts_as_the_opposite_current(e_x, e_y, psi, v, flow):
    """Property: zeta(p_d') = xi(-p_d') (only the relative velocity enters e), and
    e_dot = J v + zeta + xi, all broadcast to (3,)."""
    if np.hypot(e_x, e_y) < 0.05:
        e_x = 0.05 + abs(e_x)
    n = numeric()
    neg = tuple(-f for f in flow)
    assert n.zeta(e_x, e_y, psi, *flow) == pytest.approx(n.xi(e_x, e_y, psi, *neg), rel=1e-9, abs=1e-9)
    total = n.e_dot(e_x, e_y, psi, *v, *neg, *flow)
    split = n.J(e_x, e_y, psi) @ np.array(v) + n.zeta(e_x, e_y, psi, *flow) + n.xi(e_x, e_y, psi, *neg)
    assert total == pytest.approx(split, rel=1e-9, abs=1e-9)


def test_numeric_broadcasts_scalars_against_arrays():
    """A scalar argument is broadcast against array ones; every entry equals its scalar call."""
    n = numeric()
    psi = np.array([0.0, np.pi / 4, np.pi / 2])
    rates = n.e_dot(2.0, 0.0, psi, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert rates.shape == (3, 3)
    for k, p in enumerate(psi):
        assert np.array_equal(rates[k], n.e_dot(2.0, 0.0, p, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    # by hand: d' = u cos(psi - theta) = cos(psi) at theta = 0
    assert rates[:, 0] == pytest.approx(np.cos(psi), abs=1e-12)
    assert numeric() is n  # built once


def test_importing_the_error_geometry_loads_no_sympy():
    code = "import sys, tubekit.model.errors; print('sympy' in sys.modules)"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "False"


def test_floor_keeps_e_o_finite_at_the_target_and_changes_nothing_else():
    at_target = np.array([1.0, 2.0, 3.5, 0.3])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # 0 / 0 is silenced, not warned
        plain = error_coordinates(at_target, [1.0, 2.0, 0.5])
    assert plain[0] == 0.0 and plain[1] == 3.0 and np.isnan(plain[2])
    floored = error_coordinates(at_target, [1.0, 2.0, 0.5], floor=1e-9)
    np.testing.assert_array_equal(floored, [1e-9, 3.0, 0.0])
    away = np.array([[3.0, 4.0, 1.0, 0.2], [0.0, -2.0, 0.0, 1.0]])
    np.testing.assert_array_equal(error_coordinates(away, np.zeros(3), floor=1e-9),
                                  error_coordinates(away, np.zeros(3)))
    # broadcasting: one state against a reference path (K, 3)
    assert error_coordinates(away[0], np.zeros((5, 3))).shape == (5, 3)
