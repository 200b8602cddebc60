"""What the completion's proof reads: :class:`TerminalBounds` (``verify.theorem.terminal.terminal_bounds`` builds
it from a design) and :class:`CompletionArc`, the bounds derived for one terminal law; ``verify.theorem.terminal``
and ``verify.theorem.terminal_bearing`` read both."""

from __future__ import annotations

import math
from dataclasses import dataclass

from flint import arb

from verify.kernel.intervals import lower, upper
from verify.theorem.design import Condition

__all__ = ["TerminalBounds", "CompletionArc", "slack_condition", "FLOAT_SLACK"]

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


@dataclass(frozen=True)
class CompletionArc:
    """Derived quantities of one completion, in Arb (``verify.theorem.terminal._arc``): A_0 (the start's heading
    bound), β (the chord's), the radial spread Δ, the radial end's bounds x_min, x_max, the lateral bound Y and the
    start's least distance d_lo − D_xy."""

    a0: arb
    beta: arb
    spread: arb
    x_min: arb
    x_max: arb
    lateral: arb
    start_min: arb
