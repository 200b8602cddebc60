"""What the actuators can do for the velocity loop: saturation, the fins over the surge band, the authority.

The conditions ``loop_saturation[X|(Y|)Z|N]`` of :func:`verify.vehicle.bound.velocity_loop_bound` (Step 7 of
``docs/verify.md`` section 9: the command never saturates, so the loop's linear model holds) and the acceleration
each channel delivers against drag in V (``rate_authority[c]``: a plan's rate limit is something the vehicle can
do). Each takes the loop's fixed data (:class:`verify.vehicle.loop_data.LoopData`, read through the protocol
:class:`_Loop`: its channels, nominal balls and masses).
"""

from __future__ import annotations

import functools
import math
from typing import Any, Mapping, Protocol, Sequence

import numpy as np
from flint import arb, ctx

from tubekit.exceptions import ConfigError
from tubekit.model.vehicle_params import VehicleParams
from tubekit.validation import finite, nonnegative, positive
from verify.kernel.intervals import enclose, lower, upper
from verify.theorem.design import Condition, hull_sway_bound
from verify.vehicle.model import CHANNELS, channel_forces, channel_masses, hull_balls, thrust_floor, velocity_box
from verify.vehicle.propeller import tied_surge_authority, tied_surge_need



class _Loop(Protocol):
    """What these conditions read of the loop's fixed data (:class:`verify.vehicle.loop_data.LoopData`)."""

    lateral: bool
    names: str
    forces: str
    nominal: Mapping[str, arb]
    m_hat: tuple[arb, ...]
    model_feedforward: bool

    def box(self, error: Sequence[float]) -> tuple[tuple[float, float, float], float]: ...

    def surge_low(self, surge_error: float) -> float | None: ...

__all__ = ["actuator_authority", "rate_authority_conditions", "saturation_conditions", "straight_top_speed",
           "thrust_peaks", "SURGE_BANDS", "triple"]

_ACTUATOR = {"X": "the surge thrust", "Y": "the lateral thrust", "Z": "the heave force (stern planes on a finned "
             "vehicle)", "N": "the yaw moment (the rudder on a finned vehicle)"}


def thrust_peaks(loop: _Loop, box: tuple[float, float, float], gamma: float,
                  a_bound: Sequence[float], surge: tuple[float, float] | None = None) -> list[float]:
    """sup|τ_cmd_c| = sup|n̂_c| + m̂_c sup|a| over the velocity box (N, N, N m), m̂_c sup|a| without a model
    feedforward; ``surge`` (lo, hi) (m/s): the surge over that band instead of |u| <= box[0]."""
    nu = velocity_box(box[0], gamma, box[1], box[2])
    if surge is not None:
        nu = (enclose(surge[0], surge[1]), *nu[1:])
    if not loop.model_feedforward:  # τ_cmd = M̂ a: the integrators hold the drag, inside sup|a|
        return [upper(loop.m_hat[c] * arb(a_bound[c])) for c in range(len(loop.names))]
    forces = channel_forces(loop.nominal, nu, loop.lateral)
    return [upper(abs(forces[c]) + loop.m_hat[c] * arb(a_bound[c])) for c in range(len(loop.names))]


def actuator_authority(params: VehicleParams, v_max: Sequence[float], surge_floor: float = 0.0,
                       sway: float | None = None) -> tuple[float, float, float]:
    """(a_u, a_w, a_r): a lower bound of the acceleration each channel delivers against drag in V.

    a_c = (smallest limit over ``surge_floor`` <= |u| <= V_u and Θ − sup|n_c| over V (sway |v| <= ``sway`` rounded
    up to :data:`SWAY_GRID`, by default γ̄(V) of the free hull) and Θ) / sup m_c (m/s², m/s², rad/s²): what the
    thrusters deliver, in either direction, anywhere in V at a commanded surge of at least ``surge_floor`` (m/s;
    ``limits.u_min``, 0 without one; the corner of V has the largest drag). Under a surge floor the surge range
    [u_min, V_u] is cut into :data:`SURGE_BANDS` bands, each band's drag against its own smallest limit (a fin's,
    ∝ u², at the band's slow end), with γ̄ over u >= u_min; the smallest over the bands. Negative when the drag (or a
    fin without speed) wins.
    """
    v = triple("v_max", v_max)
    key = (v, float(surge_floor), None if sway is None else _grid_up(float(sway)), ctx.prec)
    try:
        return _authority(params, *key)
    except TypeError:  # an unhashable stand-in for a vehicle: computed without the memo
        return _authority.__wrapped__(params, *key)


#: The sway box of the authority is rounded up to a multiple of this (m/s): a wider box only lowers the bound, and
#: the fixed point's candidates then share one evaluation.
SWAY_GRID = 1e-3


def _grid_up(sway: float) -> float:
    """``sway`` rounded up to a multiple of :data:`SWAY_GRID` (never below ``sway``; +inf stays +inf)."""
    if not math.isfinite(sway):
        return sway
    up = math.ceil(sway / SWAY_GRID) * SWAY_GRID
    return up if up >= sway else math.nextafter(up, math.inf)


@functools.lru_cache(maxsize=256)
def _authority(params: VehicleParams, v: tuple[float, float, float], surge_floor: float, sway: float | None,
               prec: int) -> tuple[float, float, float]:
    """:func:`actuator_authority` of validated inputs, memoised (the fixed point asks it once per candidate backup
    with the same vehicle and box); ``prec`` keys the working precision it is computed at."""
    banded = 0.0 < surge_floor < v[0]
    gamma = (upper(hull_sway_bound(params, v[0], v[2], surge_floor if banded else None)) if sway is None
             else sway)
    if not math.isfinite(gamma):
        return (-math.inf,) * 3
    hull = hull_balls(params)
    masses = channel_masses(hull)
    nu = velocity_box(v[0], gamma, v[1], v[2])
    worst = [math.inf] * 3
    for lo, hi in _surge_bands(surge_floor, v[0]) if banded else [(surge_floor, v[0])]:  # each band, its own force
        forces = channel_forces(hull, (enclose(lo, hi), *nu[1:]) if banded else nu)
        floor = thrust_floor(params, hi, lo)
        worst = [min(w, lower((arb(floor[c]) - abs(forces[c])) / masses[c])) for c, w in enumerate(worst)]
    if params.tied:  # each hull's thrust against its own drag (verify.vehicle.propeller, T2)
        bands = _surge_bands(surge_floor, v[0]) if banded else [(-v[0], v[0])]
        worst[0] = tied_surge_authority(params, (v[0], v[1], v[2]), gamma, bands)
    return tuple(worst)


def rate_authority_conditions(authority: Sequence[float], rate: Sequence[float]) -> list[Condition]:
    """``rate_authority[c]``: a plan's rate limit ρ_c is something the vehicle can do, ρ_c <= a_c."""
    units = ("m/s^2", "m/s^2", "rad/s^2")
    return [Condition(f"rate_authority[{ax}]", f"rho_{ax} <= a_{ax} (acceleration deliverable against drag in V)",
                      float(rate[c]), float(authority[c]), bool(rate[c] <= authority[c]),
                      f"a_{ax} = {authority[c]:.4g} {units[c]} over V and the coefficient box")
            for c, ax in enumerate(CHANNELS)]


def saturation_conditions(loop: _Loop, params: VehicleParams, v: Sequence[float], assumed: list,
                          closed: bool = True, surge_excess: float | None = None) -> list[Condition]:
    """``loop_saturation[X|Z|N]``: sup|n̂_c| + m̂_c Â_c < the smallest limit over |u| <= V_u + E_u and Θ (and
    u >= u_min − E_u, the relative surge under the loop's surge floor, ``loop.surge_low``); not evaluated (no
    number) when the fixed point did not ``closed`` (its assumed bounds mean nothing then). ``surge_excess`` (N,
    :func:`verify.vehicle.bound.command_excess`) on a vehicle whose thrust is tied to its drag: X is each hull's
    own need against its own thrust instead (:func:`verify.vehicle.propeller.tied_surge_need`)."""
    box, sway = loop.box([r[0] for r in assumed])
    a_assumed = [r[1] for r in assumed]
    finite_box = closed and all(math.isfinite(x) for x in (*box, sway, *a_assumed))
    u_bar = box[0] if finite_box else v[0]  # a fixed point that did not close: the design's box, not its bounds
    u_low = max(0.0, loop.surge_low(assumed[0][0] if finite_box else 0.0) or 0.0)
    if finite_box and 0.0 < u_low < u_bar:
        peaks, floor = _banded(loop, params, box, sway, a_assumed, (u_low, u_bar))
    else:
        floor = thrust_floor(params, u_bar, u_low, loop.lateral)
        peaks = thrust_peaks(loop, box, sway, a_assumed) if finite_box else [math.inf] * len(loop.names)
    tied = finite_box and surge_excess is not None  # given only for a thrust tied to the drag
    if tied:
        bands = _surge_bands(u_low, u_bar) if 0.0 < u_low < u_bar else [(-u_bar, u_bar)]
        peaks, floor = list(peaks), list(floor)
        peaks[0], floor[0] = tied_surge_need(params, box, sway, bands, surge_excess)
    conds = []
    for c, ch in enumerate(loop.forces):
        why = (f"sup|n_hat_{loop.names[c]}| + m_hat sup|a| over {u_low:.4g} <= |u| <= {u_bar:.4g} m/s against "
               f"{floor[c]:.4g}" + (f" (the worst of {SURGE_BANDS} surge bands, each against its own limit)"
                                    if 0.0 < u_low < u_bar else "")
               if floor[c] > 0 else
               f"{_ACTUATOR[ch]} is 0 at u = 0, inside the velocity box |u| <= {u_bar:.4g} m/s: a fin's lift grows "
               "with u², so this vehicle cannot produce it at rest (a minimum surge, limits.u_min, above the loop's "
               "E_u keeps the vehicle off u = 0)")
        if ch == "Y" and loop.v_int[1] > 0.0:  # a backup that commands sway (the hold) pushes sideways
            why += (f"; the backup commands sway up to {loop.v_int[1]:.4g} m/s: a larger sway share of the "
                    "thrusters ([plant.vehicle.thrusters] shares) raises Y_max")
        peak = peaks[c]
        if not closed:  # the assumed bounds of a fixed point that did not close mean nothing: no number
            peak, why = None, "not evaluated: the loop bound did not close (root cause: loop_fixed_point)" + (
                "" if floor[c] > 0 else f"; and {why}")
        if ch == "X" and tied:
            why = (f"each hull's sup|n_u| + {surge_excess:.4g} N (m_hat_u sup|(k_i, k_p, 0) x|) against its own "
                   f"thrust, tied to its drag by top_speed, in the worst of {len(bands)} surge bands x the drag's "
                   "cells (verify.vehicle.propeller, step T1)")
        elif ch == "X":
            why += _top_speed_note(params, v[0])
        conds.append(Condition(f"loop_saturation[{ch}]", f"sup|tau_cmd_{ch}| < smallest {ch} limit over the box",
                               peak, floor[c], bool(peak is not None and peak < floor[c]), why))
    return conds


def _top_speed_note(params: VehicleParams, v_u: float) -> str:
    """The surge condition's note when V_u = ``v_u`` (m/s) lies beyond :func:`straight_top_speed`, else ''."""
    top = straight_top_speed(params)
    if v_u <= top:
        return ""
    return (f"; V_u = {v_u:.4g} m/s is beyond the weakest hull's top speed, about {top:.4g} m/s running straight "
            "(the smallest surge thrust against the largest drag of the box): that hull's surge error at the "
            f"command V_u is at least {v_u - top:.3g} m/s; a lower limits.u_max (the target and the current must "
            "fit under it: keep_up[u]) or a box whose thrust and drag belong together")


def straight_top_speed(params: VehicleParams) -> float:
    """The weakest hull's top speed running straight in still water (m/s): the positive root of
    |X_u| u + |X_u|u|| u² = X_min, the largest drag of the box (each coefficient's most negative end) against the
    smallest surge thrust over |u| <= 10 m/s; +inf when the box has no drag. A diagnostic (plain floats), not a
    proof step: a hull of the box cannot hold a surge above it, so a loop commanding one has at least the
    difference as its error. With a thrust tied to the drag (``top_speed`` [s_lo, s_hi]) every hull's thrust
    holds it at s_lo or faster (``verify.vehicle.propeller``), so the weakest top speed is s_lo."""
    if params.tied:
        return float(params.interval("top_speed")[0])
    linear, quadratic = -float(params.interval("X_u")[0]), -float(params.interval("X_uu")[0])
    thrust = float(thrust_floor(params, 10.0)[0])
    if quadratic <= 0.0:
        return thrust / linear if linear > 0.0 else math.inf
    return (-linear + math.sqrt(linear * linear + 4.0 * quadratic * thrust)) / (2.0 * quadratic)


#: Surge bands of the fins' condition under a minimum surge (:func:`_banded`).
SURGE_BANDS = 8


def _banded(loop: _Loop, params: VehicleParams, box: tuple[float, float, float], sway: float,
            a_assumed: Sequence[float], surge: tuple[float, float]) -> tuple[list[float], list[float]]:
    """(need, limit) per channel of the band where need/limit is largest: the relative surge [lo, hi] (m/s) cut into
    :data:`SURGE_BANDS` bands, in each the need sup|n̂_c| + m̂_c Â_c over the band against the smallest limit over
    it (a fin's, ∝ u², at the band's slow end): the need and the force both grow with the surge, so a band is
    compared with its own force, not with the slowest band's (the condition holds iff it holds in every band)."""
    worst: list[tuple[float, float, float]] = [(-math.inf, math.inf, math.inf)] * len(loop.names)
    for a, b in _surge_bands(*surge):
        need = thrust_peaks(loop, box, sway, a_assumed, surge=(a, b))
        limit = thrust_floor(params, b, a, loop.lateral)
        for c in range(len(loop.names)):
            ratio = need[c] / limit[c] if limit[c] > 0 else math.inf
            if ratio > worst[c][0]:
                worst[c] = (ratio, need[c], limit[c])
    return [w[1] for w in worst], [w[2] for w in worst]



def _surge_bands(lo: float, hi: float) -> list[tuple[float, float]]:
    """[lo, hi] (m/s) cut into :data:`SURGE_BANDS` equal bands (lo, hi) of the relative surge."""
    edges = np.linspace(lo, hi, SURGE_BANDS + 1)
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]


def triple(name: str, value: Any, strict: bool = False) -> tuple[float, float, float]:
    """Three finite numbers >= 0 (> 0 when ``strict``), else ConfigError naming ``name[i]``."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise ConfigError(name, "three numbers (u, w, r)", value)
    check = positive if strict else nonnegative
    return tuple(check(f"{name}[{i}]", finite(f"{name}[{i}]", x)) for i, x in enumerate(value))
