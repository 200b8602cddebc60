"""tubekit.loop.pipeline: one certified run (simulate -> metrics -> promises) as a frozen, typed result."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from tubekit.jsonable import dumps
from tubekit.loop.pipeline import CertifiedRun, certified_run
from tubekit.loop.promises import check_promises
from tubekit.model.backup import BackupPlan, axis_angle, line_of_sight_angle
from tubekit.model.trajectory import Line
from tubekit.scenario import Obstacle
from tubekit.scenario import paper_scenario
from tubekit.tiers import Tiers
from tubekit.tightening import DisturbanceBound, Tightening

pytest.importorskip("tubekit.fhocp")


@pytest.fixture(scope="module")
def short():
    return paper_scenario().with_changes(duration=1.0)


@pytest.fixture(scope="module")
def zero_tube_certified(short):
    """A run under a tightening flagged certified whose tube is zero, its disturbance bound covering the
    scenario's current (so the premises hold): any disturbed run breaks the tube promise."""
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.5, tiers=Tiers(True, True),
                                disturbance=DisturbanceBound(1.0, 1.0, 1.0))
    return certified_run(short, tight)


def test_the_run_its_metrics_and_its_promises_agree(zero_tube_certified):
    done = zero_tube_certified
    assert isinstance(done, CertifiedRun)
    assert done.metrics == done.run.metrics  # one convention: the pipeline's metrics are the run's
    assert [p.to_dict() for p in done.promises] == [p.to_dict() for p in check_promises(done.run)]
    assert done.to_dict() == done.metrics and json.loads(dumps(done.to_dict())) == done.metrics
    with pytest.raises(dataclasses.FrozenInstanceError):
        done.metrics = {}  # type: ignore[misc]


def test_a_certified_run_that_breaks_a_promise_fails_its_check(zero_tube_certified):
    done = zero_tube_certified
    by_name = {p.name: p for p in done.promises}
    assert math.isinf(by_name["tube"].observed) and done.ratio == by_name["tube"].observed
    assert by_name["disturbance"].ok and by_name["recursive_feasibility"].ok and done.premises_held
    assert done.certified and not done.promises_kept and done.check() is False
    assert "tube" in done.broken and done.metrics["promises_broken"] == list(done.broken)
    assert "broken: " in done.summary() and "tube" in done.summary().split("broken: ")[1]
    assert done.tiers == Tiers(True, True)
    line = done.summary()
    assert "\n" not in line and "certified" in line and "tube" in line


def test_a_premise_failure_is_never_a_broken_promise(short):
    """The same zero tube, but a zero disturbance bound: the premise fails, so nothing is broken."""
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.5, tiers=Tiers(True, True))
    done = certified_run(short, tight)
    by_name = {p.name: p for p in done.promises}
    assert not by_name["disturbance"].ok and not by_name["tube"].ok
    assert not done.premises_held and done.broken == () and done.check() is True
    line = done.summary()
    assert "premises failed: disturbance" in line and "broken:" not in line and "tube" in line


def test_a_tier_the_certificate_did_not_give_is_reported_but_never_broken(short):
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.0,
                                disturbance=DisturbanceBound(1.0, 1.0, 1.0), tiers=Tiers(True, False))
    done = certified_run(short, tight)
    by_name = {p.name: p for p in done.promises}
    assert not by_name["tube"].ok and by_name["tube"].tier == "tracking" and not by_name["tube"].given
    assert done.broken == () and done.check() is True and done.tiers == Tiers(True, False)


def test_the_same_run_uncertified_claims_nothing(short):
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.5)
    done = certified_run(short, tight)
    assert not done.certified and not done.promises_kept and done.check() is True
    assert done.metrics["rho_bound"] is None and done.metrics["certified"] is False


def test_the_baseline_has_no_promises(short):
    done = certified_run(short, Tightening.untightened(short), tube=False, label="baseline")
    assert done.promises == () and done.broken == () and math.isnan(done.ratio)
    assert done.check() is True and done.metrics["promises"] == [] and done.metrics["tube"] is False
    assert done.run.sigma == 0.0 and np.all(done.run.kappa[:-1] == 0.0)


def test_a_disturbance_override_reaches_the_plant(short):
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.5)
    done = certified_run(short, tight, disturbance=lambda t: (0.01, -0.02, 0.0))
    assert done.run.omega_overridden
    np.testing.assert_allclose(done.run.omega[:-1, :2], np.tile([0.01, -0.02], (len(done.run.t) - 1, 1)),
                               atol=1e-9)


class BetweenTicks:
    """ω within the bound at every tick instant (multiples of 0.01 s) but three times over in between."""

    def __init__(self, bound: float, tick: float = 0.01) -> None:
        self.bound, self.tick = bound, tick

    def __call__(self, t: float) -> np.ndarray:
        phase = t / self.tick - round(t / self.tick)
        return np.array([self.bound if abs(phase) < 1e-6 else 3.0 * self.bound, 0.0, 0.0])


def test_a_disturbance_over_its_bound_between_ticks_fails_the_premise_not_a_promise(short):
    """The issue's counterexample: the ticks see 0.12 m/s, the plant receives 0.36 m/s in between."""
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.0, tiers=Tiers(True, True),
                                disturbance=DisturbanceBound(0.12, 0.1, 0.0))
    done = certified_run(short, tight, disturbance=BetweenTicks(0.12))
    ticks = done.run.omega[:-1]
    assert np.max(np.hypot(ticks[:, 0], ticks[:, 1])) == pytest.approx(0.12)  # the ticks alone look fine
    by_name = {p.name: p for p in done.promises}
    assert not by_name["disturbance"].ok and by_name["disturbance"].observed == pytest.approx(0.24)
    assert done.run.omega_peak[0] == pytest.approx(0.36)
    assert not done.premises_held and done.broken == () and done.check() is True


@pytest.fixture(scope="module")
def runaway():
    """The target runs away at 0.6 m/s (ū = 0.4) past an obstacle cluster: plans stop passing, the backup engages.

    The backup is the one verify.backup.design_backup certifies on the paper's bounds; the tightening is a
    stand-in (2 cm margins) flagged certified for both tiers, its disturbance bound the paper's 0.12 / 0.1.
    """
    from verify.backup import design_backup
    cert = design_backup(omega_xy=0.12, omega_z=0.1, limits=(0.4, 0.3, 0.5), tick=0.01, handover=(0.35, 0.1))
    assert cert.certified
    sc = paper_scenario().with_changes(
        duration=20.0, trajectory=Line(start=(1.0, 3.0, 0.2), direction_velocity=(0.6, 0.0, 0.0)),
        obstacles=(Obstacle((2.0, 3.7, 0.2), 0.4), Obstacle((2.0, 2.3, 0.2), 0.4), Obstacle((3.0, 3.0, 0.2), 0.3)),
        **{"controller.recovery": False})  # the backup is what this fixture exercises
    n = sc.controller.horizon_steps
    tight = dataclasses.replace(
        Tightening.untightened(sc), e_d_min=sc.epsilon + 0.05, obstacle_margin=0.05, margins=np.full((n, 4), 0.02),
        tube=np.full(3, 0.05), disturbance=DisturbanceBound(0.12, 0.1, 0.02),
        backup=BackupPlan(cert.law, cert.safe_set, cert.handover), tiers=Tiers(True, True))
    return certified_run(sc, tight)


def test_the_backup_engages_and_every_safety_promise_holds(runaway):
    done = runaway
    by_name = {p.name: p for p in done.promises}
    assert done.metrics["backup_s"] >= 10.0 and done.metrics["backup_engagements"] >= 1
    assert np.any(done.run.backup_active) and not done.run.backup_active[0]
    for name in ("clearance", "workspace", "inputs", "sway"):
        assert by_name[name].tier == "safe" and by_name[name].ok, by_name[name]
        assert by_name[name].depends_on == ("disturbance",)
    assert by_name["disturbance"].ok and done.metrics["min_clearance"] > 0.0
    # recursive feasibility fails (no plan for many periods) - it guards tracking only
    assert not by_name["recursive_feasibility"].ok and by_name["tube"].depends_on == ("disturbance", "recursive_feasibility")
    assert done.broken == () and done.check() is True


def test_the_vehicle_stays_in_the_backup_safe_set_while_it_runs(runaway):
    run, safe = runaway.run, runaway.run.tightening.backup.safe_set
    on = np.flatnonzero(run.backup_active)
    for i in on:
        x, a = run.states[i], run.backup_anchor[i]
        chi = axis_angle(line_of_sight_angle(x[0], x[1], x[3], a[0], a[1]))
        level = math.hypot(x[0] - a[0], x[1] - a[1]) + safe.shape * (1.0 - math.cos(chi))
        assert level <= safe.level and abs(x[2] - a[2]) <= safe.depth
    assert np.all(np.linalg.norm(run.inputs[on[:-1]], axis=1) > 0.0)  # never the zero input
