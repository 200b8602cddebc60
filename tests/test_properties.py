"""Property suite for robust control invariance (issue 6, items a-e).

Every test here is marked ``property`` (``pytest -m property``) and documents its
property in a docstring starting with "Property:". Expected behaviour is checked
with computations independent of the code under test: the Cartesian derivation
(tubekit.derivation.numeric), finite quotients, and direct simulation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit.ancillary import LAWS
from tubekit.derivation import numeric
from tubekit.scenario import paper_scenario
from verify import strategies as vs
from verify.falsify import falsify, search_space
from verify.invariance import rho_dot_inner

from .independent import fd_rho_dot_inner

pytestmark = pytest.mark.property


@pytest.fixture(scope="module")
def certified():
    """The corrected law's certificate on the shipped certifiable scenario."""
    scenario = verify.certifiable_scenario()
    cert = verify.certify(scenario, "corrected")
    assert cert.certified, cert.summary()
    return scenario, cert


# ---------------------------------------------------------------- a. certificate soundness
def _J(state):
    return numeric().J(state[0], state[1], state[3])


def _zeta(state, pd):
    return numeric().zeta(state[0], state[1], state[3], *pd)


def _xi_matrix(state):
    """xi = M omega: the columns are xi at unit disturbances (xi is linear in omega)."""
    return np.stack([numeric().xi(state[0], state[1], state[3], *e) for e in np.eye(3)], axis=-1)


@settings(max_examples=max(10, settings.default.max_examples // 4))  # scales with the profile
@given(region=vs.regions(max_e_o=0.9), law=st.sampled_from(sorted(LAWS)), data=st.data())
def test_certificate_soundness(region, law, data):
    """Property: no sampled point beats a certified bound (L1, L2, J_lower, xi_bar) on random regions."""
    b = verify.compute_bounds(region, law, time_budget_s=0.5)
    for _ in range(25):
        u = np.array(data.draw(st.lists(st.floats(0, 1), min_size=12, max_size=12)))
        sign = region.hemisphere_signs[int(u[0] * len(region.hemisphere_signs)) % len(region.hemisphere_signs)]
        theta = -math.pi + 2 * math.pi * u[1]
        e1 = np.array([np.interp(u[2], [0, 1], region.e_d), np.interp(u[3], [0, 1], region.e_z),
                       np.interp(u[4], [0, 1], region.e_o)])
        e2 = np.array([np.interp(u[5], [0, 1], region.e_d), np.interp(u[6], [0, 1], region.e_z),
                       np.interp(u[7], [0, 1], region.e_o)])
        s1, s2 = vs.state_from_error(*e1, theta, sign), vs.state_from_error(*e2, theta, sign)
        J1 = _J(s1)
        # J_lower: lambda_min of the symmetric closed-loop gain at a point is >= the certified inf
        G = LAWS[law].closed_loop_matrix(J1)
        assert np.linalg.eigvalsh(0.5 * (G + G.T))[0] >= b["J_lower"].bound - 1e-9
        # xi_bar: sup over ||omega|| <= omega_bar of ||xi|| = omega_bar * sigma_max(M)
        assert region.omega_bar * np.linalg.norm(_xi_matrix(s1), 2) <= b["xi_bar"].bound * (1 + 1e-9) + 1e-12
        dist = np.linalg.norm(e1 - e2)
        if dist < 1e-9:
            continue
        # L1: a finite Lipschitz quotient of J(e) v_hat never exceeds the certified constant
        v_hat = np.array([(2 * u[8] - 1) * region.v_max[0], (2 * u[9] - 1) * region.v_max[1],
                          (2 * u[10] - 1) * region.v_max[2]])
        assert np.linalg.norm(J1 @ v_hat - _J(s2) @ v_hat) <= b["L1"].bound * dist * (1 + 1e-9) + 1e-12
        # L2: the same for zeta at a fixed bearing and target velocity in P
        pd = data.draw(vs.target_velocities(region))
        assert np.linalg.norm(_zeta(s1, pd) - _zeta(s2, pd)) <= b["L2"].bound * dist * (1 + 1e-9) + 1e-12


# ---------------------------------------------------------------- b. pointwise invariance
def test_pointwise_invariance_certified_law(certified):
    """Property: for the certified law, on the tube boundary (||rho|| = rho_tilde), for any omega in Omega,
    v_hat in V-bar, target velocity in P and bearing mismatch within Delta-theta, d/dt 1/2||rho||^2 <= 0."""
    scenario, cert = certified
    space = search_space(scenario, "corrected", certificate=cert)
    law = LAWS["corrected"]

    @settings(max_examples=8 * settings.default.max_examples)  # 320 in 'ci', 8000 in 'thorough'
    @given(vs.tube_configurations(space.region, space.rho_tilde, space.v_bar, space.delta_theta))
    def prop(cfg):
        assert rho_dot_inner(cfg, law, space.sigma) <= 0.0

    prop()


# ---------------------------------------------------------------- e. the paper's law is falsified
def test_paper_law_fails_toward_hemisphere():
    """Property: the paper's law violates pointwise invariance when the vehicle points at the target;
    the falsifier finds a concrete counterexample, with rho^T rho_dot > 0 recomputed independently."""
    result = falsify(paper_scenario(), "paper", budget=200)
    assert result.found
    ce = result.counterexample
    cos_rel = math.cos(ce.real[3] - math.atan2(ce.real[1], ce.real[0]))
    assert cos_rel < 0  # "toward"
    assert np.linalg.norm(ce.rho) == pytest.approx(result.space.rho_tilde, rel=1e-6)
    # independent recomputation by finite differences of the kinematics
    assert fd_rho_dot_inner(ce, LAWS["paper"], result.space.sigma) > 0


def test_falsifier_finds_nothing_for_certified_design(certified):
    """Property: with the corrected law on its certified scenario, the falsifier (hypothesis + local search)
    finds no configuration with rho^T rho_dot > 0."""
    scenario, cert = certified
    result = falsify(scenario, "corrected", certificate=cert, budget=300, local_iterations=1500)
    assert not result.found, result.summary()
    assert result.worst_value <= 0


# ---------------------------------------------------------------- c. closed-loop containment
def test_closed_loop_containment(certified):
    """Property: for random bounded disturbances in Omega (time-varying) and random starts in E-bar of the
    certified scenario, the closed loop keeps ||rho(t)|| <= rho_tilde and v(t) in V at every tick."""
    from dataclasses import replace

    from tubekit.closed_loop import simulate
    from tubekit.derivation import error_coordinates

    scenario, cert = certified
    tight = cert.tightening()
    rho_t = tight.rho_tilde
    start_region = cert.region.replace(e_d=(tight.e_d_min, min(tight.e_d_min + 0.5, tight.e_d_max)),
                                       e_o=(-0.3, 0.3), e_z=(-0.3, 0.3))
    short = replace(scenario, duration=2.0)
    p0 = scenario.trajectory.position(0.0)

    @settings(max_examples=max(3, settings.default.max_examples // 10), deadline=None)
    @given(start=vs.error_states(start_region), signal=vs.disturbance_signals(cert.region.omega_bar))
    def prop(start, signal):
        init = (p0[0] + start[0], p0[1] + start[1], p0[2] + start[2], start[3])
        run = simulate(replace(short, initial_state=init), tightening=tight, law="corrected", progress=False,
                       disturbance=signal)
        e = error_coordinates(run.states, run.desired)
        e_hat = error_coordinates(run.nominal, run.desired)
        rho = np.linalg.norm(e - e_hat, axis=-1)
        assert np.nanmax(rho) <= rho_t
        applied = run.inputs[:-1]
        assert np.all(np.abs(applied) <= scenario.limits.vector + 1e-12)
        assert int(run.saturated.sum()) == 0

    prop()
