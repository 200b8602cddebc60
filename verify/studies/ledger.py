"""The ledger of a re-check: every comparison of a stored number with the derived one, in order.

:class:`Ledger` compares in the direction that matters: ``at_least`` for upper bounds (tube, margins,
κ̄, ω̄, arc rates), ``at_most`` for what the certificate grants (V̄, the upper ends of Ē), ``equal`` for
the theorem's inputs. A stored number weaker than derived is a note, not a disagreement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Ledger"]

_BY = "re-derivation"


@dataclass
class Ledger:
    """The checks made so far (in order) and the notes on stored numbers weaker than derived."""

    checks: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def check(self, name: str, ok: bool, stored: Any, derived: Any, rule: str, by: str = _BY) -> None:
        """Record one check: the stored and the derived value, the rule relating them, what makes it."""
        self.checks.append({"name": name, "ok": bool(ok), "stored": stored, "derived": derived, "rule": rule,
                            "by": by})

    def equal(self, name: str, stored: Any, derived: Any) -> None:
        """An input of the theorem: stored == derived."""
        self.check(name, _same(stored, derived), stored, derived, "an input of the theorem: equal")

    def at_least(self, name: str, stored: float | None, derived: float | None) -> None:
        """An upper bound: stored >= derived (smaller is stronger: a disagreement; larger: a note)."""
        s, d = _num(stored, math.inf), _num(derived, math.inf)
        self.check(name, s >= d, stored, derived, "a bound: stored >= derived (a smaller one is not proved)")
        if s > d:
            self.notes.append(f"{name}: stored {stored} is weaker than derived {derived}")

    def at_most(self, name: str, stored: float | None, derived: float | None) -> None:
        """What the certificate grants (V̄, an upper end of Ē): stored <= derived."""
        s, d = _num(stored, -math.inf), _num(derived, -math.inf)
        self.check(name, s <= d, stored, derived, "granted: stored <= derived (more is not proved)")
        if s < d:
            self.notes.append(f"{name}: stored {stored} is weaker than derived {derived}")

    def each(self, how: str, name: str, stored: Any, derived: Any) -> None:
        """``at_least`` / ``at_most`` per entry, after an equal-length check."""
        s, d = list(stored or []), list(derived or [])
        if len(s) != len(d):
            self.check(f"{name} (length)", False, len(s), len(d), "one entry per derived entry")
            return
        for i, (a, b) in enumerate(zip(s, d)):
            getattr(self, how)(f"{name}[{i}]", a, b)


def _num(x: Any, none: float) -> float:
    return none if x is None else float(x)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))
