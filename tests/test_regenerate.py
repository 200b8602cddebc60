"""docs/regenerate.py: the committed figures and notebooks still show what the code produces.

"Still matches" is checked on what can be recomputed in seconds: the fingerprint (every shipped
scenario's certificate, the paper reproduction's kinematic tube and baseline runs, the drawing code's
hash) is recomputed and compared with the one stored in ``docs/artefacts.json`` when the artefacts were
written; each committed file's SHA-256 must be the one stored with it (so a figure is never replaced
without its numbers). When a test here fails, run ``python docs/regenerate.py``.
"""

from __future__ import annotations

import json
import re

import pytest

from .scripts import ROOT, load_script


def _regenerate():
    return load_script("docs/regenerate.py", "regenerate")


REGEN = _regenerate()
HINT = "stale: run `python docs/regenerate.py`"


@pytest.fixture(scope="module")
def sidecar() -> dict:
    assert REGEN.SIDECAR.is_file(), f"docs/artefacts.json is missing; {HINT}"
    return json.loads(REGEN.SIDECAR.read_text())


def test_the_fingerprint_recomputed_now_is_the_stored_one(sidecar):
    """The certificates, the reproduction's runs and the drawing code are what the artefacts were made from."""
    diff = REGEN.differences(REGEN.fingerprint(), sidecar["fingerprint"])
    assert not diff, f"{HINT}:\n" + "\n".join(diff[:20])


def test_every_committed_artefact_has_its_stored_hash(sidecar):
    changed = [rel for rel, digest in sidecar["files"].items() if REGEN.sha256(ROOT / rel) != digest]
    assert not changed, f"{HINT}: {changed} changed since their numbers were stored"


def test_every_figure_the_readme_and_docs_show_is_pinned(sidecar):
    shown = set()
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", page.read_text()):
            shown.add((page.parent / target).resolve().relative_to(ROOT).as_posix())
    assert shown, "no figure found in README.md or docs/*.md"
    assert not shown - set(sidecar["files"]), f"figures not produced by docs/regenerate.py: {shown - set(sidecar['files'])}"


def test_reproduce_md_shows_the_stored_measurements(sidecar):
    text = REGEN.REPRODUCE_MD.read_text()
    assert REGEN.BEGIN in text and REGEN.END in text
    block = text[text.index(REGEN.BEGIN):text.index(REGEN.END) + len(REGEN.END)]
    assert block == REGEN.measured_table(sidecar["fingerprint"]), HINT


def test_the_campaign_figure_is_pinned_with_its_numbers(sidecar):
    """docs/campaign_ecdf.png cannot be recomputed in seconds: it is pinned with the campaign's counts, those of
    the backup campaign docs/campaign.md reports (the tracking theorem refuses its clustered paths: no run has both
    tiers, 734 the safe tier)."""
    assert REGEN.CAMPAIGN_FIGURE in sidecar["files"]
    tiers = sidecar["campaign"]["runs_by_tier"]
    assert sidecar["campaign"]["runs"] == sum(tiers.values()) == 1000
    assert f"1000; {tiers['both']}, {tiers['safe_only']}, {tiers['none']}" in (REGEN.ROOT / "docs" / "campaign.md").read_text()


@pytest.mark.parametrize("found, stored, expected", [
    ({"a": 1.0}, {"a": 1.0 + 1e-7}, 0),          # within 1e-5 relative
    ({"a": 1.0}, {"a": 1.001}, 1),               # beyond it
    ({"a": [0.5, True]}, {"a": [0.5, False]}, 1),  # a verdict flips
    ({"a": 1.0}, {"b": 1.0}, 2),                 # a key on one side only, each way
    ({"a": "x"}, {"a": "x"}, 0),
])
def test_differences_tolerates_round_off_only(found, stored, expected):
    assert len(REGEN.differences(found, stored)) == expected


def test_measured_table_has_one_row_per_metric():
    run = {k: 0.5 for k in REGEN.RUN_KEYS}
    table = REGEN.measured_table({"reproduce": {**run, "baseline": {**run, "min_clearance": -0.0122}}})
    rows = [ln for ln in table.splitlines() if ln.startswith("| ") and "---" not in ln]
    assert len(rows) == 1 + len(REGEN.RUN_KEYS)
    assert "| -0.0122 |" in table and table.startswith(REGEN.BEGIN) and table.endswith(REGEN.END)
