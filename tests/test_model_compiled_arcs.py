"""Tests of tubekit.model.compiled_arcs: each compiled routine returns the very floats of the model's numpy
formula (tubekit.model.kinematics.unicycle_step, sinc, dsinc; tubekit.model.errors.error_coordinates), and
``tubekit certify`` never loads numba."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tubekit.model import compiled_arcs
from tubekit.model.errors import error_coordinates
from tubekit.model.kinematics import dsinc, sinc, unicycle_step

STATE = hnp.arrays(float, 4, elements=st.floats(-50.0, 50.0))


@st.composite
def plans(draw, max_steps: int = 10) -> tuple[np.ndarray, np.ndarray, float]:
    """A start state (4,), inputs (N, 3) with yaw rates exactly 0, tiny (the series branch of S') or large, and
    a step dt (s)."""
    n = draw(st.integers(1, max_steps))
    u = draw(hnp.arrays(float, n, elements=st.floats(-1.5, 1.5)))
    w = draw(hnp.arrays(float, n, elements=st.floats(-0.5, 0.5)))
    r = draw(hnp.arrays(float, n, elements=st.one_of(st.just(0.0), st.floats(-1e-3, 1e-3), st.floats(-3.0, 3.0))))
    dt = draw(st.floats(0.005, 0.5))
    return draw(STATE), np.column_stack([u, w, r]), dt


def _chained(x0: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    out = [np.asarray(x0, dtype=float)]
    for v in inputs:
        out.append(unicycle_step(out[-1], v, dt))
    return np.array(out)


@given(plans())
def test_the_rollout_is_the_chain_of_the_models_exact_step(plan):
    """Property: rollout returns the very floats of unicycle_step applied step by step."""
    x0, inputs, dt = plan
    np.testing.assert_array_equal(compiled_arcs.rollout(x0, inputs, dt), _chained(x0, inputs, dt))


@given(plans())
def test_the_row_by_row_step_is_the_models_step_on_every_row(plan):
    """Property: unicycle_steps equals the vectorised unicycle_step on (N, 4) states and (N, 3) inputs."""
    x0, inputs, dt = plan
    states = _chained(x0, inputs, dt)[:-1] + np.linspace(0.0, 1.0, len(inputs))[:, None]
    np.testing.assert_array_equal(compiled_arcs.unicycle_steps(states, inputs, dt), unicycle_step(states, inputs, dt))


@given(plans(), st.integers(1, 12))
def test_an_arc_and_a_plans_arcs_are_the_models_arcs_chained(plan, samples):
    """Property: arc is unicycle_step at every elapsed time, and plan_arcs starts every arc where the chained
    numpy arcs end (the same sequential sums)."""
    x0, inputs, dt = plan
    tau = np.linspace(0.0, dt, samples + 1)
    np.testing.assert_array_equal(compiled_arcs.arc(x0, inputs[0], tau), unicycle_step(x0, inputs[0], tau))
    expected, start = [], x0
    for v in inputs:
        expected.append(unicycle_step(start, v, tau))
        start = expected[-1][-1]
    np.testing.assert_array_equal(compiled_arcs.plan_arcs(x0, inputs, tau), np.array(expected))


def test_a_plan_of_no_arcs_has_no_states():
    assert compiled_arcs.plan_arcs(np.zeros(4), np.zeros((0, 3)), np.linspace(0.0, 0.1, 5)).shape == (0, 5, 4)


@given(plans(), st.sampled_from([0.0, 1e-9]))
def test_the_error_coordinates_are_the_models(plan, floor):
    """Property: error_coordinates equals tubekit.model.errors.error_coordinates (floor 0 and the FHOCP's)."""
    x0, inputs, dt = plan
    states = _chained(x0, inputs, dt)
    ref = states[:, :3][::-1] + 0.25
    np.testing.assert_array_equal(compiled_arcs.error_coordinates(states, ref, floor),
                                  error_coordinates(states, ref, floor))


def test_on_the_target_e_o_is_nan_without_a_floor_and_finite_with_one():
    state, ref = np.array([[1.0, 2.0, 0.0, 0.3]]), np.array([[1.0, 2.0, -0.5]])
    bare = compiled_arcs.error_coordinates(state, ref, 0.0)
    assert bare[0, 0] == 0.0 and bare[0, 1] == 0.5 and np.isnan(bare[0, 2])
    np.testing.assert_array_equal(compiled_arcs.error_coordinates(state, ref, 1e-9), error_coordinates(state, ref, 1e-9))


@given(plans())
def test_the_steps_jacobian_is_built_from_the_models_sinc_and_its_derivative(plan):
    """Property: the input columns are dt S(a) (cos, sin)(ψ + a) and dt² u/2 (S' (cos, sin) ∓ S (sin, cos)) with
    a = r dt / 2 (the model's sinc and dsinc, in numpy), and the affine model reproduces the exact step."""
    x0, inputs, dt = plan
    states = _chained(x0, inputs, dt)
    rows = compiled_arcs.step_linearisation(states, inputs, dt)
    psi, u, r = states[:-1, 3], inputs[:, 0], inputs[:, 2]
    a = 0.5 * dt * r
    th = psi + a
    sa, dsa, c, s = sinc(a), dsinc(a), np.cos(th), np.sin(th)
    np.testing.assert_array_equal(rows[1], dt * sa * c)
    np.testing.assert_array_equal(rows[5], dt * sa * s)
    np.testing.assert_array_equal(rows[2], 0.5 * dt * dt * u * (dsa * c - sa * s))
    np.testing.assert_array_equal(rows[6], 0.5 * dt * dt * u * (dsa * s + sa * c))
    ax, bxu, bxr, cx, ay, byu, byr, cy = rows
    scale = 1.0 + np.abs(states[:-1, :2]).max() + np.abs(psi).max()
    np.testing.assert_allclose(states[:-1, 0] + ax * psi + bxu * u + bxr * r + cx, states[1:, 0], rtol=0, atol=1e-14 * scale)
    np.testing.assert_allclose(states[:-1, 1] + ay * psi + byu * u + byr * r + cy, states[1:, 1], rtol=0, atol=1e-14 * scale)


@given(plans())
def test_the_bearing_errors_model_carries_the_models_e_o(plan):
    """Property: the value row of the e_o model is the e_o of error_coordinates (away from the target)."""
    x0, inputs, dt = plan
    states = _chained(x0, inputs, dt)
    ref = states[:, :3] + np.array([0.7, -0.4, 0.1])
    rows = compiled_arcs.eo_linearisation(states, ref, 1e-9)
    np.testing.assert_array_equal(rows[4], error_coordinates(states, ref, 1e-9)[:, 2])
    np.testing.assert_array_equal(rows[3], rows[4] - rows[0] * states[:, 0] - rows[1] * states[:, 1]
                                  - rows[2] * states[:, 3])


@pytest.mark.slow
def test_certify_loads_no_numba():
    """The compiled routines are imported by the loop at its first period, never by ``tubekit certify``."""
    code = ("import sys, verify; from tubekit import paper_scenario; verify.certify(paper_scenario()); "
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120)
    assert out.stdout.strip() == "False"
