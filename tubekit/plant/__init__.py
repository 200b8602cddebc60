"""The simulated vehicle: the kinematic plant of eq. (11) and the 4-DOF dynamic vehicle.

Both satisfy :class:`~tubekit.plant.base.PlantModel`; :func:`make_plant` picks one by the
scenario's ``[plant] kind``.
"""

from __future__ import annotations

from tubekit.plant.base import OmegaOverride, PlantModel
from tubekit.plant.factory import make_plant
from tubekit.plant.dynamic import DynamicPlant
from tubekit.plant.kinematic import Plant, nominal_arc, plant_rhs, rk4_hold, rk4_tuple, sway_velocity_term

__all__ = ["PlantModel", "OmegaOverride", "make_plant", "Plant", "DynamicPlant", "nominal_arc", "plant_rhs",
           "rk4_hold", "rk4_tuple", "sway_velocity_term"]
