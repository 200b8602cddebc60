"""What the closed loop needs from a plant: :class:`PlantModel`.

A plant integrates the simulated vehicle over one ancillary tick with the applied command held,
reports the current it applies and, afterwards, the total disturbance ω = ẋ − f(x) v it saw. A plant
whose ω holds more than the certificate assumes (the dynamic vehicle: current + hull sway + loop
error) also reports the water current apart (:meth:`PlantModel.current_series`,
:meth:`PlantModel.current_peak`); the kinematic plant returns None there, its ω (current + the sway
model) being what the certificate assumes. The kinematic plant of eq. (11) and the 4-DOF dynamic
vehicle both satisfy it; the loop never asks which one it has.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Protocol, Sequence

import numpy as np


__all__ = ["PlantModel", "OmegaOverride", "PiecewiseOmega"]

#: ``override(t) -> omega`` (3,), m/s: a disturbance replacing the scenario's current + sway.
OmegaOverride = Callable[[float], Any]


@dataclass(frozen=True)
class PiecewiseOmega:
    """An override constant over each period: ω(t) = ``table[k]`` (m/s), k = min(int(t / period + 1e-9), K − 1)
    (a time a rounding below k·period counts as k·period; the last entry holds after the table).

    The falsifiers' adversarial sequences (one ω per FHOCP period); the kinematic plant integrates it in its
    compiled RK4 (any other callable override takes the Python path).
    """

    table: tuple[tuple[float, float, float], ...]
    period: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.period) and self.period > 0.0):
            raise ValueError(f"PiecewiseOmega.period: a finite number > 0 (s), received {self.period!r}")
        if not self.table or any(len(row) != 3 for row in self.table):
            raise ValueError("PiecewiseOmega.table: one or more (omega_x, omega_y, omega_z) rows (m/s)")

    def __call__(self, t: float) -> tuple[float, float, float]:
        return self.table[min(int(t / self.period + 1e-9), len(self.table) - 1)]


class PlantModel(Protocol):
    """The simulated vehicle as the closed loop drives it (state [x, y, z, ψ] in m and rad)."""

    def step_tuple(self, t: float, x: Sequence[float], v: Sequence[float], h: float,
                   n: int, sway: float = 0.0) -> tuple[float, float, float, float]:
        """``n`` RK4 steps of ``h`` (s) from ``x`` at ``t`` (s) with the command ``v`` (m/s, m/s, rad/s) and the sway
        command ``sway`` (m/s; only a vehicle with lateral thrust takes one other than 0) held."""
        ...

    def step(self, t: float, x: np.ndarray, v: np.ndarray, h: float, n: int, sway: float = 0.0) -> np.ndarray:
        """:meth:`step_tuple` on arrays."""
        ...

    def current_at(self, t: float) -> tuple[float, float, float]:
        """The current (m/s) at time ``t`` (s)."""
        ...

    def omega_series(self, t: np.ndarray, states: np.ndarray, inputs: np.ndarray,
                     sway: np.ndarray | None = None) -> np.ndarray:
        """ω = ẋ − f(x) v (K + 1, 3), m/s, at the logged ticks (``sway``: the sway commands per tick, m/s; None: 0)."""
        ...

    def omega_peak(self) -> tuple[float, float]:
        """Largest ‖ω_xy‖ and |ω_z| (m/s) over every evaluation of ω the integrator made so far."""
        ...

    def current_series(self, t: np.ndarray) -> np.ndarray | None:
        """The water current (len(t), 3), m/s, applied at the times ``t`` (s); None when ω is not split."""
        ...

    def current_peak(self) -> tuple[float, float] | None:
        """Largest ‖δ_xy‖ and |δ_z| (m/s) of the water current over every evaluation so far; None when not split."""
        ...

    def history(self) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Body velocities and thrusts at every tick (``None, None`` for a plant without a body)."""
        ...
