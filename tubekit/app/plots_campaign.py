"""Figures of a campaign (``tubekit campaign``): the ECDF of each metric and the worst runs' tube ratios.

Uses matplotlib's object API (:class:`matplotlib.figure.Figure`, Agg canvas): no pyplot state, no window.
The worst runs sit within 10⁻² of the certified radius 1, so their ratio is drawn as the margin 1 − ratio
on a logarithmic axis, the ticks labelled with the ratio itself (0.99, 0.999, 0.9999, ...).

Every figure is drawn whatever the campaign holds: a metric with no finite value in any run (the tube
ratio of a campaign whose certificates have no tube, σ = 0; every run failed) gets a panel that says so
instead of a curve. The tiers each run's certificate gives (:func:`tier_of`: both, the safe tier only, none)
are named in the titles, and the uncertified runs are marked on every curve (they claim nothing). This
module also owns that reading of a row's tiers (:data:`TIERS`, :func:`tier_of`, :func:`tier_counts`), which
``summary.json`` counts (:mod:`tubekit.app.campaign_summary`); matplotlib is imported only when drawing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["ECDF_PANELS", "ecdf_figure", "worst_runs_figure", "ratio_label", "MARGIN_FLOOR", "TIERS",
           "TIER_LABELS", "tier_of", "tier_counts", "empty_reason", "uncertified_runs"]

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
#: The tiers a run's certificate can give, in the order they are reported (``summary.json``'s ``runs_by_tier``).
TIERS = ("both", "safe_only", "none")
#: Each tier as the figures name it.
TIER_LABELS = {"both": "both tiers", "safe_only": "safe tier only", "none": "uncertified"}
#: Uncertified runs named in a title before "+N more".
NAMED_RUNS = 8


def tier_of(row: Mapping) -> str:
    """The tiers ``row``'s certificate gives: ``"both"`` (safe and tracking), ``"safe_only"`` or ``"none"``.

    Reads the row's ``safe_tier`` and ``tracking_tier`` (a row without them: its ``certified``). The tracking
    tier's conditions include the safe tier's, so a run with the tracking tier has the safe tier too.
    """
    safe = bool(row.get("safe_tier", row.get("certified")))
    tracking = bool(row.get("tracking_tier", row.get("certified")))
    return "both" if safe and tracking else "safe_only" if safe else "none"


def tier_counts(rows: Sequence[Mapping]) -> dict[str, int]:
    """Runs per tier, every key of :data:`TIERS` present (0 when none)."""
    counts = dict.fromkeys(TIERS, 0)
    for row in rows:
        counts[tier_of(row)] += 1
    return counts


def uncertified_runs(rows: Sequence[Mapping]) -> list[int]:
    """The run numbers of ``rows`` whose certificate gives no tier (they claim nothing)."""
    return [int(r["run"]) for r in rows if tier_of(r) == "none" and r.get("run") is not None]


def _values(rows: Sequence[Mapping], key: str) -> np.ndarray:
    """``key``'s value per row (NaN where null)."""
    return np.array([np.nan if r.get(key) is None else float(r[key]) for r in rows], dtype=float)


def _finite(rows: Sequence[Mapping], key: str) -> np.ndarray:
    x = _values(rows, key)
    return np.sort(x[np.isfinite(x)])


def empty_reason(rows: Sequence[Mapping], key: str) -> str:
    """Why ``key`` has no finite value in ``rows`` (the text of its empty panel)."""
    if not rows:
        return "no runs: nothing to plot"
    failed = sum(bool(r.get("error")) for r in rows)
    if failed == len(rows):
        return f"every run failed ({failed}, see their error): nothing to plot"
    tail = f"\n({failed} runs failed)" if failed else ""
    if key == "max_rho_ratio":
        return "no tube: σ = 0 (tube 0) in every run's\ncertificate, nothing to plot" + tail
    return f"no finite value in any run: nothing to plot{tail}"


def _tier_text(rows: Sequence[Mapping]) -> str:
    """``"4 runs: 0 both tiers, 4 safe tier only, 0 uncertified"`` plus the uncertified runs' numbers."""
    counts = tier_counts(rows)
    text = f"{len(rows)} runs: " + ", ".join(f"{counts[t]} {TIER_LABELS[t]}" for t in TIERS)
    named = uncertified_runs(rows)
    if named:
        more = f" +{len(named) - NAMED_RUNS} more" if len(named) > NAMED_RUNS else ""
        text += f" (runs {', '.join(map(str, named[:NAMED_RUNS]))}{more}: they claim nothing)"
    return text


def _empty_panel(ax: Axes, text: str) -> None:
    """An axis holding only ``text`` in its middle (no ticks, no offset to overprint the label)."""
    ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=8, color="0.3", transform=ax.transAxes, wrap=True)
    ax.set_xticks([])
    ax.set_yticks([])


def _ecdf_panel(ax: Axes, rows: Sequence[Mapping], key: str, bound: float | None, name: str) -> int:
    """The ECDF of ``key`` on ``ax`` (uncertified runs marked, the bound dashed); the number of values drawn."""
    from matplotlib.ticker import MaxNLocator

    values = _values(rows, key)
    finite = np.isfinite(values)
    x = np.sort(values[finite])
    if not x.size:
        _empty_panel(ax, empty_reason(rows, key))
        return 0
    y = np.arange(1, x.size + 1) / x.size
    ax.step(np.r_[x[:1], x], np.r_[0.0, y], where="post", color="C0", label="all runs")
    none = np.array([tier_of(r) == "none" for r in rows], dtype=bool) & finite
    if none.any():  # each uncertified run at its place on the curve
        at = np.searchsorted(x, values[none], side="right") / x.size
        ax.plot(values[none], at, "x", color="C1", ms=5, label=f"uncertified ({int(none.sum())})")
    if bound is not None:
        ax.axvline(bound, color="C3", ls="--", label=f"{name} ({bound:g})")
    if bound is not None or none.any():
        ax.legend(loc="lower right", fontsize=7)
    ax.ticklabel_format(axis="x", useOffset=False, style="plain")  # no offset text over the axis label
    ax.tick_params(axis="x", labelsize=7)
    ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
    ax.set_ylabel("fraction of runs <= x (-)", fontsize=8)
    ax.grid(alpha=0.3)
    return int(x.size)


def ecdf_figure(rows: Sequence[Mapping], epsilon: float) -> Figure:
    """One ECDF per metric of :data:`ECDF_PANELS` (fraction of runs ≤ x), units on every axis, bounds dashed.

    Parameters
    ----------
    rows : sequence of mapping
        The campaign's rows (``runs/*.json``); a null value (no tube, a failed run) is left out of its curve.
    epsilon : float
        The scenario's ε (m), drawn on the ``min_e_d`` panel.

    Returns
    -------
    Figure
        2 x 4 panels; a metric without any finite value gets a panel saying why (:func:`empty_reason`).
        The title gives the runs per tier and names the uncertified runs, marked x on every curve.
    """
    from matplotlib.figure import Figure

    bounds = {"one": 1.0, "zero": 0.0, "epsilon": float(epsilon)}
    tracking = tier_counts(rows)["both"]
    names = {"one": f"certified radius 1, {tracking} runs" if tracking else "radius 1: no run has the tracking tier"}
    fig = Figure(figsize=(14, 6.8))  # fixed margins: a constrained layout doubles the drawing time
    fig.subplots_adjust(left=0.05, right=0.99, bottom=0.09, top=0.86, wspace=0.3, hspace=0.5)
    for ax, (key, label, bound, name) in zip(fig.subplots(2, 4).ravel(), ECDF_PANELS):
        drawn = _ecdf_panel(ax, rows, key, None if bound is None else bounds[bound], names.get(bound, name))
        ax.set_xlabel(label, fontsize=8)
        missing = len(rows) - drawn
        ax.set_title(f"{key} ({drawn} runs" + (f"; {missing} without a value)" if missing and drawn else ")"),
                     fontsize=9)
    fig.suptitle(f"Campaign: empirical distribution of each run's metric\n{_tier_text(rows)}", fontsize=11)
    return fig


def ratio_label(margin: float, _pos: object = None) -> str:
    """The tick label of a margin 1 − ratio: the ratio itself (``1e-4`` → ``0.9999``)."""
    return f"{1.0 - margin:.{max(1, int(round(-np.log10(margin))))}f}" if margin > 0 else "1"


def _run_label(run: Mapping) -> str:
    tier = tier_of(run) if any(k in run for k in ("safe_tier", "tracking_tier", "certified")) else None
    return f"run {run['run']}  seed {run['seed']}" + (f"\n{TIER_LABELS[tier]}" if tier else "")


def worst_runs_figure(worst: Sequence[Mapping], empty: str = "") -> Figure:
    """The worst runs' ``max_rho_ratio`` as the margin 1 − ratio on a log axis (ticks read as the ratio).

    Parameters
    ----------
    worst : sequence of mapping
        The runs, worst first, each with ``run``, ``seed``, ``max_rho_ratio`` (and its tiers, named in its label).
    empty : str, optional
        What to say when ``worst`` is empty (default: no run has a tube ratio).

    Returns
    -------
    Figure
        A run at or above 1 (a broken tube promise) is drawn red at :data:`MARGIN_FLOOR`, labelled with its
        ratio; with no run, one panel saying why.
    """
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, LogLocator

    worst = list(worst)[::-1]
    height = 0.35 * len(worst) + 1.8 if worst else 2.4
    fig = Figure(figsize=(8.5, height))
    left = 0.3 if worst else 0.05
    fig.subplots_adjust(left=left, right=0.97, bottom=0.8 / height, top=1 - 0.45 / height)
    ax = fig.subplots()
    ax.set_title("worst runs (replay: tubekit simulate --from-campaign DIR --run K); red: at or above 1", fontsize=9)
    if not worst:
        _empty_panel(ax, empty or "no run has a tube ratio (no tube: σ = 0): nothing to plot")
        ax.set_xlabel("max_rho_ratio (-)", fontsize=9)
        return fig
    ratios = np.array([float(w["max_rho_ratio"]) for w in worst], dtype=float)
    margin = np.maximum(1.0 - ratios, MARGIN_FLOOR)
    colours = ["C3" if (w.get("violated") or r >= 1.0) else "C0" for w, r in zip(worst, ratios)]
    ax.scatter(margin, range(len(worst)), color=colours, zorder=3)
    ax.hlines(range(len(worst)), margin, 1.0, color=colours, lw=2.0, alpha=0.6)
    for i, r in enumerate(ratios):
        ax.annotate(f"{r:.7g}", (margin[i], i), xytext=(-4, 3), textcoords="offset points", ha="right", fontsize=7)
    ax.set_xscale("log")
    ax.set_xlim(1.0, float(min(np.min(margin), 1e-5)) / 3.0)  # closer to the certified radius further right
    ax.xaxis.set_major_locator(LogLocator(base=10.0))
    ax.xaxis.set_major_formatter(FuncFormatter(ratio_label))
    ax.set_yticks(range(len(worst)), [_run_label(w) for w in worst], fontsize=7)
    ax.set_xlabel("max_rho_ratio (-), log scale in the margin 1 - ratio: the certified radius 1 lies to the right")
    ax.grid(alpha=0.3, axis="x", which="both")
    return fig
