"""What every falsifier's result shares: its runs, whether one is a counterexample, ``check()``."""

from __future__ import annotations

from typing import Any

__all__ = ["SearchOutcome"]


class SearchOutcome:
    """Mixin for a falsifier's frozen result with ``runs``, each having a ``counterexample`` flag."""

    runs: tuple[Any, ...]

    @property
    def found(self) -> bool:
        """A run is a counterexample to the certificate."""
        return any(r.counterexample for r in self.runs)

    def check(self) -> bool:
        """True when the certificate survived every run."""
        return not self.found
