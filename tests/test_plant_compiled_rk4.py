"""Tests of tubekit.plant.compiled_rk4: the compiled RK4 is the generic RK4 of the plant's right-hand side, bit for
bit (states and the disturbance's peaks), on currents, sways and steps drawn at random."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.plant.compiled_rk4 import rk4_current
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
def test_the_compiled_rk4_is_the_generic_rk4_of_the_plant_bit_for_bit(plant, t, y, v, h, n):
    """Property: rk4_current returns the very state of rk4_tuple on Plant._rhs, and the very peaks it records."""
    generic = rk4_tuple(plant._rhs, t, y, v, h, n)
    u, _, r = v
    state, peak = rk4_current(t, y, v, h, n, plant.current_parameters, plant.sway_parameters(u, r), (0.0, 0.0))
    assert state == generic
    assert peak == plant.omega_peak()


def test_the_peaks_carry_over_between_calls_and_a_nan_peak_stays_nan():
    plant = Plant(Disturbance(amplitude=(0.1, 0.1, 0.05), period=10.0))
    current = plant.current_parameters
    _, peak = rk4_current(0.0, (0.0, 0.0, 0.0, 0.0), (0.3, 0.0, 0.2), 0.01, 2, current, (0.0, 0.0, 1.0), (5.0, 4.0))
    assert peak == (5.0, 4.0)
    _, peak = rk4_current(0.0, (0.0, 0.0, 0.0, 0.0), (0.3, 0.0, 0.2), 0.01, 2, current, (0.0, 0.0, 1.0),
                          (math.nan, 0.0))
    assert math.isnan(peak[0]) and peak[1] == pytest.approx(0.05 * math.sin(2 * math.pi * 0.02 / 10.0), rel=1e-14)
