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
from tubekit.scenario import paper_scenario
from tubekit.tightening import Tightening

pytest.importorskip("tubekit.fhocp")


@pytest.fixture(scope="module")
def short():
    return paper_scenario().with_changes(duration=1.0)


@pytest.fixture(scope="module")
def zero_tube_certified(short):
    """A run under a tightening flagged certified whose tube is zero: any disturbed run breaks it."""
    tight = dataclasses.replace(Tightening.untightened(short), sigma=0.5, certified=True)
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
    assert done.certified and not done.promises_kept and done.check() is False
    # broken: the non-premise promises with a finite figure on the wrong side (the infinite tube ratio is not one)
    want = tuple(p.name for p in done.promises if p.name not in ("disturbance", "recursive_feasibility")
                 and math.isfinite(p.observed) and not p.ok)
    assert done.broken == want and "tube" not in done.broken
    premises = [by_name[n].ok for n in ("disturbance", "recursive_feasibility")]
    assert done.premises_held is all(premises)
    line = done.summary()
    assert "\n" not in line and "certified" in line and "tube" in line


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
