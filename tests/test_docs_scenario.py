"""docs/scenario.md covers every key a scenario TOML accepts, and documents no key the code refuses.

The accepted keys are derived from the code (``tubekit.scenario._TOP_KEYS``, the dataclass fields of the
settings classes, the trajectory kinds' ``toml_keys``, the vehicle's parameters); the documented ones are the
backticked names in the ``key`` column of each table, grouped by the table's section (the backticked
``[name]`` in the heading above it). Also: user docs speak no tracker jargon.
"""

from __future__ import annotations

import re
from dataclasses import fields
from pathlib import Path

import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.kinematics import InputLimits, SwayModel
from tubekit.model.trajectory import KINDS, toml_keys
from tubekit.model.vehicle_params import VehicleParams
from tubekit.model.vehicles import PlantSettings
from tubekit.scenario import _TOP_KEYS, scenario_from_dict
from tubekit.settings import ControllerSettings, Disturbance, Obstacle, RegionSettings

ROOT = Path(__file__).resolve().parent.parent
DOC = (ROOT / "docs" / "scenario.md").read_text()
NAME = re.compile(r"`([A-Za-z_][A-Za-z0-9_]*)`")


def _names(*classes: type) -> set[str]:
    return {f.name for cls in classes for f in fields(cls) if f.init}


#: Section (the table's dotted name; "" = top level) -> the keys the code accepts there.
ACCEPTED: dict[str, set[str]] = {
    "": set(_TOP_KEYS),
    "obstacles": _names(Obstacle),
    "limits": _names(InputLimits),
    "disturbance": _names(Disturbance),
    "disturbance.sway": _names(SwayModel),
    "controller": _names(ControllerSettings),
    "region": _names(RegionSettings),
    # the table [plant]: overrides are written as the table [plant.vehicle], so the key is `vehicle`; the loader
    # also reads `vehicle_file` (a file holding that table)
    "plant": _names(PlantSettings) - {"overrides"} | {"vehicle_file"},
    "plant.vehicle": _names(VehicleParams) | {"name"},
}


def _tables(text: str) -> list[tuple[str, list[dict[str, str]]]]:
    """Every markdown table as (section, rows as {column: cell}); section from the last heading above it."""
    out: list[tuple[str, list[dict[str, str]]]] = []
    section, lines = "", text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("#"):
            found = re.search(r"`\[\[?([a-z_.]+)\]\]?`", line)
            section = found.group(1) if found else ""
        if line.startswith("|") and i + 1 < len(lines) and set(lines[i + 1].replace("|", "").strip()) <= {"-"}:
            header = [c.strip() for c in line.strip("|").split("|")]
            rows, i = [], i + 2
            while i < len(lines) and lines[i].startswith("|"):
                cells = [c.strip() for c in re.split(r"(?<!\\)\|", lines[i].strip().strip("|"))]
                rows.append(dict(zip(header, cells)))
                i += 1
            out.append((section, rows))
            continue
        i += 1
    return out


def _documented() -> dict[str, set[str]]:
    """Section -> the backticked names in the ``key`` column of its tables (trajectory: by kind)."""
    found: dict[str, set[str]] = {}
    for section, rows in _tables(DOC):
        kind = ""
        for row in rows:
            if "key" not in row:
                continue
            if "kind" in row:                      # the trajectory table: a blank kind continues the one above
                kind = NAME.findall(row["kind"])[0] if row["kind"] else kind
                found.setdefault(f"trajectory:{kind}", set()).update(NAME.findall(row["key"]))
            else:
                found.setdefault(section, set()).update(NAME.findall(row["key"]))
    return found


@pytest.mark.parametrize("section", sorted(ACCEPTED))
def test_every_accepted_key_is_documented_in_its_table(section):
    documented = _documented().get(section, set())
    assert ACCEPTED[section] - documented == set(), f"[{section}] keys missing from docs/scenario.md"
    assert documented - ACCEPTED[section] == set(), f"[{section}] documents keys the code refuses"


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_trajectory_kind_and_key_is_documented(kind):
    assert _documented().get(f"trajectory:{kind}", set()) == set(toml_keys(kind))


def test_the_trajectory_kinds_are_exactly_the_codes():
    assert {k.split(":")[1] for k in _documented() if k.startswith("trajectory:")} == set(KINDS)


def test_every_table_has_its_section():
    headings = set(re.findall(r"^#+ `\[\[?([a-z_.]+)\]\]?`", DOC, flags=re.M))
    assert {"trajectory", "obstacles", "limits", "disturbance", "controller", "region", "plant"} <= headings
    assert {"disturbance.sway", "plant.vehicle"} <= headings


def _with_unknown_key(section: str) -> dict:
    """A scenario table with the key ``zz_unknown`` in the table ``section`` ("" = top level)."""
    if section == "":
        return {"zz_unknown": 1}
    if section == "obstacles":
        return {"obstacles": [{"center": [9.0, 9.0, 0.0], "radius": 0.1, "zz_unknown": 1}]}
    if section == "plant.vehicle":
        return {"plant": {"kind": "dynamic", "vehicle": {"name": "remus100", "zz_unknown": 1}}}
    table: dict = {}
    node = table
    for part in section.split("."):
        node = node.setdefault(part, {})
    node["zz_unknown"] = 1
    return table


@pytest.mark.parametrize("section", sorted(ACCEPTED))
def test_the_derived_keys_are_the_loaders(section):
    """The loader refuses an unknown key in each table, listing what it accepts: the keys derived above."""
    with pytest.raises(ConfigError, match="zz_unknown|one of|a table with") as info:
        scenario_from_dict(_with_unknown_key(section))
    expected = info.value.expected
    listed = set(re.findall(r"'([A-Za-z_][A-Za-z0-9_]*)'", expected))
    if "[" in expected:                                   # "one of the keys ['a', 'b', ...]": the exact list
        assert listed == ACCEPTED[section] - ({"name"} if section == "plant.vehicle" else set())
    else:                                                 # "a table with keys gain, amplitude, ...": each named
        assert all(re.search(rf"\b{k}\b", expected) for k in ACCEPTED[section]), expected


USER_DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
JARGON = [re.compile(r"\bissues?[ -]\d+", re.I), re.compile(r"\bitem \d+ of the issue", re.I),
          re.compile(r"\bthe issue'?s?\b", re.I)]


@pytest.mark.parametrize("path", USER_DOCS, ids=lambda p: p.name)
def test_user_docs_speak_no_tracker_jargon(path):
    """README and docs/*.md say what is true, not which tracker item made it so ('issue 22', 'item 7 of the issue')."""
    hits = [f"{path.name}:{n}: {line.strip()[:100]}" for n, line in enumerate(path.read_text().splitlines(), 1)
            if any(p.search(line) for p in JARGON)]
    assert hits == []
