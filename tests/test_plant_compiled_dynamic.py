"""Tests of tubekit.plant.compiled_dynamic: the compiled RK4 of the dynamic plant is the generic RK4 of
DynamicPlant._rhs, bit for bit (pose, body velocities, thrusts, integrators and the four peaks), for thrusters
with lateral thrust (BlueROV2 Heavy; also with a loop that feeds no model forces forward) and for fins without it
(REMUS 100), at points drawn from their boxes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit import load_scenario
from tubekit.plant.compiled_dynamic import COEFFICIENTS, actuator_limits, coefficients
from tubekit.plant.dynamic import DynamicPlant
from tubekit.plant.kinematic import rk4_tuple

SCENARIOS = {name: load_scenario(f"examples/{name}.toml")
             for name in ("bluerov2_spread", "remus100_currents", "bluerov2_harbour")}  # the last: no feedforward
SPEED = st.floats(-0.6, 0.6)


@st.composite
def plant_pairs(draw) -> tuple[DynamicPlant, DynamicPlant]:
    """Two plants of one point vehicle drawn from a bundled example's coefficient box (the same point)."""
    scenario = SCENARIOS[draw(st.sampled_from(sorted(SCENARIOS)))]
    point = scenario.plant.params.sample(np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1))))
    return DynamicPlant(scenario, params=point), DynamicPlant(scenario, params=point)


@given(plant_pairs(), st.floats(0.0, 300.0), st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-5, 5),
                                                       st.floats(-7, 7)),
       st.lists(st.tuples(SPEED, st.floats(-0.3, 0.3), st.floats(-0.5, 0.5)), min_size=1, max_size=6),
       st.sampled_from([0.005, 0.01, 0.02]), st.integers(1, 3))
def test_the_compiled_kinematic_is_the_generic_rk4_of_the_dynamic_plant_bit_for_bit(pair, t, pose, commands, h, n):
    """Property: over a sequence of held commands, step_tuple (compiled) gives the very pose, internal state and
    peaks of rk4_tuple on DynamicPlant._rhs (the Python path the loop takes under a current override)."""
    compiled, generic = pair
    for v in commands:
        got = compiled.step_tuple(t, pose, v, h, n)
        if generic.state is None:  # as step_tuple starts: trimmed at the first command, or settled
            generic.state = generic._start(v) if generic._settled_at is None else \
                generic.settled_state(generic._settled_at)
        y = rk4_tuple(generic._rhs, t, (*pose, *generic.state), v, h, n)
        generic.state = y[4:]
        assert got == y[:4]
        assert compiled.state == generic.state
        pose, t = got, t + h * n
    assert compiled._peak == generic._peak


def test_the_packed_vehicle_reads_every_coefficient_and_the_mass_entries():
    params = SCENARIOS["bluerov2_spread"].plant.params.nominal
    packed = coefficients(params)
    assert packed.shape == (len(COEFFICIENTS) + 6,)
    assert packed[COEFFICIENTS.index("N_rr")] == params.N_rr
    assert tuple(packed[-6:]) == params.mass_entries


@pytest.mark.parametrize("name, fins", [("bluerov2_spread", 0.0), ("remus100_currents", 1.0)])
def test_the_actuator_limits_say_whether_the_fins_scale_with_the_surge(name, fins):
    params = SCENARIOS[name].plant.params.nominal
    limits = actuator_limits(params, 7.5)
    assert limits[3] == fins and limits[7] == 7.5
    assert limits[0] == params.X_max


def test_the_compiled_current_and_omega_series_are_their_formulas_tick_by_tick():
    """After a few steps, current_series is current_at at every time and omega_series is δ + R(ψ)(u_b − u_c, v_b),
    δ_z + w_b − w_c from the logged body velocities (NaN where the command is NaN or past the log)."""
    import math

    scenario = SCENARIOS["bluerov2_spread"]
    plant = DynamicPlant(scenario)
    rng = np.random.default_rng(3)
    t, pose, states, inputs = 0.0, (0.0, 0.0, 0.0, 0.3), [], []
    for _ in range(12):
        v = tuple(rng.uniform(-0.2, 0.2, 3).tolist())
        states.append(pose)
        inputs.append(v)
        pose, t = plant.step_tuple(t, pose, v, 0.005, 2), t + 0.01
    times = 0.01 * np.arange(14)
    states, inputs = np.array(states + [pose, pose]), np.array(inputs + [(math.nan,) * 3, (0.1, 0.0, 0.0)])
    body, _ = plant.history()
    current = np.array([plant.current_at(float(ti)) for ti in times])
    np.testing.assert_array_equal(plant.current_series(times), current)
    expected = np.full((14, 3), np.nan)
    for i in range(len(body)):
        if np.isfinite(inputs[i, 0]):
            c1, c2, c3 = current[i]
            du, vb, cp, sp = body[i, 0] - inputs[i, 0], body[i, 1], math.cos(states[i, 3]), math.sin(states[i, 3])
            expected[i] = (c1 + du * cp - vb * sp, c2 + du * sp + vb * cp, c3 + body[i, 2] - inputs[i, 1])
    np.testing.assert_array_equal(plant.omega_series(times, states, inputs), expected)
    assert len(body) == 13 and np.isnan(expected[12:]).all()


@given(st.integers(0, 2 ** 32 - 1), st.floats(0.0, 300.0),
       st.lists(st.tuples(SPEED, st.floats(-0.3, 0.3), st.floats(-0.5, 0.5), st.floats(-0.3, 0.3)),
                min_size=1, max_size=6),
       st.sampled_from([0.005, 0.01, 0.02]), st.integers(1, 3))
def test_the_compiled_sway_command_is_the_generic_rk4_bit_for_bit(seed, t, commands, h, n):
    """Property: with lateral thrust and a commanded sway velocity v_c (command[3]), step_tuple (compiled) gives
    the very pose, state and peaks of rk4_tuple on DynamicPlant._rhs under (u_c, w_c, r_c, v_c)."""
    scenario = SCENARIOS["bluerov2_spread"]
    point = scenario.plant.params.sample(np.random.default_rng(seed))
    compiled, generic = DynamicPlant(scenario, params=point), DynamicPlant(scenario, params=point)
    assert compiled.lateral
    pose = (0.0, 0.0, 0.0, 0.3)
    for u, w, r, vc in commands:
        got = compiled.step_tuple(t, pose, (u, w, r), h, n, sway=vc)
        if generic.state is None:
            generic.state = generic._start((u, w, r))
        y = rk4_tuple(generic._rhs, t, (*pose, *generic.state), (u, w, r, vc), h, n)
        generic.state = y[4:]
        assert got == y[:4]
        assert compiled.state == generic.state
        pose, t = got, t + h * n
    assert compiled._peak == generic._peak


def test_the_compiled_omega_series_subtracts_the_commanded_sway():
    """omega_series(sway=v_c) is δ + R(ψ)(u_b − u_c, v_b − v_c), δ_z + w_b − w_c tick by tick (None: v_c = 0)."""
    import math

    plant = DynamicPlant(SCENARIOS["bluerov2_spread"])
    rng = np.random.default_rng(5)
    t, pose, states, inputs, sway = 0.0, (0.0, 0.0, 0.0, 0.3), [], [], rng.uniform(-0.1, 0.1, 9)
    for i in range(8):
        v = tuple(rng.uniform(-0.2, 0.2, 3).tolist())
        states.append(pose)
        inputs.append(v)
        pose, t = plant.step_tuple(t, pose, v, 0.005, 2, sway=float(sway[i])), t + 0.01
    times, states, inputs = 0.01 * np.arange(9), np.array(states + [pose]), np.array(inputs + [(math.nan,) * 3])
    body, _ = plant.history()
    expected = np.full((9, 3), np.nan)
    for i in range(8):
        c1, c2, c3 = plant.current_at(float(times[i]))
        du, dv = body[i, 0] - inputs[i, 0], body[i, 1] - sway[i]
        cp, sp = math.cos(states[i, 3]), math.sin(states[i, 3])
        expected[i] = (c1 + du * cp - dv * sp, c2 + du * sp + dv * cp, c3 + body[i, 2] - inputs[i, 1])
    np.testing.assert_array_equal(plant.omega_series(times, states, inputs, sway=sway), expected)
    np.testing.assert_array_equal(plant.omega_series(times, states, inputs, sway=np.zeros(9)),
                                  plant.omega_series(times, states, inputs))
