"""tubekit falsify: the one-period and closed-loop falsifiers, exit codes, JSON schema, bad input."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import verify
from tubekit.app.cli import main
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from verify.falsify.one_period import falsify, falsify_closed_loop, search_space

CERTIFIABLE = str(verify.SCENARIOS_DIR / "certifiable.toml")
PAPER_CURRENTS = verify.SCENARIOS_DIR / "paper_currents.toml"
STATE_KEYS = {"e_x", "e_y", "e_z", "psi"}


@pytest.fixture(scope="module")
def currents():
    scenario = load_scenario(PAPER_CURRENTS)
    return scenario, verify.certify(scenario)


def test_search_space_from_certificate(currents):
    scenario, cert = currents
    space = search_space(scenario, certificate=cert)
    assert space.sigma == cert.design.sigma and space.tube == tuple(cert.tube.rho)
    assert space.theta == cert.tube.theta and space.certified
    assert space.ticks * space.tick == pytest.approx(scenario.controller.dt)
    assert all(lo < hi for lo, hi in space.start)


def test_one_period_certified_finds_nothing(currents):
    scenario, cert = currents
    res = falsify(scenario, certificate=cert, budget=60, local_iterations=150)
    assert not res.found and res.stage == "none"
    assert 0.3 < res.worst_value <= 1.0  # tightness: the search reaches the tube


def test_one_period_shrunk_tube_is_found(currents):
    scenario, cert = currents
    space = search_space(scenario, certificate=cert)
    small = replace(space, tube=tuple(x / 2 for x in space.tube))
    res = falsify(scenario, space=small, budget=60, local_iterations=150)
    assert res.found and res.value > 1.0
    data = res.to_dict()
    assert set(data["counterexample"]["real"]) == STATE_KEYS and data["counterexample"]["ratio"] > 1


def test_closed_loop_certified_finds_nothing(currents):
    """Tightness figure on paper_currents: largest observed deviation / certified radius."""
    scenario, cert = currents
    res = falsify_closed_loop(scenario, budget=5, seed=0, duration=2.0, certificate=cert)
    assert res.check() and not res.found
    assert 0.3 < res.ratio <= 1.0
    assert res.simulations == 5 and res.worst.promises
    data = json.loads(json.dumps(res.to_dict()))
    assert data["found"] is False and data["mode"] == "closed-loop"


def test_closed_loop_shrunk_tube_is_found(currents):
    scenario, cert = currents
    tight = cert.tightening
    small = replace(tight, tube=np.asarray(tight.tube) / 2)
    res = falsify_closed_loop(scenario, budget=2, seed=0, duration=2.0, certificate=cert, tightening=small)
    assert res.found and not res.check() and res.ratio > 1.0
    assert "COUNTEREXAMPLE" in res.summary()


def test_closed_loop_cli_exit_0(tmp_path):
    out = tmp_path / "cl.json"
    assert main(["falsify", str(PAPER_CURRENTS), "--closed-loop", "--budget", "2", "--duration", "1",
                 "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["found"] is False and data["simulations"] == 2


def test_certified_design_exit_0(tmp_path):
    out = tmp_path / "none.json"
    assert main(["falsify", CERTIFIABLE, "--law", "corrected", "--budget", "40", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["found"] is False and "counterexample" not in data


@pytest.mark.parametrize("argv, field", [
    (["falsify", "--budget", "0"], "budget"),
    (["falsify", CERTIFIABLE, "--sigma", "-1"], "--sigma"),
    (["falsify", CERTIFIABLE, "--closed-loop", "--duration", "0"], "--duration"),
    (["falsify", "no/such/file.toml"], "CONFIG"),
])
def test_bad_input_exit_2(argv, field, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err


def test_budget_validation_in_python():
    with pytest.raises(ConfigError, match="budget"):
        falsify(paper_scenario(), "paper", budget=-5)
    with pytest.raises(ConfigError, match="budget"):
        falsify_closed_loop(paper_scenario(), budget=0)


def test_on_the_dynamic_plant_the_closed_loop_attack_draws_the_water_current_within_its_own_bound():
    """On the dynamic plant the attack's disturbance replaces the water current only (the sway and the loop's
    error are the plant's own), so it is drawn within the current's bound, the premise the certificate assumes,
    not within ω̄: on examples/bluerov2_tracked.toml (0.04 m/s per axis, ω̄_xy 0.085 m/s) no run breaks a premise and
    the attack still pushes the tube past half its radius (from the faces of R, where the tube is not promised: the
    certified start's own run stays well inside it)."""
    from pathlib import Path
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_tracked.toml")
    cert = verify.certify(sc)
    res = falsify_closed_loop(sc, budget=3, seed=0, duration=3.0, certificate=cert)
    assert res.omega_bar == (0.04, 0.04) and res.omega_bar[0] < cert.disturbance.omega_xy
    assert res.vacuous_runs == 0 and not res.found and res.worst.ratio < 1.0
    assert 0.5 < max(r.ratio for r in res.runs) < 1.0


@pytest.mark.slow
def test_a_run_from_a_start_with_no_tracking_tier_refutes_nothing_by_its_tube():
    """The closed-loop attack also starts on the faces of R, and each such start is certified on its own (the start
    is part of the design). Where that certificate gives no tracking tier the tube is not promised, so a ratio above
    1 there is no counterexample; a broken promise still is. Counterexample to the old count: on
    examples/keep_moving_survey.toml such runs reach ratios above 1 (they made `tubekit falsify --closed-loop` exit 3
    on a certified design), and the attack now reports none."""
    from verify.falsify.closed_loop import LoopRun
    unclaimed = LoopRun("evolution", (0.0, 0.0, 0.0, 0.0), 6.0, (), False, (), claims_tube=False)
    assert not unclaimed.counterexample and unclaimed.fitness() == 1.0
    assert replace(unclaimed, claims_tube=True).counterexample
    assert replace(unclaimed, broken=("clearance",)).counterexample
    from pathlib import Path
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_survey.toml")
    res = falsify_closed_loop(sc, budget=3, seed=0, duration=10.0)
    beyond = [r for r in res.runs if not r.vacuous and not r.claims_tube and r.ratio > 1.0]
    assert beyond and not res.found and res.worst.claims_tube
    assert "certifies no tracking tier" in res.summary()


def test_at_sigma_zero_the_greedy_attack_reads_the_loop_and_pushes_the_tube_to_its_edge():
    """The greedy attack reads the state, the nominal and the target from the loop's tick observer. It used to read
    them from the ancillary law's inputs, which sigma = 0 never calls, so it applied no current at all (ratio 0 on
    every sigma = 0 design). On examples/keep_moving_survey.toml (sigma = 0) from its certified start it now drives
    the deviation to the tube's edge and not beyond."""
    from pathlib import Path
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_survey.toml")
    cert = verify.certify(sc)
    res = falsify_closed_loop(sc, budget=1, seed=0, duration=5.0, certificate=cert)
    (run,) = res.runs
    assert cert.sigma.value == 0.0 and run.strategy == "greedy:max" and run.claims_tube
    assert 0.9 < run.ratio <= 1.0 and not res.found
