"""The dynamic-plant part of ``tubekit reproduce`` (issue 13): the tube controller on the 4-DOF vehicle.

:func:`run_dynamic` certifies the scenario on the dynamic plant (the BlueROV2 Heavy with rate-limited
plans unless the scenario names its own vehicle; the velocity loop's derived error bound and the hull's
sway enter ω; usually not certified, and then the best-effort sets are used and flagged), runs the tube
controller on the dynamic plant under
the same current with :func:`tubekit.loop.pipeline.certified_run` (metrics and promises in the
one convention), and writes ``dynamic_trajectory.csv``,
``dynamic_certificate.txt`` and ``dynamic_vs_kinematic.png``.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch

from tubekit.jsonable import write_text
from tubekit.loop.pipeline import CertifiedRun, certified_run
from tubekit.loop.result import SimulationResult
from tubekit.scenario import Scenario
from tubekit.app.certified import certify_design
from tubekit.app.plots import backup_stretches, shade_backup, title_lines
from tubekit.app.tiers import report_title, tier_report

__all__ = ["run_dynamic", "comparison_figure", "DYNAMIC_FILES", "DYNAMIC_VEHICLE", "DYNAMIC_RATE"]

#: Files the dynamic part writes.
DYNAMIC_FILES: tuple[str, ...] = ("dynamic_trajectory.csv", "dynamic_certificate.txt", "dynamic_vs_kinematic.png")


#: The vehicle of ``reproduce``'s dynamic run: actuated in surge, heave and yaw at any speed, as the paper
#: assumes (REMUS 100's rudder and stern planes give nothing at u = 0: ``docs/plant.md``).
DYNAMIC_VEHICLE = "bluerov2_heavy"
#: The plans' rate limit of that run (m/s², m/s², rad/s²), well inside what its thrusters deliver against
#: drag at the corner of V (``rate_authority`` in its certificate).
DYNAMIC_RATE = (0.3, 0.3, 1.0)


def _dynamic_scenario(scenario: Scenario) -> Scenario:
    """``scenario`` on the 4-DOF plant: unchanged when it is dynamic already; else the BlueROV2 Heavy with
    rate-limited plans (:data:`DYNAMIC_VEHICLE`, :data:`DYNAMIC_RATE`)."""
    if scenario.plant.dynamic:
        return scenario
    limits = scenario.limits if scenario.limits.rate is not None else replace(scenario.limits, rate=DYNAMIC_RATE)
    return scenario.with_changes(plant=replace(scenario.plant, kind="dynamic", vehicle=DYNAMIC_VEHICLE),
                                 limits=limits)


def comparison_figure(scenario: Scenario, kinematic: SimulationResult, dynamic: SimulationResult,
                      gamma: float, tiers: str | None = None) -> Figure:
    """Path, e_d, sway against γ̄ and thrust against its limits: kinematic and dynamic tube runs.

    ``tiers`` (the dynamic certificate's, :func:`tubekit.app.plots.tier_title`) is a title line; the
    dynamic run's backup-active stretches are shaded on its time axes.
    """
    fig = Figure(figsize=(12, 8.5), layout="constrained")
    ax = fig.subplots(2, 2)
    runs = (("kinematic plant", kinematic, "tab:blue"), (f"dynamic plant ({scenario.plant.vehicle})", dynamic, "tab:purple"))
    for label, run, colour in runs:
        ax[0, 0].plot(run.states[:, 0], run.states[:, 1], color=colour, lw=1.2, label=label)
        ax[0, 1].plot(run.t, run.errors[:, 0], color=colour, lw=1.2, label=label)
    pd = scenario.trajectory.position(np.linspace(0.0, kinematic.t[-1], 800))
    ax[0, 0].plot(pd[:, 0], pd[:, 1], "--", color="tab:green", lw=1.0, label="desired")
    for o in scenario.obstacles:
        ax[0, 0].add_patch(CirclePatch(o.center[:2], o.radius, color="0.45"))
    ax[0, 0].set(aspect="equal", xlabel="x (m)", ylabel="y (m)", title="path")
    ax[0, 1].axhline(scenario.epsilon, color="tab:red", ls="--", lw=1.0, label=f"ε = {scenario.epsilon:g} m")
    ax[0, 1].set(yscale="log", xlabel="t (s)", ylabel="e_d (m)", title="distance error")
    sway = dynamic.body[:, 1] if dynamic.body is not None else np.full(len(dynamic.t), np.nan)
    ax[1, 0].plot(dynamic.t, sway, color="tab:purple", lw=1.0, label="sway v_b (dynamic plant)")
    for s in (gamma, -gamma):
        ax[1, 0].axhline(s, color="tab:red", ls="--", lw=1.0, label="±γ̄ (certificate)" if s > 0 else None)
    ax[1, 0].set(xlabel="t (s)", ylabel="m/s", title="sway against its bound")
    truth = scenario.plant.truth_params  # the plant as simulated; fins: limits ∝ u² (docs/plant.md)
    limits = np.array([truth.thrust_limits_at(u) for u in dynamic.body[:, 0]]) if dynamic.body is not None else None
    if dynamic.thrust is not None:
        for k, (name, colour) in enumerate((("X / X_max", "tab:blue"), ("Z / Z_max", "tab:orange"),
                                             ("N / N_max", "tab:green"))):
            ratio = np.divide(dynamic.thrust[:, k], limits[:, k], out=np.zeros(len(limits)), where=limits[:, k] > 0)
            ax[1, 1].plot(dynamic.t, ratio, color=colour, lw=0.9, label=name)
    ax[1, 1].axhline(1.0, color="tab:red", ls="--", lw=1.0, label="limit")
    ax[1, 1].axhline(-1.0, color="tab:red", ls="--", lw=1.0)
    ax[1, 1].set(xlabel="t (s)", ylabel="thrust / limit", title="thrust against its limits")
    stretches = backup_stretches(dynamic.columns())
    for n, a in enumerate((ax[0, 1], ax[1, 0], ax[1, 1])):
        shade_backup(a, stretches, label=n == 0)
    for a in ax.flat:
        a.grid(alpha=0.3)
        a.legend(fontsize=9, loc="best")
    head = f"{scenario.name}: tube controller, kinematic vs dynamic plant"
    fig.suptitle(title_lines(head, tiers, width=140), fontsize=11)
    return fig


def run_dynamic(scenario: Scenario, staging: Path, kinematic: SimulationResult,
                progress: bool) -> tuple[CertifiedRun, dict[str, Any]]:
    """Certify and run the dynamic plant; write its files into ``staging``; return the run and its metrics.

    The metrics are the run's (``run.metrics``) plus ``failures`` (the certificate's failed
    conditions), ``vehicle``, ``velocity_loop`` (the certificate's derived loop bound, None when not
    certified) and ``tiers_report`` (:func:`tubekit.app.tiers.tier_report`).
    """
    scd = _dynamic_scenario(scenario)
    design = certify_design(scd)
    write_text(staging / "dynamic_certificate.txt", design.certificate.summary() + "\n")
    dyn = certified_run(scd, design.tightening, progress=progress, label="dynamic")
    dyn.run.write_csv(staging / "dynamic_trajectory.csv")
    metrics = dyn.to_dict()
    loop = design.tightening.velocity_loop
    metrics.update(failures=[f.condition for f in design.certificate.failures], vehicle=scd.plant.vehicle,
                   velocity_loop=None if loop is None else list(loop))
    metrics["tiers_report"] = tier_report(design.certificate, metrics)
    gamma = float(design.tightening.disturbance.sway)
    figure = comparison_figure(scd, kinematic, dyn.run, gamma, tiers=report_title(metrics["tiers_report"]))
    figure.savefig(staging / "dynamic_vs_kinematic.png", dpi=100)
    return dyn, metrics
