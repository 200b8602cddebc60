"""The typed result of :func:`verify.vehicle.bound.velocity_loop_bound`: bounds, gains, conditions, JSON.

In the JSON a non-finite number is ``null`` (:func:`tubekit.jsonable.to_jsonable`); upper bounds
read ``null`` back as +inf, the authority (a lower bound) as −inf, so a round trip is exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from tubekit.exceptions import ConfigError
from verify.theorem.design import Condition
from verify.vehicle.response import ResponseSums
from verify.kernel.parts import block, bound, integer, item, number, numbers, text

__all__ = ["LoopBound", "CHANNEL_SETS"]

_ROWS = ("e", "a", "z", "ydot")
_INPUTS = ("jump", "w_dot", "w_n")


def _sums_to_dict(s: ResponseSums) -> dict:
    """``{tick: {row: [jump, w_n]}, period: {...}, rho, terms}``."""
    return {"tick": {r: list(s.tick[o]) for o, r in enumerate(_ROWS)},
            "period": {r: list(s.period[o]) for o, r in enumerate(_ROWS)},
            "peak": {r: list(s.peak[o]) for o, r in enumerate(_ROWS)}, "rho": s.rho, "terms": s.terms}


def _sums_from_dict(d: Any, where: str) -> ResponseSums:
    """Inverse of :func:`_sums_to_dict`."""
    tick, period, peak = (block(d, k, where) for k in ("tick", "period", "peak"))
    return ResponseSums(tick=tuple(numbers(tick, r, f"{where}.tick", len(_INPUTS)) for r in _ROWS),
                        period=tuple(numbers(period, r, f"{where}.period", len(_INPUTS)) for r in _ROWS),
                        peak=tuple(numbers(peak, r, f"{where}.peak", len(_INPUTS)) for r in _ROWS),
                        rho=bound(d, "rho", where), terms=integer(d, "terms", where))


#: The loop's channels: (u, w, r), or (u, v, w, r) with a sway loop (lateral thrust).
CHANNEL_SETS = ("uwr", "uvwr")


def _gains_from(v: Any, where: str, count: int) -> tuple[ResponseSums, ...]:
    """``count`` :class:`ResponseSums`, one per channel."""
    if not isinstance(v, list) or len(v) != count:
        raise ConfigError(where, f"a list of {count} response sums, one per channel", v)
    return tuple(_sums_from_dict(g, f"{where}[{i}]") for i, g in enumerate(v))


@dataclass(frozen=True)
class LoopBound:
    """The velocity loop's derived error bound and everything it rests on.

    Attributes
    ----------
    v_max, tick, period, jump_tick, jump_period
        The inputs: command box V (m/s, m/s, rad/s), h and δ (s), jump bounds per tick and per period.
    error : (3,) floats
        E = (E_u, E_w, E_r): sup |u_b − u_c|, |w_b − w_c|, |r_b − r_c| (+inf when not certified).
    sway : float
        γ̄ (m/s): sup |v_b|; with a sway loop (``channels`` "uvwr") its error bound E_v, else the free hull's sway
        over |u| <= V_u + E_u, |r| <= V_r + E_r and the coefficient box.
    a_bound, z_bound, accel_bound : (3,) floats
        sup|a| = sup|k_p e + k_i I|, sup|z| = sup|τ − τ_cmd|/m̂ and sup|ẏ| (the body acceleration)
        (m/s², m/s², rad/s²).
    assumed : (n, 4) floats
        The assumed (E, sup|a|, sup|z|, sup|ẏ|) per channel (n = len(channels)) the fixed point was checked at.
    w_start, w_rate, w_n : (3,) floats
        Input bounds: |W(0)| <= sup|d|/m (m/s²), sup|Ẇ| and sup|ṅ̂/m̂ − λ ẏ| (m/s³).
    gains : tuple of n ResponseSums
        The impulse-response sums per channel (rows e, a + W, z, ẏ; inputs jump, Ẇ (and x(0)), w_n).
    slope : (n,) floats
        λ_c (1/s): the drag slope ∂n̂_c/∂y_c / m̂_c moved into the loop's matrix A.
    authority : (3,) floats
        Acceleration deliverable against drag anywhere in V (m/s², m/s², rad/s²).
    thrust_peak, thrust_floor : (n,) floats
        sup|τ_cmd| against the smallest actuator limit over the box (N, [N,] N, N m): X, [Y,] Z, N.
    iterations : int
        Fixed-point iterations used.
    conditions : tuple of Condition
        ``loop_stable[c]``, ``loop_fixed_point``, ``loop_saturation[X|Z|N]``, ``loop_sway``, and
        ``rate_authority[c]`` when a rate limit was given.
    reason : str
        Empty when certified, else the failed conditions.
    first_command : (3,) floats or None
        The box |u_c|, |w_c|, |r_c| <= F of the first command the start transient ``w_start`` is taken over
        (m/s, m/s, rad/s; V when no smaller box was given; None only in a file that predates it: read as V).
    channels : str
        "uwr", or "uvwr" when a sway loop regulates the sway (lateral thrust): the order of the per-channel fields.
    """

    v_max: tuple[float, float, float]
    tick: float
    period: float
    jump_tick: tuple[float, float, float]
    jump_period: tuple[float, float, float]
    error: tuple[float, float, float]
    sway: float
    a_bound: tuple[float, float, float]
    z_bound: tuple[float, float, float]
    accel_bound: tuple[float, float, float]
    assumed: tuple[tuple[float, ...], ...]
    w_start: tuple[float, float, float]
    w_rate: tuple[float, float, float]
    w_n: tuple[float, float, float]
    gains: tuple[ResponseSums, ...]
    slope: tuple[float, float, float]
    authority: tuple[float, float, float]
    thrust_peak: tuple[float, float, float]
    thrust_floor: tuple[float, float, float]
    iterations: int
    conditions: tuple[Condition, ...]
    reason: str = ""
    first_command: tuple[float, float, float] | None = None
    channels: str = "uwr"

    @property
    def certified(self) -> bool:
        """True when every condition holds."""
        return all(c.ok is True for c in self.conditions)

    @property
    def failures(self) -> tuple[Condition, ...]:
        """The conditions that do not hold."""
        return tuple(c for c in self.conditions if c.ok is not True)

    def to_dict(self) -> dict:
        """Plain JSON-able data (``certified`` included for readers; recomputed by :meth:`from_dict`)."""
        out: dict[str, Any] = {k: list(getattr(self, k)) for k in (
            "v_max", "jump_tick", "jump_period", "error", "a_bound", "z_bound", "accel_bound", "w_start", "w_rate", "w_n",
            "authority",
            "thrust_peak", "thrust_floor")}
        out.update(tick=self.tick, period=self.period, sway=self.sway, iterations=self.iterations, channels=self.channels,
                   assumed=[list(r) for r in self.assumed], gains=[_sums_to_dict(g) for g in self.gains], slope=list(self.slope), reason=self.reason,
                   certified=self.certified, conditions=[c.to_dict() for c in self.conditions],
                   first_command=None if self.first_command is None else list(self.first_command))
        return out

    @classmethod
    def from_dict(cls, d: Any, where: str = "certificate.velocity_loop") -> "LoopBound":
        """Inverse of :meth:`to_dict` (ConfigError naming the key)."""
        conds, assumed = item(d, "conditions", where), item(d, "assumed", where)
        channels = d.get("channels", "uwr") if isinstance(d, dict) else "uwr"
        if channels not in CHANNEL_SETS:
            raise ConfigError(f"{where}.channels", f"one of {CHANNEL_SETS}", channels)
        n = len(channels)
        if not isinstance(conds, list):
            raise ConfigError(f"{where}.conditions", "a list of conditions", type(conds).__name__)
        if not isinstance(assumed, list) or len(assumed) != n:
            raise ConfigError(f"{where}.assumed", f"{n} rows of 4 numbers", assumed)
        triples = {k: numbers(d, k, where, 3) for k in ("v_max", "jump_tick", "jump_period", "error", "a_bound",
                                                         "z_bound", "accel_bound", "w_start", "w_rate", "w_n")}
        per_channel = {k: numbers(d, k, where, n) for k in ("thrust_peak", "thrust_floor")}
        return cls(**triples, **per_channel, channels=channels, authority=numbers(d, "authority", where, 3, none=-math.inf),
                   tick=number(d, "tick", where), period=number(d, "period", where), sway=bound(d, "sway", where),
                   assumed=tuple(numbers({"row": r}, "row", f"{where}.assumed[{i}]", 4) for i, r in enumerate(assumed)),
                   gains=_gains_from(item(d, "gains", where), f"{where}.gains", n),
                   slope=numbers(d, "slope", where, n),
                   iterations=integer(d, "iterations", where), reason=text(d, "reason", where),
                   first_command=None if d.get("first_command") is None else numbers(d, "first_command", where, 3),
                   conditions=tuple(Condition.from_dict(c, f"{where}.conditions[{i}]") for i, c in enumerate(conds)))

    def summary_lines(self) -> list[str]:
        """Human-readable lines for a certificate's text."""
        head = "certified" if self.certified else "NOT certified: " + ", ".join(c.condition for c in self.failures)
        e, a, f, p = self.error, self.authority, self.thrust_floor, self.thrust_peak
        lines = [f"velocity loop (derived bound): {head}",
                 f"  E = ({e[0]:.4g} m/s, {e[1]:.4g} m/s, {e[2]:.4g} rad/s), sway γ̄ = {self.sway:.4g} m/s, "
                 f"{self.iterations} fixed-point iterations",
                 f"  over V = {tuple(self.v_max)}, jumps {tuple(self.jump_tick)} per tick, {tuple(self.jump_period)} "
                 f"per period (h = {self.tick:g} s, δ = {self.period:g} s)",
                 f"  authority against drag in V: ({a[0]:.4g} m/s², {a[1]:.4g} m/s², {a[2]:.4g} rad/s²)",
                 "  thrust peak / limit: " + ", ".join(
                     f"{ch} {pk:.4g}/{fl:.4g} {'N m' if ch == 'N' else 'N'}"
                     for ch, pk, fl in zip("XYZN" if self.channels == "uvwr" else "XZN", p, f))]
        lines += [f"  failed {c.condition}: {c.detail}" for c in self.failures]
        return lines
