"""Every tutorial runs top to bottom (reduced sizes) and writes the figures it promises."""

from __future__ import annotations

import re
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


def _build_notebooks():
    sys.path.insert(0, str(TUTORIALS))
    try:
        import build_notebooks
    finally:
        sys.path.remove(str(TUTORIALS))
    return build_notebooks


@pytest.mark.slow(30)
@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_tutorial_runs_as_an_executed_notebook(path, tmp_path, monkeypatch):
    """Each tutorial, converted with jupytext and executed with nbclient (quick sizes): no error, its prose,
    its figures inline, and the figure files it promises."""
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    monkeypatch.setenv("TUBEKIT_QUICK", "1")
    monkeypatch.setenv("TUBEKIT_FIGURES", str(tmp_path))
    out = _build_notebooks().build(path, tmp_path / "nb", tmp_path, timeout_s=600)
    nb = nbformat.read(str(out), as_version=4)
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert sum(c.cell_type == "markdown" for c in nb.cells) >= 2
    assert any("image/png" in o.get("data", {}) for o in outputs), f"{path.name}: no figure inline"
    readme = (TUTORIALS / "README.md").read_text()
    for fig in _promised_figures(readme, path.name):
        assert (tmp_path / fig).is_file(), f"{path.name} did not write {fig}"
        assert (tmp_path / fig).stat().st_size > 10_000


def test_executed_notebooks_are_shipped_and_linked():
    readme = (TUTORIALS / "README.md").read_text()
    for f in FILES:
        nb = TUTORIALS / "notebooks" / f"{f.stem}.ipynb"
        assert nb.is_file(), f"run python tutorials/build_notebooks.py: {nb.name} is missing"
        assert f"notebooks/{f.stem}.ipynb" in readme


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_tutorial_is_jupytext_percent_and_public_api_only(path):
    text = path.read_text()
    assert "format_name: percent" in text and "# %% [markdown]" in text
    assert "plt.show()" not in text
    for mod in re.findall(r"^from (\S+) import|^import (\S+)", text, flags=re.M):
        name = mod[0] or mod[1]
        assert not re.search(r"\._", name), f"{path.name} imports a private module {name}"


def _notebook(path):
    nbformat = pytest.importorskip("nbformat")
    return nbformat.read(str(TUTORIALS / "notebooks" / f"{path.stem}.ipynb"), as_version=4)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_executed_notebook_cells_are_the_tutorials(path):
    """The committed notebook runs the tutorial's current source, cell by cell (prose included)."""
    jupytext = pytest.importorskip("jupytext")
    source = [(c.cell_type, c.source) for c in jupytext.read(path).cells]
    shipped = [(c.cell_type, c.source) for c in _notebook(path).cells]
    assert shipped == source, f"{path.name} changed since its notebook was executed: run python docs/regenerate.py"


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_executed_notebook_carries_the_stored_fingerprint(path):
    """The notebook was executed on code with the fingerprint of docs/artefacts.json (which
    tests/test_regenerate.py recomputes): its printed certificates and runs are the code's."""
    import json

    stored = json.loads((TUTORIALS.parent / "docs" / "artefacts.json").read_text())["fingerprint"]
    stamp = _notebook(path).metadata.get("tubekit", {}).get("fingerprint")
    assert stamp == stored, f"{path.stem}.ipynb is stale: run python docs/regenerate.py"
