"""Kinematics, input limits and the sway model settings (evaluated in tests/test_plant_kinematic.py)."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.kinematics import InputLimits, SwayModel, kinematics, nominal_kinematics


def test_nominal_kinematics_eq3():
    x = np.array([1.0, 2.0, 3.0, np.pi / 2])
    dx = nominal_kinematics(x, np.array([0.4, -0.1, 0.2]))
    assert np.allclose(dx, [0.0, 0.4, -0.1, 0.2], atol=1e-15)


def test_kinematics_vectorised_and_adds_disturbance():
    x = np.zeros((5, 4))
    v = np.tile([0.3, 0.0, 0.1], (5, 1))
    om = np.tile([0.01, 0.02, 0.03], (5, 1))
    dx = kinematics(x, v, om)
    assert dx.shape == (5, 4)
    assert np.allclose(dx[0], [0.31, 0.02, 0.03, 0.1])


@pytest.mark.parametrize("kwargs, field", [
    (dict(u_max=0.0, w_max=0.3, r_max=0.5), "limits.u_max"),
    (dict(u_max=0.4, w_max=-1, r_max=0.5), "limits.w_max"),
    (dict(u_max=0.4, w_max=0.3, r_max=float("nan")), "limits.r_max"),
])
def test_input_limits_validation(kwargs, field):
    with pytest.raises(ConfigError, match=field):
        InputLimits(**kwargs)


@pytest.mark.parametrize("u_min, message", [
    (-0.1, "limits.u_min"),                 # a floor below rest: the symmetric box is u_min = None
    (0.4, r"limits\.u_min.*\[0, u_max = 0\.4\)"),   # no room left between the floor and u_max
    (0.5, "limits.u_min"),
    ("0.1", "limits.u_min"),
    (float("nan"), "limits.u_min"),
])
def test_a_surge_floor_outside_0_to_u_max_is_refused_by_name(u_min, message):
    with pytest.raises(ConfigError, match=message):
        InputLimits(0.4, 0.3, 0.5, u_min=u_min)


def test_a_surge_floor_raises_the_lower_corner_of_v_and_nothing_else():
    """A minimum surge moves only the surge's lower end; the symmetric box keeps -V as its lower corner."""
    sym, floor = InputLimits(0.4, 0.3, 0.5), InputLimits(0.4, 0.3, 0.5, u_min=0.15)
    assert sym.surge_floor == -0.4 and list(sym.lower) == [-0.4, -0.3, -0.5]
    assert floor.surge_floor == 0.15 and list(floor.lower) == [0.15, -0.3, -0.5]
    assert list(floor.vector) == [0.4, 0.3, 0.5]                  # the upper corner (and the largest |v|) unchanged
    assert sym.contains([0.0, 0.0, 0.0]) and not floor.contains([0.0, 0.0, 0.0])   # rest is outside V now
    assert floor.contains([0.15, -0.3, 0.5]) and not floor.contains([0.1499, 0.0, 0.0])


def test_input_limits_norm_and_contains():
    lim = InputLimits(0.4, 0.3, 0.5)
    assert lim.norm == pytest.approx(np.sqrt(0.16 + 0.09 + 0.25))
    assert lim.contains([0.4, -0.3, 0.0]) and not lim.contains([0.41, 0, 0])


@pytest.mark.parametrize("kwargs, field", [
    (dict(gain=-1), "sway.gain"), (dict(period=0), "sway.period"), (dict(bound=-0.1), "sway.bound"),
])
def test_sway_validation(kwargs, field):
    with pytest.raises(ConfigError, match=field):
        SwayModel(**kwargs)
