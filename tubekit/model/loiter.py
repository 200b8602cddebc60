"""The loiter backup: circle about an anchor at a constant surge, never stopping the propeller.

A torpedo-shaped vehicle cannot hold station by stopping: its rudder and planes lose their force with
the speed. The loiter law keeps the surge at u_l > 0 and turns the heading onto the line of sight to the
anchor p*; the vehicle overshoots, turns round at the full yaw rate and comes back, so it circles about
p* at a distance set by its turning radius and the current. With d the horizontal distance to p* and
φ = ψ − θ − π wrapped to (−π, π] the angle between the heading and the line of sight to p*
(:func:`tubekit.model.backup.line_of_sight_angle`; φ = 0: pointing at p*), the law is

* surge u = u_l (constant, forward);
* yaw r = −k sat(φ / χ_0): turn toward p*, whichever way is shorter (the ridge φ = ±π: pointing away);
* heave w = −w_b sat((z − z*) / z_0), as station keeping.

Every input stays in V when u_l <= ū, w_b <= w̄ and k <= r̄, and the surge never falls below u_l.
:mod:`verify.backup.loiter` proves that S = {d + β a(φ) <= c, |z − z*| <= Z} is invariant for every current
with ‖ω_xy‖ <= ω̄_xy < u_l, with a(φ) = :func:`loiter_shape` (0 pointing at p*, 1 pointing away; C¹ but
at the ridge, where it is continuous). The safe set has the station-keeping :class:`tubekit.model.backup.SafeSet`
form: a vehicle within c − β of p* lies in S whatever its heading, and the footprint is c + r̄.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.backup import NoSway, line_of_sight_angle, register_backup_law
from tubekit.validation import positive

__all__ = ["Loiter", "loiter_input", "loiter_shape", "loiter_shape_slope"]


def _sat(x: float) -> float:
    return -1.0 if x < -1.0 else 1.0 if x > 1.0 else x


@register_backup_law
@dataclass(frozen=True)
class Loiter(NoSway):
    """Gains of the loiter law (module doc).

    Attributes
    ----------
    surge : float
        u_l, the constant surge speed (m/s), > 0.
    yaw_rate : float
        k, the largest yaw rate (rad/s).
    yaw_band : float
        χ_0, the heading angle (rad) below which the yaw rate is proportional, in (0, π/2].
    heave : float
        w_b, the largest heave speed (m/s).
    heave_band : float
        z_0, the depth error (m) below which the heave speed is proportional.
    bend : float
        φ_s (rad), in (0, π/2]: the safe set's shape a(φ) is quadratic below it and linear above
        (:func:`loiter_shape`).
    """

    kind: ClassVar[str] = "loiter"

    surge: float
    yaw_rate: float
    yaw_band: float
    heave: float
    heave_band: float
    bend: float = 0.5

    def __post_init__(self) -> None:
        for name in ("surge", "yaw_rate", "yaw_band", "heave", "heave_band", "bend"):
            object.__setattr__(self, name, positive(f"backup.{name}", getattr(self, name)))
        for name in ("yaw_band", "bend"):
            if getattr(self, name) > math.pi / 2:
                raise ConfigError(f"backup.{name}", "an angle in (0, pi/2] rad", getattr(self, name))

    @property
    def blends(self) -> bool:
        """False: the law starts at the hand-over with its own command (the surge is u_l from then on)."""
        return False

    @property
    def bounds(self) -> tuple[float, float, float]:
        """(u_l, w_b, k): the largest |u|, |w|, |r| the law commands (m/s, m/s, rad/s)."""
        return self.surge, self.heave, self.yaw_rate

    @property
    def min_surge(self) -> float:
        """u_l (m/s): the law never commands less surge."""
        return self.surge

    @property
    def handover_command(self) -> tuple[float, float, float]:
        """(u_l, 0, 0): a plan ends at the loiter's surge (within J), so the surge does not jump at the hand-over;
        the yaw and heave commands start within k and w_b of 0."""
        return self.surge, 0.0, 0.0

    def within(self, u_max: float, w_max: float, r_max: float) -> bool:
        """True when every input of the law lies in V = {|u| <= u_max, |w| <= w_max, |r| <= r_max}."""
        return self.surge <= u_max and self.heave <= w_max and self.yaw_rate <= r_max

    def command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
                ) -> tuple[float, float, float]:
        """:func:`loiter_input` of this law (``elapsed`` and ``start`` are not read: the law does not blend)."""
        return loiter_input(self, state, anchor)


    def to_dict(self) -> dict[str, Any]:
        """The gains with ``kind``."""
        return {"kind": self.kind, **asdict(self)}

    def __call__(self, state: np.ndarray, anchor: np.ndarray) -> np.ndarray:
        """v = (u, w, r) (m/s, m/s, rad/s) at ``state`` [x, y, z, ψ] about ``anchor`` [x*, y*, z*] (m)."""
        return np.array(loiter_input(self, tuple(map(float, state)), tuple(map(float, anchor))))


def loiter_input(law: Loiter, state: tuple[float, float, float, float],
                 anchor: tuple[float, float, float]) -> tuple[float, float, float]:
    """The law on float tuples (the closed loop's inner loop): (u, w, r) in m/s, m/s, rad/s."""
    x, y, z, psi = state
    phi = line_of_sight_angle(x, y, psi, anchor[0], anchor[1])
    return law.surge, -law.heave * _sat((z - anchor[2]) / law.heave_band), -law.yaw_rate * _sat(phi / law.yaw_band)


def loiter_shape(bend: float, phi: float | np.ndarray) -> float | np.ndarray:
    """a(φ) (dimensionless, in [0, 1]) at the heading angle(s) φ (rad), φ_s = ``bend``:
    φ²/(2 φ_s L) for |φ| <= φ_s, (|φ| − φ_s/2)/L above, L = π − φ_s/2 (so a(±π) = 1). A float for a float."""
    x = np.minimum(np.abs(phi), math.pi)
    length = math.pi - 0.5 * bend
    out = np.where(x <= bend, x * x / (2.0 * bend * length), (x - 0.5 * bend) / length)
    return float(out) if out.ndim == 0 else out


def loiter_shape_slope(bend: float, phi: float | np.ndarray) -> float | np.ndarray:
    """a'(φ) for φ in [0, π] (rad⁻¹): φ/(φ_s L) below φ_s, 1/L above (module doc of :func:`loiter_shape`)."""
    out = np.minimum(phi, bend) / (bend * (math.pi - 0.5 * bend))
    return float(out) if np.ndim(out) == 0 else out
