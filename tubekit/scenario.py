"""Scenarios: everything a run or a certificate needs, with the paper's Section VI as default.

A scenario is loaded from TOML (see ``docs/scenario.md`` and :func:`load_scenario`)
or built in Python. Values the paper leaves out are chosen here and documented:

* obstacle radius 0.4 m, vehicle radius 0.2 m (the paper gives neither);
* initial pose 0.5 m behind the target, 0.2 m above it, heading along the path;
* sway ``v_s = clip(0.1 u r, +-0.02 m/s)`` (:class:`tubekit.model.kinematics.SwayModel`);
* FHOCP weights Q, R, P (diagonal) and the verification region.

The FHOCP mode, the terminal mode and the heading hemisphere are str-valued enums
(:class:`FhocpMode`, :class:`TerminalMode`, :class:`Heading`): a member equals its string,
so TOML and JSON keep plain strings. The law stays a registered name (users register laws).
"""

from __future__ import annotations

import math
import tomllib
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.model.kinematics import InputLimits, SwayModel
from tubekit.model.trajectory import Circle, Trajectory, trajectory_from_dict
from tubekit.validation import (StrChoice, as_vector, choice, gain, period_count, positive, replace_fields, speed_bound,
                                text, ticks_per_period)
from tubekit.model.vehicles import PlantSettings

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


class FhocpMode(StrChoice):
    """FHOCP mode: one warm-started convex solve per step, or SCP to convergence."""

    REALTIME = "realtime"
    CONVERGED = "converged"


class TerminalMode(StrChoice):
    """Terminal set F: exact penalty, hard constraint, or none."""

    SOFT = "soft"
    HARD = "hard"
    OFF = "off"


class Heading(StrChoice):
    """Heading hemisphere of the region: cos(psi - theta) < 0 ("toward"), > 0 ("away"), or either."""

    TOWARD = "toward"
    AWAY = "away"
    BOTH = "both"


LAW_NAMES = ("paper", "corrected")
HEADINGS: tuple[str, ...] = Heading.values()
#: Sign of cos(psi - theta) in each heading hemisphere (0: either).
HEMISPHERE_SIGN: dict[str, int] = {Heading.TOWARD: -1, Heading.AWAY: 1, Heading.BOTH: 0}


@dataclass(frozen=True)
class Obstacle:
    """A spherical obstacle B(center, radius) (m)."""

    center: tuple[float, float, float]
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", tuple(float(c) for c in as_vector("obstacle.center", self.center, 3)))
        object.__setattr__(self, "radius", positive("obstacle.radius", self.radius))


@dataclass(frozen=True)
class Disturbance:
    """Current delta(t) plus sway; the total omega has ||omega|| <= omega_bar.

    ``delta(t) = amplitude * [sin(a), cos(a), sin(a)] + constant``,
    ``a = 2 pi t / period``; the paper uses amplitude 0.1 m/s, period 15 s.
    Evaluated by :class:`tubekit.plant.kinematic.Plant` (this class only holds the settings
    and their bounds).

    Parameters
    ----------
    amplitude : array (3,)
        Current amplitudes along x, y, z (m/s).
    period : float
        Current period (s).
    constant : array (3,)
        Constant current (m/s).
    sway : SwayModel
        Unactuated sway model.
    """

    amplitude: tuple[float, float, float] = (0.1, 0.1, 0.1)
    period: float = 15.0
    constant: tuple[float, float, float] = (0.0, 0.0, 0.0)
    sway: SwayModel = field(default_factory=SwayModel)

    def __post_init__(self) -> None:
        amp = as_vector("disturbance.amplitude", self.amplitude, 3)
        if np.any(amp < 0):
            raise ConfigError("disturbance.amplitude", "three numbers >= 0", self.amplitude)
        object.__setattr__(self, "amplitude", tuple(float(a) for a in amp))
        object.__setattr__(self, "period", positive("disturbance.period", self.period))
        object.__setattr__(self, "constant",
                           tuple(float(c) for c in as_vector("disturbance.constant", self.constant, 3)))
        speed_bound("disturbance.amplitude", max(math.hypot(*amp[::2]), amp[1]), list(self.amplitude))
        speed_bound("disturbance.constant", math.hypot(*self.constant), list(self.constant))

    @property
    def current_bound(self) -> float:
        """delta-bar: exact max over t of ||delta(t)|| for zero constant, else a triangle bound (m/s)."""
        a1, a2, a3 = self.amplitude
        periodic = math.sqrt(max(a1 * a1 + a3 * a3, a2 * a2))
        return periodic + float(np.linalg.norm(self.constant))

    @property
    def omega_bar(self) -> float:
        """omega-bar = delta-bar + gamma-bar (eq. Wset), m/s."""
        return self.current_bound + self.sway.bound


@dataclass(frozen=True)
class ControllerSettings:
    """Tube-MPC settings.

    Parameters
    ----------
    dt : float
        FHOCP sampling period delta_t (s).
    horizon_steps : int
        N; the horizon is T = N dt (s).
    Q, R, P : array (3,)
        Diagonals of the stage, input and terminal weights.
    law : str
        Ancillary law: a name in :data:`tubekit.model.ancillary.LAWS` (built-in: :data:`LAW_NAMES`).
    sigma : float or None
        Ancillary gain; ``None`` lets the verifier choose it.
    ancillary_rate_hz : float
        Rate of the ancillary feedback kappa (Hz); a multiple of 1/dt.
    terminal_level : float
        epsilon-bar of the terminal set F = {||e||_P <= epsilon-bar}.
    fhocp_mode : FhocpMode
        ``"realtime"`` (one convex solve per step, warm-started) or ``"converged"``
        (sequential convex programming to convergence), see :mod:`tubekit.fhocp`.
    terminal_mode : TerminalMode
        Terminal set F: ``"soft"`` (exact penalty), ``"hard"`` or ``"off"``.
    fhocp_backend : str
        FHOCP solver: a name in :func:`tubekit.fhocp.registry.backends` (``"scp"``, ``"ipopt"``);
        checked when the solver is built. Left out of :meth:`Scenario.to_dict` when ``"scp"``.
    """

    dt: float = 0.1
    horizon_steps: int = 8
    Q: tuple[float, float, float] = (1.0, 1.0, 0.5)
    R: tuple[float, float, float] = (0.5, 0.5, 0.1)
    P: tuple[float, float, float] = (5.0, 5.0, 2.5)
    law: str = "corrected"
    sigma: float | None = None
    ancillary_rate_hz: float = 100.0
    terminal_level: float = 2.0
    fhocp_mode: FhocpMode = FhocpMode.REALTIME
    terminal_mode: TerminalMode = TerminalMode.SOFT
    fhocp_backend: str = "scp"

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", positive("controller.dt", self.dt))
        if not isinstance(self.horizon_steps, int) or isinstance(self.horizon_steps, bool) or self.horizon_steps < 1:
            raise ConfigError("controller.horizon_steps", "an integer >= 1", self.horizon_steps)
        for name in ("Q", "R", "P"):
            vec = as_vector(f"controller.{name}", getattr(self, name), 3)
            if np.any(vec <= 0):
                raise ConfigError(f"controller.{name}", "three numbers > 0 (a positive diagonal)",
                                  getattr(self, name))
            object.__setattr__(self, name, tuple(float(x) for x in vec))
        from tubekit.model.ancillary import LAWS  # the registry: built-in laws plus registered ones
        if not isinstance(self.law, str) or self.law not in LAWS:
            raise ConfigError("controller.law", f"one of {tuple(LAWS)}", self.law)
        if self.sigma is not None:
            object.__setattr__(self, "sigma", gain("controller.sigma", self.sigma))
        object.__setattr__(self, "ancillary_rate_hz",
                           positive("controller.ancillary_rate_hz", self.ancillary_rate_hz))
        ticks_per_period("controller.ancillary_rate_hz", self.ancillary_rate_hz, "controller.dt", self.dt)
        object.__setattr__(self, "terminal_level", positive("controller.terminal_level", self.terminal_level))
        object.__setattr__(self, "fhocp_mode", choice("controller.fhocp_mode", FhocpMode, self.fhocp_mode))
        object.__setattr__(self, "terminal_mode", choice("controller.terminal_mode", TerminalMode,
                                                         self.terminal_mode))
        if not isinstance(self.fhocp_backend, str) or not self.fhocp_backend:
            raise ConfigError("controller.fhocp_backend", "a backend name (e.g. 'scp' or 'ipopt')",
                              self.fhocp_backend)

    @property
    def horizon(self) -> float:
        """Prediction horizon T = N dt (s)."""
        return self.horizon_steps * self.dt


@dataclass(frozen=True)
class RegionSettings:
    """The error region the verifier's bounds must hold over.

    e_d in [epsilon, e_d_max], |e_z| <= e_z_max, |e_o| <= e_o_max, heading
    hemisphere "toward" (cos(psi - bearing) < 0: the vehicle points at the
    target), "away" or "both". The FHOCP keeps the nominal inside the region
    shrunk by the tube, so the bounds apply along the closed loop.
    """

    e_d_max: float = 3.0
    e_z_max: float = 1.0
    e_o_max: float = 0.9
    heading: Heading = Heading.TOWARD

    def __post_init__(self) -> None:
        object.__setattr__(self, "e_d_max", positive("region.e_d_max", self.e_d_max))
        object.__setattr__(self, "e_z_max", positive("region.e_z_max", self.e_z_max))
        eo = positive("region.e_o_max", self.e_o_max)
        if eo >= 1.0:
            raise ConfigError("region.e_o_max", "a number in (0, 1) (|e_o| = 1 makes J singular)", eo)
        object.__setattr__(self, "e_o_max", eo)
        object.__setattr__(self, "heading", choice("region.heading", Heading, self.heading))


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
                           if v is not None and not (k == "fhocp_backend" and v == "scp")},
            "region": {k: (str(v) if isinstance(v, str) else v) for k, v in asdict(self.region).items()},
        }
        if self.limits.rate is not None:  # only when set: a scenario without it keeps its dict
            d["limits"]["rate"] = list(self.limits.rate)
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
        lim = _table(d, "limits", InputLimits, {"u_max", "w_max", "r_max", "rate"})
        b = base.limits
        kw["limits"] = InputLimits(lim.get("u_max", b.u_max), lim.get("w_max", b.w_max), lim.get("r_max", b.r_max),
                                   lim.get("rate", b.rate))
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


def read_toml(path: str | Path, field: str) -> dict:
    """The table of a TOML file; every failure is a :class:`ConfigError` naming ``field`` (e.g. ``CONFIG``)."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(field, "a path to an existing TOML file", str(p))
    try:
        return tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(field, "valid TOML", str(p), str(exc)) from None
    except UnicodeDecodeError:
        raise ConfigError(field, "a UTF-8 text (TOML) file", str(p), "It is binary or not UTF-8.") from None
    except OSError as exc:
        raise ConfigError(field, "a readable file", str(p), exc.strerror or str(exc)) from None


def load_scenario(path: str | Path) -> Scenario:
    """Load a scenario from a TOML file (see :func:`scenario_from_dict`)."""
    return scenario_from_dict(read_toml(path, "CONFIG"))
