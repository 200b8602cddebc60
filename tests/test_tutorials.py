"""Every tutorial runs top to bottom (reduced sizes) and writes the figures it promises."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

TUTORIALS = Path(__file__).resolve().parent.parent / "tutorials"
FILES = sorted(TUTORIALS.glob("[0-9][0-9]_*.py"))


def _promised_figures(readme: str, name: str) -> list[str]:
    for line in readme.splitlines():
        if name in line:
            return re.findall(r"`([\w.-]+\.png)`", line)
    return []


def test_tutorials_are_listed_in_order():
    readme = (TUTORIALS / "README.md").read_text()
    numbers = [int(f.name[:2]) for f in FILES]
    assert numbers == list(range(1, len(FILES) + 1))
    for f in FILES:
        assert f.name in readme, f"{f.name} missing from tutorials/README.md"
        assert _promised_figures(readme, f.name), f"no figure listed for {f.name}"


@pytest.mark.slow
@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_tutorial_runs(path, tmp_path):
    env = dict(os.environ, TUBEKIT_QUICK="1", TUBEKIT_FIGURES=str(tmp_path), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, str(path)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    readme = (TUTORIALS / "README.md").read_text()
    for fig in _promised_figures(readme, path.name):
        assert (tmp_path / fig).is_file(), f"{path.name} did not write {fig}"
        assert (tmp_path / fig).stat().st_size > 10_000


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_tutorial_is_jupytext_percent_and_public_api_only(path):
    text = path.read_text()
    assert "format_name: percent" in text and "# %% [markdown]" in text
    assert "plt.show()" not in text
    for mod in re.findall(r"^from (\S+) import|^import (\S+)", text, flags=re.M):
        name = mod[0] or mod[1]
        assert not re.search(r"\._", name), f"{path.name} imports a private module {name}"
