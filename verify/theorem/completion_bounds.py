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

__all__ = ["TerminalBounds", "CompletionArc", "completion_arc", "start_bearing", "in_cone", "slack_condition",
           "FLOAT_SLACK"]

#: Every inequality of the completion holds with this slack (m or rad), so the run's float check agrees.
FLOAT_SLACK = 1e-9


def slack_condition(name: str, text: str, lhs: arb, rhs: arb, detail: str = "") -> Condition:
    """The condition lhs + :data:`FLOAT_SLACK` <= rhs, in Arb (lhs's upper end, rhs's lower end reported)."""
    ok = bool((lhs + arb(FLOAT_SLACK)) <= rhs) and lhs.is_finite() and rhs.is_finite()
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
    bound), β (the chord's), the radial spread Δ, the radial end's bounds x_min, x_max, the lateral bound Y and the
    start's least distance d_lo − D_xy."""

    a0: arb
    beta: arb
    spread: arb
    x_min: arb
    x_max: arb
    lateral: arb
    start_min: arb


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
    """The bounds of one completion of ``law`` from the start set about X_f (``docs/verify.md`` step 17), in Arb;
    None when a premise of the formulas fails (D_xy >= d_lo, β >= π/2)."""
    dt, dxy = arb(b.dt), arb(b.dev_xy)
    d_lo, d_hi, d_star = arb(law.d_lo), arb(law.d_hi), arb(law.d_star)
    start_min = d_lo - dxy
    if not start_min > 0:
        return None
    a0 = arb(law.alpha_max) + arb(b.dev_psi) + (dxy / d_lo).asin()
    beta = a0 * (1 - arb(law.turn) / 2)
    if not (beta < arb.pi() / 2 and a0 < arb.pi()):
        return None
    spread = max(d_hi + dxy - d_star, d_star - d_lo + dxy)
    lam = arb(law.gain_d) * dt
    curve = arb(b.accel_xy) * dt * dt / 2
    lateral = dt * arb(b.speed_xy) * _lateral_share(b, law, beta) / beta.cos() + beta.tan() * lam * spread + curve
    x_min = start_min * (1 - lam) + lam * d_star - curve
    x_max = (d_hi + dxy) * (1 - lam) + lam * d_star + curve
    return CompletionArc(a0=a0, beta=beta, spread=spread, x_min=x_min, x_max=x_max, lateral=lateral,
                         start_min=start_min)
