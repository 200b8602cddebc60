"""The backup law's safe set: the Arb proof, its conditions, and independent adversarial simulations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.backup import StationKeeping, axis_angle, line_of_sight_angle
from tubekit.model.backup import SafeSet
from verify.backup import certify_backup, design_backup, planar_rate_bound

LIMITS = (0.4, 0.3, 0.5)  # the paper's V
TICK = 0.01  # 100 Hz ancillary rate
LAW = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01)
SAFE = SafeSet(level=0.75, shape=0.4, depth=0.1)


def _lyapunov(state: np.ndarray, safe: SafeSet) -> float:
    """V = d + beta (1 - cos chi), computed here from the geometry (not from verify)."""
    d = math.hypot(state[0], state[1])
    phi = line_of_sight_angle(state[0], state[1], state[3], 0.0, 0.0)
    return d + safe.shape * (1.0 - math.cos(axis_angle(phi)))


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


def test_design_finds_a_certified_set_no_larger_than_the_hand_picked_one():
    cert = design_backup(omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.05, 0.02))
    assert cert.certified and cert.safe_set.radius <= SAFE.level
    assert cert.to_dict()["certified"] is True


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
