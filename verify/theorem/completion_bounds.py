"""What the completion's proof reads: :class:`TerminalBounds` (``verify.theorem.terminal.terminal_bounds`` builds
it from a design; ``verify.theorem.terminal`` and ``verify.theorem.terminal_bearing`` read it)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["TerminalBounds"]


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
