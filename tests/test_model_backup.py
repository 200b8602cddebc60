"""The station-keeping backup law: its geometry, its inputs and its error table."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import (SafeSet, StationKeeping, axis_angle, axis_shape, line_of_sight_angle,
                                  station_keeping_input, yaw_shape)

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



# ---- fades and ramp (issue 22) -----------------------------------------------------------------

SMOOTH = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.5, heave=0.3, heave_band=0.1,
                        surge_fade=0.4, yaw_fade=0.2, ramp=2.0)


def test_the_command_starts_at_zero_at_the_hand_over():
    # far from the anchor, deep and abeam: every unramped channel would be at its largest
    assert station_keeping_input(SMOOTH, (3.0, 0.0, 1.0, math.pi / 2), (0.0, 0.0, 0.0), 0.0) == (0.0, 0.0, 0.0)


def test_the_ramp_scales_every_channel_by_the_elapsed_fraction():
    # d = 3 m (beyond both fades), deep (sat = 1), abeam (chi = pi/2): unramped w = -0.3, r = -0.5
    _, w, r = station_keeping_input(SMOOTH, (3.0, 0.0, 1.0, math.pi / 2), (0.0, 0.0, 0.0), 0.5)
    assert w == pytest.approx(-0.3 * 0.25) and r == pytest.approx(-0.5 * 0.25)
    # facing the anchor: u = u_b s / t_r
    u, _, _ = station_keeping_input(SMOOTH, (3.0, 0.0, 0.0, math.pi), (0.0, 0.0, 0.0), 1.5)
    assert u == pytest.approx(0.2 * 0.75)


def test_the_fades_scale_surge_and_yaw_by_the_distance():
    # d = 0.1 m facing the anchor: surge 0.2 * 0.1 / 0.4; abeam at d = 0.1: yaw 0.5 * 0.1 / 0.2 (after the ramp)
    u, _, _ = station_keeping_input(SMOOTH, (0.1, 0.0, 0.0, math.pi), (0.0, 0.0, 0.0), 10.0)
    _, _, r = station_keeping_input(SMOOTH, (0.1, 0.0, 0.0, math.pi / 2), (0.0, 0.0, 0.0), 10.0)
    assert u == pytest.approx(0.05) and r == pytest.approx(-0.25)


def test_the_smaller_of_fade_and_ramp_wins():
    # d = 0.1 m (fade 0.25) at s = 1 s (ramp 0.5): surge scaled by 0.25
    u, _, _ = station_keeping_input(SMOOTH, (0.1, 0.0, 0.0, math.pi), (0.0, 0.0, 0.0), 1.0)
    assert u == pytest.approx(0.2 * 0.25)


@given(x=st.floats(-3, 3), y=st.floats(-3, 3), z=st.floats(-1, 1), psi=st.floats(-7, 7))
def test_zero_fades_and_ramp_leave_the_law_unchanged(x, y, z, psi):
    """Property: a law with d_0 = d_1 = t_r = 0 gives the same input at every elapsed time as without them."""
    off = StationKeeping(0.2, 0.5, 0.05, 0.3, 0.01, surge_fade=0.0, yaw_fade=0.0, ramp=0.0)
    for s in (0.0, 0.3, math.inf):
        assert station_keeping_input(off, (x, y, z, psi), (0.0, 0.0, 0.0), s) == \
            station_keeping_input(LAW, (x, y, z, psi), (0.0, 0.0, 0.0))


def test_after_the_ramp_and_beyond_the_fades_the_law_is_the_unfaded_one():
    unfaded = StationKeeping(0.2, 0.5, 0.5, 0.3, 0.1)
    for state in [(1.0, 0.5, 0.05, 0.3), (-2.0, 1.0, -0.3, 2.5), (0.5, 0.0, 0.0, math.pi / 2)]:
        assert station_keeping_input(SMOOTH, state, (0.0, 0.0, 0.0), 2.0) == pytest.approx(
            station_keeping_input(unfaded, state, (0.0, 0.0, 0.0)))


def test_with_a_ramp_the_command_starts_at_the_hand_over_command_and_fades_it_out():
    start = (0.15, -0.1, 0.3)
    state = (3.0, 0.0, 1.0, math.pi / 2)  # unramped: u = 0 (abeam), w = -0.3, r = -0.5
    assert station_keeping_input(SMOOTH, state, (0.0, 0.0, 0.0), 0.0, start) == start
    u, w, r = station_keeping_input(SMOOTH, state, (0.0, 0.0, 0.0), 0.5, start)  # s / t_r = 0.25
    assert u == pytest.approx(0.75 * 0.15) and w == pytest.approx(-0.3 * 0.25 - 0.75 * 0.1)
    assert r == pytest.approx(-0.5 * 0.25 + 0.75 * 0.3)
    assert station_keeping_input(SMOOTH, state, (0.0, 0.0, 0.0), 2.0, start) == \
        station_keeping_input(SMOOTH, state, (0.0, 0.0, 0.0), 2.0)
    assert SMOOTH.blends and not LAW.blends


def test_without_a_ramp_the_hand_over_command_is_ignored():
    state = (1.0, 0.5, 0.05, 0.3)
    assert station_keeping_input(LAW, state, (0.0, 0.0, 0.0), 0.0, (0.2, 0.3, 0.5)) == \
        station_keeping_input(LAW, state, (0.0, 0.0, 0.0), 0.0)


@given(x=st.floats(-3, 3), y=st.floats(-3, 3), z=st.floats(-1, 1), psi=st.floats(-7, 7), s=st.floats(0, 5),
       a=st.floats(-1, 1), b=st.floats(-1, 1), c=st.floats(-1, 1))
def test_the_blended_command_never_leaves_the_box(x, y, z, psi, s, a, b, c):
    """Property: a hand-over command in V blended into the law stays in V (u_b, w_b, k inside V)."""
    start = (0.2 * a, 0.3 * b, 0.5 * c)
    u, w, r = station_keeping_input(SMOOTH, (x, y, z, psi), (0.0, 0.0, 0.0), s, start)
    assert abs(u) <= 0.2 and abs(w) <= 0.3 and abs(r) <= 0.5  # exactly: the loop would clip one ulp over


def test_the_blend_never_rounds_above_the_box():
    """Counterexample (review of issue 22): k R + (1 − R) r̄ with k = r̄ = 0.2 rounded to 0.20000000000000004 at some
    ticks of the ramp, which the loop clips (the safe tier promises no clipped tick). Every tick of a whole ramp,
    from corners of V, stays inside V exactly."""
    law = StationKeeping(surge=0.3, yaw_rate=0.2, yaw_band=0.3161, heave=0.15, heave_band=3.75, surge_fade=8.1455,
                         yaw_fade=8.1455, ramp=17.86, yaw_law="continuous", unstable=0.6322)
    for start in ((0.3, 0.0, 0.2), (-0.3, 0.15, -0.2), (0.3, -0.15, 0.2)):
        for psi in (1.2, -1.2, 2.0, 0.4):
            for k in range(1787):
                u, w, r = station_keeping_input(law, (0.1346, 0.0, 0.3, psi), (0.0, 0.0, 0.0), k * 0.01, start)
                assert abs(u) <= 0.3 and abs(w) <= 0.15 and abs(r) <= 0.2, (start, psi, k, (u, w, r))


def test_the_law_is_continuous_at_the_anchor_with_a_fade():
    # approaching the anchor from any heading the faded surge and yaw go to zero
    for psi in np.linspace(-3, 3, 7):
        u, _, r = station_keeping_input(SMOOTH, (1e-9, 0.0, 0.0, float(psi)), (0.0, 0.0, 0.0), 10.0)
        assert abs(u) < 1e-8 and abs(r) < 1e-8


@pytest.mark.parametrize("kwargs, match", [
    ({"surge_fade": -0.1}, "backup.surge_fade"),
    ({"yaw_fade": float("nan")}, "backup.yaw_fade"),
    ({"ramp": float("inf")}, "backup.ramp"),
])
def test_bad_fades_and_ramps_are_refused(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        StationKeeping(**{**dict(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01), **kwargs})


def test_smooth_needs_both_fades_and_the_ramp():
    assert SMOOTH.smooth and not LAW.smooth
    assert not StationKeeping(0.2, 0.5, 0.05, 0.3, 0.01, surge_fade=0.3, yaw_fade=0.3).smooth


# ---- the continuous yaw law (issue 22) -------------------------------------------------------------

CONT = StationKeeping(surge=0.4, yaw_rate=0.5, yaw_band=0.2, heave=0.3, heave_band=0.1, yaw_law="continuous",
                      unstable=0.6)


@pytest.mark.parametrize("chi, expected_r", [
    (0.1, -0.25),        # inside (0, χ_u): ρ = 0.1/0.2, turn back onto the line of sight
    (0.3, -0.5),         # ρ = min(1, 1.5, 1.5) = 1
    (0.55, -0.125),      # ρ = (0.6 − 0.55)/0.2
    (0.6, 0.0),          # the unstable zero
    (0.65, 0.125),       # past χ_u: ρ = −0.05/0.2, turn the long way round
    (math.pi / 2, 0.5),  # abeam: ρ = −1 on both sides
    (-math.pi / 2 + 1e-9, 0.5),
    (-0.1, 0.25),        # ρ(π − 0.1) = −0.1/0.2: from below, turn up to 0
])
def test_the_continuous_yaw_command_by_hand(chi, expected_r):
    # the vehicle at (1, 0), the anchor at the origin: φ = ψ − π, so ψ = π + χ
    _, _, r = station_keeping_input(CONT, (1.0, 0.0, 0.0, math.pi + chi), (0.0, 0.0, 0.0))
    assert r == pytest.approx(expected_r, abs=1e-7)


@given(st.floats(-4 * math.pi, 4 * math.pi), st.floats(1e-6, 0.05))
def test_the_continuous_yaw_command_is_lipschitz_in_heading(psi, step):
    """Property: |r(ψ + δ) − r(ψ)| <= k δ / χ_0 for every heading, across abeam included."""
    r0 = station_keeping_input(CONT, (1.0, 0.0, 0.0, psi), (0.0, 0.0, 0.0))[2]
    r1 = station_keeping_input(CONT, (1.0, 0.0, 0.0, psi + step), (0.0, 0.0, 0.0))[2]
    assert abs(r1 - r0) <= 0.5 * step / 0.2 * (1 + 1e-9) + 1e-12


def test_the_continuous_shape_by_hand():
    # a(0) = 0, a = 1 on the plateau [0.75 χ_u, χ_u] = [0.45, 0.6], a(0.3) = (1 − cos(π 0.3/0.45))/2 = 3/4,
    # a((χ_u + π)/2) = 1/2, a(π/2) = (1 − cos(π (π/2)/(π − 0.6)))/2
    assert axis_shape(CONT, 0.0) == 0.0 and axis_shape(CONT, 0.6) == pytest.approx(1.0)
    assert axis_shape(CONT, 0.5) == pytest.approx(1.0) and CONT.plateau == pytest.approx(0.45)
    assert axis_shape(CONT, 0.3) == pytest.approx(0.75) and axis_shape(CONT, (0.6 + math.pi) / 2) == pytest.approx(0.5)
    assert axis_shape(CONT, math.pi / 2) == pytest.approx(0.5 * (1 - math.cos(math.pi ** 2 / 2 / (math.pi - 0.6))))
    assert axis_shape(CONT, -0.2) == axis_shape(CONT, math.pi - 0.2)  # π-periodic
    assert axis_shape(LAW, 0.4) == pytest.approx(1 - math.cos(0.4)) and yaw_shape(CONT, 2.0) == -1.0
