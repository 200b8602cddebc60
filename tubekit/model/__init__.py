"""The model: kinematics (eqs. 2, 11), the error geometry, the ancillary laws, trajectories, vehicles.

Numpy only: the sympy derivation (:mod:`tubekit.model.derivation`) is imported by the audit,
verify and the tests, never by this package's ``__init__``.
"""

from __future__ import annotations

from tubekit.model.ancillary import LAWS, AncillaryLaw, get_law, jacobian_at, register_law
from tubekit.model.errors import bearing, error_coordinates, heading_cosine, numeric
from tubekit.model.loiter import Loiter  # registers the loiter backup law (kind "loiter")
from tubekit.model.hold import Hold  # registers the hold backup law (kind "hold", lateral thrust)
from tubekit.model.no_backup import NoBackup  # registers "none": safety from the tracking tier alone
from tubekit.model.kinematics import (InputLimits, SwayModel, dsinc, kinematics, nominal_kinematics, sinc,
                                      unicycle_step)
from tubekit.model.thrusters import ThrusterGeometry
from tubekit.model.trajectory import Circle, Helix, Line, Trajectory, Waypoints, trajectory_from_dict
from tubekit.model.vehicles import VEHICLES, PlantSettings, VehicleParams, vehicle_params

__all__ = [
    "InputLimits", "SwayModel", "kinematics", "nominal_kinematics", "sinc", "dsinc", "unicycle_step",
    "error_coordinates", "bearing", "heading_cosine", "numeric",
    "AncillaryLaw", "LAWS", "get_law", "register_law", "jacobian_at",
    "Trajectory", "Circle", "Helix", "Line", "Waypoints", "trajectory_from_dict",
    "VehicleParams", "VEHICLES", "PlantSettings", "vehicle_params", "Loiter", "Hold", "NoBackup", "ThrusterGeometry",
]
