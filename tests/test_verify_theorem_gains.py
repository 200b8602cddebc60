"""Tests of verify.theorem.gains: the polar Jacobian and the entry bounds of K and G = J K over R.

Closed forms (derived by hand from J = [[c, 0, 0], [0, 1, 0], [-o c / d, 0, c]], c = s sqrt(1 - o^2)):
the corrected law K = J^-1 = [[1/c, 0, 0], [0, 1, 0], [o / (c d), 0, 1/c]], so G = I,
sup |K_uu| = sup |K_rr| = 1 / sqrt(1 - o_max^2), sup |K_rd| = o_max / (sqrt(1 - o_max^2) eps);
the paper law K = I, G = J: G_dd = G_oo = c, sup |G_od| = sup |o sqrt(1 - o^2)| / eps.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import assume, given
from hypothesis import strategies as st

import verify
from tubekit.model.ancillary import LAWS, AncillaryLaw, jacobian_at
from tubekit.exceptions import ConfigError
from verify.theorem.gains import GAIN_GAP, GainBounds, gain_bounds, polar_jacobian
from verify.kernel.region import Region

_ED, _EO = sp.symbols("e_d e_o", real=True)


@pytest.fixture(scope="module")
def scenario():
    return verify.certifiable_scenario()


def _within_gap(bound: float, exact: float) -> bool:
    """A certified sup: never below the exact value, at most the documented relative gap above it."""
    return exact - 1e-12 <= bound <= exact * (1 + GAIN_GAP) + 1e-12


# --------------------------------------------------------------------------- J
@functools.lru_cache(maxsize=2)
def _polar_numeric(sign: int):
    return sp.lambdify([_ED, _EO], polar_jacobian(sign).tolist(), modules="math")


@given(e_d=st.floats(0.05, 5.0), theta=st.floats(-math.pi, math.pi), phi=st.floats(-math.pi, math.pi),
       pd=st.tuples(*[st.floats(-10, 10)] * 3), z=st.floats(-3, 3))
def test_polar_jacobian_is_the_derived_one(e_d, theta, phi, pd, z):
    """Property: polar_jacobian(sign) at (e_d, e_o = sin(psi - theta)) equals tubekit's derived J at the state,
    with sign = sign(cos(psi - theta)) (toward the target: -1), in both hemispheres."""
    cos_rel = math.cos(phi)
    assume(abs(cos_rel) > 1e-3)   # the hemisphere boundary: J is singular there, no sign to pick
    sign = -1 if cos_rel < 0 else 1
    psi = theta + phi
    state = np.array([pd[0] + e_d * math.cos(theta), pd[1] + e_d * math.sin(theta), z, psi])
    want = jacobian_at(state, np.asarray(pd))
    got = np.array(_polar_numeric(sign)(e_d, math.sin(phi)), dtype=float)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)


def test_polar_jacobian_structure():
    for s in (-1, 1):
        J = polar_jacobian(s)
        assert J.shape == (3, 3) and J[1, :] == sp.Matrix([[0, 1, 0]])
        assert sp.simplify(J[0, 0] - s * sp.sqrt(1 - _EO**2)) == 0


# --------------------------------------------------------------------------- gain bounds
@pytest.mark.parametrize("kw", [dict(), dict(e_o=(-0.3, 0.3), e_d=(0.7, 2.0), heading="both"),
                                dict(e_o=(-0.8, 0.8), e_d=(0.2, 2.0), heading="away")])
def test_corrected_law_gains_are_the_closed_forms(scenario, kw):
    reg = Region.from_scenario(scenario, **kw)
    g = gain_bounds("corrected", reg)
    assert isinstance(g, GainBounds) and g.converged
    # G = J J^-1 = I exactly
    assert g.g_lo == (1.0, 1.0, 1.0) and g.g_hi == (1.0, 1.0, 1.0)
    assert g.g_off == ((0.0, 0.0, 0.0),) * 3
    o, eps = max(-reg.e_o[0], reg.e_o[1]), reg.e_d[0]
    c = math.sqrt(1 - o * o)
    want = [[1 / c, 0, 0], [0, 1, 0], [o / (c * eps), 0, 1 / c]]
    for j in range(3):
        for l in range(3):
            if want[j][l] == 0:
                assert g.k_abs[j][l] == 0.0
            else:
                assert _within_gap(g.k_abs[j][l], want[j][l]), (j, l, g.k_abs[j][l], want[j][l])


@pytest.mark.parametrize("kw", [dict(), dict(e_o=(-0.8, 0.8), e_d=(0.2, 2.0), heading="away")])
def test_paper_law_gains_are_the_closed_forms(scenario, kw):
    reg = Region.from_scenario(scenario, **kw)
    g = gain_bounds("paper", reg)
    assert g.converged
    assert g.k_abs == ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))   # K = I
    o, eps = max(-reg.e_o[0], reg.e_o[1]), reg.e_d[0]
    c_min = math.sqrt(1 - o * o)
    s = -1 if reg.heading == "toward" else 1
    lo, hi = sorted((s * 1.0, s * c_min))
    for j in (0, 2):
        assert g.g_lo[j] <= lo and g.g_lo[j] >= lo - GAIN_GAP * abs(lo) - 1e-12
        assert g.g_hi[j] >= hi and g.g_hi[j] <= hi + GAIN_GAP * abs(hi) + 1e-12
    assert g.g_lo[1] == g.g_hi[1] == 1.0
    peak = (o * c_min if o <= math.sqrt(0.5) else 0.5) / eps   # max of o sqrt(1 - o^2) on [0, o_max]
    assert _within_gap(g.g_off[2][0], peak)
    assert g.g_off[0] == (0.0, 0.0, 0.0) and g.g_off[2][1] == 0.0


def test_both_hemispheres_take_the_worse_sign(scenario):
    """With heading 'both' the paper law's G_dd ranges over [-1, 1] (c changes sign)."""
    g = gain_bounds("paper", Region.from_scenario(scenario, heading="both"))
    assert g.g_lo[0] <= -1.0 and g.g_hi[0] >= 1.0


def test_gain_bounds_to_dict(scenario):
    d = gain_bounds("corrected", Region.from_scenario(scenario)).to_dict()
    assert set(d) == {"k_abs", "g_lo", "g_hi", "g_off", "converged"}
    assert d["k_abs"][1] == [0.0, 1.0, 0.0] and d["converged"] is True


def test_a_tiny_budget_reports_not_converged(scenario):
    reg = Region.from_scenario(scenario, e_o=(-0.8, 0.8), e_d=(0.2, 2.0), heading="away")
    g = gain_bounds("paper", reg, max_boxes=1)
    assert not g.converged
    assert g.g_off[2][0] >= 2.5 - 1e-12   # still an upper bound (sup = 0.5 / 0.2)


def _no_symbolic(monkeypatch):
    monkeypatch.setitem(LAWS, "test-no-symbolic", AncillaryLaw("test-no-symbolic", lambda J: J, "test"))
    return "test-no-symbolic"


def _wrong_shape(monkeypatch):
    monkeypatch.setitem(LAWS, "test-wrong-shape", AncillaryLaw("test-wrong-shape", lambda J: J, "test",
                                                              symbolic_gain=lambda J: sp.eye(2)))
    return "test-wrong-shape"


@pytest.mark.parametrize("make, match", [
    (lambda mp: "no-such-law", r"law: expected one of"),
    (_no_symbolic, r"law: expected a law with a symbolic"),
    (_wrong_shape, r"law.symbolic_gain: expected a 3x3 sympy Matrix"),
])
def test_gain_bounds_errors(scenario, monkeypatch, make, match):
    with pytest.raises(ConfigError, match=match):
        gain_bounds(make(monkeypatch), Region.from_scenario(scenario))
