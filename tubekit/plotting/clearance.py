"""The clearance of a run: the vehicle ball's distance to the nearest obstacle surface (negative: overlap)."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from tubekit.scenario import Scenario
from tubekit.plotting.run import Run
from tubekit.plotting.style import LEGEND_OUTSIDE, backup_stretches, distance_text, run_style, shade_backup

__all__ = ["obstacle_gaps", "clearance_of", "draw_clearance", "clearance_figure", "CLEARANCE_LINEAR_M"]

#: Clearance (m) below which the clearance axis is linear (symlog): mm-scale penetrations stay visible.
CLEARANCE_LINEAR_M = 0.01


def obstacle_gaps(columns: Mapping[str, np.ndarray], scenario: Scenario) -> np.ndarray:
    """Per sample and obstacle: ``‖p − c_m‖ − r_m − r̄`` (m), shape (samples, obstacles)."""
    p = np.column_stack([columns["x"], columns["y"], columns["z"]]).astype(float)
    centres = np.array([o.center for o in scenario.obstacles], dtype=float).reshape(-1, 3)
    radii = np.array([o.radius for o in scenario.obstacles], dtype=float)
    return np.linalg.norm(p[:, None, :] - centres[None], axis=2) - radii[None] - scenario.vehicle_radius


def clearance_of(columns: Mapping[str, np.ndarray], scenario: Scenario) -> np.ndarray:
    """Per sample, the clearance (m) to the nearest obstacle; +inf everywhere without obstacles."""
    if not scenario.obstacles:
        return np.full(len(columns["x"]), np.inf)
    return np.min(obstacle_gaps(columns, scenario), axis=1)


def draw_clearance(ax: Axes, scenario: Scenario, runs: Sequence[Run], *, legend: bool = True) -> None:
    """Each run's clearance against time on a symlog axis (mm overlaps visible), its minimum marked; the
    contact line and the penetration band; the first run's backup stretches shaded."""
    lowest = 0.0
    for i, (label, c) in enumerate(runs):
        gap = clearance_of(c, scenario)
        if not np.any(np.isfinite(gap)):
            continue
        ax.plot(c["t"], gap, label=label, **run_style(i))
        j = int(np.nanargmin(np.where(np.isfinite(gap), gap, np.nan)))
        lowest = min(lowest, float(gap[j]))
        ax.plot([c["t"][j]], [gap[j]], "v", color=run_style(i).get("color"), mec="k", ms=7,
                label=f"{label}: min {distance_text(float(gap[j]))} at t = {float(c['t'][j]):.1f} s")
    shade_backup(ax, backup_stretches(runs[0][1]) if runs else [])
    if scenario.obstacles:
        ax.axhline(0.0, color="tab:red", ls="--", lw=1.0, label="contact")
        ax.set_yscale("symlog", linthresh=CLEARANCE_LINEAR_M, linscale=1.0)
        bottom = -max(0.02, 2.0 * abs(lowest))
        ax.axhspan(bottom, 0.0, color="tab:red", alpha=0.08, label="penetration (collision)")
        ax.set_ylim(bottom, None)
        ax.set_ylabel(f"clearance (m, symlog: linear within ±{CLEARANCE_LINEAR_M * 1e3:g} mm)", fontsize=9)
    else:
        ax.text(0.5, 0.5, "no obstacles", transform=ax.transAxes, ha="center", va="center", color="0.4")
        ax.set_ylabel("clearance (m)", fontsize=9)
    ax.set_xlabel("t (s)")
    ax.grid(alpha=0.3, which="both")
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(**LEGEND_OUTSIDE)


def clearance_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Vehicle-ball to nearest-obstacle-surface distance; symlog axis so mm-scale penetrations show."""
    fig = Figure(figsize=(8.5, 3.8), layout="constrained")
    ax = fig.add_subplot()
    draw_clearance(ax, scenario, runs)
    ax.set_title(r"Clearance: $\|p - c_m\| - r_m - \bar r$ (nearest obstacle)")
    return fig
