"""The dynamic-plant part of ``tubekit reproduce`` (issue 13): the tube controller on the 4-DOF vehicle.

:func:`run_dynamic` certifies the scenario on the dynamic plant (the BlueROV2 Heavy with rate-limited
plans unless the scenario names its own vehicle; the velocity loop's derived error bound and the hull's
sway enter ω; usually not certified, and then the best-effort sets are used and flagged), runs the tube
controller on the dynamic plant under
the same current with :func:`tubekit.loop.pipeline.certified_run` (metrics and promises in the
one convention), and writes ``dynamic_trajectory.csv``,
``dynamic_certificate.txt``, ``dynamic_vs_kinematic.png`` and the dynamic run's panel set ``dynamic_plant.png``
(:func:`tubekit.plotting.dynamic.dynamic_figure`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from tubekit.jsonable import write_text
from tubekit.loop.pipeline import CertifiedRun, certified_run
from tubekit.loop.result import SimulationResult
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.plotting.dynamic import draw_sway, draw_thrust, dynamic_figure
from tubekit.plotting.style import backup_stretches, shade_backup
from tubekit.plotting.titles import title_lines
from tubekit.plotting.top_view import draw_scene_xy
from tubekit.app.certified import certify_design
from tubekit.app.plots import DYNAMIC_FIGURE, save_figure
from tubekit.app.tiers import report_title, tier_report

__all__ = ["run_dynamic", "comparison_figure", "DYNAMIC_FILES", "DYNAMIC_VEHICLE", "DYNAMIC_RATE"]

#: Files the dynamic part writes.
DYNAMIC_FILES: tuple[str, ...] = ("dynamic_trajectory.csv", "dynamic_certificate.txt", "dynamic_vs_kinematic.png",
                                   DYNAMIC_FIGURE)


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
                      tightening: Tightening, tiers: str | None = None) -> Figure:
    """Path and e_d of the kinematic and the dynamic tube runs; the dynamic run's sway against γ̄ and thrust
    against its limits (:mod:`tubekit.plotting.dynamic`, whose bounds are ``tightening``'s).

    ``tiers`` (the dynamic certificate's, :func:`tubekit.plotting.titles.tier_title`) is a title line; the
    dynamic run's backup-active stretches are shaded on its time axes.
    """
    fig = Figure(figsize=(12, 8.5), layout="constrained")
    ax = fig.subplots(2, 2)
    runs = (("kinematic plant", kinematic, "tab:blue"), (f"dynamic plant ({scenario.plant.vehicle})", dynamic, "tab:purple"))
    draw_scene_xy(ax[0, 0], scenario, float(kinematic.t[-1]), start_target=False)
    for label, run, colour in runs:
        ax[0, 0].plot(run.states[:, 0], run.states[:, 1], color=colour, lw=1.2, label=label)
        ax[0, 1].plot(run.t, run.errors[:, 0], color=colour, lw=1.2, label=label)
    ax[0, 0].set(aspect="equal", title="path")
    ax[0, 1].axhline(scenario.epsilon, color="tab:red", ls="--", lw=1.0, label=f"ε = {scenario.epsilon:g} m")
    ax[0, 1].set(yscale="log", xlabel="t (s)", ylabel="e_d (m)", title="distance error")
    columns = dynamic.columns()
    draw_sway(ax[1, 0], columns, tightening)
    draw_thrust(ax[1, 1], scenario, columns)
    stretches = backup_stretches(columns)
    for n, a in enumerate((ax[0, 1], ax[1, 0], ax[1, 1])):
        shade_backup(a, stretches, label=n == 0)
    for a in ax.flat:
        a.grid(alpha=0.3)
        a.legend(fontsize=9, loc="best")
    for a in ax[1]:
        a.set_xlabel("t (s)")
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
    write_text(staging / "dynamic_certificate.txt", design.certificate.summary(verbose=True) + "\n")
    dyn = certified_run(scd, design.tightening, progress=progress, label="dynamic")
    dyn.run.write_csv(staging / "dynamic_trajectory.csv")
    metrics = dyn.to_dict()
    loop = design.tightening.velocity_loop
    metrics.update(failures=[f.condition for f in design.certificate.failures], vehicle=scd.plant.vehicle,
                   velocity_loop=None if loop is None else list(loop))
    metrics["tiers_report"] = tier_report(design.certificate, metrics)
    title = report_title(metrics["tiers_report"])
    figure = comparison_figure(scd, kinematic, dyn.run, design.tightening, tiers=title)
    figure.savefig(staging / "dynamic_vs_kinematic.png", dpi=100)
    panels = dynamic_figure(scd, ("tube", dyn.run.columns()), design.tightening)
    save_figure(panels, staging / DYNAMIC_FIGURE, tiers=title, dpi=100)
    return dyn, metrics
