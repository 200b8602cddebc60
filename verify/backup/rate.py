"""The backup law's command rate, in Arb: how fast its command can change along the plant.

The faded, ramped law (:class:`tubekit.model.backup.StationKeeping`, issue 22) with s the time since
the hand-over, d the distance to the anchor, φ the line-of-sight angle and χ the axis angle:

    u = u_b F cos φ,   F = min(1, d/d_0, s/t_r);    r = −k sat(χ/χ_0) G,   G = min(1, d/d_1, s/t_r);
    w = −w_b sat((z − z*)/z_0) R,   R = min(1, s/t_r),

plus the blend (1 − R) v_h of the command v_h ∈ V applied at the hand-over, whose rate is at most
|v_h| |Ṙ| <= V_c / t_r per channel: every bound below has V_c / t_r added (the blend term).

Along the plant during the backup (every quantity below is a bound that holds for almost every t):

* horizontal speed |ṗ_xy| <= S = min(u_b, ū) + ω̄_xy (ω̄_xy already holds the loop's E_u and the sway γ̄),
  so |ḋ| <= S and the bearing θ of the vehicle from the anchor turns at |θ̇| <= S/d;
* vertical speed |ż| <= S_z = min(w_b, w̄) + ω̄_z (ω̄_z holds E_w); yaw rate |ψ̇| <= Y = min(k, r̄) + E_r;
  with a ramp the blended command is anywhere in V, so S, S_z and Y use max(u_b, ū), max(w_b, w̄), max(k, r̄);
* φ = ψ − θ − π, so |φ̇| <= Y + S/d, and χ̇ = φ̇ away from the ridge χ = ±π/2;
* a minimum of Lipschitz functions is differentiable almost everywhere with the derivative of an
  active term: |Ḟ| <= max(S/d_0, 1/t_r), |Ġ| <= max(S/d_1, 1/t_r), |Ṙ| <= 1/t_r.

**Surge.** d/dt (F cos φ) = Ḟ cos φ − F sin φ φ̇, and F |φ̇| <= F Y + F S/d <= Y + S/d_0 because
F <= 1 and F <= d/d_0 (the fade cancels the 1/d of the line of sight). So

    |u̇| <= u_b (max(S/d_0, 1/t_r) + Y + S/d_0).

**Heave.** d/dt (sat(ζ) R) = sat'(ζ) ζ̇ R + sat(ζ) Ṙ with |ζ̇| <= S_z/z_0, R <= 1, |sat| <= 1:

    |ẇ| <= w_b (S_z/z_0 + 1/t_r).

**Yaw, between ridge crossings.** d/dt (sat(χ/χ_0) G) = sat'·χ̇ G/χ_0 + sat·Ġ with |sat'| <= 1 and
G |χ̇| <= G Y + G S/d <= Y + S/d_1:

    |ṙ| <= k (max(S/d_1, 1/t_r) + (Y + S/d_1)/χ_0).

**Ridge.** When the hull is abeam (χ = ±π/2) the axis angle wraps and sat(χ/χ_0) flips sign: the yaw
command jumps by 2kG. Inside S the ridge can be crossed (near the anchor the line of sight turns at
up to ω̄_xy/d, faster than any bounded yaw rate; during the ramp G is small anywhere), so the yaw
command is not Lipschitz in time: :func:`backup_tick_change` bounds the change of the held command
over one tick, 2 min(k, r̄) for yaw. (A sharper bound, 2 max_d min(kG, E_r + LOS rate), is still of
order 2 √(k ω̄_xy / d_1): no design of this law makes it small.)

**Continuous yaw law** (``yaw_law="continuous"``): r = −k ρ(φ) G with ρ π-periodic and Lipschitz 1/χ_0 on
the whole circle (:func:`tubekit.model.backup.yaw_shape`), |ρ| <= 1: there is no ridge, χ̇ = φ̇ everywhere and
the yaw bound above holds for all time, d/dt (ρ G) = ρ' φ̇ G + ρ Ġ. :func:`backup_tick_change` is then
rate × h for all three channels.

Without a ramp the command jumps at the hand-over, and without a fade the line of sight's 1/d is not
cancelled: the corresponding rate is ``inf``.
"""

from __future__ import annotations

import math

from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.validation import nonnegative, positive
from verify.kernel.intervals import upper

__all__ = ["backup_command_rate", "backup_tick_change"]


def _inputs(law: StationKeeping, safe: SafeSet, omega_xy: float, omega_z: float, limits, loop_error):
    """Validated (S, S_z, Y) as arb: horizontal and vertical speed bounds (m/s), yaw-rate bound (rad/s)."""
    if not isinstance(law, StationKeeping) or not isinstance(safe, SafeSet):
        raise ConfigError("backup", "a StationKeeping law and a SafeSet", (type(law).__name__, type(safe).__name__))
    wxy, wz = nonnegative("omega_xy", omega_xy), nonnegative("omega_z", omega_z)
    if len(tuple(limits)) != 3 or len(tuple(loop_error)) != 3:
        raise ConfigError("limits/loop_error", "three numbers each", (limits, loop_error))
    lim = [positive(f"limits[{i}]", x) for i, x in enumerate(limits)]
    err = [nonnegative(f"loop_error[{i}]", x) for i, x in enumerate(loop_error)]
    # with a ramp the command blends the hand-over's (anywhere in V) into the law: the limits bound it
    pick = max if law.blends else min
    speed = arb(pick(law.surge, lim[0])) + arb(wxy)
    speed_z = arb(pick(law.heave, lim[1])) + arb(wz)
    yaw = arb(pick(law.yaw_rate, lim[2])) + arb(err[2])
    return speed, speed_z, yaw


def backup_command_rate(law: StationKeeping, safe: SafeSet, *, omega_xy: float, omega_z: float,
                        limits: tuple[float, float, float],
                        loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
    """Upper bounds on |u̇| (m/s²), |ẇ| (m/s²), |ṙ| (rad/s²) of the backup's command along the plant.

    Derivation in the module doc. With the ridge law the yaw bound holds between crossings of the ridge
    χ = ±π/2, where the yaw command jumps (:func:`backup_tick_change` counts the jump); with the
    continuous law (``yaw_law="continuous"``) it holds everywhere.

    Parameters
    ----------
    law, safe : StationKeeping, SafeSet
        The backup law and the safe set the trajectory stays in (the bound holds anywhere).
    omega_xy, omega_z : float
        ω̄_xy, ω̄_z (m/s): current, sway and the loop's E_u, E_w together.
    limits : (float, float, float)
        V = (ū, w̄, r̄) (m/s, m/s, rad/s): the applied command is clipped to it.
    loop_error : (float, float, float)
        (E_u, E_w, E_r): the loop's errors; E_u, E_w are already inside ω̄, E_r widens the yaw rate.

    Returns
    -------
    (float, float, float)
        Each channel's bound; ``inf`` for surge without d_0 or t_r, yaw without d_1 or t_r, heave without t_r.
    """
    speed, speed_z, yaw = _inputs(law, safe, omega_xy, omega_z, limits, loop_error)
    if not law.blends:  # no ramp: the command jumps at the hand-over
        return math.inf, math.inf, math.inf
    ramp = arb(law.ramp)
    blend = [arb(float(v)) / ramp for v in limits]  # the hand-over's command fading out: |v_h| / t_r
    heave = upper(arb(law.heave) * (speed_z / arb(law.heave_band) + 1 / ramp) + blend[1])
    surge = yaw_rate = math.inf
    if law.surge_fade > 0.0:
        line = speed / arb(law.surge_fade)
        surge = upper(arb(law.surge) * (_max(line, 1 / ramp) + yaw + line) + blend[0])
    if law.yaw_fade > 0.0:
        line = speed / arb(law.yaw_fade)
        yaw_rate = upper(arb(law.yaw_rate) * (_max(line, 1 / ramp) + (yaw + line) / arb(law.yaw_band)) + blend[2])
    return surge, heave, yaw_rate


def _max(a: arb, b: arb) -> arb:
    """An arb containing max(a, b)."""
    return arb(max(upper(a), upper(b)))


def backup_tick_change(law: StationKeeping, safe: SafeSet, *, omega_xy: float, omega_z: float,
                       limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                       tick: float) -> tuple[float, float, float]:
    """Bounds (m/s, m/s, rad/s) on the change of the held command from one tick to the next during the backup.

    Surge and heave: rate × h (:func:`backup_command_rate`); with a ramp the first tick's command is the one
    applied at the hand-over (the blend), so the hand-over itself does not jump. Yaw: with the continuous law
    also rate × h; with the ridge law 2 min(k, r̄), because the ridge can be crossed inside S and the command
    then flips sign (module doc). Every channel is capped by 2 V_c (the command stays in V).
    """
    h = positive("tick", tick)
    rates = backup_command_rate(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                loop_error=loop_error)
    surge, heave, yaw = (upper(arb(r) * arb(h)) if math.isfinite(r) else math.inf for r in rates)
    cap = tuple(2.0 * float(v) for v in limits)
    if law.yaw_law != "continuous":
        yaw = cap[2]
    return min(surge, cap[0]), min(heave, cap[1]), min(yaw, cap[2])
