"""The 3-D view at true aspect: the paths, the desired path, the obstacles near the path, the vehicle ball at
the end (the frame is the path's, as the top view's: :func:`tubekit.plotting.framing.obstacles_near`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from tubekit.scenario import Scenario
from tubekit.plotting.framing import NEAR_PATH_M, desired_curve, end_time, obstacles_near
from tubekit.plotting.run import Run
from tubekit.plotting.style import run_style

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d import Axes3D

__all__ = ["view_3d"]


def _sphere(ax: Axes3D, center: Sequence[float], radius: float, **style: object) -> None:
    """A sphere surface of ``radius`` (m) at ``center``."""
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 28), np.linspace(0, np.pi, 14))
    cx, cy, cz = center
    ax.plot_surface(cx + radius * np.cos(uu) * np.sin(vv), cy + radius * np.sin(uu) * np.sin(vv),
                    cz + radius * np.cos(vv), linewidth=0, antialiased=True, shade=True, **style)


def _finite(points: np.ndarray) -> np.ndarray:
    """The rows of ``points`` without a NaN or an infinity."""
    return points[np.all(np.isfinite(points), axis=1)]


def view_3d(scenario: Scenario, runs: Sequence[Run]) -> Figure:
    """3-D view at true aspect: path(s), desired trajectory, the obstacle spheres near the path, the vehicle ball
    at each run's end."""
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the projection)

    fig = Figure(figsize=(8.4, 5.6), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    pd = desired_curve(scenario, end_time(scenario, runs))
    ax.plot(pd[:, 0], pd[:, 1], pd[:, 2], "--", color="tab:green", lw=1.0, label="desired $p_d(t)$")
    points = [pd]
    for i, (label, c) in enumerate(runs):
        ax.plot(c["x"], c["y"], c["z"], label=label, **run_style(i))
        end = (float(c["x"][-1]), float(c["y"][-1]), float(c["z"][-1]))
        _sphere(ax, end, scenario.vehicle_radius, color=run_style(i).get("color"), alpha=0.35,
                label=rf"{label}: vehicle ball $\bar r$ at the end")
        points.append(np.column_stack([c["x"], c["y"], c["z"]]).astype(float))
    path = _finite(np.vstack(points))
    for _, c in runs:  # the balls at the end, in the frame (and a flat path keeps a height)
        end = np.array([c["x"][-1], c["y"][-1], c["z"][-1]], dtype=float)
        points.append(end + np.array([[-1, -1, -1], [1, 1, 1]]) * scenario.vehicle_radius)
    lo, hi = path.min(axis=0), path.max(axis=0)
    near = obstacles_near(scenario, lo[:2], hi[:2], max(float(np.max(hi[:2] - lo[:2])), NEAR_PATH_M))
    for n, k in enumerate(near):
        o = scenario.obstacles[k]
        _sphere(ax, o.center, o.radius, color="0.45", alpha=0.55, label="obstacle" if n == 0 else None)
        points.append(np.asarray(o.center) + np.array([[-1, -1, -1], [1, 1, 1]]) * o.radius)
    allp = _finite(np.vstack(points))
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(np.maximum(hi - lo, 1e-3))
    ax.zaxis.set_major_locator(MaxNLocator(3))
    ax.yaxis.set_major_locator(MaxNLocator(5))
    ax.view_init(elev=35, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    away = len(scenario.obstacles) - len(near)
    ax.set_title("3-D view, true aspect (equal scale on x, y and z)"
                 + (f"\n{away} obstacle{'s' if away > 1 else ''} far from the path not drawn" if away else ""))
    ax.legend(fontsize=8, loc="upper left")
    return fig
