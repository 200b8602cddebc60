"""One 4-DOF vehicle's parameters, each a number or an interval [lo, hi] (a coefficient box).

:class:`VehicleParams` holds the rigid-body and added mass, the linear and quadratic drag,
the body/fin lift, the actuation (``"thrusters"``: constant limits; ``"fins"``: a propeller
in surge, stern planes and rudder with an authority ∝ u²), the actuator lag and the
velocity loop's bandwidth. Units are SI: kg, kg m², kg/s, kg/m (quadratic), kg (lift, per
m/s of surge), N, N m, rad, s, rad/s. The class defaults are REMUS 100
(:data:`tubekit.model.vehicle_sets.REMUS100`); every value, its unit and its sources are
listed in ``docs/plant.md``.

A numeric field given as ``[lo, hi]`` (lo <= hi, both finite) is stored as the tuple
``(lo, hi)`` (``lo == hi`` is stored as the number); the validation holds for every point of
the box. Point-only properties (:attr:`VehicleParams.mass_entries`, :attr:`thrust_limits`,
:meth:`thrust_limits_at`) refuse a box (use :attr:`nominal`, :meth:`sample` or :meth:`interval`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from functools import cached_property
from typing import Any, Mapping, Union

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.validation import is_number

__all__ = ["VehicleParams", "Coefficient", "ACTUATIONS", "FEEDFORWARDS", "CHANNEL_BANDWIDTHS"]

#: A coefficient: a number, or the interval (lo, hi) with lo < hi.
Coefficient = Union[float, tuple[float, float]]

#: Actuation models: constant limits, or a propeller plus fins whose authority is ∝ u².
ACTUATIONS = ("thrusters", "fins")

#: What the velocity loop feeds forward: ``"model"`` the nominal forces at the measured velocity, τ_cmd = n̂(ν) + M̂ a
#: (feedback linearisation); ``"none"`` nothing, τ_cmd = M̂ a (a PI loop whose integrators hold the drag).
FEEDFORWARDS = ("model", "none")

#: The per-channel bandwidths of the velocity loop, in the order of ν = (u, v, w, r) (0: ``loop_bandwidth``).
CHANNEL_BANDWIDTHS = ("surge_loop_bandwidth", "sway_loop_bandwidth", "heave_loop_bandwidth", "yaw_loop_bandwidth")
#: Coefficients that must be <= 0 over the whole box (damping: they remove energy).
_NONPOSITIVE = ("X_u", "Y_v", "Z_w", "N_r", "X_uu", "Y_vv", "Z_ww", "N_rr")
_POSITIVE = ("m", "I_zz", "X_max", "thruster_time_constant", "loop_bandwidth")
#: Fields each actuation leaves unused: they must be 0 (no silent ignore).
_UNUSED = {"thrusters": ("Z_uuds", "N_uudr", "fin_max"), "fins": ("Z_max", "N_max", "Y_max")}


def _coefficient(name: str, value: Any) -> Coefficient:
    """``value`` as a float or an interval (lo, hi), else ConfigError naming ``plant.vehicle.<name>``."""
    field = f"plant.vehicle.{name}"
    if isinstance(value, (list, tuple, np.ndarray)):
        items = list(value)
        if len(items) != 2 or not all(is_number(x) and np.isfinite(float(x)) for x in items):
            raise ConfigError(field, "a finite number or an interval [lo, hi] of two finite numbers", value)
        lo, hi = float(items[0]), float(items[1])
        if lo > hi:
            raise ConfigError(field, "an interval [lo, hi] with lo <= hi", value)
        return lo if lo == hi else (lo, hi)
    if not is_number(value) or not np.isfinite(float(value)):
        raise ConfigError(field, "a finite number or an interval [lo, hi] of two finite numbers", value)
    return float(value)


def _ends(value: Coefficient) -> tuple[float, float]:
    return (value[0], value[1]) if isinstance(value, tuple) else (value, value)


@dataclass(frozen=True)
class VehicleParams:
    """A 4-DOF vehicle (Fossen 2011 notation; ``docs/plant.md`` lists each value and its sources).

    Mass matrix M = M_RB + M_A over ν = (u, v, w, r):
    [[m - X_udot, 0, 0, 0], [0, m - Y_vdot, 0, m x_g - Y_rdot], [0, 0, m - Z_wdot, 0],
    [0, m x_g - N_vdot, 0, I_zz - N_rdot]]; symmetric (N_vdot = Y_rdot, one coefficient: tied
    in :meth:`sample`) and positive definite at every point of the box. Lift terms
    (``*_lift``) are fin and body lift only: the added-mass (Munk) parts are in C_A(ν).
    Actuation ``"thrusters"``: |X| <= X_max, |Z| <= Z_max, |N| <= N_max (N, N, N m), and a lateral
    force |Y| <= Y_max (N) where the thrusters give one (``Y_max`` > 0: the sway is regulated to 0 by its own
    loop, :attr:`lateral`; 0: no lateral authority, the hull's sway is free);
    ``"fins"``: |X| <= X_max (propeller), |Z| <= |Z_uuds| u² fin_max (stern planes),
    |N| <= |N_uudr| u² fin_max (rudder). Every channel lags by ``thruster_time_constant`` (s).
    ``top_speed`` s > 0 (a number or an interval, m/s) ties the surge thrust to the surge drag: each hull's
    X_max = |X_u| s + |X_uu| s² (the thrust that holds it at its top speed running straight), for some s in the
    interval; X_max's own interval must hold every such value, and a point vehicle's X_max is that value
    (:meth:`nominal`, :meth:`with_point` and :meth:`sample` derive it). 0: X_max independent of the drag.
    """

    m: Coefficient = (30.48, 31.93)              # kg: Prestero W/g; Fossen's spheroid
    I_zz: Coefficient = (3.45, 4.22)             # kg m²: Prestero; Fossen's spheroid m(a²+b²)/5
    x_g: Coefficient = 0.0                       # m, centre of gravity ahead of the origin (CB)
    X_udot: Coefficient = (-0.93, -0.86)         # kg: Prestero; Imlay spheroid (Fossen)
    Y_vdot: Coefficient = (-35.5, -30.3)         # kg
    Z_wdot: Coefficient = (-35.5, -30.3)         # kg
    N_rdot: Coefficient = (-4.88, -3.59)         # kg m²/rad
    Y_rdot: Coefficient = 1.93                   # kg m/rad (Prestero; a spheroid has none)
    N_vdot: Coefficient = 1.93                   # kg m (= Y_rdot: M symmetric)
    X_u: Coefficient = 0.0                       # kg/s, linear (not published: 0)
    Y_v: Coefficient = 0.0                       # kg/s
    Z_w: Coefficient = 0.0                       # kg/s
    N_r: Coefficient = 0.0                       # kg m²/(s rad)
    X_uu: Coefficient = (-6.23, -1.62)           # kg/m: Fossen (Allen et al. C_d 0.42); Prestero
    Y_vv: Coefficient = (-1310.0, -196.1)        # kg/m: Prestero; Fossen's strip theory (Hoerner)
    Y_rr: Coefficient = (0.0, 0.632)             # kg m/rad²: Fossen 0 (symmetric strips); Prestero
    Z_ww: Coefficient = (-196.1, -131.0)         # kg/m: Fossen; Prestero
    N_vv: Coefficient = (-3.18, 0.0)             # kg: Prestero; Fossen 0
    N_rr: Coefficient = (-94.0, -28.9)           # kg m²/rad²: Prestero; Fossen's strip theory
    Y_uv: Coefficient = -38.2                    # kg/m, body + fin lift (Prestero -28.6 - 9.64)
    Y_ur_lift: Coefficient = 6.15                # kg/rad, fin lift: Y_ur 5.22 minus Y_ura = X_udot = -0.93
    Z_uw: Coefficient = -38.2                    # kg/m, body + fin lift (Prestero -28.6 - 9.64)
    N_uv_lift: Coefficient = 10.57               # kg, N_uv -24.0 minus the Munk moment -34.57 (Prestero)
    N_ur_lift: Coefficient = -3.93               # kg m/rad, N_ur -2.00 minus N_ura = Y_rdot = 1.93
    X_max: Coefficient = (10.1, 41.2)            # N: Prestero's drag at 2.5 m/s; Fossen's propeller there
    top_speed: Coefficient = 0.0                 # m/s: > 0 ties X_max to the drag, X_max = |X_u| s + |X_uu| s²
    Z_max: Coefficient = 0.0                     # N (thrusters only)
    Y_max: Coefficient = 0.0                     # N, lateral thrust (thrusters only; 0: none, the sway is free)
    N_max: Coefficient = 0.0                     # N m (thrusters only)
    Z_uuds: Coefficient = (-9.64, -4.77)         # kg/(m rad), stern planes: Prestero; Fossen
    N_uudr: Coefficient = (-6.15, -2.75)         # kg/rad, rudder: Prestero; Fossen (|x_r Y_uudr|)
    fin_max: Coefficient = 0.349                 # rad, largest fin angle (Fossen: 20 deg)
    thruster_time_constant: Coefficient = 0.1    # s, every channel (assumption)
    loop_bandwidth: Coefficient = 5.0            # rad/s, velocity loop (PI: k_p = ω_b, k_i = ω_b²/4)
    surge_loop_bandwidth: Coefficient = 0.0      # rad/s, the surge loop's own ω_b (0: loop_bandwidth)
    sway_loop_bandwidth: Coefficient = 0.0       # rad/s, the sway loop's (lateral thrust only; 0: loop_bandwidth)
    heave_loop_bandwidth: Coefficient = 0.0      # rad/s, the heave loop's (0: loop_bandwidth)
    yaw_loop_bandwidth: Coefficient = 0.0        # rad/s, the yaw loop's (0: loop_bandwidth)
    actuation: str = "fins"                      # "thrusters" or "fins"
    loop_feedforward: str = "model"              # "model" (τ_cmd = n̂(ν) + M̂ a) or "none" (τ_cmd = M̂ a)

    def __post_init__(self) -> None:
        if not isinstance(self.actuation, str) or self.actuation not in ACTUATIONS:
            raise ConfigError("plant.vehicle.actuation", f"one of {ACTUATIONS}", self.actuation)
        if not isinstance(self.loop_feedforward, str) or self.loop_feedforward not in FEEDFORWARDS:
            raise ConfigError("plant.vehicle.loop_feedforward", f"one of {FEEDFORWARDS}", self.loop_feedforward)
        for name in _NUMERIC:
            object.__setattr__(self, name, _coefficient(name, getattr(self, name)))
        for name in _POSITIVE + (("Z_max", "N_max") if self.actuation == "thrusters" else ("fin_max",)):
            self._require(name, self.interval(name)[0] > 0.0, "a number > 0 at every point of the box")
        for name in _NONPOSITIVE:
            self._require(name, self.interval(name)[1] <= 0.0,
                          "a number <= 0 at every point of the box (damping removes energy)")
        for name in _UNUSED[self.actuation]:
            self._require(name, self.interval(name) == (0.0, 0.0), f"0 (unused with actuation = "
                          f"{self.actuation!r})")
        if self.actuation == "fins":
            for name in ("Z_uuds", "N_uudr"):
                lo, hi = self.interval(name)
                self._require(name, lo > 0.0 or hi < 0.0, "a nonzero fin coefficient (an interval not containing 0)")
        for name in CHANNEL_BANDWIDTHS:
            lo, hi = self.interval(name)
            self._require(name, lo >= 0.0 and (hi == 0.0 or lo > 0.0), "0 (the loop_bandwidth) or a number > 0 "
                          "at every point of the box")
        self._check_lateral()
        self._check_top_speed()
        self._require("N_vdot", self.interval("N_vdot") == self.interval("Y_rdot"),
                      f"the value of Y_rdot, {self.Y_rdot!r} (M symmetric at every point of the box)")
        self._check_positive_definite()
        # cached (not a dataclass field: eq, hash and repr ignore it); replace() recomputes it
        object.__setattr__(self, "_intervals", tuple(n for n in _NUMERIC if isinstance(getattr(self, n), tuple)))

    def _require(self, name: str, ok: bool, expected: str) -> None:
        if not ok:
            raise ConfigError(f"plant.vehicle.{name}", expected, getattr(self, name))

    def _check_lateral(self) -> None:
        """Y_max is 0 or > 0 over the whole box; a sway loop needs sway and yaw decoupled in M (m24 = m42 = 0)."""
        lo, hi = self.interval("Y_max")
        self._require("Y_max", lo >= 0.0 and (hi == 0.0 or lo > 0.0), "0 (no lateral thrust) or a number > 0 at "
                      "every point of the box")
        if lo > 0.0:
            for name in ("x_g", "Y_rdot"):
                self._require(name, self.interval(name) == (0.0, 0.0), "0 when Y_max > 0: the sway loop regulates "
                              "sway and yaw as separate channels, which needs m x_g - Y_rdot = 0 (M diagonal in sway "
                              "and yaw); give Y_max = 0 to keep the hull's free sway")

    def _check_top_speed(self) -> None:
        """top_speed is 0 or > 0 over the box; when > 0, X_max's interval holds every tied thrust (a point: equals
        it, to rounding)."""
        lo, hi = self.interval("top_speed")
        self._require("top_speed", lo >= 0.0 and (hi == 0.0 or lo > 0.0), "0 (X_max independent of the drag) or a "
                      "speed > 0 at every point of the box (m/s)")
        if hi == 0.0:
            return
        t_lo, t_hi = self.tied_thrust_range
        x_lo, x_hi = self.interval("X_max")
        slack = 1e-9 * max(1.0, abs(t_hi))
        if not (x_lo - slack <= t_lo and t_hi <= x_hi + slack):
            raise ConfigError("plant.vehicle.X_max", f"an interval holding every thrust the top speed ties to the "
                              f"drag, |X_u| s + |X_uu| s^2 in [{t_lo:.6g}, {t_hi:.6g}] N (or a smaller top_speed)",
                              self.X_max)

    @property
    def tied(self) -> bool:
        """True when the surge thrust is tied to the drag by a top speed (``top_speed`` > 0)."""
        return self.interval("top_speed")[1] > 0.0

    @property
    def tied_thrust_range(self) -> tuple[float, float]:
        """(smallest, largest) |X_u| s + |X_uu| s² over the box and the top speed s (N); tied vehicles only."""
        s_lo, s_hi = self.interval("top_speed")
        lin_lo, lin_hi = _abs_ends(self.interval("X_u"))
        quad_lo, quad_hi = _abs_ends(self.interval("X_uu"))
        return lin_lo * s_lo + quad_lo * s_lo * s_lo, lin_hi * s_hi + quad_hi * s_hi * s_hi

    def _tied_point(self, point: dict[str, float]) -> dict[str, float]:
        """``point`` (values of interval fields) with X_max derived from its drag and top speed, when tied."""
        if not self.tied:
            return point
        at = {n: point.get(n, 0.5 * sum(self.interval(n))) for n in ("X_u", "X_uu", "top_speed")}
        s = at["top_speed"]
        return {**point, "X_max": abs(at["X_u"]) * s + abs(at["X_uu"]) * s * s}

    @property
    def loop_gains(self) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float], tuple[float, float]]:
        """The velocity loop's PI gains (k_p (1/s), k_i (1/s²)) of the controller's model (:attr:`nominal`) per
        body velocity u, v, w, r: k_p = ω_c, k_i = ω_c²/4 with ω_c the channel's own bandwidth
        (``surge_loop_bandwidth``, ``sway_loop_bandwidth``, ``heave_loop_bandwidth``, ``yaw_loop_bandwidth``), or
        ``loop_bandwidth`` where that is 0."""
        nom = self.nominal
        base = float(nom.loop_bandwidth)
        out = []
        for name in CHANNEL_BANDWIDTHS:
            own = float(getattr(nom, name))
            w = own if own > 0.0 else base
            out.append((w, 0.25 * w ** 2))
        return out[0], out[1], out[2], out[3]

    @property
    def lateral(self) -> bool:
        """True when the thrusters give a lateral force (Y_max > 0 over the box): sway is regulated to 0."""
        return self.interval("Y_max")[0] > 0.0

    def _check_positive_definite(self) -> None:
        """M positive definite over the box: smallest diagonal entries against the largest |m24|."""
        lo = {n: self.interval(n)[0] for n in ("m", "I_zz")}
        hi = {n: self.interval(n)[1] for n in ("m", "I_zz", "X_udot", "Y_vdot", "Z_wdot", "N_rdot")}
        m11, m22 = lo["m"] - hi["X_udot"], lo["m"] - hi["Y_vdot"]
        m33, m44 = lo["m"] - hi["Z_wdot"], lo["I_zz"] - hi["N_rdot"]
        corners = [a * b for a in self.interval("m") for b in self.interval("x_g")]
        yr_lo, yr_hi = self.interval("Y_rdot")
        m24 = max(abs(max(corners) - yr_lo), abs(min(corners) - yr_hi))
        if min(m11, m22, m33, m44) <= 0.0 or m22 * m44 - m24 * m24 <= 0.0:
            raise ConfigError("plant.vehicle.M", "M = M_RB + M_A positive definite at every point of the box "
                              "(m - X_udot > 0, m - Y_vdot > 0, m - Z_wdot > 0, I_zz - N_rdot > 0, "
                              "(m - Y_vdot)(I_zz - N_rdot) > (m x_g - Y_rdot)², worst-case ends)",
                              {"m11": m11, "m22": m22, "m33": m33, "m44": m44, "|m24|": m24})

    # ---- the box -------------------------------------------------------------------------
    def interval(self, name: str) -> tuple[float, float]:
        """(lo, hi) of the numeric field ``name`` (lo == hi for a number); ValueError for other names."""
        if name not in _NUMERIC:
            raise ValueError(f"{name!r} is not a numeric vehicle parameter; one of {list(_NUMERIC)}")
        return _ends(getattr(self, name))

    @property
    def interval_fields(self) -> tuple[str, ...]:
        """Names of the fields given as an interval with lo < hi."""
        return self._intervals  # type: ignore[attr-defined, no-any-return]

    @property
    def free_fields(self) -> tuple[str, ...]:
        """The interval fields a point of the box is given by (:meth:`with_point`, a campaign's draw): every one
        but X_max when the thrust is tied to the drag (:attr:`tied`: then X_max is derived from the point)."""
        return tuple(n for n in self.interval_fields if not (self.tied and n == "X_max"))

    @property
    def is_point(self) -> bool:
        """True when no field is an interval."""
        return not self._intervals  # type: ignore[attr-defined]

    @cached_property
    def nominal(self) -> VehicleParams:
        """Every interval replaced by its midpoint (the controller's model); built once per vehicle (the velocity
        loop's bound reads it at every evaluation)."""
        mid = self._tied_point({n: 0.5 * (self.interval(n)[0] + self.interval(n)[1]) for n in self.interval_fields})
        return replace(self, **mid) if mid else self

    def shrunk(self, fraction: float) -> VehicleParams:
        """Every interval shrunk about its midpoint to ``fraction`` of its half-width: 0 gives the midpoint (a point
        vehicle, :attr:`nominal`), 1 the box itself. Raises ConfigError outside [0, 1]."""
        if not is_number(fraction) or not 0.0 <= float(fraction) <= 1.0:
            raise ConfigError("fraction", "a number in [0, 1] (of each interval's half-width)", fraction)
        if float(fraction) == 0.0:
            return self.nominal
        box = {}
        for name in self.interval_fields:
            lo, hi = self.interval(name)
            mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo) * float(fraction)
            box[name] = (mid - half, mid + half)
        return replace(self, **box) if box else self

    def sample(self, rng: np.random.Generator) -> VehicleParams:
        """A point drawn uniformly in the box (N_vdot tied to Y_rdot, M stays symmetric)."""
        point = self._tied_point({n: float(rng.uniform(*self.interval(n))) for n in self.interval_fields})
        if "Y_rdot" in point:
            point["N_vdot"] = point["Y_rdot"]
        return replace(self, **point) if point else self

    def with_point(self, values: Mapping[str, float]) -> VehicleParams:
        """The nominal point with ``values`` (interval fields only, each inside its interval) applied.

        ``Y_rdot`` and ``N_vdot`` are one coefficient: setting either sets both. Raises
        ConfigError naming ``plant.truth.<name>``.
        """
        vals = dict(values)
        for name, value in vals.items():
            if name in self.interval_fields and name not in self.free_fields:
                raise ConfigError(f"plant.truth.{name}", "absent: X_max is tied to the drag by top_speed (give "
                                  "plant.truth.top_speed, X_u or X_uu)", value)
            if name not in self.interval_fields:
                raise ConfigError(f"plant.truth.{name}", f"a coefficient given as an interval: one of "
                                  f"{list(self.interval_fields)}", value)
            lo, hi = self.interval(name)
            if not is_number(value) or not lo <= float(value) <= hi:
                raise ConfigError(f"plant.truth.{name}", f"a number in [{lo}, {hi}]", value)
        if "Y_rdot" in vals and "N_vdot" in vals and vals["Y_rdot"] != vals["N_vdot"]:
            raise ConfigError("plant.truth.N_vdot", f"the truth of Y_rdot, {vals['Y_rdot']} (M symmetric)",
                              vals["N_vdot"])
        for a, b in (("Y_rdot", "N_vdot"), ("N_vdot", "Y_rdot")):
            if a in vals:
                vals[b] = vals[a]
        tied = self._tied_point({k: float(v) for k, v in vals.items()})
        return replace(self.nominal, **tied)

    # ---- point-only quantities -------------------------------------------------------------
    def _point_only(self, what: str) -> None:
        if self._intervals:  # type: ignore[attr-defined]
            raise ValueError(f"VehicleParams.{what} needs a point vehicle; {list(self.interval_fields)} are "
                             "intervals: use .nominal, .sample(rng) or .interval(name)")

    @cached_property
    def mass_entries(self) -> tuple[float, float, float, float, float, float]:
        """(m11, m22, m33, m44, m24, m42) of M (kg, kg, kg, kg m², kg m, kg m); point vehicles only.

        Computed once per vehicle: the dynamic plant reads it at every integrator stage."""
        self._point_only("mass_entries")
        m = self.m
        return (m - self.X_udot, m - self.Y_vdot, m - self.Z_wdot, self.I_zz - self.N_rdot,
                m * self.x_g - self.Y_rdot, m * self.x_g - self.N_vdot)

    @property
    def thrust_limits(self) -> tuple[float, float, float]:
        """(X_max, Z_max, N_max) in N, N, N m; point vehicles with thrusters only."""
        self._point_only("thrust_limits")
        if self.actuation != "thrusters":
            raise ValueError("VehicleParams.thrust_limits: a finned vehicle's limits depend on the surge speed: "
                             "use .thrust_limits_at(u) or .thrust_limit_floor(u_abs_max)")
        return self.X_max, self.Z_max, self.N_max

    def thrust_limits_at(self, u: float) -> tuple[float, float, float]:
        """Limits (N, N, N m) on (X, Z, N) at surge speed ``u`` (m/s, relative to the water); point only."""
        self._point_only("thrust_limits_at")
        if self.actuation == "thrusters":
            return self.X_max, self.Z_max, self.N_max
        q = u * u * self.fin_max
        return self.X_max, abs(self.Z_uuds) * q, abs(self.N_uudr) * q

    def thrust_limit_floor(self, u_abs_max: float, u_abs_min: float = 0.0) -> tuple[float, float, float]:
        """Smallest limits (N, N, N m) over u_abs_min <= |u| <= u_abs_max (m/s) and over the box.

        Fins: the stern planes' and rudder's authority ∝ u² vanishes at u = 0, so the floor
        is 0 whenever ``u_abs_min`` is 0 (the default).
        """
        if not (is_number(u_abs_max) and is_number(u_abs_min) and 0.0 <= u_abs_min <= u_abs_max < np.inf):
            raise ValueError(f"thrust_limit_floor: need 0 <= u_abs_min <= u_abs_max < inf (m/s), "
                             f"received {u_abs_min!r}, {u_abs_max!r}")
        x = self.interval("X_max")[0]
        if self.actuation == "thrusters":
            return x, self.interval("Z_max")[0], self.interval("N_max")[0]
        q = u_abs_min * u_abs_min * self.interval("fin_max")[0]
        return x, _abs_floor(self.interval("Z_uuds")) * q, _abs_floor(self.interval("N_uudr")) * q

    # ---- copies and output -------------------------------------------------------------------
    @classmethod
    def check_keys(cls, overrides: Mapping[str, Any]) -> None:
        """ConfigError naming ``plant.vehicle.<key>`` for the first key of ``overrides`` that is no parameter."""
        known = {f.name for f in fields(cls)}
        for key in overrides:
            if key not in known:
                raise ConfigError(f"plant.vehicle.{key}", f"one of the keys {sorted(known)}", key)

    def with_overrides(self, overrides: Mapping[str, Any]) -> VehicleParams:
        """A copy with ``overrides`` (keys = field names; numbers, [lo, hi], the actuation or the loop's feedforward)
        applied and validated."""
        self.check_keys(overrides)
        return replace(self, **dict(overrides))

    def to_dict(self) -> dict[str, Any]:
        """Every parameter by name (intervals as [lo, hi] lists: TOML and JSON round-trip)."""
        return {f.name: (list(v) if isinstance(v, tuple) else v)
                for f in fields(self) for v in (getattr(self, f.name),)}


def _abs_ends(ends: tuple[float, float]) -> tuple[float, float]:
    """(min |x|, max |x|) over [lo, hi]."""
    return _abs_floor(ends), max(abs(ends[0]), abs(ends[1]))


def _abs_floor(ends: tuple[float, float]) -> float:
    """min |x| over [lo, hi]."""
    lo, hi = ends
    return 0.0 if lo <= 0.0 <= hi else min(abs(lo), abs(hi))


#: The fields that name a choice (strings), not a number or an interval.
_CHOICES = ("actuation", "loop_feedforward")
#: The numeric fields, in declaration order.
_NUMERIC: tuple[str, ...] = tuple(f.name for f in fields(VehicleParams) if f.name not in _CHOICES)
