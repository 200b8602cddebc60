"""Fig. 2, the top view: the paths with time ticks, the position tube around the nominal, the target at the
start and at the end (the lag shows), the sensing range when it fits; beside it the legend and a side view at
the nearest obstacle (:mod:`tubekit.plotting.side_view`). The frame zooms on the path
(:mod:`tubekit.plotting.framing`); what it leaves out is named in the view.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch

from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.plotting.clearance import clearance_of
from tubekit.plotting.framing import Frame, desired_curve, end_time, frame_of
from tubekit.plotting.run import Run
from tubekit.plotting.side_view import draw_obstacle_side_view
from tubekit.plotting.style import distance_text, run_style, tick_interval, tick_rows

__all__ = ["draw_scene_xy", "draw_top_view", "top_view", "fit_canvas", "tube_label"]

_TUBE_COLOUR = "#b8d4ee"


def draw_scene_xy(ax: Axes, scenario: Scenario, t_end: float, *, start_target: bool = True,
                  obstacles: Sequence[int] | None = None) -> None:
    """The static part of the top view: desired path over [0, ``t_end``], obstacles (all, or the indices
    ``obstacles``) and their r̄-inflated outline, the target at t = 0."""
    pd = desired_curve(scenario, t_end)
    ax.plot(pd[:, 0], pd[:, 1], "--", color="tab:green", lw=1.1, label="desired $p_d(t)$")
    shown = range(len(scenario.obstacles)) if obstacles is None else obstacles
    for n, k in enumerate(shown):
        o = scenario.obstacles[k]
        ax.add_patch(CirclePatch(o.center[:2], o.radius, color="0.35", alpha=0.8, label="obstacle" if n == 0 else None))
        ax.add_patch(CirclePatch(o.center[:2], o.radius + scenario.vehicle_radius, fill=False, ls=":", color="0.35",
                                 label=r"obstacle + $\bar r$ (vehicle centre must stay out)" if n == 0 else None))
    if start_target:
        ax.plot([pd[0, 0]], [pd[0, 1]], "*", color="tab:green", ms=11, mec="k", mew=0.5, label="target at $t=0$")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.3)


def tube_label(half: float, tightening: Tightening) -> str:
    """The position tube's legend entry: "(certified)" only when the certificate gives the tracking tier."""
    given = tightening.tiers.tracking
    return rf"position tube: $\hat p$ $\pm$ {half:.3g} m ({'certified' if given else 'not certified'})"


def _draw_tube_band(ax: Axes, columns: Mapping[str, np.ndarray], half: float, label: str) -> None:
    """The position tube: discs of radius ``half`` (m) around the nominal p̂ (their union is the band)."""
    xy = np.column_stack([columns["x_hat"], columns["y_hat"]]).astype(float)
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    xy = xy[:: max(1, len(xy) // 3000)]
    if not len(xy):
        return
    angle = np.linspace(0.0, 2.0 * np.pi, 25)
    ring = half * np.column_stack([np.cos(angle), np.sin(angle)])
    ax.add_collection(PolyCollection(xy[:, None, :] + ring[None], facecolor=_TUBE_COLOUR, edgecolor="none",
                                     zorder=1, label=label), autolim=False)
    ax.plot(xy[:, 0], xy[:, 1], color="tab:blue", lw=0.6, ls=(0, (1, 2)), zorder=2, label=r"nominal $\hat p$ (tube run)")


def _draw_time_ticks(ax: Axes, label: str, c: Mapping[str, np.ndarray], rows: np.ndarray, every_s: float) -> None:
    """Dots with their time (s) every ``every_s`` seconds along the run."""
    if not len(rows):
        return
    ax.plot(c["x"][rows], c["y"][rows], "o", color="k", ms=3, zorder=5, label=f"{label} every {every_s:g} s")
    for j in rows:
        ax.annotate(f"{float(c['t'][j]):g} s", (c["x"][j], c["y"][j]), xytext=(4, 4), textcoords="offset points",
                    fontsize=7, color="0.15", zorder=6)


def _draw_sensing(ax: Axes, scenario: Scenario, c: Mapping[str, np.ndarray], rows: np.ndarray, every_s: float) -> None:
    """The sensing circles R̄ at the start and at every other time tick."""
    for n, j in enumerate(np.r_[0, rows[1::2]].astype(int)):
        ax.add_patch(CirclePatch((c["x"][j], c["y"][j]), scenario.sensing_range, fill=False, lw=0.7, ls="--",
                                 color="tab:purple", alpha=0.55, zorder=2,
                                 label=rf"sensing range $\bar R$ = {scenario.sensing_range:g} m, "
                                       rf"every {2 * every_s:g} s" if n == 0 else None))


def _draw_start_and_ends(ax: Axes, scenario: Scenario, runs: Sequence[Run], t_end: float, frame: Frame) -> None:
    """The vehicle ball and heading at the start; each run's end; the target at the end and the first run's lag."""
    x0 = np.asarray(scenario.initial_state, dtype=float)
    ax.add_patch(CirclePatch(x0[:2], scenario.vehicle_radius, fc="none", ec="k", lw=1.0, zorder=4,
                             label=rf"vehicle ball $\bar r$ = {scenario.vehicle_radius:g} m"))
    ax.plot([x0[0]], [x0[1]], "o", color="white", mec="k", ms=7, zorder=5, label="start (t = 0)")
    arrow = 0.08 * max(frame.width, frame.height)  # the heading at the start, at the frame's scale
    ax.annotate("", xy=(x0[0] + arrow * np.cos(x0[3]), x0[1] + arrow * np.sin(x0[3])), xytext=(x0[0], x0[1]),
                arrowprops=dict(arrowstyle="->", color="k"), zorder=5)
    for i, (label, c) in enumerate(runs):
        ax.plot([c["x"][-1]], [c["y"][-1]], "s", color=run_style(i).get("color"), mec="k", ms=7, zorder=5,
                label=f"end of {label} (t = {float(c['t'][-1]):g} s)")
    target = np.asarray(scenario.trajectory.position(np.array([t_end])), dtype=float).reshape(-1)
    ax.plot([target[0]], [target[1]], "*", color="white", mec="tab:green", mew=1.4, ms=13, zorder=6,
            label=f"target at t = {t_end:g} s")
    if runs:
        label, c = runs[0]
        end = np.array([c["x"][-1], c["y"][-1], c["z"][-1]], dtype=float)
        ax.plot([end[0], target[0]], [end[1], target[1]], ":", color="tab:green", lw=1.2, zorder=5,
                label=f"{label}'s lag at the end: {float(np.linalg.norm(target[:3] - end)):.3g} m")


def _draw_backup(ax: Axes, runs: Sequence[Run]) -> None:
    """The first run's samples under the backup law, dotted grey."""
    if not runs or "backup_active" not in runs[0][1]:
        return
    label, c = runs[0]
    on = np.asarray(c["backup_active"], dtype=float) > 0.5
    if np.any(on):
        ax.plot(np.asarray(c["x"])[on], np.asarray(c["y"])[on], ".", color="0.35", ms=2.5, zorder=4,
                label=f"{label}: backup law active")


def _note_left_out(ax: Axes, scenario: Scenario, runs: Sequence[Run], frame: Frame) -> None:
    """Name in the view what the frame leaves out: obstacles far from the path, a sensing range wider than it."""
    notes = []
    away = len(scenario.obstacles) - len(frame.obstacles)
    if away:
        gap = min(float(np.nanmin(clearance_of(c, scenario))) for _, c in runs) if runs else float("nan")
        notes.append(f"{away} obstacle{'s' if away > 1 else ''} outside the view"
                     + (f" (min clearance {distance_text(gap)})" if runs else ""))
    if runs and not frame.sensing:
        notes.append(rf"sensing range $\bar R$ = {scenario.sensing_range:g} m: wider than the view, not drawn")
    if notes:
        ax.text(0.01, 0.01, "\n".join(notes), transform=ax.transAxes, ha="left", va="bottom", fontsize=7,
                color="0.2", zorder=7, bbox=dict(fc="white", ec="0.7", alpha=0.85, lw=0.5))


def draw_top_view(ax: Axes, scenario: Scenario, runs: Sequence[Run], *,
                  tightening: Tightening | None = None) -> Frame:
    """Draw the top view of ``runs`` on ``ax`` (the first run gets the tube, the time ticks, the sensing circles
    and the lag); ``tightening``'s ``obstacle_margin`` (m) is the tube's half-width (none when 0 or absent).
    Returns the frame drawn (:func:`tubekit.plotting.framing.frame_of`)."""
    t_end = end_time(scenario, runs)
    half = float(tightening.obstacle_margin) if tightening is not None and runs else 0.0
    frame = frame_of(scenario, runs, tube_half=half)
    draw_scene_xy(ax, scenario, t_end, obstacles=frame.obstacles)
    if half > 0:
        _draw_tube_band(ax, runs[0][1], half, tube_label(half, tightening))
    for i, (label, c) in enumerate(runs):
        ax.plot(c["x"], c["y"], label=label, zorder=3, **run_style(i))
    if runs:
        every = tick_interval(t_end)
        rows = tick_rows(np.asarray(runs[0][1]["t"], dtype=float), every)
        _draw_time_ticks(ax, runs[0][0], runs[0][1], rows, every)
        if frame.sensing:
            _draw_sensing(ax, scenario, runs[0][1], rows, every)
    _draw_start_and_ends(ax, scenario, runs, t_end, frame)
    _draw_backup(ax, runs)
    _note_left_out(ax, scenario, runs, frame)
    _show(ax, frame)
    return frame


def _show(ax: Axes, frame: Frame) -> None:
    """Limit the view to ``frame`` at equal scales: the frame is the data limits (the artists' own are dropped),
    so the equal aspect widens one side of it rather than fighting fixed limits."""
    ax.ignore_existing_data_limits = True
    ax.update_datalim(np.array([[frame.x[0], frame.y[0]], [frame.x[1], frame.y[1]]]))
    ax.margins(0.0)
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")


def fit_canvas(fig: Figure, ax: Axes, legend_in: float = 2.9, longest_in: float = 6.2) -> None:
    """Size the figure to the data's aspect (equal scales, no empty half canvas) plus the legend's width."""
    ax.autoscale_view()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    dx, dy = max(x1 - x0, 1e-6), max(y1 - y0, 1e-6)
    scale = longest_in / max(dx, dy)
    width, height = max(dx * scale, 2.5), max(dy * scale, 2.5)
    fig.set_size_inches(width + legend_in + 0.9, height + 0.9)
    ax.set_aspect("equal", adjustable="datalim")


def top_view(scenario: Scenario, runs: Sequence[Run], *, tightening: Tightening | None = None) -> Figure:
    """Fig. 2: :func:`draw_top_view`; beside it the legend (small) and a side view at the nearest obstacle
    (passes over it, mm overlaps, zoomed).

    Parameters
    ----------
    runs : sequence of (label, columns)
        The first run gets the time ticks, the sensing circles, the tube and the lag at the end.
    tightening : Tightening, optional
        Its ``obstacle_margin`` (m) is the half-width of the position tube drawn around the first run's
        nominal path, labelled "(certified)" only when its tiers give tracking.
    """
    fig = Figure(layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(2.5, 1.25), height_ratios=(1.0, 1.1))
    ax = fig.add_subplot(grid[:, 0])
    frame = draw_top_view(ax, scenario, runs, tightening=tightening)
    ax.set_title(f"Top view ({scenario.name})")
    height = 6.0
    fig.set_size_inches(min(max(height * frame.width / frame.height, 3.0), 9.0) + 3.6, height + 0.4)
    side = fig.add_subplot(grid[1, 1])
    draw_obstacle_side_view(side, scenario, runs, [run_style(i) for i in range(len(runs))])
    legend_ax = fig.add_subplot(grid[0, 1])
    legend_ax.set_axis_off()
    handles, labels = ax.get_legend_handles_labels()
    more = side.get_legend_handles_labels()
    legend_ax.legend(handles + more[0], labels + more[1], loc="upper left", fontsize=6.5, frameon=False,
                     borderaxespad=0.0, handlelength=1.6)
    return fig
