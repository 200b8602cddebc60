"""verify.studies.rederive: the direction of each comparison (stronger is a disagreement, weaker a note)."""

from __future__ import annotations

import math

import pytest

from verify.studies.rederive import Ledger

CASES = [
    ("at_least", 0.9, 1.0, False, False),    # an upper bound below the derived one: not proved
    ("at_least", 1.0, 1.0, True, False),
    ("at_least", 1.1, 1.0, True, True),      # a looser bound: a note
    ("at_least", None, 1.0, True, True),     # no finite bound stored (null): weaker
    ("at_least", 1.0, None, False, False),   # derived: no finite bound at all
    ("at_most", 0.5, 0.4, False, False),     # V_bar larger than derived: not proved
    ("at_most", 0.3, 0.4, True, True),
    ("equal", 0.4, 0.4, True, False),
    ("equal", [0.1, 3.0], [0.1, 3.0], True, False),
    ("equal", [0.1, 3.0], [0.1, 4.0], False, False),
]


@pytest.mark.parametrize("how, stored, derived, ok, note", CASES)
def test_directions(how, stored, derived, ok, note):
    led = Ledger()
    getattr(led, how)("x", stored, derived)
    c = led.checks[0]
    assert c["ok"] is ok and c["name"] == "x" and (c["stored"], c["derived"]) == (stored, derived)
    assert bool(led.notes) is note


def test_each_checks_the_length_first():
    led = Ledger()
    led.each("at_least", "margins.e_d", [1.0], [0.5, 0.6])
    assert [c["name"] for c in led.checks] == ["margins.e_d (length)"] and not led.checks[0]["ok"]
    led = Ledger()
    led.each("at_least", "tube.rho", [1.0, math.inf], [0.5, 0.6])
    assert [c["ok"] for c in led.checks] == [True, True] and len(led.notes) == 2
