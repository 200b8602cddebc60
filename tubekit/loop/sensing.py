"""On-board sensing: which obstacles the FHOCP knows about.

Rule (the paper, Section III-B: the vehicle perceives the workspace inside the
sensing ball B(eta_1, R-bar)): an obstacle B(c, r_o) is *detected* at a
position p when the sensing ball touches it, i.e. when its **surface** is
within R-bar of the vehicle centre::

    ||p - c|| - r_o <= R-bar        (3-D Euclidean distance, m)

The vehicle radius r-bar does not enter the rule: R-bar is measured from the
vehicle centre, as B(eta_1, R-bar) in the paper. Obstacles are static, so once
detected an obstacle stays in the vehicle's map (:class:`ObstacleMap`); the
closed loop hands the FHOCP the map, never an undetected obstacle.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from tubekit.scenario import Obstacle
from tubekit.validation import as_vector, positive

__all__ = ["surface_distance", "detected_mask", "detected_obstacles", "ObstacleMap"]


def surface_distance(position: np.ndarray, obstacles: Sequence[Obstacle]) -> np.ndarray:
    """Distance (m) from ``position`` (3,) to each obstacle's surface, shape (M,).

    Negative when the point is inside an obstacle.
    """
    p = as_vector("position", np.asarray(position, dtype=float)[:3], 3)
    if len(obstacles) == 0:
        return np.zeros(0)
    centers = np.array([o.center for o in obstacles], dtype=float)
    radii = np.array([o.radius for o in obstacles], dtype=float)
    return np.linalg.norm(centers - p, axis=1) - radii


def detected_mask(position: np.ndarray, obstacles: Sequence[Obstacle], sensing_range: float) -> np.ndarray:
    """Boolean mask (M,): obstacle surface within ``sensing_range`` (m) of ``position``."""
    rng = positive("sensing_range", sensing_range)
    return surface_distance(position, obstacles) <= rng


def detected_obstacles(position: np.ndarray, obstacles: Sequence[Obstacle],
                       sensing_range: float) -> tuple[Obstacle, ...]:
    """The obstacles whose surface is within ``sensing_range`` (m) of ``position`` (3,) or (4,).

    Parameters
    ----------
    position : array (3,) or (4,)
        Vehicle centre [x, y, z] (m); a full state [x, y, z, psi] is accepted.
    obstacles : sequence of Obstacle
        All obstacles of the workspace.
    sensing_range : float
        R-bar (m), measured from the vehicle centre.

    Returns
    -------
    tuple of Obstacle
        The detected obstacles, in the input order.
    """
    mask = detected_mask(position, obstacles, sensing_range)
    return tuple(o for o, m in zip(obstacles, mask) if m)


@dataclass
class ObstacleMap:
    """The vehicle's memory of detected (static) obstacles.

    Parameters
    ----------
    obstacles : sequence of Obstacle
        Every obstacle in the workspace (ground truth, unknown to the controller).
    sensing_range : float
        R-bar (m).
    remember : bool
        Keep an obstacle once detected (default). ``False`` gives the
        memoryless rule: only what is inside R-bar right now.
    """

    obstacles: Sequence[Obstacle]
    sensing_range: float
    remember: bool = True
    known: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.obstacles = tuple(self.obstacles)
        self.sensing_range = positive("sensing_range", self.sensing_range)
        self.known = np.zeros(len(self.obstacles), dtype=bool)

    def update(self, position: np.ndarray) -> tuple[Obstacle, ...]:
        """Sense at ``position`` and return the obstacles the controller now knows."""
        now = detected_mask(position, self.obstacles, self.sensing_range)
        self.known = (self.known | now) if self.remember else now
        return tuple(o for o, k in zip(self.obstacles, self.known) if k)

    @property
    def count(self) -> int:
        """Number of obstacles currently known."""
        return int(self.known.sum())
