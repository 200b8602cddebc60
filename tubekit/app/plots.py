"""Figures: a run (paper Figs. 2-4, ‖ρ‖ against ρ̃, a 3-D view, clearance) and a design envelope.

Uses matplotlib's object API (:class:`matplotlib.figure.Figure`, Agg canvas):
no pyplot state, no window, never ``show()``. Every function takes logged
columns (as from ``trajectory.csv``), so figures can be redrawn from the CSVs.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch

from ..exceptions import ConfigError
from ..metrics import clearance, rho_period_peaks
from ..scenario import Scenario

if TYPE_CHECKING:  # verify is imported for its type only; plotting needs no certificate code
    from verify.envelope import EnvelopeResult

__all__ = [
    "Run",
    "top_view",
    "errors_figure",
    "inputs_figure",
    "rho_figure",
    "view_3d",
    "clearance_figure",
    "plot_all",
    "FIGURE_FILES",
    "envelope_figure",
    "plot_envelope",
]

#: File names written by :func:`plot_all`.
FIGURE_FILES: tuple[str, ...] = ("fig2_top_view.png", "fig3_errors.png", "fig4_inputs.png", "rho.png",
                                 "view_3d.png", "clearance.png")

Run = tuple[str, Mapping[str, np.ndarray]]  # (label, columns)
_STYLE = {0: dict(color="tab:blue", lw=1.4), 1: dict(color="tab:orange", lw=1.0, alpha=0.85)}


def _style(i: int) -> dict:
    return dict(_STYLE.get(i, dict(lw=1.0)))


def _desired_curve(scenario: Scenario, t_end: float) -> np.ndarray:
    return np.asarray(scenario.trajectory.position(np.linspace(0.0, t_end, 2000)))


def top_view(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Fig. 2: path(s), desired trajectory, obstacles (and inflated by r̄), sensing circle at t = 0."""
    fig = Figure(figsize=(6.4, 6.2), layout="constrained")
    ax = fig.add_subplot()
    t_end = float(runs[0][1]["t"][-1]) if runs else scenario.duration
    pd = _desired_curve(scenario, t_end)
    ax.plot(pd[:, 0], pd[:, 1], "--", color="tab:green", lw=1.2, label="desired $p_d(t)$")
    for k, o in enumerate(scenario.obstacles):
        ax.add_patch(CirclePatch(o.center[:2], o.radius, color="0.35", alpha=0.8,
                                 label="obstacle" if k == 0 else None))
        ax.add_patch(CirclePatch(o.center[:2], o.radius + scenario.vehicle_radius, fill=False, ls=":",
                                 color="0.35", label=r"obstacle + $\bar r$" if k == 0 else None))
    for i, (label, c) in enumerate(runs):
        ax.plot(c["x"], c["y"], label=label, **_style(i))
    x0 = np.asarray(scenario.initial_state)
    ax.add_patch(CirclePatch(x0[:2], scenario.sensing_range, fill=False, color="tab:blue", lw=1.0,
                             label=r"sensing range $\bar R$ at $t=0$"))
    ax.add_patch(CirclePatch(x0[:2], scenario.vehicle_radius, color="tab:blue", alpha=0.3,
                             label=r"vehicle ball $\bar r$"))
    ax.annotate("", xy=(x0[0] + 0.6 * np.cos(x0[3]), x0[1] + 0.6 * np.sin(x0[3])), xytext=(x0[0], x0[1]),
                arrowprops=dict(arrowstyle="->", color="tab:blue"))
    p0 = pd[0]
    ax.plot([p0[0]], [p0[1]], "*", color="tab:blue", ms=12, label="target at $t=0$")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"Top view ({scenario.name})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center", framealpha=0.8)
    return fig


def errors_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Fig. 3: e_d, e_z, e_o against time, with ε on e_d."""
    fig = Figure(figsize=(7.5, 6.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    names = (("e_d", "$e_d$ (m)"), ("e_z", "$e_z$ (m)"), ("e_o", "$e_o$ (-)"))
    for ax, (key, lab) in zip(axes, names):
        for i, (label, c) in enumerate(runs):
            ax.plot(c["t"], c[key], label=label, **_style(i))
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[0].axhline(scenario.epsilon, color="tab:red", ls="--", lw=1.0, label=rf"$\epsilon$ = {scenario.epsilon:g} m")
    axes[0].set_yscale("log")
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle("Tracking errors")
    return fig


def inputs_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Fig. 4: u, w, r against time, with the bounds of V."""
    fig = Figure(figsize=(7.5, 6.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    lim = scenario.limits.vector
    names = (("u", "u (m/s)"), ("w", "w (m/s)"), ("r", "r (rad/s)"))
    for ax, (key, lab), b in zip(axes, names, lim):
        for i, (label, c) in enumerate(runs):
            ax.plot(c["t"], c[key], label=label, **_style(i))
        ax.axhline(b, color="tab:red", ls="--", lw=1.0, label="bound of V")
        ax.axhline(-b, color="tab:red", ls="--", lw=1.0)
        ax.set_ylim(-1.15 * b, 1.15 * b)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, ncol=3)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle("Control inputs (applied, v = v̂ + κ)")
    return fig


def rho_figure(runs: Sequence[Run], rho_tilde: float | None, certified: bool) -> Figure:
    """‖ρ(t)‖ = ‖e − ê‖ (peak of each sampling period) against the tube radius ρ̃."""
    fig = Figure(figsize=(7.5, 3.8), layout="constrained")
    ax = fig.add_subplot()
    for i, (label, c) in enumerate(runs):
        tt, peak = rho_period_peaks(c)
        ax.plot(tt, peak, label=rf"$\max\|\rho\|$ per period, {label}", **_style(i))
    if rho_tilde is not None and np.isfinite(rho_tilde) and rho_tilde > 0:
        lab = (rf"$\tilde\rho$ = {rho_tilde:.3g} (certified)" if certified
               else rf"$\tilde\rho$ = {rho_tilde:.3g} (best effort, NOT certified)")
        ax.axhline(rho_tilde, color="tab:red", ls="--" if certified else ":", lw=1.2, label=lab)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(r"$\|\rho\| = \|e - \hat e\|$")
    ax.set_title("Deviation from the nominal (ρ resets to 0 at every FHOCP sample)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def view_3d(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """3-D view: path(s), desired trajectory, obstacle spheres."""
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the projection)

    fig = Figure(figsize=(7.0, 6.0), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    t_end = float(runs[0][1]["t"][-1]) if runs else scenario.duration
    pd = _desired_curve(scenario, t_end)
    ax.plot(pd[:, 0], pd[:, 1], pd[:, 2], "--", color="tab:green", lw=1.0, label="desired")
    for i, (label, c) in enumerate(runs):
        ax.plot(c["x"], c["y"], c["z"], label=label, **_style(i))
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 24), np.linspace(0, np.pi, 12))
    for o in scenario.obstacles:
        cx, cy, cz = o.center
        ax.plot_wireframe(cx + o.radius * np.cos(uu) * np.sin(vv), cy + o.radius * np.sin(uu) * np.sin(vv),
                          cz + o.radius * np.cos(vv), color="0.4", lw=0.4)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title("3-D view (z axis stretched; spheres drawn to the same scale)")
    ax.legend(fontsize=8)
    return fig


def clearance_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Vehicle-ball to nearest-obstacle-surface distance against time."""
    fig = Figure(figsize=(7.5, 3.4), layout="constrained")
    ax = fig.add_subplot()
    for i, (label, c) in enumerate(runs):
        pos = np.column_stack([c["x"], c["y"], c["z"]])
        ax.plot(c["t"], clearance(pos, scenario.obstacles, scenario.vehicle_radius), label=label, **_style(i))
    ax.axhline(0.0, color="tab:red", ls="--", lw=1.0, label="contact")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("clearance (m)")
    if scenario.obstacles:
        ax.set_ylim(-0.2, min(3.0, ax.get_ylim()[1]))
    ax.set_title(r"Clearance: $\|p - c_m\| - r_m - \bar r$ (nearest obstacle)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_all(out_dir: str | Path, scenario: Scenario, runs: Sequence[Run], *,
             rho_tilde: float | None = None, certified: bool = False, dpi: int = 110) -> list[Path]:
    """Write every figure of :data:`FIGURE_FILES` into ``out_dir``; returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figs = (top_view(scenario, runs), errors_figure(scenario, runs), inputs_figure(scenario, runs),
            rho_figure(runs, rho_tilde, certified), view_3d(scenario, runs), clearance_figure(scenario, runs))
    paths = []
    for name, fig in zip(FIGURE_FILES, figs):
        p = out / name
        fig.savefig(p, dpi=dpi)
        paths.append(p)
    return paths


def envelope_figure(result: EnvelopeResult) -> Figure:
    """omega_bar_xy against target speed at one epsilon: the certified frontier (region under it shaded)
    beside the physical-necessity frontier min(u_max - s, r_max epsilon), with the reference operating
    points (:data:`verify.envelope.REFERENCE_POINTS`) marked: green inside the certified region, red outside,
    white when the point's epsilon is not this envelope's."""
    from verify.envelope import REFERENCE_POINTS  # data only: verify imports no plotting library

    u_max, r_max = result.limits[0], result.limits[2]
    fig = Figure(figsize=(7.6, 5.4), layout="constrained")
    ax = fig.add_subplot()
    s_fine = np.linspace(0.0, u_max, 400)
    need = np.minimum(u_max - s_fine, r_max * result.epsilon)
    ax.plot(s_fine, need, "--", color="k", lw=1.6, zorder=4,
            label=f"necessary: min(u_max - s, r_max eps) = min({u_max:g} - s, {r_max * result.epsilon:.3g})")
    ax.fill_between(s_fine, need, 0.5, color="0.85", label="physically impossible")
    cert = np.nan_to_num(result.certified_omega, nan=0.0)
    ax.fill_between(result.speeds, 0.0, cert, color="tab:green", alpha=0.3, label="certified")
    ax.plot(result.speeds, result.certified_omega, "o-", color="tab:green", ms=4, lw=1.4,
            label="certified frontier (bisection)")
    ax.axhline(result.gamma + result.current_offset, color="tab:gray", ls=":", lw=1,
               label=f"sway gamma_bar = {result.gamma:.3g} m/s (no current)")
    for (name, speed, omega, eps), marker in zip(REFERENCE_POINTS, ("*", "D")):
        same_eps = abs(eps - result.epsilon) < 1e-9
        inside = omega <= np.interp(speed, result.speeds, cert)
        colour = ("tab:green" if inside else "tab:red") if same_eps else "white"
        verdict = ("inside" if inside else "outside") if same_eps else "other eps: not judged here"
        ax.plot([speed], [omega], marker, ms=13 if marker == "*" else 8, mec="k", color=colour,
                label=f"{name}: {speed:g} m/s, {omega:g} m/s at eps {eps:g} m ({verdict})")
    rmin, rmed = result.ratio_min, result.ratio_median
    ratio = "no feasible speed" if rmin is None else f"certified / necessary: min {rmin:.4f}, median {rmed:.4f}"
    ax.set_title(f"{result.scenario_name}, law '{result.law}', eps = {result.epsilon:g} m\n{ratio}", fontsize=10)
    ax.set_xlim(0.0, u_max)
    ax.set_ylim(0.0, max(0.3, 1.15 * float(np.max(need))))
    ax.set_xlabel("horizontal target speed s [m/s]")
    ax.set_ylabel("omega_bar_xy = current amplitude + sway bound [m/s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return fig


def plot_envelope(result: EnvelopeResult, path: str | Path) -> Path:
    """Save :func:`envelope_figure` to ``path`` (PNG/PDF/SVG by extension, 120 dpi); returns the path.

    Raises
    ------
    ConfigError
        When the directory of ``path`` does not exist (field ``--plot``).
    """
    path = Path(path)
    if not path.parent.exists():
        raise ConfigError("--plot", "a file in an existing directory", str(path))
    envelope_figure(result).savefig(path, dpi=120)
    return path
