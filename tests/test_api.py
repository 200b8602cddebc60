"""The short Python API ``tubekit.simulate(scenario, certificate)``: its inputs, its refusals, its runs."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tubekit
from tubekit.exceptions import ConfigError
from tubekit.tightening import Tightening


def _pc():
    import verify
    return tubekit.load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


@pytest.mark.parametrize("scenario, certificate, duration, match", [
    ("paper_currents.toml", None, None, "scenario: expected a tubekit.Scenario"),
    (None, None, -1.0, "duration"),
    (None, None, math.nan, "duration"),
    (None, None, "100", "duration"),
    (None, None, True, "duration"),
    (None, 42, 0.3, "certificate: expected a verify.Certificate or a tubekit.Tightening"),
])
def test_bad_arguments_are_refused_before_anything_runs(scenario, certificate, duration, match):
    sc = _pc() if scenario is None else scenario
    with pytest.raises(ConfigError, match=match):
        tubekit.simulate(sc, certificate, duration=duration, progress=False)


def test_an_uncertified_certificate_is_refused_with_what_to_do():
    import verify
    # a current faster than the vehicle: no tier of promise can be certified
    sc = tubekit.paper_scenario().with_changes(**{"disturbance.amplitude": (0.5, 0.5, 0.1)})
    cert = verify.certify(sc)
    assert not cert.certified
    with pytest.raises(ConfigError, match="best_effort_tightening"):
        tubekit.simulate(sc, cert, duration=0.3, progress=False)


def test_without_a_certificate_the_baseline_runs_for_the_duration_asked():
    run = tubekit.simulate(_pc(), None, duration=0.3, progress=False)
    assert not run.tube and run.t[-1] == pytest.approx(0.3)
    assert np.all(run.kappa[np.isfinite(run.kappa)] == 0.0)  # no ancillary feedback in the baseline


def test_a_certificate_runs_the_tube_with_its_own_tightening(pc_cert):
    run = tubekit.simulate(_pc(), pc_cert, duration=0.3, progress=False)
    assert run.tube and run.tightening.design_key == pc_cert.design_key
    assert all(p.ok for p in tubekit.check_promises(run))


def test_a_tightening_is_accepted_directly(pc_cert):
    run = tubekit.simulate(_pc(), pc_cert.tightening, duration=0.2, progress=False)
    assert isinstance(run.tightening, Tightening) and run.tightening.certified


@pytest.mark.parametrize("start", [(0.0, 2.5, 0.0, 0.0), (2.5, 0.7, 0.0, 0.0), (-9.55, 3.0, 0.2, 0.0)],
                         ids=["other start", "beside an obstacle", "at the wall"])
def test_a_certificate_never_runs_from_another_start(pc_cert, start):
    """Issue 30, attack 1: with the certificate of paper_currents and a scenario that differs only in its start, the
    run used to start "safe: certified" and collide or leave the workspace (clearance -0.050 m); the start is part of
    the design now, so the run is refused before any tick, naming initial_state."""
    with pytest.raises(ConfigError, match=r"design_key\.initial_state: expected the certificate's value"):
        tubekit.simulate(_pc().with_changes(initial_state=start), pc_cert, duration=0.3, progress=False)
