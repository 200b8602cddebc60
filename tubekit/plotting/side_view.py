"""The side view beside the top view: each run seen from the nearest obstacle (horizontal distance, height).

A top view cannot show a pass over an obstacle nor a millimetre overlap: in the plane of the
horizontal distance to the nearest obstacle's centre and the height above it, the obstacle is a
disc of radius r_m and the set the vehicle centre must avoid a disc of radius r_m + r̄, so a pass
over it and a graze of a few millimetres both show (a zoomed inset around the closest approach,
drawn only when it is much narrower than the view). A run that never comes within :data:`NEAR_M`
of an obstacle is not drawn: its closest approach is named in the view instead.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Circle as CirclePatch

from tubekit.scenario import Scenario
from tubekit.plotting.clearance import obstacle_gaps
from tubekit.plotting.run import Run
from tubekit.plotting.style import distance_text

__all__ = ["obstacle_frame", "draw_obstacle_side_view", "NEAR_M", "ZOOM_SHARE"]

#: Distance (m) from the inflated obstacle's surface within which a sample is drawn in the side view.
NEAR_M = 0.8
#: The zoomed inset is drawn when its width is at most this share of the view's width (else the view shows it).
ZOOM_SHARE = 0.35


def obstacle_frame(columns: Mapping[str, np.ndarray], scenario: Scenario) -> dict[str, np.ndarray]:
    """Per sample: horizontal distance ``h`` (m) to the nearest obstacle's centre, height ``dz`` (m) above it,
    the clearance ``gap`` (m, ball to surface, negative = overlap) and that obstacle's radius ``r`` (m)."""
    p = np.column_stack([columns["x"], columns["y"], columns["z"]]).astype(float)
    centres = np.array([o.center for o in scenario.obstacles], dtype=float).reshape(-1, 3)
    radii = np.array([o.radius for o in scenario.obstacles], dtype=float)
    gaps = obstacle_gaps(columns, scenario)
    k = np.nanargmin(np.where(np.isfinite(gaps), gaps, np.inf), axis=1)
    rows = np.arange(len(p))
    rel = p - centres[k]
    return {"h": np.hypot(rel[:, 0], rel[:, 1]), "dz": rel[:, 2], "gap": gaps[rows, k], "r": radii[k]}


def _discs(ax: Axes, radius: float, inflated: float) -> None:
    ax.add_patch(CirclePatch((0.0, 0.0), radius, color="0.35", alpha=0.8, zorder=1))
    ax.add_patch(CirclePatch((0.0, 0.0), inflated, fill=False, ls=":", color="0.35", zorder=1))


def _zoom(ax: Axes, radius: float, inflated: float, near: Sequence[tuple[dict, dict, int]],
          worst: tuple[float, float, float]) -> None:
    """The inset around the closest approach ``worst`` = (gap, h, dz), when narrow enough to show more."""
    half = max(0.03, 2.5 * abs(worst[0]))
    if 2.0 * half > ZOOM_SHARE * (inflated + NEAR_M):
        return
    zoom = ax.inset_axes((0.52, 0.02, 0.46, 0.42))
    _discs(zoom, radius, inflated)
    for f, style, j in near:
        zoom.plot(f["h"], f["dz"], **style)
        zoom.plot([f["h"][j]], [f["dz"][j]], marker="v", color=style.get("color"), mec="k", ms=6, ls="none")
    zoom.set_xlim(worst[1] - half, worst[1] + half)
    zoom.set_ylim(worst[2] - half, worst[2] + half)
    zoom.set_aspect("equal")
    zoom.set_xticks([])
    zoom.set_yticks([])
    zoom.set_xlabel(f"zoom: {2e3 * half:.0f} mm wide", fontsize=6.5, labelpad=1)
    ax.indicate_inset_zoom(zoom, edgecolor="0.3")


def draw_obstacle_side_view(ax: Axes, scenario: Scenario, runs: Sequence[Run], styles: Sequence[dict]) -> None:
    """Draw every run that comes near its nearest obstacle in (horizontal distance, height), its closest
    approach a labelled marker (the smallest clearance, for a legend), with a zoom when it helps; the runs that
    stay away are named in the view. Nothing is drawn without obstacles."""
    if not scenario.obstacles or not runs:
        ax.set_axis_off()
        return
    radius = float(max(o.radius for o in scenario.obstacles))
    inflated = radius + scenario.vehicle_radius
    _discs(ax, radius, inflated)
    near, away, worst = [], [], None
    for (label, c), style in zip(runs, styles):
        f = obstacle_frame(c, scenario)
        j = int(np.nanargmin(f["gap"]))
        if f["gap"][j] >= NEAR_M:
            away.append(f"{label} {distance_text(float(f['gap'][j]))}")
            continue
        shown = np.where(f["gap"] < NEAR_M, 1.0, np.nan)
        f = {"h": f["h"] * shown, "dz": f["dz"] * shown, "gap": f["gap"]}
        ax.plot(f["h"], f["dz"], **style)
        ax.plot([f["h"][j]], [f["dz"][j]], marker="v", color=style.get("color"), mec="k", ms=6, ls="none", zorder=5,
                label=f"{label}: min clearance {distance_text(float(f['gap'][j]))}")
        near.append((f, style, j))
        if worst is None or f["gap"][j] < worst[0]:
            worst = (float(f["gap"][j]), float(f["h"][j]), float(f["dz"][j]))
    if worst is not None:
        _zoom(ax, radius, inflated, near, worst)
    if away:
        ax.text(0.98, 0.98, f"never within {NEAR_M:g} m\n(min clearance):\n" + "\n".join(away),
                transform=ax.transAxes, ha="right", va="top", fontsize=6.5, color="0.2")
    ax.set_xlim(0.0, inflated + NEAR_M)
    ax.set_ylim(-inflated - 0.5, inflated + 0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("horizontal distance to its centre (m)", fontsize=8)
    ax.set_ylabel("height above its centre (m)", fontsize=8)
    ax.set_title("Side view at the nearest obstacle\n(grey: obstacle; dotted: + vehicle radius)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
