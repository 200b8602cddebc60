"""The plant of eq. (11) as simulated: disturbance, sway, RK4 integrator, exact nominal arc."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from tubekit import paper_scenario
from tubekit.model.kinematics import SwayModel, kinematics, nominal_kinematics
from tubekit.plant.kinematic import Plant, nominal_arc, plant_rhs, rk4_hold, sway_velocity_term
from tubekit.scenario import Disturbance


def _omega_reference(sc, t, x, v):
    """ω = δ(t) + v_s [-sin ψ, cos ψ, 0], written out from the documented formulas (numpy, independent)."""
    d, s = sc.disturbance, sc.disturbance.sway
    a = 2.0 * np.pi * t / d.period
    current = np.asarray(d.amplitude) * np.array([np.sin(a), np.cos(a), np.sin(a)]) + np.asarray(d.constant)
    vs = s.gain * v[0] * v[2] + s.amplitude * np.sin(2.0 * np.pi * t / s.period)  # the model: no clip
    return current + vs * np.array([-np.sin(x[3]), np.cos(x[3]), 0.0])


def test_plant_rhs_is_eq11_with_model_disturbance():
    sc = paper_scenario().with_changes(disturbance=Disturbance(amplitude=(0.1, 0.2, 0.05), constant=(0.01, -0.02, 0.03),
                                                 sway=SwayModel(gain=0.3, amplitude=0.05, period=7.0, bound=0.04)))
    rng = np.random.default_rng(0)
    for _ in range(50):
        t = rng.uniform(0, 100)
        x = rng.uniform(-3, 3, 4)
        v = rng.uniform(-0.5, 0.5, 3)
        want = kinematics(x, v, _omega_reference(sc, t, x, v))
        np.testing.assert_allclose(plant_rhs(sc, t, x, v), want, atol=1e-14)


def test_rk4_matches_tight_solve_ivp():
    sc = paper_scenario().with_changes(disturbance=Disturbance(
        sway=SwayModel(gain=0.0, amplitude=0.015, period=3.0, bound=0.02)))
    x0 = np.array([0.2, 2.9, 0.1, 0.3])
    v = np.array([0.35, -0.1, 0.4])

    def f(t, x):
        return kinematics(x, v, _omega_reference(sc, t, x, v))

    ref = solve_ivp(f, (3.0, 3.5), x0, rtol=1e-12, atol=1e-12, method="DOP853").y[:, -1]
    got = rk4_hold(sc, 3.0, x0, v, 0.5, 100)  # 5 ms steps, as in the closed loop
    np.testing.assert_allclose(got, ref, atol=1e-10)


def test_nominal_arc_is_exact():
    x0 = np.array([1.0, -2.0, 0.5, 2.0])
    tau = np.linspace(0, 0.1, 11)
    for v in (np.array([0.4, 0.2, -0.5]), np.array([0.3, -0.1, 0.0]), np.array([0.0, 0.0, 0.3])):
        ref = solve_ivp(lambda t, x: nominal_kinematics(x, v), (0, 0.1), x0, t_eval=tau, rtol=1e-12,
                        atol=1e-13).y.T
        np.testing.assert_allclose(nominal_arc(x0, v, tau), ref, atol=1e-11)


@given(psi=st.floats(-10, 10), vs=st.floats(-1, 1))
def test_sway_term_is_lateral(psi, vs):
    """Property: g(x, v_s) is orthogonal to the heading and has norm |v_s| (eq. 2)."""
    g = sway_velocity_term(np.array([0, 0, 0, psi]), vs)
    heading = np.array([np.cos(psi), np.sin(psi), 0.0])
    assert abs(g @ heading) < 1e-12
    assert np.linalg.norm(g) == pytest.approx(abs(vs), abs=1e-12)


@given(u=st.floats(-0.4, 0.4), r=st.floats(-0.5, 0.5), t=st.floats(0, 1000))
def test_sway_within_the_derived_bound_over_v(u, r, t):
    """Property: with v in V the sway applied never exceeds gain u_max r_max + amplitude (gamma-bar)."""
    plant = Plant(Disturbance(sway=SwayModel(gain=0.5, amplitude=0.05, period=7.0, bound=0.15)))
    assert abs(plant.sway_velocity(t, np.zeros(4), np.array([u, 0.0, r]))) <= 0.5 * 0.4 * 0.5 + 0.05 + 1e-15


def test_zero_sway_allowed():
    plant = Plant(Disturbance(sway=SwayModel(gain=0.0, amplitude=0.0, bound=0.0)))
    assert plant.sway_velocity(3.0, np.zeros(4), np.array([0.4, 0, 0.5])) == 0.0


# ---- the Plant API ---------------------------------------------------------------------

def _plant():
    return Plant(Disturbance(amplitude=(0.1, 0.2, 0.05), period=11.0, constant=(0.01, -0.02, 0.03),
                             sway=SwayModel(gain=0.3, amplitude=0.05, period=7.0, bound=0.04)))


def test_current_is_vectorised_and_periodic():
    plant = _plant()
    t = np.linspace(0.0, 30.0, 12).reshape(3, 4)
    cur = plant.current(t)
    assert cur.shape == (3, 4, 3)
    np.testing.assert_allclose(cur[1, 2], plant.current(float(t[1, 2])), atol=0)
    np.testing.assert_allclose(plant.current(t + 11.0), cur, atol=1e-12)
    a = 2 * np.pi * 2.5 / 11.0
    np.testing.assert_allclose(plant.current(2.5), [0.1 * np.sin(a) + 0.01, 0.2 * np.cos(a) - 0.02,
                                                    0.05 * np.sin(a) + 0.03], atol=1e-15)


def test_omega_is_current_plus_sway_term():
    plant = _plant()
    rng = np.random.default_rng(1)
    for _ in range(20):
        t, x, v = rng.uniform(0, 50), rng.uniform(-2, 2, 4), rng.uniform(-0.5, 0.5, 3)
        want = plant.current(t) + sway_velocity_term(x, plant.sway_velocity(t, x, v))
        np.testing.assert_allclose(plant.omega(t, x, v), want, atol=1e-15)
        np.testing.assert_allclose(plant.rhs(t, x, v), kinematics(x, v, want), atol=1e-15)


def test_sway_is_the_model_not_a_clip():
    plant = _plant()  # gain 0.3, u r = 0.25 at t = 0 (wave term 0): 0.075, above the declared 0.04
    assert plant.sway_velocity(0.0, np.zeros(4), np.array([0.5, 0.0, 0.5])) == pytest.approx(0.3 * 0.25)


def test_step_is_rk4_hold_and_step_tuple():
    plant = _plant()
    x0, v = np.array([0.2, 2.9, 0.1, 0.3]), np.array([0.35, -0.1, 0.4])
    got = plant.step(1.0, x0, v, 0.005, 20)
    np.testing.assert_array_equal(got, rk4_hold(plant, 1.0, x0, v, 0.1, 20))
    np.testing.assert_array_equal(got, plant.step_tuple(1.0, tuple(x0), tuple(v), 0.005, 20))


@given(t=st.floats(0.0, 200.0), psi=st.floats(-4.0, 4.0), u=st.floats(-0.5, 0.5), w=st.floats(-0.3, 0.3),
       r=st.floats(-0.6, 0.6), n=st.integers(1, 4))
def test_the_compiled_step_equals_the_generic_rk4_bit_for_bit(t, psi, u, w, r, n):
    """Property: step_tuple (the compiled RK4) returns the very floats, and records the very omega peak, of
    rk4_tuple on the plant's _rhs (the generic integrator it replaces in the loop)."""
    from tubekit.plant.kinematic import rk4_tuple
    fused, generic = _plant(), _plant()
    x, v = (0.3, -1.2, 0.4, psi), (u, w, r)
    assert fused.step_tuple(t, x, v, 0.005, n) == rk4_tuple(generic._rhs, t, x, v, 0.005, n)
    assert fused.omega_peak() == generic.omega_peak()


def test_override_replaces_current_and_sway():
    plant = Plant(_plant().disturbance, override=lambda t: (0.01 * t, -0.02, 0.0))
    x, v = np.array([0.0, 0.0, 0.0, 1.0]), np.array([0.3, 0.0, 0.2])
    np.testing.assert_array_equal(plant.omega(2.0, x, v), [0.02, -0.02, 0.0])
    assert math.isnan(plant.sway_velocity(2.0, x, v))


def test_plant_of_scenario():
    sc = paper_scenario()
    plant = Plant.of(sc)
    assert plant.disturbance is sc.disturbance and plant.override is None


def test_omega_series_matches_omega_per_tick_and_skips_nan_inputs():
    plant = _plant()
    rng = np.random.default_rng(5)
    t = np.arange(6) * 0.01
    states = rng.uniform(-1, 1, (6, 4))
    inputs = rng.uniform(-0.4, 0.4, (6, 3))
    inputs[-1] = np.nan
    out = plant.omega_series(t, states, inputs)
    for i in range(5):
        np.testing.assert_array_equal(out[i], plant.omega(t[i], states[i], inputs[i]))
    assert np.all(np.isnan(out[-1]))
    assert plant.current_at(0.3) == tuple(plant.current(0.3))


def test_the_omega_peak_is_over_every_stage_evaluation():
    """An override of 0.5 m/s horizontally (0.3, 0.4) and -0.2 m/s vertically except at the tick
    instants t = 0, 0.01 (where it is zero): only the RK4 stages between the ticks see it."""
    def between(t):
        return np.zeros(3) if min(abs(t), abs(t - 0.01)) < 1e-9 else np.array([0.3, 0.4, -0.2])

    plant = Plant(paper_scenario().disturbance, override=between)
    assert plant.omega_peak() == (0.0, 0.0)
    plant.step(0.0, np.zeros(4), np.array([0.2, 0.0, 0.1]), 0.01, 1)   # stages at 0, 0.005, 0.005, 0.01
    assert plant.omega_peak() == pytest.approx((0.5, 0.2))
    assert np.all(plant.omega_series(np.array([0.0, 0.01]), np.zeros((2, 4)), np.zeros((2, 3))) == 0.0)
