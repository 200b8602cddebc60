"""The backup law's safe set: the Arb proof, its conditions, and independent adversarial simulations."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import StationKeeping, axis_angle, line_of_sight_angle
from tubekit.model.backup import SafeSet
from verify.backup import certify_backup, design_backup, planar_rate_bound
from verify.backup.proof import held_rate_sampled

LIMITS = (0.4, 0.3, 0.5)  # the paper's V
TICK = 0.01  # 100 Hz ancillary rate
LAW = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01)
SAFE = SafeSet(level=0.75, shape=0.4, depth=0.1)


@functools.lru_cache(maxsize=None)
def _smooth_design():
    """The smooth design on the paper's currents (5 s: computed once for this file)."""
    return design_backup(omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.125, 0.08), smooth=True)


def _lyapunov(state: np.ndarray, safe: SafeSet, unstable: float = 0.0) -> float:
    """V = d + beta (1 - cos chi), or with χ_u > 0 the continuous law's V = d + beta a(chi) (a: half a cosine wave
    up on [0, 0.75 χ_u], 1 up to χ_u, down on [χ_u, π]), computed here from the geometry (not from verify)."""
    d = math.hypot(state[0], state[1])
    phi = line_of_sight_angle(state[0], state[1], state[3], 0.0, 0.0)
    if unstable == 0.0:
        return d + safe.shape * (1.0 - math.cos(axis_angle(phi)))
    x = phi % math.pi
    wave = min(1.0, x / (0.75 * unstable)) if x <= unstable else (math.pi - x) / (math.pi - unstable)
    return d + safe.shape * 0.5 * (1.0 - math.cos(math.pi * wave))


def _tick(state: np.ndarray, v: np.ndarray, omega: np.ndarray, h: float, n: int = 4) -> np.ndarray:
    """RK4 of x' = f(x) v + omega over one tick, v and omega held."""
    def rhs(x):
        return np.array([v[0] * math.cos(x[3]) + omega[0], v[0] * math.sin(x[3]) + omega[1], v[1] + omega[2], v[2]])
    dt = h / n
    for _ in range(n):
        k1 = rhs(state); k2 = rhs(state + 0.5 * dt * k1); k3 = rhs(state + 0.5 * dt * k2); k4 = rhs(state + dt * k3)
        state = state + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return state


def _adversarial_run(law, safe, start, omega_xy, omega_z, seconds, directions=8):
    """Greedy adversary: each tick, the current direction (of ``directions``) that ends the tick at the largest V."""
    angles = np.linspace(0.0, 2 * math.pi, directions, endpoint=False)
    state, worst, worst_z = np.asarray(start, float), 0.0, 0.0
    for _ in range(int(round(seconds / TICK))):
        v = law(state, np.zeros(3))
        wz = omega_z if state[2] >= 0 else -omega_z
        nxt = [_tick(state, v, np.array([omega_xy * math.cos(a), omega_xy * math.sin(a), wz]), TICK) for a in angles]
        state = max(nxt, key=lambda s: _lyapunov(s, safe))
        worst, worst_z = max(worst, _lyapunov(state, safe)), max(worst_z, abs(state[2]))
    return worst, worst_z, state


def test_the_paper_currents_certify_a_station_keeping_set():
    cert = certify_backup(LAW, SAFE, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.05, 0.02))
    assert cert.certified, cert.summary_lines()
    assert cert.rate_bound < 0
    assert cert.rate_sampled <= cert.rate_bound  # a sampled value never exceeds the certified bound


@pytest.mark.parametrize("heading", [0.0, 1.0, math.pi / 2, 2.5, math.pi])
def test_an_adversary_cannot_push_the_vehicle_out(heading):
    """Starts on the hand-over circle (d = c - beta) with every kind of heading; 30 s of worst-case current."""
    start = [SAFE.handover_radius, 0.0, 0.09, heading]
    worst, worst_z, _ = _adversarial_run(LAW, SAFE, start, 0.12, 0.1, seconds=30.0)
    assert worst <= SAFE.level
    assert worst_z <= SAFE.depth


def test_a_current_faster_than_the_surge_is_refused_and_escapes():
    cert = certify_backup(LAW, SAFE, omega_xy=0.25, omega_z=0.1, limits=LIMITS, tick=TICK)
    assert not cert.certified
    assert "backup_level_set" in {c.condition for c in cert.failures}
    # the counterexample: a steady 0.25 m/s current carries the vehicle out of the set
    state = np.array([0.0, 0.0, 0.0, math.pi])
    for _ in range(3000):
        state = _tick(state, LAW(state, np.zeros(3)), np.array([0.25, 0.0, 0.0]), TICK)
    assert math.hypot(state[0], state[1]) > SAFE.level


@pytest.mark.parametrize("kwargs, failed", [
    ({"handover": (0.5, 0.0)}, "backup_handover"),
    ({"handover": (0.0, 0.5)}, "backup_handover_depth"),
    ({"omega_z": 0.35}, "backup_heave"),
    ({"limits": (0.1, 0.3, 0.5)}, "backup_inputs"),
    ({"tick": 0.5}, "backup_ridge"),
])
def test_each_condition_names_its_failure(kwargs, failed):
    args = {**dict(omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.05, 0.02)), **kwargs}
    cert = certify_backup(LAW, SAFE, **args)
    assert failed in {c.condition for c in cert.failures}


def test_a_level_set_too_close_to_the_anchor_has_no_tick_room():
    bound, boxes = planar_rate_bound(LAW, SafeSet(level=0.4, shape=0.399, depth=0.1), 0.12, TICK)
    assert bound == math.inf and boxes == 0


@pytest.mark.parametrize("kwargs, match", [
    ({"omega_xy": -0.1}, "omega_xy"),
    ({"tick": 0.0}, "tick"),
    ({"handover": (float("nan"), 0.0)}, r"handover\[0\]"),
])
def test_bad_arguments_are_refused(kwargs, match):
    args = {**dict(omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK), **kwargs}
    with pytest.raises(ConfigError, match=match):
        certify_backup(LAW, SAFE, **args)



def test_a_smaller_set_is_refused_and_the_adversary_leaves_it():
    """The proof is not vacuous: a set the adversary can leave is not certified."""
    small = SafeSet(level=0.5, shape=0.3, depth=0.1)
    cert = certify_backup(LAW, small, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK)
    assert not cert.certified
    worst, _, _ = _adversarial_run(LAW, small, [small.handover_radius, 0.0, 0.0, math.pi / 2], 0.12, 0.1, 30.0)
    assert worst > small.level


# ---- fades, ramp and the yaw-rate error (issue 22) ---------------------------------------------

import dataclasses  # noqa: E402

from verify.backup import BackupCertificate, ramp_window  # noqa: E402

#: d_tick = c − β − h (u_b + ω̄_xy) = 0.75 − 0.4 − 0.01 * 0.32 = 0.3468 m on the paper's currents.
D_TICK = 0.75 - 0.4 - 0.01 * 0.32
FADED = dataclasses.replace(LAW, surge_fade=0.3, yaw_fade=0.3, ramp=0.5)
DEEP = SafeSet(level=0.75, shape=0.4, depth=0.4)


def _names(cert) -> set[str]:
    return {c.condition for c in cert.conditions}


def test_an_unfaded_law_keeps_the_conditions_it_had():
    cert = certify_backup(LAW, SAFE, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK)
    assert not {"backup_fade", "backup_ramp"} & _names(cert)
    assert len(cert.conditions) == 8


def test_a_faded_ramped_law_certifies_with_its_two_conditions():
    # ramp window (the ramp blends the hand-over's command, anywhere in V, so the speeds are u_max, w_max):
    # (0.75 − 0.4 − 0.05)/(0.4 + 0.12) = 0.5769 s horizontally, (0.4 − 0.02)/(0.3 + 0.1) = 0.95 s in depth
    cert = certify_backup(FADED, DEEP, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.05, 0.02))
    assert cert.certified, cert.summary_lines()
    fade = next(c for c in cert.conditions if c.condition == "backup_fade")
    ramp = next(c for c in cert.conditions if c.condition == "backup_ramp")
    assert fade.lhs == 0.3 and fade.rhs == pytest.approx(D_TICK)
    assert ramp.lhs == pytest.approx(0.51) and ramp.rhs == pytest.approx(0.3 / 0.52)
    assert ramp_window(FADED, DEEP, omega_xy=0.12, omega_z=0.1, tick=TICK, handover=(0.05, 0.02),
                       limits=LIMITS) == pytest.approx(0.3 / 0.52 - 0.01)


@pytest.mark.parametrize("law, safe, failed", [
    (dataclasses.replace(FADED, yaw_fade=0.35), DEEP, "backup_fade"),     # 0.35 > d_tick = 0.3468
    (dataclasses.replace(FADED, ramp=0.57), DEEP, "backup_ramp"),         # 0.58 > 0.3 / 0.52 = 0.5769
    (FADED, SafeSet(level=0.75, shape=0.4, depth=0.2), "backup_ramp"),    # (0.2 − 0.02)/0.4 = 0.45 < 0.51
])
def test_a_fade_or_ramp_too_long_is_refused(law, safe, failed):
    cert = certify_backup(law, safe, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.05, 0.02))
    assert {c.condition for c in cert.failures} == {failed}


def test_the_yaw_rate_error_widens_the_level_set_rate_and_the_ridge():
    base, _ = planar_rate_bound(LAW, SAFE, 0.12, TICK)
    wide, _ = planar_rate_bound(LAW, SAFE, 0.12, TICK, yaw_rate_error=0.05)
    assert wide > base
    # E_r = 0.2: the ridge needs (u_b sin 2Δ + ω̄_xy)/d_tick + E_r < k; 0.12/0.3468 + 0.2 > 0.5 already
    cert = certify_backup(LAW, SAFE, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, yaw_rate_error=0.2)
    assert "backup_ridge" in {c.condition for c in cert.failures}
    ridge = next(c for c in cert.conditions if c.condition == "backup_ridge")
    assert ridge.lhs > 0.12 / D_TICK + 0.2 and "E_r" in ridge.inequality


def test_the_smooth_certificate_round_trips_and_an_old_one_still_reads():
    cert = certify_backup(FADED, DEEP, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.05, 0.02),
                          yaw_rate_error=0.01)
    assert BackupCertificate.from_dict(cert.to_dict()) == cert
    old = certify_backup(LAW, SAFE, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK).to_dict()
    # an unfaded law at E_r = 0 writes the keys it wrote before issue 22, and its kind (issue 30)
    assert set(old["law"]) == {"kind", "surge", "yaw_rate", "yaw_band", "heave", "heave_band"}
    assert old["law"]["kind"] == "station_keeping" and "yaw_rate_error" not in old
    assert BackupCertificate.from_dict(old).law == LAW
    del old["law"]["kind"]  # a certificate written before issue 30 stored no kind: station keeping
    assert BackupCertificate.from_dict(old).law == LAW


def test_a_stored_negative_ramp_is_refused_naming_it():
    d = certify_backup(FADED, DEEP, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK).to_dict()
    d["law"]["ramp"] = -1.0
    with pytest.raises(ConfigError, match=r"certificate\.backup\.law\.ramp"):
        BackupCertificate.from_dict(d)


@pytest.mark.parametrize("start", [(0.0, 0.0, 0.0), (0.4, 0.3, 0.5), (-0.4, 0.3, -0.5)])
def test_the_smooth_law_resists_the_adversary_from_the_hand_over(start):
    """The greedy adversary of this file, with the ramp running from the hand-over (s = 0) and blending the
    hand-over's command out of a corner of V (surging away from the anchor, heaving down)."""
    cert = _smooth_design()
    law, s = cert.law, cert.safe_set
    angles = np.linspace(0.0, 2 * math.pi, 8, endpoint=False)
    for heading in (0.0, math.pi / 2, 2.5):
        state = np.array([0.125, 0.0, 0.08, heading])
        worst = worst_z = 0.0
        for k in range(1000):
            v = law(state, np.zeros(3), k * TICK, start)
            wz = 0.1 if state[2] >= 0 else -0.1
            nxt = [_tick(state, v, np.array([0.12 * math.cos(a), 0.12 * math.sin(a), wz]), TICK) for a in angles]
            state = max(nxt, key=lambda x: _lyapunov(x, s, law.unstable))
            worst, worst_z = max(worst, _lyapunov(state, s, law.unstable)), max(worst_z, abs(state[2]))
        assert worst <= s.level and worst_z <= s.depth


def test_the_sampled_rate_of_many_shapes_at_once_is_each_shapes_own_to_the_bit():
    """rates_sampled (the shape search's screen, every shape in one array) gives, per shape, exactly the float of
    V̇ sampled at 721 χ in [0, π/2] for that shape alone (written out here, one shape at a time), on a grid of shapes
    up to the level and a few currents; and rate_sampled is its entry."""
    from verify.backup.proof import rate_sampled, rates_sampled

    def alone(beta: float, omega: float, e_r: float) -> float:
        chi = np.linspace(0.0, math.pi / 2, 721)
        gp, d = beta * np.sin(chi), 1.5 - beta * (1 - np.cos(chi))
        r = -LAW.yaw_rate * np.clip(chi / LAW.yaw_band, -1.0, 1.0)
        u = LAW.surge * np.cos(chi)
        return float((-u * np.cos(chi) + omega * np.sqrt(1 + (gp / d) ** 2)
                      + gp * (r + e_r + u * np.sin(chi) / d)).max())
    shapes = np.round(np.arange(0.05, 1.5, 0.05), 6)
    for omega in (0.0, 0.05, 0.3):
        together = rates_sampled(LAW, 1.5, shapes, omega, yaw_err=0.01)
        assert together.tolist() == [alone(float(b), omega, 0.01) for b in shapes]
        assert rate_sampled(LAW, SafeSet(level=1.5, shape=0.5, depth=1.0), omega, yaw_err=0.01) == together[9]


@st.composite
def _station_keeping(draw, yaw_law: str):
    """A station-keeping law with the yaw law ``yaw_law`` and a safe set around it with room for a tick."""
    continuous = yaw_law == "continuous"
    law = StationKeeping(surge=draw(st.floats(0.15, 0.5)), yaw_rate=draw(st.floats(0.1, 1.0)),
                         yaw_band=draw(st.floats(0.02, 0.3)), heave=0.3, heave_band=0.01, yaw_law=yaw_law,
                         unstable=draw(st.floats(0.3, 1.2)) if continuous else 0.0)
    shape = draw(st.floats(0.05, 1.0))
    return law, SafeSet(level=shape + draw(st.floats(0.05, 2.0)), shape=shape, depth=0.1)


@pytest.mark.parametrize("yaw_law", ["ridge", "continuous"])
@settings(max_examples=25, deadline=None, derandomize=True)
@given(data=st.data(), omega_xy=st.floats(0.0, 0.3), yaw_err=st.floats(0.0, 0.2))
def test_the_bisections_bound_is_at_least_every_sampled_held_rate(yaw_law, data, omega_xy, yaw_err):
    """Property: the Arb bisection's bound of V̇ on V = c is at least every sampled held rate (the values the search
    reads to refute a candidate before its proof), for both yaw laws, with or without a yaw-rate error; so a
    positive sample means ``backup_level_set`` fails."""
    law, safe = data.draw(_station_keeping(yaw_law))
    sampled = held_rate_sampled(law, safe, omega_xy, TICK, yaw_err=yaw_err)
    bound, _ = planar_rate_bound(law, safe, omega_xy, TICK, 1024, yaw_err)
    assert bound >= sampled - 1e-12
    if sampled > 0.0:
        cert = certify_backup(law, safe, omega_xy=omega_xy, omega_z=0.1, limits=LIMITS, tick=TICK,
                              max_boxes=1024, yaw_rate_error=yaw_err)
        assert not cert.certified and "backup_level_set" in [c.condition for c in cert.failures]


def test_the_held_rate_is_the_no_hold_rate_when_the_tick_does_not_move_the_angle():
    """With the input held for no angle (Δ = 0 when the tick is tiny) the held rate is the sampled rate of the same
    instant: the two samplers agree on the ridge law to a float's rounding at the tick's Δ."""
    from verify.backup.proof import rate_sampled
    assert held_rate_sampled(LAW, SAFE, 0.12, 1e-9) == pytest.approx(rate_sampled(LAW, SAFE, 0.12), abs=1e-7)
