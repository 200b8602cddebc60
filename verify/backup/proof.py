"""The backup law's safe set, proved in Arb: station keeping holds for all time.

The law (:class:`tubekit.model.backup.StationKeeping`) is held at the ancillary rate (tick h). With d
the horizontal distance to the anchor, χ the axis angle (``tubekit.model.backup.axis_angle``) and
ω the total disturbance (current and sway, ‖ω_xy‖ <= ω̄_xy, |ω_z| <= ω̄_z), along the plant

    ḋ = −u cos φ + ω_r,   χ̇ = r + ε_r + (u sin φ − ω_t) / d,   u = u_b cos φ',  r = −k sat(χ'/χ_0),

where φ', χ' are the angles at the last tick and |ε_r| <= E_r (``yaw_rate_error``: the velocity loop's
yaw-rate error on the dynamic plant, 0 on the kinematic one). The candidate safe set is

    S = {V = d + β (1 − cos χ) <= c,  |z − z*| <= Z}.

**Theorem** (first exit). On the level set V = c, d >= c − β; within a tick d changes by at most
h (u_b + ω̄_xy) and χ by at most Δ = h (k + E_r + (u_b + ω̄_xy)/d_tick), d_tick = c − β − h (u_b + ω̄_xy) > 0.
If, for every χ ∈ [0, π/2] and every χ' within Δ of χ, the supremum over ‖ω_xy‖ <= ω̄_xy of V̇,

    −u_b cos χ' cos χ + ω̄_xy √(1 + (g'/d)²) + g' (−k sat(χ'/χ_0) + E_r + u_b cos χ' sin χ / d),   g' = β sin χ,

is negative (:func:`planar_rate_bound`, Arb bisection over χ; the case χ < 0 is the mirror image),
and the axis angle cannot cross ±π/2 within a tick (condition ``ridge``), then a trajectory that
starts in S cannot reach V = c with V̇ >= 0, so it never leaves S. Depth: where |z − z*| = Z the
held heave command is −w_b sign(z − z*) (``z_0 + h (w_b + ω̄_z) <= Z``) and w_b > ω̄_z.
Every input of the law lies in V, so the sway bound γ̄ inside ω̄_xy (derived over V) applies.
A state whose horizontal distance to the anchor is at most c − β (any heading) and whose depth
error is at most Z lies in S: that is the hand-over condition.

**Fades and ramp** (``StationKeeping.surge_fade`` d_0, ``yaw_fade`` d_1, ``ramp`` t_r). The argument above
only uses the law at tick starts with d >= d_tick (``backup_fade``: d_0, d_1 <= d_tick, so the fades are
1 there) and after the ramp. During the ramp the command blends the one applied at the hand-over (in V)
into the law, so the vehicle's speed is at most U + ω̄_xy horizontally and W + ω̄_z in depth,
(U, W) = (max(u_b, ū), max(w_b, w̄)): from the hand-over (d <= h_xy, |z − z*| <= h_z) V = c needs
d >= c − β, at least (c − β − h_xy)/(U + ω̄_xy) seconds later, and |z − z*| = Z at least
(Z − h_z)/(W + ω̄_z) seconds later; ``backup_ramp`` asks t_r + h below both, so every tick start that
matters has s >= t_r, where the blend is over. The command's rate is bounded in :mod:`verify.backup.rate`.

**Continuous yaw law** (``StationKeeping.yaw_law == "continuous"``): the level set is V = d + β a(χ)
(:func:`tubekit.model.backup.axis_shape`), the rate bound is :func:`verify.backup.continuous.continuous_rate_bound`
over the whole axis circle, and the condition ``backup_ridge`` is replaced by ``backup_unstable``
(0 < χ_u < χ_c); every other condition is the same.

This module is the ``certify`` step of the station-keeping proof (:mod:`verify.backup.station_keeping`, registered
for :class:`verify.backup.protocol.BackupProof`); the :class:`BackupCertificate` it returns is the protocol's.
"""

from __future__ import annotations

import math

import numpy as np
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.model.loiter import Loiter
from tubekit.validation import nonnegative, positive
from verify.theorem.design import Condition
from verify.kernel.intervals import bisect_sup, enclose, lower, upper
from verify.backup.continuous import (continuous_held_rate_sampled, continuous_rate_bound, continuous_rate_sampled,
                                      unstable_condition)
from verify.backup.protocol import BackupCertificate
from verify.backup.rate import backup_command_rate, backup_tick_change

__all__ = ["BackupCertificate", "planar_rate_bound", "certify_backup", "ramp_window", "tick_distance", "rate_sampled",
           "rates_sampled", "held_rate_sampled", "ridge_rate", "hold_conditions", "angle_step", "checked_bounds",
           "backup_command_rate", "backup_tick_change", "BACKUP_MAX_BOXES"]

#: Bisection budget of :func:`planar_rate_bound` (intervals of χ examined): a work unit, not seconds.
BACKUP_MAX_BOXES = 4096
_HALF_PI_UP = math.nextafter(math.pi / 2, math.inf)


def tick_distance(law: StationKeeping | Loiter, safe: SafeSet, omega_xy: float, tick: float) -> float:
    """A float <= c − β − h (u_b + ω̄_xy) (m): the least distance to the anchor during a tick that ends on V = c
    (u_b the law's largest surge)."""
    return lower(arb(safe.level) - arb(safe.shape) - arb(tick) * (arb(law.surge) + arb(omega_xy)))


def angle_step(law: StationKeeping | Loiter, omega_xy: float, tick: float, d_tick: float,
               yaw_err: float = 0.0) -> float:
    """Δ (rad), a float >= h (k + E_r + (u_b + ω̄_xy) / d_tick): how far χ moves within one tick."""
    return upper(arb(tick) * (arb(law.yaw_rate) + arb(yaw_err) + (arb(law.surge) + arb(omega_xy)) / arb(d_tick)))


def _rate_upper(law: StationKeeping, safe: SafeSet, omega_xy: float, delta: float, a: float, b: float,
                yaw_err: float = 0.0) -> float:
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
            + g_prime * (r_up + arb(yaw_err) + ub * held_cos * x.sin() / d))
    return upper(rate)


def rate_sampled(law: StationKeeping, safe: SafeSet, omega_xy: float, n: int = 721, yaw_err: float = 0.0) -> float:
    """The largest V̇ (m/s) at sampled χ with the input of the same instant (no hold) and the worst ω."""
    if law.yaw_law == "continuous":
        return continuous_rate_sampled(law, safe, omega_xy, 2 * n - 1, yaw_err)
    return float(rates_sampled(law, safe.level, np.array([float(safe.shape)]), omega_xy, n, yaw_err)[0])


def held_rate_sampled(law: StationKeeping, safe: SafeSet, omega_xy: float, tick: float, n: int = 721,
                      yaw_err: float = 0.0) -> float:
    """The largest V̇ (m/s) at sampled χ (where d > 0) with the input held from χ' at either end of the tick's drift
    Δ (:func:`angle_step`) and the worst ω; ``inf`` when c − β − h (u_b + ω̄_xy) <= 0 (no Δ: the bisection's own
    verdict). Each is a value the bisection's bound of every interval holding χ encloses (:func:`_rate_upper`: χ'
    within its held angles, the yaw term at its lowest held angle), so a positive one means
    :func:`planar_rate_bound` is not negative: the search refutes ``backup_level_set`` without the bisection."""
    d_tick = tick_distance(law, safe, omega_xy, tick)
    if not d_tick > 0.0:
        return math.inf
    delta = angle_step(law, omega_xy, tick, d_tick, yaw_err)
    if law.yaw_law == "continuous":
        return continuous_held_rate_sampled(law, safe, omega_xy, delta, 2 * n - 1, yaw_err)
    chi = np.linspace(0.0, math.pi / 2, n)
    gp = safe.shape * np.sin(chi)
    d = safe.level - safe.shape * (1 - np.cos(chi))
    inside = d > 0.0
    chi, gp, d = chi[inside], gp[inside], d[inside]
    turn = -law.yaw_rate * np.clip((chi - delta) / law.yaw_band, -1.0, 1.0)
    base = omega_xy * np.sqrt(1 + (gp / d) ** 2) + gp * (turn + yaw_err)
    best = -math.inf
    for held in (np.maximum(chi - delta, -math.pi / 2), np.minimum(chi + delta, math.pi / 2)):
        surge = law.surge * np.cos(held)
        best = max(best, float((base - surge * np.cos(chi) + gp * surge * np.sin(chi) / d).max(initial=-math.inf)))
    return best


def rates_sampled(law: StationKeeping, level: float, shapes: np.ndarray, omega_xy: float, n: int = 721,
                  yaw_err: float = 0.0) -> np.ndarray:
    """:func:`rate_sampled` (m/s) of the switched law on the level ``level`` (m) for each shape β of ``shapes`` (m) at
    once: the same samples, the same float operations per element (a row per shape)."""
    chi = np.linspace(0.0, math.pi / 2, n)
    beta = np.asarray(shapes, dtype=float)[:, None]
    gp = beta * np.sin(chi)
    d = level - beta * (1 - np.cos(chi))
    r = -law.yaw_rate * np.clip(chi / law.yaw_band, -1.0, 1.0)
    u = law.surge * np.cos(chi)
    rate = -u * np.cos(chi) + omega_xy * np.sqrt(1 + (gp / d) ** 2) + gp * (r + yaw_err + u * np.sin(chi) / d)
    return rate.max(axis=1)


def planar_rate_bound(law: StationKeeping, safe: SafeSet, omega_xy: float, tick: float,
                      max_boxes: int = BACKUP_MAX_BOXES, yaw_rate_error: float = 0.0) -> tuple[float, int]:
    """(bound, intervals): a certified upper bound (m/s) of V̇ on the level set V = c, by bisection in χ.

    Bisection stops on an interval once its bound is negative; the bound returned is the largest
    over the final cover of [0, π/2] (``inf`` when c − β cannot absorb a tick's motion). The yaw
    rate error E_r (rad/s) widens χ̇ (the law's fades and ramp are 1 on the level set: ``backup_fade``).
    """
    d_tick = tick_distance(law, safe, omega_xy, tick)
    if not d_tick > 0.0:
        return math.inf, 0
    delta = angle_step(law, omega_xy, tick, d_tick, yaw_rate_error)
    if law.yaw_law == "continuous":
        return continuous_rate_bound(law, safe, omega_xy, delta, max_boxes, yaw_rate_error)
    return bisect_sup(lambda a, b: _rate_upper(law, safe, omega_xy, delta, a, b, yaw_rate_error),
                      0.0, _HALF_PI_UP, max_boxes)


def _ramp_speeds(law: StationKeeping, limits: tuple[float, float, float]) -> tuple[float, float]:
    """(U, W) (m/s): the largest surge and heave commands during the ramp, max(u_b, ū) and max(w_b, w̄): the ramp
    blends the command applied at the hand-over (in V) into the law (module doc)."""
    return max(law.surge, float(limits[0])), max(law.heave, float(limits[1]))


def _reach_time(law: StationKeeping, safe: SafeSet, omega_xy: float, omega_z: float,
                handover: tuple[float, float], limits: tuple[float, float, float]) -> float:
    """A float <= min((c − β − h_xy)/(U + ω̄_xy), (Z − h_z)/(W + ω̄_z)) (s), (U, W) of :func:`_ramp_speeds`: no
    exit of S before it."""
    surge, heave = _ramp_speeds(law, limits)
    planar = (arb(safe.level) - arb(safe.shape) - arb(handover[0])) / (arb(surge) + arb(omega_xy))
    depth = (arb(safe.depth) - arb(handover[1])) / (arb(heave) + arb(omega_z))
    return min(lower(planar), lower(depth))


def ramp_window(law: StationKeeping, safe: SafeSet, *, omega_xy: float, omega_z: float, tick: float,
                handover: tuple[float, float], limits: tuple[float, float, float]) -> float:
    """A float t (s) with t + h <= min((c − β − h_xy)/(U + ω̄_xy), (Z − h_z)/(W + ω̄_z)), (U, W) = (max(u_b, ū),
    max(w_b, w̄)), within a relative 1e-9 of the largest: the longest ramp t_r that ``backup_ramp`` admits (negative
    when none does)."""
    t = lower(arb(_reach_time(law, safe, omega_xy, omega_z, handover, limits)) - arb(tick))
    return t * (1 - 1e-9) if t > 0 else t


def _smooth_conditions(law: StationKeeping, safe: SafeSet, dist: tuple[float, float], tick: float,
                       handover: tuple[float, float], d_tick: float,
                       limits: tuple[float, float, float]) -> tuple[Condition, ...]:
    """``backup_fade`` (when a fade is on) and ``backup_ramp`` (when the ramp is on), with both numbers."""
    out = []
    if law.surge_fade > 0.0 or law.yaw_fade > 0.0:
        fade = max(law.surge_fade, law.yaw_fade)
        out.append(Condition("backup_fade", "d_0, d_1 <= d_tick = c − β − h (u_b + ω̄_xy)", fade, d_tick,
                             fade <= d_tick, "the law is unfaded at every tick start near V = c"))
    if law.ramp > 0.0:
        need = upper(arb(law.ramp) + arb(tick))
        window = _reach_time(law, safe, dist[0], dist[1], handover, limits)
        out.append(Condition("backup_ramp", "t_r + h <= (c − β − h_xy)/(max(u_b, u_max) + ω̄_xy) and t_r + h <= "
                             "(Z − h_z)/(max(w_b, w_max) + ω̄_z)", need, window, need <= window,
                             "the ramp (which blends the hand-over's command into the law) ends before V = c or "
                             "|z − z*| = Z can be reached"))
    return tuple(out)


def ridge_rate(surge: float, omega_xy: float, delta: float, d_tick: float, yaw_err: float) -> float:
    """A float >= (u min(1, 2Δ) + ω̄_xy)/d_tick + E_r (rad/s): how fast the line of sight can turn the heading
    toward the ridge within 2Δ of it (``inf`` when d_tick <= 0); the law must turn faster (``backup_ridge``)."""
    if not d_tick > 0:
        return math.inf
    return upper((arb(surge) * arb(min(1.0, 2 * delta)) + arb(omega_xy)) / arb(d_tick) + arb(yaw_err))


def hold_conditions(law: StationKeeping | Loiter, safe: SafeSet, omega_z: float, tick: float,
                    handover: tuple[float, float]) -> tuple[Condition, ...]:
    """The depth hold and the hand-over, the same for every law with a saturated heave w = −w_b sat((z − z*)/z_0)
    and a safe set {d + β a <= c, |z − z*| <= Z}, a <= 1: ``backup_heave``, ``backup_depth_hold``,
    ``backup_handover`` (d <= c − β: in S whatever the heading), ``backup_handover_depth``."""
    hold_z = upper(arb(law.heave_band) + arb(tick) * (arb(law.heave) + arb(omega_z)))
    return (
        Condition("backup_heave", "ω̄_z < w_b", omega_z, law.heave, omega_z < law.heave),
        Condition("backup_depth_hold", "z_0 + h (w_b + ω̄_z) <= Z", hold_z, safe.depth, hold_z <= safe.depth),
        Condition("backup_handover", "hand-over distance <= c − β", handover[0], safe.handover_radius,
                  handover[0] <= safe.handover_radius),
        Condition("backup_handover_depth", "hand-over depth error <= Z", handover[1], safe.depth,
                  handover[1] <= safe.depth))


def _conditions(law: StationKeeping, safe: SafeSet, dist: tuple[float, float], limits: tuple[float, float, float],
                tick: float, handover: tuple[float, float], rate: float, yaw_err: float) -> tuple[Condition, ...]:
    """Every inequality of the theorem, with both numbers."""
    wxy, wz = dist
    d_tick = tick_distance(law, safe, wxy, tick)
    delta = angle_step(law, wxy, tick, d_tick, yaw_err) if d_tick > 0 else math.inf
    ridge = ridge_rate(law.surge, wxy, delta, d_tick, yaw_err)
    ridge_text = "(u_b sin 2Δ + ω̄_xy) / d_tick" + (" + E_r" if yaw_err > 0 else "") + " < k and χ_0 <= π/2 − 2Δ"
    cond = Condition
    return (
        cond("backup_inputs", "u_b <= u_max, w_b <= w_max, k <= r_max", max(law.surge / limits[0],
             law.heave / limits[1], law.yaw_rate / limits[2]), 1.0, law.within(*limits), "largest ratio"),
        cond("backup_tick", "c − β − h (u_b + ω̄_xy) > 0", d_tick, 0.0, d_tick > 0.0),
        unstable_condition(law, wxy) if law.yaw_law == "continuous" else
        cond("backup_ridge", ridge_text, ridge, law.yaw_rate,
             ridge < law.yaw_rate and law.yaw_band <= math.pi / 2 - 2 * delta),
        cond("backup_level_set", "sup V̇ on V = c < 0", rate, 0.0, rate < 0.0),
    ) + hold_conditions(law, safe, wz, tick, handover) + _smooth_conditions(law, safe, dist, tick, handover, d_tick, limits)


def checked_bounds(omega_xy: float, omega_z: float, tick: float, yaw_rate_error: float,
                   handover: tuple[float, float]) -> tuple[float, float, float, float, tuple[float, float]]:
    """(ω̄_xy, ω̄_z, h, E_r, hand-over) as floats, each checked (ConfigError naming it): the numbers every backup
    proof holds against."""
    return (nonnegative("omega_xy", omega_xy), nonnegative("omega_z", omega_z), positive("tick", tick),
            nonnegative("yaw_rate_error", yaw_rate_error),
            (nonnegative("handover[0]", handover[0]), nonnegative("handover[1]", handover[1])))


def certify_backup(law: StationKeeping, safe: SafeSet, *, omega_xy: float, omega_z: float,
                   limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                   max_boxes: int = BACKUP_MAX_BOXES, yaw_rate_error: float = 0.0) -> BackupCertificate:
    """Prove (or refute, naming the failed inequalities) that ``safe`` is invariant under ``law``.

    Parameters
    ----------
    law, safe : StationKeeping, SafeSet
        The backup law and its candidate safe set.
    omega_xy, omega_z : float
        Certified disturbance bounds (m/s), current and sway together (and the loop's E_u, E_w).
    limits : (float, float, float)
        V: u_max, w_max (m/s), r_max (rad/s).
    tick : float
        Hold of the law (s): 1 / ancillary rate.
    handover : (float, float)
        Largest horizontal distance and depth error (m) from the anchor when the backup takes over.
    yaw_rate_error : float
        E_r (rad/s): ψ̇ = r + ε_r with |ε_r| <= E_r (the velocity loop's yaw error; 0 = exact).
    """
    if not isinstance(law, StationKeeping) or not isinstance(safe, SafeSet):
        raise ConfigError("backup", "a StationKeeping law and a SafeSet", (type(law).__name__, type(safe).__name__))
    wxy, wz, h, e_r, handover = checked_bounds(omega_xy, omega_z, tick, yaw_rate_error, handover)
    rate, boxes = planar_rate_bound(law, safe, wxy, h, max_boxes, e_r)
    conditions = _conditions(law, safe, (wxy, wz), tuple(float(x) for x in limits), h, handover, rate, e_r)
    return BackupCertificate(law=law, safe_set=safe, omega_xy=wxy, omega_z=wz, tick=h, rate_bound=rate,
                             rate_sampled=rate_sampled(law, safe, wxy, yaw_err=e_r), boxes=boxes,
                             conditions=conditions, handover=handover, yaw_rate_error=e_r)
