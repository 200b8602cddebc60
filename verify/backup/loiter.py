"""The loiter law's proof (:class:`tubekit.model.loiter.Loiter`): a backup that never stops, proved in Arb.

The law is held at the ancillary rate (tick h). With d the horizontal distance to the anchor, φ ∈ (−π, π] the
angle between the heading and the line of sight to it (0: pointing at it) and ω the total disturbance
(‖ω_xy‖ <= ω̄_xy, |ω_z| <= ω̄_z), along the plant

    ḋ = −u_l cos φ + ω_r,   φ̇ = r + ε_r + (u_l sin φ − ω_t) / d,   r = −k sat(φ'/χ_0),

φ' the angle at the last tick, |ε_r| <= E_r. The candidate safe set is

    S = {V = d + β a(φ) <= c,  |z − z*| <= Z},

a(φ) = :func:`tubekit.model.loiter.loiter_shape` (0 at φ = 0, 1 at φ = ±π, even, nondecreasing in |φ|).

**Theorem** (first exit). On the level set V = c, d >= c − β; within a tick d changes by at most
h (u_l + ω̄_xy) and φ by at most Δ = h (k + E_r + (u_l + ω̄_xy)/d_tick), d_tick = c − β − h (u_l + ω̄_xy) > 0
(``backup_tick``). If, for every φ ∈ [0, π] and every φ' within Δ of φ, the supremum over ‖ω_xy‖ <= ω̄_xy of V̇,

    −u_l cos φ + ω̄_xy √(1 + (β a'/d)²) + β a' (−k sat(φ'/χ_0) + E_r + u_l sin φ / d),   d = c − β a(φ),

is negative (:func:`loiter_rate_bound`, Arb bisection over φ on each piece of a; the case φ < 0 is the mirror
image; ``backup_level_set``), and the heading cannot cross the ridge φ = ±π within a tick
(``backup_ridge``: (u_l min(1, 2Δ) + ω̄_xy)/d_tick + E_r < k and χ_0 <= π − 2Δ, so the held command turns away
from the ridge wherever the heading is within 2Δ of it), then a trajectory that starts in S cannot reach V = c
with V̇ >= 0, and V is continuous across the ridge (a(π) = a(−π)): it never leaves S. Depth, the hand-over
(d <= c − β, any heading, and |z − z*| <= Z) and the inputs are as for station keeping
(:mod:`verify.backup.proof`). The surge is u_l at every instant: the law never stops the propeller.

Steps of the protocol: :meth:`LoiterProof.design` — :func:`design_loiter` (a grid: the smallest certified
level per surge); :meth:`LoiterProof.certify` — :func:`certify_loiter`; :meth:`LoiterProof.command_rate` and
:meth:`LoiterProof.tick_change` — :func:`loiter_command_rate`, :func:`loiter_tick_change`. Importing this module
registers :data:`LOITER_PROOF` (``verify/backup/__init__.py`` imports it).
"""

from __future__ import annotations

import math

import numpy as np
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupLaw, SafeSet
from tubekit.model.loiter import Loiter, loiter_shape, loiter_shape_slope
from tubekit.validation import nonnegative, positive
from verify.backup.proof import angle_step, checked_bounds, hold_conditions, ridge_rate, tick_distance
from verify.backup.protocol import BackupCertificate, Fits, register_backup_proof
from verify.backup.search import depth_band
from verify.kernel.intervals import bisect_sup, enclose, lower, upper
from verify.theorem.design import Condition

__all__ = ["LoiterProof", "LOITER_PROOF", "certify_loiter", "design_loiter", "loiter_surges", "loiter_rate_bound",
           "shape_floor",
           "loiter_rate_sampled", "loiter_command_rate", "loiter_tick_change", "LOITER_MAX_BOXES"]

#: Bisection budget of :func:`loiter_rate_bound` (intervals of φ examined, both pieces): a work unit, not seconds.
LOITER_MAX_BOXES = 4096
#: The design grid (:func:`design_loiter`): surge fractions of ū (besides the surge floor u_min itself), the yaw band
#: χ_0 (rad), level and shape steps (m). The slowest loiter turns tightest (radius u_l / k), so its set is smallest.
SURGE_FRACTIONS = (0.2, 0.3, 0.4, 0.5, 0.625, 0.75, 0.875, 1.0)
YAW_BAND = 0.1
LEVEL_STEP = 0.25
MAX_LEVEL = 40.0
_PI_UP = math.nextafter(math.pi, math.inf)


def _law_of(law: BackupLaw) -> Loiter:
    if not isinstance(law, Loiter):
        raise ConfigError("backup.kind", f"a {Loiter.kind} law", getattr(law, "kind", type(law).__name__))
    return law


def _shape_enclosure(bend: float, x: arb, quadratic: bool) -> tuple[arb, arb]:
    """(a, a') over the ball ``x`` of φ (rad) on one piece of the shape (module doc of ``loiter_shape``)."""
    s, length = arb(bend), arb(math.pi) - arb(bend) / 2
    if quadratic:
        return x * x / (2 * s * length), x / (s * length)
    return (x - s / 2) / length, 1 / length


def _rate_upper(law: Loiter, safe: SafeSet, omega_xy: float, delta: float, yaw_err: float, quadratic: bool,
                a: float, b: float) -> float:
    """An upper bound (m/s) of V̇ over φ ∈ [a, b] on the level set, every held φ' and every ω."""
    x = enclose(a, b)
    beta, u = arb(safe.shape), arb(law.surge)
    shape, slope = _shape_enclosure(law.bend, x, quadratic)
    d = arb(safe.level) - beta * shape
    if not lower(d) > 0.0:
        return math.inf
    g = beta * slope
    held_low = max(-1.0, min(1.0, lower((arb(a) - arb(delta)) / arb(law.yaw_band))))
    r_up = -arb(law.yaw_rate) * arb(held_low)
    rate = -u * x.cos() + arb(omega_xy) * (1 + (g / d) ** 2).sqrt() + g * (r_up + arb(yaw_err) + u * x.sin() / d)
    return upper(rate)


def loiter_rate_bound(law: Loiter, safe: SafeSet, omega_xy: float, tick: float,
                      max_boxes: int = LOITER_MAX_BOXES, yaw_rate_error: float = 0.0) -> tuple[float, int]:
    """(bound, intervals): a certified upper bound (m/s) of V̇ on V = c (module doc), by bisection in φ over
    [0, φ_s] and [φ_s, π] (the two pieces of a); ``inf`` when c − β cannot absorb a tick's motion."""
    d_tick = tick_distance(law, safe, omega_xy, tick)
    if not d_tick > 0.0:
        return math.inf, 0
    delta = angle_step(law, omega_xy, tick, d_tick, yaw_rate_error)
    half = max(1, max_boxes // 2)
    low, n_low = bisect_sup(lambda a, b: _rate_upper(law, safe, omega_xy, delta, yaw_rate_error, True, a, b),
                            0.0, law.bend, half)
    high, n_high = bisect_sup(lambda a, b: _rate_upper(law, safe, omega_xy, delta, yaw_rate_error, False, a, b),
                              law.bend, _PI_UP, half)
    return max(low, high), n_low + n_high


def loiter_rate_sampled(law: Loiter, safe: SafeSet, omega_xy: float, n: int = 1441, yaw_err: float = 0.0) -> float:
    """The largest V̇ (m/s) at sampled φ ∈ [0, π] with the input of the same instant (no hold) and the worst ω."""
    return float(_sampled_rates(law, safe.level, np.array([safe.shape]), omega_xy, n, yaw_err)[0])


def _sampled_rates(law: Loiter, level: float, shapes: np.ndarray, omega_xy: float, n: int,
                   yaw_err: float) -> np.ndarray:
    """The largest sampled V̇ (m/s) at level c = ``level`` for each shape β of ``shapes`` (no hold, worst ω)."""
    phi = np.linspace(0.0, math.pi, n)[None, :]
    a, slope = loiter_shape(law.bend, phi), loiter_shape_slope(law.bend, phi)
    g = shapes[:, None] * slope
    d = level - shapes[:, None] * a
    r = -law.yaw_rate * np.clip(phi / law.yaw_band, -1.0, 1.0)
    rate = (-law.surge * np.cos(phi) + omega_xy * np.sqrt(1 + (g / d) ** 2)
            + g * (r + yaw_err + law.surge * np.sin(phi) / d))
    return rate.max(axis=1)


def shape_floor(law: Loiter, omega_xy: float, yaw_err: float = 0.0) -> float:
    """β_min (m): at the ridge (pointing away, d = c − β) V̇ <= u_l + ω̄_xy − β (k − E_r)/L needs
    β > L (u_l + ω̄_xy)/(k − E_r), L = π − φ_s/2 (a necessary condition; ``inf`` when k <= E_r)."""
    room = law.yaw_rate - yaw_err
    return (math.pi - 0.5 * law.bend) * (law.surge + omega_xy) / room if room > 0.0 else math.inf


def _conditions(law: Loiter, safe: SafeSet, dist: tuple[float, float], limits: tuple[float, float, float],
                tick: float, handover: tuple[float, float], rate: float, yaw_err: float) -> tuple[Condition, ...]:
    """Every inequality of the theorem, with both numbers (the depth hold and the hand-over as station keeping's:
    :func:`verify.backup.proof.hold_conditions`)."""
    wxy, wz = dist
    d_tick = tick_distance(law, safe, wxy, tick)
    delta = angle_step(law, wxy, tick, d_tick, yaw_err) if d_tick > 0 else math.inf
    ridge = ridge_rate(law.surge, wxy, delta, d_tick, yaw_err)
    return (
        Condition("backup_inputs", "u_l <= u_max, w_b <= w_max, k <= r_max", max(
            law.surge / limits[0], law.heave / limits[1], law.yaw_rate / limits[2]), 1.0,
            law.within(*limits), "largest ratio"),
        Condition("backup_surge", "ω̄_xy < u_l (the loiter outruns the current)", wxy, law.surge, wxy < law.surge),
        Condition("backup_tick", "c − β − h (u_l + ω̄_xy) > 0", d_tick, 0.0, d_tick > 0.0),
        Condition("backup_ridge", "(u_l min(1, 2Δ) + ω̄_xy) / d_tick + E_r < k and χ_0 <= π − 2Δ", ridge,
                  law.yaw_rate, ridge < law.yaw_rate and law.yaw_band <= math.pi - 2 * delta),
        Condition("backup_level_set", "sup V̇ on V = c < 0", rate, 0.0, rate < 0.0),
    ) + hold_conditions(law, safe, wz, tick, handover)


def certify_loiter(law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                   limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                   max_boxes: int = LOITER_MAX_BOXES, yaw_rate_error: float = 0.0) -> BackupCertificate:
    """Prove (or refute, naming each failed inequality) that ``safe`` is invariant under the loiter ``law`` held at
    the tick h (s) against ω̄_xy, ω̄_z (m/s) and E_r (rad/s), from every hand-over within ``handover`` (m, m)."""
    loiter = _law_of(law)
    wxy, wz, h, e_r, handover = checked_bounds(omega_xy, omega_z, tick, yaw_rate_error, handover)
    rate, boxes = loiter_rate_bound(loiter, safe, wxy, h, max_boxes, e_r)
    conditions = _conditions(loiter, safe, (wxy, wz), tuple(float(x) for x in limits), h, handover, rate, e_r)
    return BackupCertificate(law=loiter, safe_set=safe, omega_xy=wxy, omega_z=wz, tick=h, rate_bound=rate,
                             rate_sampled=loiter_rate_sampled(loiter, safe, wxy, yaw_err=e_r), boxes=boxes,
                             conditions=conditions, handover=handover, yaw_rate_error=e_r)


def _best_shape(law: Loiter, level: float, omega_xy: float, handover: float, yaw_err: float) -> float | None:
    """The shape β on a 5 cm grid from :func:`shape_floor` to c − h_xy with the most negative sampled level-set
    rate, or None."""
    floor = shape_floor(law, omega_xy, yaw_err)
    if not math.isfinite(floor):
        return None
    shapes = np.round(np.arange(0.05 * math.floor(floor / 0.05), level - handover, 0.05), 6)
    shapes = shapes[shapes > 0.0]
    if shapes.size == 0:
        return None
    rates = _sampled_rates(law, level, shapes, omega_xy, 361, yaw_err)
    i = int(np.argmin(rates))
    return float(shapes[i]) if rates[i] < 0.0 else None


def loiter_surges(u_max: float, surge_floor: float | None = None) -> tuple[float, ...]:
    """The surges :func:`design_loiter` tries, slowest first (m/s): the floor u_min when given, then f ū for f of
    :data:`SURGE_FRACTIONS` above it (a loiter never commands less than the plans' floor: ``backup_min_surge``)."""
    floor = 0.0 if surge_floor is None else float(surge_floor)
    grid = [f * u_max for f in SURGE_FRACTIONS if f * u_max > floor]
    return tuple(([floor] if surge_floor is not None and 0.0 < floor < u_max else []) + grid)


def design_loiter(*, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
                  handover: tuple[float, float] = (0.0, 0.0), yaw_rate_error: float = 0.0,
                  max_boxes: int = LOITER_MAX_BOXES, surge_floor: float | None = None) -> BackupCertificate:
    """The certified loiter with the smallest safe radius on a fixed grid (deterministic): for each surge u_l of
    :func:`loiter_surges` (``surge_floor``: the plans' u_min, m/s) with k = r̄ and χ_0 = :data:`YAW_BAND`, the
    levels c of a :data:`LEVEL_STEP` grid up to :data:`MAX_LEVEL` in order, each with the shape of the most
    negative sampled rate, until one certifies; the smallest certified level over the surges. Returns the last
    refuted candidate when none certifies."""
    wxy, wz, h = nonnegative("omega_xy", omega_xy), nonnegative("omega_z", omega_z), positive("tick", tick)
    lim = tuple(float(x) for x in limits)
    z0, depth = depth_band(handover, lim, wz, h)
    best: BackupCertificate | None = None
    last: BackupCertificate | None = None
    levels = np.round(np.arange(LEVEL_STEP, MAX_LEVEL + 1e-9, LEVEL_STEP), 6)
    for surge in loiter_surges(lim[0], surge_floor):
        law = Loiter(surge=surge, yaw_rate=lim[2], yaw_band=YAW_BAND, heave=lim[1], heave_band=z0)
        start = shape_floor(law, wxy, yaw_rate_error) + handover[0]
        for level in levels[(levels > start) & (levels < (best.safe_set.level if best else math.inf))]:
            shape = _best_shape(law, float(level), wxy, handover[0], yaw_rate_error)
            if shape is None:
                continue
            last = certify_loiter(law, SafeSet(level=float(level), shape=shape, depth=depth), omega_xy=wxy,
                                  omega_z=wz, limits=lim, tick=h, handover=handover, max_boxes=max_boxes,
                                  yaw_rate_error=yaw_rate_error)
            if last.certified:
                best = last
                break
    if best is not None:
        return best
    if last is not None:
        return last
    law = Loiter(surge=lim[0], yaw_rate=lim[2], yaw_band=YAW_BAND, heave=lim[1], heave_band=z0)
    return certify_loiter(law, SafeSet(level=MAX_LEVEL, shape=1.0, depth=depth), omega_xy=wxy, omega_z=wz,
                          limits=lim, tick=h, handover=handover, max_boxes=max_boxes, yaw_rate_error=yaw_rate_error)


def loiter_command_rate(law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                        limits: tuple[float, float, float],
                        loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
    """Upper bounds on |u̇|, |ẇ|, |ṙ| of the command along the plant (m/s², m/s², rad/s²): 0 (constant surge),
    w_b (w_b + ω̄_z + E_w)/z_0, and ``inf`` for yaw (the line of sight turns at up to (u_l + ω̄_xy)/d near the
    anchor, and r = −k sat(φ/χ_0) follows it)."""
    loiter = _law_of(law)
    heave = upper(arb(loiter.heave) * (arb(loiter.heave) + arb(omega_z) + arb(loop_error[1])) / arb(loiter.heave_band))
    return 0.0, heave, math.inf


def loiter_tick_change(law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                       limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                       tick: float) -> tuple[float, float, float]:
    """The largest change of the held command from one tick to the next (m/s, m/s, rad/s): 0 for surge, the heave
    rate × h (at most 2 w_b), and 2 k for yaw (the command flips sign where the heading crosses the ridge)."""
    loiter = _law_of(law)
    _, heave, _ = loiter_command_rate(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                      loop_error=loop_error)
    return 0.0, min(upper(arb(heave) * arb(tick)), 2.0 * loiter.heave), 2.0 * loiter.yaw_rate


class LoiterProof:
    """The proof of ``kind = "loiter"`` (module doc); a stateless object."""

    kind: str = Loiter.kind

    def design(self, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
               handover: tuple[float, float], yaw_rate_error: float = 0.0, smooth: bool = False,
               fits: Fits | None = None, surge_floor: float | None = None) -> BackupCertificate:
        """:func:`design_loiter`, no slower than ``surge_floor``. The law's yaw command is not rate-bounded
        (``smooth`` and ``fits`` are not read: the velocity loop is charged its tick change, 2 k)."""
        return design_loiter(omega_xy=omega_xy, omega_z=omega_z, limits=limits, tick=tick, handover=handover,
                             yaw_rate_error=yaw_rate_error, surge_floor=surge_floor)

    def certify(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                yaw_rate_error: float = 0.0) -> BackupCertificate:
        """:func:`certify_loiter` (ConfigError when ``law`` is not a Loiter)."""
        return certify_loiter(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits, tick=tick,
                              handover=handover, yaw_rate_error=yaw_rate_error)

    def command_rate(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                     limits: tuple[float, float, float],
                     loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
        """:func:`loiter_command_rate` (m/s², m/s², rad/s²)."""
        return loiter_command_rate(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                   loop_error=loop_error)

    def tick_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> tuple[float, float, float]:
        """:func:`loiter_tick_change` (m/s, m/s, rad/s per tick)."""
        return loiter_tick_change(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                  loop_error=loop_error, tick=tick)

    def sway_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> float:
        """0 (m/s): the law never commands sway."""
        return 0.0

    def summary_lines(self, cert: BackupCertificate) -> list[str]:
        """The loiter's lines: verdict, safe set, gains, level-set rate."""
        s, law = cert.safe_set, _law_of(cert.law)
        head = "certified" if cert.certified else "NOT certified: " + ", ".join(c.condition for c in cert.failures)
        return [f"backup (loiter): {head}",
                f"  safe set: horizontal radius {s.radius:.3f} m, depth band ±{s.depth:.3f} m; hand-over within "
                f"{s.handover_radius:.3f} m of the anchor (any heading)",
                f"  law: surge u_l {law.surge:g} m/s (never less), k {law.yaw_rate:g} rad/s, χ_0 {law.yaw_band:g} rad, "
                f"w_b {law.heave:g} m/s; against ω̄_xy {cert.omega_xy:.4g} m/s, ω̄_z {cert.omega_z:.4g} m/s",
                f"  sup V̇ on the level set <= {cert.rate_bound:.4g} m/s (sampled {cert.rate_sampled:.4g}, "
                f"{cert.boxes} intervals)"]


#: The registered loiter proof.
LOITER_PROOF = register_backup_proof(LoiterProof())
