"""Desired trajectories: analytic velocities and their bounds."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.trajectory import Circle, Helix, Line, Waypoints, trajectory_from_dict

TRAJECTORIES = [
    Circle(),
    Circle(radius=2.0, rate=-0.1, center=(1, 2, -1), phase=0.4),
    Helix(radius=1.5, rate=0.2, climb=0.03),
    Line(start=(0, 1, 2), direction_velocity=(0.1, -0.2, 0.05)),
    Waypoints(points=((0, 0, 0), (3, 0, 0), (3, 3, 1)), speed=0.3),
]


@pytest.mark.parametrize("traj", TRAJECTORIES, ids=lambda t: t.kind)
def test_velocity_is_derivative_of_position(traj):
    t = np.linspace(0.0, 40.0, 4001)
    fd = np.gradient(traj.position(t), t, axis=0)
    assert np.allclose(fd[2:-2], traj.velocity(t)[2:-2], atol=1e-4)


@pytest.mark.parametrize("traj", TRAJECTORIES, ids=lambda t: t.kind)
def test_velocity_bound_holds_and_is_reached(traj):
    t = np.linspace(0.0, 200.0, 200001)
    v = np.abs(traj.velocity(t))
    bound = traj.velocity_bound()
    assert np.all(v <= bound + 1e-12)
    assert np.allclose(v.max(axis=0), bound, rtol=1e-3, atol=1e-9)
    assert np.hypot(v[:, 0], v[:, 1]).max() <= traj.horizontal_speed_bound() + 1e-12


def test_paper_circle():
    c = Circle()  # p_d = [3 sin(pi t/25), 3 cos(pi t/25), 0]
    assert np.allclose(c.position(12.5), [3.0, 0.0, 0.0], atol=1e-12)
    assert c.horizontal_speed_bound() == pytest.approx(3 * np.pi / 25)


def test_waypoints_stop_at_points():
    w = Waypoints(points=((0, 0, 0), (2, 0, 0)), speed=0.5)
    assert np.allclose(w.position(100.0), [2, 0, 0])
    assert np.allclose(w.velocity(np.array([0.0, 100.0])), 0.0)


@pytest.mark.parametrize("table, field", [
    ({"kind": "spiral"}, "trajectory.kind"),
    ({"kind": "circle", "radius": -1}, "trajectory.radius"),
    ({"kind": "circle", "colour": 1}, "trajectory"),
    ({"kind": "waypoints", "points": [[0, 0, 0]]}, "trajectory.points"),
    ({"kind": "waypoints", "points": [[0, 0, 0], [0, 0, 0]]}, "trajectory.points"),
    ({"kind": "line", "velocity": [1, 2]}, "trajectory.velocity"),
])
def test_trajectory_from_dict_errors(table, field):
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        trajectory_from_dict(table)


@pytest.mark.parametrize("traj", TRAJECTORIES, ids=lambda t: t.kind)
def test_round_trip(traj):
    again = trajectory_from_dict(traj.to_dict())
    t = np.linspace(0, 30, 31)
    assert np.allclose(again.position(t), traj.position(t))


def test_config_error_is_value_error():
    with pytest.raises(ConfigError):
        trajectory_from_dict("circle")
