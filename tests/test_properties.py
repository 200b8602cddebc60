"""Property suite for robust control invariance (issue 6, items a-e).

Every test here is marked ``property`` (``pytest -m property``) and documents its
property in a docstring starting with "Property:". Expected behaviour is checked
with computations independent of the code under test: the Cartesian derivation
(tubekit.model.errors.numeric), finite quotients, and direct simulation.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit.model.ancillary import LAWS
from tubekit.model.errors import numeric
from verify.falsify import strategies as vs
from verify.falsify.one_period import falsify, search_space
from verify.falsify.invariance import one_period_ratio


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


@pytest.mark.slow
@settings(max_examples=max(10, settings.default.max_examples // 4))  # scales with the profile
@given(region=vs.regions(max_e_o=0.9), law=st.sampled_from(sorted(LAWS)), data=st.data())
def test_certificate_soundness(region, law, data):
    """Property: no sampled point beats a certified bound (L1, L2, J_lower, xi_bar) on random regions."""
    b = verify.compute_bounds(region, law, max_boxes=2000)
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


# ---------------------------------------------------------------- b. one-period tube (the theorem)
def test_one_period_tube_certified_law(certified):
    """Property: for the certified law, from any start in E-bar with rho = 0 (the reset), any constant omega
    with ||omega_xy|| <= omega_bar_xy and |omega_z| <= omega_bar_z, v_hat in V-bar and target velocity in P,
    one period of the sampled-data loop keeps max_j |rho_j| / tube_j <= 1."""
    scenario, cert = certified
    space = search_space(scenario, "corrected", certificate=cert)
    law = LAWS["corrected"]

    @settings(max_examples=2 * settings.default.max_examples, deadline=None)
    @given(vs.period_configurations(space.region, space.start, space.v_bar, space.omega_bar))
    def prop(cfg):
        assert one_period_ratio(cfg, law, space.sigma, np.asarray(space.tube), space.tick, space.ticks) <= 1.0

    prop()


def test_falsifier_finds_nothing_for_certified_design(certified):
    """Property: with the corrected law on its certified scenario, the one-period falsifier (hypothesis +
    local search) finds no start whose deviation leaves the certified box tube."""
    scenario, cert = certified
    result = falsify(scenario, "corrected", certificate=cert, budget=100, local_iterations=300)
    assert not result.found, result.summary()
    assert result.worst_value <= 1.0


# ---------------------------------------------------------------- c. closed-loop containment
def test_closed_loop_containment(certified):
    """Property: for random bounded disturbances in Omega (time-varying) and random starts in E-bar of the
    certified scenario, the closed loop keeps max_j |rho_j(t)| / tube_j <= 1 and v(t) in V at every tick.
    The start is part of the design, so each start runs under the certificate of its own design (same σ)."""
    from tubekit.design_inputs import DesignInputs

    from tubekit.loop.closed_loop import run_closed_loop
    from tubekit.model.errors import error_coordinates

    scenario, cert = certified
    tight = cert.tightening
    tube = np.asarray(tight.tube)
    eo, ez = min(0.3, tight.e_o_max), min(0.3, tight.e_z_max)  # starts in E-bar
    start_region = cert.region.replace(e_d=(tight.e_d_min, min(tight.e_d_min + 0.5, tight.e_d_max)),
                                       e_o=(-eo, eo), e_z=(-ez, ez))
    short = scenario.with_changes(duration=2.0, **{"controller.law": "corrected"})
    p0 = scenario.trajectory.position(0.0)
    omega_low = min(tight.disturbance.omega_xy, tight.disturbance.omega_z)

    @settings(max_examples=max(3, settings.default.max_examples // 10), deadline=None)
    @given(start=vs.error_states(start_region), signal=vs.disturbance_signals(omega_low))
    def prop(start, signal):
        init = (p0[0] + start[0], p0[1] + start[1], p0[2] + start[2], start[3])
        here = replace(short, initial_state=init)
        own = verify.certify(DesignInputs.of(here, sigma=tight.sigma))
        assert np.array_equal(own.design.tube.rho, tube)  # the one-period tube does not depend on the start
        # the tracking tier also needs the terminal law's plan from the start (initial_terminal), which depends
        # on it: the tube is run under the certified tightening bound to this start's design
        run = run_closed_loop(here, replace(tight, design=DesignInputs.of(here, sigma=tight.sigma)), progress=False,
                              disturbance=signal)
        e = error_coordinates(run.states, run.desired)
        e_hat = error_coordinates(run.nominal, run.desired)
        assert np.nanmax(np.max(np.abs(e - e_hat) / tube, axis=-1)) <= 1.0
        applied = run.inputs[:-1]
        assert np.all(np.abs(applied) <= scenario.limits.vector + 1e-12)
        assert int(run.saturated.sum()) == 0

    prop()


# ---------------------------------------------------------------- d. the FHOCP
@pytest.fixture(scope="module")
def fhocp_solver(certified):
    from tubekit.fhocp import FHOCP

    scenario, cert = certified
    return FHOCP(scenario, replace(cert.tightening, backup=None, terminal_law=None), mode="converged")


def test_fhocp_plans_and_shifted_candidate(certified, fhocp_solver):
    """Property: from states in E-bar at any time, the FHOCP's plan satisfies the tightened constraints
    (V-bar, e_d >= epsilon + rho_tilde, inflated obstacles, |e_o|, |e_z|, e_d_max, dynamics) within 1e-6,
    and the shifted plan (tube MPC's candidate) is feasible at the next step w.r.t. the same constraints.
    Checked by an independent rollout with fine RK4 and direct distance computations. The FHOCP is the
    one without the backup's terminal rows and without the tracking theorem's terminal set: those are soft and
    traded against the tracking rows where both cannot hold (e.g. the plan's end near an obstacle, or a start
    from which X_f is out of reach within the horizon), see test_fhocp_scp."""
    from tubekit.model.kinematics import nominal_kinematics
    from tubekit.loop.sensing import detected_obstacles

    scenario, cert = certified
    tight = cert.tightening
    dt, n = scenario.controller.dt, scenario.controller.horizon_steps
    eo, ez = min(0.3, tight.e_o_max), min(0.3, tight.e_z_max)  # starts in E-bar
    start_region = cert.region.replace(e_d=(tight.e_d_min, tight.e_d_min + 1.0), e_o=(-eo, eo), e_z=(-ez, ez))

    def fine_rollout(s0, inputs):
        out, s = [np.asarray(s0, float)], np.asarray(s0, float)
        for v in inputs:
            h = dt / 50
            for _ in range(50):
                k1 = nominal_kinematics(s, v); k2 = nominal_kinematics(s + h / 2 * k1, v)
                k3 = nominal_kinematics(s + h / 2 * k2, v); k4 = nominal_kinematics(s + h * k3, v)
                s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            out.append(s)
        return np.array(out)

    def check(states, inputs, t0, obstacles, tol):
        assert np.all(np.abs(inputs) <= tight.v_max + tol)
        times = t0 + dt * np.arange(1, n + 1)
        p_d = scenario.trajectory.position(times)
        indep = fine_rollout(states[0], inputs)[1:]
        assert np.allclose(indep, states[1:], atol=1e-6)
        e_x, e_y = indep[:, 0] - p_d[:, 0], indep[:, 1] - p_d[:, 1]
        e_d = np.hypot(e_x, e_y)
        assert np.all(e_d >= tight.e_d_min - tol) and np.all(e_d <= tight.e_d_max + tol)
        assert np.all(np.abs(indep[:, 2] - p_d[:, 2]) <= tight.e_z_max + tol)
        e_o = (e_x * np.sin(indep[:, 3]) - e_y * np.cos(indep[:, 3])) / e_d
        assert np.all(np.abs(e_o) <= tight.e_o_max + tol)
        for ob in obstacles:
            dist = np.linalg.norm(indep[:, :3] - np.asarray(ob.center), axis=1)
            assert np.all(dist >= ob.radius + scenario.vehicle_radius + tight.obstacle_margin - tol)

    p_traj = scenario.trajectory

    @settings(max_examples=max(5, settings.default.max_examples // 4), deadline=None)
    @given(rel=vs.error_states(start_region), t=st.floats(0.0, 80.0))
    def prop(rel, t):
        p = p_traj.position(t)
        state = np.array([p[0] + rel[0], p[1] + rel[1], p[2] + rel[2], rel[3]])
        obstacles = detected_obstacles(state[:3], scenario.obstacles, scenario.sensing_range)
        fhocp_solver.reset()
        plan = fhocp_solver.solve(t, state, obstacles)
        assert not plan.fallback
        check(plan.states, plan.inputs, t, obstacles, 1e-6)
        nxt = plan.states[1]
        seen = detected_obstacles(nxt[:3], scenario.obstacles, scenario.sensing_range)
        s2, v2, _ = fhocp_solver.shifted_candidate(t + dt, nxt, seen)
        check(s2, v2, t + dt, seen, 1e-6)

    prop()
