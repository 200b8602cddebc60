"""The backup law: station keeping about an anchor point, surging forward or astern.

When no plan can be followed, the vehicle holds its position about an anchor p* (the end of the
last accepted plan). With d the horizontal distance to p*, θ = atan2(y − y*, x − x*) the bearing of
the vehicle from p* and φ = ψ − θ − π the angle between the heading and the line of sight to p*
(φ = 0: pointing at p*), the law is

* surge u = u_b cos φ — ahead when facing p*, astern when facing away, zero when abeam;
* yaw r = −k sat(χ / χ_0), χ = φ wrapped to (−π/2, π/2]: the hull's axis is turned onto the
  line of sight, whichever end points at p*;
* heave w = −w_b sat((z − z*) / z_0).

Every input stays in V when u_b <= ū, w_b <= w̄ and k <= r̄, so the law never saturates.
:func:`verify.backup.certify_backup` proves that the set
S = {d + β(1 − cos χ) <= c, |z − z*| <= Z} is invariant under the law held at the ancillary rate
for every current within the certified bound; this module only evaluates the law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.validation import nonnegative, positive

__all__ = ["StationKeeping", "SafeSet", "BackupPlan", "line_of_sight_angle", "axis_angle", "station_keeping_input"]


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


@dataclass(frozen=True)
class StationKeeping:
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
    """

    surge: float
    yaw_rate: float
    yaw_band: float
    heave: float
    heave_band: float

    def __post_init__(self) -> None:
        for name in ("surge", "yaw_rate", "yaw_band", "heave", "heave_band"):
            object.__setattr__(self, name, positive(f"backup.{name}", getattr(self, name)))
        if self.yaw_band > math.pi / 2:
            raise ConfigError("backup.yaw_band", "an angle in (0, pi/2] rad", self.yaw_band)

    def within(self, u_max: float, w_max: float, r_max: float) -> bool:
        """True when every input of the law lies in V = {|u| <= u_max, |w| <= w_max, |r| <= r_max}."""
        return self.surge <= u_max and self.heave <= w_max and self.yaw_rate <= r_max

    def __call__(self, state: np.ndarray, anchor: np.ndarray) -> np.ndarray:
        """v = (u, w, r) (m/s, m/s, rad/s) at ``state`` [x, y, z, ψ] about ``anchor`` [x*, y*, z*] (m)."""
        return np.array(station_keeping_input(self, tuple(map(float, state)), tuple(map(float, anchor))))


def station_keeping_input(law: StationKeeping, state: tuple[float, float, float, float],
                          anchor: tuple[float, float, float]) -> tuple[float, float, float]:
    """The law on float tuples (the closed loop's inner loop): (u, w, r) in m/s, m/s, rad/s."""
    x, y, z, psi = state
    phi = line_of_sight_angle(x, y, psi, anchor[0], anchor[1])
    chi = axis_angle(phi)
    u = law.surge * math.cos(phi)
    r = -law.yaw_rate * _sat(chi / law.yaw_band)
    w = -law.heave * _sat((z - anchor[2]) / law.heave_band)
    return u, w, r


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
    law : StationKeeping
        The station-keeping law.
    safe_set : SafeSet
        Its invariant set about the anchor (the end of the last accepted plan).
    handover : (float, float)
        Largest horizontal distance and depth error (m) from the anchor when the backup takes over
        (the replayed plan's last position and depth margins).
    """

    law: StationKeeping
    safe_set: SafeSet
    handover: tuple[float, float] = (0.0, 0.0)

    def footprint(self, vehicle_radius: float) -> tuple[float, float]:
        """(horizontal radius, half height) (m) of the safe set inflated by the vehicle ball."""
        return self.safe_set.radius + vehicle_radius, self.safe_set.depth + vehicle_radius

