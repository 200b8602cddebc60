"""The dynamic plant's panel set of one run: thrust against its limits, the velocity loop's error against its
derived bound E, the hull's sway against its bound γ̄, and the clearance.

The bounds are the run's tightening's (``velocity_loop``, ``disturbance.sway``), labelled "certified" only when
the certificate gives the safe tier, to which these promises belong; the limits are the vehicle's as simulated
(``scenario.plant.truth_params``; a finned vehicle's depend on the surge speed).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.plotting.clearance import draw_clearance
from tubekit.plotting.run import Run
from tubekit.plotting.style import backup_stretches, shade_backup

__all__ = ["thrust_ratios", "draw_thrust", "draw_loop_error", "draw_sway", "dynamic_figure"]

_CHANNELS = (("X", "X / X_max", "tab:blue"), ("Z", "Z / Z_max", "tab:orange"), ("N", "N / N_max", "tab:green"))
_LOOP = (("u", "|u_b - u|", "tab:blue"), ("w", "|w_b - w|", "tab:orange"), ("r", "|r_b - r|", "tab:green"))


def _given(tightening: Tightening | None) -> str:
    return "certified" if tightening is not None and tightening.tiers.safe else "not certified"


def thrust_ratios(scenario: Scenario, columns: Mapping[str, np.ndarray]) -> np.ndarray:
    """Thrust over its limit per channel (X, Z, N), shape (samples, 3); 0 where a limit is 0."""
    truth = scenario.plant.truth_params  # the plant as simulated; fins: limits grow with u² (docs/plant.md)
    u = np.nan_to_num(np.asarray(columns["u_b"], dtype=float))
    limits = np.array([truth.thrust_limits_at(float(v)) for v in u], dtype=float).reshape(-1, 3)
    thrust = np.column_stack([columns[name] for name, _, _ in _CHANNELS]).astype(float)
    return np.divide(thrust, limits, out=np.zeros_like(thrust), where=limits > 0)


def draw_thrust(ax: Axes, scenario: Scenario, columns: Mapping[str, np.ndarray]) -> None:
    """Each channel's thrust over its limit against time, with the limits ±1."""
    ratio = thrust_ratios(scenario, columns)
    for k, (_, label, colour) in enumerate(_CHANNELS):
        ax.plot(columns["t"], ratio[:, k], color=colour, lw=0.9, label=label)
    ax.axhline(1.0, color="tab:red", ls="--", lw=1.0, label="limit")
    ax.axhline(-1.0, color="tab:red", ls="--", lw=1.0)
    ax.set(ylabel="thrust / limit", title="thrust against its limits")


def draw_loop_error(ax: Axes, columns: Mapping[str, np.ndarray], tightening: Tightening | None) -> None:
    """The velocity loop's error per axis, over the derived bound E when the tightening has one (else itself)."""
    bound = None if tightening is None else tightening.velocity_loop
    ratio = bound is not None and all(b > 0 for b in bound)
    for k, (key, label, colour) in enumerate(_LOOP):
        error = np.abs(np.asarray(columns[f"{key}_b"], dtype=float) - np.asarray(columns[key], dtype=float))
        ax.plot(columns["t"], error / bound[k] if ratio else error, color=colour, lw=0.9,
                label=f"{label} / E_{key} (E_{key} = {bound[k]:.3g})" if ratio else label)
    if ratio:
        ax.axhline(1.0, color="tab:red", ls="--", lw=1.0, label=f"derived bound E ({_given(tightening)})")
        ax.set(ylabel="loop error / E", title="velocity-loop error against its bound E")
    else:
        ax.set(ylabel="m/s, rad/s", title="velocity-loop error (no derived bound E: not certified)")


def draw_sway(ax: Axes, columns: Mapping[str, np.ndarray], tightening: Tightening | None) -> None:
    """The hull's sway v_b against ±γ̄ (the tightening's ``disturbance.sway``, when positive)."""
    ax.plot(columns["t"], columns["v_b"], color="tab:purple", lw=1.0, label="sway $v_b$")
    gamma = 0.0 if tightening is None else float(tightening.disturbance.sway)
    if gamma > 0:
        ax.axhline(gamma, color="tab:red", ls="--", lw=1.0,
                   label=rf"$\pm\bar\gamma$ = {gamma:.3g} m/s ({_given(tightening)})")
        ax.axhline(-gamma, color="tab:red", ls="--", lw=1.0)
    ax.set(ylabel="m/s", title="sway against its bound" if gamma > 0 else "sway (no bound)")


def dynamic_figure(scenario: Scenario, run: Run, tightening: Tightening | None = None) -> Figure:
    """The dynamic plant's panel set of one run (module doc): thrust, loop error, sway, clearance, 2 × 2."""
    label, columns = run
    fig = Figure(figsize=(12, 7.5), layout="constrained")
    ax = fig.subplots(2, 2, sharex=True)
    draw_thrust(ax[0, 0], scenario, columns)
    draw_loop_error(ax[0, 1], columns, tightening)
    draw_sway(ax[1, 0], columns, tightening)
    draw_clearance(ax[1, 1], scenario, [run], legend=False)
    ax[1, 1].set_title("clearance (nearest obstacle)")
    stretches = backup_stretches(columns)
    for n, a in enumerate(ax.flat):
        if a is not ax[1, 1]:
            shade_backup(a, stretches, label=n == 0)
        a.grid(alpha=0.3, which="both")
        if a.get_legend_handles_labels()[0]:
            a.legend(fontsize=8, loc="best")
    for a in ax[1]:
        a.set_xlabel("t (s)")
    fig.suptitle(f"{scenario.name}: {label} run on the dynamic plant ({scenario.plant.vehicle})", fontsize=11)
    return fig
