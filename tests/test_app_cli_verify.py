"""CLI tests: `tubekit certify` / `tubekit envelope` exit codes, JSON, and the bad-input table."""

from __future__ import annotations

import json
import math

import pytest

from tubekit.app.cli import main
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from verify import SCENARIOS_DIR, certify

CERTIFIABLE = str(SCENARIOS_DIR / "certifiable.toml")
KEYS = {"certified", "law", "region", "problem", "tube", "margins", "sigma", "v_bar", "inputs", "failures",
        "conditions", "assumptions", "premises", "design_key", "elapsed_s"}


def test_certify_paper_scenario_with_the_papers_law_exits_3(tmp_path, capsys):
    out = tmp_path / "c.json"
    assert main(["certify", "--law", "paper", "--json", str(out)]) == 3
    d = json.loads(out.read_text())
    assert KEYS <= set(d) and d["certified"] is False and d["law"] == "paper"
    assert {"e_d", "e_z", "e_o", "heading", "pd_dot_max", "omega_bar", "v_max"} <= set(d["region"])
    assert d["region"]["e_d"] == [0.1, 3.0] and d["region"]["heading"] == "toward"
    assert {"rho", "theta", "kappa", "certified"} <= set(d["tube"])
    ctrl = d["inputs"]["scenario"]["controller"]
    assert (ctrl["dt"], ctrl["horizon_steps"], ctrl["ancillary_rate_hz"]) == (0.1, 8, 100.0)
    # physics, not the tube: the target (3 pi / 25 m/s) plus the current and sway (0.1 + 0.1 * 0.4 * 0.5) outrun
    # u_max = 0.4; the yaw screen at e_d = epsilon is not a condition where step 17 proves a plan at every period
    failed = {f["condition"] for f in d["failures"]}
    assert "keep_up[u]" in failed and "yaw_budget" not in failed
    keep_up = next(f for f in d["failures"] if f["condition"] == "keep_up[u]")
    assert keep_up["rhs"] == pytest.approx(3 * math.pi / 25 + 0.1 + 0.1 * 0.4 * 0.5, rel=1e-9)
    text = capsys.readouterr().out
    assert "NOT CERTIFIED" in text and "keep_up[u]" in text


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
    # the certified frontier never exceeds the physical-necessity frontier u_max - speed (keep-up)
    for s_, c, n in zip(d["speeds"], d["certified_omega"], d["necessary_omega"]):
        assert n == pytest.approx(0.4 - s_, abs=1e-12)
        assert c is None or c <= n + 1e-9
    assert 0 <= d["ratio_min"] <= 1 and any(c is not None for c in d["certified_omega"])
    assert png.stat().st_size > 1000
    assert "ratio" in capsys.readouterr().out


# ---- issue 24 item 12: certify -v, falsify on an uncertified scenario, --law the same everywhere ----------

def test_certify_verbose_lists_every_sigma_tried_with_its_failures(capsys):
    assert main(["certify", "-v"]) == 3
    out = capsys.readouterr().out
    cert = certify(paper_scenario())
    assert f"Designs tried ({len(cert.tried)}):" in out
    for trial in cert.tried:
        assert f"{len(trial.failed)} failed: {', '.join(trial.failed)}" in out
    assert main(["certify"]) == 3 and "Designs tried" not in capsys.readouterr().out


def test_certify_prints_the_short_certificate_and_v_the_full_one(capsys):
    """Issue 35 item 6: the short certificate says what to change; -v prints every condition and assumption."""
    assert main(["certify"]) == 3
    short = capsys.readouterr().out
    assert len(short.splitlines()) <= 25 and "— set limits.u_max >= 0.503 m/s" in short
    assert "Assumptions" not in short and "[ok  ]" not in short
    assert main(["certify", "-v"]) == 3
    full = capsys.readouterr().out
    cert = certify(paper_scenario())
    assert full.startswith(cert.summary(verbose=True).split("\nElapsed:")[0])
    assert "Assumptions (outside the model):" in full and "Designs tried" in full


def test_certify_quiet_prints_no_summary(capsys):
    assert main(["certify", "-q"]) == 3
    assert capsys.readouterr().out == ""


class _FakeSpace:
    def __init__(self, certified: bool) -> None:
        self.certified = certified


class _FakeResult:
    def __init__(self, found: bool, certified: bool) -> None:
        self.found, self.space = found, _FakeSpace(certified)

    def summary(self) -> str:
        return "COUNTEREXAMPLE found" if self.found else "no counterexample"

    def to_dict(self) -> dict:
        return {"found": self.found}


@pytest.mark.parametrize("found, certified, code, note", [
    (False, True, 0, False), (True, True, 3, False), (False, False, 3, True), (True, False, 3, True),
])
def test_falsify_says_when_it_tested_a_best_effort_tube(found, certified, code, note, monkeypatch, capsys):
    """0 only when a certified scenario resists; an uncertified one exits 3 and says its tube promises nothing."""
    import verify.falsify.one_period as one_period

    monkeypatch.setattr(one_period, "falsify", lambda *a, **k: _FakeResult(found, certified))
    assert main(["falsify", "--budget", "1"]) == code
    out = capsys.readouterr().out
    assert ("tested its best-effort tube, which promises nothing" in out) is note


LAW_COMMANDS = ("reproduce", "simulate", "certify", "envelope", "falsify")


def test_law_is_one_option_everywhere():
    """``--law NAME``, one help, validated by one function (the bad-input table checks each refusal)."""
    from tubekit.app.cli import build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command")
    laws = []
    for name in LAW_COMMANDS:
        action = next(a for a in sub.choices[name]._actions if a.dest == "law")
        laws.append((action.metavar, action.choices, action.help, action.default))
    assert len(set(laws)) == 1 and laws[0][0] == "NAME" and laws[0][1] is None


def test_quiet_help_is_per_subcommand():
    from tubekit.app.cli import build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command")

    def quiet(name):
        return next(a.help for a in sub.choices[name]._actions if a.dest == "quiet")
    assert "no summary" in quiet("certify")
    assert all("certify" not in quiet(name) and "summary" not in quiet(name) for name in sub.choices
               if name != "certify")
