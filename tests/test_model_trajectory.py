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


@pytest.mark.parametrize("table, match", [
    ({"kind": "line", "direction_velocity": [1, 0, 0]},
     r"^trajectory\.direction_velocity: expected one of the keys \['start', 'velocity'\] of a line trajectory"),
    ({"kind": "line", "vel": [1, 0, 0]}, r"^trajectory\.vel: expected one of the keys \['start', 'velocity'\]"),
    ({"kind": "circle", "duration": 5.0}, r"trajectory\.duration: .* belongs above the first table$"),
    ({"kind": "circle", "radius": "3"}, r"^trajectory\.radius: expected a finite number, received '3'"),
    ({"kind": ["circle"]}, r"^trajectory\.kind: expected one of"),
])
def test_errors_name_the_documented_key(table, match):
    """Issue 24 item 3: a wrong key on a line lists the documented keys (``velocity``, not the Python name)."""
    with pytest.raises(ConfigError, match=match):
        trajectory_from_dict(table)


def test_a_wrong_key_that_is_no_top_level_key_gets_no_hint():
    with pytest.raises(ConfigError) as info:
        trajectory_from_dict({"kind": "line", "vel": [1, 0, 0]})
    assert "top-level" not in str(info.value)


def test_line_takes_its_documented_velocity_key():
    line = trajectory_from_dict({"kind": "line", "start": [0, 1, 2], "velocity": [0.5, 0, 0]})
    assert line.position(2.0).tolist() == [1.0, 1.0, 2.0]  # start + 2 s x 0.5 m/s along x, by hand


@pytest.mark.parametrize("traj", TRAJECTORIES, ids=lambda t: t.kind)
def test_repr_holds_plain_floats(traj):
    """Issue 24 item 9: no ``np.float64(...)`` in a trajectory's repr."""
    assert "np." not in repr(traj) and "float64" not in repr(traj)


@pytest.mark.parametrize("make", [
    lambda: Circle(radius=3.0, rate=0.2),
    lambda: Helix(radius=2.0, rate=-0.3, climb=0.05),
    lambda: Line(start=(0.0, 0.0, 0.0), direction_velocity=(0.2, 0.1, -0.05)),
    lambda: Waypoints(points=((0.0, 0.0, 0.0), (4.0, 0.0, 1.0), (4.0, 3.0, 1.0)), speed=0.3),
])
def test_the_acceleration_bound_holds_on_second_differences(make):
    """Property: |p_d(t+h) − 2 p_d(t) + p_d(t−h)| / h² (the acceleration, to O(h²)) stays below the bound, and
    for the circle and the line the bound is attained (it is the exact sup, not a loose one)."""
    tr = make()
    a_xy, a_z = tr.acceleration_bound()
    t = np.linspace(0.05, 60.0, 6001)
    h = 1e-3
    acc = (tr.position(t + h) - 2 * tr.position(t) + tr.position(t - h)) / h ** 2
    assert np.max(np.hypot(acc[:, 0], acc[:, 1])) <= a_xy * (1 + 1e-4) + 1e-9
    assert np.max(np.abs(acc[:, 2])) <= a_z * (1 + 1e-4) + 1e-9
    if isinstance(tr, (Circle, Line)):
        assert np.max(np.hypot(acc[:, 0], acc[:, 1])) == pytest.approx(a_xy, rel=1e-4, abs=1e-9)


@pytest.mark.parametrize("trajectory", [
    Line(direction_velocity=(0.3, -0.4, 0.1)),
    Circle(radius=3.0, rate=-0.2),
    Helix(radius=2.0, rate=0.1, climb=0.05),
    Waypoints(points=((0.0, 0.0, 0.0), (4.0, 0.0, 0.0), (4.0, 3.0, 0.0)), speed=0.3),
])
def test_the_horizontal_speed_floor_is_below_every_sampled_speed_and_zero_where_the_path_stops(trajectory):
    """Property: the floor lower-bounds the horizontal speed at every sampled time; a line and a circle keep their
    speed (floor = bound), waypoints rest at their corners (floor 0)."""
    t = np.linspace(0.0, 60.0, 6001)
    speed = np.hypot(*np.asarray(trajectory.velocity(t))[:, :2].T)
    floor = trajectory.horizontal_speed_floor()
    assert np.all(speed >= floor - 1e-12)
    if isinstance(trajectory, Waypoints):
        assert floor == 0.0 and speed.min() < 1e-9
    else:
        assert floor == pytest.approx(trajectory.horizontal_speed_bound()) and floor > 0
