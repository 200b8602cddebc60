"""Issue 16: bad inputs to the console script. Each: exit 2, one stderr line naming the field, no traceback,
nothing written. Run in-process through ``tubekit.app.cli.main`` (no certification starts: every check comes
first), two through a subprocess.
"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pytest

from tubekit.app.cli import main

GOOD_TOML = 'name = "ok"\nduration = 2.0\n'


@dataclass(frozen=True)
class Case:
    """One bad input: the TOML text (or None: the paper scenario), extra arguments, the field named."""

    id: str
    field: str
    toml: str | None = GOOD_TOML
    args: tuple[str, ...] = ()
    command: str = "simulate"
    setup: Callable[[Path, pytest.MonkeyPatch], None] | None = None  # may create files, patch the OS
    out: str = "out"  # --out, relative to tmp_path; None: no --out


def _existing_file(tmp: Path, _mp) -> None:
    (tmp / "taken").write_text("a file, not a directory\n")


def _no_write_access(_tmp: Path, mp: pytest.MonkeyPatch) -> None:
    mp.setattr(os, "access", lambda path, mode, **kw: False)


def _mkdtemp_denied(_tmp: Path, mp: pytest.MonkeyPatch) -> None:
    def deny(*args, **kwargs):
        raise PermissionError(13, "Permission denied")
    mp.setattr(tempfile, "mkdtemp", deny)


def _unreadable_config(_tmp: Path, mp: pytest.MonkeyPatch) -> None:
    original = pathlib.Path.read_text

    def read_text(self, *args, **kwargs):
        if self.name == "bad.toml":
            raise PermissionError(13, "Permission denied", str(self))
        return original(self, *args, **kwargs)
    mp.setattr(pathlib.Path, "read_text", read_text)


CASES = [
    # geometry of the start
    Case("obstacle-on-start", "initial_state",
         'initial_state = [3.0, 0.0, 0.0, 0.0]\n'),
    Case("obstacle-placed-on-start", "initial_state",
         '[[obstacles]]\ncenter = [-0.5, 3.0, 0.2]\nradius = 0.4\n'),
    Case("start-in-inflated-obstacle", "initial_state", 'initial_state = [3.0, 0.55, 0.0, 0.0]\n'),
    Case("start-outside-workspace", "initial_state", 'initial_state = [50.0, 3.0, 0.0, 0.0]\n'),
    Case("start-on-target", "initial_state", 'initial_state = [0.0, 3.0, 0.2, 0.0]\n'),
    Case("start-closer-than-epsilon", "initial_state", 'initial_state = [0.05, 3.0, 0.0, 0.0]\n'),
    # sizes
    Case("duration-1e9", "duration", 'duration = 1e9\n'),
    Case("duration-1e6", "duration", 'duration = 1e6\n'),
    Case("rate-1e9-hz", "controller.ancillary_rate_hz", '[controller]\nancillary_rate_hz = 1e9\n'),
    Case("cli-duration-1e9", "duration", args=("--duration", "1e9")),
    Case("cli-duration-nan", "--duration", args=("--duration", "nan")),
    Case("duration-nan", "duration", 'duration = nan\n'),
    Case("duration-inf", "duration", 'duration = inf\n'),
    Case("duration-negative", "duration", 'duration = -5.0\n'),
    # horizon and limits
    Case("horizon-100000", "controller.horizon_steps", '[controller]\nhorizon_steps = 100000\n'),
    Case("horizon-400", "controller.horizon_steps", '[controller]\nhorizon_steps = 400\n'),
    Case("horizon-zero", "controller.horizon_steps", '[controller]\nhorizon_steps = 0\n'),
    Case("horizon-fraction", "controller.horizon_steps", '[controller]\nhorizon_steps = 2.5\n'),
    Case("u-max-40", "limits.u_max", '[limits]\nu_max = 40\n'),
    Case("r-max-negative", "limits.r_max", '[limits]\nr_max = -1.0\n'),
    Case("workspace-too-narrow", "workspace",
         'obstacles = []\nworkspace = [[-0.8, 2.7, -1.0], [-0.2, 3.3, 1.0]]\n'),
    Case("workspace-inverted", "workspace", 'workspace = [[10.0, -10.0, -5.0], [-10.0, 10.0, 5.0]]\n'),
    Case("dt-negative", "controller.dt", '[controller]\ndt = -0.1\n'),
    # other values
    Case("epsilon-zero", "epsilon", 'epsilon = 0.0\n'),
    Case("state-three-numbers", "initial_state", 'initial_state = [0.0, 0.0, 0.0]\n'),
    Case("state-string", "initial_state", 'initial_state = ["a", 0.0, 0.0, 0.0]\n'),
    Case("vehicle-wider-than-sensing", "sensing_range", 'vehicle_radius = 2.0\n'),
    Case("obstacles-overlap", "obstacles[0], obstacles[1]",
         '[[obstacles]]\ncenter = [3.0, 0.0, 0.0]\nradius = 0.4\n'
         '[[obstacles]]\ncenter = [3.5, 0.0, 0.0]\nradius = 0.4\n'),
    Case("key-under-wrong-table", "controller.e_o_max", '[controller]\ne_o_max = 0.5\n'),
    Case("top-level-key-after-table", "trajectory", '[trajectory]\nkind = "circle"\nduration = 50.0\n'),
    # the CONFIG file
    Case("config-binary", "CONFIG", toml="\x00\xff\xfe binary"),
    Case("config-missing", "CONFIG", toml=None, args=("missing.toml",)),
    Case("config-directory", "CONFIG", toml=None, args=(".",)),
    Case("config-unreadable", "CONFIG", setup=_unreadable_config),
    Case("config-toml-syntax", "CONFIG", 'duration = = 1\n'),
    # --out
    Case("out-is-a-file", "--out", setup=_existing_file, out="taken"),
    Case("out-under-a-file", "--out", setup=_existing_file, out="taken/sub"),
    Case("out-not-writable", "--out", setup=_no_write_access),
    Case("out-cannot-be-created", "--out", setup=_mkdtemp_denied),
    Case("reproduce-out-is-a-file", "--out", toml=None, command="reproduce", setup=_existing_file, out="taken"),
    Case("reproduce-duration-1e9", "duration", toml=None, command="reproduce", args=("--duration", "1e9")),
    # --json of the other commands (checked before their work)
    Case("certify-json-in-missing-dir", "--json", toml=None, command="certify",
         args=("--json", "nowhere/cert.json"), out=""),
    Case("audit-json-is-a-directory", "--json", toml=None, command="audit", args=("--json", "."), out=""),
    # issue 24 item 1: products and counts that overflow, huge counts, output formats -- before any work
    Case("duration-1e308", "duration", 'duration = 1e308\n'),
    Case("cli-duration-max-float", "--duration", args=("--duration", "1.7976931348623157e308")),
    Case("reproduce-duration-1e308", "--duration", toml=None, command="reproduce", args=("--duration", "1e308")),
    Case("rate-times-dt-overflows", "controller.ancillary_rate_hz",
         '[controller]\ndt = 10.0\nancillary_rate_hz = 1e308\nhorizon_steps = 1\n'),
    Case("current-1e200", "disturbance.constant", '[disturbance]\nconstant = [1e200, 0.0, 0.0]\n'),
    Case("envelope-plot-xyz", "--plot", toml=None, command="envelope", args=("--plot", "out.xyz"), out=""),
    Case("certify-max-boxes-1e12", "--max-boxes", toml=None, command="certify", args=("--max-boxes", "10" * 6),
         out=""),
    Case("audit-samples-1e9", "--samples", toml=None, command="audit", args=("--samples", "1000000000"), out=""),
    Case("falsify-budget-1e9", "--budget", toml=None, command="falsify", args=("--budget", "1000000000"), out=""),
    Case("falsify-seed-negative", "--seed", toml=None, command="falsify", args=("--seed", "-1"), out=""),
    Case("falsify-duration-1e308", "--duration", toml=None, command="falsify",
         args=("--closed-loop", "--duration", "1e308"), out=""),
    Case("campaign-workers-0", "--workers", command="campaign", args=("--workers", "0")),
    Case("falsify-sigma-1e308", "--sigma", toml=None, command="falsify", args=("--sigma", "1e308"), out=""),
    Case("sigma-1e308", "controller.sigma", '[controller]\nsigma = 1e308\n', command="certify", out=""),
    Case("envelope-eps-1e308", "--eps", toml=None, command="envelope", args=("--eps", "1e308"), out=""),
    # item 2: strict types; a target that leaves the workspace; one validation for every command
    Case("duration-string", "duration", 'duration = "100"\n'),
    Case("duration-bool", "duration", 'duration = true\n'),
    Case("name-number", "name", 'name = 5\n'),
    Case("horizon-bool", "controller.horizon_steps", '[controller]\nhorizon_steps = true\n'),
    Case("circle-1e6", "trajectory", '[trajectory]\nkind = "circle"\nradius = 1e6\n'),
    Case("certify-circle-1e6", "trajectory", '[trajectory]\nkind = "circle"\nradius = 1e6\n', command="certify",
         out=""),
    Case("certify-start-on-target", "initial_state", 'initial_state = [0.0, 3.0, 0.2, 0.0]\n', command="certify",
         out=""),
    Case("envelope-start-on-target", "initial_state", 'initial_state = [0.0, 3.0, 0.2, 0.0]\n',
         command="envelope", out=""),
    Case("falsify-start-on-target", "initial_state", 'initial_state = [0.0, 3.0, 0.2, 0.0]\n', command="falsify",
         out=""),
    Case("certify-duration-string", "duration", 'duration = "100"\n', command="certify", out=""),
    # item 3: the error names the right field
    Case("line-wrong-key", "['start', 'velocity']", '[trajectory]\nkind = "line"\nvel = [0.1, 0.0, 0.0]\n'),
    Case("dt-1e-9", "controller.dt", '[controller]\ndt = 1e-9\n'),
    # item 12: --law is one option everywhere
    Case("simulate-law-unknown", "--law", args=("--law", "nonsense")),
    Case("certify-law-unknown", "--law", command="certify", args=("--law", "nonsense"), out=""),
    Case("falsify-law-unknown", "--law", command="falsify", args=("--law", "nonsense"), out=""),
    Case("falsify-duration-without-closed-loop", "--duration", toml=None, command="falsify",
         args=("--duration", "2"), out=""),
]


def _snapshot(root: Path) -> dict[str, bytes | None]:
    """Every path under ``root`` (hidden ones included) with its bytes (None for directories)."""
    return {str(p.relative_to(root)): (None if p.is_dir() else p.read_bytes()) for p in root.rglob("*")}


def _params() -> list:
    return [pytest.param(c, id=c.id) for c in CASES]


@pytest.mark.parametrize("case", _params())
def test_bad_input(case: Case, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = [case.command]
    if case.toml is not None:
        (tmp_path / "bad.toml").write_bytes(case.toml.encode("latin-1"))
        argv.append("bad.toml")
    argv += list(case.args)
    if case.out:
        argv += ["--out", case.out]
    if case.command in ("simulate", "reproduce"):
        argv.append("--no-progress")
    before = _snapshot(tmp_path)
    if case.setup is not None:
        case.setup(tmp_path, monkeypatch)
        before = _snapshot(tmp_path)
    rc = main(argv)
    monkeypatch.undo()
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert rc == 2, (rc, err)
    assert len(err.splitlines()) == 1, err
    assert case.field in err, err
    assert "Traceback" not in err and "__init__" not in err and "array(" not in err
    assert _snapshot(tmp_path) == before  # nothing written, no staging directory left


def test_table_is_large_enough():
    assert len(CASES) >= 60


@pytest.mark.parametrize("text, field", [("\x00\xff binary", "CONFIG"), ("duration = 1e9\n", "duration")])
def test_bad_input_through_the_console_script(text, field, tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_bytes(text.encode("latin-1"))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "tubekit.app.cli", "simulate", str(cfg), "--out", str(out)],
                          capture_output=True, text=True, timeout=600)  # a hang guard, not a verdict
    assert proc.returncode == 2
    err = proc.stderr.strip()
    assert field in err and "Traceback" not in err and len(err.splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("argv, field", [
    (["simulate", "{cfg}", "--out", "{out}", "--duration", "1.7976931348623157e308"], "--duration"),
    (["envelope", "--plot", "{out}.xyz"], "--plot"),
    (["certify", "{cfg}"], "initial_state"),
    (["simulate", "{cfg}", "--out", "{out}"], "initial_state"),
])
def test_issue_24_frictions_through_the_console_script(argv, field, tmp_path):
    """Issue 24 items 1-2 as a user meets them: exit 2, one line naming the field, no traceback, nothing written.

    The CONFIG puts the start exactly on the target (simulate and certify refuse it alike)."""
    cfg = tmp_path / "on_target.toml"
    cfg.write_text("initial_state = [0.0, 3.0, 0.2, 0.0]\n" if field == "initial_state" else "duration = 2.0\n")
    out = tmp_path / "out"
    args = [a.format(cfg=cfg, out=out) for a in argv]
    before = _snapshot(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "tubekit.app.cli", *args], capture_output=True, text=True,
                          timeout=600, cwd=tmp_path)  # a hang guard, not a verdict
    err = proc.stderr.strip()
    assert proc.returncode == 2, err
    assert len(err.splitlines()) == 1 and field in err and "Traceback" not in err
    assert _snapshot(tmp_path) == before
