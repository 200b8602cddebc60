"""tubekit: reproducible, verifiable tube-based NMPC for underactuated AUVs."""

from __future__ import annotations

from .ancillary import LAWS, AncillaryLaw, get_law, register_law
from .api import simulate
from .derivation import derive, error_coordinates, numeric
from .exceptions import ConfigError, NotAvailableError, ShapeError, SolverError, TubekitError
from .model import InputLimits, SwayModel, kinematics, nominal_kinematics
from .scenario import (ControllerSettings, Disturbance, Obstacle, RegionSettings, Scenario,
                       load_scenario, paper_scenario, scenario_from_dict)
from .promises import Promise, check_promises
from .simulation_result import SimulationResult
from .tightening import Tightening
from .trajectory import Circle, Helix, Line, Trajectory, Waypoints

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "TubekitError", "ConfigError", "ShapeError", "SolverError", "NotAvailableError",
    "InputLimits", "SwayModel", "kinematics", "nominal_kinematics",
    "derive", "numeric", "error_coordinates",
    "AncillaryLaw", "LAWS", "get_law", "register_law",
    "Trajectory", "Circle", "Helix", "Line", "Waypoints",
    "Obstacle", "Disturbance", "ControllerSettings", "RegionSettings", "Scenario",
    "paper_scenario", "load_scenario", "scenario_from_dict",
    "Tightening",
    "simulate", "SimulationResult", "Promise", "check_promises",
]
