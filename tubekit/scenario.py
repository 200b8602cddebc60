"""Scenarios: everything a run or a certificate needs, with the paper's Section VI as default.

A scenario is loaded from TOML (see ``docs/scenario.md`` and :func:`load_scenario`)
or built in Python. Values the paper leaves out are chosen here and documented:

* obstacle radius 0.4 m, vehicle radius 0.2 m (the paper gives neither);
* initial pose 0.5 m behind the target, 0.2 m above it, heading along the path;
* sway ``v_s = clip(0.1 u r, +-0.02 m/s)`` (:class:`tubekit.model.kinematics.SwayModel`);
* FHOCP weights Q, R, P (diagonal) and the verification region.

The settings of each component (obstacles, current, controller, region, and the str-valued enums
:class:`FhocpMode`, :class:`TerminalMode`, :class:`Heading`) live in :mod:`tubekit.settings` and are
re-exported here; :class:`Scenario` composes them.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.model.kinematics import InputLimits, SwayModel
from tubekit.model.trajectory import Circle, Trajectory, trajectory_from_dict
from tubekit.model.vehicles import PlantSettings
from tubekit.settings import (HEADINGS, HEMISPHERE_SIGN, LAW_NAMES, ControllerSettings, Disturbance, FhocpMode,
                              Heading, Obstacle, RegionSettings, TerminalMode)
from tubekit.validation import as_vector, period_count, positive, read_toml, replace_fields, text

__all__ = [
    "Obstacle",
    "Disturbance",
    "ControllerSettings",
    "RegionSettings",
    "Scenario",
    "paper_scenario",
    "read_toml",
    "HEMISPHERE_SIGN",
    "load_scenario",
    "scenario_from_dict",
    "LAW_NAMES",
    "HEADINGS",
    "FhocpMode",
    "TerminalMode",
    "Heading",
]


@dataclass(frozen=True)
class Scenario:
    """A complete scenario (units: m, s, rad).

    Parameters
    ----------
    name : str
        Label used in outputs.
    trajectory : Trajectory
        Desired trajectory p_d(t).
    obstacles : tuple of Obstacle
        Static spherical obstacles.
    limits : InputLimits
        Input set V.
    vehicle_radius : float
        r-bar, radius of the ball covering the vehicle (m).
    sensing_range : float
        R-bar (m); obstacles join the FHOCP once their surface is within it.
    epsilon : float
        Lower bound on e_d (m).
    duration : float
        Simulated time (s).
    initial_state : array (4,)
        [x, y, z, psi] at t = 0.
    disturbance : Disturbance
        Current and sway.
    controller : ControllerSettings
        Tube-MPC settings.
    region : RegionSettings
        Verification region.
    workspace : tuple of two (3,) arrays or None
        Axis-aligned workspace box [lower, upper] (m).
    plant : PlantSettings
        ``[plant]``: kinematic (default) or the dynamic 4-DOF vehicle (``docs/plant.md``).
    """

    name: str = "paper-section-VI"
    trajectory: Trajectory = field(default_factory=Circle)
    obstacles: tuple[Obstacle, ...] = ()
    limits: InputLimits = field(default_factory=lambda: InputLimits(0.4, 0.3, 0.5))
    vehicle_radius: float = 0.2
    sensing_range: float = 1.5
    epsilon: float = 0.1
    duration: float = 100.0
    initial_state: tuple[float, float, float, float] = (-0.5, 3.0, 0.2, 0.0)
    disturbance: Disturbance = field(default_factory=Disturbance)
    controller: ControllerSettings = field(default_factory=ControllerSettings)
    region: RegionSettings = field(default_factory=RegionSettings)
    workspace: tuple[tuple[float, float, float], tuple[float, float, float]] | None = (
        (-10.0, -10.0, -5.0), (10.0, 10.0, 5.0))
    plant: PlantSettings = field(default_factory=PlantSettings)

    def __post_init__(self) -> None:
        text("name", self.name)
        object.__setattr__(self, "vehicle_radius", positive("vehicle_radius", self.vehicle_radius))
        object.__setattr__(self, "sensing_range", positive("sensing_range", self.sensing_range))
        if self.sensing_range <= self.vehicle_radius:
            raise ConfigError("sensing_range", f"a number > vehicle_radius = {self.vehicle_radius}",
                              self.sensing_range, "the paper requires R-bar > r-bar")
        object.__setattr__(self, "epsilon", positive("epsilon", self.epsilon))
        object.__setattr__(self, "duration", positive("duration", self.duration))
        object.__setattr__(self, "initial_state",
                           tuple(float(x) for x in as_vector("initial_state", self.initial_state, 4)))
        obstacles = tuple(o if isinstance(o, Obstacle) else Obstacle(**o) for o in self.obstacles)
        object.__setattr__(self, "obstacles", obstacles)
        for i, a in enumerate(obstacles):
            for j in range(i + 1, len(obstacles)):
                b = obstacles[j]
                gap = float(np.linalg.norm(np.subtract(a.center, b.center)))
                need = 2 * self.vehicle_radius + a.radius + b.radius
                if gap <= need:
                    raise ConfigError(
                        f"obstacles[{i}], obstacles[{j}]",
                        f"centres more than 2 r-bar + r_i + r_j = {need:.4g} m apart (eq. obstacle_dis)",
                        f"{gap:.4g} m", "move the obstacles apart or shrink them")
        if self.region.e_d_max <= self.epsilon:
            raise ConfigError("region.e_d_max", f"a number > epsilon = {self.epsilon}", self.region.e_d_max,
                              "the region e_d in [epsilon, e_d_max] would be empty")
        if self.workspace is not None:
            lo = as_vector("workspace[0]", self.workspace[0], 3)
            hi = as_vector("workspace[1]", self.workspace[1], 3)
            if np.any(hi <= lo):
                raise ConfigError("workspace", "lower < upper on every axis", self.workspace)
            object.__setattr__(self, "workspace", (tuple(float(x) for x in lo), tuple(float(x) for x in hi)))
        period_count("duration", self.duration, self.controller.dt)
        self._check_lateral_backup()
        self._check_settled_start()

    def _check_settled_start(self) -> None:
        """A settled start (``[plant] start = "settled"``) needs a rate limit, so that the first command lies within
        J of ``limits.initial`` (a jump the loop's bound counts), and a straight run there (w = r = 0: heave and
        yaw at rest, so the hull's sway is at rest too and the loop's equilibrium exists)."""
        if not self.plant.settled:
            return
        if self.limits.rate is None:
            raise ConfigError("plant.start", "'trimmed' without limits.rate (a settled start needs the first command "
                              "within the plans' jump of limits.initial)", self.plant.start)
        start = self.limits.start_command
        if start[1] != 0.0 or start[2] != 0.0:
            raise ConfigError("limits.initial", "w = r = 0 under a settled start (the loop settles on a straight "
                              "run)", [float(x) for x in start])

    def _check_lateral_backup(self) -> None:
        """A backup law that commands sway (``controller.backup = "hold"``) needs a dynamic plant whose vehicle has
        lateral thrust (``Y_max`` > 0): the kinematic plant and a free-swaying hull take no sway command."""
        from tubekit.model.backup import BACKUP_LAWS  # the registry (tubekit.model registers every law)
        if not BACKUP_LAWS[self.controller.backup].lateral:
            return
        if not (self.plant.dynamic and self.plant.params.lateral):
            raise ConfigError("controller.backup", "a law without a sway command (station_keeping, loiter) unless "
                              "[plant] is dynamic with lateral thrust (Y_max > 0)", self.controller.backup)

    @property
    def steps(self) -> int:
        """Number of FHOCP sampling periods in the run."""
        return int(round(self.duration / self.controller.dt))

    def with_changes(self, **changes: Any) -> "Scenario":
        """A copy with fields replaced; a dotted name reaches into a nested settings object.

        ``sc.with_changes(duration=20.0, **{"limits.u_max": 0.3, "controller.fhocp_mode": "converged"})``.
        Every changed object is rebuilt, so its validation runs again.

        Raises
        ------
        ConfigError
            An unknown field (named in full), or a value its owner rejects.
        """
        return replace_fields(self, changes)

    def to_dict(self) -> dict:
        """A JSON/TOML-friendly description (the inverse of :func:`scenario_from_dict`)."""
        d = {
            "name": self.name,
            "trajectory": self.trajectory.to_dict(),
            "obstacles": [{"center": list(o.center), "radius": o.radius} for o in self.obstacles],
            "limits": {"u_max": self.limits.u_max, "w_max": self.limits.w_max, "r_max": self.limits.r_max},
            "vehicle_radius": self.vehicle_radius,
            "sensing_range": self.sensing_range,
            "epsilon": self.epsilon,
            "duration": self.duration,
            "initial_state": list(self.initial_state),
            "disturbance": {
                "amplitude": list(self.disturbance.amplitude),
                "period": self.disturbance.period,
                "constant": list(self.disturbance.constant),
                "sway": asdict(self.disturbance.sway),
            },
            "controller": {k: (list(v) if isinstance(v, tuple) else str(v) if isinstance(v, str) else v)
                           for k, v in asdict(self.controller).items()
                           if v is not None and not (k == "fhocp_backend" and v == "scp")
                           and not (k == "backup" and v == "station_keeping")
                           and not (k in ("candidate", "recovery") and v is True)
                           and not (k == "lookahead" and v == 0.0)},
            "region": {k: (str(v) if isinstance(v, str) else v) for k, v in asdict(self.region).items()},
        }
        if self.limits.rate is not None:  # only when set: a scenario without it keeps its dict
            d["limits"]["rate"] = list(self.limits.rate)
        if self.limits.u_min is not None:  # likewise: a symmetric box keeps its dict (and its design key)
            d["limits"]["u_min"] = self.limits.u_min
        if self.limits.initial is not None:  # likewise: a start at rest keeps its dict
            d["limits"]["initial"] = list(self.limits.initial)
        if self.workspace is not None:
            d["workspace"] = [list(self.workspace[0]), list(self.workspace[1])]
        if self.plant != PlantSettings():  # the default kinematic plant leaves the dict as before
            d["plant"] = self.plant.to_dict()
        return d


def paper_scenario() -> Scenario:
    """Section VI of the paper, with the choices it leaves out filled in (see module doc)."""
    return Scenario(
        obstacles=(Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((-3.0, 0.0, 0.0), 0.4)),
    )


_TOP_KEYS = {"name", "trajectory", "obstacles", "limits", "vehicle_radius", "sensing_range", "epsilon",
             "duration", "initial_state", "disturbance", "controller", "region", "workspace", "plant"}


@contextmanager
def _field_prefix(old: str, new: str):
    """Re-raise errors of a nested constructor with the full TOML path (``old`` -> ``new``)."""
    try:
        yield
    except ShapeError as exc:
        name = new + exc.name[len(old):] if exc.name.startswith(old) else f"{new}.{exc.name}"
        raise ShapeError(name, exc.expected, exc.received) from None
    except ConfigError as exc:
        name = new + exc.field[len(old):] if exc.field.startswith(old) else f"{new}.{exc.field}"
        raise ConfigError(name, exc.expected, exc.received) from None


def _table(d: dict, key: str, cls, allowed: set[str]):
    sub = d.get(key, {})
    if not isinstance(sub, dict):
        raise ConfigError(key, "a table", sub)
    unknown = set(sub) - allowed
    if unknown:
        raise ConfigError(f"{key}.{sorted(unknown)[0]}", f"one of the keys {sorted(allowed)}",
                          sorted(unknown)[0])
    return sub


def scenario_from_dict(d: dict) -> Scenario:
    """Build a :class:`Scenario` from a dict (parsed TOML); missing keys take the paper's values.

    Raises
    ------
    ConfigError
        Naming the offending field and what was expected.
    """
    if not isinstance(d, dict):
        raise ConfigError("scenario", "a table", type(d).__name__)
    unknown = set(d) - _TOP_KEYS
    if unknown:
        raise ConfigError(sorted(unknown)[0], f"one of the top-level keys {sorted(_TOP_KEYS)}", sorted(unknown)[0])
    base = paper_scenario()
    kw: dict[str, Any] = {}
    if "name" in d:
        kw["name"] = text("name", d["name"])
    if "trajectory" in d:
        kw["trajectory"] = trajectory_from_dict(d["trajectory"])
    if "obstacles" in d:
        obs = d["obstacles"]
        if not isinstance(obs, list):
            raise ConfigError("obstacles", "a list of {center, radius} tables", obs)
        built = []
        for i, o in enumerate(obs):
            if not isinstance(o, dict) or set(o) != {"center", "radius"}:
                raise ConfigError(f"obstacles[{i}]", "a table with exactly 'center' and 'radius'", o)
            with _field_prefix("obstacle", f"obstacles[{i}]"):
                built.append(Obstacle(o["center"], o["radius"]))
        kw["obstacles"] = tuple(built)
    if "limits" in d:
        lim = _table(d, "limits", InputLimits, {"u_max", "w_max", "r_max", "rate", "u_min", "initial"})
        b = base.limits
        kw["limits"] = InputLimits(lim.get("u_max", b.u_max), lim.get("w_max", b.w_max), lim.get("r_max", b.r_max),
                                   lim.get("rate", b.rate), lim.get("u_min", b.u_min), lim.get("initial", b.initial))
    for key in ("vehicle_radius", "sensing_range", "epsilon", "duration"):
        if key in d:
            kw[key] = d[key]
    if "initial_state" in d:
        kw["initial_state"] = d["initial_state"]
    if "disturbance" in d:
        dist = dict(_table(d, "disturbance", Disturbance, {"amplitude", "period", "constant", "sway"}))
        sway = dist.pop("sway", None)
        if sway is not None:
            if not isinstance(sway, dict) or set(sway) - {"gain", "amplitude", "period", "bound"}:
                raise ConfigError("disturbance.sway", "a table with keys gain, amplitude, period, bound", sway)
            with _field_prefix("sway", "disturbance.sway"):
                dist["sway"] = SwayModel(**sway)
        kw["disturbance"] = Disturbance(**dist)
    if "controller" in d:
        ctrl = _table(d, "controller", ControllerSettings, set(ControllerSettings.__dataclass_fields__))
        kw["controller"] = ControllerSettings(**ctrl)
    if "region" in d:
        reg = _table(d, "region", RegionSettings, set(RegionSettings.__dataclass_fields__))
        kw["region"] = RegionSettings(**reg)
    if "workspace" in d:
        ws = d["workspace"]
        if ws is not None and (not isinstance(ws, list) or len(ws) != 2):
            raise ConfigError("workspace", "[[x_lo, y_lo, z_lo], [x_hi, y_hi, z_hi]]", ws)
        kw["workspace"] = None if ws is None else (tuple(ws[0]), tuple(ws[1]))
    if "plant" in d:
        kw["plant"] = PlantSettings.from_dict(d["plant"])
    return replace(base, **kw)


def load_scenario(path: str | Path) -> Scenario:
    """Load a scenario from a TOML file (see :func:`scenario_from_dict`); a relative ``[plant] vehicle_file`` is
    read from the scenario file's folder."""
    d = read_toml(path, "CONFIG")
    plant = d.get("plant")
    if isinstance(plant, dict) and isinstance(plant.get("vehicle_file"), str):
        d = {**d, "plant": {**plant, "vehicle_file": str(Path(path).parent / plant["vehicle_file"])}}
    return scenario_from_dict(d)
