"""Shipped vehicle parameter sets for the dynamic plant, and the scenario's ``[plant]`` settings.

:class:`VehicleParams` holds one 4-DOF (surge, sway, heave, yaw) vehicle: rigid-body
and added mass, quadratic cross-flow drag, body/fin lift, thrust limits, thruster
time constant and the low-level velocity loop's bandwidth. Units are SI: kg,
kg m², kg/m (quadratic), kg (lift, per m/s of surge), N, N m, s, rad/s.
Every value, its unit and its source are listed in ``docs/plant.md``.

:data:`VEHICLES` maps a name to its published set; ``remus100`` is REMUS 100
reduced to 4-DOF with the coefficients of Prestero (2001), Table 4.x (body
at the centre of buoyancy, x_g = 0, neutral buoyancy W = B).
:class:`PlantSettings` is the scenario's ``[plant]`` table (see :mod:`tubekit.scenario`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from typing import Any, Mapping

from tubekit.exceptions import ConfigError
from tubekit.validation import finite, nonnegative, positive

__all__ = ["VehicleParams", "VEHICLES", "PlantSettings", "PLANT_KINDS", "vehicle_params", "REMUS100"]

PLANT_KINDS = ("kinematic", "dynamic")

#: Coefficients that must be <= 0 (damping: they remove energy).
_NONPOSITIVE = ("X_u", "Y_v", "Z_w", "N_r", "X_uu", "Y_vv", "Z_ww", "N_rr")


@dataclass(frozen=True)
class VehicleParams:
    """A 4-DOF vehicle (Fossen 2011 notation; see ``docs/plant.md`` for each source).

    Mass matrix M = M_RB + M_A over ν = (u, v, w, r):
    [[m - X_udot, 0, 0, 0], [0, m - Y_vdot, 0, m x_g - Y_rdot], [0, 0, m - Z_wdot, 0],
    [0, m x_g - N_vdot, 0, I_zz - N_rdot]]; it must be symmetric positive definite.
    Lift terms (``*_lift``) are the fin and body lift only: the added-mass (Munk)
    parts of Prestero's totals are produced by the Coriolis matrix C_A(ν).
    """

    m: float = 30.48                # kg, W / g = 299 N / 9.81
    I_zz: float = 3.45              # kg m²
    x_g: float = 0.0                # m, centre of gravity ahead of the origin (CB)
    X_udot: float = -0.93           # kg
    Y_vdot: float = -35.5           # kg
    Z_wdot: float = -35.5           # kg
    N_rdot: float = -4.88           # kg m²/rad
    Y_rdot: float = 1.93            # kg m/rad
    N_vdot: float = 1.93            # kg m
    X_u: float = 0.0                # kg/s, linear (not published: 0)
    Y_v: float = 0.0                # kg/s
    Z_w: float = 0.0                # kg/s
    N_r: float = 0.0                # kg m²/(s rad)
    X_uu: float = -1.62             # kg/m
    Y_vv: float = -1310.0           # kg/m
    Y_rr: float = 0.632             # kg m/rad²
    Z_ww: float = -131.0            # kg/m
    N_vv: float = -3.18             # kg
    N_rr: float = -94.0             # kg m²/rad²
    Y_uv: float = -28.6             # kg/m, body + fin lift
    Y_ur_lift: float = 6.15         # kg/rad, fin lift: Y_ur 5.22 minus Y_ura = X_udot = -0.93
    Z_uw: float = -28.6             # kg/m, body + fin lift
    N_uv_lift: float = 10.57        # kg, N_uv -24.0 minus the Munk moment Y_vdot - X_udot = -34.57
    N_ur_lift: float = -3.93        # kg m/rad, N_ur -2.00 minus N_ura = Y_rdot = 1.93
    X_max: float = 10.0             # N, surge thrust limit
    Z_max: float = 30.0             # N, heave force limit
    N_max: float = 50.0             # N m, yaw moment limit
    thruster_time_constant: float = 0.1   # s
    loop_bandwidth: float = 5.0     # rad/s, low-level velocity loop (PI: k_p = ω_b, k_i = ω_b²/4)

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, finite(f"plant.vehicle.{f.name}", getattr(self, f.name)))
        positive("plant.vehicle.m", self.m)
        positive("plant.vehicle.I_zz", self.I_zz)
        for name in _NONPOSITIVE:
            if getattr(self, name) > 0.0:
                raise ConfigError(f"plant.vehicle.{name}", "a number <= 0 (damping removes energy)",
                                  getattr(self, name))
        for name in ("X_max", "Z_max", "N_max", "thruster_time_constant", "loop_bandwidth"):
            positive(f"plant.vehicle.{name}", getattr(self, name))
        m11, m22, m33, m44, m24, m42 = self.mass_entries
        if abs(m24 - m42) > 1e-9 * max(1.0, abs(m24)):
            raise ConfigError("plant.vehicle.N_vdot", f"m x_g - N_vdot = m x_g - Y_rdot (M symmetric), "
                              f"i.e. N_vdot = {self.Y_rdot}", self.N_vdot)
        if min(m11, m22, m33) <= 0.0 or m22 * m44 - m24 * m42 <= 0.0:
            raise ConfigError("plant.vehicle.M", "M = M_RB + M_A positive definite (m - X_udot > 0, "
                              "m - Y_vdot > 0, m - Z_wdot > 0, (m - Y_vdot)(I_zz - N_rdot) > (m x_g - Y_rdot)²)",
                              {"m11": m11, "m22": m22, "m33": m33, "m44": m44, "m24": m24})

    @property
    def mass_entries(self) -> tuple[float, float, float, float, float, float]:
        """(m11, m22, m33, m44, m24, m42) of M (kg, kg m, kg m²)."""
        m = self.m
        return (m - self.X_udot, m - self.Y_vdot, m - self.Z_wdot, self.I_zz - self.N_rdot,
                m * self.x_g - self.Y_rdot, m * self.x_g - self.N_vdot)

    @property
    def thrust_limits(self) -> tuple[float, float, float]:
        """(X_max, Z_max, N_max) in N, N, N m."""
        return self.X_max, self.Z_max, self.N_max

    def with_overrides(self, overrides: Mapping[str, Any]) -> VehicleParams:
        """A copy with ``overrides`` (keys = field names) applied and validated."""
        known = {f.name for f in fields(self)}
        for key in overrides:
            if key not in known:
                raise ConfigError(f"plant.vehicle.{key}", f"one of the keys {sorted(known)}", key)
        return replace(self, **dict(overrides))

    def to_dict(self) -> dict[str, float]:
        """Every parameter by name."""
        return asdict(self)


#: REMUS 100, Prestero (2001), reduced to 4-DOF (the defaults of :class:`VehicleParams`).
REMUS100 = VehicleParams()

#: Shipped parameter sets by name.
VEHICLES: dict[str, VehicleParams] = {"remus100": REMUS100}


def vehicle_params(name: str, overrides: Mapping[str, Any] | None = None) -> VehicleParams:
    """The shipped set ``name`` with ``overrides`` applied (ConfigError naming ``plant.vehicle...``)."""
    if name not in VEHICLES:
        raise ConfigError("plant.vehicle", f"one of {sorted(VEHICLES)}", name)
    return VEHICLES[name].with_overrides(overrides or {})


@dataclass(frozen=True)
class PlantSettings:
    """The scenario's ``[plant]`` table.

    Parameters
    ----------
    kind : str
        ``"kinematic"`` (eq. 11 with the sway model; the default) or ``"dynamic"``
        (:class:`tubekit.plant.dynamic.DynamicPlant`).
    vehicle : str
        Name of the shipped parameter set (:data:`VEHICLES`).
    overrides : mapping or pairs
        Inline ``[plant.vehicle]`` parameters replacing the shipped ones.
    tracking_bound : (3,) floats
        Assumed bound on the velocity loop's error |u_b - u|, |w_b - w|, |r_b - r|
        (m/s, m/s, rad/s): not derived, measured over the shipped scenarios and
        checked in every run (promise ``velocity_loop``).
    """

    kind: str = "kinematic"
    vehicle: str = "remus100"
    overrides: tuple[tuple[str, float], ...] = ()
    tracking_bound: tuple[float, float, float] = (0.8, 0.5, 1.0)

    def __post_init__(self) -> None:
        if self.kind not in PLANT_KINDS:
            raise ConfigError("plant.kind", f"one of {PLANT_KINDS}", self.kind)
        tb = self.tracking_bound
        if not isinstance(tb, (list, tuple)) or len(tb) != 3:
            raise ConfigError("plant.tracking_bound", "three numbers >= 0 [du, dw, dr] (m/s, m/s, rad/s)", tb)
        object.__setattr__(self, "tracking_bound",
                           tuple(nonnegative(f"plant.tracking_bound[{i}]", x) for i, x in enumerate(tb)))
        over = dict(self.overrides)
        object.__setattr__(self, "overrides", tuple(sorted((str(k), v) for k, v in over.items())))
        self.params  # validates the vehicle now, naming the field

    @property
    def params(self) -> VehicleParams:
        """The vehicle's parameters (shipped set + overrides)."""
        return vehicle_params(self.vehicle, dict(self.overrides))

    @property
    def dynamic(self) -> bool:
        """True for the 4-DOF plant."""
        return self.kind == "dynamic"

    def to_dict(self) -> dict[str, Any]:
        """The ``[plant]`` table (vehicle overrides under ``vehicle``, with ``name``)."""
        return {"kind": self.kind, "vehicle": {"name": self.vehicle, **dict(self.overrides)},
                "tracking_bound": list(self.tracking_bound)}

    @classmethod
    def from_dict(cls, d: Any) -> PlantSettings:
        """Parse ``[plant]``: ``vehicle`` is a name, or a table with optional ``name`` plus overrides."""
        if not isinstance(d, dict):
            raise ConfigError("plant", "a table", d)
        unknown = set(d) - {"kind", "vehicle", "tracking_bound"}
        if unknown:
            raise ConfigError(f"plant.{sorted(unknown)[0]}", "one of the keys ['kind', 'tracking_bound', "
                              "'vehicle']", sorted(unknown)[0])
        kw: dict[str, Any] = {k: d[k] for k in ("kind", "tracking_bound") if k in d}
        veh = d.get("vehicle", "remus100")
        if isinstance(veh, str):
            kw["vehicle"] = veh
        elif isinstance(veh, dict):
            over = dict(veh)
            kw["vehicle"] = str(over.pop("name", "remus100"))
            kw["overrides"] = over
        else:
            raise ConfigError("plant.vehicle", "a vehicle name or a table of parameters", veh)
        return cls(**kw)

