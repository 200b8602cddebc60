"""The vehicles for the dynamic plant, and the scenario's ``[plant]`` settings.

:class:`VehicleParams` (:mod:`tubekit.model.vehicle_params`) holds one 4-DOF vehicle, each
numeric field a number or an interval [lo, hi]; :data:`VEHICLES`
(:mod:`tubekit.model.vehicle_sets`) maps a name to a shipped set: ``remus100`` (REMUS 100:
propeller, stern planes and rudder) and ``bluerov2_heavy`` (BlueROV2 Heavy: eight T200
thrusters). Every value, its unit and its sources are listed in ``docs/plant.md``.
:class:`PlantSettings` is the scenario's ``[plant]`` table (see :mod:`tubekit.scenario`),
with ``[plant.truth]``: the coefficients of the plant as simulated, a point of the box, and
``[plant.vehicle.thrusters]``: a thruster geometry (:mod:`tubekit.model.thrusters`) from which
X_max, Z_max, N_max are derived instead of given.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any, Mapping

from tubekit.exceptions import ConfigError
from tubekit.model.thrusters import LIMIT_KEYS, ThrusterGeometry
from tubekit.model.vehicle_params import ACTUATIONS, VehicleParams
from tubekit.model.vehicle_sets import BLUEROV2_HEAVY, REMUS100, VEHICLES
from tubekit.validation import read_toml

__all__ = ["VehicleParams", "VEHICLES", "PlantSettings", "PLANT_KINDS", "vehicle_params", "read_vehicle_file",
           "CUSTOM", "REMUS100", "BLUEROV2_HEAVY", "ACTUATIONS", "ThrusterGeometry", "PLANT_STARTS"]

PLANT_KINDS = ("kinematic", "dynamic")
#: How the dynamic plant's velocity loop starts at t = 0 (``[plant] start``): ``"trimmed"`` at the first command
#: (ν = the command, τ = n̂(ν), integrators 0) or ``"settled"`` at ``limits.initial`` (ν = that command, τ = n(ν) of
#: the vehicle as simulated, the integrators holding the model's mismatch: the loop's equilibrium, no transient).
PLANT_STARTS = ("trimmed", "settled")


#: The name of a vehicle given whole (every parameter in ``[plant.vehicle]`` or a vehicle file, no shipped set).
CUSTOM = "custom"


def vehicle_params(name: str, overrides: Mapping[str, Any] | None = None) -> VehicleParams:
    """The shipped set ``name`` with ``overrides`` applied, or with ``name = "custom"`` (:data:`CUSTOM`) the vehicle
    ``overrides`` gives whole: every parameter, none taken from a shipped set (ConfigError naming
    ``plant.vehicle...``)."""
    overrides = overrides or {}
    if name == CUSTOM:
        VehicleParams.check_keys(overrides)  # a misspelt key first: it is also why its intended key is missing
        missing = [f.name for f in fields(VehicleParams) if f.name not in overrides]
        if missing:
            raise ConfigError(f"plant.vehicle.{missing[0]}", f"every parameter of a {CUSTOM!r} vehicle (no shipped "
                              f"set to take it from; {len(missing)} missing: {', '.join(missing[:6])}"
                              f"{', ...' if len(missing) > 6 else ''})", "missing")
        return VehicleParams().with_overrides(overrides)
    if name not in VEHICLES:
        raise ConfigError("plant.vehicle", f"one of {sorted(VEHICLES)} or {CUSTOM!r} with every parameter", name)
    return VEHICLES[name].with_overrides(overrides)


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
        Inline ``[plant.vehicle]`` parameters replacing the shipped ones; with ``thrusters`` (a
        table or a :class:`ThrusterGeometry`): the ``[plant.vehicle.thrusters]`` table.
    truth : mapping or pairs
        ``[plant.truth]``: the value of interval coefficients in the plant as simulated (each
        inside its interval; the others take the midpoint). Default: the nominal vehicle.
    start : str
        How the velocity loop starts (:data:`PLANT_STARTS`; dynamic plant only): ``"trimmed"`` (default) at the
        first command with the integrators at 0, or ``"settled"``: the vehicle has run straight at
        ``limits.initial`` under its loop long enough before t = 0 for the loop to be at its equilibrium (the
        integrators carry the mismatch between the model and the vehicle), so the loop bound has no start
        transient (``docs/plant.md`` section 2; the scenario checks ``limits``).

    Attributes
    ----------
    thrusters : ThrusterGeometry or None
        ``[plant.vehicle.thrusters]`` (from ``overrides``, where it stays: it is part of the
        vehicle table, so ``dataclasses.replace`` keeps it): the thruster geometry whose derived
        box gives X_max, Z_max, N_max (N, N, N m) of :attr:`params`; not with any of them in
        ``overrides``, not on a finned vehicle. :meth:`to_dict` writes the table, never the
        derived limits.
    """

    kind: str = "kinematic"
    vehicle: str = "remus100"
    overrides: tuple[tuple[str, Any], ...] = ()
    truth: tuple[tuple[str, float], ...] = ()
    start: str = "trimmed"
    thrusters: ThrusterGeometry | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.kind not in PLANT_KINDS:
            raise ConfigError("plant.kind", f"one of {PLANT_KINDS}", self.kind)
        if self.start not in PLANT_STARTS:
            raise ConfigError("plant.start", f"one of {PLANT_STARTS}", self.start)
        if self.start == "settled" and self.kind != "dynamic":
            raise ConfigError("plant.start", "'trimmed' on the kinematic plant (it has no velocity loop to settle)",
                              self.start)
        over = _pairs("plant.vehicle", self.overrides)
        thrusters = over.pop("thrusters", None)
        if thrusters is not None:
            _refuse_thrusters(self.vehicle, over, thrusters)  # before any linear program
            if not isinstance(thrusters, ThrusterGeometry):
                thrusters = ThrusterGeometry.from_dict(thrusters)
        object.__setattr__(self, "thrusters", thrusters)
        params = vehicle_params(self.vehicle, _with_thrusters(self.vehicle, over, thrusters))  # names the field
        # stored as validated: numbers, (lo, hi) tuples (hashable; [lo, lo] becomes lo), the actuation, the thrusters
        stored = [(k, getattr(params, k)) for k in over] + ([("thrusters", thrusters)] if thrusters is not None else [])
        object.__setattr__(self, "overrides", tuple(sorted(stored, key=lambda kv: kv[0])))
        truth = _pairs("plant.truth", self.truth)
        params.with_point(truth)  # every truth value names an interval field and lies inside it
        object.__setattr__(self, "truth", tuple(sorted((k, float(v)) for k, v in truth.items())))

    @property
    def params(self) -> VehicleParams:
        """The vehicle's parameters (shipped set + overrides, + the thrusters' derived limits): a point or a box."""
        over = {k: v for k, v in self.overrides if k != "thrusters"}
        return vehicle_params(self.vehicle, _with_thrusters(self.vehicle, over, self.thrusters))

    @property
    def truth_params(self) -> VehicleParams:
        """The plant as simulated: a point, the nominal vehicle with the ``truth`` values."""
        return self.params.with_point(dict(self.truth))

    @property
    def dynamic(self) -> bool:
        """True for the 4-DOF plant."""
        return self.kind == "dynamic"

    @property
    def settled(self) -> bool:
        """True when the velocity loop starts at its equilibrium at ``limits.initial`` (``start = "settled"``)."""
        return self.start == "settled"

    def shrunk(self, share: float) -> PlantSettings:
        """This plant over its bundled vehicle's coefficient box shrunk about its midpoints to ``share`` of each
        half-width (:meth:`VehicleParams.shrunk`; 1 is the published box, 0 its midpoint): every interval coefficient
        of the bundled box becomes an override, the other overrides (bandwidths, limits, thrusters) stay. Raises
        ConfigError for a share outside [0, 1] or a ``truth`` value outside the new box."""
        published = vehicle_params(self.vehicle)
        box = published.shrunk(share)
        spread = {name: getattr(box, name) for name in published.interval_fields}
        return replace(self, overrides=tuple({**dict(self.overrides), **spread}.items()))

    def to_dict(self) -> dict[str, Any]:
        """The ``[plant]`` table (vehicle overrides under ``vehicle``, with ``name``; ``thrusters`` inside it)."""
        over = {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.overrides if k != "thrusters"}
        out: dict[str, Any] = {"kind": self.kind, "vehicle": {"name": self.vehicle, **over}}
        if self.thrusters is not None:
            out["vehicle"]["thrusters"] = self.thrusters.to_dict()
        if self.truth:
            out["truth"] = dict(self.truth)
        if self.settled:  # written only when set: a trimmed start keeps its dict
            out["start"] = self.start
        return out

    @classmethod
    def from_dict(cls, d: Any) -> PlantSettings:
        """Parse ``[plant]``: ``vehicle`` is a name, or a table with optional ``name``, ``thrusters`` plus overrides."""
        if not isinstance(d, dict):
            raise ConfigError("plant", "a table", d)
        if "tracking_bound" in d:
            raise ConfigError("plant.tracking_bound", "absent: the velocity loop's error bound is derived from the "
                              "vehicle by the certificate (verify.vehicle.bound), never assumed", d["tracking_bound"])
        unknown = set(d) - {"kind", "vehicle", "vehicle_file", "truth", "start"}
        if unknown:
            raise ConfigError(f"plant.{sorted(unknown)[0]}", "one of the keys ['kind', 'start', 'truth', 'vehicle', "
                              "'vehicle_file']", sorted(unknown)[0])
        if "vehicle_file" in d:
            if "vehicle" in d:
                raise ConfigError("plant.vehicle_file", "absent when [plant] vehicle is given (one vehicle)",
                                  d["vehicle_file"])
            d = {**{k: v for k, v in d.items() if k != "vehicle_file"},
                 "vehicle": read_vehicle_file(d["vehicle_file"])}
        kw: dict[str, Any] = {k: d[k] for k in ("kind", "start") if k in d}
        if "truth" in d:
            if not isinstance(d["truth"], dict):
                raise ConfigError("plant.truth", "a table of coefficient values", d["truth"])
            kw["truth"] = d["truth"]
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



def read_vehicle_file(path: Any) -> dict[str, Any]:
    """The ``[plant.vehicle]`` table a vehicle file holds (``[plant] vehicle_file``): a TOML file of parameters,
    with ``name`` a shipped set to start from, or without it (or ``name = "custom"``) every parameter; its table
    ``[thrusters]`` is the vehicle's ``[plant.vehicle.thrusters]`` (X_max, Z_max, N_max then derived, not given).

    Raises
    ------
    ConfigError
        ``plant.vehicle_file``: not a path, missing, or not valid TOML.
    """
    if not isinstance(path, (str, Path)) or not str(path):
        raise ConfigError("plant.vehicle_file", "the path of a TOML file of vehicle parameters", path)
    table = read_toml(path, "plant.vehicle_file")
    return {"name": CUSTOM, **table}


def _actuation(name: str, overrides: Mapping[str, Any]) -> str | None:
    """The vehicle's actuation: the override, else the shipped set's (None for a custom vehicle without one)."""
    return overrides.get("actuation", VEHICLES[name].actuation if name in VEHICLES else None)


def _refuse_thrusters(name: str, overrides: Mapping[str, Any], table: Any) -> None:
    """ConfigError naming ``plant.vehicle.thrusters`` when a thruster table (``table``) is given with
    X_max/Z_max/N_max/Y_max (one source of limits) or on a finned vehicle (its Z and N come from the fins)."""
    received = table.to_dict() if isinstance(table, ThrusterGeometry) else table
    given = [k for k in LIMIT_KEYS if k in overrides]
    if given:
        raise ConfigError("plant.vehicle.thrusters", f"absent when {'/'.join(LIMIT_KEYS)} are given (one source of "
                          f"limits; {', '.join(given)} given)", received)
    actuation = _actuation(name, overrides)
    if actuation == "fins":
        raise ConfigError("plant.vehicle.thrusters", "absent on a finned vehicle (actuation 'fins': its heave force "
                          "and yaw moment come from the fins; set actuation = 'thrusters')", received)


def _with_thrusters(name: str, overrides: dict[str, Any], thrusters: ThrusterGeometry | None) -> dict[str, Any]:
    """``overrides`` plus X_max, Z_max, N_max and Y_max derived from ``thrusters`` (unchanged without them).

    Raises
    ------
    ConfigError
        ``plant.vehicle.thrusters.shares`` when a vehicle with actuation "thrusters" gets a limit 0.
    """
    if thrusters is None:
        return overrides
    actuation = _actuation(name, overrides)
    limits = thrusters.limits()
    if actuation == "thrusters" and not all(x > 0.0 for x in limits):
        raise ConfigError("plant.vehicle.thrusters.shares", "3 numbers > 0 (a vehicle with actuation 'thrusters' "
                          "needs every limit X_max, Z_max, N_max > 0)", list(thrusters.shares))
    # the lateral limit too: the table's fourth share, else 0 (a box asking zero sway leaves none for a sway loop)
    return {**overrides, **thrusters.vehicle_limits()}


def _pairs(field: str, value: Any) -> dict[str, Any]:
    """A mapping or (name, value) pairs as a dict with str keys, else ConfigError naming ``field``."""
    if isinstance(value, Mapping):
        return {str(k): v for k, v in value.items()}
    try:
        return {str(k): v for k, v in value}
    except (TypeError, ValueError):
        raise ConfigError(field, "a table of name = value", value) from None
