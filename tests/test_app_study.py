"""``tubekit reproduce`` / ``tubekit simulate``: files, keys, metrics recomputed from the CSV, exit codes."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import verify
from tubekit.tiers import Tiers
from tubekit import Tightening
from tubekit.app.cli import main
from tubekit.app.study import OUTPUT_FILES, QUICK_DURATION_S
from tubekit.loop.metrics import METRIC_KEYS, read_trajectory_csv
from tubekit.app.plots import FIGURE_FILES

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
REQUIRED_COLUMNS = ("t", "x", "y", "z", "psi", "u", "w", "r", "x_d", "y_d", "z_d")


class FakeCertificate:
    """Stands in for verify's certificate where the real certification would dominate test time."""

    def __init__(self, scenario, certified):
        self.scenario, self.certified = scenario, certified
        self.failures = [] if certified else [SimpleNamespace(condition="fake")]
        self.disturbance = SimpleNamespace(gamma=0.02)  # what the dynamic part of reproduce reads
        self.tiers = Tiers(certified, certified)
        self.tier_failures = {"safe": () if certified else ("fake",), "tracking": () if certified else ("fake",)}
        self.inputs, self.law, self.sigma_source = SimpleNamespace(sigma=0.5), "corrected", "fake"
        self.tried, self.tube = (SimpleNamespace(sigma=0.5),), SimpleNamespace(certified=True, rho=(0.03, 0.0, 0.0))

    def to_dict(self):
        return {"certified": self.certified, "fake": True, "rho": 0.03}

    def summary(self, verbose=False):
        return "fake certificate for tests"

    def best_effort_tightening(self, min_input_fraction=0.5):
        base = Tightening.untightened(self.scenario)  # the verdict and gamma travel in the tightening
        return dataclasses.replace(base, sigma=0.5, tube=np.array([0.03, 0.0, 0.0]),
                                   e_d_min=self.scenario.epsilon + 0.03, obstacle_margin=0.02,
                                   v_max=base.v_max * 0.9, tiers=Tiers(self.certified, self.certified),
                                   disturbance=(0.25, 0.15, self.disturbance.gamma))  # covers the current


def _fake_certify(certified=False):
    def certify(scenario, law=None):
        return FakeCertificate(scenario, certified)
    return certify


def _real_certify_available() -> bool:
    try:
        import tubekit.fhocp  # noqa: F401
    except ImportError:
        return False
    return callable(getattr(verify, "certify", None))


# ---- independent recomputation of metrics.json from trajectory.csv ------------------------

def _recompute(cols: dict, meta: dict, scenario: dict) -> dict:
    t = cols["t"]
    px, py, pz = cols["x"], cols["y"], cols["z"]
    ex, ey, ez = px - cols["x_d"], py - cols["y_d"], pz - cols["z_d"]
    clear = math.inf
    for o in meta["obstacles"]:
        (cx, cy, cz), r = o["center"], o["radius"]
        d = np.sqrt((px - cx) ** 2 + (py - cy) ** 2 + (pz - cz) ** 2) - r - meta["vehicle_radius"]
        clear = min(clear, float(d.min()))
    lim = meta["input_limits"]
    ratio = np.nanmax(np.column_stack([np.abs(cols["u"]) / lim[0], np.abs(cols["w"]) / lim[1],
                                       np.abs(cols["r"]) / lim[2]]))
    traj = scenario["trajectory"]
    if traj["kind"] in ("circle", "helix"):
        th = np.arctan2(py - traj["center"][1], px - traj["center"][0])
        dth = np.diff(th)
        dth = np.arctan2(np.sin(dth), np.cos(dth))  # shortest signed increments
        turns = -math.copysign(1.0, traj["rate"]) * float(dth.sum()) / (2 * math.pi)
        # passes: count crossings of each obstacle's bearing, sample by sample
        phi = -math.copysign(1.0, traj["rate"]) * np.concatenate([[th[0]], th[0] + np.cumsum(dth)])
        passes = []
        for o in meta["obstacles"]:
            pm = -math.copysign(1.0, traj["rate"]) * math.atan2(o["center"][1] - traj["center"][1],
                                                               o["center"][0] - traj["center"][0])
            k = np.floor((phi - pm) / (2 * math.pi))
            passes.append(int(np.sum(np.diff(k))))
    else:
        turns, passes = None, None
    # rho from the logged nominal, with the paper's e_d and e_o definitions (eqs. 13-14)
    xh, yh = cols["x_hat"] - cols["x_d"], cols["y_hat"] - cols["y_d"]
    edh = np.hypot(xh, yh)
    eoh = (xh * np.sin(cols["psi_hat"]) - yh * np.cos(cols["psi_hat"])) / edh
    ed = np.hypot(ex, ey)
    eo = (ex * np.sin(cols["psi"]) - ey * np.cos(cols["psi"])) / ed
    rho = np.sqrt((ed - edh) ** 2 + (ez - (cols["z_hat"] - cols["z_d"])) ** 2 + (eo - eoh) ** 2)
    step_ms = cols["step_ms"][np.isfinite(cols["step_ms"])]
    first = np.isfinite(cols["step_ms"])
    below = ed < meta["epsilon"]
    return {
        "saturated_ticks": int(np.sum(cols["saturated"] == 1)),
        "fallback_steps": int(np.sum(first & (cols["fallback"] == 1))),
        "solve_ms_median": float(np.median(cols["solve_ms"][first])),
        "fhocp_max_violation": float(np.nanmax(cols["plan_violation"])),
        "collision": bool(clear < 0),
        "e_d_below_epsilon_count": int(np.sum(np.diff(np.concatenate([[0], below.astype(int)])) == 1)),
        "duration_s": float(t[-1] - t[0]),
        "steps": int(step_ms.size),
        "min_clearance": clear if meta["obstacles"] else None,
        "min_e_d": float(ed.min()),
        "max_input_ratio": float(ratio),
        "saturated_steps": len({int(s) for s, f in zip(cols["step"], cols["saturated"]) if f == 1}),
        "encirclements": turns,
        "obstacle_passes": passes,
        "tracking_rmse": float(np.sqrt(np.mean(ex ** 2 + ey ** 2 + ez ** 2))),
        "max_rho": float(np.nanmax(rho)),
        "step_ms_median": float(np.median(step_ms)),
        "step_ms_p95": float(np.percentile(step_ms, 95)),
        "wall_s": float(np.nanmax(cols["wall_s"])),
    }


def _check_outputs(out: Path, *, certified: bool | None = None) -> dict:
    for name in OUTPUT_FILES + FIGURE_FILES:
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    metrics = json.loads((out / "metrics.json").read_text())
    scenario = json.loads((out / "scenario.json").read_text())
    json.loads((out / "certificate.json").read_text())
    for key in METRIC_KEYS:
        assert key in metrics, key
        assert key in metrics["baseline"], key
    assert metrics["baseline"]["tube"] is False and metrics["tube"] is True
    assert metrics["baseline"]["sigma"] == 0.0
    if certified is not None:
        assert metrics["certified"] is certified
        assert (metrics["rho_bound"] is None) is (not certified)
        if certified:
            assert metrics["rho_bound"] == pytest.approx(metrics["rho_tilde_used"])
    assert metrics["baseline"]["rho_bound"] is None
    for csv_name, meta in (("trajectory.csv", metrics), ("baseline_trajectory.csv", metrics["baseline"])):
        cols = read_trajectory_csv(out / csv_name)
        for c in REQUIRED_COLUMNS:
            assert c in cols, c
        want = _recompute(cols, meta, scenario)
        assert len(meta["e_d_below_epsilon"]) == want.pop("e_d_below_epsilon_count")
        for key, value in want.items():
            if value is None or isinstance(value, (list, bool)):
                assert meta[key] == value, key
            else:
                assert meta[key] == pytest.approx(value, rel=1e-7, abs=1e-9), key
    return metrics


# ---- simulate --------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["circle", "helix", "line", "waypoints"])
def test_simulate_each_example(name, tmp_path, capsys):
    if not _real_certify_available():
        pytest.skip("verify.certify or tubekit.fhocp not available yet")
    out = tmp_path / name
    rc = main(["simulate", str(EXAMPLES / f"{name}.toml"), "--out", str(out), "--duration", "3", "--no-progress"])
    assert rc == 0
    metrics = _check_outputs(out)
    assert metrics["scenario"] == name and metrics["duration_s"] == pytest.approx(3.0)
    assert "acceptance" not in metrics
    assert "wrote" in capsys.readouterr().out


def test_simulate_certified_scenario_stays_in_its_tube(tmp_path):
    """The verifier's certifiable scenario: rho_bound is reported and the run keeps ||rho|| below it."""
    if not _real_certify_available():
        pytest.skip("verify.certify or tubekit.fhocp not available yet")
    out = tmp_path / "cert"
    cfg = Path(verify.__file__).parent / "scenarios" / "certifiable.toml"
    assert main(["simulate", str(cfg), "--out", str(out), "--duration", "5", "--no-progress"]) == 0
    metrics = _check_outputs(out, certified=True)
    assert 0 < metrics["max_rho"] <= metrics["rho_bound"]
    assert metrics["saturated_steps"] == 0
    assert 0 < metrics["max_rho_ratio"] <= 1 and metrics["promises_kept"] is True


BAD_CONFIGS = [
    ('duration = -5.0\n', "duration"),
    ('[trajectory]\nkind = "spiral"\n', "trajectory.kind"),
    ('[[obstacles]]\ncenter = [1.0, 0.0, 0.0]\nradius = -0.4\n', "obstacles[0].radius"),
    ('[controller]\nlaw = "magic"\n', "controller.law"),
    ('[limits]\nu_max = "fast"\n', "limits.u_max"),
    ('colour = "red"\n', "colour"),
    ('duration = = 1\n', "CONFIG"),
]


@pytest.mark.parametrize("text, field", BAD_CONFIGS, ids=[f for _, f in BAD_CONFIGS])
def test_invalid_config_exits_2_naming_the_field(text, field, tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    rc = main(["simulate", str(cfg), "--out", str(tmp_path / "out"), "--no-progress"])
    assert rc == 2
    err = capsys.readouterr().err.strip()
    assert field in err and "Traceback" not in err and len(err.splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_missing_config_and_bad_duration(tmp_path, capsys):
    assert main(["simulate", str(tmp_path / "nope.toml"), "--no-progress"]) == 2
    assert "CONFIG" in capsys.readouterr().err
    assert main(["simulate", str(EXAMPLES / "line.toml"), "--duration", "-1", "--no-progress"]) == 2
    assert "--duration" in capsys.readouterr().err
    out = tmp_path / "tiny"
    assert main(["reproduce", "--duration", "0.01", "--out", str(out), "--no-progress"]) == 2
    assert "--duration: expected at least one FHOCP period" in capsys.readouterr().err
    assert not out.exists()


def test_invalid_config_console_script(tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text('[region]\ne_o_max = 1.5\n')
    out = subprocess.run([sys.executable, "-m", "tubekit.app.cli", "simulate", str(cfg)], capture_output=True,
                         text=True, timeout=600)  # a hang guard, not a verdict
    assert out.returncode == 2
    assert "region.e_o_max" in out.stderr and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


# ---- reproduce -------------------------------------------------------------------------

@pytest.mark.parametrize("certified", [False, True])
def test_reproduce_writes_every_file_and_key(certified, tmp_path, monkeypatch):
    pytest.importorskip("tubekit.fhocp")
    monkeypatch.setattr(verify, "certify", _fake_certify(certified), raising=False)
    out = tmp_path / "rep"
    rc = main(["reproduce", "--out", str(out), "--duration", "4", "--no-progress"])
    metrics = _check_outputs(out, certified=certified)
    # the fake 'certified' certificate promises a zero tube, which any disturbed run breaks: exit 4
    assert rc == (4 if certified else 0)
    assert metrics["promises_kept"] is False
    assert metrics["max_rho_ratio"] is None  # infinite (a zero tube) is written as null in strict JSON
    acc = metrics["acceptance"]
    for key in ("no_collision", "inputs_within_V", "two_encirclements", "e_d_at_least_epsilon"):
        assert isinstance(acc[key], bool)
    assert acc["no_collision"] is (metrics["min_clearance"] >= 0)
    assert acc["e_d_at_least_epsilon"] is (metrics["min_e_d"] >= metrics["epsilon"])
    assert metrics["scenario"] == "paper-section-VI" and metrics["steps"] == 40
    assert [o["center"] for o in metrics["obstacles"]] == [[3.0, 0.0, 0.0], [-3.0, 0.0, 0.0]]
    # issue 13: reproduce also runs the tube controller on the dynamic plant, and says what it measured
    from tubekit.app.dynamic_study import DYNAMIC_FILES
    for name in DYNAMIC_FILES:
        assert (out / name).is_file() and (out / name).stat().st_size > 20, name  # the fake certificate is short
    dyn = metrics["dynamic"]
    assert dyn["vehicle"] == "bluerov2_heavy" and len(dyn["velocity_error_max"]) == 3
    assert dyn["sway_bound"] == 0.02 and 0 < dyn["sway_max"]
    dyn_csv = np.genfromtxt(out / "dynamic_trajectory.csv", delimiter=",", names=True)
    assert {"u_b", "v_b", "w_b", "r_b", "X", "Z", "N"} <= set(dyn_csv.dtype.names)
    assert dyn["sway_max"] == pytest.approx(float(np.nanmax(np.abs(dyn_csv["v_b"]))), rel=1e-9)


@pytest.mark.parametrize("certified", [False, True])
def test_metrics_json_is_the_runs_metrics_key_for_key(certified, tmp_path, monkeypatch):
    """One convention: metrics.json's run part is SimulationResult.metrics, key for key and value for value."""
    pytest.importorskip("tubekit.fhocp")
    from tubekit.app.study import STUDY_KEYS, StudyResult, run_study
    from tubekit.scenario import paper_scenario

    monkeypatch.setattr(verify, "certify", _fake_certify(certified), raising=False)
    out = tmp_path / "m"
    result = run_study(paper_scenario().with_changes(duration=2.0), out, progress=False, with_acceptance=True,
                       dynamic=True, echo=lambda line: None)
    stored = json.loads((out / "metrics.json").read_text())
    assert isinstance(result, StudyResult) and result.to_dict() == stored
    assert {k: v for k, v in stored.items() if k not in STUDY_KEYS} == result.tube.run.metrics
    assert stored["baseline"] == result.baseline.run.metrics
    dynamic_only = ("failures", "vehicle", "velocity_loop", "tiers_report")
    assert {k: v for k, v in stored["dynamic"].items() if k not in dynamic_only} == result.dynamic.run.metrics
    assert stored["sway_bound"] == 0.02 and stored["max_rho_ratio"] is None and "promises" in stored
    # the fake certified certificate's zero tube is broken by any disturbed run: check() fails only then
    assert result.check() is (not certified) and result.certified is certified
    summary = result.summary()
    assert "min_clearance" in summary and "acceptance:" in summary and "dynamic plant" in summary


def test_quick_and_law_options(tmp_path, monkeypatch):
    pytest.importorskip("tubekit.fhocp")
    monkeypatch.setattr(verify, "certify", _fake_certify(), raising=False)
    out = tmp_path / "q"
    assert main(["reproduce", "--out", str(out), "--quick", "--law", "paper", "--no-progress"]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["duration_s"] == pytest.approx(QUICK_DURATION_S)
    assert metrics["law"] == "paper"
    assert json.loads((out / "scenario.json").read_text())["controller"]["law"] == "paper"


@pytest.fixture(scope="module")
def real_reproduce(tmp_path_factory):
    if not _real_certify_available():
        pytest.skip("verify.certify or tubekit.fhocp not available yet")
    out = tmp_path_factory.mktemp("real") / "reproduce"
    rc = main(["reproduce", "--out", str(out), "--duration", "5", "--no-progress"])
    return rc, out


@pytest.mark.slow
def test_reproduce_with_real_certificate(real_reproduce):
    rc, out = real_reproduce
    assert rc == 0
    metrics = _check_outputs(out)
    cert = json.loads((out / "certificate.json").read_text())
    assert isinstance(cert, dict) and cert
    assert (metrics["rho_bound"] is None) is (not metrics["certified"])
    assert metrics["checks"]["inputs_finite"] and metrics["baseline"]["checks"]["inputs_finite"]


# ---- atomic output: a failed or interrupted run leaves the previous results untouched ----------

def _tree(root: Path) -> dict[str, bytes | None]:
    """Every path under ``root`` (hidden staging directories included) with its bytes."""
    return {str(p.relative_to(root)): (None if p.is_dir() else p.read_bytes()) for p in root.rglob("*")}


@pytest.fixture
def previous_results(tmp_path, monkeypatch):
    """A finished reproduce run in ``tmp_path/rep`` (fake certificate), and the tree of ``tmp_path``."""
    pytest.importorskip("tubekit.fhocp")
    monkeypatch.setattr(verify, "certify", _fake_certify(), raising=False)
    out = tmp_path / "rep"
    assert main(["reproduce", "--out", str(out), "--duration", "1", "--no-progress"]) == 0
    return out, _tree(tmp_path)


def test_exception_mid_run_leaves_previous_results(previous_results, tmp_path, monkeypatch):
    import tubekit.app.study as study

    out, before = previous_results

    def fail(*args, **kwargs):  # after the CSVs of the new run are written into the staging directory
        raise RuntimeError("simulated failure while plotting")

    monkeypatch.setattr(study, "plot_all", fail)
    with pytest.raises(RuntimeError, match="simulated failure"):
        main(["reproduce", "--out", str(out), "--duration", "2", "--no-progress"])
    assert _tree(tmp_path) == before


def test_interrupt_mid_run_leaves_previous_results(previous_results, tmp_path, monkeypatch, capsys):
    import tubekit.app.study as study

    out, before = previous_results
    capsys.readouterr()

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(study, "run_tube_and_baseline", interrupt)
    assert main(["reproduce", "--out", str(out), "--duration", "2", "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "Traceback" not in err
    assert _tree(tmp_path) == before


def test_rerun_replaces_the_whole_directory(previous_results, tmp_path):
    out, _ = previous_results
    (out / "stale.txt").write_text("from an older run\n")
    assert main(["reproduce", "--out", str(out), "--duration", "2", "--no-progress"]) == 0
    assert not (out / "stale.txt").exists()
    assert json.loads((out / "metrics.json").read_text())["duration_s"] == pytest.approx(2.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]  # no staging or old directory left
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o777 & ~umask  # not the 0o700 of a temporary directory


def test_animate_writes_a_gif(tmp_path, monkeypatch):
    pytest.importorskip("tubekit.fhocp")
    monkeypatch.setattr(verify, "certify", _fake_certify(), raising=False)
    out = tmp_path / "anim"
    assert main(["reproduce", "--out", str(out), "--duration", "1", "--no-progress", "--animate", "-q"]) == 0
    from PIL import Image

    with Image.open(out / "top_view.gif") as gif:
        assert gif.n_frames > 10
