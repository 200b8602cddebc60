"""CLI tests: `tubekit certify` / `tubekit envelope` exit codes, JSON, and the bad-input table."""

from __future__ import annotations

import json

import pytest

from tubekit.app.cli import main
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from verify import SCENARIOS_DIR, certify

CERTIFIABLE = str(SCENARIOS_DIR / "certifiable.toml")
KEYS = {"certified", "law", "region", "problem", "tube", "margins", "sigma", "v_bar", "horizon", "failures",
        "conditions", "assumptions", "premises", "scenario_data", "elapsed_s"}


def test_certify_paper_scenario_with_the_papers_law_exits_3(tmp_path, capsys):
    out = tmp_path / "c.json"
    assert main(["certify", "--law", "paper", "--json", str(out)]) == 3
    d = json.loads(out.read_text())
    assert KEYS <= set(d) and d["certified"] is False and d["law"] == "paper"
    assert {"e_d", "e_z", "e_o", "heading", "pd_dot_max", "omega_bar", "v_max"} <= set(d["region"])
    assert d["region"]["e_d"] == [0.1, 3.0] and d["region"]["heading"] == "toward"
    assert {"rho", "theta", "kappa", "certified"} <= set(d["tube"])
    assert {"steps", "dt"} <= set(d["horizon"])
    # physics, not the tube: target + current outrun the vehicle, and at e_d = 0.1 the current turns the
    # line of sight at 0.12 / 0.1 = 1.2 rad/s > r_max = 0.5 rad/s
    assert {f["condition"] for f in d["failures"]} >= {"keep_up[u]", "yaw_budget"}
    yaw = next(f for f in d["failures"] if f["condition"] == "yaw_budget")
    assert yaw["rhs"] == pytest.approx((0.1 + 0.1 * 0.4 * 0.5) / 0.1, rel=1e-9)
    text = capsys.readouterr().out
    assert "NOT CERTIFIED" in text and "yaw_budget" in text


def test_certify_defaults_to_the_scenarios_law(tmp_path):
    out = tmp_path / "c.json"
    assert main(["certify", "--json", str(out), "--quiet"]) == 3
    assert json.loads(out.read_text())["law"] == paper_scenario().controller.law


def test_certify_certifiable_scenario_exits_0(capsys):
    assert main(["certify", CERTIFIABLE]) == 0
    assert "CERTIFIED" in capsys.readouterr().out


def test_certify_json_to_stdout_is_pure_json(capsys):
    assert main(["certify", CERTIFIABLE, "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["certified"] is True


BAD_TOML = {
    "zero vehicle radius": ("vehicle_radius = 0.0\n", "vehicle_radius"),
    "negative vehicle radius": ("vehicle_radius = -0.2\n", "vehicle_radius"),
    "negative obstacle radius": ("[[obstacles]]\ncenter = [3.0, 0.0, 0.0]\nradius = -0.4\n", r"obstacles\[0\]"),
    "overlapping obstacles": ("[[obstacles]]\ncenter = [3.0, 0.0, 0.0]\nradius = 0.4\n"
                              "[[obstacles]]\ncenter = [3.5, 0.0, 0.0]\nradius = 0.4\n", "obstacle_dis"),
    "zero epsilon": ("epsilon = 0.0\n", "epsilon"),
    "negative epsilon": ("epsilon = -0.1\n", "epsilon"),
    "empty region": ("epsilon = 0.5\n[region]\ne_d_max = 0.4\n", "region.e_d_max"),
    "NaN": ("epsilon = nan\n", "epsilon"),
    "NaN limit": ("[limits]\nu_max = nan\n", "limits.u_max"),
}


@pytest.mark.parametrize("case", sorted(BAD_TOML))
def test_bad_input_exits_2_with_one_message(case, tmp_path, capsys):
    text, field = BAD_TOML[case]
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    with pytest.raises(ConfigError, match=field):
        load_scenario(cfg)
    assert main(["certify", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert "error" in err and "expected" in err


def test_unknown_law_exits_2(capsys):
    with pytest.raises(ConfigError, match="law"):
        certify(paper_scenario(), "telepathy")
    assert main(["certify", "--law", "telepathy"]) == 2
    err = capsys.readouterr().err
    assert "law" in err and "paper" in err and "corrected" in err and "Traceback" not in err


@pytest.mark.parametrize("argv, field", [
    (["certify", "/nonexistent/dir/x.toml"], "CONFIG"),
    (["certify", "--max-boxes", "0"], "--max-boxes"),
    (["certify", "--max-boxes", "-3"], "--max-boxes"),
    (["certify", CERTIFIABLE, "--json", "/nonexistent/dir/c.json"], "--json"),
    (["envelope", CERTIFIABLE, "--plot", "/nonexistent/dir/p.png"], "--plot"),
    (["envelope", "--law", "telepathy"], "law"),
])
def test_other_bad_arguments_exit_2(argv, field, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err


def test_envelope_cli_quick_writes_json_and_plot(tmp_path, capsys):
    out, png = tmp_path / "e.json", tmp_path / "e.png"
    assert main(["envelope", CERTIFIABLE, "--quick", "--json", str(out), "--plot", str(png)]) == 0
    d = json.loads(out.read_text())
    # the certified frontier never exceeds the physical-necessity frontier min(u_max - speed, r_max eps)
    for s_, c, n in zip(d["speeds"], d["certified_omega"], d["necessary_omega"]):
        assert n == pytest.approx(min(0.4 - s_, 0.5 * 0.5), abs=1e-12)
        assert c is None or c <= n + 1e-9
    assert 0 < d["ratio_min"] <= 1
    assert png.stat().st_size > 1000
    assert "ratio" in capsys.readouterr().out
