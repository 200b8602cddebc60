"""tubekit: reproducible, verifiable tube-based NMPC for underactuated AUVs.

Role subpackages (``docs/architecture.md``): :mod:`tubekit.model` (kinematics, error geometry,
laws, trajectories, vehicles), :mod:`tubekit.plant` (the simulated vehicle), :mod:`tubekit.fhocp`
(the FHOCP and its solvers), :mod:`tubekit.loop` (the closed loop, its result, metrics and
promises), :mod:`tubekit.paper` (the printed equations and their audit) and :mod:`tubekit.app`
(the command line, files and figures). ``import tubekit`` loads neither sympy nor matplotlib.
"""

from __future__ import annotations

from typing import Any

from tubekit.api import Certified, simulate
from tubekit.design_inputs import DesignInputs
from tubekit.exceptions import ConfigError, NotAvailableError, ShapeError, SolverError, TubekitError
from tubekit.loop.promises import Promise, check_promises
from tubekit.loop.result import SimulationResult
from tubekit.model.ancillary import LAWS, AncillaryLaw, get_law, register_law
from tubekit.model.errors import error_coordinates, numeric
from tubekit.model.kinematics import InputLimits, SwayModel, kinematics, nominal_kinematics
from tubekit.model.trajectory import Circle, Helix, Line, Trajectory, Waypoints
from tubekit.scenario import (ControllerSettings, Disturbance, Obstacle, RegionSettings, Scenario,
                              load_scenario, paper_scenario, scenario_from_dict)
from tubekit.tightening import Tightening
from tubekit.tiers import Tiers
from tubekit.version import __version__

__all__ = [
    "__version__",
    "TubekitError", "ConfigError", "ShapeError", "SolverError", "NotAvailableError",
    "InputLimits", "SwayModel", "kinematics", "nominal_kinematics",
    "derive", "numeric", "error_coordinates",
    "AncillaryLaw", "LAWS", "get_law", "register_law",
    "Trajectory", "Circle", "Helix", "Line", "Waypoints",
    "Obstacle", "Disturbance", "ControllerSettings", "RegionSettings", "Scenario",
    "paper_scenario", "load_scenario", "scenario_from_dict",
    "Tightening", "Tiers", "DesignInputs", "Certified",
    "simulate", "SimulationResult", "Promise", "check_promises",
]


def __getattr__(name: str) -> Any:
    """``tubekit.derive``: the sympy derivation, imported on first use (``import tubekit`` stays sympy-free)."""
    if name == "derive":
        from tubekit.model.derivation import derive

        return derive
    raise AttributeError(f"module 'tubekit' has no attribute {name!r}")
