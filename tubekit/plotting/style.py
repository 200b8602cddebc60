"""The look shared by every figure of a run: run styles, the backup's shading, time ticks, distances as text."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes

__all__ = ["run_style", "LEGEND_OUTSIDE", "backup_stretches", "shade_backup", "tick_interval", "tick_rows",
           "distance_text"]

_STYLE = {0: dict(color="tab:blue", lw=1.4), 1: dict(color="tab:orange", lw=1.0, alpha=0.85)}
#: A legend to the right of its axes, outside them.
LEGEND_OUTSIDE = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8)


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


def shade_backup(ax: Axes, stretches: Sequence[tuple[float, float]], *, label: bool = True) -> None:
    """Shade the backup-active stretches (grey) on a time axis; one legend entry when ``label``."""
    for n, (a, b) in enumerate(stretches):
        ax.axvspan(a, b, color="0.5", alpha=0.18, lw=0, zorder=0,
                   label="backup law active (station keeping)" if label and n == 0 else None)


def tick_interval(t_end: float, ticks: int = 8) -> float:
    """A round time step (s) giving at most about ``ticks`` marks over ``t_end`` seconds."""
    for step in (0.5, 1, 2, 5, 10, 20, 25, 50, 100, 200, 500, 1000):
        if t_end / step <= ticks:
            return float(step)
    return float(10 ** np.ceil(np.log10(max(t_end, 1.0) / ticks)))


def tick_rows(t: np.ndarray, every_s: float) -> np.ndarray:
    """Row indices of the first samples at or after each multiple of ``every_s`` (s), t = 0 excluded."""
    marks = np.arange(every_s, float(t[-1]) + 1e-9, every_s)
    return np.unique(np.searchsorted(t, marks - 1e-9))


def distance_text(metres: float) -> str:
    """A signed distance at a readable scale: ``+4.2 mm`` below a metre, ``+15.48 m`` from a metre up."""
    if not np.isfinite(metres):
        return "none"
    return f"{1e3 * metres:+.1f} mm" if abs(metres) < 1.0 else f"{metres:+.2f} m"
