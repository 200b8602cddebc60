"""The terminal tracking law and its terminal set: what completes the shifted candidate at its end.

Tube MPC keeps a plan available by the *candidate* (Chisci et al. 2001): the previous plan shifted by one
period and completed at its end by a terminal law that keeps the error in a terminal set. Here the terminal
set is, with d the horizontal distance to the target, α = ψ − λ_los the heading's angle to the line of
sight λ_los = atan2(y_d − y, x_d − x) (α = 0: pointing at the target; e_o = −sin α) and e_z = z − z_d,

    X_f = {d_lo <= d <= d_hi, |α| <= α_f, |e_z| <= z_f, |φ| <= φ_f, |v_{N−1} − κ_f(x_N)| <= S},

φ the bearing: the angle between the target's horizontal velocity and the line of sight (φ = 0: the vehicle
trails the target). The bearing face is used only under a minimum surge (φ_f = π otherwise: no face); there it
keeps the target's speed along the line of sight, hence the law's surge, above the floor (``docs/verify.md``,
step 17b). The *row faces* |v_{N−1} − κ_f(x_N)| <= S = (S_u, S_w, S_r), the plan's last row against the law's own
row at the plan's end, are used only for rate-limited plans (S = 0 otherwise: no face); there they keep the
completion's row within the plans' jump J of the row before it (step 17c). The law, held over one period δ (a plan's row) from the state at time t, is

* r = T / δ with the turn T = −g α (turn the fraction g of the way onto the line of sight) or, with the
  *line-of-sight feedforward* (``los_feedforward``), T = −g α + δ ω̂, ω̂ = (P_⊥ − N tan α) / d the rate at which
  the line of sight turns at the row's start (P_⊥ = ṗ_d(t) · n the target's speed across it, n the line of sight
  turned by +90°, N tan α the vehicle's own speed across it): the heading then follows the line of sight's turn
  instead of catching it up one period late (step 17e);
* u = N / (S(T / 2) cos(α + T / 2)), N = V_r + λ (d − d*), V_r = ṗ_d(t) · (p_d − p) / d the target's
  speed away from the vehicle along the line of sight, S(x) = sin x / x: the exact unicycle arc then closes
  the radial gap by the fraction λ δ of d − d* (the target's own curvature aside); with T = −g α this is
  N / (S(g α / 2) cos(α (1 − g / 2)));
* w = ż_d(t) − λ_z e_z.

``verify.theorem.terminal`` proves, for the target's path and the certified disturbance, that the law from
any state within the replay's deviation of X_f stays in V̄ and in R (with the last arc's margins), lands in
X_f again one period later, and that its arc and the backup's footprint at its end stay clear of every
obstacle: the candidate always passes the exact check, so a plan is always available (``docs/verify.md``,
step 17). This module only evaluates the law and the set.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.kinematics import sinc
from tubekit.validation import finite, positive

__all__ = ["TerminalLaw", "line_of_sight", "bearing", "NO_BEARING", "NO_ROWS"]

#: ``bearing_max`` of a terminal set without the bearing face (rad).
NO_BEARING = math.pi
#: ``row_u``, ``row_w``, ``row_r`` of a terminal set without the row faces.
NO_ROWS = 0.0


def line_of_sight(state: np.ndarray, p_d: np.ndarray) -> tuple[float, float, float]:
    """(d (m), α (rad), e_z (m)) of the nominal ``state`` [x, y, z, ψ] against the target position ``p_d`` (3,)."""
    dx, dy = float(p_d[0] - state[0]), float(p_d[1] - state[1])
    los = math.atan2(dy, dx)
    alpha = math.atan2(math.sin(state[3] - los), math.cos(state[3] - los))
    return math.hypot(dx, dy), alpha, float(state[2] - p_d[2])


def bearing(state: np.ndarray, p_d: np.ndarray, pd_dot: np.ndarray) -> float:
    """φ (rad, in [−π, π]): the angle from the line of sight (``state`` [x, y, z, ψ] to ``p_d`` (3,)) to the
    target's horizontal velocity ``pd_dot`` (3,); nan when the target does not move horizontally."""
    if math.hypot(float(pd_dot[0]), float(pd_dot[1])) == 0.0:
        return math.nan
    los = math.atan2(float(p_d[1] - state[1]), float(p_d[0] - state[0]))
    phi = math.atan2(float(pd_dot[1]), float(pd_dot[0])) - los
    return math.atan2(math.sin(phi), math.cos(phi))


@dataclass(frozen=True)
class TerminalLaw:
    """The certified terminal set X_f and law (module doc); lengths in m, angles in rad, gains in 1/s."""

    d_lo: float
    d_hi: float
    d_star: float
    alpha_max: float
    z_max: float
    gain_d: float
    gain_z: float
    turn: float
    bearing_max: float = NO_BEARING
    row_u: float = NO_ROWS
    row_w: float = NO_ROWS
    row_r: float = NO_ROWS
    los_feedforward: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.los_feedforward, bool):
            raise ConfigError("terminal.los_feedforward", "a bool (True: the yaw row follows the line of sight's "
                              "turn)", self.los_feedforward)
        for name in _NUMBER_FIELDS:
            finite(f"terminal.{name}", getattr(self, name))
        positive("terminal.d_lo", self.d_lo)
        if not self.d_lo <= self.d_star <= self.d_hi:
            raise ConfigError("terminal.d_star", f"within [d_lo, d_hi] = [{self.d_lo}, {self.d_hi}] m", self.d_star)
        if not 0.0 < self.alpha_max < math.pi / 2:
            raise ConfigError("terminal.alpha_max", "in (0, pi/2) rad", self.alpha_max)
        positive("terminal.z_max", self.z_max)
        if not 0.0 < self.turn <= 1.0:
            raise ConfigError("terminal.turn", "in (0, 1]", self.turn)
        for name in ("gain_d", "gain_z"):
            if getattr(self, name) < 0.0:
                raise ConfigError(f"terminal.{name}", ">= 0 (1/s)", getattr(self, name))
        if not 0.0 < self.bearing_max <= NO_BEARING:
            raise ConfigError("terminal.bearing_max", "in (0, pi] rad (pi: no bearing face)", self.bearing_max)
        rows = (self.row_u, self.row_w, self.row_r)
        if any(r < 0.0 for r in rows) or (any(r == NO_ROWS for r in rows) and any(r > 0.0 for r in rows)):
            raise ConfigError("terminal.row_u", "row_u, row_w, row_r all > 0 (m/s, m/s, rad/s), or all 0 (no row "
                              "faces)", list(rows))

    @property
    def has_rows(self) -> bool:
        """True when X_f has the row faces |v_{N−1} − κ_f(x_N)| <= (S_u, S_w, S_r) (rate-limited plans)."""
        return self.row_u > NO_ROWS

    def row_slacks(self, state: np.ndarray, p_d: np.ndarray, pd_dot: np.ndarray, last_row: np.ndarray,
                   dt: float) -> dict[str, float]:
        """Slack (>= 0: inside) of each row face: S_c − |v_c − κ_f(state)_c| for the plan's last row ``last_row``
        (3,) and the law's row at its end ``state`` (4,), the target's ``p_d``, ``pd_dot`` (3,) at the same time and
        the period ``dt`` (s); empty without the faces."""
        if not self.has_rows:
            return {}
        gap = np.abs(np.asarray(last_row, dtype=float) - self.command(state, p_d, pd_dot, dt))
        bands = (self.row_u, self.row_w, self.row_r)
        return {f"terminal set: |v_{c} - kappa_f|": float(s - g) if math.isfinite(g) else -math.inf
                for c, s, g in zip("uwr", bands, gap)}

    @property
    def has_bearing(self) -> bool:
        """True when X_f has the bearing face |φ| <= φ_f."""
        return self.bearing_max < NO_BEARING

    def slacks(self, state: np.ndarray, p_d: np.ndarray, pd_dot: np.ndarray | None = None) -> dict[str, float]:
        """Slack (>= 0: inside) of each face of X_f at ``state`` (4,) against ``p_d`` (3,) and, for the bearing
        face, the target's velocity ``pd_dot`` (3,) at the same time (needed when :attr:`has_bearing`)."""
        x = np.asarray(state, dtype=float)
        d, alpha, e_z = line_of_sight(x, np.asarray(p_d, dtype=float))
        out = {"terminal set: d >= d_lo": d - self.d_lo, "terminal set: d <= d_hi": self.d_hi - d,
               "terminal set: |alpha|": self.alpha_max - abs(alpha), "terminal set: |e_z|": self.z_max - abs(e_z)}
        if self.has_bearing:
            if pd_dot is None:
                raise ValueError("TerminalLaw.slacks: a bearing face needs the target's velocity pd_dot")
            phi = bearing(x, np.asarray(p_d, dtype=float), np.asarray(pd_dot, dtype=float))
            out["terminal set: |bearing|"] = self.bearing_max - abs(phi) if math.isfinite(phi) else -math.inf
        return out

    def contains(self, state: np.ndarray, p_d: np.ndarray, pd_dot: np.ndarray | None = None) -> bool:
        """True when ``state`` lies in X_f (``pd_dot``: see :meth:`slacks`)."""
        return min(self.slacks(state, p_d, pd_dot).values()) >= 0.0

    def command(self, state: np.ndarray, p_d: np.ndarray, pd_dot: np.ndarray, dt: float) -> np.ndarray:
        """The law's row v = [u, w, r] (m/s, m/s, rad/s) at the nominal ``state`` (4,), the target's position
        ``p_d`` (3,) and velocity ``pd_dot`` (3,) at the row's start, held over ``dt`` (s)."""
        x = np.asarray(state, dtype=float)
        p = np.asarray(p_d, dtype=float)
        v = np.asarray(pd_dot, dtype=float)
        d, alpha, e_z = line_of_sight(x, p)
        dx, dy = p[0] - x[0], p[1] - x[1]
        radial = (v[0] * dx + v[1] * dy) / d if d > 0.0 else 0.0
        closing = radial + self.gain_d * (d - self.d_star)
        g = self.turn
        if self.los_feedforward and d > 0.0:
            across = (v[1] * dx - v[0] * dy) / d
            turn = -g * alpha + dt * (across - closing * math.tan(alpha)) / d
            u = closing / (float(sinc(0.5 * turn)) * math.cos(alpha + 0.5 * turn))
            return np.array([u, v[2] - self.gain_z * e_z, turn / dt])
        # T = −g α: the memoryless law, written as it was so that its floats stay the certified runs' own
        u = closing / (float(sinc(0.5 * g * alpha)) * math.cos(alpha * (1 - g / 2)))
        return np.array([u, v[2] - self.gain_z * e_z, -g * alpha / dt])

    def to_dict(self) -> dict[str, float]:
        """The thirteen numbers by name (``los_feedforward`` as 1.0 or 0.0)."""
        return {k: float(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, d: object, where: str = "terminal") -> "TerminalLaw":
        """Inverse of :meth:`to_dict`; a missing or extra key is a ConfigError naming ``where``."""
        names = [f.name for f in fields(cls)]
        if not isinstance(d, dict) or set(d) != set(names):
            raise ConfigError(where, f"an object with exactly the keys {names}",
                              sorted(d) if isinstance(d, dict) else type(d).__name__)
        values = {k: float(d[k]) for k in names}
        if values["los_feedforward"] not in (0.0, 1.0):
            raise ConfigError(f"{where}.los_feedforward", "1.0 or 0.0", d["los_feedforward"])
        return cls(**{**values, "los_feedforward": values["los_feedforward"] == 1.0})


#: The twelve number fields of :class:`TerminalLaw` (all but ``los_feedforward``), validated in its order.
_NUMBER_FIELDS = tuple(f.name for f in fields(TerminalLaw) if f.name != "los_feedforward")
