"""What the completion's proof reads: :class:`TerminalBounds` (``verify.theorem.terminal.terminal_bounds`` builds
it from a design) and :class:`CompletionArc`, the bounds derived for one terminal law; ``verify.theorem.terminal``
and ``verify.theorem.terminal_bearing`` read both."""

from __future__ import annotations

import math
from dataclasses import dataclass

from flint import arb

from tubekit.model.terminal_law import TerminalLaw

from verify.kernel.intervals import lower, upper
from verify.theorem.design import Condition

__all__ = ["TerminalBounds", "CompletionArc", "completion_arc", "feedforward_residual", "start_bearing", "in_cone",
           "slack_condition", "FLOAT_SLACK"]

#: Every inequality of the completion holds with this slack (m or rad), so the run's float check agrees.
FLOAT_SLACK = 1e-9
_SLACK = arb(FLOAT_SLACK)  # the float's exact ball


def slack_condition(name: str, text: str, lhs: arb, rhs: arb, detail: str = "") -> Condition:
    """The condition lhs + :data:`FLOAT_SLACK` <= rhs, in Arb (lhs's upper end, rhs's lower end reported)."""
    ok = bool((lhs + _SLACK) <= rhs) and lhs.is_finite() and rhs.is_finite()
    return Condition(name, text, upper(lhs) if lhs.is_finite() else math.inf,
                     lower(rhs) if rhs.is_finite() else math.inf, ok, detail)


@dataclass(frozen=True)
class TerminalBounds:
    """What the completion's proof reads (floats; m, s, rad): V̄, the target's speed and acceleration bounds,
    the replay's deviation at the shifted end, and R shrunk by the last arc's margins and the check's pad."""

    dt: float
    steps: int
    v_bar: tuple[float, float, float]
    speed_xy: float
    speed_z: float
    accel_xy: float
    accel_z: float
    dev_xy: float
    dev_z: float
    dev_psi: float
    room_d: tuple[float, float]
    room_o: float
    room_z: float
    speed_floor_xy: float = 0.0  # the target's least horizontal speed (m/s; 0: it may stop)
    surge_floor: float | None = None  # u_min + kappa_bar_u under a minimum surge (m/s), else None
    jumps: tuple[float, float, float] | None = None  # the plans' jump J per period (m/s, m/s, rad/s), else None


@dataclass(frozen=True)
class CompletionArc:
    """Derived quantities of one completion, in Arb (:func:`completion_arc`): A_0 (the start's heading
    bound), β (the chord's), the radial spread Δ, the radial end's bounds x_min, x_max, the lateral bound Y, the
    start's least distance d_lo − D_xy, the feedforward's bound Ω = sup |ω̂| (rad/s; 0 without it), the largest turn
    T_max = g A_0 + δ Ω (rad) and the heading's residual: |α' − (1 − g) α̃| <= ``residual`` (rad; the line of
    sight's turn atan(Y / x_min) without the feedforward, :func:`feedforward_residual` with it)."""

    a0: arb
    beta: arb
    spread: arb
    x_min: arb
    x_max: arb
    lateral: arb
    start_min: arb
    omega: arb
    turn_max: arb
    residual: arb


def start_bearing(b: TerminalBounds, law: TerminalLaw) -> arb:
    """Φ_0 = φ_f + asin(D_xy / d_lo) (rad): the completion's start lies within the replay's deviation of X_f, so
    its bearing is at most this (π or more without a bearing face)."""
    return arb(law.bearing_max) + (arb(b.dev_xy) / arb(law.d_lo)).asin()


def in_cone(b: TerminalBounds, law: TerminalLaw) -> bool:
    """True when X_f's bearing face bounds the completion's bearings by :func:`start_bearing` (a face, and a target
    whose horizontal speed has a positive floor, so that the bearing is defined)."""
    return law.has_bearing and b.speed_floor_xy > 0.0


def _lateral_share(b: TerminalBounds, law: TerminalLaw, beta: arb) -> arb:
    """The largest |sin φ − cos φ tan β'| cos β over the start's bearings |φ| <= Φ_0 and chord angles |β'| <= β:
    sin(Φ_0 + β) while Φ_0 + β < π/2 (``docs/verify.md`` step 17b), else 1 (Cauchy–Schwarz)."""
    if not in_cone(b, law):
        return arb(1)
    top = start_bearing(b, law) + beta
    return top.sin() if top < arb.pi() / 2 else arb(1)


def completion_arc(b: TerminalBounds, law: TerminalLaw) -> CompletionArc | None:
    """The bounds of one completion of ``law`` from the start set about X_f (``docs/verify.md`` step 17, with the
    line-of-sight feedforward step 17e), in Arb; None when a premise of the formulas fails (D_xy >= d_lo,
    β >= π/2, and with the feedforward A_0 >= π/2)."""
    dt, dxy = arb(b.dt), arb(b.dev_xy)
    d_lo, d_hi, d_star = arb(law.d_lo), arb(law.d_hi), arb(law.d_star)
    start_min = d_lo - dxy
    if not start_min > 0:
        return None
    a0 = arb(law.alpha_max) + arb(b.dev_psi) + (dxy / d_lo).asin()
    spread = max(d_hi + dxy - d_star, d_star - d_lo + dxy)
    lam = arb(law.gain_d) * dt
    closing = arb(b.speed_xy) + arb(law.gain_d) * spread  # N_max = P + λ Δ
    omega = arb(0)
    if law.los_feedforward:
        if not a0 < arb.pi() / 2:
            return None
        omega = (arb(b.speed_xy) * _across_share(b, law) + closing * a0.tan()) / start_min
    beta = a0 * (1 - arb(law.turn) / 2) + dt * omega / 2
    if not (beta < arb.pi() / 2 and a0 < arb.pi()):
        return None
    curve = arb(b.accel_xy) * dt * dt / 2
    lateral = dt * arb(b.speed_xy) * _lateral_share(b, law, beta) / beta.cos() + beta.tan() * lam * spread + curve
    x_min = start_min * (1 - lam) + lam * d_star - curve
    x_max = (d_hi + dxy) * (1 - lam) + lam * d_star + curve
    turn_max = arb(law.turn) * a0 + dt * omega
    residual = (lateral / x_min).atan() if x_min > 0 else arb("inf")
    if law.los_feedforward and x_min > 0:
        residual = feedforward_residual(b, a0, spread, lam, closing, omega, turn_max, x_min, lateral, start_min)
    return CompletionArc(a0=a0, beta=beta, spread=spread, x_min=x_min, x_max=x_max, lateral=lateral,
                         start_min=start_min, omega=omega, turn_max=turn_max, residual=residual)


def _across_share(b: TerminalBounds, law: TerminalLaw) -> arb:
    """The largest |sin φ| over the start's bearings: sin Φ_0 in the cone while Φ_0 < π/2, else 1 (P_⊥ <= P)."""
    if not in_cone(b, law):
        return arb(1)
    phi0 = start_bearing(b, law)
    return phi0.sin() if phi0 < arb.pi() / 2 else arb(1)


def feedforward_residual(b: TerminalBounds, a0: arb, spread: arb, lam: arb, closing: arb, omega: arb, turn_max: arb,
                         x_min: arb, lateral: arb, start_min: arb) -> arb:
    """E (rad): |δ ω̂ − θ| over the completion, θ = atan(q'_y / q'_x) the line of sight's turn (step 17e). With
    y_0 = δ (P_⊥ − N tan α̃) = δ d̃ ω̂, the chord's lateral δ N tan(α̃ + T/2) = δ N tan α̃ − y_1 and the target's
    curvature ρ (|ρ| <= A δ²/2): q'_y = y_0 + y_1 + ρ_y and q'_x − d̃ = −λ δ (d̃ − d*) + ρ_x, so

        |δ ω̂ − q'_y / q'_x| <= |y_0| |q'_x − d̃| / (d̃ q'_x) + (|y_1| + |ρ_y|) / q'_x,
        |y_1| <= δ N_max sec²(A_0 + δΩ/2) T_max / 2  (the mean value theorem on tan, between α̃ and α̃ + T/2),

    and |z − atan z| <= |z|³ / 3 with |z| <= Y / x_min."""
    dt = arb(b.dt)
    curve = arb(b.accel_xy) * dt * dt / 2
    y0 = dt * omega * start_min
    top = a0 + dt * omega / 2  # >= A_0 and >= β = A_0 (1 − g/2) + δΩ/2: the mean value theorem's interval
    if not top < arb.pi() / 2:
        return arb("inf")
    y1 = dt * closing * turn_max / (2 * top.cos() ** 2)
    z = lateral / x_min
    return y0 * (lam * spread + curve) / (start_min * x_min) + (y1 + curve) / x_min + z ** 3 / 3
