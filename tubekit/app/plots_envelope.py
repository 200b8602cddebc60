"""The design-envelope figure of ``tubekit envelope --plot`` (:func:`verify.studies.envelope`).

What it draws, every layer named in the legend: the physical-necessity frontier (dashed; above it grey,
impossible for any controller), the certified region (green, under the bisected frontier: dots at the searched
speeds, straight lines between them), what is physically possible but not certified or not searched
(hatched), the scenario's sway bound gamma_bar (the part of omega_bar_xy that is not current: the current a
speed allows is the certified omega_bar_xy minus gamma_bar), the sweep's floor when the scenario has a
constant current (gamma_bar + ||c_xy||: the amplitude is swept from 0, nothing below is searched), and
the scenario's own (target speed, current) point with its verdict, also in the title. A paper's reference point
(:data:`verify.studies.envelope.REFERENCE_POINTS`) is named only when the scenario's own point is that point.

Uses matplotlib's object API (:class:`matplotlib.figure.Figure`, Agg canvas): no pyplot state, no window.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from tubekit.exceptions import ConfigError

if TYPE_CHECKING:  # verify is imported for its type only; plotting needs no certificate code
    from verify.studies.envelope import EnvelopeResult

__all__ = ["envelope_figure", "plot_envelope"]

OMEGA = r"$\bar\omega_{xy}$"
GAMMA = r"$\bar\gamma$"
#: Tolerances (m/s, m/s, m) under which the scenario's point is a reference point of the paper.
REFERENCE_TOL = (5e-3, 1e-6, 1e-9)


def _wrap(text: str, width: int = 80) -> str:
    """``text`` broken into lines of at most ``width`` characters at spaces (labels and title stay readable)."""
    return textwrap.fill(text, width, break_long_words=False, break_on_hyphens=False)


def _has_own_point(result: EnvelopeResult) -> bool:
    """True when the result records the scenario's own point and verdict."""
    own = getattr(result, "own_speed", math.nan)
    return math.isfinite(own) and math.isfinite(result.own_omega) and result.own_certified is not None


def _reference_name(result: EnvelopeResult) -> str | None:
    """The name of the paper's reference point the scenario's own point is (same speed, omega_bar_xy and
    epsilon, both the scenario's and the envelope's), or None."""
    from verify.studies.envelope import REFERENCE_POINTS  # data only: verify imports no plotting library

    if not _has_own_point(result):
        return None
    ds, dw, de = REFERENCE_TOL
    for name, speed, omega, eps in REFERENCE_POINTS:
        if (abs(result.own_speed - speed) <= ds and abs(result.own_omega - omega) <= dw
                and abs(result.own_epsilon - eps) <= de and abs(result.epsilon - eps) <= de):
            return name
    return None


def _own_words(result: EnvelopeResult) -> str:
    """``target 0.377 m/s, current 0.12 m/s`` (and the scenario's epsilon when the envelope's differs)."""
    words = f"target {result.own_speed:.3g} m/s, current {result.own_current:.3g} m/s"
    if abs(result.own_epsilon - result.epsilon) > 1e-12:
        words += f", judged at ε = {result.epsilon:g} m (yours: {result.own_epsilon:g} m)"
    return words


def _physics_note(result: EnvelopeResult) -> str:
    """``; beyond physics: ...`` when the scenario's omega_bar_xy exceeds the necessity frontier at its speed."""
    need = result.limits[0] - result.own_speed
    if result.own_omega <= need + 1e-9:
        return ""
    return f"; beyond physics: any controller needs {OMEGA} ≤ {max(need, 0.0):.3g} m/s here"


def _certified_curve(result: EnvelopeResult, s: np.ndarray) -> np.ndarray:
    """The certified frontier on ``s`` (m/s): straight between the searched speeds, 0 outside them or where
    none certifies."""
    speeds = np.asarray(result.speeds, dtype=float)
    cert = np.nan_to_num(np.asarray(result.certified_omega, dtype=float), nan=0.0)
    inside = (s >= speeds[0] - 1e-12) & (s <= speeds[-1] + 1e-12)
    return np.where(inside, np.interp(s, speeds, cert), 0.0)


def _draw_frontiers(ax: Axes, result: EnvelopeResult, s: np.ndarray, top: float) -> None:
    """Necessity (dashed, grey above), the certified region and frontier, the possible-but-not-certified rest."""
    u_max = result.limits[0]
    need = u_max - s
    ax.plot(s, need, "--", color="k", lw=1.6, zorder=4,
            label=f"necessary for any controller (keep-up): u_max - s = {u_max:g} - s")
    ax.fill_between(s, need, top, color="0.85", label="physically impossible")
    cert = _certified_curve(result, s)
    if np.isfinite(result.certified_omega).any():
        ax.fill_between(s, 0.0, cert, where=cert > 0, interpolate=True, color="tab:green", alpha=0.3,
                        label="certified (under the frontier)")
        ax.plot(result.speeds, result.certified_omega, "o-", color="tab:green", ms=4, lw=1.4,
                label="certified frontier: bisection at the dots, straight between them")
    possible = np.maximum(need, 0.0)
    gap = possible > cert + 1e-12
    if gap.any():
        ax.fill_between(s, cert, possible, where=gap, interpolate=True, facecolor="none", edgecolor="tab:orange",
                        hatch="///", lw=0.0, label="physically possible, not certified (or not searched)")


def _draw_floors(ax: Axes, result: EnvelopeResult) -> None:
    """The sway bound gamma_bar (where the current is zero) and, with a constant current, the sweep's floor."""
    gamma, offset = result.gamma, result.current_offset
    what = (f"sway + velocity-loop error at zero current, {GAMMA} = {gamma:.3g} m/s (derived by the dynamic "
            f"certificate; it grows with the current)" if result.dynamic else
            f"sway bound {GAMMA} = {gamma:.3g} m/s of this scenario (gain u_max r_max + amplitude): "
            f"the current allowed at a speed is the certified {OMEGA} minus {GAMMA}")
    ax.axhline(gamma, color="tab:gray", ls=":", lw=1.2, label=_wrap(what))
    if offset > 1e-12:
        ax.axhline(gamma + offset, color="tab:purple", ls="-.", lw=1.2,
                   label=_wrap(f"{GAMMA} + constant current {offset:.3g} m/s = {gamma + offset:.3g} m/s: the sweep's "
                               "floor (current amplitude 0; not searched below)"))


def _draw_own_point(ax: Axes, result: EnvelopeResult) -> None:
    """The scenario's own (target speed, omega_bar_xy) point, coloured and labelled with its verdict."""
    if not _has_own_point(result):
        return
    ref = _reference_name(result)
    name = "your scenario" + (f" (= the {ref} point)" if ref else "")
    colour = ("tab:green" if result.own_certified else "tab:orange" if result.own_safe else "tab:red")
    ax.plot([result.own_speed], [result.own_omega], "*", ms=16, mec="k", color=colour, zorder=6,
            label=_wrap(f"{name}: {_own_words(result)} ({OMEGA} = {result.own_omega:.3g}): "
                        f"{result.own_verdict()}{_physics_note(result)}"))
    ax.annotate("your scenario", (result.own_speed, result.own_omega), xytext=(-10, 8),
                textcoords="offset points", ha="right", fontsize=8, zorder=6)


def _title(result: EnvelopeResult) -> str:
    """Scenario and law; the headline (the scenario's verdict); the ratio or why nothing certifies."""
    lines = [f"{result.scenario_name}, law '{result.law}', ε = {result.epsilon:g} m: "
             "the current each target speed allows"]
    if _has_own_point(result):
        verdict = result.own_verdict()
        head = next(p for p in ("not certified", "certified", "not recorded") if verdict.startswith(p))
        lines.append(f"your scenario ({_own_words(result)}): {head.upper()}{verdict[len(head):]}"
                     f"{_physics_note(result)}")
    if np.isfinite(result.certified_omega).any():
        rmin, rmed = result.ratio_min, result.ratio_median
        lines.append("no speed is physically feasible" if rmin is None else
                     f"certified / necessary: min {rmin:.4f}, median {rmed:.4f}")
    else:
        fails = sorted({f for f in result.first_failure if f})
        lines.append("nothing certifies at any searched speed, even at current amplitude 0"
                     + (f" (first failure: {', '.join(fails)})" if fails else ""))
    return "\n".join(_wrap(line, 110) for line in lines)


def envelope_figure(result: EnvelopeResult) -> Figure:
    """omega_bar_xy against target speed at one epsilon: the certified region beside the physical-necessity
    frontier u_max - s (keep-up), the scenario's sway bound and the scenario's own point with its
    verdict (module doc: every layer is named in the legend, nothing is left unexplained).

    Parameters
    ----------
    result : EnvelopeResult
        From :func:`verify.studies.envelope.envelope`.

    Returns
    -------
    matplotlib.figure.Figure
        One axes (``fig.axes[0]``) with its legend under the plot.
    """
    u_max, yaw = result.limits[0], result.limits[2] * result.epsilon
    has_own = _has_own_point(result)
    x_top = max(u_max, 1.05 * result.own_speed) if has_own else u_max
    kink = [u_max - yaw] if 0.0 < u_max - yaw < x_top else []
    s = np.unique(np.concatenate([np.linspace(0.0, x_top, 400), np.asarray(result.speeds, dtype=float), kink]))
    heights = [0.3, 1.15 * yaw, 1.15 * (result.gamma + result.current_offset)]
    top = max(heights + ([1.15 * result.own_omega] if has_own else []))
    fig = Figure(figsize=(8.4, 7.6), layout="constrained")
    ax = fig.add_subplot()
    _draw_frontiers(ax, result, s, top)
    _draw_floors(ax, result)
    _draw_own_point(ax, result)
    ax.set_title(_title(result), fontsize=10)
    ax.set_xlim(0.0, x_top)
    ax.set_ylim(0.0, top)
    ax.set_xlabel("horizontal target speed s [m/s]")
    ax.set_ylabel(f"{OMEGA} = horizontal current + sway bound {GAMMA} [m/s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.1), frameon=False)
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
