"""The top view's frame: a zoom on the path, the obstacles near it, the sensing range only when it fits.

A scenario's scales differ by orders of magnitude (a 2 m path, obstacles 17 m away, a 15 m sensing range): the
frame is the box of what the vehicle and the target did (the desired path over the run, every run's path, the
start), grown to the obstacles within one path-width of it and by a margin; the sensing circles are drawn only
when their diameter fits in that frame (else the frame would be a blob in a circle).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from tubekit.scenario import Scenario
from tubekit.plotting.run import Run

__all__ = ["Frame", "frame_of", "end_time", "desired_curve", "obstacles_near", "NEAR_PATH_M"]

#: Smallest distance (m) from the path's box within which an obstacle is drawn (a short path still shows its
#: neighbours; a path of width w shows the obstacles within w of it).
NEAR_PATH_M = 1.0


@dataclass(frozen=True)
class Frame:
    """The limits of a top view and what is drawn in it.

    Attributes
    ----------
    x, y : tuple of float
        Axis limits (m).
    obstacles : tuple of int
        Indices (in ``scenario.obstacles``) of the obstacles in view.
    sensing : bool
        The sensing circles fit in the frame (drawn); else the sensing range is only named.
    """

    x: tuple[float, float]
    y: tuple[float, float]
    obstacles: tuple[int, ...]
    sensing: bool

    @property
    def width(self) -> float:
        """Width (m) of the frame."""
        return self.x[1] - self.x[0]

    @property
    def height(self) -> float:
        """Height (m) of the frame."""
        return self.y[1] - self.y[0]


def end_time(scenario: Scenario, runs: Sequence[Run]) -> float:
    """The last logged time (s) of the first run; the scenario's duration without a run."""
    return float(runs[0][1]["t"][-1]) if runs else float(scenario.duration)


def desired_curve(scenario: Scenario, t_end: float, samples: int = 2000) -> np.ndarray:
    """The desired position p_d(t) (m) over [0, ``t_end``], shape (samples, 3)."""
    return np.asarray(scenario.trajectory.position(np.linspace(0.0, t_end, samples)), dtype=float)


def _path_box(scenario: Scenario, runs: Sequence[Run], t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corner (x, y; m) of the desired path over the run, every run's path and the start."""
    parts = [desired_curve(scenario, t_end)[:, :2], np.asarray(scenario.initial_state, dtype=float)[None, :2]]
    parts += [np.column_stack([c["x"], c["y"]]).astype(float) for _, c in runs]
    points = np.vstack(parts)
    points = points[np.all(np.isfinite(points), axis=1)]
    return points.min(axis=0), points.max(axis=0)


def obstacles_near(scenario: Scenario, lo: np.ndarray, hi: np.ndarray, reach: float) -> tuple[int, ...]:
    """Indices of the obstacles whose r̄-inflated disc comes within ``reach`` (m) of the box [lo, hi] (x, y)."""
    near = []
    for k, o in enumerate(scenario.obstacles):
        centre = np.asarray(o.center, dtype=float)[:2]
        outside = np.maximum(np.maximum(lo - centre, centre - hi), 0.0)
        if float(np.linalg.norm(outside)) - o.radius - scenario.vehicle_radius <= reach:
            near.append(k)
    return tuple(near)


def frame_of(scenario: Scenario, runs: Sequence[Run], *, tube_half: float = 0.0) -> Frame:
    """The frame of a top view of ``runs``: the path's box, the obstacles near it, a margin, the sensing circles
    when they fit (module doc). ``tube_half`` (m): the position tube's half-width, kept inside the margin."""
    lo, hi = _path_box(scenario, runs, end_time(scenario, runs))
    reach = max(float(np.max(hi - lo)), NEAR_PATH_M)
    near = obstacles_near(scenario, lo, hi, reach)
    for k in near:
        o = scenario.obstacles[k]
        centre, r = np.asarray(o.center, dtype=float)[:2], o.radius + scenario.vehicle_radius
        lo, hi = np.minimum(lo, centre - r), np.maximum(hi, centre + r)
    pad = max(0.06 * float(np.max(hi - lo)), tube_half + scenario.vehicle_radius, 0.2)
    lo, hi = lo - pad, hi + pad
    reach_r = float(scenario.sensing_range)
    sensing = bool(runs) and 2.0 * reach_r <= float(np.max(hi - lo))
    if sensing:
        c = runs[0][1]
        xy = np.column_stack([c["x"], c["y"]]).astype(float)
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        lo, hi = np.minimum(lo, xy.min(axis=0) - reach_r), np.maximum(hi, xy.max(axis=0) + reach_r)
    return Frame(x=(float(lo[0]), float(hi[0])), y=(float(lo[1]), float(hi[1])), obstacles=near, sensing=sensing)
