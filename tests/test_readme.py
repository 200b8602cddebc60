"""The README's promises: every command in it runs and exits as it says; its Python runs; its links exist.

Every fenced command block is executed (in a scratch directory that sees ``verify/`` and ``examples/``),
each line with the exit code its comment states (``# exit 3``; 0 when none). The Quick start's two
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
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

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


def _run(line: str, cwd: Path) -> tuple[str, list[tuple[int, str]]]:
    """Run ``line`` (``A && B``: each in turn, stopping at a failure); per part its exit code and stderr."""
    results = []
    for part in line.split("#", 1)[0].split("&&"):
        argv = shlex.split(part)
        assert argv[0] == "tubekit", f"README command not a tubekit command: {part!r}"
        proc = subprocess.run([sys.executable, "-m", "tubekit", *argv[1:]], cwd=cwd, capture_output=True,
                              text=True, timeout=600)
        results.append((proc.returncode, proc.stderr))
        if proc.returncode != 0:
            break
    return line, results


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


@pytest.mark.slow(80)
def test_every_readme_command_runs_and_exits_as_stated(tmp_path):
    """Each command line, two at a time: the exit code its comment states, no traceback."""
    for name in ("verify", "examples"):
        (tmp_path / name).symlink_to(ROOT / name)
    commands = _commands()
    assert len(commands) >= 6
    with ThreadPoolExecutor(max_workers=2) as pool:
        outcomes = list(pool.map(lambda ln: _run(ln, tmp_path), commands))
    for line, results in outcomes:
        codes = [code for code, _ in results]
        want = [0] * (len(line.split("#", 1)[0].split("&&")) - 1) + [_expected_exit(line)]
        assert codes == want, f"{line!r}: exit codes {codes}, README says {want}\n{results[-1][1][-2000:]}"
        assert not any("Traceback" in err for _, err in results), f"{line!r} printed a traceback"


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
