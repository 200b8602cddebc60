"""verify.falsify.backup_loop: disturbance sequences against runs of the loop in which the backup may engage."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import verify
from tubekit import load_scenario
from tubekit.exceptions import ConfigError
from tubekit.scenario import Obstacle
from verify.falsify.backup_loop import falsify_backup_loop, push_disturbance

from .scripts import load_script

BASE = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
MISSION = load_script("benchmarks/mission.py", "mission_benchmark")


def test_push_points_at_the_nearest_obstacle_at_the_bound():
    sc = BASE.with_changes(obstacles=(Obstacle((10.0, 0.0, 1.0), 0.5), Obstacle((-10.0, 0.0, -1.0), 0.5)))
    omega = push_disturbance(sc, 0.12, 0.1)
    for t in (0.0, 3.0, 17.0):
        w = np.asarray(omega(t))
        p = np.asarray(sc.trajectory.position(np.array([t]))[0])
        o = np.array([10.0, 0.0, 1.0]) if p[0] >= 0 else np.array([-10.0, 0.0, -1.0])
        assert math.hypot(w[0], w[1]) == pytest.approx(0.12)
        assert np.dot(w[:2], (o - p)[:2]) > 0.99 * 0.12 * np.linalg.norm((o - p)[:2])
        assert w[2] == pytest.approx(math.copysign(0.1, o[2] - p[2]))


def test_no_obstacle_no_push():
    assert push_disturbance(BASE.with_changes(obstacles=()), 0.12, 0.1)(1.0) == (0.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def result(pc_cert):
    return falsify_backup_loop(BASE, pc_cert.tightening, budget=3, seed=2, duration=4.0)


def test_the_certified_design_keeps_its_safety_promises(result):
    assert result.check(), result.summary()
    assert len(result.runs) == 3 and result.runs[0].strategy == "push"
    assert all(r.certified and r.min_clearance > 0 for r in result.runs)
    assert result.worst.fitness() == max(r.fitness() for r in result.runs)
    assert result.to_dict()["simulations"] == 3


@pytest.mark.parametrize("kwargs, match", [({"budget": 0}, "budget"), ({"duration": -1.0}, "duration")])
def test_bad_arguments_are_refused(pc_cert, kwargs, match):
    with pytest.raises(ConfigError, match=match):
        falsify_backup_loop(BASE, pc_cert.tightening, **kwargs)


#: The FHOCP fails from this time on in the transit (s): the vehicle is then abreast of the first rock (the push run's
#: smallest clearance was 0.44 m, V / c 0.71 at the time of writing).
BLIND_FROM = 32.0


class _BlindAfter:
    """The shipped SCP until :data:`BLIND_FROM`, then a failed solve every period (a NaN first input, flagged)."""

    def __init__(self, scenario, tightening):
        from tubekit.fhocp import FHOCP
        self.inner = FHOCP(scenario, tightening)

    def solve(self, t, state, obstacles):
        res = self.inner.solve(t, state, obstacles)
        if t < BLIND_FROM:
            return res
        inputs = np.array(res.inputs, dtype=float)
        inputs[0] = np.nan
        return dataclasses.replace(res, inputs=inputs, fallback=True, status="fallback")


@pytest.fixture
def blind_backend(monkeypatch):
    """A backend named "blind-after" (:class:`_BlindAfter`) registered for one test."""
    from tubekit.fhocp import registry
    monkeypatch.setattr(registry, "_BACKENDS", dict(registry._BACKENDS))
    registry.register_backend("blind-after", _BlindAfter)
    return "blind-after"


def _transit_scenario(backend: str):
    """The transit past two rocks 0.9 m off its line (``benchmarks/mission.py``), 40 s, without the shifted
    candidate and the recovery plans, its FHOCP failing from :data:`BLIND_FROM` on: its certificate gives the safe
    tier alone (the rocks are too near the path for the tracking theorem), the last accepted plan is replayed,
    then the backup holds the vehicle beside the first rock about the anchor that plan's terminal condition chose,
    with the current pushed toward the rock: what this test exercises."""
    return MISSION.transit().with_changes(duration=40.0, **{"controller.candidate": False,
                                                             "controller.recovery": False,
                                                             "controller.fhocp_backend": backend})


def test_the_backup_engages_near_the_rocks_and_keeps_every_safety_promise(blind_backend):
    """The FHOCP fails near the rocks and the loop hands over to the backup; V stays below c while it runs,
    under the push toward the rock and one evolved disturbance."""
    sc = _transit_scenario(blind_backend)
    cert = verify.certify(sc)
    assert cert.tiers.safe and cert.tightening.backup is not None and cert.tightening.backup.anchor_reach > 0.0
    result = falsify_backup_loop(sc, cert.tightening, budget=2, seed=0)
    assert result.check(), result.summary()
    engaged = [r for r in result.runs if r.backup_s > 0]
    assert len(engaged) == 2, result.summary()
    assert all(r.backup_s >= 40.0 - BLIND_FROM - sc.controller.horizon_steps * sc.controller.dt - 1e-9
               for r in engaged)
    assert all(0.0 < r.level_ratio <= 1.0 for r in engaged)
    assert all(r.min_clearance > 0 for r in result.runs)
