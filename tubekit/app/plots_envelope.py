"""The design-envelope figure of ``tubekit envelope --plot`` (:func:`verify.studies.envelope`).

Uses matplotlib's object API (:class:`matplotlib.figure.Figure`, Agg canvas): no pyplot state, no window.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from tubekit.exceptions import ConfigError

if TYPE_CHECKING:  # verify is imported for its type only; plotting needs no certificate code
    from verify.studies.envelope import EnvelopeResult

__all__ = ["envelope_figure", "plot_envelope"]


def envelope_figure(result: EnvelopeResult) -> Figure:
    """omega_bar_xy against target speed at one epsilon: the certified frontier (region under it shaded)
    beside the physical-necessity frontier min(u_max - s, r_max epsilon), with the reference operating
    points (:data:`verify.studies.envelope.REFERENCE_POINTS`) marked: green inside the certified region, red outside,
    white when the point's epsilon is not this envelope's."""
    from verify.studies.envelope import REFERENCE_POINTS  # data only: verify imports no plotting library

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
