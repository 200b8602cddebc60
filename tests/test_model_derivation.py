"""The sympy-derived error dynamics against finite differences of the kinematics."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st

from tubekit.model.derivation import derive, symbols
from tubekit.model.errors import error_coordinates, numeric
from tubekit.model.kinematics import kinematics

finite = st.floats(-1.0, 1.0, allow_nan=False)


def _fd_error_rate(state, v, omega, p_d, pd_dot, h=1e-6):
    """Central difference of e along the kinematics (independent of the derivation)."""
    f = kinematics(state, v, omega)
    e_plus = error_coordinates(state + h * f, p_d + h * pd_dot)
    e_minus = error_coordinates(state - h * f, p_d - h * pd_dot)
    return (e_plus - e_minus) / (2 * h)


@given(
    e_d=st.floats(0.05, 10.0), bearing=st.floats(-np.pi, np.pi), psi=st.floats(-np.pi, np.pi),
    v=st.tuples(finite, finite, finite), omega=st.tuples(finite, finite, finite),
    pd_dot=st.tuples(finite, finite, finite),
)
def test_e_dot_matches_finite_differences(e_d, bearing, psi, v, omega, pd_dot):
    """Property: the derived e_dot equals the finite-difference rate of e along eq. (11)."""
    p_d = np.array([0.3, -0.2, 0.1])
    state = np.array([p_d[0] + e_d * np.cos(bearing), p_d[1] + e_d * np.sin(bearing), 0.7, psi])
    e_x, e_y = state[0] - p_d[0], state[1] - p_d[1]
    derived = numeric().e_dot(e_x, e_y, psi, *v, *omega, *pd_dot)
    fd = _fd_error_rate(state, np.array(v), np.array(omega), p_d, np.array(pd_dot))
    assert np.allclose(derived, fd, rtol=1e-5, atol=1e-5 * (1 + 1 / e_d))


@pytest.mark.parametrize("e_d", [1e-3, 1e-2])
@pytest.mark.parametrize("psi_offset", [0.3, np.pi - 0.3])  # away and toward hemispheres
def test_near_singular_distance(e_d, psi_offset):
    bearing = 0.7
    p_d = np.zeros(3)
    state = np.array([e_d * np.cos(bearing), e_d * np.sin(bearing), 0.0, bearing + psi_offset])
    v, omega, pdd = np.array([0.3, 0.1, 0.2]), np.array([0.05, -0.02, 0.01]), np.array([0.2, 0.1, 0.0])
    derived = numeric().e_dot(state[0], state[1], state[3], *v, *omega, *pdd)
    fd = _fd_error_rate(state, v, omega, p_d, pdd, h=1e-9 * e_d / 1e-3)
    assert np.allclose(derived, fd, rtol=1e-4, atol=1e-6 / e_d)


def test_decomposition_is_exact():
    d = derive()
    assert d.residual == sp.zeros(3, 1)
    s = symbols()
    assert d.J.free_symbols <= {s["e_x"], s["e_y"], s["psi"]}
    assert d.zeta.free_symbols & {s["omega_1"], s["u"]} == set()
    assert d.xi.free_symbols & {s["xdot_d"], s["u"]} == set()


def test_closed_form_polar():
    """J = [[c,0,0],[0,1,0],[-e_o c/e_d,0,c]] with c = cos(psi - bearing) (hand derivation)."""
    rng = np.random.default_rng(1)
    d, th, phi = rng.uniform(0.1, 3, 50), rng.uniform(-3, 3, 50), rng.uniform(-3, 3, 50)
    J = numeric().J(d * np.cos(th), d * np.sin(th), th + phi)
    c, s = np.cos(phi), np.sin(phi)
    assert np.allclose(J[:, 0, 0], c) and np.allclose(J[:, 2, 2], c)
    assert np.allclose(J[:, 2, 0], -s * c / d)
    assert np.allclose(J[:, 1, 1], 1.0)


def test_generated_module_equals_the_derivation():
    """The shipped closed-form code is the derivation: same source hash, same text (same sympy), same values."""
    import tubekit.model._generated_dynamics as gen
    from tubekit.model.derivation import GENERATED_PATH, derivation_hash, generated_source

    assert gen.DERIVATION_HASH == derivation_hash(), "run `python -m tubekit.model.derivation` to regenerate"
    if gen.SYMPY_VERSION == sp.__version__:
        assert GENERATED_PATH.read_text() == generated_source()
    d, s = derive(), symbols()
    args = [s[n] for n in ("e_x", "e_y", "psi")]
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-3, 3, (40, 2)), rng.uniform(-4, 4, 40)])
    reference = sp.lambdify(args, list(d.J), modules="numpy")
    for ex, ey, psi in pts:
        assert np.allclose(gen.jacobian_scalar(ex, ey, psi), reference(ex, ey, psi), rtol=1e-12, atol=1e-12)
        assert np.allclose(numeric().J(ex, ey, psi).ravel(), reference(ex, ey, psi), rtol=1e-12, atol=1e-12)
        e = gen.error_scalar(ex, ey, 0.4, psi)
        assert np.allclose(e, error_coordinates(np.array([ex, ey, 0.4, psi]), np.zeros(3)), rtol=1e-12)
        rho, sigma = rng.normal(size=3), 2.5
        kappa = -sigma * np.linalg.solve(numeric().J(ex, ey, psi), rho)
        assert np.allclose(gen.corrected_kappa(ex, ey, psi, *rho, sigma), kappa, rtol=1e-9, atol=1e-9)


def test_generated_scalars_raise_where_undefined():
    import tubekit.model._generated_dynamics as gen
    with pytest.raises(ZeroDivisionError):
        gen.error_scalar(0.0, 0.0, 0.0, 0.3)
    with pytest.raises(ZeroDivisionError):  # bearing pi/2, psi = 0: cos(psi - bearing) = 0, J singular
        gen.corrected_kappa(0.0, 1.0, 0.0, 0.1, 0.1, 0.1, 1.0)
