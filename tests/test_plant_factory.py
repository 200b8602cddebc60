"""Choosing the plant (:func:`tubekit.plant.make_plant`): by the scenario's ``[plant] kind`` or an
explicit ``kind``, the override handed through, and every unknown kind refused with a ConfigError."""

from __future__ import annotations

from dataclasses import replace

import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.vehicles import PlantSettings
from tubekit.plant import DynamicPlant, Plant, make_plant
from tubekit.scenario import paper_scenario


def _scenario(kind: str):
    return replace(paper_scenario(), plant=PlantSettings(kind=kind))


@pytest.mark.parametrize("scenario_kind, kind, cls", [
    ("kinematic", None, Plant),
    ("dynamic", None, DynamicPlant),
    ("kinematic", "dynamic", DynamicPlant),   # the argument wins over the scenario
    ("dynamic", "kinematic", Plant),
])
def test_the_kind_comes_from_the_argument_else_the_scenario(scenario_kind, kind, cls):
    assert type(make_plant(_scenario(scenario_kind), kind=kind)) is cls


def test_the_default_scenario_runs_the_kinematic_plant():
    assert type(make_plant(paper_scenario())) is Plant


@pytest.mark.parametrize("kind", ["kinematic", "dynamic"])
def test_the_plant_is_built_from_the_scenario_and_keeps_the_override(kind):
    scenario = _scenario(kind)
    water = (0.3, 0.0, -0.1)

    def override(t):
        return water

    plant = make_plant(scenario, override)
    assert plant.override is override
    # x(T) = x(0) + water T at rest (the override replaces the scenario's current in both plants)
    assert plant.step_tuple(0.0, (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 0.1, 10) == pytest.approx(
        (0.3, 0.0, -0.1, 1.0), abs=1e-12)
    if kind == "kinematic":
        assert plant.disturbance is scenario.disturbance
    else:
        assert plant.params == scenario.plant.truth_params


@pytest.mark.parametrize("kind, received", [
    ("hovercraft", "'hovercraft'"),
    ("Dynamic", "'Dynamic'"),          # kinds are case-sensitive
    ("kinematic ", "'kinematic '"),    # no silent strip
    ("", "''"),
    (3, "3"),
])
def test_an_unknown_kind_is_a_config_error(kind, received):
    with pytest.raises(ConfigError, match=rf"^plant: expected one of \('kinematic', 'dynamic'\), "
                                          rf"received {received}$") as caught:
        make_plant(paper_scenario(), kind=kind)
    assert caught.value.field == "plant" and caught.value.received == kind
