"""Kinematics, input limits and the sway model."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model import InputLimits, SwayModel, kinematics, nominal_kinematics, sway_velocity_term


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


@given(psi=st.floats(-10, 10), vs=st.floats(-1, 1))
def test_sway_term_is_lateral(psi, vs):
    """Property: g(x, v_s) is orthogonal to the heading and has norm |v_s| (eq. 2)."""
    g = sway_velocity_term(np.array([0, 0, 0, psi]), vs)
    heading = np.array([np.cos(psi), np.sin(psi), 0.0])
    assert abs(g @ heading) < 1e-12
    assert np.linalg.norm(g) == pytest.approx(abs(vs), abs=1e-12)


@given(u=st.floats(-5, 5), r=st.floats(-5, 5), t=st.floats(0, 1000))
def test_sway_model_respects_bound(u, r, t):
    """Property: the sway model never exceeds its bound gamma-bar."""
    m = SwayModel(gain=0.5, amplitude=0.05, period=7.0, bound=0.03)
    assert abs(m.velocity(t, np.array([u, 0.0, r]))) <= 0.03


def test_zero_sway_allowed():
    assert SwayModel(gain=0.0, amplitude=0.0, bound=0.0).velocity(3.0, np.array([0.4, 0, 0.5])) == 0.0


@pytest.mark.parametrize("kwargs, field", [
    (dict(u_max=0.0, w_max=0.3, r_max=0.5), "limits.u_max"),
    (dict(u_max=0.4, w_max=-1, r_max=0.5), "limits.w_max"),
    (dict(u_max=0.4, w_max=0.3, r_max=float("nan")), "limits.r_max"),
])
def test_input_limits_validation(kwargs, field):
    with pytest.raises(ConfigError, match=field):
        InputLimits(**kwargs)


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
