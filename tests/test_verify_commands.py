"""CLI tests: `tubekit certify` / `tubekit envelope` exit codes, JSON, and the bad-input table."""

from __future__ import annotations

import json
import math

import pytest

from tubekit.cli import main
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from verify import SCENARIOS_DIR, certify, envelope

CERTIFIABLE = str(SCENARIOS_DIR / "certifiable.toml")
KEYS = {"certified", "law", "region", "bounds", "sigma", "rho", "v_bar", "horizon", "failures", "assumptions",
        "elapsed_s"}


def test_certify_paper_scenario_with_the_papers_law_exits_3(tmp_path, capsys):
    out = tmp_path / "c.json"
    assert main(["certify", "--law", "paper", "--json", str(out)]) == 3
    d = json.loads(out.read_text())
    assert KEYS <= set(d) and d["certified"] is False and d["law"] == "paper"
    assert {"e_d", "e_z", "e_o", "heading", "pd_dot_max", "omega_bar", "v_max"} <= set(d["region"])
    assert d["region"]["e_d"] == [0.1, 3.0] and d["region"]["heading"] == "toward"
    for name in ("L1", "L2", "J_lower", "xi_bar"):
        assert {"sampled", "bound"} <= set(d["bounds"][name])
    assert {"T", "T_max", "ok"} <= set(d["horizon"])
    assert {f["condition"] for f in d["failures"]} >= {"J_lower", "sigma"}
    text = capsys.readouterr().out
    assert "NOT CERTIFIED" in text and "J_lower" in text


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
    (["certify", "--gap", "0"], "--gap"),
    (["certify", "--gap", "nan"], "--gap"),
    (["certify", "--time-budget", "-1"], "--time-budget"),
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
    assert d["certified_at_scenario"] is True
    assert d["max_omega_bar"] >= d["omega_bar"] and d["min_epsilon"] <= d["epsilon"]
    assert d["max_speed"] >= d["speed"]
    assert png.stat().st_size > 1000
    assert "largest omega_bar" in capsys.readouterr().out


def test_envelope_brackets_certify():
    """The envelope's headline numbers are consistent with certify(): just inside certifies,
    a few tolerances outside does not."""
    s = load_scenario(CERTIFIABLE)
    res = envelope(s, "corrected", quick=True)
    from verify import Region
    base = Region.from_scenario(s)
    kw = dict(time_budget_s=0.5, gap=0.10)
    w = res.max_omega_bar
    assert certify(s, "corrected", region=base.replace(omega_bar=w), **kw).certified
    assert not certify(s, "corrected", region=base.replace(omega_bar=w * 1.01), **kw).certified
    e = res.min_epsilon
    assert certify(s, "corrected", region=base.replace(e_d=(e, 3.0)), **kw).certified
    assert not certify(s, "corrected", region=base.replace(e_d=(e * 0.99, 3.0)), **kw).certified
    # the envelope of the paper's scenario is empty at its own epsilon and omega_bar
    p = envelope(paper_scenario(), "corrected", quick=True)
    assert p.max_omega_bar is None and p.max_speed is None and not p.certified_at_scenario
    assert math.isfinite(p.omega_max_by_speed[0]) and p.omega_max_by_speed[0] < 0.01
