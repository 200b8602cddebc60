"""tubekit falsify: exit codes, JSON schema, shrinking, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

import verify
from tubekit.ancillary import LAWS
from tubekit.cli import main
from tubekit.exceptions import ConfigError
from tubekit.scenario import paper_scenario
from verify.falsify import SearchSpace, falsify
from verify.invariance import rho_dot_inner
from verify.region import Region

CERTIFIABLE = str(verify.SCENARIOS_DIR / "certifiable.toml")
STATE_KEYS = {"e_x", "e_y", "e_z", "psi"}


def test_paper_law_counterexample_json(tmp_path, capsys):
    out = tmp_path / "ce.json"
    assert main(["falsify", "--law", "paper", "--budget", "100", "--json", str(out)]) == 3
    data = json.loads(out.read_text())
    assert data["found"] is True
    ce = data["counterexample"]
    assert set(ce["real"]) == STATE_KEYS and set(ce["nominal"]) == STATE_KEYS
    assert len(ce["v_hat"]) == 3 and len(ce["omega"]) == 3 and len(ce["pd_dot"]) == 3
    assert ce["rho_dot_inner"] > 0 and ce["rho_norm"] > 0 and ce["sigma"] > 0
    assert "COUNTEREXAMPLE" in capsys.readouterr().out


def test_certified_design_exit_0(tmp_path):
    out = tmp_path / "none.json"
    assert main(["falsify", CERTIFIABLE, "--law", "corrected", "--budget", "150", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["found"] is False and "counterexample" not in data


def test_counterexample_is_shrunk():
    """The hypothesis stage returns a minimal example: simpler (closer to the unit cube's origin) than
    the worst configuration seen, and still a violation when re-evaluated."""
    region = Region(e_d=(0.2, 3.0), e_z=(-1, 1), e_o=(-0.9, 0.9), heading="toward", pd_dot_max=(0.3, 0.3, 0),
                    pd_dot_xy_max=0.3, omega_bar=0.1, v_max=(0.4, 0.3, 0.5))
    space = SearchSpace(region, "paper", 5.0, 0.05, 0.3, (0.3, 0.2, 0.4), False)
    res = falsify(paper_scenario(), space=space, budget=200)
    assert res.found and res.stage == "hypothesis"
    assert rho_dot_inner(res.counterexample, LAWS["paper"], 5.0) == pytest.approx(res.value) and res.value > 0
    assert res.worst_value >= res.value
    # the shrunk example sits on the simplest corner: zero disturbance and target velocity
    assert np.allclose(res.counterexample.omega, 0) and np.allclose(res.counterexample.pd_dot, 0)


@pytest.mark.parametrize("argv, field", [
    (["falsify", "--budget", "0"], "budget"),
    (["falsify", "--sigma", "-1"], "--sigma"),
    (["falsify", "--rho", "nan"], "--rho"),
    (["falsify", "no/such/file.toml"], "CONFIG"),
])
def test_bad_input_exit_2(argv, field, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err


def test_budget_validation_in_python():
    with pytest.raises(ConfigError, match="budget"):
        falsify(paper_scenario(), "paper", budget=-5)
