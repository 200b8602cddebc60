"""The console script: help for every subcommand, version, errors without tracebacks."""

from __future__ import annotations

import subprocess
import sys

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
        tiers = {"safe": False, "tracking": False}
        tier_failures = {"safe": ("fake",), "tracking": ("fake",)}

        def to_dict(self):
            return {"certified": False, "fake": True}

        def summary(self):
            return "fake certificate"

        def best_effort_tightening(self, min_input_fraction=0.5):
            return dc_replace(Tightening.untightened(scenario), sigma=0.5, rho_tilde=0.03,
                              disturbance=(0.0, 0.0, 0.02))
    return Fake()


@pytest.mark.parametrize("flag, shown", [(None, True), ("-q", False), ("-v", True)])
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
    from verify.certificate import NotCertifiedError

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
