"""The console script: help for every subcommand, version, errors without tracebacks."""

from __future__ import annotations

from tubekit.tiers import Tiers

import subprocess
import sys

import numpy as np
import pytest

from tubekit import __version__
from tubekit.app.cli import SUBCOMMANDS, Subcommand, main


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_every_subcommand_has_help(name, capsys):
    with pytest.raises(SystemExit) as exc:
        main([name, "--help"])
    assert exc.value.code == 0
    assert "usage: tubekit " + name in capsys.readouterr().out


def test_version(capsys):
    with pytest.raises(SystemExit):
        main(["--version"])
    assert __version__ in capsys.readouterr().out


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "COMMAND" in capsys.readouterr().out


def test_console_script_installed():
    out = subprocess.run([sys.executable, "-m", "tubekit.app.cli", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "reproduce" in out.stdout


def test_missing_dependency_disables_only_that_command(monkeypatch, capsys):
    import tubekit.app.cli as cli

    def configure_broken(parser):
        import tubekit._no_such_module_for_test  # noqa: F401

    monkeypatch.setitem(cli.SUBCOMMANDS, "broken", Subcommand("a broken command", configure_broken, lambda args: 0))
    assert main(["broken"]) == 1
    err = capsys.readouterr().err
    assert "not available" in err and "_no_such_module_for_test" in err
    assert main(["audit", "--samples", "20"]) == 0  # the others still work


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_every_subcommand_takes_verbose_and_quiet(name, capsys):
    with pytest.raises(SystemExit):
        main([name, "--help"])
    out = capsys.readouterr().out
    assert "-v, --verbose" in out and "-q, --quiet" in out


def _fake_certify(scenario, law=None):
    from dataclasses import replace as dc_replace

    from tubekit import Tightening

    from types import SimpleNamespace

    class Fake:
        certified = False
        failures = [SimpleNamespace(condition="fake")]
        disturbance = SimpleNamespace(gamma=0.02)  # read by the dynamic-plant part of reproduce
        tiers = Tiers(False, False)
        tier_failures = {"safe": ("fake",), "tracking": ("fake",)}
        inputs, law, sigma_source = SimpleNamespace(sigma=0.5), "corrected", "fake"
        tried, tube = (SimpleNamespace(sigma=0.5),), SimpleNamespace(certified=False, rho=(0.03, 0.0, 0.0))

        def to_dict(self):
            return {"certified": False, "fake": True}

        def summary(self, verbose=False):
            return "fake certificate"

        def best_effort_tightening(self, min_input_fraction=0.5):
            return dc_replace(Tightening.untightened(scenario), sigma=0.5, tube=np.array([0.03, 0.0, 0.0]),
                              disturbance=(0.0, 0.0, 0.02))
    return Fake()


@pytest.mark.parametrize("flag, shown", [(None, True), ("-q", False), ("-v", True)])
@pytest.mark.slow
def test_diagnostics_are_logged_on_stderr_results_on_stdout(flag, shown, tmp_path, monkeypatch, capsys):
    pytest.importorskip("tubekit.fhocp")
    import verify

    monkeypatch.setattr(verify, "certify", _fake_certify, raising=False)
    argv = ["reproduce", "--out", str(tmp_path / "r"), "--duration", "1", "--no-progress"] + ([flag] if flag else [])
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert ("certifying" in captured.err) is shown and "certifying" not in captured.out
    assert "wrote" in captured.out and "min_clearance" in captured.out  # results stay on stdout


# ---- exit codes by error type: one row of tubekit.app.exit_codes.error_table each ---------------------------

def _raise(exc):
    def run(args):
        raise exc
    return run


def _error_rows():
    from verify.certificate.certify import NotCertifiedError

    from tubekit.exceptions import ConfigError, NotAvailableError, ShapeError, SolverError, TubekitError

    return [
        (ConfigError("--out", "a directory", "x.txt"), 2, "error: --out: expected a directory"),
        (ShapeError("initial_state", "(4,)", (3,)), 2, "error: initial_state: expected shape (4,)"),
        (NotCertifiedError("scenario 'x' is not certified"), 3, "not certified: scenario 'x' is not certified"),
        (SolverError("IPOPT failed"), 1, "solver failed: IPOPT failed"),
        (NotAvailableError("cyipopt is not installed"), 1, "not available: cyipopt is not installed. Try: pip install"),
        (ImportError("No module named 'dask'"), 1, "not available: No module named 'dask'. Try: pip install"),
        (TubekitError("a state nobody expected"), 1, "internal error: TubekitError: a state nobody expected"),
        (FileNotFoundError(2, "No such file or directory", "cfg.toml"), 2, "error: cfg.toml: No such file"),
        (KeyboardInterrupt(), 130, "interrupted"),
    ]


@pytest.mark.parametrize("row", range(9))
def test_each_error_type_has_its_exit_code_and_one_line(row, monkeypatch, capsys):
    import tubekit.app.cli as cli

    exc, code, message = _error_rows()[row]
    monkeypatch.setitem(cli.SUBCOMMANDS, "failing", Subcommand("raises", lambda parser: None, _raise(exc)))
    assert main(["failing"]) == code
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert err.startswith(f"tubekit failing: {message}")


def test_an_error_outside_the_table_is_not_hidden(monkeypatch):
    import tubekit.app.cli as cli

    monkeypatch.setitem(cli.SUBCOMMANDS, "buggy", Subcommand("a bug", lambda parser: None,
                                                             _raise(ZeroDivisionError("a bug"))))
    with pytest.raises(ZeroDivisionError, match="a bug"):
        main(["buggy"])


def test_a_multi_line_error_is_reported_on_one_line(monkeypatch, capsys):
    import tubekit.app.cli as cli
    from tubekit.exceptions import SolverError

    monkeypatch.setitem(cli.SUBCOMMANDS, "noisy", Subcommand("x", lambda parser: None,
                                                             _raise(SolverError("first\nsecond\nthird"))))
    assert main(["noisy"]) == 1
    assert capsys.readouterr().err == "tubekit noisy: solver failed: first\n"


def test_bad_input_exits_2_in_a_subprocess(tmp_path):
    out = subprocess.run([sys.executable, "-m", "tubekit.app.cli", "simulate", str(tmp_path / "none.toml")],
                         capture_output=True, text=True)
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1
    assert out.stderr.startswith("tubekit simulate: error: CONFIG")


# ---- issue 24 item 4: the campaign without its extra --------------------------------------------------------

def _without_dask(monkeypatch):
    import importlib.util

    import tubekit.app.commands_study as commands_study

    real = importlib.util.find_spec
    monkeypatch.setattr(commands_study.importlib.util, "find_spec",
                        lambda name, *a: None if name in ("distributed", "pyarrow") else real(name, *a))


def test_campaign_help_lists_every_argument_without_dask(monkeypatch, capsys):
    _without_dask(monkeypatch)
    with pytest.raises(SystemExit):
        main(["campaign", "--help"])
    out = capsys.readouterr().out
    assert all(word in out for word in ("SPEC", "--out DIR", "--workers N", "--scheduler", "--no-progress"))
    assert 'pip install -e ".[campaign]"' in " ".join(out.split())  # argparse wraps the epilog


def test_campaign_without_dask_is_one_line_naming_the_extra(monkeypatch, capsys, tmp_path):
    _without_dask(monkeypatch)
    spec = tmp_path / "small.toml"
    spec.write_text("runs = 2\n")
    assert main(["campaign", str(spec), "--out", str(tmp_path / "x")]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("tubekit campaign: not available: distributed and pyarrow")
    assert err.endswith('Try: pip install -e ".[campaign]"') and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml"]


# ---- issue 24 item 10: a lock on --out ------------------------------------------------------------------------

class _Done:
    def check(self) -> bool:
        return True


def _fake_study(seen: list):
    def run_study(scenario, out, **kwargs):
        seen.append(sorted(p.name for p in out.parent.iterdir()))
        return _Done()
    return run_study


def _simulate(tmp_path) -> list[str]:
    cfg = tmp_path / "ok.toml"
    cfg.write_text("duration = 2.0\n")
    return ["simulate", str(cfg), "--out", str(tmp_path / "out"), "--no-progress"]


def test_a_run_holds_the_lock_and_removes_it(tmp_path, monkeypatch):
    import tubekit.app.study as study

    seen: list = []
    monkeypatch.setattr(study, "run_study", _fake_study(seen))
    assert main(_simulate(tmp_path)) == 0
    assert ".out.lock" in seen[0] and not (tmp_path / ".out.lock").exists()


def test_the_lock_is_removed_on_errors(tmp_path, monkeypatch, capsys):
    import tubekit.app.study as study
    from tubekit.exceptions import SolverError

    def failing(scenario, out, **kwargs):
        assert (tmp_path / ".out.lock").exists()
        raise SolverError("no plan")
    monkeypatch.setattr(study, "run_study", failing)
    assert main(_simulate(tmp_path)) == 1
    assert not (tmp_path / ".out.lock").exists()


def test_a_stale_lock_of_a_dead_process_is_taken_over(tmp_path, monkeypatch):
    import tubekit.app.study as study

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    (tmp_path / ".out.lock").write_text(dead.stdout)  # that process has exited
    seen: list = []
    monkeypatch.setattr(study, "run_study", _fake_study(seen))
    assert main(_simulate(tmp_path)) == 0
    assert seen and not (tmp_path / ".out.lock").exists()


def test_a_second_concurrent_run_refuses_with_one_line(tmp_path):
    """Another process holds the lock (tubekit.app.output.OutputLock, as a run does): simulate exits 2 at once."""
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time\nfrom pathlib import Path\nfrom tubekit.app.output import OutputLock\n"
         f"with OutputLock(Path({str(tmp_path / 'out')!r})):\n    print('locked', flush=True)\n"
         "    sys.stdin.readline()\n"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        lock = (tmp_path / ".out.lock").read_text()
        proc = subprocess.run([sys.executable, "-m", "tubekit.app.cli", *_simulate(tmp_path)], capture_output=True,
                              text=True, timeout=600)  # a hang guard, not a verdict
        err = proc.stderr.strip()
        assert proc.returncode == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
        assert err.startswith("tubekit simulate: error: --out: expected a directory no other tubekit run is writing")
        assert f"pid {holder.pid}" in err
        assert (tmp_path / ".out.lock").read_text() == lock and not (tmp_path / "out").exists()
    finally:
        holder.communicate("\n", timeout=60)
    assert holder.returncode == 0 and not (tmp_path / ".out.lock").exists()


# ---- issue 24 item 3: a full disk is the machine's fault: exit 1, the path ------------------------------------

def test_a_full_disk_exits_1_naming_the_path(tmp_path, monkeypatch, capsys):
    import errno

    import tubekit.app.study as study
    from tubekit.app.output import StagedOutput

    def run_study(scenario, out, **kwargs):
        with StagedOutput(out) as staged:
            (staged.path / "metrics.json").write_text("{}")
            raise OSError(errno.ENOSPC, "No space left on device")  # a write() names no file
    monkeypatch.setattr(study, "run_study", run_study)
    assert main(_simulate(tmp_path)) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"tubekit simulate: cannot write {tmp_path / 'out'}: No space left on device")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.toml"]  # no staging directory, no lock left


# ---- issue 24 item 11: Ctrl-C in a campaign: the workers ignore it, the client stops them ------------------

def _child_sigint() -> str:
    probe = "import signal; print('ignored' if signal.getsignal(signal.SIGINT) is signal.SIG_IGN else 'handled')"
    return subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True).stdout.strip()


def test_processes_started_in_the_block_ignore_ctrl_c():
    """A dask worker spawned inside ``children_ignore_interrupts`` has SIGINT ignored (no KeyboardInterrupt
    traceback of its own); the parent's handler is back after the block."""
    import signal

    from tubekit.app.exit_codes import children_ignore_interrupts

    before, child_before = signal.getsignal(signal.SIGINT), _child_sigint()
    with children_ignore_interrupts():
        assert _child_sigint() == "ignored"
    assert signal.getsignal(signal.SIGINT) is before and _child_sigint() == child_before


def test_a_ctrl_c_a_library_swallows_is_raised_again_when_the_block_ends():
    """Inside ``interrupts_remembered`` a SIGINT raises KeyboardInterrupt; caught and dropped by the code inside (as
    a closing cluster may), it is raised again at the block's end, and the previous handler is back."""
    import os
    import signal

    from tubekit.app.exit_codes import interrupts_remembered

    before = signal.getsignal(signal.SIGINT)
    caught = []
    with pytest.raises(KeyboardInterrupt):
        with interrupts_remembered():
            try:
                os.kill(os.getpid(), signal.SIGINT)
                for _ in range(1000):  # the handler runs at the next bytecode boundary
                    pass
            except KeyboardInterrupt:
                caught.append(True)  # swallowed, as a library might
    assert caught == [True] and signal.getsignal(signal.SIGINT) is before
    with interrupts_remembered():  # no Ctrl-C: nothing raised
        pass
