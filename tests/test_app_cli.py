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
