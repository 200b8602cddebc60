"""Tests of verify.theorem.design: disturbance bounds, the theorem's inputs, V_bar and the named conditions.

Expected numbers are recomputed here from the scenario's data (closed forms written in the tests) or by
sampling the disturbance model directly; nothing is copied from the code under test.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import verify
from tubekit.model.kinematics import InputLimits, SwayModel
from tubekit.scenario import Disturbance, load_scenario
from verify.theorem.design import (Condition, Design, arc_rates, disturbance_bounds, evaluate_design, tube_problem)
from verify.theorem.gains import gain_bounds
from verify.kernel.region import Region


@pytest.fixture(scope="module")
def pc():
    """paper_currents: scenario, region, corrected-law gains, disturbance bounds."""
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    reg = Region.from_scenario(sc)
    return sc, reg, gain_bounds("corrected", reg), disturbance_bounds(sc)


@pytest.fixture(scope="module")
def design(pc):
    sc, reg, g, dist = pc
    return evaluate_design(sc, reg, g, 3.125, dist)


def _cond(d: Design, name: str) -> Condition:
    found = [c for c in d.conditions if c.condition == name]
    assert len(found) == 1, [c.condition for c in d.conditions]
    return found[0]


# --------------------------------------------------------------------------- disturbance
@given(amp=st.tuples(*[st.floats(0.0, 0.3)] * 3), const=st.tuples(*[st.floats(-0.2, 0.2)] * 3),
       gain=st.floats(0.0, 0.5), samp=st.floats(0.0, 0.05), t=st.floats(0.0, 200.0),
       u=st.floats(-1, 1), r=st.floats(-1, 1), psi=st.floats(-math.pi, math.pi))
def test_disturbance_bounds_cover_the_model(amp, const, gain, samp, t, u, r, psi):
    """Property: the bounds are the closed forms max(a_x, a_y) + ||c_xy|| + gamma, a_z + |c_z|,
    gamma = gain u_max r_max + amplitude, and they cover the current + sway evaluated here (eq. 2)."""
    sc = verify.certifiable_scenario()
    lim = sc.limits
    dist = Disturbance(amplitude=amp, period=15.0, constant=const,
                       sway=SwayModel(gain=gain, amplitude=samp, period=10.0, bound=1.0))
    b = disturbance_bounds(sc.with_changes(disturbance=dist))
    gamma = gain * lim.u_max * lim.r_max + samp
    assert b.gamma == pytest.approx(gamma, rel=1e-12, abs=1e-15) and b.gamma >= gamma * (1 - 1e-15)
    assert b.omega_xy == pytest.approx(max(amp[0], amp[1]) + math.hypot(const[0], const[1]) + gamma, rel=1e-12,
                                       abs=1e-15)
    assert b.omega_z == pytest.approx(amp[2] + abs(const[2]), rel=1e-12, abs=1e-15)
    assert b.declared_sway == 1.0
    a = 2 * math.pi * t / 15.0
    vs = gain * (u * lim.u_max) * (r * lim.r_max) + samp * math.sin(2 * math.pi * t / 10.0)
    om = (amp[0] * math.sin(a) + const[0] - vs * math.sin(psi),
          amp[1] * math.cos(a) + const[1] + vs * math.cos(psi),
          amp[2] * math.sin(a) + const[2])
    assert math.hypot(om[0], om[1]) <= b.omega_xy * (1 + 1e-12) + 1e-15
    assert abs(om[2]) <= b.omega_z * (1 + 1e-12) + 1e-15


def test_disturbance_bounds_of_paper_currents(pc):
    *_, dist = pc
    assert dist.omega_xy == pytest.approx(0.1 + 0.1 * 0.4 * 0.5) and dist.omega_z == pytest.approx(0.1)
    assert dist.gamma == pytest.approx(0.02) and dist.declared_sway == 0.02
    assert dist.to_dict() == {"omega_xy": dist.omega_xy, "omega_z": dist.omega_z, "gamma": dist.gamma,
                              "declared_sway": 0.02, "yaw_rate_error": 0.0}  # kinematic plant: psi_dot = r


# --------------------------------------------------------------------------- the theorem's inputs
def test_tube_problem_is_the_scenario(pc):
    sc, reg, g, dist = pc
    p = tube_problem(sc, reg, g, 3.125, dist)
    assert p.ticks == 10 and p.tick == pytest.approx(0.01) and p.period == pytest.approx(0.1)
    assert (p.eps, p.e_o_max, p.u_max, p.w_max, p.r_max) == (0.5, 0.5, 0.4, 0.3, 0.5)
    assert p.pd_xy == pytest.approx(3.0 * math.pi / 50) and p.pd_z == 0.0
    assert p.omega_xy == dist.omega_xy and p.sigma == 3.125 and p.k_abs == g.k_abs


def test_arc_rates_are_the_closed_forms(pc):
    """Along a nominal arc: |e_d'| <= u + P, |e_z'| <= w + |zdot_d|, |e_o'| <= r + (u + P) / eps, ||p'|| <= ||(u, w)||."""
    sc, reg, g, dist = pc
    rates = arc_rates(tube_problem(sc, reg, g, 3.125, dist))
    P = 3.0 * math.pi / 50
    want = (0.4 + P, 0.3, 0.5 + (0.4 + P) / 0.5, math.hypot(0.4, 0.3))
    for got, w in zip(rates, want):
        assert w <= got <= w * (1 + 1e-12)


# --------------------------------------------------------------------------- conditions
def test_every_condition_of_a_finite_tube_has_both_numbers(design):
    assert design.certified and design.tube.certified and design.failures == []
    for c in design.conditions:
        if c.condition == "tube":
            continue   # see test_verify_certificate.test_the_tube_condition_has_both_numbers
        assert c.lhs is not None and c.rhs is not None and math.isfinite(c.lhs) and math.isfinite(c.rhs), c
        assert c.ok is True and c.inequality


def test_input_tightening_numbers(design, pc):
    sc, reg, g, dist = pc
    kap = design.tube.kappa
    for i, ax in enumerate("uwr"):
        c = _cond(design, f"v_bar[{ax}]")
        assert c.lhs == pytest.approx(reg.v_max[i] - kap[i], rel=1e-12) and c.rhs == 0.0
        assert design.v_bar[i] <= reg.v_max[i] - kap[i] + 1e-15
    ku = _cond(design, "keep_up[u]")
    assert ku.lhs == pytest.approx(0.4 - kap[0]) and ku.rhs == pytest.approx(3 * math.pi / 50 + dist.omega_xy)
    kw = _cond(design, "keep_up[w]")
    assert kw.lhs == pytest.approx(0.3 - kap[1]) and kw.rhs == pytest.approx(dist.omega_z)
    yb = _cond(design, "yaw_budget")
    assert yb.lhs == pytest.approx(0.5 - kap[2]) and yb.rhs == pytest.approx(dist.omega_xy / 0.5)


def test_state_condition_numbers(design, pc):
    sc, reg, *_ = pc
    m = design.margins
    ed = _cond(design, "e_bar[e_d]")
    assert ed.lhs == pytest.approx(0.5 + m.e_d[-1]) and ed.rhs == pytest.approx(3.0 - m.e_d[-1])
    eo = _cond(design, "e_bar[e_o]")
    assert eo.lhs == m.e_o[-1] and eo.rhs == 0.5
    sens = _cond(design, "sensing")
    reach = 0.8 * math.hypot(design.v_bar[0], design.v_bar[1]) + m.position[-1] + 0.2
    assert sens.lhs == pytest.approx(reach, rel=1e-12) and sens.rhs == 1.5
    ob = _cond(design, "obstacles[0,1]")
    assert ob.lhs == pytest.approx(10.6) and ob.rhs == pytest.approx(2 * (0.2 + m.position[-1]) + 0.8)


@pytest.mark.parametrize("state, why", [
    ((-0.51, 3.0, 0.2, 0.0), "e_d below epsilon + M_0"),
    ((-0.8, 3.0, 0.2, math.pi), "away from the target (heading 'toward' certified)"),
    ((-0.8, 3.0, 0.2, 0.6), "|e_o| = sin 0.6 above e_o_max - M_0"),
])
def test_initial_condition_fails_outside(pc, state, why):
    sc, reg, g, dist = pc
    d = evaluate_design(sc.with_changes(initial_state=state), reg, g, 3.125, dist)
    c = _cond(d, "initial")
    assert c.ok is False and not d.certified, why
    assert "e(0) = " in c.detail


def test_initial_condition_numbers(design):
    """e(0) of paper_currents: vehicle at (-0.8, 3), target at (0, 3): e = (0.8, 0.2, 0); the worst
    violation is the largest of the box slacks and minus the obstacle clearance (negative = inside)."""
    c = _cond(design, "initial")
    m = design.margins
    slack = max(0.5 + m.e_d[0] - 0.8, 0.8 - 3.0 + m.e_d[0], 0.2 - (1.0 - m.e_z[0]), -1.0 - 0.2 + m.e_z[0],
                0.0 - (0.5 - m.e_o[0]), -0.5 + m.e_o[0])
    assert c.ok and c.lhs == pytest.approx(slack, abs=1e-9) and c.rhs == 0.0


def test_sway_condition(pc):
    sc, reg, g, _ = pc
    low = replace(sc.disturbance, sway=replace(sc.disturbance.sway, bound=0.005))
    sc_low = sc.with_changes(disturbance=low)
    d = evaluate_design(sc_low, reg, g, 3.125, disturbance_bounds(sc_low))
    c = _cond(d, "sway_bound")
    assert c.ok is False and c.lhs == 0.005 and c.rhs == pytest.approx(0.1 * 0.4 * 0.5)


def test_a_diverging_tube_stops_the_pipeline(pc):
    sc, reg, g, dist = pc
    d = evaluate_design(sc, reg, g, 1e4, dist)
    assert [c.condition for c in d.conditions] == ["sway_bound", "tube"]
    assert _cond(d, "tube").ok is False and "diverge" in _cond(d, "tube").detail
    assert d.margins is None and d.v_bar is None and d.score == -math.inf and not d.certified
    assert [c.condition for c in d.failures] == ["tube"]


def test_condition_to_dict_drops_non_finite():
    c = Condition("x", "a < b", math.inf, float("nan"), False, "d")
    assert c.to_dict() == {"condition": "x", "inequality": "a < b", "lhs": None, "rhs": None, "ok": False,
                           "detail": "d"}
    assert Condition("y", "", 1, None, None).to_dict()["lhs"] == 1.0


def test_score_is_the_smallest_normalised_slack(design, pc):
    """score = min(V_bar_i / V_i, 1 - 2 M_j / width_j) over inputs and error axes (last arc)."""
    sc, reg, *_ = pc
    m = design.margins
    want = min(min(v / vm for v, vm in zip(design.v_bar, reg.v_max)),
               1 - 2 * m.e_d[-1] / 2.5, 1 - 2 * m.e_z[-1] / 2.0, 1 - 2 * m.e_o[-1] / 1.0)
    assert design.score == pytest.approx(want, rel=1e-12)


def test_limits_enter_v_bar(pc):
    sc, reg, g, dist = pc
    sc2 = sc.with_changes(limits=InputLimits(0.3, 0.3, 0.5))
    reg2 = Region.from_scenario(sc2)
    d = evaluate_design(sc2, reg2, g, 3.125, disturbance_bounds(sc2))
    assert _cond(d, "keep_up[u]").ok is False    # 0.3 - kappa_u < 0.188 + 0.115
    assert np.isclose(_cond(d, "keep_up[u]").rhs, 3 * math.pi / 50 + 0.1 + 0.1 * 0.3 * 0.5)


def test_a_surge_floor_is_reserved_kappa_bar_above_u_min_and_fails_when_the_band_closes(keep_moving_cert):
    """``v_bar[surge_floor]``: the nominal surge lives in [u_min + kappa_u, u_max - kappa_u]; at sigma = 25 1/s the
    feedback's kappa_u closes the band once u_min reaches u_max - 2 kappa_u, and the tracking tier is refused. The
    safe tier stands on its own sigma = 0 design, where kappa = 0 leaves the band [u_min, u_max] open, with a
    loiter at the floor itself (its grid starts at u_min)."""
    import verify
    sc = keep_moving_cert.inputs.scenario.with_changes(**{"controller.sigma": 25.0})
    cert = verify.certify(sc)
    kappa = cert.design.tube.kappa[0]
    floor = {x.condition: x for x in cert.design.conditions}["v_bar[surge_floor]"]
    assert kappa > 0.0 and floor.ok is True
    assert floor.lhs == pytest.approx(0.2 + kappa, rel=1e-9) and floor.rhs == pytest.approx(1.0 - kappa, rel=1e-9)
    closed = verify.certify(sc.with_changes(**{"limits.u_min": 1.0 - 1.5 * kappa}))
    held = {x.condition: x for x in closed.design.conditions}
    assert held["v_bar[surge_floor]"].ok is False and not closed.tiers.tracking
    safe = {x.condition: x for x in closed.tier_conditions["safe"]}
    assert closed.tiers.safe and safe["safe_only.v_bar[surge_floor]"].ok and safe["backup_min_surge"].ok
    assert closed.backup.law.surge == pytest.approx(1.0 - 1.5 * kappa)
    sym = {x.condition for x in verify.certify(sc.with_changes(**{"limits.u_min": None})).design.conditions}
    assert "v_bar[surge_floor]" not in sym                                        # the symmetric box: no such row


def _positive_root(a: float, b: float, force: float) -> float:
    """The positive root of a v² + b v = force (a > 0)."""
    return (-b + math.sqrt(b * b + 4 * a * force)) / (2 * a)


def test_a_surge_floor_narrows_the_hulls_sway_bound_to_the_lift_it_keeps():
    """Under u >= u_low > 0 the lift term Y_uv u damps the sway and the surge factors out of the two u-terms: beyond
    the turn's steady sway v_c = |Y_ur_lift − m11| r / |Y_uv| the worst surge is u_low, below it ū, so
    v* = max(v_low, min(v_c, v_high)). At REMUS 100's midpoint the bound is that closed form, from the vehicle's
    numbers, below the earlier floored form (F at ū over b at u_low) and the bound over |u| <= ū; a floor at or
    above ū changes nothing."""
    from tubekit.model.vehicle_sets import REMUS100
    from verify.theorem.design import hull_sway_bound
    p = REMUS100.nominal
    u, r, u_low = 1.05, 0.15, 0.47
    m11, m22, _, _, m24, _ = p.mass_entries
    turn, a = abs(p.Y_ur_lift - m11), abs(p.Y_vv)
    low = _positive_root(a, -p.Y_v - p.Y_uv * u_low, turn * u_low * r + abs(p.Y_rr) * r * r)
    high = _positive_root(a, -p.Y_v - p.Y_uv * u, turn * u * r + abs(p.Y_rr) * r * r)
    earlier = _positive_root(a, -p.Y_v - p.Y_uv * u_low, turn * u * r + abs(p.Y_rr) * r * r)
    v_c = turn * r / abs(p.Y_uv)
    expected = max(low, min(v_c, high)) + 2 * abs(m24) * r / m22
    floored = float(hull_sway_bound(p, u, r, u_low).mid())
    assert floored == pytest.approx(expected, rel=1e-9)
    assert floored < earlier + 2 * abs(m24) * r / m22
    assert floored < float(hull_sway_bound(p, u, r).mid())
    assert float(hull_sway_bound(p, u, r, u).mid()) == float(hull_sway_bound(p, u, r).mid())


def test_under_a_surge_floor_the_hulls_sway_bound_is_capped_by_the_turns_steady_sway():
    """A turn's steady sway (m11 − Y_ur_lift) r / |Y_uv| does not depend on the surge: under a floor of 0.9 m/s,
    REMUS 100's midpoint gets a bound that grows with the top speed ū only up to that steady sway (plus the
    r-coupling 2|m24| r / m22), at r = 0.05 rad/s, from ū = 0.95 to 10 m/s; at 10 m/s the earlier form (F at ū
    over b at u_low) is more than twice as large."""
    from tubekit.model.vehicle_sets import REMUS100
    from verify.theorem.design import hull_sway_bound
    p = REMUS100.nominal
    m11, m22, _, _, m24, _ = p.mass_entries
    cap = abs(p.Y_ur_lift - m11) * 0.05 / abs(p.Y_uv) + 2 * abs(m24) * 0.05 / m22
    bounds = [float(hull_sway_bound(p, u_bar, 0.05, 0.9).mid()) for u_bar in (0.95, 1.0, 1.5, 2.5, 10.0)]
    assert bounds == sorted(bounds) and bounds[0] < bounds[-1] <= cap * (1 + 1e-12)
    turn, a, b = abs(p.Y_ur_lift - m11), abs(p.Y_vv), -p.Y_v - p.Y_uv * 0.9
    earlier = _positive_root(a, b, turn * 10.0 * 0.05 + abs(p.Y_rr) * 0.05 ** 2)  # F at ū = 10 over b at u_low
    assert bounds[-1] < 0.5 * earlier


@pytest.mark.parametrize("seed", [None, 0, 1])
def test_on_the_simulated_torpedo_the_sway_stays_within_the_floored_bound(seed):
    """Property: REMUS 100 as simulated (its box's midpoint, and two random points of the published box), no
    current, the surge command switching between 0.6 and 1.0 m/s and the yaw rate bang-bang between ±0.1 rad/s:
    |v| stays within γ̄ over the run's own surge range [min u, max u] and max |r|, and the box's floored bound
    covers the point's."""
    from tubekit.model.vehicle_sets import REMUS100
    from tubekit.plant.dynamic import DynamicPlant
    from tubekit.scenario import scenario_from_dict
    from verify.theorem.design import hull_sway_bound
    truth = REMUS100.nominal if seed is None else REMUS100.sample(np.random.default_rng(seed))
    scenario = scenario_from_dict({"plant": {"kind": "dynamic", "vehicle": {
        k: v for k, v in REMUS100.to_dict().items() if k != "name"}},
        "disturbance": {"amplitude": [0.0, 0.0, 0.0], "sway": {"gain": 0.0, "bound": 0.0}}})
    plant = DynamicPlant(scenario, params=truth)
    command, pose, t, body = [0.6, 0.0, 0.0], (0.0, 0.0, 0.0, 0.0), 0.0, []
    for k in range(400):  # 40 s of 0.1 s periods
        command[0] += max(-0.02, min(0.02, (0.6, 1.0)[(k // 90) % 2] - command[0]))
        command[2] += max(-0.01, min(0.01, (0.1 if (k // 60) % 2 == 0 else -0.1) - command[2]))
        for _ in range(10):
            pose = plant.step_tuple(t, pose, tuple(command), 0.01, 1)
            t += 0.01
            body.append(plant.state[:4])
    body = np.array(body)
    u_lo, u_hi, r_hi = float(body[:, 0].min()), float(np.abs(body[:, 0]).max()), float(np.abs(body[:, 3]).max())
    assert u_lo > 0.55 and r_hi > 0.09  # the run did what it was asked
    point = hull_sway_bound(truth, u_hi, r_hi, u_lo)
    sway = float(np.abs(body[:, 1]).max())
    assert 0.0 < sway <= float(point.mid() - point.rad())
    assert float(hull_sway_bound(REMUS100, u_hi, r_hi, u_lo).mid()) >= float(point.mid())
