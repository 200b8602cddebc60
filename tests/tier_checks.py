"""What the tests say about a certificate's refused tracking tier (a helper, not a test module)."""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["refused_only_by_the_row_faces"]


def refused_only_by_the_row_faces(names: Iterable[str]) -> bool:
    """True when the failed conditions ``names`` are all the tracking theorem's terminal ingredients
    (``terminal_*``) and at least one is a row face's rate condition (``terminal_rate[u|w|r]``): rate-limited
    plans whose completion the row faces do not keep within J (``docs/verify.md`` step 17c), nothing else."""
    names = list(names)
    return bool(names) and all(n.startswith("terminal_") for n in names) and any(
        n.startswith("terminal_rate[") for n in names)
