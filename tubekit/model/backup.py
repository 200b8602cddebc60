"""The backup law: station keeping about an anchor point, surging forward or astern.

When no plan can be followed, the vehicle holds its position about an anchor p* (the end of the
last accepted plan). With d the horizontal distance to p*, θ = atan2(y − y*, x − x*) the bearing of
the vehicle from p* and φ = ψ − θ − π the angle between the heading and the line of sight to p*
(φ = 0: pointing at p*), the law is

* surge u = u_b cos φ — ahead when facing p*, astern when facing away, zero when abeam;
* yaw r = −k sat(χ / χ_0), χ = φ wrapped to (−π/2, π/2]: the hull's axis is turned onto the
  line of sight, whichever end points at p*;
* heave w = −w_b sat((z − z*) / z_0).

Optionally (issue 22, every one 0 = off) each channel is faded near the anchor and ramped from the
hand-over: with s the time since the hand-over (s),

* u = u_b f cos φ, f = min(1, d/d_0, s/t_r);  r = −k sat(χ/χ_0) g, g = min(1, d/d_1, s/t_r);
* w = −w_b sat((z − z*)/z_0) min(1, s/t_r),

d_0 = ``surge_fade``, d_1 = ``yaw_fade`` (m), t_r = ``ramp`` (s); a zero fade or ramp drops its term.
With a ramp the command applied at the hand-over, v_h, fades out over the same t_r: the law returns
the above plus (1 − min(1, s/t_r)) v_h. The command is then continuous at the hand-over (no plan has
to end at rest), stays in V (a convex combination of v_h ∈ V and the law) and, away from the ridge
χ = ±π/2 (everywhere with the continuous yaw law below), is Lipschitz along every trajectory
(:func:`verify.backup.backup_command_rate`).

**Continuous yaw** (``yaw_law="continuous"``, issue 22). The yaw law above jumps from −k to +k where the
hull crosses abeam (the ridge χ = ±π/2). The continuous law replaces sat(χ/χ_0) by ρ(φ), π-periodic
and Lipschitz with constant 1/χ_0, with a stable zero at χ = 0 and an unstable zero at χ = χ_u
(``unstable``, 0 < χ_u < π/2): with x = φ mod π ∈ [0, π),

* ρ = min(1, x/χ_0, (χ_u − x)/χ_0) on [0, χ_u] (turn back onto the line of sight),
* ρ = −min(1, (x − χ_u)/χ_0, (π − x)/χ_0) on [χ_u, π) (turn the long way round, through abeam).

Its safe set uses a(χ) of :func:`axis_shape` in place of 1 − cos χ (both have minimum 0, maximum 1):
a rises on [0, χ_p], χ_p = :data:`SHAPE_PLATEAU` χ_u (``StationKeeping.plateau``), is 1 on [χ_p, χ_u]
(where the line of sight's turn can outpace the small ρ, the radial speed alone must decrease V) and
falls on [χ_u, π).

Every input stays in V when u_b <= ū, w_b <= w̄ and k <= r̄, so the law never saturates.

**The backup-law protocol.** The loop, the terminal condition and the velocity loop's bound read a backup
law only through :class:`BackupLaw`: its ``kind`` (the registry key of :data:`BACKUP_LAWS` and of its proof
in ``verify.backup``), ``command(state, anchor, elapsed, start)``, ``bounds`` (the largest |u|, |w|, |r| it
commands), ``within(V)``, ``blends`` and ``to_dict``. A new backup law is one module beside this one,
registered with :func:`register_backup_law`, and one proof beside :mod:`verify.backup.proof`;
:class:`StationKeeping` is the first implementation. The safe set's footprint for the terminal condition
is :meth:`BackupPlan.footprint`.

:func:`verify.backup.certify_backup` proves that the set
S = {d + β(1 − cos χ) <= c, |z − z*| <= Z} is invariant under the law held at the ancillary rate
for every current within the certified bound; this module only evaluates the law.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.validation import nonnegative, positive

__all__ = ["BackupLaw", "BACKUP_LAWS", "register_backup_law", "backup_law_from_dict", "StationKeeping", "NoSway",
           "SafeSet", "BackupPlan", "line_of_sight_angle", "axis_angle", "station_keeping_input", "yaw_shape", "axis_shape",
           "YAW_LAWS", "SHAPE_PLATEAU", "ANCHOR_RING", "ANCHOR_DIRECTIONS", "anchor_offsets"]


@runtime_checkable
class BackupLaw(Protocol):
    """What the loop, the terminal condition and the velocity loop's bound read of a backup law (module doc)."""

    kind: ClassVar[str]
    #: True when the law commands sway (a vehicle with lateral thrust: :mod:`tubekit.model.hold`).
    lateral: ClassVar[bool]

    @property
    def blends(self) -> bool:
        """True when the command applied at the hand-over fades out (the command is continuous there)."""
        ...

    @property
    def bounds(self) -> tuple[float, float, float]:
        """The largest |u|, |w|, |r| the law commands after its ramp (m/s, m/s, rad/s)."""
        ...

    @property
    def min_surge(self) -> float:
        """The smallest surge the law commands after its ramp (m/s; negative: it backs up)."""
        ...

    @property
    def handover_command(self) -> tuple[float, float, float]:
        """(u, w, r) a plan must end within J of when the law does not blend (``Tightening.terminal_command``):
        the command it starts near (m/s, m/s, rad/s)."""
        ...

    def within(self, u_max: float, w_max: float, r_max: float) -> bool:
        """True when every command of the law lies in V."""
        ...

    def command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                elapsed: float, start: tuple[float, float, float]) -> tuple[float, float, float]:
        """(u, w, r) at ``state`` about ``anchor``, ``elapsed`` s after the hand-over, ``start`` the command then."""
        ...

    @property
    def sway_bound(self) -> float:
        """The largest |v| the law commands (m/s; 0 when it never commands sway)."""
        ...

    @property
    def sway_release(self) -> float:
        """A plan may take over only once the law's sway command is within this of 0 (m/s; ∞ without sway)."""
        ...

    def lateral_command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                        elapsed: float, start: tuple[float, float, float]) -> tuple[float, float, float, float]:
        """(u, w, r, v): :meth:`command` and the sway command v (m/s; 0 for a law that never commands sway)."""
        ...

    def to_dict(self) -> dict[str, Any]:
        """The law's parameters as JSON, with its ``kind``."""
        ...

#: The yaw laws: "ridge" (r = −k sat(χ/χ_0), the default) and "continuous" (r = −k ρ(φ)).
YAW_LAWS = ("ridge", "continuous")
#: χ_p / χ_u: where the continuous law's a(χ) reaches its plateau 1 below the unstable angle.
SHAPE_PLATEAU = 0.75


def _sat(x: float) -> float:
    """Clip ``x`` to [−1, 1]."""
    return -1.0 if x < -1.0 else 1.0 if x > 1.0 else x


def line_of_sight_angle(x: float, y: float, psi: float, anchor_x: float, anchor_y: float) -> float:
    """φ = ψ − θ − π wrapped to (−π, π] (rad): 0 when the vehicle points at the anchor; 0 at the anchor."""
    dx, dy = x - anchor_x, y - anchor_y
    if dx == 0.0 and dy == 0.0:
        return 0.0
    phi = psi - math.atan2(dy, dx) - math.pi
    return math.atan2(math.sin(phi), math.cos(phi))


def axis_angle(phi: float) -> float:
    """χ: φ (rad) wrapped to (−π/2, π/2], the angle between the hull's axis and the line of sight."""
    if phi > math.pi / 2:
        return phi - math.pi
    if phi <= -math.pi / 2:
        return phi + math.pi
    return phi


class NoSway:
    """The backup-law protocol's sway members for a law that never commands sway (station keeping, the loiter)."""

    #: The law never commands sway.
    lateral: ClassVar[bool] = False

    @property
    def sway_bound(self) -> float:
        """0 (m/s): no sway command."""
        return 0.0

    @property
    def sway_release(self) -> float:
        """∞: the law never commands sway, so it never holds a plan back."""
        return math.inf

    def lateral_command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                        elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
                        ) -> tuple[float, float, float, float]:
        """(``command``, 0): no sway command."""
        u, w, r = self.command(state, anchor, elapsed, start)  # the law's own (the subclass's)
        return u, w, r, 0.0


@dataclass(frozen=True)
class StationKeeping(NoSway):
    """Gains of the station-keeping law.

    Attributes
    ----------
    surge : float
        u_b, the largest surge speed (m/s).
    yaw_rate : float
        k, the largest yaw rate (rad/s).
    yaw_band : float
        χ_0, the axis angle (rad) below which the yaw rate is proportional.
    heave : float
        w_b, the largest heave speed (m/s).
    heave_band : float
        z_0, the depth error (m) below which the heave speed is proportional.
    surge_fade : float
        d_0 (m): the surge is scaled by d/d_0 within d_0 of the anchor (0: no fade).
    yaw_fade : float
        d_1 (m): the yaw rate is scaled by d/d_1 within d_1 of the anchor (0: no fade).
    ramp : float
        t_r (s): every channel is scaled by s/t_r for the first t_r seconds after the hand-over (0: none).
    yaw_law : str
        "ridge" (default: r = −k sat(χ/χ_0)) or "continuous" (r = −k ρ(φ), module doc).
    unstable : float
        χ_u (rad), the continuous law's unstable axis angle, in (0, π/2); 0 with the ridge law.
    """

    kind: ClassVar[str] = "station_keeping"

    surge: float
    yaw_rate: float
    yaw_band: float
    heave: float
    heave_band: float
    surge_fade: float = 0.0
    yaw_fade: float = 0.0
    ramp: float = 0.0
    yaw_law: str = "ridge"
    unstable: float = 0.0

    def __post_init__(self) -> None:
        for name in ("surge", "yaw_rate", "yaw_band", "heave", "heave_band"):
            object.__setattr__(self, name, positive(f"backup.{name}", getattr(self, name)))
        for name in ("surge_fade", "yaw_fade", "ramp"):
            object.__setattr__(self, name, nonnegative(f"backup.{name}", getattr(self, name)))
        if self.yaw_band > math.pi / 2:
            raise ConfigError("backup.yaw_band", "an angle in (0, pi/2] rad", self.yaw_band)
        if self.yaw_law not in YAW_LAWS:
            raise ConfigError("backup.yaw_law", f"one of {YAW_LAWS}", self.yaw_law)
        object.__setattr__(self, "unstable", nonnegative("backup.unstable", self.unstable))
        if self.yaw_law == "continuous" and not 0.0 < self.unstable < math.pi / 2:
            raise ConfigError("backup.unstable", "an angle χ_u in (0, pi/2) rad (the continuous law)", self.unstable)
        if self.yaw_law == "ridge" and self.unstable != 0.0:
            raise ConfigError("backup.unstable", "0 with the ridge yaw law", self.unstable)

    @property
    def smooth(self) -> bool:
        """True when both fades and the ramp are on (the command is rate-bounded; with the ridge law only
        away from the ridge)."""
        return self.surge_fade > 0.0 and self.yaw_fade > 0.0 and self.ramp > 0.0

    @property
    def plateau(self) -> float:
        """χ_p = SHAPE_PLATEAU χ_u (rad): a(χ) = 1 on [χ_p, χ_u] (the continuous law; 0 with the ridge law)."""
        return self.unstable * SHAPE_PLATEAU

    def within(self, u_max: float, w_max: float, r_max: float) -> bool:
        """True when every input of the law lies in V = {|u| <= u_max, |w| <= w_max, |r| <= r_max}."""
        return self.surge <= u_max and self.heave <= w_max and self.yaw_rate <= r_max

    @property
    def bounds(self) -> tuple[float, float, float]:
        """(u_b, w_b, k): the largest |u|, |w|, |r| the law commands after its ramp (m/s, m/s, rad/s)."""
        return self.surge, self.heave, self.yaw_rate

    @property
    def min_surge(self) -> float:
        """−u_b (m/s): station keeping surges astern as well as ahead."""
        return -self.surge

    @property
    def handover_command(self) -> tuple[float, float, float]:
        """(0, 0, 0): without a ramp a plan ends at rest."""
        return 0.0, 0.0, 0.0

    def command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
                ) -> tuple[float, float, float]:
        """:func:`station_keeping_input` of this law (float tuples: the loop's inner loop)."""
        return station_keeping_input(self, state, anchor, elapsed, start)


    def to_dict(self) -> dict[str, Any]:
        """The gains with ``kind``; the fades, the ramp and the yaw law only when set (0 / "ridge": off)."""
        out: dict[str, Any] = {"kind": self.kind}
        for name, value in asdict(self).items():
            if (name in ("surge_fade", "yaw_fade", "ramp", "unstable") and value == 0.0) or \
                    (name == "yaw_law" and value == "ridge"):
                continue
            out[name] = value
        return out

    @property
    def blends(self) -> bool:
        """True when the ramp is on: the command applied at the hand-over fades out over t_r (module doc)."""
        return self.ramp > 0.0

    def __call__(self, state: np.ndarray, anchor: np.ndarray, elapsed: float = math.inf,
                 start: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
        """v = (u, w, r) (m/s, m/s, rad/s) at ``state`` [x, y, z, ψ] about ``anchor`` [x*, y*, z*] (m),
        ``elapsed`` seconds after the hand-over, ``start`` the command applied at the hand-over."""
        return np.array(station_keeping_input(self, tuple(map(float, state)), tuple(map(float, anchor)), elapsed,
                                              tuple(map(float, start))))


def _fade(value: float, scale: float) -> float:
    """min(1, value / scale), 1 when ``scale`` is 0 (the term is off)."""
    return 1.0 if scale <= 0.0 or value >= scale else max(0.0, value / scale)


def station_keeping_input(law: StationKeeping, state: tuple[float, float, float, float],
                          anchor: tuple[float, float, float], elapsed: float = math.inf,
                          start: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> tuple[float, float, float]:
    """The law on float tuples (the closed loop's inner loop): (u, w, r) in m/s, m/s, rad/s.

    ``elapsed`` is the time s (s) since the backup took over; the default (∞) is the law after its ramp.
    ``start`` is the command (m/s, m/s, rad/s) applied at the hand-over; with a ramp it fades out over t_r.
    """
    x, y, z, psi = state
    phi = line_of_sight_angle(x, y, psi, anchor[0], anchor[1])
    chi = axis_angle(phi)
    ramp = _fade(elapsed, law.ramp)
    d = math.hypot(x - anchor[0], y - anchor[1]) if law.surge_fade > 0.0 or law.yaw_fade > 0.0 else math.inf
    u = law.surge * min(_fade(d, law.surge_fade), ramp) * math.cos(phi)
    turn = yaw_shape(law, phi) if law.yaw_law == "continuous" else _sat(chi / law.yaw_band)
    r = -law.yaw_rate * turn * min(_fade(d, law.yaw_fade), ramp)
    w = -law.heave * _sat((z - anchor[2]) / law.heave_band) * ramp
    if law.ramp > 0.0 and ramp < 1.0:
        return _blended(law, (u, w, r), start, 1.0 - ramp)
    return u, w, r


def _blended(law: StationKeeping, command: tuple[float, float, float], start: tuple[float, float, float],
             rest: float) -> tuple[float, float, float]:
    """The law's ``command`` plus ``rest`` (1 − s/t_r) times the hand-over's ``start``, each channel clamped to
    ±max(its law bound, |start_c|): exactly, |law| <= bound · s/t_r, so the sum lies there and the clamp only
    removes rounding (k R + (1 − R) r̄ can round one ulp above r̄, which the loop would clip)."""
    out = []
    for value, blend, bound in zip(command, start, (law.surge, law.heave, law.yaw_rate)):
        top = max(bound, abs(blend))
        out.append(min(max(value + rest * blend, -top), top))
    return out[0], out[1], out[2]


def yaw_shape(law: StationKeeping, phi: float) -> float:
    """ρ(φ) of the continuous yaw law (module doc): π-periodic in φ (rad), in [−1, 1], Lipschitz 1/χ_0."""
    x = math.fmod(phi, math.pi)
    x = x + math.pi if x < 0.0 else x
    band, cut = law.yaw_band, law.unstable
    if x <= cut:
        return min(1.0, x / band, (cut - x) / band)
    return -min(1.0, (x - cut) / band, (math.pi - x) / band)


def axis_shape(law: StationKeeping, phi: float) -> float:
    """a(χ) of the safe set V = d + β a(χ) (dimensionless, in [0, 1]) at the line-of-sight angle φ (rad).

    Ridge law: 1 − cos χ. Continuous law: with x = φ mod π and χ_p = ``law.plateau``,
    (1 − cos(π min(x, χ_p)/χ_p))/2 on [0, χ_u] and (1 − cos(π (π − x)/(π − χ_u)))/2 on [χ_u, π):
    minimum 0 at χ = 0, maximum 1 on [χ_p, χ_u], C¹.
    """
    if law.yaw_law != "continuous":
        return 1.0 - math.cos(axis_angle(phi))
    x = math.fmod(phi, math.pi)
    x = x + math.pi if x < 0.0 else x
    cut = law.unstable
    top = law.plateau
    arg = math.pi * min(x, top) / top if x <= cut else math.pi * (math.pi - x) / (math.pi - cut)
    return 0.5 * (1.0 - math.cos(arg))


@dataclass(frozen=True)
class SafeSet:
    """S = {d + β(1 − cos χ) <= c, |z − z*| <= Z} about the anchor (c = ``level``, β = ``shape``, Z = ``depth``, m)."""

    level: float
    shape: float
    depth: float

    def __post_init__(self) -> None:
        positive("backup.level", self.level)
        nonnegative("backup.shape", self.shape)
        positive("backup.depth", self.depth)

    @property
    def radius(self) -> float:
        """Largest horizontal distance (m) from the anchor inside S."""
        return self.level

    @property
    def handover_radius(self) -> float:
        """Horizontal distance (m) within which every heading lies in S."""
        return self.level - self.shape


@dataclass(frozen=True)
class BackupPlan:
    """The certified backup handed to the loop: the law, its safe set and the hand-over it was proved for.

    Attributes
    ----------
    law : BackupLaw
        The backup law (station keeping, the first :class:`BackupLaw`).
    safe_set : SafeSet
        Its invariant set about the anchor (the end of the last accepted plan).
    handover : (float, float)
        Largest horizontal distance and depth error (m) from the anchor when the backup takes over
        (the replayed plan's last position and depth margins, plus ``anchor_reach`` horizontally).
    anchor_reach : float
        Largest horizontal distance (m) from the plan's nominal end at which the loop may place the anchor
        (``docs/verify.md`` step 12): the hand-over was proved for the last arc's margin plus this distance.
    """

    law: BackupLaw
    safe_set: SafeSet
    handover: tuple[float, float] = (0.0, 0.0)
    anchor_reach: float = 0.0

    def __post_init__(self) -> None:
        nonnegative("backup.anchor_reach", self.anchor_reach)

    def footprint(self, vehicle_radius: float) -> tuple[float, float]:
        """(horizontal radius, half height) (m) of the safe set inflated by the vehicle ball."""
        return self.safe_set.radius + vehicle_radius, self.safe_set.depth + vehicle_radius


#: Directions (unit vectors in the horizontal plane, (ANCHOR_RING, 2)) in which the loop and the FHOCP may move the
#: backup's anchor from a plan's end, by ``BackupPlan.anchor_reach`` (``docs/verify.md`` step 11): both read the same
#: ring, so an anchor the FHOCP plans for is one the exact check tries.
ANCHOR_RING = 16
ANCHOR_DIRECTIONS = np.stack([np.cos(2.0 * np.pi * np.arange(ANCHOR_RING) / ANCHOR_RING),
                              np.sin(2.0 * np.pi * np.arange(ANCHOR_RING) / ANCHOR_RING)], axis=1)
ANCHOR_DIRECTIONS.setflags(write=False)


@functools.lru_cache(maxsize=64)
def anchor_offsets(reach: float) -> np.ndarray:
    """(ANCHOR_RING + 1, 3) horizontal offsets (m) of the anchor from a plan's end: none first, then ``reach`` along
    each of :data:`ANCHOR_DIRECTIONS` (only the first when ``reach`` is 0). Read-only (cached per reach)."""
    out = np.zeros((1 if reach <= 0.0 else ANCHOR_RING + 1, 3))
    if reach > 0.0:
        out[1:, :2] = reach * ANCHOR_DIRECTIONS
    out.setflags(write=False)
    return out


#: Backup laws by ``kind`` (their JSON tag); :func:`register_backup_law` adds one.
BACKUP_LAWS: dict[str, type] = {StationKeeping.kind: StationKeeping}


def register_backup_law(cls: type) -> type:
    """Register a backup-law class under its ``kind`` (usable as a class decorator); ConfigError when the class does
    not state a ``kind`` or the kind is taken by another class."""
    kind = getattr(cls, "kind", None)
    if not isinstance(kind, str) or not kind:
        raise ConfigError("backup.kind", "a class with a non-empty str 'kind'", cls)
    if BACKUP_LAWS.get(kind, cls) is not cls:
        raise ConfigError("backup.kind", f"a kind not yet registered (taken: {sorted(BACKUP_LAWS)})", kind)
    BACKUP_LAWS[kind] = cls
    return cls


def backup_law_from_dict(d: Any, where: str = "backup.law") -> BackupLaw:
    """The backup law of a :meth:`BackupLaw.to_dict` dict (``kind`` absent: station keeping); ConfigError naming
    ``where.<key>`` when the kind is unknown or a parameter is missing, unknown or out of range."""
    if not isinstance(d, dict):
        raise ConfigError(where, "a table of the law's parameters", d)
    params = dict(d)
    kind = params.pop("kind", StationKeeping.kind)
    if kind not in BACKUP_LAWS:
        raise ConfigError(f"{where}.kind", f"one of {sorted(BACKUP_LAWS)}", kind)
    cls = BACKUP_LAWS[kind]
    try:
        return cls(**params)
    except TypeError as exc:
        raise ConfigError(where, f"the parameters of a {kind} law", sorted(params), str(exc)) from None
    except ConfigError as exc:
        name = exc.field.split(".", 1)[1] if exc.field.startswith("backup.") else exc.field
        raise ConfigError(f"{where}.{name}", exc.expected, exc.received) from None
