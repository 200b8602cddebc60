"""The closed-loop backup falsifier: disturbance sequences against runs in which the backup engages.

The safe tier promises, for every current within the certified bounds and for all time, no
collision, the vehicle inside the workspace and v ∈ V never clipped — through plans accepted,
replayed, and the backup law at the end of a replay (``docs/verify.md``). This module attacks that
claim with the loop that runs (:func:`tubekit.loop.pipeline.certified_run`, ``disturbance=``
override) on scenarios where the FHOCP fails often (see the scenario families of
:mod:`verify.falsify.strategies`):

* **push**: the current at its bound toward the obstacle nearest to the target's position
  (horizontal ‖ω_xy‖ = ω̄_xy, heave toward the obstacle's depth), a state-free greedy;
* **evolution**: piecewise-constant sequences (one ω per FHOCP period), seeded (1 + λ) evolution
  strategy maximising :meth:`BackupLoopRun.fitness`: the smallest clearance (negated), the largest
  backup Lyapunov value V = d + β(1 − cos χ) over c while the backup is active, a broken safety
  promise (+10), and the backup time (a small bonus, to steer toward runs in which it engages).

The budget counts simulations, never seconds; the search is deterministic for a seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.loop.pipeline import CertifiedRun, certified_run
from tubekit.loop.promises import TIER_OF
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.validation import duration_seconds

from verify.falsify.backup import backup_lyapunov
from verify.falsify.closed_loop import piecewise_disturbance
from verify.falsify.outcome import SearchOutcome

__all__ = ["BackupLoopRun", "BackupLoopResult", "falsify_backup_loop", "push_disturbance", "safety_broken",
           "backup_figures"]

#: Offspring per generation of the evolution strategy, and its mutation step (unit cube).
_LAMBDA, _STEP = 4, 0.2


def safety_broken(sim: CertifiedRun) -> tuple[str, ...]:
    """Names of the safe tier's promises the run broke (:attr:`CertifiedRun.broken`: a given tier, its
    premises held; a premise failure never counts)."""
    return tuple(name for name in sim.broken if TIER_OF.get(name) == "safe")


def backup_figures(sim: CertifiedRun) -> tuple[float, float]:
    """(seconds with the backup active, largest V / c while active; NaN when never active or the log
    carries no anchor column ``backup_anchor``)."""
    run, backup = sim.run, sim.run.tightening.backup
    seconds = float(sim.metrics.get("backup_s") or 0.0)
    active = np.asarray(run.backup_active, dtype=bool)
    anchors = getattr(run, "backup_anchor", None)
    if backup is None or anchors is None or not np.any(active):
        return seconds, math.nan
    level = max(backup_lyapunov(run.states[k], np.asarray(anchors[k], dtype=float), backup.safe_set.shape,
                                backup.law) for k in np.flatnonzero(active))
    return seconds, level / backup.safe_set.level


def push_disturbance(scenario: Scenario, omega_xy: float, omega_z: float) -> Callable:
    """``disturbance(t)``: ω at its bound toward the obstacle nearest to the target's position at t."""
    centers = np.array([o.center for o in scenario.obstacles], dtype=float).reshape(-1, 3)

    def omega(t: float) -> tuple[float, float, float]:
        if not len(centers):
            return (0.0, 0.0, 0.0)
        p = np.asarray(scenario.trajectory.position(np.array([float(t)]))[0], dtype=float)
        o = centers[int(np.argmin(np.linalg.norm(centers - p, axis=1)))]
        dx, dy = o[0] - p[0], o[1] - p[1]
        n = math.hypot(dx, dy) or 1.0
        return (omega_xy * dx / n, omega_xy * dy / n, math.copysign(omega_z, o[2] - p[2]))
    return omega


@dataclass(frozen=True)
class BackupLoopRun:
    """One closed-loop run: clearance, backup time, backup V / c and the safety promises broken."""

    strategy: str
    min_clearance: float
    backup_s: float
    level_ratio: float
    broken: tuple[str, ...]
    certified: bool
    sequence: tuple[tuple[float, float, float], ...] | None = field(default=None, repr=False)

    def fitness(self) -> float:
        """What the search maximises (module doc)."""
        level = self.level_ratio if math.isfinite(self.level_ratio) else 0.0
        return -self.min_clearance + level + (10.0 if self.broken else 0.0) + 0.01 * self.backup_s

    @property
    def counterexample(self) -> bool:
        """A certified run broke a promise of the safe tier."""
        return self.certified and bool(self.broken)

    def to_dict(self) -> dict:
        """JSON form."""
        return {"strategy": self.strategy, "min_clearance": self.min_clearance, "backup_s": self.backup_s,
                "level_ratio": None if math.isnan(self.level_ratio) else self.level_ratio,
                "broken": list(self.broken), "certified": self.certified,
                "sequence": None if self.sequence is None else [list(w) for w in self.sequence]}


@dataclass(frozen=True)
class BackupLoopResult(SearchOutcome):
    """Outcome of :func:`falsify_backup_loop`: the worst run and how often the backup engaged."""

    scenario: str
    duration: float
    seed: int
    worst: BackupLoopRun
    runs: tuple[BackupLoopRun, ...] = field(repr=False, default=())

    def summary(self) -> str:
        """Readable text."""
        w = self.worst
        engaged = sum(r.backup_s > 0 for r in self.runs)
        return (("COUNTEREXAMPLE found" if self.found else "no safety promise broken")
                + f" (backup in the loop, {len(self.runs)} runs of {self.duration:g} s on {self.scenario!r}, seed "
                f"{self.seed}; backup engaged in {engaged}): smallest clearance {w.min_clearance:.4g} m, "
                f"backup {w.backup_s:.3g} s, V / c {w.level_ratio:.4g}, by {w.strategy}")

    def to_dict(self) -> dict:
        """JSON form."""
        return {"mode": "backup-loop", "found": self.found, "scenario": self.scenario, "duration": self.duration,
                "seed": self.seed, "simulations": len(self.runs),
                "engaged": sum(r.backup_s > 0 for r in self.runs), "worst": self.worst.to_dict()}


def _run(scenario: Scenario, tightening: Tightening, strategy: str, omega: Callable) -> BackupLoopRun:
    sim = certified_run(scenario, tightening, disturbance=omega)
    seconds, level = backup_figures(sim)
    clearance = sim.metrics["min_clearance"]
    return BackupLoopRun(strategy, float(clearance) if clearance is not None else math.inf, seconds, level,
                         safety_broken(sim), sim.certified, tuple(getattr(omega, "table", ())) or None)


def falsify_backup_loop(scenario: Scenario, tightening: Tightening, *, budget: int = 8, seed: int = 0,
                        duration: float | None = None) -> BackupLoopResult:
    """Search disturbance sequences within the tightening's bounds for a run that breaks a safety promise.

    Parameters
    ----------
    scenario : Scenario
        The design (its duration is replaced by ``duration`` when given).
    tightening : Tightening
        The certificate's sets; its ``disturbance`` gives ω̄_xy and ω̄_z.
    budget : int
        Simulations (>= 1): one push run, the rest a (1 + 4) evolution strategy.
    seed : int
        Seed; the search is deterministic for a seed.
    duration : float, optional
        Seconds simulated per run.
    """
    if not isinstance(budget, int) or isinstance(budget, bool) or budget < 1:
        raise ConfigError("budget", "an integer >= 1 (simulations)", budget)
    if duration is not None:
        scenario = scenario.with_changes(duration=duration_seconds("duration", duration))
    wxy, wz = tightening.disturbance.omega_xy, tightening.disturbance.omega_z
    runs = [_run(scenario, tightening, "push", push_disturbance(scenario, wxy, wz))]
    rng = np.random.default_rng(seed)
    periods, dt = scenario.steps, scenario.controller.dt

    def evaluate(genome: np.ndarray) -> BackupLoopRun:
        return _run(scenario, tightening, "evolution", piecewise_disturbance(wxy, wz, dt, genome.reshape(periods, 3)))

    if budget > 1:
        parent = rng.uniform(0, 1, 3 * periods)
        parent[1::3] = 1.0
        best = evaluate(parent)
        runs.append(best)
        while len(runs) < budget:
            for _ in range(min(_LAMBDA, budget - len(runs))):
                child = np.clip(parent + rng.normal(0, _STEP, parent.size), 0, 1)
                run = evaluate(child)
                runs.append(run)
                if run.fitness() >= best.fitness():
                    parent, best = child, run
    worst = max(runs, key=BackupLoopRun.fitness)
    return BackupLoopResult(scenario=scenario.name, duration=float(scenario.duration), seed=seed, worst=worst,
                            runs=tuple(runs))
