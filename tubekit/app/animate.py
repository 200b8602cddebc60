"""The top-view animation of ``--animate`` (``tubekit reproduce`` / ``tubekit simulate``).

Frames are drawn on one matplotlib :class:`~matplotlib.figure.Figure` (Agg, no
window): the static scene of :func:`tubekit.plotting.top_view.draw_scene_xy` is rendered
once (layout fixed, background kept), then per frame only the moving artists are
drawn over it (blitting): each run's path so far, its vehicle ball, the sensing
circle R̄, the target p_d(t) and the clock. The frames are written as a GIF
through Pillow (a matplotlib dependency, one shared palette) and, where an
``ffmpeg`` executable exists, also as MP4.
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path
from typing import Sequence

import numpy as np
from matplotlib.animation import FFMpegWriter
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch

from tubekit.scenario import Scenario
from tubekit.plotting.run import Run
from tubekit.plotting.style import run_style
from tubekit.plotting.top_view import draw_scene_xy, fit_canvas

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
    fig = Figure(figsize=(7.0, 7.0), layout="constrained")
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
    clock = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=11,
                    bbox=dict(boxstyle="round", fc="white", alpha=0.8))
    ax.set_title(f"Top view ({scenario.name})")
    fit_canvas(fig, ax, legend_in=0.0, longest_in=5.2)
    width, height = fig.get_size_inches()
    fig.set_size_inches(max(width, 6.4), height + 1.2)  # room for the legend below the axes
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2, fontsize=9, frameon=False)
    return fig, lines, balls, [sensing], target, clock


def _frame_pixels(canvas: FigureCanvasAgg) -> np.ndarray:
    """The canvas as an RGB array (height, width, 3)."""
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def _write_gif(path: Path, frames: list[np.ndarray], fps: int) -> None:
    """Frames (RGB arrays) as a looping GIF, one palette for all (built from the last, fullest frame)."""
    from PIL import Image

    palette = Image.fromarray(frames[-1]).quantize(colors=128, method=Image.Quantize.MEDIANCUT)
    images = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(round(1000 / fps)), loop=0,
                   optimize=False)


def animate_top_view(out_dir: str | Path, scenario: Scenario, runs: Sequence[Run], *, frames: int = 100,
                     fps: int = 10, dpi: int = 72) -> list[Path]:
    """Write the top-view animation into ``out_dir``; returns the files written (GIF, MP4 where possible).

    Parameters
    ----------
    runs : sequence of (label, columns)
        Runs on the same time grid; the first one carries the sensing circle.
    frames, fps, dpi : int
        Number of frames (evenly spaced in simulated time), frames per second, resolution (dots per inch).
    """
    if not runs:
        return []
    fig, lines, balls, (sensing,), target, clock = _build_frame(scenario, runs)
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    moving = [*lines, *balls, sensing, target, clock]
    for artist in moving:
        artist.set_animated(True)
    canvas.draw()  # the layout is computed once, here; the static scene is kept as the background
    fig.set_layout_engine("none")
    background = canvas.copy_from_bbox(fig.bbox)
    t = np.asarray(runs[0][1]["t"], dtype=float)
    pixels = []
    for j in frame_rows(t, frames):
        for (_, c), line, ball in zip(runs, lines, balls):
            k = min(j, len(c["t"]) - 1)
            line.set_data(c["x"][:k + 1], c["y"][:k + 1])
            ball.center = (c["x"][k], c["y"][k])
        sensing.center = balls[0].center
        p_d = np.asarray(scenario.trajectory.position(np.array([t[j]]))).reshape(-1)
        target.set_data([p_d[0]], [p_d[1]])
        clock.set_text(f"t = {t[j]:5.1f} s")
        canvas.restore_region(background)
        for artist in moving:
            fig.draw_artist(artist)
        pixels.append(_frame_pixels(canvas))
    written = [Path(out_dir) / ANIMATION_GIF]
    _write_gif(written[0], pixels, fps)
    if shutil.which("ffmpeg") and FFMpegWriter.isAvailable():
        written.append(_write_mp4(Path(out_dir) / ANIMATION_MP4, pixels, fps))
    LOGGER.debug("wrote %s (%d frames)", ", ".join(map(str, written)), len(pixels))
    return written


def _write_mp4(path: Path, frames: list[np.ndarray], fps: int) -> Path:
    """Frames (RGB arrays) as an MP4 through the ``ffmpeg`` executable (even sizes, yuv420p)."""
    import subprocess

    h, w = (frames[0].shape[0] // 2) * 2, (frames[0].shape[1] // 2) * 2
    cmd = ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}",
           "-r", str(fps), "-i", "-", "-pix_fmt", "yuv420p", str(path)]
    data = b"".join(np.ascontiguousarray(f[:h, :w]).tobytes() for f in frames)
    subprocess.run(cmd, input=data, check=True)
    return path
