"""The backup law's safe set, proved in Arb: station keeping holds for all time.

The law (:class:`tubekit.model.backup.StationKeeping`) is held at the ancillary rate (tick h). With d
the horizontal distance to the anchor, χ the axis angle (``tubekit.model.backup.axis_angle``) and
ω the total disturbance (current and sway, ‖ω_xy‖ <= ω̄_xy, |ω_z| <= ω̄_z), along the plant

    ḋ = −u cos φ + ω_r,        χ̇ = r + (u sin φ − ω_t) / d,        u = u_b cos φ',  r = −k sat(χ'/χ_0),

where φ', χ' are the angles at the last tick. The candidate safe set is

    S = {V = d + β (1 − cos χ) <= c,  |z − z*| <= Z}.

**Theorem** (first exit). On the level set V = c, d >= c − β; within a tick d changes by at most
h (u_b + ω̄_xy) and χ by at most Δ = h (k + (u_b + ω̄_xy)/d_tick), d_tick = c − β − h (u_b + ω̄_xy) > 0.
If, for every χ ∈ [0, π/2] and every χ' within Δ of χ, the supremum over ‖ω_xy‖ <= ω̄_xy of V̇,

    −u_b cos χ' cos χ + ω̄_xy √(1 + (g'/d)²) + g' (−k sat(χ'/χ_0) + u_b cos χ' sin χ / d),   g' = β sin χ,

is negative (:func:`planar_rate_bound`, Arb bisection over χ; the case χ < 0 is the mirror image),
and the axis angle cannot cross ±π/2 within a tick (condition ``ridge``), then a trajectory that
starts in S cannot reach V = c with V̇ >= 0, so it never leaves S. Depth: where |z − z*| = Z the
held heave command is −w_b sign(z − z*) (``z_0 + h (w_b + ω̄_z) <= Z``) and w_b > ω̄_z.
Every input of the law lies in V, so the sway bound γ̄ inside ω̄_xy (derived over V) applies.
A state whose horizontal distance to the anchor is at most c − β (any heading) and whose depth
error is at most Z lies in S: that is the hand-over condition.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.validation import nonnegative, positive
from verify.design import Condition
from verify.intervals import enclose, lower, upper
from verify.parts import block, bound, integer, item, number, numbers

__all__ = ["BackupCertificate", "planar_rate_bound", "certify_backup", "design_backup",
           "BACKUP_MAX_BOXES"]

#: Bisection budget of :func:`planar_rate_bound` (intervals of χ examined): a work unit, not seconds.
BACKUP_MAX_BOXES = 4096
_HALF_PI_UP = math.nextafter(math.pi / 2, math.inf)


@dataclass(frozen=True)
class BackupCertificate:
    """The backup law, its safe set, the disturbance it holds against and every checked condition."""

    law: StationKeeping
    safe_set: SafeSet
    omega_xy: float
    omega_z: float
    tick: float
    rate_bound: float
    rate_sampled: float
    boxes: int
    conditions: tuple[Condition, ...]
    handover: tuple[float, float] = (0.0, 0.0)

    @property
    def certified(self) -> bool:
        """True when every condition holds."""
        return all(c.ok for c in self.conditions)

    @property
    def failures(self) -> tuple[Condition, ...]:
        """The conditions that do not hold."""
        return tuple(c for c in self.conditions if not c.ok)

    def to_dict(self) -> dict:
        """Plain JSON-able data (floats, strings, booleans)."""
        return {"law": asdict(self.law), "safe_set": asdict(self.safe_set), "omega_xy": self.omega_xy,
                "omega_z": self.omega_z, "tick": self.tick, "rate_bound": self.rate_bound,
                "rate_sampled": self.rate_sampled, "boxes": self.boxes, "certified": self.certified,
                "handover": list(self.handover), "conditions": [c.to_dict() for c in self.conditions]}

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.backup") -> "BackupCertificate":
        """Inverse of :meth:`to_dict` (``certified`` is recomputed; ConfigError naming the key)."""
        law_ = _typed(StationKeeping, block(d, "law", where), f"{where}.law",
                      ("surge", "yaw_rate", "yaw_band", "heave", "heave_band"))
        safe_ = _typed(SafeSet, block(d, "safe_set", where), f"{where}.safe_set", ("level", "shape", "depth"))
        conds = item(d, "conditions", where)
        if not isinstance(conds, list):
            raise ConfigError(f"{where}.conditions", "a list of conditions", type(conds).__name__)
        return cls(law=law_, safe_set=safe_, omega_xy=number(d, "omega_xy", where),
                   omega_z=number(d, "omega_z", where), tick=number(d, "tick", where),
                   rate_bound=bound(d, "rate_bound", where), rate_sampled=number(d, "rate_sampled", where),
                   boxes=integer(d, "boxes", where),
                   conditions=tuple(Condition.from_dict(c, f"{where}.conditions[{i}]") for i, c in enumerate(conds)),
                   handover=numbers(d, "handover", where, 2))

    def summary_lines(self) -> list[str]:
        """Human-readable lines for a certificate's text."""
        s, law = self.safe_set, self.law
        head = "certified" if self.certified else "NOT certified: " + ", ".join(c.condition for c in self.failures)
        return [f"backup (station keeping): {head}",
                f"  safe set: horizontal radius {s.radius:.3f} m, depth band ±{s.depth:.3f} m; hand-over within "
                f"{s.handover_radius:.3f} m of the anchor (any heading)",
                f"  law: u_b {law.surge:g} m/s, k {law.yaw_rate:g} rad/s, w_b {law.heave:g} m/s; against "
                f"ω̄_xy {self.omega_xy:.4g} m/s, ω̄_z {self.omega_z:.4g} m/s",
                f"  sup V̇ on the level set <= {self.rate_bound:.4g} m/s (sampled {self.rate_sampled:.4g}, "
                f"{self.boxes} intervals)"]


def _typed(cls: type, d: dict, where: str, keys: tuple[str, ...]):
    """``cls(**numbers)`` from ``d``, a ConfigError naming ``where.key`` when a value is refused."""
    try:
        return cls(**{k: number(d, k, where) for k in keys})
    except ConfigError as exc:
        if exc.field.startswith(where):
            raise
        raise ConfigError(f"{where}.{exc.field.split('.')[-1]}", exc.expected, exc.received) from None


def _tick_distance(law: StationKeeping, safe: SafeSet, omega_xy: float, tick: float) -> float:
    """A float <= c − β − h (u_b + ω̄_xy) (m): the least distance to the anchor during a tick that ends on V = c."""
    return lower(arb(safe.level) - arb(safe.shape) - arb(tick) * (arb(law.surge) + arb(omega_xy)))


def _angle_step(law: StationKeeping, omega_xy: float, tick: float, d_tick: float) -> float:
    """Δ (rad), a float >= h (k + (u_b + ω̄_xy) / d_tick): how far χ moves within one tick."""
    return upper(arb(tick) * (arb(law.yaw_rate) + (arb(law.surge) + arb(omega_xy)) / arb(d_tick)))


def _rate_upper(law: StationKeeping, safe: SafeSet, omega_xy: float, delta: float, a: float, b: float) -> float:
    """An upper bound (m/s) of V̇ over χ ∈ [a, b] on the level set, every held χ' and every ω."""
    x = enclose(a, b)
    beta, c, ub = arb(safe.shape), arb(safe.level), arb(law.surge)
    g_prime = beta * x.sin()
    d = c - beta * (1 - x.cos())
    held = enclose(max(a - delta, -math.pi / 2), min(b + delta, _HALF_PI_UP))
    ratio_low = max(-1.0, min(1.0, lower((arb(a) - arb(delta)) / arb(law.yaw_band))))
    r_up = -arb(law.yaw_rate) * arb(ratio_low)
    held_cos = held.cos()
    rate = (-ub * held_cos * x.cos() + arb(omega_xy) * (1 + (g_prime / d) ** 2).sqrt()
            + g_prime * (r_up + ub * held_cos * x.sin() / d))
    return upper(rate)


def _rate_sampled(law: StationKeeping, safe: SafeSet, omega_xy: float, n: int = 721) -> float:
    """The largest V̇ (m/s) at sampled χ with the input of the same instant (no hold) and the worst ω."""
    chi = np.linspace(0.0, math.pi / 2, n)
    gp = safe.shape * np.sin(chi)
    d = safe.level - safe.shape * (1 - np.cos(chi))
    r = -law.yaw_rate * np.clip(chi / law.yaw_band, -1.0, 1.0)
    u = law.surge * np.cos(chi)
    rate = -u * np.cos(chi) + omega_xy * np.sqrt(1 + (gp / d) ** 2) + gp * (r + u * np.sin(chi) / d)
    return float(rate.max())


def planar_rate_bound(law: StationKeeping, safe: SafeSet, omega_xy: float, tick: float,
                      max_boxes: int = BACKUP_MAX_BOXES) -> tuple[float, int]:
    """(bound, intervals): a certified upper bound (m/s) of V̇ on the level set V = c, by bisection in χ.

    Bisection stops on an interval once its bound is negative; the bound returned is the largest
    over the final cover of [0, π/2] (``inf`` when c − β cannot absorb a tick's motion).
    """
    d_tick = _tick_distance(law, safe, omega_xy, tick)
    if not d_tick > 0.0:
        return math.inf, 0
    delta = _angle_step(law, omega_xy, tick, d_tick)
    pending, done, used = [(0.0, _HALF_PI_UP)], [], 0
    while pending:
        a, b = pending.pop()
        bound = _rate_upper(law, safe, omega_xy, delta, a, b)
        used += 1
        if bound < 0.0 or used + len(pending) >= max_boxes or b - a < 1e-9:
            done.append(bound)
            continue
        mid = 0.5 * (a + b)
        pending += [(mid, b), (a, mid)]
    return max(done), used


def _conditions(law: StationKeeping, safe: SafeSet, dist: tuple[float, float], limits: tuple[float, float, float],
                tick: float, handover: tuple[float, float], rate: float) -> tuple[Condition, ...]:
    """Every inequality of the theorem, with both numbers."""
    wxy, wz = dist
    d_tick = _tick_distance(law, safe, wxy, tick)
    delta = _angle_step(law, wxy, tick, d_tick) if d_tick > 0 else math.inf
    ridge = upper((arb(law.surge) * arb(min(1.0, 2 * delta)) + arb(wxy)) / arb(d_tick)) if d_tick > 0 else math.inf
    hold_z = upper(arb(law.heave_band) + arb(tick) * (arb(law.heave) + arb(wz)))
    cond = Condition
    return (
        cond("backup_inputs", "u_b <= u_max, w_b <= w_max, k <= r_max", max(law.surge / limits[0],
             law.heave / limits[1], law.yaw_rate / limits[2]), 1.0, law.within(*limits), "largest ratio"),
        cond("backup_tick", "c − β − h (u_b + ω̄_xy) > 0", d_tick, 0.0, d_tick > 0.0),
        cond("backup_ridge", "(u_b sin 2Δ + ω̄_xy) / d_tick < k and χ_0 <= π/2 − 2Δ", ridge, law.yaw_rate,
             ridge < law.yaw_rate and law.yaw_band <= math.pi / 2 - 2 * delta),
        cond("backup_level_set", "sup V̇ on V = c < 0", rate, 0.0, rate < 0.0),
        cond("backup_heave", "ω̄_z < w_b", wz, law.heave, wz < law.heave),
        cond("backup_depth_hold", "z_0 + h (w_b + ω̄_z) <= Z", hold_z, safe.depth, hold_z <= safe.depth),
        cond("backup_handover", "hand-over distance <= c − β", handover[0], safe.handover_radius,
             handover[0] <= safe.handover_radius),
        cond("backup_handover_depth", "hand-over depth error <= Z", handover[1], safe.depth,
             handover[1] <= safe.depth),
    )


def certify_backup(law: StationKeeping, safe: SafeSet, *, omega_xy: float, omega_z: float,
                   limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                   max_boxes: int = BACKUP_MAX_BOXES) -> BackupCertificate:
    """Prove (or refute, naming the failed inequalities) that ``safe`` is invariant under ``law``.

    Parameters
    ----------
    law, safe : StationKeeping, SafeSet
        The backup law and its candidate safe set.
    omega_xy, omega_z : float
        Certified disturbance bounds (m/s), current and sway together.
    limits : (float, float, float)
        V: u_max, w_max (m/s), r_max (rad/s).
    tick : float
        Hold of the law (s): 1 / ancillary rate.
    handover : (float, float)
        Largest horizontal distance and depth error (m) from the anchor when the backup takes over.
    """
    if not isinstance(law, StationKeeping) or not isinstance(safe, SafeSet):
        raise ConfigError("backup", "a StationKeeping law and a SafeSet", (type(law).__name__, type(safe).__name__))
    wxy, wz, h = nonnegative("omega_xy", omega_xy), nonnegative("omega_z", omega_z), positive("tick", tick)
    handover = (nonnegative("handover[0]", handover[0]), nonnegative("handover[1]", handover[1]))
    rate, boxes = planar_rate_bound(law, safe, wxy, h, max_boxes)
    conditions = _conditions(law, safe, (wxy, wz), tuple(float(x) for x in limits), h, handover, rate)
    return BackupCertificate(law=law, safe_set=safe, omega_xy=wxy, omega_z=wz, tick=h, rate_bound=rate,
                             rate_sampled=_rate_sampled(law, safe, wxy), boxes=boxes, conditions=conditions,
                             handover=handover)


def _candidates(limits: tuple[float, float, float], omega_xy: float) -> list[tuple[float, float]]:
    """(u_b, k) pairs to try: surge fractions of u_max above ω̄_xy, the full yaw rate."""
    return [(f * limits[0], limits[2]) for f in (0.5, 0.625, 0.75, 0.875, 1.0) if f * limits[0] > omega_xy]


def design_backup(*, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
                  handover: tuple[float, float] = (0.0, 0.0), max_boxes: int = BACKUP_MAX_BOXES) -> BackupCertificate:
    """The certified station-keeping design with the smallest safe radius on a fixed grid (deterministic).

    The grid (surge fractions, shapes β, levels c) is searched with the float rate of
    :func:`_rate_sampled` as a filter; each candidate that passes is then proved by
    :func:`certify_backup`. Returns the last refuted candidate when none is certified.
    """
    wxy, wz, h = nonnegative("omega_xy", omega_xy), nonnegative("omega_z", omega_z), positive("tick", tick)
    heave = limits[1]
    band = max(1e-3, 0.5 * handover[1])
    depth = max(handover[1], band + h * (heave + wz)) * (1 + 1e-9)
    best: BackupCertificate | None = None
    last: BackupCertificate | None = None
    for surge, yaw in _candidates(limits, wxy):
        law = StationKeeping(surge=surge, yaw_rate=yaw, yaw_band=0.05, heave=heave, heave_band=band)
        for level in np.round(np.arange(0.2, 6.0001, 0.05), 6):
            if best is not None and level >= best.safe_set.level:
                break
            shape = _best_shape(law, float(level), wxy, handover[0])
            if shape is None:
                continue
            last = certify_backup(law, SafeSet(level=float(level), shape=shape, depth=depth), omega_xy=wxy,
                                  omega_z=wz, limits=limits, tick=h, handover=handover, max_boxes=max_boxes)
            if last.certified:
                best = last
                break
    if best is not None:
        return best
    if last is None:
        law = StationKeeping(surge=limits[0], yaw_rate=limits[2], yaw_band=0.05, heave=heave, heave_band=band)
        last = certify_backup(law, SafeSet(level=6.0, shape=1.0, depth=depth), omega_xy=wxy, omega_z=wz,
                              limits=limits, tick=h, handover=handover, max_boxes=max_boxes)
    return last


def _best_shape(law: StationKeeping, level: float, omega_xy: float, handover: float) -> float | None:
    """The shape β on a grid with the most negative sampled level-set rate at ``level``, or None."""
    best, value = None, 0.0
    for shape in np.round(np.arange(0.05, level - handover, 0.05), 6):
        rate = _rate_sampled(law, SafeSet(level=level, shape=float(shape), depth=1.0), omega_xy)
        if rate < value:
            best, value = float(shape), rate
    return best
