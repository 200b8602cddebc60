"""tubekit.model.terminal_law: the terminal set X_f and the terminal law, evaluated (the proof is verify's)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.kinematics import unicycle_step
from tubekit.model.terminal_law import NO_BEARING, NO_ROWS, TerminalLaw, bearing, line_of_sight

GOOD = dict(d_lo=0.6, d_hi=0.9, d_star=0.75, alpha_max=0.06, z_max=0.8, gain_d=1.5, gain_z=0.3, turn=0.6)


@pytest.mark.parametrize("change, match", [
    ({"d_star": 1.0}, "terminal.d_star"),
    ({"d_lo": 0.0}, "terminal.d_lo"),
    ({"alpha_max": 1.6}, "terminal.alpha_max"),
    ({"turn": 0.0}, "terminal.turn"),
    ({"turn": 1.5}, "terminal.turn"),
    ({"gain_d": -1.0}, "terminal.gain_d"),
    ({"z_max": float("nan")}, "terminal.z_max"),
    ({"bearing_max": 0.0}, "terminal.bearing_max"),
    ({"bearing_max": 3.5}, "terminal.bearing_max"),
    ({"row_u": 0.01}, "terminal.row_u"),                                  # one face without the others
    ({"row_u": -0.01, "row_w": 0.01, "row_r": 0.01}, "terminal.row_u"),   # a negative face
    ({"row_r": float("inf"), "row_u": 0.01, "row_w": 0.01}, "terminal.row_r"),
    ({"los_feedforward": 1}, "terminal.los_feedforward"),               # an int is not a bool
    ({"los_feedforward": "yes"}, "terminal.los_feedforward"),
])
def test_a_bad_set_is_refused_naming_the_field(change, match):
    with pytest.raises(ConfigError, match=match):
        TerminalLaw(**{**GOOD, **change})


def test_the_dict_round_trip_is_exact_and_a_missing_key_is_named():
    law = TerminalLaw(**GOOD)
    assert TerminalLaw.from_dict(law.to_dict()) == law
    with pytest.raises(ConfigError, match="certificate.terminal"):
        TerminalLaw.from_dict({k: v for k, v in GOOD.items() if k != "turn"}, "certificate.terminal")


def test_a_bearing_face_row_faces_and_the_feedforward_survive_the_round_trip_among_thirteen_keys():
    law = TerminalLaw(**GOOD, bearing_max=0.4, row_u=0.01, row_w=0.002, row_r=0.03, los_feedforward=True)
    assert law.has_bearing and not TerminalLaw(**GOOD).has_bearing and TerminalLaw(**GOOD).bearing_max == NO_BEARING
    assert law.has_rows and not TerminalLaw(**GOOD).has_rows and TerminalLaw(**GOOD).row_u == NO_ROWS
    assert len(law.to_dict()) == 13 and law.to_dict()["los_feedforward"] == 1.0
    assert TerminalLaw.from_dict(law.to_dict()) == law and TerminalLaw.from_dict(law.to_dict()).los_feedforward is True
    with pytest.raises(ConfigError, match="certificate.terminal.los_feedforward"):
        TerminalLaw.from_dict({**law.to_dict(), "los_feedforward": 0.5}, "certificate.terminal")


def test_the_feedforward_row_by_hand():
    """The vehicle 1 m behind the target, pointing at it (α = 0), the target moving at (0.2, 0.1) m/s: the line of
    sight turns at ω̂ = (P_⊥ − N tan α) / d = 0.1 rad/s, so r = 0.1 rad/s instead of 0 (the turn T = δ ω̂ = 0.01
    rad), and u = N / (S(T/2) cos(T/2)) with N = 0.2 + 1.5 (1 − 0.75) = 0.575 m/s; w is unchanged."""
    state, target, velocity = np.array([-1.0, 0.0, 0.1, 0.0]), np.zeros(3), np.array([0.2, 0.1, 0.0])
    fed = TerminalLaw(**GOOD, los_feedforward=True).command(state, target, velocity, 0.1)
    plain = TerminalLaw(**GOOD).command(state, target, velocity, 0.1)
    assert fed[2] == pytest.approx(0.1) and plain[2] == 0.0
    assert fed[0] == pytest.approx(0.575 / (math.sin(0.005) / 0.005 * math.cos(0.005)), rel=1e-12)
    assert plain[0] == pytest.approx(0.575) and fed[1] == plain[1] == pytest.approx(-0.03)


def test_with_the_feedforward_the_exact_arc_keeps_a_crossing_target_on_the_line_of_sight():
    """A target crossing at 0.3 m/s, 2 m ahead: over one exact unicycle arc of the row, the memoryless law lets
    the line of sight turn away by about δ P_⊥ / d = 0.015 rad; with the feedforward the heading's angle to it stays
    below a hundredth of that (what is left is second order in δ)."""
    law = dataclasses.replace(TerminalLaw(**GOOD), d_hi=2.5, d_star=2.0)
    state, velocity = np.array([-2.0, 0.0, 0.0, 0.0]), np.array([0.0, 0.3, 0.0])
    ends = {}
    for fed in (False, True):
        row = dataclasses.replace(law, los_feedforward=fed).command(state, np.zeros(3), velocity, 0.1)
        ends[fed] = line_of_sight(unicycle_step(state, row, 0.1), 0.1 * velocity)[1]
    assert abs(ends[False]) == pytest.approx(0.015, rel=0.05)
    assert abs(ends[True]) < 0.01 * abs(ends[False])


def test_the_row_faces_by_hand():
    """The vehicle 1 m behind a target moving at 0.2 m/s along +x, pointing at it: the law's row is
    u = 0.2 + 1.5 (1 − 0.75) = 0.575 m/s, w = −0.3 · 0.1 = −0.03 m/s (e_z = 0.1 m) and r = 0; a last row
    (0.58, −0.03, 0.02) then has the slacks 0.01 − 0.005, 0.002 − 0 and 0.03 − 0.02."""
    law = TerminalLaw(**GOOD, row_u=0.01, row_w=0.002, row_r=0.03)
    state = np.array([-1.0, 0.0, 0.1, 0.0])
    slacks = law.row_slacks(state, np.zeros(3), np.array([0.2, 0.0, 0.0]), np.array([0.58, -0.03, 0.02]), 0.1)
    assert slacks == pytest.approx({"terminal set: |v_u - kappa_f|": 0.005, "terminal set: |v_w - kappa_f|": 0.002,
                                    "terminal set: |v_r - kappa_f|": 0.01})
    assert TerminalLaw(**GOOD).row_slacks(state, np.zeros(3), np.zeros(3), np.zeros(3), 0.1) == {}


@pytest.mark.parametrize("state, target, velocity, expected", [
    ([-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.4, 0.0, 0.0], 0.0),              # trailing: the velocity along the LOS
    ([-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.3, 0.0], math.pi / 2),      # the target crosses to the left
    ([1.0, 0.0, 0.0, math.pi], [0.0, 0.0, 0.0], [0.4, 0.0, 0.0], math.pi),       # the target comes at the vehicle
    ([-1.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.2, 0.0], math.pi / 4),     # LOS at 45 deg, velocity at 90
])
def test_the_bearing_by_hand(state, target, velocity, expected):
    assert abs(bearing(np.array(state), np.array(target), np.array(velocity))) == pytest.approx(expected)


def test_the_bearing_face_needs_the_targets_velocity_and_a_standing_target_is_outside():
    law = TerminalLaw(**GOOD, bearing_max=0.4)
    x, p = np.array([-0.7, 0.0, 0.1, 0.0]), np.zeros(3)
    with pytest.raises(ValueError, match="pd_dot"):
        law.slacks(x, p)
    assert law.slacks(x, p, np.array([0.4, 0.1, 0.0]))["terminal set: |bearing|"] == pytest.approx(0.4 - math.atan(0.25))
    assert law.slacks(x, p, np.zeros(3))["terminal set: |bearing|"] == -math.inf
    assert "terminal set: |bearing|" not in TerminalLaw(**GOOD).slacks(x, p)


def test_line_of_sight_by_hand():
    # vehicle at the origin heading +y, target 1 m along +x and 0.5 m above: alpha = pi/2 (target to starboard)
    d, alpha, e_z = line_of_sight(np.array([0.0, 0.0, 0.0, math.pi / 2]), np.array([1.0, 0.0, 0.5]))
    assert d == pytest.approx(1.0) and alpha == pytest.approx(math.pi / 2) and e_z == pytest.approx(-0.5)


def test_the_slacks_name_each_face():
    law = TerminalLaw(**GOOD)
    s = law.slacks(np.array([-0.7, 0.0, 0.1, 0.0]), np.array([0.0, 0.0, 0.0]))
    assert s["terminal set: d >= d_lo"] == pytest.approx(0.1) and s["terminal set: d <= d_hi"] == pytest.approx(0.2)
    assert s["terminal set: |alpha|"] == pytest.approx(0.06) and s["terminal set: |e_z|"] == pytest.approx(0.7)
    assert law.contains(np.array([-0.7, 0.0, 0.1, 0.0]), np.zeros(3))
    assert not law.contains(np.array([-0.7, 0.0, 0.1, 0.1]), np.zeros(3))


@settings(max_examples=60, deadline=None)
@given(d=st.floats(0.5, 2.0), alpha=st.floats(-0.3, 0.3), speed=st.floats(-0.2, 0.2), e_z=st.floats(-0.5, 0.5))
def test_the_arc_closes_the_radial_gap_by_lambda_delta(d, alpha, speed, e_z):
    """Property: against a target moving at constant velocity along the line of sight, one held row of the law
    moves the vehicle on the exact unicycle arc so that d' − d* = (1 − λδ)(d − d*) and e_z' = (1 − λ_z δ) e_z,
    and the heading turns by −g α (the design relation the proof uses; here with no lateral target motion)."""
    law = TerminalLaw(**{**GOOD, "d_lo": 0.4, "d_hi": 2.2, "d_star": 1.0})
    dt = 0.1
    x = np.array([-d, 0.0, e_z, alpha])            # target at the origin: line of sight along +x
    v_target = np.array([speed, 0.0, 0.0])
    row = law.command(x, np.zeros(3), v_target, dt)
    end = unicycle_step(x, row, dt)
    target_end = v_target * dt
    q = target_end[:2] - end[:2]
    assert q[0] == pytest.approx((1 - law.gain_d * dt) * (d - 1.0) + 1.0, abs=1e-12)
    assert end[2] - target_end[2] == pytest.approx((1 - law.gain_z * dt) * e_z, abs=1e-12)
    assert end[3] == pytest.approx(alpha * (1 - law.turn), abs=1e-12)
