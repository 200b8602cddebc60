"""Soundness and tightness of the certified bounds (verify.lemma1.bounds) and the polar model (verify.lemma1.polar).

References are independent of verify: the Cartesian callables of
tubekit.model.errors.numeric(), the numeric ancillary gains of tubekit.model.ancillary.LAWS,
finite differences, brute-force grids and the closed forms derived by hand
(c = cos(psi - theta) = s sqrt(1 - e_o^2)):

* J = [[c,0,0],[0,1,0],[-e_o c/e_d,0,c]], zeta = [-a, -zdot_d, c b/e_d], xi = [alpha, omega_3, -c beta/e_d];
* sup ||xi|| = omega_bar max(1, max|c|/e_d);  sup ||d zeta/d theta|| = h max(1, max|c|/e_d);
* ||d zeta/de|| = |b| sqrt(c^2/e_d^4 + e_o^2/(c^2 e_d^2));
* paper law: lambda(sym J) = {1, c - |c||e_o|/(2e_d), c + |c||e_o|/(2e_d)};
* corrected law: J K = I, ||row_r(J^-1)|| = sqrt(1 + e_o^2/e_d^2)/|c|.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.ancillary import LAWS
from tubekit.model.errors import numeric
from tubekit.scenario import load_scenario, paper_scenario
from verify.lemma1.bounds import compute_bounds
from verify.lemma1.polar import A_V, B_V, ALPHA, BETA, E_D, E_O, law_gain, polar_model
from verify.kernel.region import Region
from verify import SCENARIOS_DIR

GAP = 0.05


def _regions() -> dict[str, Region]:
    paper = Region.from_scenario(paper_scenario())
    cert = Region.from_scenario(load_scenario(SCENARIOS_DIR / "certifiable.toml"))
    both = Region.from_scenario(paper_scenario(), heading="both", e_d=(0.3, 2.0), e_o=(-0.4, 0.7),
                                pd_dot_max=(0.1, 0.2, 0.05), pd_dot_xy_max=0.2)
    return {"paper": paper, "certifiable": cert, "both": both}


REGIONS = _regions()


@lru_cache(maxsize=None)
def bounds(name: str, law: str):
    return compute_bounds(REGIONS[name], law, gap=GAP, max_boxes=20000)


def _cart(e_d, e_o, theta, s):
    """(e_x, e_y, psi) of a point with error (e_d, e_o), bearing theta, hemisphere s."""
    phi = np.where(s > 0, np.arcsin(e_o), np.pi - np.arcsin(e_o))
    return e_d * np.cos(theta), e_d * np.sin(theta), theta + phi


def _c(e_o, s):
    return s * math.sqrt(1 - e_o**2)


# ----------------------------------------------------------------------------- the polar model
@pytest.mark.parametrize("s", [-1, 1])
def test_polar_model_matches_the_cartesian_derivation(s):
    pm = polar_model(s)
    nd = numeric()
    rng = np.random.default_rng(3 + s)
    zd, om3 = sp.Symbol("zdot_d", real=True), sp.Symbol("omega_3", real=True)
    fJ = sp.lambdify([E_D, E_O], pm.J)
    fZ = sp.lambdify([E_D, E_O, A_V, B_V, zd], pm.zeta)
    fX = sp.lambdify([E_D, E_O, ALPHA, BETA, om3], pm.xi)
    for _ in range(50):
        e_d, e_o, th = rng.uniform(0.05, 4), rng.uniform(-0.99, 0.99), rng.uniform(-np.pi, np.pi)
        ex, ey, psi = _cart(e_d, e_o, th, s)
        pdot, om = rng.normal(size=3), rng.normal(size=3)
        n, t = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])
        np.testing.assert_allclose(np.array(fJ(e_d, e_o), float), nd.J(ex, ey, psi), atol=1e-10)
        np.testing.assert_allclose(np.array(fZ(e_d, e_o, pdot[:2] @ n, pdot[:2] @ t, pdot[2]), float).ravel(),
                                   nd.zeta(ex, ey, psi, *pdot), atol=1e-10)
        np.testing.assert_allclose(np.array(fX(e_d, e_o, om[:2] @ n, om[:2] @ t, om[2]), float).ravel(),
                                   nd.xi(ex, ey, psi, *om), atol=1e-10)


@pytest.mark.parametrize("s", [-1, 1])
def test_polar_model_equals_the_hand_derived_closed_forms(s):
    pm = polar_model(s)
    c = s * sp.sqrt(1 - E_O**2)
    zd, om3 = sp.Symbol("zdot_d", real=True), sp.Symbol("omega_3", real=True)
    J = sp.Matrix([[c, 0, 0], [0, 1, 0], [-E_O * c / E_D, 0, c]])
    zeta = sp.Matrix([-A_V, -zd, c * B_V / E_D])
    xi = sp.Matrix([ALPHA, om3, -c * BETA / E_D])
    assert (pm.J - J).applyfunc(sp.simplify) == sp.zeros(3, 3)
    assert (pm.zeta - zeta).applyfunc(sp.simplify) == sp.zeros(3, 1)
    assert (pm.xi - xi).applyfunc(sp.simplify) == sp.zeros(3, 1)
    assert pm.zeta_rotation_form


@pytest.mark.parametrize("law", ["paper", "corrected"])
def test_symbolic_gain_matches_the_numeric_law(law):
    rng = np.random.default_rng(7)
    for s in (-1, 1):
        K, _ = law_gain(law, s)
        fK = sp.lambdify([E_D, E_O], K)
        for _ in range(20):
            e_d, e_o, th = rng.uniform(0.1, 3), rng.uniform(-0.9, 0.9), rng.uniform(-3, 3)
            J = numeric().J(*_cart(e_d, e_o, th, s))
            np.testing.assert_allclose(np.array(fK(e_d, e_o), float), LAWS[law].gain_of_jacobian(J), atol=1e-9)


# ----------------------------------------------------------------------------- closed forms
def _grid(reg: Region, n: int = 801):
    ed = np.linspace(*reg.e_d, n)[:, None]
    eo = np.linspace(*reg.e_o, n)[None, :]
    return ed, eo


@pytest.mark.parametrize("name", ["paper", "certifiable", "both"])
def test_bounds_bracket_the_closed_forms(name):
    reg = REGIONS[name]
    b = bounds(name, "corrected")
    ed, eo = _grid(reg)
    absc = np.sqrt(1 - eo**2)
    h, om = reg.pd_dot_xy_max, reg.omega_bar
    ref = {
        "xi_bar": om * max(1.0, float(np.max(absc / ed))),
        "zeta_theta": h * max(1.0, float(np.max(absc / ed))),
        "L2": h * float(np.max(np.sqrt(absc**2 / ed**4 + eo**2 / (absc**2 * ed**2)))),
        "K_row_u": float(np.max(1 / absc)),
        "K_row_r": float(np.max(np.sqrt(1 + eo**2 / ed**2) / absc)),
        "K_row_w": 1.0,
        "JK_norm": 1.0,
    }
    for key, val in ref.items():
        br = b[key]
        assert br.sampled <= br.bound
        assert val <= br.bound * (1 + 1e-12), key          # sound (grid value is attained)
        assert br.bound <= val * (1 + GAP) + 1e-12, key     # tight to the gap
    assert b["J_lower"].bound == pytest.approx(1.0) and b["J_lower"].bound <= 1.0


@pytest.mark.parametrize("name", ["paper", "certifiable", "both"])
def test_paper_law_j_lower_brackets_the_closed_form(name):
    reg = REGIONS[name]
    b = bounds(name, "paper")["J_lower"]
    ed, eo = _grid(reg)
    absc = np.sqrt(1 - eo**2)
    worst = []
    for s in reg.hemisphere_signs:
        c = s * absc
        worst.append(min(1.0, float(np.min(c - absc * np.abs(eo) / (2 * ed)))))
    ref = min(worst)
    assert b.bound <= ref + 1e-12 and b.sampled >= b.bound
    assert abs(b.bound - ref) <= GAP * abs(ref) + 1e-12
    if reg.heading in ("toward", "both"):
        assert b.bound < 0  # Remark 1 fails for the paper's law when the vehicle points at the target


def test_l1_brackets_a_finite_difference_brute_force():
    reg = REGIONS["paper"]
    b = bounds("paper", "paper")["L1"]
    nd = numeric()
    ed = np.linspace(*reg.e_d, 121)
    eo = np.linspace(*reg.e_o, 121)
    ED, EO = np.meshgrid(ed, eo, indexing="ij")
    best = 0.0
    th = 0.4
    for s in reg.hemisphere_signs:
        for u, r in ((reg.v_max[0], reg.v_max[2]), (reg.v_max[0], -reg.v_max[2])):
            v = np.array([u, 0.0, r])
            hstep = 1e-6

            def h(e_d, e_o):
                return nd.J(*_cart(e_d, e_o, th, s)) @ v

            D = np.stack([(h(ED + hstep, EO) - h(ED - hstep, EO)) / (2 * hstep), np.zeros(ED.shape + (3,)),
                          (h(ED, EO + hstep) - h(ED, EO - hstep)) / (2 * hstep)], axis=-1)
            best = max(best, float(np.max(np.linalg.norm(D, ord=2, axis=(-2, -1)))))
    assert best <= b.bound * (1 + 1e-6)
    assert b.bound <= best * (1 + GAP) + 1e-9


# ----------------------------------------------------------------------------- soundness properties
def _point(reg: Region, data, s_idx: int):
    s = reg.hemisphere_signs[s_idx % len(reg.hemisphere_signs)]
    e_d = data.draw(st.floats(*reg.e_d))
    e_o = data.draw(st.floats(*reg.e_o))
    return e_d, e_o, s


def _ball(data, radius: float, dim: int) -> np.ndarray:
    v = np.array([data.draw(st.floats(-1, 1)) for _ in range(dim)])
    n = np.linalg.norm(v)
    scale = data.draw(st.one_of(st.just(1.0), st.floats(0, 1)))  # the boundary of the ball, often
    return np.zeros(dim) if n == 0 else v / n * radius * scale


REGION_LAW = st.sampled_from([(r, law) for r in REGIONS for law in ("paper", "corrected")])


@settings(derandomize=True, max_examples=300, deadline=None)
@given(rl=REGION_LAW, data=st.data(), theta=st.floats(-math.pi, math.pi), s_idx=st.integers(0, 1))
def test_no_sampled_xi_exceeds_xi_bar(rl, data, theta, s_idx):
    """Property: ||xi(e_x, e_y, psi, omega)|| <= xi_bar for every sampled point of R, bearing and omega in Omega."""
    name, law = rl
    reg = REGIONS[name]
    e_d, e_o, s = _point(reg, data, s_idx)
    om = _ball(data, reg.omega_bar, 3)
    xi = numeric().xi(*_cart(e_d, e_o, theta, s), *om)
    assert np.linalg.norm(xi) <= bounds(name, law)["xi_bar"].bound * (1 + 1e-12)


def _pair(reg: Region, data, s_idx: int):
    """Two points of R in one hemisphere: far apart or (often) close, so the ratio probes the derivative."""
    e1 = _point(reg, data, s_idx)
    if data.draw(st.booleans()):
        return e1, _point(reg, data, s_idx)
    a = data.draw(st.floats(0, 2 * math.pi))
    d = data.draw(st.floats(1e-5, 1e-2))
    e_d = min(max(e1[0] + d * math.cos(a), reg.e_d[0]), reg.e_d[1])
    e_o = min(max(e1[1] + d * math.sin(a), reg.e_o[0]), reg.e_o[1])
    return e1, (e_d, e_o, e1[2])


@settings(derandomize=True, max_examples=400, deadline=None)
@given(rl=REGION_LAW, data=st.data(), th1=st.floats(-math.pi, math.pi), th2=st.floats(-math.pi, math.pi),
       s_idx=st.integers(0, 1), su=st.sampled_from([-1.0, 1.0]), sw=st.floats(-1, 1), sr=st.floats(-1, 1))
def test_no_sampled_pair_beats_l1(rl, data, th1, th2, s_idx, su, sw, sr):
    """Property: ||J(e1) v - J(e2) v|| <= L1 ||e1 - e2|| for pairs in R (same hemisphere, any
    bearings: J depends on e only) and v in V."""
    name, law = rl
    reg = REGIONS[name]
    e1, e2 = _pair(reg, data, s_idx)
    v = np.array([su, sw, sr]) * np.array(reg.v_max)
    nd = numeric()
    d = nd.J(*_cart(e1[0], e1[1], th1, e1[2])) @ v - nd.J(*_cart(e2[0], e2[1], th2, e2[2])) @ v
    de = math.hypot(e1[0] - e2[0], e1[1] - e2[1])
    assert np.linalg.norm(d) <= bounds(name, law)["L1"].bound * de * (1 + 1e-9) + 1e-15


@settings(derandomize=True, max_examples=400, deadline=None)
@given(rl=REGION_LAW, data=st.data(), theta=st.floats(-math.pi, math.pi), s_idx=st.integers(0, 1),
       gam=st.floats(0, 2 * math.pi), rad=st.one_of(st.just(1.0), st.floats(0, 1)), zs=st.floats(-1, 1))
def test_no_sampled_pair_beats_l2(rl, data, theta, s_idx, gam, rad, zs):
    """Property: ||zeta(e1, theta) - zeta(e2, theta)|| <= L2 ||e1 - e2|| for pairs in R at a common
    bearing and a common p_d_dot in P."""
    name, law = rl
    reg = REGIONS[name]
    e1, e2 = _pair(reg, data, s_idx)
    h = reg.pd_dot_xy_max * rad
    pd = np.array([h * math.cos(gam), h * math.sin(gam), zs * reg.pd_dot_max[2]])
    pd[:2] = np.clip(pd[:2], -np.array(reg.pd_dot_max[:2]), reg.pd_dot_max[:2])
    nd = numeric()
    d = nd.zeta(*_cart(e1[0], e1[1], theta, e1[2]), *pd) - nd.zeta(*_cart(e2[0], e2[1], theta, e2[2]), *pd)
    de = math.hypot(e1[0] - e2[0], e1[1] - e2[1])
    assert np.linalg.norm(d) <= bounds(name, law)["L2"].bound * de * (1 + 1e-9) + 1e-15


@settings(derandomize=True, max_examples=300, deadline=None)
@given(rl=REGION_LAW, data=st.data(), theta=st.floats(-math.pi, math.pi), s_idx=st.integers(0, 1))
def test_no_sampled_gain_beats_j_lower_or_the_row_bounds(rl, data, theta, s_idx):
    """Property: lambda_min(sym(J K)) >= J_lower, ||row_i K|| <= K_row_i and ||J K|| <= JK_norm at
    sampled points of R, with K from the numeric law in tubekit.model.ancillary."""
    name, law = rl
    reg = REGIONS[name]
    e_d, e_o, s = _point(reg, data, s_idx)
    J = numeric().J(*_cart(e_d, e_o, theta, s))
    K = LAWS[law].gain_of_jacobian(J)
    JK = J @ K
    b = bounds(name, law)
    assert np.linalg.eigvalsh((JK + JK.T) / 2)[0] >= b["J_lower"].bound - 1e-12
    for i, ax in enumerate("uwr"):
        assert np.linalg.norm(K[i]) <= b[f"K_row_{ax}"].bound * (1 + 1e-12)
    assert np.linalg.norm(JK, 2) <= b["JK_norm"].bound * (1 + 1e-12)


@settings(derandomize=True, max_examples=300, deadline=None)
@given(rl=REGION_LAW, data=st.data(), th1=st.floats(-math.pi, math.pi), dth=st.floats(-math.pi, math.pi),
       s_idx=st.integers(0, 1), gam=st.floats(0, 2 * math.pi))
def test_no_sampled_bearing_mismatch_beats_the_fold(rl, data, th1, dth, s_idx, gam):
    """Property: ||zeta(e, theta) - zeta(e, theta_hat)|| <= zeta_theta * 2 |sin((theta - theta_hat)/2)| at
    the same error e (the bound the certificate folds into xi_tilde)."""
    name, law = rl
    reg = REGIONS[name]
    e_d, e_o, s = _point(reg, data, s_idx)
    h = reg.pd_dot_xy_max
    pd = np.array([h * math.cos(gam), h * math.sin(gam), 0.0])
    nd = numeric()
    d = nd.zeta(*_cart(e_d, e_o, th1, s), *pd) - nd.zeta(*_cart(e_d, e_o, th1 + dth, s), *pd)
    assert np.linalg.norm(d) <= bounds(name, law)["zeta_theta"].bound * 2 * abs(math.sin(dth / 2)) + 1e-12


def test_every_bound_states_its_set_and_gap():
    b = bounds("paper", "corrected")
    for name in ("L1", "L2", "J_lower", "xi_bar"):
        br = b[name]
        assert "e in R" in br.holds_over and "e_d in [0.1, 3]" in br.holds_over
        assert br.converged and br.gap <= GAP
        d = br.to_dict()
        assert {"sampled", "bound"} <= set(d)
    assert "omega" in b["xi_bar"].holds_over and "v_hat in V" in b["L1"].holds_over
    assert "p_d_dot" in b["L2"].holds_over


def test_an_exhausted_budget_is_reported_not_hidden():
    reg = REGIONS["paper"].replace(e_d=(0.1234, 2.5))  # fresh region: not in the cache
    b = compute_bounds(reg, "paper", gap=1e-6, max_boxes=3)
    assert not b["L1"].converged
    assert b["L1"].gap > 1e-6
    assert b["L1"].bound >= b["L1"].sampled


def test_names_selects_a_subset_with_the_same_values():
    full = bounds("certifiable", "corrected")
    part = compute_bounds(REGIONS["certifiable"], "corrected", gap=GAP, max_boxes=20000, names=("J_lower", "xi_bar"))
    assert set(part.items) == {"J_lower", "xi_bar"}
    assert part["xi_bar"].bound == full["xi_bar"].bound and part["J_lower"].bound == full["J_lower"].bound == 1.0


@pytest.mark.parametrize("names, match", [
    (("L1", "L3"), r"names: expected a non-empty tuple of names in .*received 'L3'"),
    ((), r"names: expected a non-empty tuple"),
    ("L1", r"names: expected a non-empty tuple"),
])
def test_names_refuses_unknown(names, match):
    with pytest.raises(ConfigError, match=match):
        compute_bounds(REGIONS["paper"], "paper", names=names)
