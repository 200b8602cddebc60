"""One certified run: simulate → metrics (one convention) → promises, as a typed result.

:func:`certified_run` is the run part of every study that runs the loop under a certificate's
tightening: ``tubekit reproduce`` / ``simulate`` (tube and baseline), the dynamic-plant part of
``reproduce``, each run of ``tubekit campaign`` and each run of the closed-loop falsifier
(:mod:`verify.falsify.closed_loop`). Obtaining the tightening (certifying, or taking a given
certificate) is the caller's step: the core never imports :mod:`verify`. The verdict is the
tightening's own ``certified`` flag, the one place it is stored.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from tubekit.loop.closed_loop import TickObserver, run_closed_loop
from tubekit.loop.metrics import run_metrics
from tubekit.loop.promises import PREMISES, Promise, broken_promises, check_promises, tier_outcomes
from tubekit.loop.result import SimulationResult
from tubekit.plant.base import OmegaOverride
from tubekit.scenario import Scenario
from tubekit.tiers import Tiers
from tubekit.tightening import Tightening

__all__ = ["CertifiedRun", "certified_run"]


@dataclass(frozen=True)
class CertifiedRun:
    """A finished run with its metrics (as ``metrics.json`` holds them) and the promises measured on it.

    Attributes
    ----------
    run : SimulationResult
        The closed-loop log.
    promises : tuple of Promise
        What the certificate promises, measured (empty for the baseline).
    metrics : dict
        :func:`tubekit.loop.metrics.run_metrics` of ``run`` (equal to ``run.metrics``).
    """

    run: SimulationResult
    promises: tuple[Promise, ...]
    metrics: dict[str, Any]

    @property
    def certified(self) -> bool:
        """The tightening the run used came from a certified certificate."""
        return bool(self.run.tightening.certified)

    @property
    def promises_kept(self) -> bool:
        """Every promise (premises included) held; True for the baseline, which is promised nothing."""
        return all(p.ok for p in self.promises)

    @property
    def premises_held(self) -> bool:
        """The theorem's premises (:data:`tubekit.loop.promises.PREMISES`) held on the run."""
        return all(p.ok for p in self.promises if p.name in PREMISES)

    @property
    def broken(self) -> tuple[str, ...]:
        """Names of the promises broken (:func:`tubekit.loop.promises.broken_promises`): of a tier the
        certificate gave, with every premise it depends on held (a NaN figure, e.g. sway under an
        override, is skipped). A premise failure is never a broken promise."""
        return broken_promises(self.promises)

    @property
    def tiers(self) -> Tiers:
        """Which tiers of promise the run's certificate gives."""
        return self.run.tightening.tiers

    @property
    def outcome(self) -> dict[str, str]:
        """Per tier, what happened on the run next to what the certificate gives
        (:func:`tubekit.loop.promises.tier_outcomes`: kept, BROKEN, not in force, not certified)."""
        return tier_outcomes(self.promises, self.tiers)

    @property
    def ratio(self) -> float:
        """max_j |e_j - ê_j| / tube_j over the run (1 = the certified tube; inf for a zero tube; NaN: baseline)."""
        tube = [p for p in self.promises if p.name == "tube"]
        return float(tube[0].observed) if tube else math.nan

    def check(self) -> bool:
        """False only when a certified run broke a promise of a tier its certificate gave, with that
        promise's premises held (exit 4 of the CLI)."""
        return not (self.certified and self.broken)

    def summary(self) -> str:
        """One line: the run, its verdict by tier, the backup time, the broken promises and failed premises."""
        kind = "tube" if self.run.tube else "baseline"
        if not self.run.tube:
            verdict = "no certificate"
        elif self.certified:
            verdict = "; ".join(f"{tier}: {outcome}" for tier, outcome in self.outcome.items())
        else:
            verdict = "not certified"
        line = (f"{kind} run of {self.run.scenario.name!r} ({verdict}): min clearance "
                f"{self.metrics['min_clearance']}, min e_d {self.metrics['min_e_d']:.4g} m, "
                f"tube ratio {self.metrics['max_rho_ratio']}, backup {self.metrics['backup_s']:.3g} s")
        premises = [p.name for p in self.promises if p.name in PREMISES and not p.ok]
        other = [p.name for p in self.promises if p.name not in PREMISES and not p.ok and p.name not in self.broken]
        return (line + (f"; broken: {', '.join(self.broken)}" if self.broken else "")
                + (f"; premises failed: {', '.join(premises)}" if premises else "")
                + (f"; not kept (not promised): {', '.join(other)}" if other else ""))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the metrics (promises included)."""
        return dict(self.metrics)


def certified_run(scenario: Scenario, tightening: Tightening, *, tube: bool = True,
                  disturbance: OmegaOverride | None = None, solver_factory: Any = None, progress: bool = False,
                  label: str | None = None, observer: TickObserver | None = None) -> CertifiedRun:
    """Simulate ``scenario`` under ``tightening``, measure it in the one convention and check its promises.

    Parameters
    ----------
    scenario : Scenario
        What to run; its law, FHOCP mode and plant kind are the scenario's.
    tightening : Tightening
        The certificate's (or best-effort, or untightened) sets; σ and the verdict are its own.
    tube : bool
        ``False`` runs the baseline (nominal MPC alone; no promises).
    disturbance : callable, optional
        ``disturbance(t) -> omega`` (m/s) replacing the scenario's current + sway.
    solver_factory : callable, optional
        ``factory(scenario, tightening)`` returning the FHOCP solver; default :class:`tubekit.fhocp.FHOCP`.
    progress : bool
        A progress bar on a terminal.
    label : str, optional
        Progress-bar label.
    observer : callable, optional
        Told (state, nominal, target) at every tick a plan is followed (:func:`run_closed_loop`).
    """
    run = run_closed_loop(scenario, tightening, tube=tube, progress=progress, label=label,
                          solver_factory=solver_factory, disturbance=disturbance, observer=observer)
    promises = tuple(check_promises(run, uncertified=True)) if tube else ()
    return CertifiedRun(run=run, promises=promises, metrics=run_metrics(run, promises))
