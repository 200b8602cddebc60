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
        failures = [{"condition": "fake"}]
        disturbance = SimpleNamespace(gamma=0.02)  # read by the dynamic-plant part of reproduce

        def to_dict(self):
            return {"certified": False, "fake": True}

        def summary(self):
            return "fake certificate"

        def best_effort_tightening(self, min_input_fraction=0.5):
            return dc_replace(Tightening.untightened(scenario), sigma=0.5, rho_tilde=0.03)
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
