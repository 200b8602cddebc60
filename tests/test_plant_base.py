"""The plant contract (:class:`tubekit.plant.base.PlantModel`): both plants offer every method of
the Protocol with its parameters, and behave as it documents on a case worked out by hand; the
piecewise-constant override's validation and indexing rule."""

from __future__ import annotations

import inspect
import math
from dataclasses import replace

import numpy as np
import pytest

from tubekit.model.vehicles import PlantSettings
from tubekit.plant.base import PiecewiseOmega, PlantModel
from tubekit.plant.dynamic import DynamicPlant
from tubekit.plant.kinematic import Plant
from tubekit.scenario import paper_scenario

#: The methods the closed loop calls on a plant, read from the Protocol itself.
PROTOCOL_METHODS = sorted(name for name, value in vars(PlantModel).items()
                          if inspect.isfunction(value) and not name.startswith("_"))


def _parameter_names(function) -> list[str]:
    return [p.name for p in inspect.signature(function).parameters.values()]


def missing_from(cls: type) -> list[str]:
    """The Protocol methods ``cls`` lacks, or offers with other parameter names (structural check)."""
    problems = []
    for name in PROTOCOL_METHODS:
        method = getattr(cls, name, None)
        if not callable(method):
            problems.append(f"{name}: missing")
        elif _parameter_names(method) != _parameter_names(getattr(PlantModel, name)):
            problems.append(f"{name}: {_parameter_names(method)} != {_parameter_names(getattr(PlantModel, name))}")
    return problems


def test_the_protocol_names_what_the_loop_calls():
    assert PROTOCOL_METHODS == ["current_at", "current_peak", "current_series", "history", "omega_peak", "omega_series",
                                "step", "step_tuple"]


@pytest.mark.parametrize("cls", [Plant, DynamicPlant])
def test_both_plants_satisfy_the_protocol_structurally(cls):
    assert missing_from(cls) == []


def test_the_structural_check_rejects_a_plant_that_lacks_a_method_or_renames_a_parameter():
    class NoHistory:
        def step_tuple(self, t, x, v, h, n, sway=0.0): ...
        def step(self, t, x, v, h, n, sway=0.0): ...
        def current_at(self, t): ...
        def omega_series(self, t, states, inputs, sway=None): ...
        def omega_peak(self): ...
        def current_series(self, t): ...
        def current_peak(self): ...

    class Renamed(NoHistory):
        def history(self): ...
        def step(self, t, x, v, dt, n, sway=0.0): ...

    assert missing_from(NoHistory) == ["history: missing"]
    assert missing_from(Renamed) == ["step: ['self', 't', 'x', 'v', 'dt', 'n', 'sway'] != "
                                     "['self', 't', 'x', 'v', 'h', 'n', 'sway']"]


def _plant(kind: str, override=None) -> PlantModel:
    scenario = paper_scenario()
    scenario = replace(scenario, plant=PlantSettings(kind=kind))
    return Plant.of(scenario, override) if kind == "kinematic" else DynamicPlant(scenario, override)


WATER = (0.1, -0.2, 0.05)  # m/s, a constant current replacing the scenario's


@pytest.mark.parametrize("kind", ["kinematic", "dynamic"])
def test_at_rest_the_vehicle_drifts_with_the_water(kind):
    """Command v = 0 from rest: the pose moves by (water velocity) * (n h) and the heading stays.

    By hand: x' = u cos psi - v sin psi + c_1 with u = v = 0 (kinematic: f(x) 0 = 0; dynamic: the
    trimmed start nu = (0, 0, 0, 0) with tau = n(0) = 0 stays at rest), so x(T) = x(0) + c T.
    """
    plant = _plant(kind, override=lambda t: WATER)
    x0, h, n = (1.0, 2.0, -3.0, 0.4), 0.05, 40
    end = plant.step_tuple(0.0, x0, (0.0, 0.0, 0.0), h, n)
    assert isinstance(end, tuple) and len(end) == 4
    T = h * n
    assert end == pytest.approx((1.0 + WATER[0] * T, 2.0 + WATER[1] * T, -3.0 + WATER[2] * T, 0.4), abs=1e-12)


@pytest.mark.parametrize("kind", ["kinematic", "dynamic"])
def test_step_is_step_tuple_on_arrays(kind):
    first, second = _plant(kind), _plant(kind)
    x0, v = np.array([0.0, 0.0, -1.0, 0.3]), np.array([1.0, 0.1, 0.05])
    as_array = first.step(0.0, x0, v, 0.01, 10)
    as_tuple = second.step_tuple(0.0, tuple(x0), tuple(v), 0.01, 10)
    assert isinstance(as_array, np.ndarray) and as_array.shape == (4,)
    assert np.array_equal(as_array, np.array(as_tuple))


def test_only_the_dynamic_plant_has_a_body_history():
    kinematic, dynamic = _plant("kinematic"), _plant("dynamic")
    for plant in (kinematic, dynamic):
        plant.step_tuple(0.0, (0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.01, 5)
        plant.step_tuple(0.05, (0.05, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.01, 5)
    assert kinematic.history() == (None, None)
    body, thrust = dynamic.history()
    assert body.shape == (3, 4) and thrust.shape == (3, 3)  # two ticks logged at their start, plus the end
    assert body[0] == pytest.approx([1.0, 0.0, 0.0, 0.0])  # the trimmed start: nu = (u_c, 0, w_c, r_c)


@pytest.mark.parametrize("kind", ["kinematic", "dynamic"])
def test_current_at_is_the_override_or_the_scenario_current(kind):
    plain = _plant(kind).current_at(0.0)
    expected = paper_scenario().disturbance
    # by hand, at t = 0: delta = amplitude * [sin 0, cos 0, sin 0] + constant
    assert plain == pytest.approx((expected.constant[0], expected.amplitude[1] + expected.constant[1],
                                   expected.constant[2]))
    if kind == "dynamic":  # the dynamic plant's current is the override (the kinematic one applies it in omega)
        assert _plant(kind, override=lambda t: WATER).current_at(2.0) == WATER


@pytest.mark.parametrize("kind", ["kinematic", "dynamic"])
def test_omega_series_measures_the_water_at_rest_and_nan_without_an_input(kind):
    """At rest in a constant override the disturbance omega = x' - f(x) v is the water velocity itself."""
    plant = _plant(kind, override=lambda t: WATER)
    h, n, ticks = 0.05, 4, 3
    t = np.arange(ticks + 1) * h * n
    states = [np.array([0.0, 0.0, 0.0, 0.4])]
    for k in range(ticks):
        states.append(plant.step(t[k], states[-1], np.zeros(3), h, n))
    inputs = np.vstack([np.zeros((ticks, 3)), np.full((1, 3), np.nan)])  # no command after the last tick
    omega = plant.omega_series(t, np.array(states), inputs)
    assert omega.shape == (ticks + 1, 3)
    assert omega[:ticks] == pytest.approx(np.tile(WATER, (ticks, 1)), abs=1e-12)
    assert np.all(np.isnan(omega[ticks]))


@pytest.mark.parametrize("kind", ["kinematic", "dynamic"])
def test_only_the_dynamic_plant_reports_the_water_current_apart(kind):
    """The dynamic plant's ω holds the hull's sway and the loop error besides the water (issue 30): it reports
    the water apart, at the ticks and over every stage (here the override: exactly WATER). The kinematic
    plant's ω is what the certificate assumes, not split: None."""
    plant = _plant(kind, override=lambda t: WATER)
    plant.step_tuple(0.0, (0.0, 0.0, 0.0, 0.0), (0.3, 0.05, 0.2), 0.01, 5)
    t = np.array([0.0, 0.05])
    if kind == "kinematic":
        assert plant.current_series(t) is None and plant.current_peak() is None
        return
    assert plant.current_series(t).shape == (2, 3) and np.all(plant.current_series(t) == WATER)
    assert plant.current_peak() == (math.hypot(WATER[0], WATER[1]), abs(WATER[2]))
    assert plant.omega_peak() != plant.current_peak()  # ω also holds the hull's sway and the loop error


@pytest.mark.parametrize("period, table", [(0.0, ((0.0, 0.0, 0.0),)), (-1.0, ((0.0, 0.0, 0.0),)),
                                           (math.nan, ((0.0, 0.0, 0.0),)), (0.1, ()), (0.1, ((0.0, 0.0),))])
def test_a_piecewise_override_needs_a_positive_period_and_rows_of_three(period, table):
    with pytest.raises(ValueError, match="PiecewiseOmega"):
        PiecewiseOmega(table, period)


def test_a_piecewise_override_holds_its_last_row_after_the_table_and_counts_a_rounding_below_a_boundary_as_on_it():
    omega = PiecewiseOmega(((1.0, 0.0, 0.0), (2.0, 0.0, 0.0)), 0.1)
    assert omega(0.0)[0] == 1.0 and omega(0.0999999)[0] == 1.0
    assert omega(3 * 0.1 - 0.2 - 1e-12)[0] == 2.0     # 0.1 less a rounding: already the second period
    assert omega(50.0)[0] == 2.0
