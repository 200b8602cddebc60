"""The deviation from the nominal against the tube box: per axis, |e_j − ê_j| / tube_j, what the ``tube`` promise
checks (max over the axes <= 1, while a plan is followed)."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from tubekit.plotting.run import Run
from tubekit.plotting.style import backup_stretches, run_style, shade_backup

__all__ = ["rho_figure"]

_AXES = (("rho_d", "e_d", "m"), ("rho_z", "e_z", "m"), ("rho_o", "e_o", "-"))


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
    there is no tube (``tube`` None or not positive). Ticks under the backup law are left out (grey).
    ``certified``: the certificate gives the tracking tier, to which the tube belongs."""
    fig = Figure(figsize=(8.0, 5.4), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    box = None if tube is None else np.asarray(tube, dtype=float)
    ratio = box is not None and bool(np.all(box > 0))
    worst = []
    if runs:
        label, c = runs[0]
        following = np.asarray(c.get("backup_active", np.zeros(len(c["t"]))), dtype=float) < 0.5
        for j, (ax, (key, name, unit)) in enumerate(zip(axes, _AXES)):
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
