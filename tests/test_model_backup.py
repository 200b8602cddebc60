"""The station-keeping backup law: its geometry, its inputs and its error table."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping, axis_angle, line_of_sight_angle, station_keeping_input

LAW = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01)


def test_pointing_at_the_anchor_surges_ahead_without_turning():
    # vehicle at (1, 0) heading west (psi = pi) looks straight at the anchor at the origin
    u, w, r = station_keeping_input(LAW, (1.0, 0.0, 0.0, math.pi), (0.0, 0.0, 0.0))
    assert u == pytest.approx(0.2) and r == pytest.approx(0.0, abs=1e-12) and w == 0.0


def test_facing_away_backs_towards_the_anchor():
    # heading east at (1, 0): the anchor is astern, so the law reverses at full surge
    u, _, r = station_keeping_input(LAW, (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert u == pytest.approx(-0.2) and r == pytest.approx(0.0, abs=1e-12)


def test_abeam_turns_at_full_rate_without_surge():
    # heading north at (1, 0): the anchor is abeam (to port), phi = -pi/2 -> chi = pi/2
    u, _, r = station_keeping_input(LAW, (1.0, 0.0, 0.0, math.pi / 2), (0.0, 0.0, 0.0))
    assert abs(u) < 1e-12 and abs(r) == pytest.approx(0.5)


def test_depth_error_commands_heave_towards_the_anchor_depth():
    _, w_deep, _ = station_keeping_input(LAW, (1.0, 0.0, 2.0, math.pi), (0.0, 0.0, 0.0))
    _, w_small, _ = station_keeping_input(LAW, (1.0, 0.0, 0.005, math.pi), (0.0, 0.0, 0.0))
    assert w_deep == pytest.approx(-0.3) and w_small == pytest.approx(-0.15)


def test_at_the_anchor_the_law_is_defined():
    assert np.all(np.isfinite(LAW(np.zeros(4), np.zeros(3))))


@given(x=st.floats(-5, 5), y=st.floats(-5, 5), z=st.floats(-2, 2), psi=st.floats(-7, 7))
def test_inputs_never_leave_the_box(x, y, z, psi):
    """Property: |u| <= u_b, |w| <= w_b, |r| <= k at every state."""
    u, w, r = LAW(np.array([x, y, z, psi]), np.zeros(3))
    assert abs(u) <= 0.2 + 1e-12 and abs(w) <= 0.3 + 1e-12 and abs(r) <= 0.5 + 1e-12


@given(d=st.floats(0.1, 5.0), theta=st.floats(-3.1, 3.1), psi=st.floats(-3.1, 3.1),
       u=st.floats(-0.4, 0.4), r=st.floats(-0.5, 0.5), wx=st.floats(-0.2, 0.2), wy=st.floats(-0.2, 0.2))
def test_line_of_sight_rate_matches_finite_differences(d, theta, psi, u, r, wx, wy):
    """Property: phi' = r + (u sin phi - omega_t)/d, the rate the safe-set proof uses."""
    p = np.array([d * math.cos(theta), d * math.sin(theta)])
    phi = line_of_sight_angle(p[0], p[1], psi, 0.0, 0.0)
    if abs(abs(phi) - math.pi) < 1e-3:
        return  # the wrap point
    h = 1e-6
    vel = u * np.array([math.cos(psi), math.sin(psi)]) + np.array([wx, wy])
    q = p + h * vel
    phi_next = line_of_sight_angle(q[0], q[1], psi + h * r, 0.0, 0.0)
    omega_t = -wx * math.sin(theta) + wy * math.cos(theta)
    expected = r + (u * math.sin(phi) - omega_t) / d
    assert (phi_next - phi) / h == pytest.approx(expected, abs=1e-4)


def test_axis_angle_folds_the_stern_onto_the_bow():
    assert axis_angle(math.pi) == pytest.approx(0.0)
    assert axis_angle(-math.pi / 2) == pytest.approx(math.pi / 2)
    assert axis_angle(2.0) == pytest.approx(2.0 - math.pi)


@pytest.mark.parametrize("field, kwargs, match", [
    ("surge", {"surge": 0.0}, "backup.surge"),
    ("yaw_rate", {"yaw_rate": -1.0}, "backup.yaw_rate"),
    ("yaw_band", {"yaw_band": 2.0}, "backup.yaw_band"),
    ("heave", {"heave": float("nan")}, "backup.heave"),
    ("heave_band", {"heave_band": "x"}, "backup.heave_band"),
])
def test_bad_gains_are_refused(field, kwargs, match):
    base = dict(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01)
    with pytest.raises(ConfigError, match=match):
        StationKeeping(**{**base, **kwargs})


@pytest.mark.parametrize("kwargs, match", [
    ({"level": 0.0}, "backup.level"),
    ({"shape": -0.1}, "backup.shape"),
    ({"depth": float("inf")}, "backup.depth"),
])
def test_bad_safe_set_is_refused(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        SafeSet(**{**dict(level=0.75, shape=0.4, depth=0.1), **kwargs})


def test_safe_set_radii():
    s = SafeSet(level=0.75, shape=0.4, depth=0.1)
    assert s.radius == 0.75 and s.handover_radius == pytest.approx(0.35)

