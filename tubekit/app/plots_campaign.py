"""Figures of a campaign (``tubekit campaign``): the ECDF of each metric and the worst runs' tube ratios.

Uses matplotlib's object API (:class:`matplotlib.figure.Figure`, Agg canvas): no pyplot state, no window.
The worst runs sit within 10⁻² of the certified radius 1, so their ratio is drawn as the margin 1 − ratio
on a logarithmic axis, the ticks labelled with the ratio itself (0.99, 0.999, 0.9999, ...).
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator

__all__ = ["ECDF_PANELS", "ecdf_figure", "worst_runs_figure", "ratio_label", "MARGIN_FLOOR"]

#: Per panel: metric key, axis label with its unit, the bound drawn (None: none) and the bound's name.
ECDF_PANELS: tuple[tuple[str, str, str | None, str], ...] = (
    ("max_rho_ratio", "max_rho_ratio: max_j |e_j - e_hat_j| / tube_j (-)", "one", "certified radius 1"),
    ("min_clearance", "min_clearance: ball to obstacle surface (m)", "zero", "contact"),
    ("min_e_d", "min_e_d: smallest distance to the target (m)", "epsilon", "epsilon"),
    ("tracking_rmse", "tracking_rmse (m)", None, ""),
    ("saturated_steps", "saturated_steps (ticks with v clipped to V)", None, ""),
    ("replaced_steps", "replaced_steps (plans replaced, count)", None, ""),
    ("backup_s", "backup_s: time under the backup law (s)", None, ""),
    ("wall_s", "wall_s: wall time of the run (s)", None, ""),
)
#: Smallest margin 1 − ratio (-) drawn on the log axis; a ratio at or above 1 (a broken promise) is drawn there.
MARGIN_FLOOR = 1e-9


def _finite(rows: Sequence[Mapping], key: str) -> np.ndarray:
    x = np.array([float(r[key]) for r in rows if r.get(key) is not None], dtype=float)
    return np.sort(x[np.isfinite(x)])


def ecdf_figure(rows: Sequence[Mapping], epsilon: float) -> Figure:
    """One ECDF per metric of :data:`ECDF_PANELS` (fraction of runs ≤ x), units on every axis, bounds dashed."""
    bounds = {"one": 1.0, "zero": 0.0, "epsilon": float(epsilon)}
    fig = Figure(figsize=(14, 6.5))  # fixed margins: a constrained layout doubles the drawing time
    fig.subplots_adjust(left=0.05, right=0.99, bottom=0.09, top=0.9, wspace=0.3, hspace=0.42)
    for ax, (key, label, bound, name) in zip(fig.subplots(2, 4).ravel(), ECDF_PANELS):
        x = _finite(rows, key)
        ax.step(np.r_[x[:1], x], np.arange(x.size + 1) / max(x.size, 1), where="post", color="C0")
        if bound is not None:
            ax.axvline(bounds[bound], color="C3", ls="--", label=f"{name} ({bounds[bound]:g})")
            ax.legend(loc="lower right", fontsize=8)
        ax.set_xlabel(label, fontsize=8)
        ax.set_ylabel("fraction of runs <= x (-)", fontsize=8)
        ax.set_title(f"{key} ({x.size} runs)", fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle(f"Campaign: empirical distribution of each run's metric ({len(rows)} runs)")
    return fig


def ratio_label(margin: float, _pos: object = None) -> str:
    """The tick label of a margin 1 − ratio: the ratio itself (``1e-4`` → ``0.9999``)."""
    return f"{1.0 - margin:.{max(1, int(round(-np.log10(margin))))}f}" if margin > 0 else "1"


def worst_runs_figure(worst: Sequence[Mapping]) -> Figure:
    """The worst runs' ``max_rho_ratio`` as the margin 1 − ratio on a log axis (ticks read as the ratio);
    a run at or above 1 (a broken tube promise) is drawn red at :data:`MARGIN_FLOOR` and labelled with its ratio."""
    worst = list(worst)[::-1]
    ratios = np.array([float(w["max_rho_ratio"]) for w in worst], dtype=float)
    margin = np.maximum(1.0 - ratios, MARGIN_FLOOR)
    height = 0.35 * len(worst) + 1.8
    fig = Figure(figsize=(8.5, height))
    fig.subplots_adjust(left=0.3, right=0.97, bottom=0.8 / height, top=1 - 0.45 / height)
    ax = fig.subplots()
    colours = ["C3" if (w.get("violated") or r >= 1.0) else "C0" for w, r in zip(worst, ratios)]
    ax.scatter(margin, range(len(worst)), color=colours, zorder=3)
    ax.hlines(range(len(worst)), margin, 1.0, color=colours, lw=2.0, alpha=0.6)
    for i, r in enumerate(ratios):
        ax.annotate(f"{r:.7g}", (margin[i], i), xytext=(-4, 3), textcoords="offset points", ha="right", fontsize=7)
    ax.set_xscale("log")
    low = float(min(np.min(margin), 1e-5)) if len(worst) else 1e-5
    ax.set_xlim(1.0, low / 3.0)  # closer to the certified radius further right
    ax.xaxis.set_major_locator(LogLocator(base=10.0))
    ax.xaxis.set_major_formatter(FuncFormatter(ratio_label))
    ax.set_yticks(range(len(worst)), [f"run {w['run']}  seed {w['seed']}" for w in worst], fontsize=7)
    ax.set_xlabel("max_rho_ratio (-), log scale in the margin 1 - ratio: the certified radius 1 lies to the right")
    ax.set_title("worst runs (replay: tubekit simulate --from-campaign DIR --run K); red: at or above 1", fontsize=9)
    ax.grid(alpha=0.3, axis="x", which="both")
    return fig
