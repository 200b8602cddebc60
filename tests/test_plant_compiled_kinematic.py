"""Tests of tubekit.plant.compiled_kinematic: the compiled RK4 is the generic RK4 of the plant's right-hand side, bit for
bit (states and the disturbance's peaks), and the compiled ω series is ω tick by tick, on currents, sways and
steps drawn at random."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.plant.base import PiecewiseOmega
from tubekit.plant.compiled_kinematic import NO_TABLE, rk4_current
from tubekit.plant.kinematic import Plant, rk4_tuple
from tubekit.settings import Disturbance
from tubekit.model.kinematics import SwayModel

SPEED = st.floats(-0.8, 0.8)


@st.composite
def plants(draw) -> Plant:
    """A kinematic plant with a drawn current (amplitude, constant, period) and sway (gain, amplitude, period)."""
    amplitude = tuple(draw(st.floats(0.0, 0.3)) for _ in range(3))
    constant = tuple(draw(st.floats(-0.2, 0.2)) for _ in range(3))
    sway = SwayModel(gain=draw(st.floats(0.0, 0.5)), amplitude=draw(st.floats(0.0, 0.1)),
                     period=draw(st.floats(1.0, 30.0)))
    return Plant(Disturbance(amplitude=amplitude, period=draw(st.floats(0.5, 60.0)), constant=constant, sway=sway))


@given(plants(), st.floats(0.0, 500.0), st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-5, 5),
                                                   st.floats(-7, 7)),
       st.tuples(SPEED, SPEED, st.floats(-1.0, 1.0)), st.floats(1e-4, 0.1), st.integers(1, 6))
def test_the_compiled_kinematic_is_the_generic_rk4_of_the_plant_bit_for_bit(plant, t, y, v, h, n):
    """Property: rk4_current returns the very state of rk4_tuple on Plant._rhs, and the very peaks it records."""
    generic = rk4_tuple(plant._rhs, t, y, v, h, n)
    u, _, r = v
    state, peak = rk4_current(t, y, v, h, n, plant.current_parameters, plant.sway_parameters(u, r), (0.0, 0.0),
                              NO_TABLE, 1.0)
    assert state == generic
    assert peak == plant.omega_peak()


def test_the_peaks_carry_over_between_calls_and_a_nan_peak_stays_nan():
    plant = Plant(Disturbance(amplitude=(0.1, 0.1, 0.05), period=10.0))
    current = plant.current_parameters
    _, peak = rk4_current(0.0, (0.0, 0.0, 0.0, 0.0), (0.3, 0.0, 0.2), 0.01, 2, current, (0.0, 0.0, 1.0), (5.0, 4.0),
                          NO_TABLE, 1.0)
    assert peak == (5.0, 4.0)
    _, peak = rk4_current(0.0, (0.0, 0.0, 0.0, 0.0), (0.3, 0.0, 0.2), 0.01, 2, current, (0.0, 0.0, 1.0),
                          (math.nan, 0.0), NO_TABLE, 1.0)
    assert math.isnan(peak[0]) and peak[1] == pytest.approx(0.05 * math.sin(2 * math.pi * 0.02 / 10.0), rel=1e-14)


@given(st.one_of(plants(), st.builds(lambda o: Plant(Disturbance(), o), st.deferred(lambda: piecewise_overrides()))),
       st.integers(1, 40), st.integers(0, 2 ** 32 - 1))
def test_the_compiled_omega_series_is_omega_tick_by_tick(plant, ticks, seed):
    """Property: Plant.omega_series (compiled) equals Plant.omega at every tick, NaN rows where u or r is NaN,
    under the modelled current and sway and under a piecewise-constant override."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 200.0, ticks))
    states, inputs = rng.uniform(-5.0, 5.0, (ticks, 4)), rng.uniform(-0.8, 0.8, (ticks, 3))
    inputs[rng.random(ticks) < 0.2, rng.integers(0, 3)] = np.nan
    expected = np.full((ticks, 3), np.nan)
    for i in range(ticks):
        if np.isfinite(inputs[i, 0]) and np.isfinite(inputs[i, 2]):
            expected[i] = plant.omega(float(t[i]), states[i], inputs[i])
    np.testing.assert_array_equal(plant.omega_series(t, states, inputs), expected)


@st.composite
def piecewise_overrides(draw) -> PiecewiseOmega:
    """A piecewise-constant ω (m/s) of 1 to 6 periods of 0.05 to 0.5 s, rows drawn in ±0.3 m/s."""
    rows = draw(st.integers(1, 6))
    table = tuple(tuple(draw(st.floats(-0.3, 0.3)) for _ in range(3)) for _ in range(rows))
    return PiecewiseOmega(table, draw(st.floats(0.05, 0.5)))


@given(piecewise_overrides(), st.floats(0.0, 3.0), st.tuples(SPEED, SPEED, st.floats(-1.0, 1.0)),
       st.floats(-7.0, 7.0), st.sampled_from([0.005, 0.01, 0.05]), st.integers(1, 6))
def test_a_piecewise_override_is_integrated_compiled_as_the_generic_rk4_does(override, t, v, psi, h, n):
    """Property: under a PiecewiseOmega override the plant's step (compiled) returns the very state and peaks of
    rk4_tuple on the plant's _rhs, including steps that cross a period's boundary."""
    compiled, generic = Plant(Disturbance(), override), Plant(Disturbance(), override)
    y = (0.3, -1.2, 0.4, psi)
    assert compiled.step_tuple(t, y, v, h, n) == rk4_tuple(generic._rhs, t, y, v, h, n)
    assert compiled.omega_peak() == generic.omega_peak()
