"""The hold backup: station keeping with lateral thrust, the position pulled straight back to the anchor.

A vehicle whose thrusters give a lateral force (the BlueROV2 Heavy; ``VehicleParams.lateral``) need not turn to
move sideways: it can hold station the way ROV pilots do, commanding a velocity in the horizontal plane toward the
anchor p* through surge *and* sway. With Δ = p_xy − p*_xy the horizontal offset, ψ the heading and
e_z = z − z*, the law is

* q = −k Δ, scaled down to |q| = s where k |Δ| > s (the world-frame velocity asked for, at most s);
* (u, v) = R(ψ)ᵀ q: surge and sway commands, the body-frame components of q;
* r = r_t sat(v / v_t): the nose turns toward q, so that the sway command decays (a plan can take over only once
  the last sway command is within ``release`` of 0, :func:`tubekit.loop.plan_check.check_sway`);
* w = −w_b sat(e_z / z_0).

From the hand-over the command applied then, v_h = (u_h, w_h, r_h) (sway 0: plans never command it), is blended
into the law over the ramp t_r: with σ = min(1, s_e / t_r), s_e the time since the hand-over,
(u, w, r) = (1 − σ) v_h + σ (u, w, r)_law and the sway σ v_law. The command is continuous at the hand-over, lies in
V when s <= ū, w_b <= w̄ and r_t <= r̄, and is Lipschitz along every trajectory (no ridge, no switch).

``verify.backup.hold`` proves the disc {|Δ| <= c, |e_z| <= Z} invariant: along the plant
ṗ_xy = R(ψ)(u + ε_u, v + ε_v) + current = q + (rotation of the held q) + η with ‖η‖ <= ω̄_xy, so one tick of
the held command contracts |Δ| by k h (up to the heading's turn) and the disturbance adds at most ω̄_xy h. The
law needs no heading: its safe set is a disc, of radius about ω̄_xy / k, not the surge-only hull's loop.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.backup import register_backup_law
from tubekit.validation import nonnegative, positive

__all__ = ["Hold", "hold_input"]


def _sat(x: float) -> float:
    return -1.0 if x < -1.0 else 1.0 if x > 1.0 else x


@register_backup_law
@dataclass(frozen=True)
class Hold:
    """Gains of the hold law (module doc).

    Attributes
    ----------
    gain : float
        k (1/s), the position gain: the velocity asked for is −k Δ.
    speed : float
        s (m/s), the largest horizontal speed asked for (|q| <= s).
    heave : float
        w_b, the largest heave speed (m/s).
    heave_band : float
        z_0, the depth error (m) below which the heave speed is proportional.
    ramp : float
        t_r (s), > 0: the command applied at the hand-over is blended into the law over t_r.
    turn : float
        r_t (rad/s), the largest yaw rate of the turn toward q (0: the heading is left as it is).
    turn_band : float
        v_t (m/s), > 0: the sway command below which the yaw rate is proportional, r = r_t v / v_t.
    release : float
        (m/s), > 0: a plan may take over from the law only once its sway command is within ``release`` of 0 (the
        sway command then jumps to 0, a jump the velocity loop's bound is charged).
    """

    kind: ClassVar[str] = "hold"
    #: The law commands sway (a vehicle with lateral thrust only).
    lateral: ClassVar[bool] = True

    gain: float
    speed: float
    heave: float
    heave_band: float
    ramp: float
    turn: float = 0.0
    turn_band: float = 0.05
    release: float = 0.01

    def __post_init__(self) -> None:
        for name in ("gain", "speed", "heave", "heave_band", "ramp", "turn_band", "release"):
            object.__setattr__(self, name, positive(f"backup.{name}", getattr(self, name)))
        object.__setattr__(self, "turn", nonnegative("backup.turn", self.turn))

    @property
    def blends(self) -> bool:
        """True: the command applied at the hand-over fades out over t_r."""
        return True

    @property
    def bounds(self) -> tuple[float, float, float]:
        """(s, w_b, r_t): the largest |u|, |w|, |r| the law commands after its ramp (m/s, m/s, rad/s)."""
        return self.speed, self.heave, self.turn

    @property
    def sway_bound(self) -> float:
        """s (m/s): the largest |v| the law commands."""
        return self.speed

    @property
    def sway_release(self) -> float:
        """The largest |v| (m/s) at which a plan may take over (``release``)."""
        return self.release

    @property
    def min_surge(self) -> float:
        """−s (m/s): the law surges astern as well as ahead."""
        return -self.speed

    @property
    def handover_command(self) -> tuple[float, float, float]:
        """(0, 0, 0) (not read: the law blends from the command applied at the hand-over)."""
        return 0.0, 0.0, 0.0

    def within(self, u_max: float, w_max: float, r_max: float) -> bool:
        """True when every input of the law lies in V = {|u| <= u_max, |w| <= w_max, |r| <= r_max}."""
        return all(b <= m for b, m in zip(self.bounds, (u_max, w_max, r_max)))

    def command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
                ) -> tuple[float, float, float]:
        """(u, w, r) of :func:`hold_input` (the sway command is :meth:`lateral_command`'s fourth entry)."""
        u, w, r, _ = hold_input(self, state, anchor, elapsed, start)
        return u, w, r

    def lateral_command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                        elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
                        ) -> tuple[float, float, float, float]:
        """(u, w, r, v) of :func:`hold_input` (m/s, m/s, rad/s, m/s)."""
        return hold_input(self, state, anchor, elapsed, start)

    def to_dict(self) -> dict[str, Any]:
        """The gains with ``kind``."""
        return {"kind": self.kind, **asdict(self)}

    def __call__(self, state: np.ndarray, anchor: np.ndarray, elapsed: float = math.inf,
                 start: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
        """(u, w, r, v) (m/s, m/s, rad/s, m/s) at ``state`` [x, y, z, ψ] about ``anchor`` [x*, y*, z*] (m)."""
        return np.array(hold_input(self, tuple(map(float, state)), tuple(map(float, anchor)), elapsed,
                                   tuple(map(float, start))))


def hold_input(law: Hold, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
               elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
               ) -> tuple[float, float, float, float]:
    """The law on float tuples (the closed loop's inner loop): (u, w, r, v) in m/s, m/s, rad/s, m/s.

    ``elapsed`` is the time (s) since the backup took over (the default, ∞, is the law after its ramp); ``start``
    the command (u, w, r) applied at the hand-over, blended out over t_r. Each channel is clamped to
    ±max(its law bound, |start_c|), which only removes rounding (the blend is a convex combination).
    """
    x, y, z, psi = state
    if not (elapsed >= 0.0):
        raise ConfigError("elapsed", "a time >= 0 since the hand-over (s)", elapsed)
    qx, qy = -law.gain * (x - anchor[0]), -law.gain * (y - anchor[1])
    norm = math.hypot(qx, qy)
    if norm > law.speed:
        qx, qy = qx * (law.speed / norm), qy * (law.speed / norm)
    c, s = math.cos(psi), math.sin(psi)
    u_law, v_law = c * qx + s * qy, -s * qx + c * qy
    w_law = -law.heave * _sat((z - anchor[2]) / law.heave_band)
    law_cmd = (u_law, w_law, law.turn * _sat(v_law / law.turn_band))
    sigma = 1.0 if elapsed >= law.ramp else elapsed / law.ramp
    if sigma >= 1.0:
        return law_cmd[0], law_cmd[1], law_cmd[2], v_law
    out = []
    for value, blend, bound in zip(law_cmd, start, law.bounds):
        top = max(bound, abs(blend))
        out.append(min(max(sigma * value + (1.0 - sigma) * blend, -top), top))
    return out[0], out[1], out[2], sigma * v_law
