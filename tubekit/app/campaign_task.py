"""One campaign run on a worker (issue 15): the task a worker receives and the row it returns.

:func:`simulate_task` runs the task's scenario under the shipped tightening (each simulation is
:func:`tubekit.loop.pipeline.certified_run`; the verdict travels in ``Tightening.certified``), plus
``falsify.sequences`` runs where the current is replaced by a random piecewise-constant disturbance
within the certificate's bounds (:func:`verify.falsify.closed_loop.piecewise_disturbance`, one ω per FHOCP
period, drawn from the run's seed); the row keeps the worst figure of each metric over those runs.
Nothing in a row depends on the worker, the order or the scheduler except ``wall_s``. The client side
is :mod:`tubekit.app.campaign`; this module imports neither it nor dask.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from tubekit.exceptions import TubekitError
from tubekit.loop.promises import current_bound
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

if TYPE_CHECKING:  # verify loads with the certificate task, not with this module
    from tubekit.app.certified import IssuedCertificate

__all__ = ["RunTask", "simulate_task", "simulate_all", "row_of"]


@dataclass(frozen=True)
class RunTask:
    """Everything a worker needs for one run (pickled to the worker); ``tightening.certified`` is the verdict
    (None: the tightening of the certificate task the run depends on, see :func:`simulate_task`)."""

    run: int
    seed: int
    scenario: Scenario
    tightening: Tightening | None
    sequences: int


def _disturbances(task: RunTask) -> list[Callable | None]:
    """None (the scenario's current), then ``sequences`` piecewise-constant ω within the certificate's bounds: on the
    kinematic plant the whole ω̄ (current and sway, both assumed); on the dynamic plant, where the override replaces
    the water current only and the hull's sway and the loop error are the plant's own, the current's bound
    (:func:`tubekit.loop.promises.current_bound`, the premise the certificate assumes)."""
    if task.sequences == 0:
        return [None]
    from verify.falsify.closed_loop import piecewise_disturbance

    bound = task.tightening.disturbance
    omega_xy, omega_z = bound.omega_xy, bound.omega_z
    if task.scenario.plant.dynamic:
        omega_xy, omega_z = current_bound(task.scenario)
    rng = np.random.default_rng([task.seed, 1])
    dt = task.scenario.controller.dt
    return [None] + [piecewise_disturbance(omega_xy, omega_z, dt, rng.random((task.scenario.steps, 3)))
                     for _ in range(task.sequences)]


def simulate_all(task: RunTask) -> list[Any]:
    """Each simulation of the run: a :class:`tubekit.loop.pipeline.CertifiedRun` per disturbance."""
    from tubekit.loop.pipeline import certified_run

    return [certified_run(task.scenario, task.tightening, label="tube", disturbance=disturbance)
            for disturbance in _disturbances(task)]


def _figures_of(sim: Any) -> dict[str, Any]:
    metrics = sim.metrics
    return {"max_rho_ratio": sim.ratio, "min_clearance": float(metrics["min_clearance"]),
            "min_e_d": float(metrics["min_e_d"]), "tracking_rmse": float(metrics["tracking_rmse"]),
            "saturated_steps": int(metrics["saturated_steps"]), "broken": list(sim.broken),
            "replaced_steps": int(metrics["replaced_steps"]), "backup_s": float(metrics["backup_s"]),
            "backup_engagements": int(metrics["backup_engagements"]),
            "safety_broken": [p.name for p in sim.promises if p.tier == "safe" and p.name in sim.broken],
            "premises_held": sim.premises_held}


def _tiers_of(tightening: Tightening) -> dict[str, bool]:
    """``safe_tier`` and ``tracking_tier``: the tiers the run's certificate gives."""
    return {"safe_tier": tightening.tiers.safe, "tracking_tier": tightening.tiers.tracking}


def simulate_task(task: RunTask, issued: IssuedCertificate | None = None) -> dict[str, Any]:
    """Run ``task`` and return its row (without the sampled values); ``wall_s`` is the only timing.

    ``issued`` (a :class:`tubekit.app.certified.IssuedCertificate`, the result of the certificate task the
    run depends on) gives the tightening when ``task.tightening`` is None.
    """
    if issued is not None:
        task = replace(task, tightening=issued.tightening)
    started = time.perf_counter()
    try:
        sims = simulate_all(task)
    except TubekitError as exc:  # a run that cannot be simulated is recorded, not retried
        return {"run": task.run, "seed": task.seed, "certified": bool(task.tightening.certified),
                **_tiers_of(task.tightening), "max_rho_ratio": None, "min_clearance": None, "min_e_d": None,
                "tracking_rmse": None, "saturated_steps": None, "replaced_steps": None, "backup_s": None,
                "backup_engagements": None, "violated": False, "safety_broken": "", "premises_held": False,
                "broken": "", "worst_sequence": -1, "error": str(exc).splitlines()[0],
                "wall_s": time.perf_counter() - started}
    return row_of(task, sims, started)


def row_of(task: RunTask, sims: list[Any], started: float) -> dict[str, Any]:
    """The row of a run: the worst figure of each metric over its simulations."""
    figures = [_figures_of(sim) for sim in sims]
    worst = int(np.argmax([f["max_rho_ratio"] for f in figures]))
    return {"run": task.run, "seed": task.seed, "certified": bool(task.tightening.certified),
            **_tiers_of(task.tightening), "max_rho_ratio": figures[worst]["max_rho_ratio"],
            "min_clearance": min(f["min_clearance"] for f in figures),
            "min_e_d": min(f["min_e_d"] for f in figures),
            "tracking_rmse": max(f["tracking_rmse"] for f in figures),
            "saturated_steps": max(f["saturated_steps"] for f in figures),
            **{k: max(f[k] for f in figures) for k in ("replaced_steps", "backup_s", "backup_engagements")},
            "violated": any(f["broken"] for f in figures),
            "safety_broken": ",".join(sorted({n for f in figures for n in f["safety_broken"]})),
            "premises_held": all(f["premises_held"] for f in figures),
            "broken": ",".join(sorted({n for f in figures for n in f["broken"]})),
            "worst_sequence": worst, "error": "", "wall_s": time.perf_counter() - started}
