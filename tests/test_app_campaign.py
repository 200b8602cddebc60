"""``tubekit campaign`` (issue 15): spec errors, reproducibility across workers and schedulers,
resumption, a killed worker, replay. Every process listens on 127.0.0.1 and is stopped by pid."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed")
pq = pytest.importorskip("pyarrow.parquet")

from tubekit.app.campaign import FIGURES, read_rows, run_campaign  # noqa: E402
from tubekit.app.campaign_spec import load_spec, run_seed  # noqa: E402
from tubekit.app.certified import input_key as certificate_key  # noqa: E402
from tubekit.app.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "verify" / "scenarios" / "paper_currents.toml"
SAMPLES = """
[sample]
"disturbance.amplitude" = { uniform = [[0.05, 0.05, 0.05], [0.1, 0.1, 0.1]] }
"disturbance.period" = { uniform = [8.0, 20.0] }
"initial_state" = { choice = [[-0.8, 3.0, 0.2, 0.0], [-1.0, 2.8, -0.2, -0.1]] }

[falsify]
sequences = 1
"""
RUNS = 6


def _spec(folder: Path, runs: int = RUNS, body: str = SAMPLES, head: str | None = None) -> Path:
    path = folder / f"spec_{runs}.toml"
    head = head if head is not None else f'scenario = "{SCENARIO.as_posix()}"\nruns = {runs}\nseed = 11\n' \
                                         f"duration = 2.0\n"
    path.write_text(head + body, encoding="utf-8")
    return path


def _without_wall(rows: list[dict]) -> list[dict]:
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]


def _stop(proc: subprocess.Popen) -> None:
    """Stop a process we started, by its pid: SIGTERM, then SIGKILL."""
    if proc.poll() is None:
        os.kill(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)


@pytest.fixture(scope="module")
def serial(tmp_path_factory) -> Path:
    """The reference campaign: one worker process."""
    folder = tmp_path_factory.mktemp("serial")
    run_campaign(load_spec(_spec(folder)), folder / "out", workers=1, progress=False)
    return folder / "out"


# ---- the spec -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("head, body, field", [
    (None, "bogus = 1\n", "bogus"),
    (f'scenario = "{SCENARIO.as_posix()}"\nruns = 0\nseed = 1\n', "", "runs"),
    (f'scenario = "{SCENARIO.as_posix()}"\nruns = 2\n', "", "seed"),
    ('scenario = "missing.toml"\nruns = 2\nseed = 1\n', "", "scenario"),
    (None, '[sample]\n"nope.x" = { uniform = [0, 1] }\n', "sample.nope.x"),
    (None, '[sample]\n"disturbance.amplitude" = { uniform = [0, 1] }\n', "sample.disturbance.amplitude.uniform"),
    (None, '[sample]\n"disturbance.period" = { uniform = [5, 1] }\n', "sample.disturbance.period.uniform"),
    (None, '[sample]\n"disturbance.period" = { normal = [5, 1] }\n', "sample.disturbance.period"),
    (None, '[sample]\n"disturbance.period" = { uniform = [-5, -1] }\n', "sample.disturbance.period"),
    (None, '[falsify]\nsequences = -1\n', "falsify.sequences"),
])
def test_a_bad_spec_is_one_line_naming_the_field_exit_2_nothing_written(tmp_path, capsys, head, body, field):
    out = tmp_path / "out"
    code = main(["campaign", str(_spec(tmp_path, 2, body, head)), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and f"error: {field}:" in err, err
    assert not out.exists()


def test_run_seeds_are_spawned_children_and_independent_of_the_run_count(tmp_path):
    children = np.random.SeedSequence(11).spawn(4)
    assert [run_seed(11, k) for k in range(4)] == [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1))
                                                   for c in children]
    small, large = load_spec(_spec(tmp_path, 3)), load_spec(_spec(tmp_path, 50))
    assert small.fingerprint == large.fingerprint
    assert small.plan(2).values == large.plan(2).values and small.plan(2).seed == large.plan(2).seed


def test_the_current_period_is_not_a_certificate_input(tmp_path):
    """The current's period is not a design input (DesignInputs resets it): certify ignores it."""
    import verify

    spec = load_spec(_spec(tmp_path))
    a = spec.plan(0).scenario
    b = a.with_changes(disturbance=type(a.disturbance)(amplitude=a.disturbance.amplitude, period=3.0,
                                                      constant=a.disturbance.constant, sway=a.disturbance.sway))
    assert certificate_key(a) == certificate_key(b)
    da, db = verify.certify(a).to_dict(), verify.certify(b).to_dict()
    for d in (da, db):
        d.pop("elapsed_s")
        d.pop("scenario_data", None)
        d.pop("checksum", None)  # a checksum of the whole stored certificate, scenario_data included
    assert da == db


# ---- reproducibility, resumption, replay ----------------------------------------------------------------

def test_two_workers_equal_one_worker(serial, tmp_path):
    summary = run_campaign(load_spec(_spec(tmp_path)), tmp_path / "out", workers=2, progress=False)
    assert summary["workers"] == 2 and summary["runs"] == RUNS
    assert _without_wall(read_rows(tmp_path / "out")) == _without_wall(read_rows(serial))
    table = pq.read_table(tmp_path / "out" / "runs.parquet").to_pylist()
    assert [r["run"] for r in table] == list(range(RUNS))
    for column in ("seed", "certified", "max_rho_ratio", "min_clearance", "min_e_d", "tracking_rmse",
                   "saturated_steps", "violated", "wall_s", "disturbance.period", "disturbance.amplitude[2]"):
        assert column in table[0]
    summary = json.loads((serial / "summary.json").read_text())
    assert summary["largest_max_rho_ratio"]["max_rho_ratio"] == max(r["max_rho_ratio"] for r in table)
    assert all((serial / "figures" / name).stat().st_size > 0 for name in ("ecdf.png", "worst_runs.png"))


def test_an_interrupted_campaign_resumes_without_recomputing_finished_runs(serial, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(serial, out)
    (out / "runs.parquet").unlink()
    for k in range(0, RUNS, 2):  # the state an interruption leaves: half the runs stored
        (out / "runs" / f"run_{k:06d}.json").unlink()
    kept = {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir()}
    certificates = {p.name: p.stat().st_mtime_ns for p in (out / "certificates").iterdir()}
    summary = run_campaign(load_spec(_spec(tmp_path)), out, workers=1, progress=False)
    assert summary["computed_runs"] == RUNS // 2 and summary["skipped_runs"] == RUNS - RUNS // 2
    assert {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir() if p.name in kept} == kept
    assert {p.name: p.stat().st_mtime_ns for p in (out / "certificates").iterdir()} == certificates  # reused
    assert _without_wall(read_rows(out)) == _without_wall(read_rows(serial))
    assert pq.read_table(out / "runs.parquet").num_rows == RUNS


def test_each_distinct_certificate_is_stored_once_and_the_summary_gives_the_throughput(serial, tmp_path):
    from tubekit.app.certified import read_cached

    spec = load_spec(_spec(tmp_path))
    plans = [spec.plan(k) for k in range(RUNS)]
    distinct = {certificate_key(p.scenario) for p in plans}
    stored = sorted((serial / "certificates").glob("*.json"))
    assert len(stored) == len(distinct) >= 2
    assert all(read_cached(serial / "certificates", p.scenario).certified for p in plans)
    summary = json.loads((serial / "summary.json").read_text())
    assert summary["distinct_certificates"] == len(distinct)
    rate = summary["throughput"]
    assert rate["simulated_s"] == RUNS * 2.0 * 2  # duration 2 s, the scenario's current and one sequence
    assert rate["runs_per_minute"] == pytest.approx(60 * RUNS / summary["campaign_wall_s"])
    assert rate["simulated_s_per_wall_s"] == pytest.approx(RUNS * 4.0 / summary["campaign_wall_s"])


def test_a_stored_certificate_edited_after_issue_is_refused_exit_2(serial, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(serial, out)
    (out / "runs" / "run_000000.json").unlink()
    path = sorted((out / "certificates").glob("*.json"))[0]
    data = json.loads(path.read_text())
    path.write_text(json.dumps({**data, "scenario": "edited"}), encoding="utf-8")
    assert main(["campaign", str(_spec(tmp_path)), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{path.name}.checksum: expected the SHA-256 of the content" in err and len(err.splitlines()) == 1
    assert not (out / "runs" / "run_000000.json").exists()


def test_another_spec_into_the_same_directory_is_refused(serial, tmp_path, capsys):
    other = _spec(tmp_path, RUNS, SAMPLES.replace("8.0, 20.0", "9.0, 20.0"))
    assert main(["campaign", str(other), "--out", str(serial)]) == 2
    assert "--out" in capsys.readouterr().err


def test_simulate_from_campaign_replays_a_run_exactly(serial, tmp_path):
    assert main(["simulate", "--from-campaign", str(serial), "--run", "3", "--out", str(tmp_path / "r")]) == 0
    replay = json.loads((tmp_path / "r" / "replay.json").read_text())
    assert replay["identical"] and replay["replayed"]["max_rho_ratio"] == replay["stored"]["max_rho_ratio"]
    assert (tmp_path / "r" / "trajectory.csv").stat().st_size > 0


# ---- an existing scheduler, and a worker killed mid-campaign --------------------------------------------

def _start_scheduler(folder: Path) -> tuple[subprocess.Popen, str]:
    info = folder / "scheduler.json"
    proc = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                             "--port", "0", "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(info)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not info.exists() and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.2)
    time.sleep(0.3)
    return proc, json.loads(info.read_text())["address"]


def _start_worker(address: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                             "--no-nanny", "--host", "127.0.0.1", "--no-dashboard"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@pytest.mark.slow
def test_a_campaign_on_an_existing_scheduler_survives_a_killed_worker(serial, tmp_path):
    runs = 14
    procs: list[subprocess.Popen] = []
    try:
        scheduler, address = _start_scheduler(tmp_path)
        procs.append(scheduler)
        assert address.startswith("tcp://127.0.0.1:")
        victim, survivor = _start_worker(address), _start_worker(address)
        procs += [victim, survivor]
        out = tmp_path / "out"
        campaign = subprocess.Popen([sys.executable, "-m", "tubekit.app.cli", "campaign", str(_spec(tmp_path, runs)),
                                     "--out", str(out), "--scheduler", address, "--no-progress"],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        procs.append(campaign)
        deadline = time.monotonic() + 90
        while len(list((out / "runs").glob("run_*.json"))) < 2 and time.monotonic() < deadline:
            assert campaign.poll() is None, campaign.communicate()
            time.sleep(0.1)
        stored_at_kill = len(list((out / "runs").glob("run_*.json")))
        os.kill(victim.pid, signal.SIGKILL)  # mid-campaign: its current run is lost and retried elsewhere
        stdout, stderr = campaign.communicate(timeout=120)
        assert campaign.returncode == 0, stderr
    finally:
        for proc in reversed(procs):
            _stop(proc)
    assert stored_at_kill < runs
    rows = pq.read_table(out / "runs.parquet").to_pylist()
    assert [r["run"] for r in rows] == list(range(runs))
    assert _without_wall(rows[:RUNS]) == _without_wall(read_rows(serial))
    assert json.loads((out / "summary.json").read_text())["scheduler"] == address


# ---- issue 21: dense clusters, the backup and the tiers -------------------------------------------------
CLUSTER_SAMPLES = """
[sample]
"obstacles" = { cluster = { count = [4, 7], radius = [0.3, 0.4], gap = [0.01, 0.05], center = [[0.8, 2.2, 0.0], [1.2, 2.6, 0.0]], margin = 0.15 } }
"""


def test_a_cluster_campaign_reports_safety_backup_and_tracking(tmp_path):
    """Clusters on the path at 2-6 s: the summary counts safety breaks (none), backup time and tiers."""
    head = f'scenario = "{SCENARIO.as_posix()}"\nruns = 3\nseed = 5\nduration = 6.0\n'
    summary = run_campaign(load_spec(_spec(tmp_path, 3, CLUSTER_SAMPLES, head)), tmp_path / "out", workers=1,
                           progress=False)
    rows = read_rows(tmp_path / "out")
    assert summary["safety_broken_safe_tier"] == 0
    assert summary["safe_tier_runs"] == sum(r["safe_tier"] for r in rows)
    engaged = [r for r in rows if r["backup_s"] > 0]
    assert summary["backup"]["runs_engaged"] == len(engaged)
    assert summary["backup"]["share_of_simulated_time"] == pytest.approx(sum(r["backup_s"] for r in rows) / 18.0)
    assert all(r["replaced_steps"] >= round(r["backup_s"] / 0.1) - 1 for r in rows)  # the backup follows a replay
    table = pq.read_table(tmp_path / "out" / "runs.parquet").to_pylist()
    assert {"obstacles.count", "backup_s", "safety_broken", "safe_tier", "tracking_tier"} <= set(table[0])
    assert [json.loads(r["obstacles"]) and r["obstacles.count"] for r in table] == \
        [len(json.loads(r["obstacles"])) for r in table]


# ---- issue 35: the paper's own scenario (safe tier only, σ = 0: no tube) ------------------------------------

@pytest.mark.slow
def test_a_campaign_on_the_papers_scenario_exits_0_with_its_figures_and_runs_per_tier(tmp_path):
    """``scenario = "paper"`` certifies the safe tier only, at σ = 0 (no tube: every ratio is null). The CLI
    exits 0, draws both figures and counts the runs per tier; no run is called certified."""
    spec = _spec(tmp_path, 2, "", 'scenario = "paper"\nruns = 2\nseed = 3\nduration = 2.0\n')
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "tubekit", "campaign", str(spec), "--out", str(out),
                           "--workers", "1", "--no-progress"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    assert all((out / "figures" / name).stat().st_size > 0 for name in FIGURES)
    summary = json.loads((out / "summary.json").read_text())
    assert "certified_runs" not in summary and summary["runs"] == 2
    assert summary["runs_by_tier"] == {"both": 0, "safe_only": 2, "none": 0}
    assert summary["tracking_tier_runs"] == 0 and summary["largest_max_rho_ratio"] is None
    assert "0 with both tiers, 2 with the safe tier only, 0 uncertified; no tube ratio" in done.stdout
