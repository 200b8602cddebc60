"""Choose the plant of a scenario: :func:`make_plant` (``[plant] kind``)."""

from __future__ import annotations

from tubekit.exceptions import ConfigError
from tubekit.model.vehicles import PLANT_KINDS
from tubekit.plant.base import OmegaOverride, PlantModel
from tubekit.plant.dynamic import DynamicPlant
from tubekit.plant.kinematic import Plant
from tubekit.scenario import Scenario

__all__ = ["make_plant"]


def make_plant(scenario: Scenario, override: OmegaOverride | None = None, kind: str | None = None) -> PlantModel:
    """The plant of ``scenario``: ``kind`` (default ``scenario.plant.kind``), one of ``PLANT_KINDS``.

    Raises
    ------
    ConfigError
        An unknown ``kind``.
    """
    kind = scenario.plant.kind if kind is None else kind
    if kind == "dynamic":
        return DynamicPlant(scenario, override)
    if kind == "kinematic":
        return Plant.of(scenario, override)
    raise ConfigError("plant", f"one of {PLANT_KINDS}", kind)
