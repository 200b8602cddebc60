"""Tests of verify.theorem.sampled: the one-period tube under the nominal reset, and the per-arc margins.

The soundness test simulates one FHOCP period of the real sampled-data loop with an integrator
written here (not tubekit.loop.closed_loop): reset x_hat = x at t_k, the nominal arc under a constant
v_hat in V_bar, kappa from the law held over each tick of 1/f s, the plant x_dot = f(x) v + omega with
omega at the certificate's bound and chosen adversarially tick by tick. The closed forms (sigma = 0,
the decoupled e_z channel) are derived by hand in the docstrings.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import verify
from tubekit.model.ancillary import get_law
from tubekit.scenario import load_scenario
from verify.theorem.sampled import HorizonMargins, PeriodTube, TubeProblem, horizon_margins, one_period_tube

SHIPPED = ("paper_currents.toml", "certifiable.toml")
#: Relative inflation of the certified fixed point (documented in verify.theorem.sampled), plus rounding.
INFLATION = 2e-6


@pytest.fixture(scope="module")
def certs() -> dict:
    out = {}
    for name in SHIPPED:
        sc = load_scenario(verify.SCENARIOS_DIR / name)
        out[name] = (sc, verify.certify(sc))
    # paper_currents chooses sigma = 0; its sigma = 3.125 design (also certified) exercises the feedback
    sc = out["paper_currents.toml"][0]
    sc = sc.with_changes(controller=replace(sc.controller, sigma=3.125))
    out["paper_currents.toml@3.125"] = (sc, verify.certify(sc))
    return out


def _problem(**changes) -> TubeProblem:
    """A hand-built problem: the corrected law over |e_o| <= 0.5, e_d >= 0.5 (G = I, K as the closed forms)."""
    k_ro = 0.5 / (math.sqrt(0.75) * 0.5)
    base = TubeProblem(eps=0.5, e_o_max=0.5, u_max=0.4, w_max=0.3, r_max=0.5, omega_xy=0.12, omega_z=0.1,
                       pd_xy=0.1885, pd_z=0.0, sigma=0.0, tick=0.01, ticks=10,
                       k_abs=((1 / math.sqrt(0.75), 0.0, 0.0), (0.0, 1.0, 0.0), (k_ro, 0.0, 1 / math.sqrt(0.75))),
                       g_lo=(1.0, 1.0, 1.0), g_hi=(1.0, 1.0, 1.0),
                       g_off=((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
    return replace(base, **changes)


# --------------------------------------------------------------------------- independent simulation
def _rhs(x, v, om):
    """Kinematics eq. (11), written here: [u cos psi + w1, u sin psi + w2, w + w3, r]."""
    return np.array([v[0] * math.cos(x[3]) + om[0], v[0] * math.sin(x[3]) + om[1], v[1] + om[2], v[2]])


def _rk4(x, v, om, h):
    k1 = _rhs(x, v, om)
    k2 = _rhs(x + h / 2 * k1, v, om)
    k3 = _rhs(x + h / 2 * k2, v, om)
    k4 = _rhs(x + h * k3, v, om)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def _errors(x, pd):
    """e = [e_d, e_z, e_o] with e_o = sin(psi - theta), theta the bearing of the vehicle from the target."""
    dx, dy = x[0] - pd[0], x[1] - pd[1]
    ed = math.hypot(dx, dy)
    return np.array([ed, x[2] - pd[2], math.sin(x[3] - math.atan2(dy, dx))])


def _omega(mode, x, pd, rho, tube, wxy, wz, angle, zsign, tick):
    """The disturbance of one tick at its full bound (||omega_xy|| = wxy, |omega_z| = wz).

    d e_d / dt gets omega . n_r and d e_o / dt gets -cos(psi - theta) omega . n_t / e_d
    (n_r radial, n_t tangential unit vectors): the greedy modes push one of them.
    """
    n_r = np.array([x[0] - pd[0], x[1] - pd[1]])
    n_r /= np.linalg.norm(n_r)
    n_t = np.array([-n_r[1], n_r[0]])
    cos_rel = math.cos(x[3] - math.atan2(n_r[1], n_r[0]))
    o_dir = -math.copysign(1.0, cos_rel) * n_t          # increases e_o
    ratio = np.abs(rho) / tube
    if mode == "const":
        d = np.array([math.cos(angle[0]), math.sin(angle[0])])
    elif mode == "piecewise":   # one direction per tick
        a = angle[tick % len(angle)]
        d = np.array([math.cos(a), math.sin(a)])
    elif mode in ("d+", "d-"):
        d = n_r if mode == "d+" else -n_r
    elif mode in ("o+", "o-"):
        d = o_dir if mode == "o+" else -o_dir
    else:  # "ratio": push the axis that is furthest out in its own direction
        j = 0 if ratio[0] >= ratio[2] else 2
        s = 1.0 if rho[j] >= 0 else -1.0
        d = s * (n_r if j == 0 else o_dir)
        zsign = 1.0 if rho[1] >= 0 else -1.0
    return np.array([wxy * d[0], wxy * d[1], zsign * wz])


def simulate_period(sc, cert, x0, t0, v_hat, mode, angle=(0.0,), zsign=1.0, substeps=5):
    """One period of the loop; returns (max_j |e_j - e_hat_j| / tube_j, max_i |kappa_i| / kappa_bar_i,
    whether e stayed in R, whether e_hat stayed in R shrunk by the tube)."""
    law = get_law(sc.controller.law)
    sigma = cert.sigma.value
    ticks = int(round(sc.controller.ancillary_rate_hz * sc.controller.dt))
    h = sc.controller.dt / ticks
    tube = np.asarray(cert.tube.rho)
    kbar = np.asarray(cert.kappa_bar)
    wxy, wz = cert.disturbance.omega_xy, cert.disturbance.omega_z
    reg = cert.region
    x, xh = np.array(x0, dtype=float), np.array(x0, dtype=float)   # the reset
    worst, kworst, in_r, nominal_ok = 0.0, 0.0, True, True
    for i in range(ticks):
        t = t0 + i * h
        pd = sc.trajectory.position(t)
        rho = _errors(x, pd) - _errors(xh, pd)
        kappa = law(x, xh, pd, sigma)
        # |kappa_i| <= kappa_bar_i; where kappa_bar_i = 0 (sigma = 0) kappa_i must be exactly 0
        ratio = np.where(kbar > 0, np.abs(kappa) / np.where(kbar > 0, kbar, 1.0), np.where(kappa == 0, 0.0, np.inf))
        kworst = max(kworst, float(np.max(ratio)))
        om = _omega(mode, x, pd, rho, tube, wxy, wz, angle, zsign, i)
        v = np.asarray(v_hat) + kappa
        for s in range(substeps):
            x, xh = _rk4(x, v, om, h / substeps), _rk4(xh, v_hat, np.zeros(3), h / substeps)
            pd = sc.trajectory.position(t + (s + 1) * h / substeps)
            e, eh = _errors(x, pd), _errors(xh, pd)
            worst = max(worst, float(np.max(np.abs(e - eh) / tube)))
            in_r &= reg.e_d[0] <= e[0] <= reg.e_d[1] and abs(e[1]) <= reg.e_z[1] and abs(e[2]) <= reg.e_o[1]
            nominal_ok &= (reg.e_d[0] + tube[0] <= eh[0] <= reg.e_d[1] - tube[0]
                           and abs(eh[1]) <= reg.e_z[1] - tube[1] and abs(eh[2]) <= reg.e_o[1] - tube[2])
    return worst, kworst, in_r, nominal_ok


@st.composite
def period_cases(draw, name: str):
    """A state with e in R shrunk by the tube (toward hemisphere), a time, v_hat in V_bar, an adversary
    (a constant or per-tick direction at the bound, or a greedy one)."""
    return dict(name=name, fd=draw(st.floats(0.0, 1.0)), fz=draw(st.floats(-1.0, 1.0)),
                fo=draw(st.floats(-1.0, 1.0)), theta=draw(st.floats(-math.pi, math.pi)),
                t0=draw(st.floats(0.0, 100.0)),
                v=draw(st.tuples(*[st.floats(-1.0, 1.0)] * 3)),
                mode=draw(st.sampled_from(["const", "piecewise", "d+", "d-", "o+", "o-", "ratio"])),
                angle=draw(st.lists(st.floats(-math.pi, math.pi), min_size=10, max_size=10)),
                zsign=draw(st.sampled_from([-1.0, 1.0])))


def _state(sc, cert, case):
    reg, tube = cert.region, np.asarray(cert.tube.rho)
    ed = reg.e_d[0] + tube[0] + case["fd"] * (reg.e_d[1] - reg.e_d[0] - 2 * tube[0])
    ez = case["fz"] * (reg.e_z[1] - tube[1])
    eo = case["fo"] * (reg.e_o[1] - tube[2])
    pd = sc.trajectory.position(case["t0"])
    th = case["theta"]
    psi = th + math.pi - math.asin(eo)      # sin(psi - theta) = e_o, cos(psi - theta) < 0 (toward)
    return np.array([pd[0] + ed * math.cos(th), pd[1] + ed * math.sin(th), pd[2] + ez, psi])


def _check_case(certs, case):
    sc, cert = certs[case["name"]]
    x0 = _state(sc, cert, case)
    v_hat = np.asarray(case["v"]) * cert.v_bar
    worst, kworst, in_r, nominal_ok = simulate_period(sc, cert, x0, case["t0"], v_hat, case["mode"],
                                                      case["angle"], case["zsign"])
    assume(nominal_ok)  # the theorem's premise: the nominal arc stays in R shrunk by the tube
    assert worst <= 1.0, f"deviation/radius {worst} > 1"
    assert kworst <= 1.0, f"|kappa| / kappa_bar {kworst} > 1"
    assert in_r


@given(case=period_cases("paper_currents.toml"))
def test_one_period_tube_is_sound_paper_currents(certs, case):
    """Property: over one period of the sampled-data loop (paper_currents), every adversary at the
    disturbance bound keeps max_j |e_j - e_hat_j| / tube_j <= 1 and |kappa_i| <= kappa_bar_i."""
    _check_case(certs, case)


@given(case=period_cases("paper_currents.toml@3.125"))
def test_one_period_tube_is_sound_paper_currents_with_feedback(certs, case):
    """Property: the same for paper_currents with sigma = 3.125 1/s fixed (certified too; feedback on)."""
    _check_case(certs, case)


@given(case=period_cases("certifiable.toml"))
def test_one_period_tube_is_sound_certifiable(certs, case):
    """Property: the same for certifiable.toml (sigma h = 1, the deadbeat edge)."""
    _check_case(certs, case)


@pytest.mark.parametrize("name", SHIPPED)
def test_the_greedy_adversary_nearly_fills_the_tube(certs, name):
    """The simulation is not vacuous: the greedy adversary reaches a large part of the tube, and a
    doubled disturbance (outside the certificate) leaves it."""
    sc, cert = certs[name]
    case = dict(name=name, fd=0.3, fz=0.0, fo=0.6, theta=0.4, t0=3.0, v=(0.5, 0.0, -0.5), mode="ratio",
                angle=(0.0,), zsign=1.0)
    x0 = _state(sc, cert, case)
    worst, _, _, ok = simulate_period(sc, cert, x0, 3.0, np.asarray(case["v"]) * cert.v_bar, "ratio")
    assert ok and 0.9 < worst <= 1.0
    d = cert.disturbance
    doubled = replace(cert, disturbance=replace(d, omega_xy=2 * d.omega_xy, omega_z=2 * d.omega_z))
    bad, _, _, _ = simulate_period(sc, doubled, x0, 3.0, np.asarray(case["v"]) * cert.v_bar, "ratio")
    assert bad > 1.0


# --------------------------------------------------------------------------- closed forms
def test_sigma_zero_gives_the_open_loop_drift():
    """Without feedback over delta = 0.1 s: |dz| <= omega_z delta, ||dp_xy|| <= omega_xy delta, so
    rho_z = omega_z delta, rho_d = omega_xy delta, the bearing moves by at most asin(omega_xy delta / eps)
    and rho_o = theta (the heading does not move); all up to the 1e-6 inflation."""
    p = _problem()
    t = one_period_tube(p)
    assert t.certified and t.reason == ""
    delta = 0.1
    th = math.asin(0.12 * delta / 0.5)
    expected = (0.12 * delta, 0.1 * delta, th)
    for got, want in zip(t.rho, expected):
        assert want <= got <= want * (1 + INFLATION) + 1e-11
    assert th <= t.theta <= th * (1 + INFLATION) + 1e-11
    assert t.kappa == (0.0, 0.0, 0.0) and t.psi == 0.0
    assert t.p_xy == pytest.approx(0.12 * delta, rel=1e-12) and t.p_z == pytest.approx(0.1 * delta, rel=1e-12)


@given(sh=st.floats(0.05, 1.0), wz=st.floats(0.001, 0.2))
def test_z_channel_equals_the_zoh_recursion(sh, wz):
    """Property: e_z is decoupled (row z of J and K is e_z's own), so under ZOH rho_z(t_{i+1}) =
    (1 - sigma h) rho_z(t_i) + h omega_z and the tube's rho_z is h omega_z sum_{k<m} (1 - sigma h)^k."""
    h, m = 0.01, 10
    p = _problem(sigma=sh / h, omega_z=wz)
    t = one_period_tube(p)
    assert t.certified
    want = h * wz * sum((1 - sh) ** k for k in range(m))
    assert want <= t.rho[1] <= want * (1 + INFLATION) + 1e-11


@given(w1=st.floats(1e-3, 0.15), dw=st.floats(1e-3, 0.1), wz=st.floats(1e-3, 0.1),
       sigma=st.sampled_from([0.0, 3.125, 25.0]))
def test_tube_grows_with_the_disturbance(w1, dw, wz, sigma):
    """Property: a larger omega_xy gives a componentwise larger (or equal) certified tube.

    (omega >= 1e-3: a vanishing disturbance hits the bug pinned by test_a_vanishing_disturbance_certifies.)"""
    small = one_period_tube(_problem(omega_xy=w1, omega_z=wz, sigma=sigma))
    large = one_period_tube(_problem(omega_xy=w1 + dw, omega_z=wz, sigma=sigma))
    assert small.certified and large.certified
    for a, b in zip(small.rho + (small.theta,) + small.kappa, large.rho + (large.theta,) + large.kappa):
        assert b >= a * (1 - 1e-9)


@pytest.mark.parametrize("changes", [dict(omega_xy=10.0), dict(sigma=1e4), dict(omega_xy=2.0, eps=0.05)])
def test_absurd_problems_diverge(changes):
    t = one_period_tube(_problem(**changes))
    assert not t.certified and "diverge" in t.reason
    assert t.kappa == (math.inf,) * 3 and t.p_xy == math.inf


@pytest.mark.parametrize("w", [0.0, 1e-6])
def test_a_vanishing_disturbance_certifies(w):
    """No (or almost no) disturbance: the real vehicle follows the nominal; the tube must exist and be tiny."""
    t = one_period_tube(_problem(omega_xy=w, omega_z=w, sigma=25.0))
    assert t.certified
    assert max(t.rho) <= 1e-4


def test_tube_to_dict_is_plain():
    t = one_period_tube(_problem(sigma=3.125))
    d = t.to_dict()
    assert isinstance(d["rho"], list) and isinstance(d["kappa"], list) and d["certified"] is True
    pd = _problem().to_dict()
    assert pd["k_abs"][1] == [0.0, 1.0, 0.0] and pd["g_lo"] == [1.0, 1.0, 1.0] and pd["ticks"] == 10
    assert _problem().period == pytest.approx(0.1)


# --------------------------------------------------------------------------- horizon margins
def test_margins_without_feedback_are_linear_in_the_arc():
    """sigma = 0: psi = 0, so the replayed candidate drifts by p_xy = omega_xy delta per arc:
    M_d[j] = (j + 1) omega_xy delta, M_z[j] = (j + 1) omega_z delta, M_o[j] = (j + 1) asin(omega_xy delta / eps),
    M_pos[j] = (j + 1) ||(omega_xy, omega_z)|| delta."""
    p = _problem()
    m = horizon_margins(p, one_period_tube(p), 8)
    assert isinstance(m, HorizonMargins) and len(m.e_d) == 8
    j = np.arange(8) + 1
    np.testing.assert_allclose(m.e_d, j * 0.012, rtol=INFLATION)
    np.testing.assert_allclose(m.e_z, j * 0.01, rtol=INFLATION)
    np.testing.assert_allclose(m.e_o, j * math.asin(0.012 / 0.5), rtol=INFLATION)
    np.testing.assert_allclose(m.position, j * math.hypot(0.012, 0.01), rtol=INFLATION)


@given(sigma=st.floats(0.0, 40.0), wxy=st.floats(0.0, 0.12), arcs=st.integers(1, 12))
def test_margins_are_the_tube_plus_the_candidate_drifts(sigma, wxy, arcs):
    """Property: margins are non-decreasing along the horizon and M_j = M_0 + sum_{i=1..j} drift_i with
    drift_i = p_xy + u_max psi delta i for e_d (closed-form sum j p_xy + u_max psi delta j (j + 1) / 2)."""
    p = _problem(sigma=sigma, omega_xy=wxy)
    t = one_period_tube(p)
    assume(t.certified)
    m = horizon_margins(p, t, arcs)
    for col in (m.e_d, m.e_z, m.e_o, m.position):
        assert len(col) == arcs and all(b >= a for a, b in zip(col, col[1:]))
    j = np.arange(arcs)
    want_d = t.rho[0] + j * t.p_xy + p.u_max * t.psi * p.period * j * (j + 1) / 2
    np.testing.assert_allclose(m.e_d, want_d, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(m.e_z, t.rho[1] + j * t.p_z, rtol=1e-9, atol=1e-15)
    assert np.all(np.asarray(m.e_d) >= want_d * (1 - 1e-12))


def test_margins_of_the_shipped_certificate(certs):
    sc, cert = certs["paper_currents.toml"]
    m = cert.margins
    assert set(m.to_dict()) == {"e_d", "e_z", "e_o", "position"}
    assert all(len(v) == sc.controller.horizon_steps for v in m.to_dict().values())
    assert m.e_d[0] == cert.tube.rho[0] and m.e_o[0] == cert.tube.rho[2]
    assert isinstance(cert.design.tube, PeriodTube)


def test_a_yaw_rate_error_turns_the_heading_tube():
    """On the dynamic plant psi_dot = r_cmd + (velocity-loop error): the heading bound grows by dr * delta."""
    base = one_period_tube(_problem(sigma=0.0))
    t = one_period_tube(_problem(sigma=0.0, yaw_rate_error=0.1))
    assert base.psi == 0.0 and t.psi >= 0.1 * 0.1
    assert t.rho[2] > base.rho[2] and t.p_xy > base.p_xy
