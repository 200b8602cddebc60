"""The velocity loop's fixed data per vehicle: its gains, balls, slopes and rigorous response sums.

:class:`LoopData` holds what the fixed point of :mod:`verify.vehicle.bound` reads every round and never changes:
the nominal and true coefficient balls, the gains k_p = ω_b and k_i = ω_b²/4, the actuator lag, the channels'
masses, the constant drag slopes λ_c (the midpoint of ∂n̂_c/∂y_c / m̂_c over V) and, per channel, the impulse
response sums of :func:`loop_matrix` (:func:`verify.vehicle.response.impulse_sums`). :func:`loop_data_of` builds
it once per hashable vehicle, command box and tick.
"""

from __future__ import annotations

import functools
import math
from typing import Sequence

from flint import arb, ctx

from tubekit.model.vehicle_params import VehicleParams
from verify.kernel.intervals import upper
from verify.theorem.design import hull_sway_bound, relative_surge_floor
from verify.vehicle.model import (channel_gradient, channel_masses, hull_balls, nominal_balls, nominal_params,
                                  point_time_constant, velocity_box, with_sway, without_sway, CHANNELS,
                                  LATERAL_CHANNELS)
from verify.vehicle.response import RESPONSE_PREC, ResponseSums, gain_balls, impulse_sums
from verify.vehicle.cells import Cell, channel_cells
from verify.vehicle.pi_loop import ChannelFacts, channel_facts

__all__ = ["LoopData", "loop_data_of", "loop_matrix"]


def loop_matrix(k_p: float, k_i: float, time_constant: float, slope: float = 0.0) -> list[list[arb]]:
    """A (1/s) of the module doc for gains k_p (1/s), k_i (1/s²), the actuator lag T_thr (s) and λ_c (1/s).

    With λ_c = ``slope`` the z row loses λ_c (k_i, k_p, 1): the part λ_c ẏ of w_n moved into A.
    """
    with ctx.workprec(RESPONSE_PREC):
        kp, ki, t, lam = arb(k_p), arb(k_i), arb(time_constant), arb(slope)
        zero = arb(0)
        return [[zero, arb(1), zero], [-ki, -kp, arb(-1)],
                [kp * ki - lam * ki, kp * kp - ki - lam * kp, kp - 1 / t - lam]]


class LoopData:
    """The vehicle's fixed data for the fixed point: balls, gains, slopes λ_c, the response sums per channel."""

    def __init__(self, params: VehicleParams, v_max: Sequence[float], tick: float, ticks: int,
                 sway_max: float = 0.0, surge_floor: float = 0.0) -> None:
        self.params, self.v_max, self.tick, self.ticks = params, tuple(v_max), tick, int(ticks)
        # u_min (m/s): the commanded surge never falls below it, so the relative surge stays >= u_min − E_u
        self.surge_floor = float(surge_floor)
        # with lateral thrust a fourth channel, sway (index 1), regulated to its command: the command box is
        # |v_c| <= sway_max (0 but under a backup law that commands sway, verify.backup.hold)
        self.lateral = bool(getattr(params, "lateral", False))
        self.names = LATERAL_CHANNELS if self.lateral else CHANNELS
        self.own = (0, 1, 2, 3) if self.lateral else (0, 2, 3)
        self.forces = "XYZN" if self.lateral else "XZN"
        self.v_int = with_sway(self.v_max, float(sway_max), self.lateral)
        self.nominal, self.hull = nominal_balls(params), hull_balls(params)
        nom = nominal_params(params)
        # loop_bandwidth's gains (what the LDI studies of benchmarks/ read); the bound reads each channel's own:
        self.k_p, self.k_i = float(nom.loop_bandwidth), 0.25 * float(nom.loop_bandwidth) ** 2
        # per channel (in the order of ``names``): its own PI gains (k_p, k_i), the loop_bandwidth's where the vehicle
        # gives the channel no bandwidth of its own (VehicleParams.loop_gains)
        self.gains: tuple[tuple[float, float], ...] = tuple(params.loop_gains[i] for i in self.own)
        self.lag = point_time_constant(params)
        self.m_hat = channel_masses(self.nominal, self.lateral)
        self.m_true = channel_masses(self.hull, self.lateral)
        box, gamma = self.box((0.0,) * len(self.names))
        self.slope = tuple(float(x.mid()) for x in self.slopes(box, gamma)) if math.isfinite(gamma) \
            else (0.0,) * len(self.names)
        bases = tuple(loop_matrix(kp, ki, self.lag, lam) for lam, (kp, ki) in zip(self.slope, self.gains))  # A(λ_c)
        self.sums: tuple[ResponseSums, ...] = tuple(_channel_sums(a, kp, ki, tick, ticks)
                                                    for a, (kp, ki) in zip(bases, self.gains))
        h = arb(tick)
        # the sums as balls, per channel and output row: (jump per tick, jump per period, h Ẇ, h w_n, start peak)
        self.gain_balls = tuple(gain_balls(s, tick) for s in self.sums)
        # per channel and output row, the L1 gain of the direction (0, −1, k_p − λ_c) = −b_J + λ_c b_n along which
        # the mass mismatch enters in verify.vehicle.bound's second decomposition: h Σ g_J + |λ_c| h Σ g_n
        self.mass_gain_balls = tuple(tuple(h * g[0] + abs(arb(lam)) * g[3] for g in rows)
                                     for rows, lam in zip(self.gain_balls, self.slope))
        # loop_feedforward "none" (τ_cmd = M̂ a): the frozen-slope bound's data (verify.vehicle.pi_loop), and none of
        # the model loop's decompositions (their matrices are of τ_cmd = n̂(ν) + M̂ a)
        self.model_feedforward = params.loop_feedforward == "model"
        self.free: tuple[ChannelFacts, ...] | None = None if self.model_feedforward else \
            tuple(channel_facts(self, c) for c in range(len(self.names)))
        # step 5c: per channel, its own constant coefficients split into cells (verify.vehicle.cells)
        self.cells: tuple[tuple[Cell, ...], ...] = tuple(channel_cells(self, c, a) for c, a in enumerate(bases)) \
            if self.stable and self.model_feedforward else tuple(() for _ in self.names)

    def channel_gains(self, c: int) -> tuple[arb, arb]:
        """(k_p, k_i) of channel ``c`` (an index into ``names``) as balls."""
        kp, ki = self.gains[c]
        return arb(kp), arb(ki)

    @property
    def stable(self) -> bool:
        """Every channel's sampled loop is stable (without a model feedforward: every piece of every channel)."""
        if self.free is not None:
            return all(f.stable for f in self.free)
        return all(s.stable for s in self.sums)

    def box(self, error: Sequence[float]) -> tuple[tuple[float, float, float], float]:
        """(ū, w̄, r̄) = V + E and the sway's bound over it (m/s, m/s, rad/s; m/s): with lateral thrust the sway
        channel's E_v (``error`` then has the sway channel at index 1), else γ̄ of the free hull (over
        u >= :meth:`surge_low` under a surge floor)."""
        bar = tuple(upper(arb(v) + arb(e)) for v, e in zip(self.v_int, error))
        if self.lateral:
            return without_sway(bar, True), bar[1]
        return bar, upper(hull_sway_bound(self.params, bar[0], bar[2], self.surge_low(error[0])))

    def surge_low(self, surge_error: float) -> float | None:
        """u_min − E_u (m/s), rounded down, the relative surge's floor; None without a surge floor."""
        return relative_surge_floor(self.surge_floor, surge_error)

    def slopes(self, box: Sequence[float], gamma: float) -> list[arb]:
        """∂n̂_c/∂y_c / m̂_c over the velocity box (1/s): the drag's slope in the channel's own speed."""
        grads = channel_gradient(self.nominal, velocity_box(box[0], gamma, box[1], box[2]), self.lateral)
        return [grads[c][self.own[c]] / self.m_hat[c] for c in range(len(self.names))]


def _channel_sums(a: list, k_p: float, k_i: float, tick: float, ticks: int) -> ResponseSums:
    """The impulse-response sums of one channel's loop matrix ``a`` with its gains: the inputs (jump, Ẇ, w_n)
    and the outputs (e, a, z, ẏ) of :mod:`verify.vehicle.bound`."""
    kp, ki = arb(k_p), arb(k_i)
    return impulse_sums(a, [[0, 1, -kp], [1 / ki, 0, 0], [0, 0, -1]], [[0, 1, 0], [ki, kp, 0], [0, 0, 1], [ki, kp, 1]],
                        tick=tick, ticks_per_period=ticks)


@functools.lru_cache(maxsize=8)
def _cached_loop(params: VehicleParams, v_max: tuple, tick: float, ticks: int, prec: int,
                 sway_max: float = 0.0, surge_floor: float = 0.0) -> LoopData:
    """:class:`LoopData` memoised on its inputs and the working precision ``prec`` (bits) it is built at."""
    return LoopData(params, v_max, tick, ticks, sway_max, surge_floor)


def loop_data_of(params: VehicleParams, v_max: tuple, tick: float, ticks: int, sway_max: float = 0.0,
                 surge_floor: float = 0.0) -> LoopData:
    """The :class:`LoopData` (its impulse-response sums) of a vehicle, V, h and the surge floor u_min (m/s), built
    once per (hashable) vehicle: it does not depend on the jump bounds, which the fixed point of
    :mod:`verify.vehicle.compose` changes each round."""
    try:
        hash(params)
    except TypeError:
        return LoopData(params, v_max, tick, ticks, sway_max, surge_floor)
    return _cached_loop(params, v_max, tick, ticks, ctx.prec, sway_max, float(surge_floor))
