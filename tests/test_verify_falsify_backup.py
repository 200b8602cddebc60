"""verify.falsify.backup: the station-keeping safe set against adversarial currents from hand-over starts."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupPlan, SafeSet, StationKeeping
from verify.falsify.backup import BACKUP_START_DIM, backup_lyapunov, falsify_backup, handover_start

LAW = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01)
#: The set verify.backup certifies on the paper's currents (tests/test_verify_backup.py).
PLAN = BackupPlan(LAW, SafeSet(level=0.75, shape=0.4, depth=0.1), handover=(0.35, 0.05))


@pytest.mark.parametrize("state, expected", [
    ([1.0, 0.0, 0.0, math.pi], 1.0),                 # facing the anchor: V = d
    ([1.0, 0.0, 0.0, 0.0], 1.0),                     # facing away (astern): chi = 0 too
    ([1.0, 0.0, 0.0, math.pi / 2], 1.0 + 0.4),       # abeam: V = d + beta
    ([0.0, 2.0, 5.0, 3 * math.pi / 2], 2.0),         # depth does not enter V
])
def test_lyapunov_value_from_the_geometry(state, expected):
    assert backup_lyapunov(np.array(state), np.zeros(3), 0.4) == pytest.approx(expected, abs=1e-12)


def test_handover_starts_lie_on_the_handover_circle():
    for u in np.random.default_rng(3).uniform(0, 1, (20, BACKUP_START_DIM)):
        s = handover_start(PLAN, u)
        assert math.hypot(s[0], s[1]) == pytest.approx(0.35)
        assert abs(s[2]) <= 0.05 + 1e-12


def test_the_certified_set_survives_and_the_attack_gets_close():
    """Greedy and evolution within the certified currents: V stays <= c, and the worst run is near c."""
    result = falsify_backup(PLAN, omega_xy=0.12, omega_z=0.1, tick=0.01, budget=6, seconds=8.0, seed=1)
    assert result.check(), result.summary()
    assert 0.9 < result.worst.level_ratio <= 1.0
    assert all(r.depth_ratio <= 1.0 for r in result.runs)
    assert result.to_dict()["simulations"] == 6


def test_a_current_faster_than_the_surge_pushes_the_vehicle_out():
    result = falsify_backup(PLAN, omega_xy=0.3, omega_z=0.1, tick=0.01, budget=1, seconds=8.0)
    assert result.found and not result.check()
    assert result.worst.left and result.worst.level_ratio > 1.0
    assert "COUNTEREXAMPLE" in result.summary()


def test_the_search_is_deterministic_for_a_seed():
    a = falsify_backup(PLAN, omega_xy=0.12, omega_z=0.1, tick=0.01, budget=3, seconds=2.0, seed=5)
    b = falsify_backup(PLAN, omega_xy=0.12, omega_z=0.1, tick=0.01, budget=3, seconds=2.0, seed=5)
    assert a.runs == b.runs


@pytest.mark.parametrize("kwargs, match", [
    ({"budget": 0}, "budget"),
    ({"budget": True}, "budget"),
    ({"seconds": -1.0}, "seconds"),
    ({"piece": 0.0}, "piece"),
    ({"tick": math.nan}, "tick"),
])
def test_bad_arguments_are_refused(kwargs, match):
    args = {"omega_xy": 0.12, "omega_z": 0.1, "tick": 0.01, **kwargs}
    with pytest.raises(ConfigError, match=match):
        falsify_backup(PLAN, **args)


# ---- the smooth law (issue 22) -----------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _smooth_plan(omega_xy: float, yaw_rate_error: float) -> BackupPlan:
    from verify.backup import design_backup
    cert = design_backup(omega_xy=omega_xy, omega_z=0.1, limits=(0.4, 0.3, 0.5), tick=0.01, handover=(0.125, 0.08),
                         smooth=True, yaw_rate_error=yaw_rate_error)
    assert cert.certified
    return BackupPlan(cert.law, cert.safe_set, handover=(0.125, 0.08))


@pytest.mark.parametrize("omega_xy, yaw_rate_error, command", [(0.12, 0.0, (0.0, 0.0, 0.0)),
                                                                 (0.2, 0.05, (0.0, 0.0, 0.0)),
                                                                 (0.12, 0.0, (0.4, 0.3, 0.5))])
def test_the_certified_smooth_set_survives_the_search(omega_xy, yaw_rate_error, command):
    """Greedy and evolution from hand-over starts, the ramp running from s = 0 (blending the hand-over's command, a
    corner of V in the last case), the adversary choosing the yaw error."""
    plan = _smooth_plan(omega_xy, yaw_rate_error)
    result = falsify_backup(plan, omega_xy=omega_xy, omega_z=0.1, tick=0.01, budget=5, seconds=4.0, seed=2,
                            yaw_rate_error=yaw_rate_error, command=command)
    assert plan.law.yaw_law == "continuous"  # the smooth design's yaw law has no jump abeam
    assert result.check(), result.summary()
    assert result.worst.level_ratio > 0.3  # the attack is not idle: V is pushed from <= 0.125 + β towards c


def test_a_ramp_longer_than_the_window_is_refused_and_the_adversary_exits():
    """A ramp of 100 s (``backup_ramp`` allows about 1.2 s): the certificate refuses it, and the current carries the
    weak law's vehicle out of the set before the ramp ends."""
    import dataclasses

    from verify.backup import certify_backup
    plan = _smooth_plan(0.12, 0.0)
    slow = BackupPlan(dataclasses.replace(plan.law, ramp=100.0), plan.safe_set, handover=plan.handover)
    cert = certify_backup(slow.law, slow.safe_set, omega_xy=0.12, omega_z=0.1, limits=(0.4, 0.3, 0.5), tick=0.01,
                          handover=plan.handover)
    assert {c.condition for c in cert.failures} == {"backup_ramp"}
    result = falsify_backup(slow, omega_xy=0.12, omega_z=0.1, tick=0.01, budget=1, seconds=8.0, seed=0)
    assert result.found and result.worst.left


def test_a_bad_yaw_rate_error_is_refused():
    with pytest.raises(ConfigError, match="yaw_rate_error"):
        falsify_backup(PLAN, omega_xy=0.12, omega_z=0.1, tick=0.01, yaw_rate_error=-0.1)


def test_the_continuous_law_s_lyapunov_function_by_hand():
    # at (1, 0) heading π + χ_u the axis is at the unstable angle: a = 1, V = 1 + β; heading π: V = 1;
    # heading π/2 (abeam): a = (1 − cos(π (π/2)/(π − χ_u)))/2
    law = StationKeeping(0.4, 0.5, 0.5, 0.3, 0.1, yaw_law="continuous", unstable=0.6)
    assert backup_lyapunov(np.array([1.0, 0.0, 0.0, math.pi + 0.6]), np.zeros(3), 0.4, law) == pytest.approx(1.4)
    assert backup_lyapunov(np.array([1.0, 0.0, 0.0, math.pi]), np.zeros(3), 0.4, law) == pytest.approx(1.0)
    abeam = 1.0 + 0.4 * 0.5 * (1 - math.cos(math.pi * (math.pi / 2) / (math.pi - 0.6)))
    assert backup_lyapunov(np.array([1.0, 0.0, 0.0, math.pi / 2]), np.zeros(3), 0.4, law) == pytest.approx(abeam)
