"""verify.falsify.backup: the station-keeping safe set against adversarial currents from hand-over starts."""

from __future__ import annotations

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
