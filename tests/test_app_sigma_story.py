"""tubekit.app.sigma_story: why sigma was chosen and the tube where the tube is visible (issue 35, item 5)."""

from __future__ import annotations

import pytest

import verify
from tubekit import load_scenario, paper_scenario
from tubekit.app.sigma_story import sigma_story


def test_the_papers_scenario_says_no_tube_is_promised_and_why():
    sc = paper_scenario()
    lines = sigma_story(sc, verify.certify(sc))
    assert lines[0].startswith("sigma = 0 1/s (largest slack among the certified ones tried; tried 0, 3.125")
    assert "tracking not certified (keep_up[u]" in lines[1] and "no tube is promised" in lines[1]


def test_a_tracking_design_at_sigma_zero_shows_its_tube_and_the_tube_at_a_larger_sigma():
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    lines = sigma_story(sc, verify.certify(sc))
    assert "one-period tube |e - e_hat| <= [0.012, 0.01, 0.024]" in lines[1] and "the disturbance alone" in lines[1]
    assert lines[2].startswith("  at sigma = 100 1/s the one-period tube would be [")


def test_a_declared_sigma_is_its_own_story():
    sc = verify.certifiable_scenario()
    lines = sigma_story(sc, verify.certify(sc))
    assert lines[0] == "sigma = 100 1/s (controller.sigma; tried 100)" and len(lines) == 2


def test_sigma_on_the_command_line_is_certified_and_run(tmp_path):
    from tubekit.app.cli import main
    assert main(["simulate", str(verify.SCENARIOS_DIR / "paper_currents.toml"), "--sigma", "3.125", "--duration",
                 "1", "--out", str(tmp_path / "s"), "--no-progress"]) in (0, 3)
    import json
    cert = json.loads((tmp_path / "s" / "certificate.json").read_text())
    assert cert["sigma"]["value"] == pytest.approx(3.125) and cert["sigma"]["source"] == "controller.sigma"
