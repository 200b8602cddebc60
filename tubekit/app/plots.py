"""Figures of a run: paper Figs. 2-4, the per-axis deviation against the tube box, a 3-D view, clearance.

Uses matplotlib's object API (:class:`matplotlib.figure.Figure`, Agg canvas):
no pyplot state, no window, never ``show()``. Every function takes logged
columns (as from ``trajectory.csv``), so figures can be redrawn from the CSVs.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch
from matplotlib.ticker import MaxNLocator

from tubekit.exceptions import ConfigError
from tubekit.loop.metrics import clearance
from tubekit.loop.result import SimulationResult
from tubekit.tiers import Tiers
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.app.plots_obstacle import draw_obstacle_side_view
from tubekit.app.plots_envelope import envelope_figure, plot_envelope  # re-exported: their old home

__all__ = [
    "Run",
    "plot_run",
    "top_view",
    "draw_scene_xy",
    "fit_canvas",
    "run_style",
    "errors_figure",
    "inputs_figure",
    "period_envelope",
    "rho_figure",
    "view_3d",
    "clearance_figure",
    "plot_all",
    "FIGURE_FILES",
    "envelope_figure",
    "plot_envelope",
    "backup_stretches",
    "shade_backup",
    "tier_title",
    "title_lines",
]

#: File names written by :func:`plot_all`.
FIGURE_FILES: tuple[str, ...] = ("fig2_top_view.png", "fig3_errors.png", "fig4_inputs.png", "rho.png",
                                 "view_3d.png", "clearance.png")

Run = tuple[str, Mapping[str, np.ndarray]]  # (label, columns)
_STYLE = {0: dict(color="tab:blue", lw=1.4), 1: dict(color="tab:orange", lw=1.0, alpha=0.85)}
_LEGEND_OUTSIDE = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8)
#: Clearance (m) below which the clearance axis is linear (symlog): mm-scale penetrations stay visible.
CLEARANCE_LINEAR_M = 0.01


def run_style(i: int) -> dict:
    """Line style of the ``i``-th run (0: the tube run, 1: the baseline)."""
    return dict(_STYLE.get(i, dict(lw=1.0)))


def backup_stretches(columns: Mapping[str, np.ndarray]) -> list[tuple[float, float]]:
    """(start, end) times (s) of the stretches in which the backup law ran (column ``backup_active``; none
    when the column is absent). A stretch ends at the first tick that follows a plan again."""
    active = columns.get("backup_active")
    if active is None:
        return []
    on = np.asarray(active, dtype=float) > 0.5
    t = np.asarray(columns["t"], dtype=float)
    edges = np.diff(np.r_[0, on.astype(int), 0])
    return [(float(t[a]), float(t[min(b, len(t) - 1)])) for a, b in zip(np.flatnonzero(edges == 1),
                                                                      np.flatnonzero(edges == -1))]


def shade_backup(ax, stretches: Sequence[tuple[float, float]], *, label: bool = True) -> None:
    """Shade the backup-active stretches (grey) on a time axis; one legend entry when ``label``."""
    for n, (a, b) in enumerate(stretches):
        ax.axvspan(a, b, color="0.5", alpha=0.18, lw=0, zorder=0,
                   label="backup law active (station keeping)" if label and n == 0 else None)


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


def _desired_curve(scenario: Scenario, t_end: float) -> np.ndarray:
    return np.asarray(scenario.trajectory.position(np.linspace(0.0, t_end, 2000)))


def _t_end(scenario: Scenario, runs: Sequence[Run]) -> float:
    return float(runs[0][1]["t"][-1]) if runs else scenario.duration


def _tick_interval(t_end: float, ticks: int = 8) -> float:
    """A round time step (s) giving at most about ``ticks`` marks over ``t_end`` seconds."""
    for step in (0.5, 1, 2, 5, 10, 20, 25, 50, 100, 200, 500, 1000):
        if t_end / step <= ticks:
            return float(step)
    return float(10 ** np.ceil(np.log10(max(t_end, 1.0) / ticks)))


def _tick_rows(t: np.ndarray, every_s: float) -> np.ndarray:
    """Row indices of the first samples at or after each multiple of ``every_s`` (s), t = 0 excluded."""
    marks = np.arange(every_s, float(t[-1]) + 1e-9, every_s)
    return np.unique(np.searchsorted(t, marks - 1e-9))


def _position_tube(tightening: Tightening | None) -> float:
    """Half-width (m) of the position tube: the margin the FHOCP keeps between p̂ and the inflated obstacles."""
    return float(tightening.obstacle_margin) if tightening is not None else 0.0


def draw_scene_xy(ax, scenario: Scenario, t_end: float, *, start_target: bool = True) -> None:
    """The static part of the top view: desired path, obstacles, obstacles inflated by r̄, target at t = 0."""
    pd = _desired_curve(scenario, t_end)
    ax.plot(pd[:, 0], pd[:, 1], "--", color="tab:green", lw=1.1, label="desired $p_d(t)$")
    for k, o in enumerate(scenario.obstacles):
        ax.add_patch(CirclePatch(o.center[:2], o.radius, color="0.35", alpha=0.8,
                                 label="obstacle" if k == 0 else None))
        ax.add_patch(CirclePatch(o.center[:2], o.radius + scenario.vehicle_radius, fill=False, ls=":",
                                 color="0.35", label=r"obstacle + $\bar r$ (vehicle centre must stay out)"
                                 if k == 0 else None))
    if start_target:
        ax.plot([pd[0, 0]], [pd[0, 1]], "*", color="tab:green", ms=11, mec="k", mew=0.5, label="target at $t=0$")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.3)


def _draw_tube_band(ax, columns: Mapping[str, np.ndarray], half_width: float, label: str) -> None:
    """The position tube: discs of radius ``half_width`` (m) around the nominal p̂ (their union is the band)."""
    xy = np.column_stack([columns["x_hat"], columns["y_hat"]])
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    xy = xy[:: max(1, len(xy) // 3000)]
    discs = [CirclePatch(p, half_width) for p in xy]
    ax.add_collection(PatchCollection(discs, facecolor="#b8d4ee", edgecolor="none", zorder=1))
    ax.fill([], [], color="#b8d4ee", label=label)  # legend proxy
    ax.plot(xy[:, 0], xy[:, 1], color="tab:blue", lw=0.6, ls=(0, (1, 2)), zorder=2, label=r"nominal $\hat p$ (tube run)")


def _draw_path_with_time(ax, scenario: Scenario, runs: Sequence[Run], every_s: float) -> None:
    """Each run's path with start/end markers; the first run with time ticks and the sensing range."""
    for i, (label, c) in enumerate(runs):
        style = run_style(i)
        ax.plot(c["x"], c["y"], label=label, zorder=3, **style)
        ax.plot([c["x"][-1]], [c["y"][-1]], "s", color=style.get("color"), mec="k", ms=7, zorder=5,
                label=f"end of {label} (t = {float(c['t'][-1]):g} s)")
    if not runs:
        return
    c = runs[0][1]
    rows = _tick_rows(np.asarray(c["t"]), every_s)
    ax.plot(c["x"][rows], c["y"][rows], "o", color="k", ms=3, zorder=5, label=f"{runs[0][0]} every {every_s:g} s")
    for j in rows:
        ax.annotate(f"{float(c['t'][j]):g} s", (c["x"][j], c["y"][j]), xytext=(4, 4), textcoords="offset points",
                    fontsize=7, color="0.15", zorder=6)
    for n, j in enumerate(np.r_[0, rows[1::2]]):
        ax.add_patch(CirclePatch((c["x"][j], c["y"][j]), scenario.sensing_range, fill=False, lw=0.7,
                                 ls="--", color="tab:purple", alpha=0.55, zorder=2,
                                 label=rf"sensing range $\bar R$ = {scenario.sensing_range:g} m, "
                                       rf"every {2 * every_s:g} s" if n == 0 else None))
    x0 = np.asarray(scenario.initial_state)
    ax.add_patch(CirclePatch(x0[:2], scenario.vehicle_radius, fc="none", ec="k", lw=1.0, zorder=4,
                             label=rf"vehicle ball $\bar r$ = {scenario.vehicle_radius:g} m"))
    ax.plot([x0[0]], [x0[1]], "o", color="white", mec="k", ms=7, zorder=5, label="start (t = 0)")
    ax.annotate("", xy=(x0[0] + 0.6 * np.cos(x0[3]), x0[1] + 0.6 * np.sin(x0[3])), xytext=(x0[0], x0[1]),
                arrowprops=dict(arrowstyle="->", color="k"), zorder=5)


def fit_canvas(fig: Figure, ax, legend_in: float = 2.9, longest_in: float = 6.2) -> None:
    """Size the figure to the data's aspect (equal scales, no empty half canvas) plus the legend's width."""
    ax.autoscale_view()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    dx, dy = max(x1 - x0, 1e-6), max(y1 - y0, 1e-6)
    scale = longest_in / max(dx, dy)
    width, height = max(dx * scale, 2.5), max(dy * scale, 2.5)
    fig.set_size_inches(width + legend_in + 0.9, height + 0.9)
    ax.set_aspect("equal", adjustable="datalim")


def _scene_extent(ax) -> tuple[float, float]:
    """Width and height (m) of the data drawn on ``ax`` (its autoscaled limits)."""
    ax.autoscale_view()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    return max(x1 - x0, 1e-6), max(y1 - y0, 1e-6)


def top_view(scenario: Scenario, runs: Sequence[Run], *, tightening: Tightening | None = None) -> Figure:
    """Fig. 2: paths with time ticks, the position tube around the nominal, sensing range at intervals; beside
    it the legend (small) and a side view at the nearest obstacle (passes over it, mm overlaps, zoomed).

    Parameters
    ----------
    runs : sequence of (label, columns)
        The first run gets the time ticks, the sensing circles and the tube.
    tightening : Tightening, optional
        Its ``obstacle_margin`` (m) is the half-width of the position tube drawn
        around the first run's nominal path (none when 0 or absent).
    """
    fig = Figure(layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(2.5, 1.25), height_ratios=(1.0, 1.1))
    ax = fig.add_subplot(grid[:, 0])
    t_end = _t_end(scenario, runs)
    draw_scene_xy(ax, scenario, t_end)
    half = _position_tube(tightening)
    if runs and half > 0:
        certified = bool(getattr(tightening, "certified", False))
        _draw_tube_band(ax, runs[0][1], half, rf"position tube: $\hat p$ $\pm$ {half:.3g} m "
                                              f"({'certified' if certified else 'best effort, NOT certified'})")
    _draw_path_with_time(ax, scenario, runs, _tick_interval(t_end))
    if runs and "backup_active" in runs[0][1]:
        c = runs[0][1]
        on = np.asarray(c["backup_active"], dtype=float) > 0.5
        if np.any(on):
            ax.plot(np.asarray(c["x"])[on], np.asarray(c["y"])[on], ".", color="0.35", ms=2.5, zorder=4,
                    label=f"{runs[0][0]}: backup law active")
    ax.set_title(f"Top view ({scenario.name})")
    dx, dy = _scene_extent(ax)
    height = 6.0
    fig.set_size_inches(min(max(height * dx / dy, 3.0), 9.0) + 3.6, height + 0.4)
    ax.set_aspect("equal", adjustable="datalim")
    side = fig.add_subplot(grid[1, 1])
    draw_obstacle_side_view(side, scenario, runs, [run_style(i) for i in range(len(runs))])
    legend_ax = fig.add_subplot(grid[0, 1])
    legend_ax.set_axis_off()
    handles, labels = ax.get_legend_handles_labels()
    more = side.get_legend_handles_labels()
    legend_ax.legend(handles + more[0], labels + more[1], loc="upper left", fontsize=6.5, frameon=False,
                     borderaxespad=0.0, handlelength=1.6)
    return fig


def plot_run(run: SimulationResult) -> Figure:
    """The figure of one run: its top view (:func:`top_view`), with the position tube of a tube run."""
    if not isinstance(run, SimulationResult):
        raise ConfigError("run", "a tubekit.SimulationResult", type(run).__name__)
    label = "tube" if run.tube else "baseline"
    return top_view(run.scenario, [(label, run.columns())], tightening=run.tightening if run.tube else None)


def errors_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Fig. 3: e_d, e_z, e_o against time, with ε on e_d."""
    fig = Figure(figsize=(7.5, 6.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    names = (("e_d", "$e_d$ (m)"), ("e_z", "$e_z$ (m)"), ("e_o", "$e_o$ (-)"))
    for ax, (key, lab) in zip(axes, names):
        for i, (label, c) in enumerate(runs):
            ax.plot(c["t"], c[key], label=label, **run_style(i))
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
        shade_backup(ax, backup_stretches(runs[0][1]) if runs else [], label=ax is axes[0])
    axes[0].axhline(scenario.epsilon, color="tab:red", ls="--", lw=1.0, label=rf"$\epsilon$ = {scenario.epsilon:g} m")
    axes[0].set_yscale("log")
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle("Tracking errors")
    return fig


def period_envelope(columns: Mapping[str, np.ndarray], key: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per FHOCP period: start time (s), min and max of column ``key``; the times end with the last sample's."""
    step = np.asarray(columns["step"])
    values = np.asarray(columns[key], dtype=float)
    starts = np.flatnonzero(np.r_[True, step[1:] != step[:-1]])
    ends = np.r_[starts[1:], len(step)]
    lo, hi = np.full(len(starts), np.nan), np.full(len(starts), np.nan)
    for n, (a, b) in enumerate(zip(starts, ends)):
        chunk = values[a:b][np.isfinite(values[a:b])]
        if chunk.size:
            lo[n], hi[n] = chunk.min(), chunk.max()
    t = np.asarray(columns["t"], dtype=float)
    return np.r_[t[starts], t[-1]], np.r_[lo, lo[-1:]], np.r_[hi, hi[-1:]]


def inputs_figure(scenario: Scenario, runs: Sequence[Run], *, tightening: Tightening | None = None) -> Figure:
    """Fig. 4: per axis, v̂ as a line, the per-period min/max envelope of the applied v, bounds of V and V̄."""
    fig = Figure(figsize=(8.8, 6.8), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    lim = scenario.limits.vector
    tight = None if tightening is None else np.asarray(tightening.v_max, dtype=float)
    names = (("u", "u (m/s)"), ("w", "w (m/s)"), ("r", "r (rad/s)"))
    for n, (ax, (key, lab), b) in enumerate(zip(axes, names, lim)):
        for i, (label, c) in enumerate(runs):
            colour = run_style(i).get("color")
            t_edges, lo, hi = period_envelope(c, key)
            ax.fill_between(t_edges, lo, hi, step="post", color=colour, alpha=0.25 if i == 0 else 0.15, lw=0,
                            label=f"{label}: applied v, min-max per period")
            ax.plot(c["t"], c[f"{key}_hat"], drawstyle="steps-post", color=colour, lw=1.2 if i == 0 else 0.9,
                    label=rf"{label}: $\hat v$ (FHOCP)")
        ax.axhline(b, color="tab:red", ls="--", lw=1.0, label=r"bound of $V$")
        ax.axhline(-b, color="tab:red", ls="--", lw=1.0)
        if tight is not None and tight[n] < b - 1e-12:
            ax.axhline(tight[n], color="tab:purple", ls=":", lw=1.2, label=r"bound of $\bar V$ (tightened, for $\hat v$)")
            ax.axhline(-tight[n], color="tab:purple", ls=":", lw=1.2)
        elif tight is not None:
            ax.plot([], [], ls="none", label=r"$\bar V = V$ on this axis (no tightening)")
        ax.set_ylim(-1.15 * b, 1.15 * b)
        shade_backup(ax, backup_stretches(runs[0][1]) if runs else [], label=n == 0)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[0].legend(**_LEGEND_OUTSIDE)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(r"Control inputs: nominal $\hat v$ and applied $v = \hat v + \kappa$")
    return fig


def _period_peaks(columns: Mapping[str, np.ndarray], values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per sampling period: its end time (s) and the max of ``values`` over its ticks (the pre-reset peak)."""
    step = np.asarray(columns["step"])
    m = int(np.sum(step == step[0]))
    n = (len(values) - 1) // m if m else 0
    t = np.asarray(columns["t"], dtype=float)
    if m < 1 or n < 1 or n * m + 1 != len(values):
        return t, values
    with np.errstate(all="ignore"):
        return t[m::m][:n], np.nanmax(values[1:n * m + 1].reshape(n, m), axis=1)


def rho_figure(runs: Sequence[Run], tube: Sequence[float] | None, certified: bool) -> Figure:
    """Per axis, |e_j − ê_j| / tube_j (peak of each sampling period) of the first run against 1, the box the
    ``tube`` promise checks (max_j of these ratios ≤ 1, while a plan is followed); |e_j − ê_j| itself when
    there is no tube (``tube`` None or not positive). Ticks under the backup law are left out (grey)."""
    fig = Figure(figsize=(8.0, 5.4), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    box = None if tube is None else np.asarray(tube, dtype=float)
    ratio = box is not None and bool(np.all(box > 0))
    names = (("rho_d", "e_d", "m"), ("rho_z", "e_z", "m"), ("rho_o", "e_o", "-"))
    worst = []
    if runs:
        label, c = runs[0]
        following = np.asarray(c.get("backup_active", np.zeros(len(c["t"]))), dtype=float) < 0.5
        for j, (ax, (key, name, unit)) in enumerate(zip(axes, names)):
            dev = np.where(following, np.abs(np.asarray(c[key], dtype=float)), np.nan)
            tt, peak = _period_peaks(c, dev / box[j] if ratio else dev)
            ax.plot(tt, peak, label=f"{label}, max per period", **run_style(0))
            worst.append(float(np.nanmax(peak)) if np.any(np.isfinite(peak)) else float("nan"))
            ax.set_ylabel(rf"$|\rho_{{{name[2:]}}}|$ / tube" if ratio else rf"$|\rho_{{{name[2:]}}}|$ ({unit})")
            ax.grid(alpha=0.3)
            if ratio:
                ax.axhline(1.0, color="tab:red", ls="--" if certified else ":", lw=1.2,
                           label=f"tube box ({name}: {box[j]:.4g} {unit}), {'certified' if certified else 'NOT certified'}")
                ax.set_ylim(0.0, 1.4)  # the legend sits above the box line, clear of the data
            shade_backup(ax, backup_stretches(c), label=j == 0)
            ax.legend(fontsize=7, loc="upper center", ncol=3, frameon=False)
    head = "|e_j - e_hat_j| / tube_j per axis" if ratio else "|e_j - e_hat_j| per axis (no tube: nothing promised)"
    top = f"; largest {np.nanmax(worst):.6g} (promise: <= 1)" if ratio and worst else ""
    fig.suptitle(f"Deviation from the nominal, {head}{top}\n(it restarts at 0 at every FHOCP sample)", fontsize=10)
    axes[-1].set_xlabel("t (s)")
    return fig


def _sphere(ax, center: Sequence[float], radius: float, **style) -> None:
    """A sphere surface of ``radius`` (m) at ``center``."""
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 28), np.linspace(0, np.pi, 14))
    cx, cy, cz = center
    ax.plot_surface(cx + radius * np.cos(uu) * np.sin(vv), cy + radius * np.sin(uu) * np.sin(vv),
                    cz + radius * np.cos(vv), linewidth=0, antialiased=True, shade=True, **style)


def view_3d(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """3-D view at true aspect: path(s), desired trajectory, obstacle spheres, the vehicle ball at the end."""
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the projection)

    fig = Figure(figsize=(8.4, 5.6), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    pd = _desired_curve(scenario, _t_end(scenario, runs))
    ax.plot(pd[:, 0], pd[:, 1], pd[:, 2], "--", color="tab:green", lw=1.0, label="desired $p_d(t)$")
    points = [pd]
    for i, (label, c) in enumerate(runs):
        ax.plot(c["x"], c["y"], c["z"], label=label, **run_style(i))
        end = (float(c["x"][-1]), float(c["y"][-1]), float(c["z"][-1]))
        _sphere(ax, end, scenario.vehicle_radius, color=run_style(i).get("color"), alpha=0.6)
        points.append(np.column_stack([c["x"], c["y"], c["z"]]))
    for k, o in enumerate(scenario.obstacles):
        _sphere(ax, o.center, o.radius, color="0.45", alpha=0.55)
        points.append(np.asarray(o.center) + np.array([[-1, -1, -1], [1, 1, 1]]) * o.radius)
    ax.plot([], [], "o", color="0.45", ms=9, label="obstacle")
    ax.plot([], [], "o", color="tab:blue", alpha=0.6, ms=6, label=r"vehicle ball $\bar r$ at the end")
    allp = np.vstack([p[np.all(np.isfinite(p), axis=1)] for p in points])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(np.maximum(hi - lo, 1e-3))
    ax.zaxis.set_major_locator(MaxNLocator(3))
    ax.view_init(elev=35, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title("3-D view, true aspect (equal scale on x, y and z)")
    ax.legend(fontsize=8, loc="upper left")
    return fig


def clearance_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Vehicle-ball to nearest-obstacle-surface distance; symlog axis so mm-scale penetrations show."""
    fig = Figure(figsize=(8.5, 3.8), layout="constrained")
    ax = fig.add_subplot()
    lowest = 0.0
    for i, (label, c) in enumerate(runs):
        pos = np.column_stack([c["x"], c["y"], c["z"]])
        gap = clearance(pos, scenario.obstacles, scenario.vehicle_radius)
        ax.plot(c["t"], gap, label=label, **run_style(i))
        if np.any(np.isfinite(gap)):
            j = int(np.nanargmin(gap))
            lowest = min(lowest, float(gap[j]))
            ax.plot([c["t"][j]], [gap[j]], "v", color=run_style(i).get("color"), mec="k", ms=7,
                    label=f"{label}: min {1e3 * gap[j]:+.1f} mm at t = {float(c['t'][j]):.1f} s")
    ax.axhline(0.0, color="tab:red", ls="--", lw=1.0, label="contact")
    shade_backup(ax, backup_stretches(runs[0][1]) if runs else [])
    if scenario.obstacles:
        ax.set_yscale("symlog", linthresh=CLEARANCE_LINEAR_M, linscale=1.0)
        bottom = -max(0.02, 2.0 * abs(lowest))
        ax.axhspan(bottom, 0.0, color="tab:red", alpha=0.08, label="penetration (collision)")
        ax.set_ylim(bottom, None)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(f"clearance (m, symlog: linear within ±{CLEARANCE_LINEAR_M * 1e3:g} mm)", fontsize=9)
    ax.set_title(r"Clearance: $\|p - c_m\| - r_m - \bar r$ (nearest obstacle)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(**_LEGEND_OUTSIDE)
    return fig


def plot_all(out_dir: str | Path, scenario: Scenario, runs: Sequence[Run], *,
             rho_tilde: float | None = None, certified: bool = False, dpi: int = 110,
             tightening: Tightening | None = None, tiers: str | None = None) -> list[Path]:
    """Write every figure of :data:`FIGURE_FILES` into ``out_dir``; returns the paths.

    ``tightening`` (optional) adds the position tube to the top view, the bounds of V̄ to the inputs and the
    per-axis tube box to ``rho.png`` (``rho_tilde`` is accepted for callers of the older figure and unused);
    ``tiers`` (optional, :func:`tier_title`) is added as a title line to every figure. The first run's
    backup-active stretches are shaded on every time axis and marked on the top view.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figs = (top_view(scenario, runs, tightening=tightening), errors_figure(scenario, runs),
            inputs_figure(scenario, runs, tightening=tightening),
            rho_figure(runs, None if tightening is None else tightening.tube, certified),
            view_3d(scenario, runs), clearance_figure(scenario, runs))
    paths = []
    for name, fig in zip(FIGURE_FILES, figs):
        if tiers:
            head = fig.get_suptitle()
            fig.suptitle(title_lines(head, tiers), fontsize=9 if head else 10)
        p = out / name
        fig.savefig(p, dpi=dpi)
        paths.append(p)
    return paths
