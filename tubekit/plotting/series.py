"""Figs. 3 and 4 of the paper, against time: the tracking errors (with ε) and the inputs (with V and V̄)."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.plotting.run import Run
from tubekit.plotting.style import LEGEND_OUTSIDE, backup_stretches, run_style, shade_backup

__all__ = ["draw_errors", "errors_figure", "period_envelope", "draw_inputs", "inputs_figure"]

_ERRORS = (("e_d", "$e_d$ (m)"), ("e_z", "$e_z$ (m)"), ("e_o", "$e_o$ (-)"))
_INPUTS = (("u", "u (m/s)"), ("w", "w (m/s)"), ("r", "r (rad/s)"))


def draw_errors(axes: Sequence[Axes], scenario: Scenario, runs: Sequence[Run], *, legend: bool = True) -> None:
    """e_d (log scale, with ε), e_z, e_o of every run on three axes; the first run's backup stretches shaded."""
    for ax, (key, lab) in zip(axes, _ERRORS):
        for i, (label, c) in enumerate(runs):
            ax.plot(c["t"], c[key], label=label, **run_style(i))
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
        shade_backup(ax, backup_stretches(runs[0][1]) if runs else [], label=ax is axes[0])
    axes[0].axhline(scenario.epsilon, color="tab:red", ls="--", lw=1.0, label=rf"$\epsilon$ = {scenario.epsilon:g} m")
    axes[0].set_yscale("log")
    if legend:
        axes[0].legend(fontsize=8)


def errors_figure(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """Fig. 3: e_d, e_z, e_o against time, with ε on e_d."""
    fig = Figure(figsize=(7.5, 6.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    draw_errors(axes, scenario, runs)
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


def _bounds(ax: Axes, bound: float, tight: float | None, low: float | None = None,
            tight_low: float | None = None) -> None:
    """V's corners on one axis (``bound`` and ``low``, None: −``bound``), and V̄'s (``tight``, ``tight_low``, None:
    −``tight``) where tightened (else a note on the axes: no legend entry without a line); units of the axis."""
    low = -bound if low is None else low
    ax.axhline(bound, color="tab:red", ls="--", lw=1.0, label=r"bound of $V$")
    ax.axhline(low, color="tab:red", ls="--", lw=1.0)
    if tight is not None:
        tight_low = -tight if tight_low is None else tight_low
    if tight is not None and (tight < bound - 1e-12 or tight_low > low + 1e-12):
        ax.axhline(tight, color="tab:purple", ls=":", lw=1.2, label=r"bound of $\bar V$ (tightened, for $\hat v$)")
        ax.axhline(tight_low, color="tab:purple", ls=":", lw=1.2)
    elif tight is not None:
        ax.text(0.99, 0.985, r"$\bar V = V$ on this axis (no tightening)", transform=ax.transAxes, ha="right",
                va="top", fontsize=7, color="tab:purple")  # in the band above the bound (ylim ±1.3 V)


def draw_inputs(axes: Sequence[Axes], scenario: Scenario, runs: Sequence[Run], *,
                tightening: Tightening | None = None, legend: bool = True) -> None:
    """Per axis (u, w, r): v̂ as a line, the per-period min/max envelope of the applied v, the bounds of V and V̄."""
    tight = None if tightening is None else np.asarray(tightening.v_max, dtype=float)
    tight_low = None if tightening is None else tightening.v_low
    lows = scenario.limits.lower  # V's lower corner: −V but for a surge floor (limits.u_min)
    for n, (ax, (key, lab), b) in enumerate(zip(axes, _INPUTS, scenario.limits.vector)):
        for i, (label, c) in enumerate(runs):
            colour = run_style(i).get("color")
            t_edges, lo, hi = period_envelope(c, key)
            ax.fill_between(t_edges, lo, hi, step="post", color=colour, alpha=0.25 if i == 0 else 0.15, lw=0,
                            label=f"{label}: applied v, min-max per period")
            ax.plot(c["t"], c[f"{key}_hat"], drawstyle="steps-post", color=colour, lw=1.2 if i == 0 else 0.9,
                    label=rf"{label}: $\hat v$ (FHOCP)")
        _bounds(ax, float(b), None if tight is None else float(tight[n]), float(lows[n]),
                None if tight_low is None else float(tight_low[n]))
        ax.set_ylim(-1.3 * b, 1.3 * b)
        shade_backup(ax, backup_stretches(runs[0][1]) if runs else [], label=n == 0)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    if legend:
        axes[0].legend(**LEGEND_OUTSIDE)


def inputs_figure(scenario: Scenario, runs: Sequence[Run], *, tightening: Tightening | None = None) -> Figure:
    """Fig. 4: per axis, v̂ as a line, the per-period min/max envelope of the applied v, bounds of V and V̄."""
    fig = Figure(figsize=(8.8, 6.8), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    draw_inputs(axes, scenario, runs, tightening=tightening)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(r"Control inputs: nominal $\hat v$ and applied $v = \hat v + \kappa$")
    return fig
