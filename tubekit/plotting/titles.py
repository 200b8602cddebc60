"""The verdict on a figure: which tiers the certificate gives and what happened to them on the run."""

from __future__ import annotations

import textwrap
from typing import Mapping, Sequence

from tubekit.tiers import Tiers
from tubekit.plotting.run import PlottedRun

__all__ = ["tier_title", "title_lines", "run_verdict", "BASELINE_VERDICT"]

#: The verdict of a baseline run (the nominal MPC alone, no certificate).
BASELINE_VERDICT = "baseline: nothing is promised"


def title_lines(head: str, tiers: str | None, width: int = 110) -> str:
    """``head`` and the tier line below it, wrapped at ``width`` characters (a long list of failed conditions)."""
    if not tiers:
        return head
    wrapped = textwrap.fill(tiers, width)
    return f"{head}\n{wrapped}" if head else wrapped


def tier_title(tiers: Tiers | Mapping[str, bool] | None, failures: Mapping[str, Sequence[str]] | None = None,
               outcomes: Mapping[str, str] | None = None) -> str:
    """The title line of the tiers: ``safe: certified, kept; tracking: not certified (keep_up, yaw_budget)``.

    ``outcomes`` (per tier, :func:`tubekit.loop.promises.tier_outcomes` of a run) replaces "certified" by what
    happened on the run ("certified, kept", "certified, not in force (recursive_feasibility failed)", ...).
    """
    if tiers is None:
        return "no certificate (baseline only): nothing is promised"
    if isinstance(tiers, Tiers):
        tiers = tiers.to_dict()
    parts = []
    for name in ("safe", "tracking"):
        ok = bool(tiers.get(name, False))
        failed = list((failures or {}).get(name, ()))
        reason = f" ({', '.join(failed)})" if failed and not ok else ""
        said = (outcomes or {}).get(name) if ok else None
        parts.append(f"{name}: {said or ('certified' if ok else 'not certified')}{reason}")
    return "; ".join(parts)


def run_verdict(run: PlottedRun) -> str:
    """The verdict of one run: its tiers with their outcome on the run (``run.metrics["outcome"]``), e.g.
    ``safe: certified, kept; tracking: certified, not in force (recursive_feasibility failed)``; a baseline run's
    is :data:`BASELINE_VERDICT`."""
    if not run.tube:
        return BASELINE_VERDICT
    metrics = run.metrics
    return tier_title(metrics.get("tiers") or run.tightening.tiers, outcomes=metrics.get("outcome"))
