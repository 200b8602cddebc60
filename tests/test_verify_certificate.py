"""Tests of verify.certificate: outcomes, named failures, the algebra, the FHOCP hand-off.

Expected numbers are recomputed here from the bounds and the scenario (or from
the paper's data), not copied from the code under test.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace

import numpy as np
import pytest

from tubekit.ancillary import LAWS
from tubekit.derivation import error_coordinates
from tubekit.model import kinematics
from tubekit.scenario import ControllerSettings, paper_scenario
from tubekit.tightening import Tightening
from verify import Certificate, NotCertifiedError, Region, certifiable_scenario, certify
from verify import bounds as vb

REQUIRED_KEYS = {"certified", "law", "region", "bounds", "sigma", "rho", "v_bar", "horizon", "failures",
                 "assumptions", "elapsed_s"}


@pytest.fixture(scope="module")
def paper_paper() -> Certificate:
    return certify(paper_scenario(), "paper")


@pytest.fixture(scope="module")
def paper_corrected() -> Certificate:
    return certify(paper_scenario(), "corrected")


@pytest.fixture(scope="module")
def cert_ok() -> Certificate:
    return certify(certifiable_scenario(), "corrected")


def _failure(cert: Certificate, name: str) -> dict:
    found = [f for f in cert.failures if f["condition"] == name]
    assert found, f"{name} not among {[f['condition'] for f in cert.failures]}"
    return found[0]


# --------------------------------------------------------------------------- the paper's scenario
def test_paper_law_is_not_certified_with_named_inequalities(paper_paper):
    c = paper_paper
    assert not c.certified and not c.is_certified
    names = {f["condition"] for f in c.failures}
    assert {"J_lower", "sigma", "keep_up_real[u]", "horizon"} <= names
    jl = _failure(c, "J_lower")
    assert jl["lhs"] < 0 and jl["rhs"] == 0 and "Remark 1" in jl["inequality"]
    sg = _failure(c, "sigma")
    L1, L2 = c.bounds["L1"].bound, c.bounds["L2"].bound
    assert sg["rhs"] == pytest.approx(L1 + L2) and sg["lhs"] == 0.0
    # keep-up of the real vehicle: u_max = 0.4 vs target speed 3 pi / 25 + omega_bar (paper data)
    ku = _failure(c, "keep_up_real[u]")
    assert ku["lhs"] == 0.4
    assert ku["rhs"] == pytest.approx(3 * math.pi / 25 + math.sqrt(0.02) + 0.02, rel=1e-9)
    for f in c.failures:
        assert set(f) == {"condition", "inequality", "lhs", "rhs", "detail"}
    assert c.sigma["value"] is None and c.rho["rho_tilde"] is None
    assert "v_bar[u]" in c.not_evaluated


def test_horizon_condition_recomputed(paper_paper):
    c = paper_paper
    s = paper_scenario()
    xi_t = c.rho["xi_tilde"]
    t_max = s.sensing_range / (math.sqrt(0.4**2 + 0.3**2 + 0.5**2) + xi_t)
    assert c.horizon["T"] == pytest.approx(0.8)
    assert c.horizon["T_max"] == pytest.approx(t_max, rel=1e-12) and c.horizon["T_max"] <= t_max
    assert c.horizon["ok"] is False
    # even without the bearing fold, the printed condition fails: 1.5 / (0.7071 + omega_bar / eps) < 0.8
    assert 1.5 / (math.sqrt(0.5) + (math.sqrt(0.02) + 0.02) / 0.1) < 0.8


def test_bearing_fold_recomputed(paper_paper):
    c = paper_paper
    reg = c.region
    dtheta = 0.1 * (2 * 0.4 + 2 * reg.pd_dot_xy_max + reg.omega_bar) / reg.e_d[0]
    fold = c.bounds["zeta_theta"].bound * 2 * math.sin(min(dtheta, math.pi) / 2)
    assert c.rho["delta_theta"] == pytest.approx(dtheta, rel=1e-12)
    assert c.rho["bearing_fold"] == pytest.approx(fold, rel=1e-12)
    assert c.rho["xi_tilde"] == pytest.approx(c.bounds["xi_bar"].bound + fold, rel=1e-12)
    assert c.rho["xi_tilde"] >= c.bounds["xi_bar"].bound + fold


def test_corrected_law_fails_on_inputs_in_the_paper_scenario(paper_corrected):
    c = paper_corrected
    assert not c.certified
    names = {f["condition"] for f in c.failures}
    assert {"v_bar[u]", "v_bar[r]", "keep_up_nominal[u]", "keep_up_real[u]", "horizon"} <= names
    assert "J_lower" not in names and "sigma" not in names
    b = c.bounds
    sig = c.sigma["value"]
    assert c.sigma["min"] == pytest.approx((b["L1"].bound + b["L2"].bound) / b["J_lower"].bound, rel=1e-12)
    assert c.sigma["max"] == pytest.approx(100.0 / b["JK_norm"].bound, rel=1e-12)
    assert sig == pytest.approx(c.sigma["max"])
    rho = c.rho["xi_tilde"] / (sig * b["J_lower"].bound - b["L1"].bound - b["L2"].bound)
    assert c.rho["rho_tilde"] == pytest.approx(rho, rel=1e-12) and c.rho["rho_tilde"] >= rho
    kappa_r = sig * b["K_row_r"].bound * c.rho["rho_tilde"]
    assert _failure(c, "v_bar[r]")["lhs"] == pytest.approx(0.5 - kappa_r, rel=1e-9)


# --------------------------------------------------------------------------- the certifiable scenario
def test_certifiable_scenario_certifies(cert_ok):
    c = cert_ok
    assert c.certified and c.failures == [] and c.not_evaluated == []
    assert all(cond.ok for cond in c.conditions)
    b = c.bounds
    rho = c.rho["rho_tilde"]
    sig = c.sigma["value"]
    assert sig * b["J_lower"].bound > b["L1"].bound + b["L2"].bound
    for i, ax in enumerate("uwr"):
        assert c.v_bar[i] == pytest.approx(c.region.v_max[i] - sig * b[f"K_row_{ax}"].bound * rho, rel=1e-9)
        assert c.v_bar[i] > 0
    assert c.v_bar[0] >= c.region.pd_dot_xy_max
    assert c.e_bar["e_d"][0] == pytest.approx(c.region.e_d[0] + rho)
    assert c.horizon["ok"] and c.horizon["T"] <= c.horizon["T_max"]


def test_tightening_of_a_certified_design(cert_ok):
    t = cert_ok.tightening()
    assert isinstance(t, Tightening)
    np.testing.assert_allclose(t.v_max, cert_ok.v_bar)
    rho = cert_ok.rho["rho_tilde"]
    assert t.rho_tilde == rho and t.sigma == cert_ok.sigma["value"]
    assert t.e_d_min == pytest.approx(0.5 + rho) and t.e_o_max == pytest.approx(0.5 - rho)
    assert t.e_z_max == pytest.approx(1.0 - rho) and t.e_d_max == pytest.approx(3.0 - rho)
    assert t.obstacle_margin == cert_ok.obstacle_margin > 0


@pytest.mark.parametrize("fixture", ["paper_paper", "paper_corrected"])
def test_tightening_of_an_uncertified_design(fixture, request):
    c = request.getfixturevalue(fixture)
    with pytest.raises(NotCertifiedError, match="not certified"):
        c.tightening()
    t = c.tightening(allow_uncertified=True)
    v = np.array(c.region.v_max)
    assert np.all(t.v_max >= 0.5 * v - 1e-12) and np.all(t.v_max <= v)
    assert t.v_max[0] >= min(c.region.pd_dot_xy_max, v[0]) - 1e-12  # nominal can keep up
    assert c.region.e_d[0] < t.e_d_min < t.e_d_max < c.region.e_d[1]
    assert 0 < t.e_o_max < 0.9 and 0 < t.e_z_max < 1.0
    assert 0 <= t.obstacle_margin <= paper_scenario().vehicle_radius
    assert t.sigma > 0 and math.isfinite(t.rho_tilde)


def test_fixed_sigma_outside_the_admissible_range_is_named():
    s = certifiable_scenario()
    low = s.with_changes(controller=replace(s.controller, sigma=1.0))
    c = certify(low, "corrected")
    f = _failure(c, "sigma")
    b = c.bounds
    assert f["lhs"] == 1.0 and f["rhs"] == pytest.approx(b["L1"].bound + b["L2"].bound, rel=1e-9)
    high = s.with_changes(controller=replace(s.controller, sigma=150.0))
    c2 = certify(high, "corrected")
    f2 = _failure(c2, "sigma_sampled")
    assert f2["lhs"] == 150.0 and f2["rhs"] == pytest.approx(100.0)


def test_terminal_set_failure_is_named():
    s = certifiable_scenario()
    c = certify(s.with_changes(controller=replace(s.controller, terminal_level=1.0)), "corrected")
    f = _failure(c, "terminal")
    # min over E_bar of ||e||_P = sqrt(P_dd) (epsilon + rho) with P = diag(5, 5, 2.5)
    assert f["lhs"] == pytest.approx(math.sqrt(5.0) * (0.5 + c.rho["rho_tilde"]), rel=1e-9)
    assert f["rhs"] == 1.0


def test_region_override_is_used():
    s = certifiable_scenario()
    reg = Region.from_scenario(s, e_o=(-0.3, 0.3))
    c = certify(s, "corrected", region=reg)
    assert c.region.e_o == (-0.3, 0.3)
    assert "e_o in [-0.3, 0.3]" in c.bounds["L1"].holds_over


# --------------------------------------------------------------------------- serialisation
@pytest.mark.parametrize("fixture", ["paper_paper", "paper_corrected", "cert_ok"])
def test_to_dict_is_strict_json_with_the_issue_keys(fixture, request):
    c = request.getfixturevalue(fixture)
    d = c.to_dict()
    assert REQUIRED_KEYS <= set(d)
    json.dumps(d, allow_nan=False)
    assert d["certified"] is c.certified and d["law"] == c.law
    assert {"e_d", "e_z", "e_o", "heading", "pd_dot_max", "omega_bar", "v_max"} <= set(d["region"])
    for name in ("L1", "L2", "J_lower", "xi_bar"):
        assert {"sampled", "bound"} <= set(d["bounds"][name])
    assert {"T", "T_max", "ok"} <= set(d["horizon"])
    assert isinstance(d["assumptions"], list) and len(d["assumptions"]) >= 5
    assert any("bearing" in a for a in d["assumptions"])
    assert any("continuous-time" in a for a in d["assumptions"])


def test_summary_names_the_failures(paper_paper):
    text = paper_paper.summary()
    assert "NOT CERTIFIED" in text
    for f in paper_paper.failures:
        assert f["condition"] in text
    assert "Assumptions" in text and "L1" in text


# --------------------------------------------------------------------------- closed-loop tube check
def _simulate_period(cert: Certificate, scenario, n: int, seed: int):
    """Real and nominal vehicles over one FHOCP period from a common state (the reset).

    RK4 with step 1e-3 s (sigma * step = 0.1). Constant omega on the sphere ||omega|| = omega_bar,
    constant nominal input v_hat in V_bar, the corrected law's gain from tubekit.ancillary.
    Returns max ||rho||, max |v_i| / V_i and max ||p - p_hat|| per run (runs whose real error leaves
    R are dropped: the certificate says nothing about them).
    """
    rng = np.random.default_rng(seed)
    reg = cert.region
    sigma = cert.sigma["value"]
    law = LAWS["corrected"]
    traj = scenario.trajectory
    t0 = rng.uniform(0, 100, n)
    e_d = rng.uniform(0.6, 2.8, n)
    e_o = rng.uniform(-0.45, 0.45, n)
    e_z = rng.uniform(-0.9, 0.9, n)
    th = rng.uniform(-np.pi, np.pi, n)
    pd0 = traj.position(t0)
    x = np.stack([pd0[:, 0] + e_d * np.cos(th), pd0[:, 1] + e_d * np.sin(th), pd0[:, 2] + e_z,
                  th + np.pi - np.arcsin(e_o)], axis=1)
    xh = x.copy()
    om = rng.normal(size=(n, 3))
    om *= reg.omega_bar / np.linalg.norm(om, axis=1, keepdims=True)
    vh = rng.uniform(-1, 1, (n, 3)) * cert.v_bar

    def rhs(t, X, XH):
        pd = traj.position(t)
        rho = error_coordinates(X, pd) - error_coordinates(XH, pd)
        K = law.gain(X, pd)
        kappa = -sigma * np.einsum("nij,nj->ni", K, rho)
        v = vh + kappa
        return kinematics(X, v, om), kinematics(XH, vh, np.zeros_like(om)), v

    h = 1e-3
    max_rho = np.zeros(n)
    max_v = np.zeros(n)
    max_p = np.zeros(n)
    inside = np.ones(n, dtype=bool)
    for k in range(int(round(scenario.controller.dt / h))):
        t = t0 + k * h
        k1, q1, v1 = rhs(t, x, xh)
        k2, q2, _ = rhs(t + h / 2, x + h / 2 * k1, xh + h / 2 * q1)
        k3, q3, _ = rhs(t + h / 2, x + h / 2 * k2, xh + h / 2 * q2)
        k4, q4, _ = rhs(t + h, x + h * k3, xh + h * q3)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        xh = xh + h / 6 * (q1 + 2 * q2 + 2 * q3 + q4)
        pd = traj.position(t + h)
        e, eh = error_coordinates(x, pd), error_coordinates(xh, pd)
        bearing = np.arctan2(x[:, 1] - pd[:, 1], x[:, 0] - pd[:, 0])
        inside &= (e[:, 0] >= reg.e_d[0]) & (np.abs(e[:, 2]) <= reg.e_o[1]) & (np.cos(x[:, 3] - bearing) < 0)
        max_rho = np.maximum(max_rho, np.linalg.norm(e - eh, axis=1))
        max_v = np.maximum(max_v, np.max(np.abs(v1) / np.array(reg.v_max), axis=1))
        max_p = np.maximum(max_p, np.linalg.norm(x[:, :3] - xh[:, :3], axis=1))
    return max_rho[inside], max_v[inside], max_p[inside]


def test_simulated_tube_stays_inside_rho_tilde(cert_ok):
    """Lemma 1 + the bearing fold, checked by simulation over one FHOCP period of the certifiable
    scenario: ||e - e_hat|| <= rho_tilde, the real input stays in V, and ||p - p_hat|| stays within
    the obstacle margin."""
    s = certifiable_scenario()
    rho, v, p = _simulate_period(cert_ok, s, n=300, seed=11)
    assert len(rho) >= 250
    assert np.max(rho) <= cert_ok.rho["rho_tilde"]
    assert np.max(v) <= 1.0 + 1e-9
    assert np.max(p) <= cert_ok.obstacle_margin
    assert np.max(rho) > 0  # the disturbance did push the real vehicle off the nominal


def test_a_wrong_sign_law_would_break_the_tube(cert_ok):
    """The simulation check can fail: with kappa of the opposite sign the tube is left."""
    cert_bad = replace(cert_ok, sigma=dict(cert_ok.sigma, value=-cert_ok.sigma["value"]))
    rho, _, _ = _simulate_period(cert_bad, certifiable_scenario(), n=60, seed=5)
    assert np.max(rho) > cert_ok.rho["rho_tilde"]


# --------------------------------------------------------------------------- performance
def test_paper_scenario_certifies_within_the_budget():
    """Issue 3: the paper's scenario certifies (to the 5 % gap) in <= 30 s; caches cleared first."""
    for fn in (vb._solve, vb._compiled, vb.polar_model, vb.law_gain):
        fn.cache_clear()
    for law in ("paper", "corrected"):
        t0 = time.perf_counter()
        c = certify(paper_scenario(), law)
        elapsed = time.perf_counter() - t0
        assert elapsed <= 30.0
        assert all(c.bounds[n].converged for n in ("L1", "L2", "J_lower", "xi_bar"))


def test_controller_defaults_are_the_papers():
    # guards the interpretation of the paper scenario used above
    c = ControllerSettings()
    assert c.dt == 0.1 and c.horizon_steps == 8 and c.ancillary_rate_hz == 100.0
