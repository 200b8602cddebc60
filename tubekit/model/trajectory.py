"""Desired trajectories p_d(t) with analytic velocities.

Every trajectory gives ``position(t)`` and ``velocity(t)`` (m, m/s; vectorised
over ``t``) and a rigorous ``velocity_bound()`` = [max|xdot_d|, max|ydot_d|,
max|zdot_d|] plus ``horizontal_speed_bound()`` used by the verifier.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field, fields

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.validation import as_vector, finite, positive

__all__ = ["Trajectory", "Circle", "Helix", "Line", "Waypoints", "trajectory_from_dict", "toml_keys", "KINDS",
           "TOML_NAMES"]


class Trajectory(ABC):
    """Base class: a smooth desired trajectory p_d(t)."""

    kind: str = "trajectory"

    @abstractmethod
    def position(self, t: np.ndarray | float) -> np.ndarray:
        """p_d(t) (m), shape t.shape + (3,)."""

    @abstractmethod
    def velocity(self, t: np.ndarray | float) -> np.ndarray:
        """p_d_dot(t) (m/s), shape t.shape + (3,)."""

    @abstractmethod
    def velocity_bound(self) -> np.ndarray:
        """Componentwise bound [max|xdot_d|, max|ydot_d|, max|zdot_d|] (m/s)."""

    def horizontal_speed_bound(self) -> float:
        """Bound on sqrt(xdot_d^2 + ydot_d^2) (m/s)."""
        return float(np.hypot(*self.velocity_bound()[:2]))

    def horizontal_speed_floor(self) -> float:
        """A lower bound on sqrt(xdot_d^2 + ydot_d^2) over all time (m/s); 0 when not known (a path that stops)."""
        return 0.0

    def acceleration_bound(self) -> tuple[float, float]:
        """(horizontal, vertical) bounds on ‖p̈_d,xy‖ and |z̈_d| (m/s²); (inf, inf) when not known."""
        return (math.inf, math.inf)

    @abstractmethod
    def to_dict(self) -> dict:
        """A TOML/JSON-friendly description."""


@dataclass(frozen=True)
class Circle(Trajectory):
    """Horizontal circle p_d = c + radius [sin(rate t + phase), cos(rate t + phase), 0].

    The paper's Section VI uses ``Circle(radius=3, rate=pi/25)``.

    Parameters
    ----------
    radius : float
        Circle radius (m).
    rate : float
        Angular rate (rad/s); speed is radius * |rate| (m/s).
    center : array (3,)
        Centre (m).
    phase : float
        Phase at t = 0 (rad).
    """

    radius: float = 3.0
    rate: float = np.pi / 25.0
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    phase: float = 0.0
    kind: str = field(default="circle", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", positive("trajectory.radius", self.radius))
        object.__setattr__(self, "rate", finite("trajectory.rate", self.rate))
        object.__setattr__(self, "center", tuple(float(x) for x in as_vector("trajectory.center", self.center, 3)))
        object.__setattr__(self, "phase", finite("trajectory.phase", self.phase))

    def position(self, t):
        a = self.rate * np.asarray(t, dtype=float) + self.phase
        c = self.center
        out = np.empty(a.shape + (3,))
        out[..., 0] = c[0] + self.radius * np.sin(a)
        out[..., 1] = c[1] + self.radius * np.cos(a)
        out[..., 2] = c[2] + 0.0 * a
        return out

    def velocity(self, t):
        a = self.rate * np.asarray(t, dtype=float) + self.phase
        k = self.radius * self.rate
        return np.stack([k * np.cos(a), -k * np.sin(a), 0.0 * a], axis=-1)

    def velocity_bound(self):
        k = abs(self.radius * self.rate)
        return np.array([k, k, 0.0])

    def horizontal_speed_bound(self):
        return abs(self.radius * self.rate)

    def horizontal_speed_floor(self):
        return abs(self.radius * self.rate)

    def acceleration_bound(self):
        return (abs(self.radius) * self.rate * self.rate, 0.0)

    def to_dict(self):
        return {"kind": "circle", "radius": self.radius, "rate": self.rate,
                "center": list(self.center), "phase": self.phase}


@dataclass(frozen=True)
class Helix(Circle):
    """A :class:`Circle` that climbs at constant vertical speed ``climb`` (m/s)."""

    climb: float = 0.05
    kind: str = field(default="helix", init=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "climb", finite("trajectory.climb", self.climb))

    def position(self, t):
        p = super().position(t)
        p[..., 2] = p[..., 2] + self.climb * np.asarray(t, dtype=float)
        return p

    def velocity(self, t):
        v = super().velocity(t)
        v[..., 2] = self.climb
        return v

    def velocity_bound(self):
        b = super().velocity_bound()
        b[2] = abs(self.climb)
        return b

    def to_dict(self):
        d = super().to_dict()
        d.update(kind="helix", climb=self.climb)
        return d


@dataclass(frozen=True)
class Line(Trajectory):
    """Straight line p_d = start + velocity * t.

    Parameters
    ----------
    start : array (3,)
        Position at t = 0 (m).
    direction_velocity : array (3,)
        Constant velocity (m/s); its TOML/JSON key is ``velocity``.
    """

    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction_velocity: tuple[float, float, float] = (0.2, 0.0, 0.0)
    kind: str = field(default="line", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", tuple(float(x) for x in as_vector("trajectory.start", self.start, 3)))
        object.__setattr__(self, "direction_velocity",
                           tuple(float(x) for x in as_vector("trajectory.velocity", self.direction_velocity, 3)))

    def position(self, t):
        t = np.asarray(t, dtype=float)[..., None]
        return np.asarray(self.start) + t * np.asarray(self.direction_velocity)

    def velocity(self, t):
        t = np.asarray(t, dtype=float)
        return np.broadcast_to(np.asarray(self.direction_velocity), t.shape + (3,)).copy()

    def velocity_bound(self):
        return np.abs(np.asarray(self.direction_velocity))

    def horizontal_speed_bound(self):
        return float(np.hypot(*self.direction_velocity[:2]))

    def horizontal_speed_floor(self):
        return float(np.hypot(*self.direction_velocity[:2]))

    def acceleration_bound(self):
        return (0.0, 0.0)

    def to_dict(self):
        return {"kind": "line", "start": list(self.start), "velocity": list(self.direction_velocity)}


@dataclass(frozen=True)
class Waypoints(Trajectory):
    """Piecewise-linear path through waypoints, traversed with a smooth time law.

    Each segment i is traversed in time ``L_i / speed * 15/8`` with the quintic
    (minimum-jerk) time law s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, so the vehicle
    target stops at every waypoint and the peak speed on every segment is exactly
    ``speed`` (m/s). After the last waypoint p_d stays there.
    """

    points: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0), (5.0, 0.0, 0.0))
    speed: float = 0.2
    kind: str = field(default="waypoints", init=False)

    def __post_init__(self) -> None:
        pts = np.asarray(self.points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] < 2 or not np.all(np.isfinite(pts)):
            raise ConfigError("trajectory.points", "a list of at least two [x, y, z] points", self.points)
        lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        if np.any(lengths <= 0):
            raise ConfigError("trajectory.points", "consecutive points that differ", self.points)
        object.__setattr__(self, "points", tuple(tuple(float(x) for x in p) for p in pts))
        object.__setattr__(self, "speed", positive("trajectory.speed", self.speed))

    def _segments(self):
        pts = np.asarray(self.points)
        lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        durations = lengths / self.speed * 15.0 / 8.0
        starts = np.concatenate([[0.0], np.cumsum(durations)])
        return pts, durations, starts

    def _eval(self, t, derivative: bool):
        pts, dur, starts = self._segments()
        t = np.asarray(t, dtype=float)
        tc = np.clip(t, 0.0, starts[-1])
        idx = np.clip(np.searchsorted(starts, tc, side="right") - 1, 0, len(dur) - 1)
        tau = (tc - starts[idx]) / dur[idx]
        a, b = pts[idx], pts[idx + 1]
        if derivative:
            ds = (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / dur[idx]
            ds = np.where((t < 0) | (t > starts[-1]), 0.0, ds)
            return (b - a) * ds[..., None]
        s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
        return a + (b - a) * s[..., None]

    def position(self, t):
        return self._eval(t, derivative=False)

    def velocity(self, t):
        return self._eval(t, derivative=True)

    def velocity_bound(self):
        pts = np.asarray(self.points)
        d = np.diff(pts, axis=0)
        unit = d / np.linalg.norm(d, axis=1, keepdims=True)
        return np.max(np.abs(unit), axis=0) * self.speed

    def horizontal_speed_bound(self):
        pts = np.asarray(self.points)
        d = np.diff(pts, axis=0)
        unit = d / np.linalg.norm(d, axis=1, keepdims=True)
        return float(np.max(np.hypot(unit[:, 0], unit[:, 1])) * self.speed)

    def acceleration_bound(self):
        # p̈_d = (b − a) s''(τ) / T² on a segment of duration T, and max |s''| = 10 / √3 for the quintic
        # s = 10τ³ − 15τ⁴ + 6τ⁵ (at τ = (3 − √3) / 6); outside the segments p_d is at rest.
        pts, dur, _ = self._segments()
        d = np.diff(pts, axis=0)
        peak = 10.0 / math.sqrt(3.0) / dur ** 2
        return (float(np.max(np.hypot(d[:, 0], d[:, 1]) * peak)), float(np.max(np.abs(d[:, 2]) * peak)))

    def to_dict(self):
        return {"kind": "waypoints", "points": [list(p) for p in self.points], "speed": self.speed}


#: The classes by TOML ``kind``.
KINDS: dict[str, type[Trajectory]] = {"circle": Circle, "helix": Helix, "line": Line, "waypoints": Waypoints}
#: A field whose TOML/JSON key differs from its Python name, by kind: {TOML key: field name}.
TOML_NAMES: dict[str, dict[str, str]] = {"line": {"velocity": "direction_velocity"}}
#: Top-level scenario keys a user may write after the [trajectory] header by mistake (for the hint).
_TOP_LEVEL_KEYS = ("name", "duration", "epsilon", "vehicle_radius", "sensing_range", "initial_state", "workspace")


def toml_keys(kind: str) -> list[str]:
    """The documented TOML keys of a trajectory ``kind`` (``kind`` itself aside), sorted."""
    renamed = {name: key for key, name in TOML_NAMES.get(kind, {}).items()}
    return sorted(renamed.get(f.name, f.name) for f in fields(KINDS[kind]) if f.init)


def trajectory_from_dict(d: dict) -> Trajectory:
    """Build a trajectory from a TOML/JSON table with a ``kind`` key and the keys of its ``to_dict``.

    Raises
    ------
    ConfigError
        An unknown kind, an unknown key (the error lists the documented keys of that kind) or a bad value.
    """
    if not isinstance(d, dict):
        raise ConfigError("trajectory", "a table with a 'kind' key", d)
    d = dict(d)
    kind = d.pop("kind", None)
    if not isinstance(kind, str) or kind not in KINDS:
        raise ConfigError("trajectory.kind", f"one of {tuple(KINDS)}", kind)
    allowed = toml_keys(kind)
    for key in sorted(d):
        if key not in allowed:
            hint = ("a top-level key written after the [trajectory] header belongs above the first table"
                    if key in _TOP_LEVEL_KEYS else "")
            raise ConfigError(f"trajectory.{key}", f"one of the keys {allowed} of a {kind} trajectory", key, hint)
    names = TOML_NAMES.get(kind, {})
    return KINDS[kind](**{names.get(key, key): value for key, value in d.items()})
