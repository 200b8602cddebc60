"""The top-view animation of ``--animate`` (``tubekit reproduce`` / ``tubekit simulate``).

Frames are drawn on one matplotlib :class:`~matplotlib.figure.Figure` (Agg, no
window): the static scene of :func:`tubekit.app.plots.draw_scene_xy`, then per
frame each run's path so far, its vehicle ball, the sensing circle R̄ and the
target p_d(t). Written as a GIF through Pillow (a matplotlib dependency) and,
where an ``ffmpeg`` executable exists, also as MP4.
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path
from typing import Sequence

import numpy as np
from matplotlib.animation import FFMpegWriter, PillowWriter
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch

from tubekit.scenario import Scenario
from tubekit.app.plots import Run, draw_scene_xy, fit_canvas, run_style

__all__ = ["animate_top_view", "ANIMATION_GIF", "ANIMATION_MP4", "frame_rows"]

#: File names written by :func:`animate_top_view` (the MP4 only where ffmpeg exists).
ANIMATION_GIF = "top_view.gif"
ANIMATION_MP4 = "top_view.mp4"

LOGGER = logging.getLogger(__name__)


def frame_rows(t: np.ndarray, frames: int) -> np.ndarray:
    """Row indices of ``frames`` samples evenly spaced in time from the first to the last."""
    t = np.asarray(t, dtype=float)
    return np.unique(np.searchsorted(t, np.linspace(t[0], t[-1], max(frames, 2)) - 1e-9).clip(0, len(t) - 1))


def _build_frame(scenario: Scenario, runs: Sequence[Run]) -> tuple[Figure, list, list, list, object, object]:
    """The figure and its moving artists: per run a path line and a vehicle ball; sensing circle; target; clock."""
    fig = Figure(figsize=(8.0, 6.0), layout="constrained")
    ax = fig.add_subplot()
    t_end = float(runs[0][1]["t"][-1])
    draw_scene_xy(ax, scenario, t_end, start_target=False)
    reach = scenario.sensing_range
    for _, c in runs:  # the full extent (sensing circles included), so the view does not jump
        ax.plot([np.nanmin(c["x"]) - reach, np.nanmax(c["x"]) + reach],
                [np.nanmin(c["y"]) - reach, np.nanmax(c["y"]) + reach], alpha=0.0)
    lines, balls = [], []
    for i, (label, _) in enumerate(runs):
        style = run_style(i)
        (line,) = ax.plot([], [], label=label, **style)
        ball = CirclePatch((np.nan, np.nan), scenario.vehicle_radius, color=style.get("color"), alpha=0.5)
        ax.add_patch(ball)
        lines.append(line)
        balls.append(ball)
    sensing = CirclePatch((np.nan, np.nan), scenario.sensing_range, fill=False, ls="--", lw=0.8,
                          color="tab:purple", label=rf"sensing range $\bar R$ ({runs[0][0]})")
    ax.add_patch(sensing)
    (target,) = ax.plot([], [], "*", color="tab:green", ms=11, mec="k", mew=0.5, label="target $p_d(t)$")
    clock = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=10,
                    bbox=dict(boxstyle="round", fc="white", alpha=0.8))
    ax.set_title(f"Top view ({scenario.name})")
    fit_canvas(fig, ax, legend_in=2.4, longest_in=5.5)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7)
    return fig, lines, balls, [sensing], target, clock


def animate_top_view(out_dir: str | Path, scenario: Scenario, runs: Sequence[Run], *, frames: int = 120,
                     fps: int = 12, dpi: int = 80) -> list[Path]:
    """Write the top-view animation into ``out_dir``; returns the files written (GIF, MP4 where possible).

    Parameters
    ----------
    runs : sequence of (label, columns)
        Runs on the same time grid; the first one carries the sensing circle.
    frames, fps : int
        Number of frames (evenly spaced in simulated time) and frames per second.
    """
    if not runs:
        return []
    fig, lines, balls, (sensing,), target, clock = _build_frame(scenario, runs)
    t = np.asarray(runs[0][1]["t"], dtype=float)
    rows = frame_rows(t, frames)
    writers: list[tuple[Path, object]] = [(Path(out_dir) / ANIMATION_GIF, PillowWriter(fps=fps))]
    if shutil.which("ffmpeg") and FFMpegWriter.isAvailable():
        writers.append((Path(out_dir) / ANIMATION_MP4, FFMpegWriter(fps=fps)))
    written = []
    for path, writer in writers:
        with writer.saving(fig, str(path), dpi):
            for j in rows:
                for (_, c), line, ball in zip(runs, lines, balls):
                    k = min(j, len(c["t"]) - 1)
                    line.set_data(c["x"][:k + 1], c["y"][:k + 1])
                    ball.center = (c["x"][k], c["y"][k])
                sensing.center = balls[0].center
                p_d = np.asarray(scenario.trajectory.position(np.array([t[j]]))).reshape(-1)
                target.set_data([p_d[0]], [p_d[1]])
                clock.set_text(f"t = {t[j]:5.1f} s")
                writer.grab_frame()
        written.append(path)
        LOGGER.debug("wrote %s (%d frames)", path, len(rows))
    return written
