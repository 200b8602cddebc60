"""The campaign's local cluster (tubekit.app.campaign_cluster): workers on 127.0.0.1 forked from the warm
fork server, deaf to Ctrl-C, which the client turns into exit 130 after stopping them. Every process is
started here and stopped by its id."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from tubekit.app.campaign_cluster import PRELOAD, open_client  # noqa: E402
from tubekit.exceptions import ConfigError  # noqa: E402

SCENARIO = Path(__file__).resolve().parents[1] / "verify" / "scenarios" / "paper_currents.toml"


def test_the_workers_are_forks_of_the_fork_server_on_the_loopback_deaf_to_ctrl_c():
    def probe() -> tuple:
        import signal as sig

        return (os.getppid(), sig.getsignal(sig.SIGINT) is sig.SIG_IGN, os.environ.get("OMP_NUM_THREADS"),
                all(name in sys.modules for name in PRELOAD))

    with open_client(2, None) as client:
        addresses = list(client.scheduler_info()["workers"])
        found = client.gather([client.submit(probe, pure=False, workers=[a]) for a in addresses])
    assert len(addresses) == 2 and all(a.startswith("tcp://127.0.0.1:") for a in addresses)
    parents = {parent for parent, *_ in found}
    assert len(parents) == 1 and os.getpid() not in parents  # one parent, the fork server, not this process
    assert [tuple(rest) for _, *rest in found] == [(True, "1", True)] * 2


def test_without_a_fork_server_nothing_is_started(monkeypatch):
    """Where the platform has no fork server (Windows), the workers are spawned as dask does by default."""
    import multiprocessing

    from tubekit.app.campaign_cluster import start_fork_server

    monkeypatch.setattr(multiprocessing, "get_all_start_methods", lambda: ["spawn"])
    assert start_fork_server(None) is False


@pytest.mark.parametrize("address", ["127.0.0.1:8786", "udp://127.0.0.1:8786"])
def test_a_scheduler_address_without_tcp_is_refused(address):
    with pytest.raises(ConfigError, match="--scheduler"):
        with open_client(1, address):
            pass


def _group(pgid: int) -> list[str]:
    """The live (not zombie) processes of process group ``pgid``."""
    listed = subprocess.run(["ps", "-eo", "pgid=,stat="], capture_output=True, text=True).stdout.split("\n")
    return [line for line in listed if line.split() and line.split()[0] == str(pgid) and "Z" not in line.split()[1]]


def test_ctrl_c_stops_the_workers_and_exits_130_in_one_line(tmp_path):
    """Ctrl-C after the first finished run: 60 runs, so the campaign is still running when the signal arrives on a
    loaded machine too (the interrupt, not the campaign's end, must decide the exit code)."""
    spec = tmp_path / "spec.toml"
    spec.write_text(f'scenario = "{SCENARIO.as_posix()}"\nruns = 60\nseed = 3\nduration = 6.0\n', encoding="utf-8")
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "tubekit.app.cli", "campaign", str(spec), "--out", str(out),
                             "--workers", "2", "--no-progress"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)  # its own group: a terminal's Ctrl-C reaches all
    try:
        deadline = time.monotonic() + 120
        while not list((out / "runs").glob("run_*.json")) and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr and stderr.strip().splitlines()[-1].startswith("tubekit campaign: interrupted")
    deadline = time.monotonic() + 15
    while _group(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _group(proc.pid)  # the fork server and every worker are gone with the client


def test_the_warm_up_copy_is_short_and_never_certifies_a_dynamic_design():
    """The warm-up runs 1 s and, for a dynamic campaign, on the kinematic plant (its certificate is discarded)."""
    from tubekit.app.campaign_cluster import WARM_DURATION_S, warm_scenario
    from tubekit.scenario import load_scenario
    root = Path(__file__).resolve().parents[1]
    kinematic = load_scenario(SCENARIO)
    dynamic = load_scenario(root / "examples" / "bluerov2_currents.toml")
    assert warm_scenario(kinematic) == kinematic.with_changes(duration=1.0) and WARM_DURATION_S == 1.0
    warm = warm_scenario(dynamic)
    assert warm.plant.kind == "kinematic" and dynamic.plant.kind == "dynamic"
    assert warm.duration == 1.0 and warm.trajectory == dynamic.trajectory and warm.limits == dynamic.limits


def test_the_warm_up_copy_of_a_lateral_backup_campaign_is_a_valid_kinematic_scenario():
    """A campaign whose backup commands sway (the hold law, which only a dynamic plant with lateral thrust takes):
    the kinematic warm-up copy falls back to station keeping instead of being refused."""
    from tubekit.app.campaign_cluster import warm_scenario
    from tubekit.scenario import load_scenario
    pier = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_pier.toml")
    warm = warm_scenario(pier)
    assert pier.controller.backup == "hold" and warm.controller.backup == "station_keeping"
    assert warm.plant.kind == "kinematic" and warm.duration == 1.0


def test_the_warm_up_copy_of_a_settled_start_campaign_is_a_valid_kinematic_scenario():
    """A campaign whose loop starts settled (``[plant] start = "settled"``, which only the dynamic plant takes): the
    kinematic warm-up copy starts trimmed instead of being refused (it was: 'plant.start: expected 'trimmed' on the
    kinematic plant')."""
    from tubekit.app.campaign_cluster import warm_scenario
    from tubekit.scenario import load_scenario
    underway = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_published_underway.toml")
    warm = warm_scenario(underway)
    assert underway.plant.settled and warm.plant.kind == "kinematic" and not warm.plant.settled
