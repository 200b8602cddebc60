"""The README's promises: every command in it runs and exits as it says; its Python runs; its links exist.

Every fenced command block is executed (in a scratch directory that sees ``verify/`` and ``examples/``),
each line with the exit code its comment states (``# exit 3``; 0 when none): each line is its own test, run
through ``tubekit.app.cli.main`` (the console script's entry point) so the suite spreads them over its workers,
and one chain of them runs as a process to show the installed command itself works. The Quick start's two
lines are the only ones not run verbatim: ``pip install -e . && tubekit reproduce`` (a 100 s study on
two plants) is stood in for by the README's own ``tubekit reproduce --quick`` line, which runs the same
command for 10 simulated seconds, and ``pip install -e ".[test]" && pytest`` is this suite (CI runs it
verbatim; here it is checked to be exactly that string).
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from tubekit.app.cli import main

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()
QUICK_START = ["pip install -e . && tubekit reproduce", 'pip install -e ".[test]" && pytest']


def _blocks(text: str) -> list[list[str]]:
    """The non-empty lines of every fenced block without a language (commands), in order."""
    return [[ln.strip() for ln in body.splitlines() if ln.strip()]
            for body in re.findall(r"^ *```\n(.*?)^ *```", text, flags=re.S | re.M)]


def _quick_start_block() -> list[str]:
    return _blocks(README.split("## Quick start", 1)[1])[0]


def _commands() -> list[str]:
    """Every command line of the README outside the Quick start."""
    return [ln for block in _blocks(README) for ln in block if ln not in QUICK_START]


def _expected_exit(line: str) -> int:
    found = re.search(r"#\s*exit (\d+)", line)
    return int(found.group(1)) if found else 0


def _parts(line: str) -> list[list[str]]:
    """The argv of each command of ``line`` (``A && B``), its comment dropped; each starts with ``tubekit``."""
    parts = [shlex.split(part) for part in line.split("#", 1)[0].split("&&")]
    for argv in parts:
        assert argv[0] == "tubekit", f"README command not a tubekit command: {argv!r}"
    return parts


def _wanted(line: str) -> list[int]:
    """The exit codes the README states for ``line``: 0 for every command of a chain but the last."""
    return [0] * (len(_parts(line)) - 1) + [_expected_exit(line)]


def _slug(line: str) -> str:
    return re.sub(r"\W+", "_", line.split("#", 1)[0].replace("tubekit ", "")).strip("_")[:70]


@pytest.fixture
def readme_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A scratch working directory that sees ``verify/`` and ``examples/``, as a reader's checkout does."""
    for name in ("verify", "examples"):
        (tmp_path / name).symlink_to(ROOT / name)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_quick_start_has_exactly_two_commands():
    assert _quick_start_block() == QUICK_START


def test_the_quick_start_reproduce_has_a_short_stand_in():
    assert any(ln.startswith("tubekit reproduce --quick") for ln in _commands())


def test_every_outcome_of_certify_is_explained():
    section = README.split("## Certify your design", 1)[1].split("\n## ", 1)[0]
    for outcome in ("**Certified** (exit 0)", "**Safe only** (exit 3)", "**Not certified** (exit 3)",
                    "--search-region", "tubekit envelope", "read the failed conditions"):
        assert outcome in section, outcome


def test_the_dynamic_vehicles_section_is_reserved():
    assert "## Dynamic vehicles" in README


def test_the_readme_has_its_commands():
    assert len(_commands()) >= 6


@pytest.mark.parametrize("line", _commands(), ids=_slug)
def test_each_readme_command_exits_as_stated(line: str, readme_dir: Path, capsys: pytest.CaptureFixture) -> None:
    """The command line's exit codes are the ones its comment states (a chain stops at its first failure)."""
    codes = []
    for argv in _parts(line):
        codes.append(main(argv[1:]))
        if codes[-1] != 0:
            break
    assert codes == _wanted(line), f"{line!r}: exit codes {codes}, README says {_wanted(line)}\n" \
                                   f"{capsys.readouterr().err[-2000:]}"


def test_a_readme_chain_runs_as_a_process(readme_dir: Path) -> None:
    """The certify-then-recheck chain through ``python -m tubekit``, each as its own process: the exit codes the
    README states, no traceback, and the certificate file written between them."""
    line = next(ln for ln in _commands() if "--json" in ln and "recheck" in ln)
    codes = []
    for argv in _parts(line):
        proc = subprocess.run([sys.executable, "-m", "tubekit", *argv[1:]], cwd=readme_dir, capture_output=True,
                              text=True, timeout=600)
        assert "Traceback" not in proc.stderr, proc.stderr[-2000:]
        codes.append(proc.returncode)
    assert codes == _wanted(line)
    assert (readme_dir / "cert.json").is_file()


def test_python_examples_run():
    blocks = re.findall(r"```python\n(.*?)```", README, flags=re.S)
    assert blocks
    for code in blocks:
        exec(compile(code, "README.md", "exec"), {"__name__": "readme_example"})


def test_every_relative_link_and_figure_exists():
    targets = re.findall(r"\]\(([^)#:]+)\)", README)
    assert targets
    missing = [t for t in targets if not (ROOT / t).exists()]
    assert not missing, missing


def test_every_test_the_docs_cite_exists():
    """A test named in the README or ``docs/`` (``tests/test_x.py`` or ``tests/test_x.py::test_y``) exists."""
    missing = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for file, name in re.findall(r"(tests/test_\w+\.py)(?:::(\w+))?", path.read_text(encoding="utf-8")):
            target = ROOT / file
            if not target.is_file() or (name and f"def {name}(" not in target.read_text(encoding="utf-8")):
                missing.append(f"{path.name}: {file}{'::' + name if name else ''}")
    assert not missing, missing
