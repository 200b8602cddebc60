"""The velocity loop's error bound E = (E_u, E_w, E_r), derived in Arb from the vehicle (issue 22).

**Model.** Per channel c ∈ (u, w, r), y = u, w or r: m_c ẏ = τ − n_c(ν; θ) with θ anywhere in the
coefficient box Θ (yaw with the sway row eliminated, :mod:`verify.vehicle.model`); the actuator
τ̇ = (sat(τ_cmd) − τ)/T_thr; the controller τ_cmd = n̂_c(ν) + m̂_c a, a = k_p e + k_i I, e = y* − y,
İ = e, k_p = ω_b, k_i = ω_b²/4 (nominal n̂, m̂: ``tubekit.plant.dynamic``). Without saturation put
z = (τ − τ_cmd)/m̂_c, s = a + z = (τ − n̂_c)/m̂_c and W = ẏ − s = (1 − 1/μ) ẏ + d/m̂_c (the
acceleration the model mismatch adds; μ = m̂_c/m_c, d = n̂_c − n_c). With Ĩ = I + W/k_i and a
constant drag slope λ_c, x = (Ĩ, e, z) obeys (:func:`loop_matrix`)

    ẋ = A x + (1/k_i, 0, 0) Ẇ + (0, 0, −1) w_n,      w_n = ṅ̂_c/m̂_c − λ_c ẏ,
    A = [[0, 1, 0], [−k_i, −k_p, −1], [k_i (k_p − λ_c), k_p² − k_i − λ_c k_p, k_p − 1/T_thr − λ_c]],

and e = (0, 1, 0) x, z = (0, 0, 1) x, ẏ = (k_i, k_p, 1) x, a = (k_i, k_p, 0) x − W; Ẇ = (μ − 1) ṡ + ḋ/m_c
with ṡ = −z/T_thr − λ_c ẏ − w_n. A command jump J adds J (0, 1, −k_p) to x (τ is continuous). The
trimmed start (e = I = z = 0, τ = n̂(ν(0)), ν(0) = (u_c, 0, w_c, r_c) of the first command) gives
x(0) = (W(0)/k_i, 0, 0) with W(0) = d(ν(0))/m_c, so |W(0)| <= sup|d|/m_c over the first command's box
|y_c(0)| <= F_c, v(0) = 0 (``first_command``; where it is not given, F = V). d vanishes at rest, so a loop
that starts from rest and whose first command moves by at most J (the plans' rate limit) starts with almost no
transient. A *settled* start (``settled``: the loop at its equilibrium at ν(0), the integrators holding the
mismatch, ``[plant] start = "settled"``) has x(0) = 0 exactly; its first command is a jump the sums count.
:func:`verify.vehicle.response.impulse_sums` bounds every output by the sums of its sampled
response: jumps (J_tick at every tick, J_period − J_tick more at period boundaries, worst phase),
the inputs Ẇ and w_n (L1), and the free response from x(0) (peak).

**Second decomposition: the mass mismatch in the state.** The first one charges the mass mismatch through
(μ − 1) ṡ, whose Ẑ/T_thr term is large for a fast actuator. Instead, with W' = d/m_c and Ĩ = I + W'/(μ k_i)
(μ is constant), the same loop is exactly ẋ = A(μ) x + (1/k_i, 0, 0) ḋ/m̂_c + (0, 0, −1) w_n with
A(μ) = A + (μ − 1) (0, −1, k_p − λ_c)(k_i, k_p, 1)ᵀ and ẏ = μ (k_i, k_p, 1) x, a = (k_i, k_p, 0) x − d/m̂_c.
Since (k_i, k_p, 1) x = ẏ/μ, the mass mismatch is the input (1 − 1/μ) ẏ along (0, −1, k_p − λ_c) =
−(0, 1, −k_p) + λ_c (0, 0, −1), whose L1 gain is at most h Σ g_J + |λ_c| h Σ g_n (the jump's and w_n's
columns, already summed); ḋ/m̂_c enters where Ẇ did, and x(0) = (d(ν(0))/(m̂_c k_i), 0, 0). The jumps are the
same. :func:`computed_bounds` takes, output by output, the smaller of the two (both hold under the same
assumptions); the second is what closes the loop over wider coefficient boxes (``docs/plant.md`` section 4).

**Third decomposition: the channel's own coefficients in cells** (:mod:`verify.vehicle.cells`). θ is constant, so
the channel's own mass entry and its linear and quadratic damping coefficient are split into cells; in each, the
cell's centre (μ_k, δ_k) goes into the loop's matrix and only the residuals are inputs. Its bound is the largest over
the cells (every θ lies in one); :func:`computed_bounds` keeps the smallest of the three. It is what closes the loop
over the BlueROV2's published spread at the owners' speed.

**Theorem (first exit).** Let (E, Â, Ẑ, Ŷ) be assumed bounds of (|e|, |a|, |z|, |ẏ|) per channel.
While they hold on [0, t): ν lies in the box |y_c| <= V_c + E_c, |v| <= γ̄ (hull ISS bound,
:func:`verify.theorem.design.hull_sway_bound`); no channel saturates (``loop_saturation``), so the model
above holds; the inputs obey the bounds of :func:`input_bounds`; so :func:`computed_bounds`
bounds (|e|, |a|, |z|, |ẏ|) on [0, t] (a jump at t included). If every computed bound is strictly
below the assumed one (``loop_fixed_point``), let t* be the first time an assumed bound is reached:
at t* the computed bounds still hold, so the state is strictly inside, and it stays inside a
little after t* (the signals are right-continuous, jumps isolated): a contradiction. So
|u_b − u_c| <= E_u, |w_b − w_c| <= E_w, |r_b − r_c| <= E_r and |v_b| <= γ̄ for all time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.validation import finite, nonnegative, positive
from verify.theorem.design import Condition, hull_sway_bound
from verify.kernel.intervals import upper
from verify.vehicle.result import LoopBound
from tubekit.model.vehicle_params import VehicleParams
from verify.vehicle.model import (arb_body_forces, channel_gradient, channel_mismatch, channel_mismatch_gradient,
                                  point_time_constant, velocity_box, with_sway, without_sway)
from verify.vehicle.loop_data import LoopData, loop_data_of, loop_matrix
from verify.vehicle.cells import CellInputs, cell_inputs, cell_starts, channel_bounds
from verify.vehicle.pi_loop import free_bounds, free_stability, free_start
from verify.vehicle.why_open import open_cause, own_gains
from verify.vehicle.saturation import (SURGE_BANDS, actuator_authority, rate_authority_conditions,
                                       saturation_conditions, triple)

__all__ = ["LoopBound", "velocity_loop_bound", "actuator_authority", "loop_matrix", "computed_bounds",
           "input_bounds", "start_bounds", "start_bounds_nominal", "start_terms", "own_gains", "Inputs",
           "command_excess",
           "rate_authority_conditions", "LOOP_MAX_ITERATIONS", "LOOP_INFLATION", "SURGE_BANDS"]

#: Default bound on the fixed-point iterations (a count, not seconds).
LOOP_MAX_ITERATIONS = 60
#: Each iteration assumes (1 + LOOP_INFLATION) x the bounds it computed.
LOOP_INFLATION = 0.05


@dataclass(frozen=True)
class Inputs:
    """Bounds of the model's inputs per channel, given the assumed bounds (see the module doc).

    Attributes
    ----------
    start : (3,) floats
        sup|d_c|/m_c >= |W(0)| (m/s², m/s², rad/s²).
    rate : (3,) floats
        sup|Ẇ| (m/s³, m/s³, rad/s³).
    drag : (3,) floats
        sup|w_n| = sup|ṅ̂_c/m̂_c − λ_c ẏ| (same units).
    mismatch : (3,) floats
        sup|W| <= sup|1 − 1/μ| Ŷ + sup|d|/m̂ (m/s², m/s², rad/s²): a = (k_i, k_p, 0) x − W.
    sway : float
        γ̄ (m/s) over the assumed velocity box.
    start_mass, rate_mass, mass : (3,) floats
        The second decomposition (module doc, "mass in the state"): sup|d_c(ν(0))|/m̂_c, sup|ḋ_c|/m̂_c and
        sup|1 − 1/μ| Ŷ_c (m/s², m/s³, m/s³; rad for yaw).
    mass_ratio : (3,) floats
        sup μ = sup m̂_c/m_c per channel: ẏ = μ (k_i, k_p, 1) x in the second decomposition.
    cells : per channel, per cell of :mod:`verify.vehicle.cells`, a CellInputs
        The third decomposition's residuals (empty: that step is not used).
    """

    start: tuple[float, float, float]
    rate: tuple[float, float, float]
    drag: tuple[float, float, float]
    mismatch: tuple[float, float, float]
    sway: float
    start_mass: tuple[float, float, float]
    rate_mass: tuple[float, float, float]
    mass: tuple[float, float, float]
    mass_ratio: tuple[float, float, float]
    cells: tuple[tuple[CellInputs, ...], ...] = ()


def _rates(loop: LoopData, nu: Sequence[arb], accel: Sequence[float]) -> tuple[arb, arb, arb, arb]:
    """Bounds of |u̇|, |v̇|, |ẇ|, |ṙ|: the channels' Ŷ, and the sway row m22 v̇ = −n2 − m24 ṙ over Θ (with lateral
    thrust the sway channel's own Ŷ_v)."""
    if len(accel) != len(loop.names):
        raise ValueError(f"_rates: one acceleration bound per channel {loop.names!r}, received {len(accel)}")
    if loop.lateral:
        return tuple(arb(a) for a in accel)
    h = loop.hull
    sway = (abs(arb_body_forces(h, nu)[1]) + abs(h["m24"]) * arb(accel[2])) / h["m22"]
    return arb(accel[0]), arb(upper(sway)), arb(accel[1]), arb(accel[2])


def _start_mismatch(loop: LoopData, first_command: Sequence[float]) -> tuple:
    """The mismatch d_c (balls) over the first command's box |y_c| <= F_c, v = 0, and Θ."""
    return channel_mismatch(loop.nominal, loop.hull,
                            velocity_box(first_command[0], 0.0, first_command[1], first_command[2]), loop.lateral)


def start_bounds(loop: LoopData, first_command: Sequence[float]) -> tuple[float, float, float]:
    """sup|W(0)| = sup|d_c|/m_c over the first command's box |y_c| <= F_c, v = 0, and Θ (m/s², m/s², rad/s²): the
    start transient of the trimmed start (module doc); it does not depend on the fixed point's assumption."""
    return _per_mass(_start_mismatch(loop, first_command), loop.m_true)


def start_bounds_nominal(loop: LoopData, first_command: Sequence[float]) -> tuple[float, float, float]:
    """sup|d_c|/m̂_c over the same box (m/s², m/s², rad/s²): the start transient of the second decomposition (its
    Ĩ(0) = d/(m̂ k_i); module doc)."""
    return _per_mass(_start_mismatch(loop, first_command), loop.m_hat)


def start_terms(loop: LoopData, first_command: Sequence[float], settled: bool = False) -> tuple:
    """The start transient of the three decompositions: :func:`start_bounds`, :func:`start_bounds_nominal` and
    :func:`verify.vehicle.cells.cell_starts` (m/s², m/s², rad/s²); zeros for a settled start (x(0) = 0: at the
    equilibrium e = 0, z = 0 and Ĩ = I + D/k_i = 0 because the integrators hold −D/k_i)."""
    if settled:
        zeros = (0.0,) * len(loop.names)
        return zeros, zeros, tuple((0.0,) * len(cells) for cells in loop.cells)
    d_start = _start_mismatch(loop, first_command)
    return _per_mass(d_start, loop.m_true), _per_mass(d_start, loop.m_hat), cell_starts(loop, first_command)


def _per_mass(d: Sequence[arb], masses: Sequence[arb]) -> tuple[float, ...]:
    """sup|d_c| / m_c per channel (rounded up)."""
    return tuple(upper(abs(x) / m) for x, m in zip(d, masses))


def input_bounds(loop: LoopData, error: Sequence[float], z_bound: Sequence[float],
                 accel: Sequence[float], start: Sequence[float] | None = None,
                 start_mass: Sequence[float] | None = None,
                 start_cells: Sequence[Sequence[float]] | None = None) -> Inputs:
    """The model's input bounds over the box |y_c| <= V_c + E_c, |v| <= γ̄ and Θ, given Ẑ and Ŷ = sup|ẏ|;
    ``start`` is sup|W(0)| (:func:`start_bounds`; None: sup|d|/m over that same box), ``start_mass`` the second
    decomposition's (:func:`start_bounds_nominal`; None: sup|d|/m̂ over that box), ``start_cells`` the third's
    (:func:`verify.vehicle.cells.cell_starts`; None: sup|d|/m̂ over that box, per cell).

    ŵ_n = (sup|∂n̂_c/∂y_c − λ_c m̂_c| Ŷ_c + Σ_{j ≠ c} sup|∂n̂_c/∂ν_j| |ν̇_j|)/m̂_c;
    sup|Ẇ| = sup|μ − 1| (Ẑ/T_thr + |λ_c| Ŷ_c + ŵ_n) + Σ_j sup|∂d_c/∂ν_j| |ν̇_j| / m_c;
    the second decomposition: sup|ḋ_c|/m̂_c = Σ_j sup|∂d_c/∂ν_j| |ν̇_j| / m̂_c and sup|1 − 1/μ| Ŷ_c.
    """
    box, gamma = loop.box(error)
    n = len(loop.names)
    if not math.isfinite(gamma) or not all(math.isfinite(x) for x in (*box, *z_bound, *accel)):
        inf = (math.inf,) * n
        return Inputs(start=inf, rate=inf, drag=inf, mismatch=inf, sway=math.inf, start_mass=inf, rate_mass=inf,
                      mass=inf, mass_ratio=inf)
    nu = velocity_box(box[0], gamma, box[1], box[2])
    rates = _rates(loop, nu, accel)
    grads = channel_gradient(loop.nominal, nu, loop.lateral)
    d = channel_mismatch(loop.nominal, loop.hull, nu, loop.lateral)
    d_grad = channel_mismatch_gradient(loop.nominal, loop.hull, nu, loop.lateral)
    rate, drag, mismatch, rate_mass, mass, ratio = [], [], [], [], [], []
    for c in range(n):
        own, lam, y_dot = loop.own[c], arb(loop.slope[c]), arb(accel[c])
        cross = sum((abs(g) * x for j, (g, x) in enumerate(zip(grads[c], rates)) if j != own), arb(0))
        w_n = (abs(grads[c][own] - lam * loop.m_hat[c]) * y_dot + cross) / loop.m_hat[c]
        s_dot = arb(z_bound[c]) / arb(loop.lag) + abs(lam) * y_dot + w_n
        mu = loop.m_hat[c] / loop.m_true[c]
        d_change = sum((abs(g) * x for g, x in zip(d_grad[c], rates)), arb(0))
        rate.append(upper(abs(mu - 1) * s_dot + d_change / loop.m_true[c]))
        drag.append(upper(w_n))
        mismatch.append(upper(abs(1 - 1 / mu) * y_dot + abs(d[c]) / loop.m_hat[c]))
        rate_mass.append(upper(d_change / loop.m_hat[c]))
        mass.append(upper(abs(1 - 1 / mu) * y_dot))
        ratio.append(upper(mu))
    start = _per_mass(d, loop.m_true) if start is None else start
    start_mass = _per_mass(d, loop.m_hat) if start_mass is None else start_mass
    cells = tuple(cell_inputs(loop, c, nu, rates, accel[c], None if start_cells is None else start_cells[c])
                  for c in range(n))
    return Inputs(start=tuple(start), rate=tuple(rate), drag=tuple(drag), mismatch=tuple(mismatch), sway=gamma,
                  start_mass=tuple(start_mass), rate_mass=tuple(rate_mass), mass=tuple(mass), mass_ratio=tuple(ratio),
                  cells=cells)


def computed_bounds(loop: LoopData, jump_tick: Sequence[float], jump_period: Sequence[float],
                    inputs: Inputs | None = None) -> list[list[float]]:
    """[sup|e|, sup|a|, sup|z|, sup|ẏ|] per channel; ``inputs`` None: jumps only (the first guess).

    Each output is the smaller of the module doc's two decompositions, both valid under the same assumptions.
    Row o of the first (e, a + W, z, ẏ): J_tick Σ g_J + (J_period − J_tick) max_phase Σ_period g_J
    + h Σ g_W sup|Ẇ| + h Σ g_n sup|w_n| + peak g_W sup|W(0)|; sup|a| adds sup|W|. The second
    (:func:`_mass_in_state`) replaces sup|Ẇ| and sup|W(0)| by sup|ḋ|/m̂ and sup|d(ν(0))|/m̂ and adds the input
    (1 − 1/μ) ẏ along (0, −1, k_p − λ_c); its ẏ row is μ (k_i, k_p, 1) x.
    """
    out = []
    for c in range(len(loop.names)):
        jt, jp = arb(jump_tick[c]), arb(jump_period[c])
        in_cells = _in_cells(loop, c, jt, jp, inputs) if inputs is not None else ()
        row = []
        for o, (g_tick, g_period, h_rate, h_drag, peak) in enumerate(loop.gain_balls[c]):
            x = jt * g_tick + (jp - jt) * g_period
            if inputs is None:
                row.append(upper(x))
                continue
            first = x + h_rate * arb(inputs.rate[c]) + h_drag * arb(inputs.drag[c]) + peak * arb(inputs.start[c])
            first += arb(inputs.mismatch[c]) if o == 1 else 0
            row.append(min(upper(first), _mass_in_state(loop, c, o, x, inputs), in_cells[o]))
        out.append(row)
    return out


def _in_cells(loop: LoopData, c: int, jump_tick: arb, jump_period: arb, inputs: Inputs) -> tuple[float, ...]:
    """The four outputs of channel ``c`` in the third decomposition (:mod:`verify.vehicle.cells`): each the largest
    over the channel's cells; +inf where the step is not used."""
    cells = loop.cells[c] if inputs.cells else ()
    if not cells:
        return (math.inf,) * 4
    return channel_bounds(cells, jump_tick, jump_period, inputs.drag[c], inputs.cells[c])


def _mass_in_state(loop: LoopData, c: int, o: int, jumps: arb, inputs: Inputs, mismatch: bool = True) -> float:
    """Output ``o`` of channel ``c`` in the second decomposition (module doc), given its jumps' part ``jumps``;
    ``mismatch`` False: for o = 1, sup|(k_i, k_p, 0) x| alone (a without its − d/m̂)."""
    _, _, h_rate, h_drag, peak = loop.gain_balls[c][o]
    x = (jumps + h_rate * arb(inputs.rate_mass[c]) + h_drag * arb(inputs.drag[c])
         + loop.mass_gain_balls[c][o] * arb(inputs.mass[c]) + peak * arb(inputs.start_mass[c]))
    if o == 1 and mismatch:
        x += arb(inputs.mismatch[c])
    if o == 3:
        x *= arb(inputs.mass_ratio[c])
    return upper(x)


def command_excess(loop: LoopData, jump_tick: Sequence[float], jump_period: Sequence[float], inputs: Inputs) -> float:
    """sup|τ_cmd_u − n_u(ν; θ)| (N) of the surge channel, by the second decomposition (module doc): there
    a = (k_i, k_p, 0) x − d/m̂ with d = n̂ − n(θ) exactly, so τ_cmd = n̂ + m̂ a = n(ν; θ) + m̂ (k_i, k_p, 0) x, and this
    is m̂_u sup|(k_i, k_p, 0) x| under the inputs' assumptions (what :mod:`verify.vehicle.propeller` weighs against
    each hull's own thrust)."""
    jt, jp = arb(jump_tick[0]), arb(jump_period[0])
    g_tick, g_period = loop.gain_balls[0][1][:2]
    return upper(loop.m_hat[0] * arb(_mass_in_state(loop, 0, 1, jt * g_tick + (jp - jt) * g_period, inputs, False)))


def _validate(params: VehicleParams, v_max: Any, tick: Any, period: Any, jump_tick: Any, jump_period: Any,
              rate: Any, max_iterations: Any) -> tuple:
    if not hasattr(params, "loop_bandwidth") or not hasattr(params, "interval"):
        raise ConfigError("params", "a VehicleParams", type(params).__name__)
    v = triple("v_max", v_max)
    h, d = positive("tick", finite("tick", tick)), positive("period", finite("period", period))
    ticks = round(d / h)
    if ticks < 1 or abs(ticks * h - d) > 1e-9 * d:
        raise ConfigError("period", f"a whole number >= 1 of ticks of {h} s", period)
    jt, jp = triple("jump_tick", jump_tick), triple("jump_period", jump_period)
    for c in range(3):
        if jp[c] < jt[c]:
            raise ConfigError(f"jump_period[{c}]", f">= jump_tick[{c}] = {jt[c]} (the total jump at a period "
                              "boundary)", jp[c])
    rho = None if rate is None else triple("rate", rate)
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) or max_iterations < 1:
        raise ConfigError("max_iterations", "an integer >= 1", max_iterations)
    point_time_constant(params)
    return v, h, d, int(ticks), jt, jp, rho


def velocity_loop_bound(params: VehicleParams, *, v_max: Sequence[float], tick: float, period: float,
                        jump_tick: Sequence[float], jump_period: Sequence[float],
                        rate: Sequence[float] | None = None, first_command: Sequence[float] | None = None,
                        surge_floor: float = 0.0, max_iterations: int = LOOP_MAX_ITERATIONS,
                        sway: tuple[float, float, float] = (0.0, 0.0, 0.0), settled: bool = False) -> LoopBound:
    """The velocity loop's error bound over the command box ``v_max`` (m/s, m/s, rad/s) and Θ.

    Parameters
    ----------
    params : VehicleParams
        The vehicle, possibly with coefficient intervals (the bound holds for every point).
    v_max : (3,) floats
        The command box V: |u_c| <= V_u, |w_c| <= V_w, |r_c| <= V_r.
    tick, period : float
        h and δ (s); δ a whole number of ticks.
    jump_tick, jump_period : (3,) floats
        Bound on the command's change at every tick, and at a period boundary (total, >= jump_tick).
    rate : (3,) floats, optional
        A plan's rate limit ρ (m/s², m/s², rad/s²): adds ``rate_authority[c]`` (ρ_c <= a_c).
    first_command : (3,) floats, optional
        F: a bound on |u_c|, |w_c|, |r_c| of the first command, at which the run starts trimmed (m/s, m/s,
        rad/s); the start transient W(0) = d(ν(0))/m is bounded over |ν(0)| <= min(F, V), v(0) = 0. Default V.
    surge_floor : float
        u_min (m/s): the commanded surge never falls below it (``limits.u_min``; 0: no floor). The fins'
        limits in ``loop_saturation`` are then taken over u >= u_min − E_u (their force ∝ u², relative to the
        water) instead of down to u = 0.
    max_iterations : int
        Bound on the fixed-point iterations.
    sway : (3,) floats
        With lateral thrust, the sway command's bound |v_c| <= V_v (m/s), its change per tick and at a period
        boundary (m/s): (0, 0, 0) while only plans run (the sway loop regulates to 0); a backup law that commands
        sway (``verify.backup.hold``) gives its own. Refused other than 0 without lateral thrust.
    settled : bool
        The run starts at the loop's equilibrium (``[plant] start = "settled"``): e = 0, τ = n(ν(0)) and the
        integrators holding the mismatch, so x(0) = 0 in every decomposition (Ĩ = I + D/k_i = 0) and there is no
        start transient (:func:`start_terms`); the first command's change from ν(0) must be within
        ``jump_period`` (the sums count a jump at t = 0). ``first_command`` is then not read.
    """
    v, h, d, ticks, jt, jp, rho = _validate(params, v_max, tick, period, jump_tick, jump_period, rate,
                                            max_iterations)
    first = v if first_command is None else tuple(min(f, x) for f, x in zip(triple("first_command",
                                                                                      first_command), v))
    sway_max, sway_tick, sway_period = _sway_command(params, sway)
    floor_u = nonnegative("surge_floor", surge_floor)
    loop = loop_data_of(params, v, h, ticks, sway_max, floor_u)
    start, start_mass, start_cells = start_terms(loop, first, settled)
    # the sway channel's command: 0 under plans, a lateral backup's own jumps
    jt_int, jp_int = with_sway(jt, sway_tick, loop.lateral), with_sway(jp, sway_period, loop.lateral)
    n = len(loop.names)
    starts = (start, start_mass, start_cells, free_start(loop, first, settled) if loop.free is not None else ())
    base = _round(loop, jt_int, jp_int, None, starts)[0]
    assumed = [[x * (1 + LOOP_INFLATION) + 1e-12 for x in row] for row in base]
    first_box = [row[0] for row in assumed]
    found, k, computed, inputs, growth = False, 0, base, None, None
    stop = f"no closing after {max_iterations} rounds"
    while loop.stable and k < max_iterations and not found:
        k += 1
        computed, inputs = _round(loop, jt_int, jp_int, assumed, starts)
        found = all(computed[c][o] < assumed[c][o] for c in range(n) for o in range(4))
        if growth is None:  # against the jumps' own bounds only (an output no jump moves starts from ~0: no ratio)
            growth = [[computed[c][o] / assumed[c][o] if base[c][o] > 0.0 else math.nan for o in range(4)]
                      for c in range(n)]
        if not found:
            grown = [[x * (1 + LOOP_INFLATION) for x in row] for row in computed]
            if not all(math.isfinite(x) for row in grown for x in row):
                stop = f"the bounds overflow after {k} rounds"
                break
            assumed = [[max(a, g) for a, g in zip(ra, rg)] for ra, rg in zip(assumed, grown)]
    if loop.lateral and not found:  # no sway bound to take the authority over
        authority = (-math.inf,) * 3
    else:  # over |v| <= E_v with a sway loop, else the free hull's γ̄
        authority = actuator_authority(params, v, floor_u, upper(arb(sway_max) + arb(computed[1][0]))
                                       if loop.lateral else None)
    excess = command_excess(loop, jt_int, jp_int, inputs) if found and inputs and params.tied else None
    return _result(loop, params, (v, h, d, jt, jp, first), assumed, computed, inputs, authority,
                   (k, max_iterations), found, rho, open_cause(loop, found, stop, growth, first_box), excess)


def _round(loop: LoopData, jump_tick: Sequence[float], jump_period: Sequence[float], assumed: list | None,
           starts: tuple) -> tuple[list[list[float]], Inputs | None]:
    """One round of the fixed point: the computed bounds (and the model loop's inputs) under ``assumed`` (None: the
    jumps' own bounds), by Steps 4-5c, or by step 5d without a model feedforward (``starts``: the start terms of
    :func:`start_terms`, then :func:`verify.vehicle.pi_loop.free_start`'s)."""
    if loop.free is not None:
        zero = (0.0,) * len(loop.names)
        error, accel = ([r[0] for r in assumed], [r[3] for r in assumed]) if assumed is not None else (zero, zero)
        return free_bounds(loop, loop.free, jump_tick, jump_period, error, accel, starts[3]), None
    if assumed is None:
        return computed_bounds(loop, jump_tick, jump_period), None
    inputs = input_bounds(loop, [r[0] for r in assumed], [r[2] for r in assumed], [r[3] for r in assumed], *starts[:3])
    return computed_bounds(loop, jump_tick, jump_period, inputs), inputs


def _sway_command(params: VehicleParams, sway: Sequence[float]) -> tuple[float, float, float]:
    """(V_v, per-tick jump, per-period jump) of the sway command, checked: each >= 0, the period's jump the larger,
    all 0 without lateral thrust (ConfigError naming ``sway``)."""
    values = triple("sway", sway)
    if any(x < 0.0 for x in values):
        raise ConfigError("sway", "three numbers >= 0 (m/s): V_v, per-tick and per-period jumps", sway)
    if any(values) and not getattr(params, "lateral", False):
        raise ConfigError("sway", "(0, 0, 0) on a vehicle without lateral thrust (Y_max = 0)", sway)
    return values[0], values[1], max(values[1], values[2])


def _result(loop: LoopData, params: VehicleParams, given: tuple, assumed: list, computed: list, inputs: Inputs | None,
            authority: tuple, iterations: tuple[int, int], found: bool, rho: tuple | None,
            why_open: str = "", surge_excess: float | None = None) -> LoopBound:
    """The :class:`LoopBound` with every condition of the theorem (bounds +inf when not certified); ``surge_excess``:
    :func:`command_excess` of a vehicle whose thrust is tied to its drag (None: not tied, or no bound)."""
    v, h, d, jt, jp, first = given
    lat = loop.lateral
    error = without_sway(tuple(r[0] for r in computed), lat) if found else (math.inf,) * 3
    if not found:
        gamma = math.inf
    elif lat:  # the sway loop's own error bound E_v (its command is 0)
        gamma = computed[1][0]
    else:
        gamma = upper(hull_sway_bound(params, upper(arb(v[0]) + arb(error[0])), upper(arb(v[2]) + arb(error[2])),
                                      loop.surge_low(error[0])))
    conds = free_stability(loop) if loop.free is not None else [
        Condition(f"loop_stable[{ax}]", "||A_d^K||_inf < 1 (the sampled loop is stable; geometric tail)", s.rho, 1.0,
                  s.stable, f"K = {s.terms} ticks summed term by term, A_d = exp(A h) in Arb, lambda_{ax} = {lam:.4g} "
                  "1/s") for ax, s, lam in zip(loop.names, loop.sums, loop.slope)]
    ratio = max(computed[c][o] / assumed[c][o] for c in range(len(loop.names)) for o in range(4)) \
        if loop.stable else None
    if ratio is not None and not math.isfinite(ratio):
        ratio = None
    conds.append(Condition("loop_fixed_point", "max computed/assumed of (sup|e|, sup|a|, sup|z|, sup|ydot|) < 1 "
                           "(first exit)", ratio, 1.0, found, f"{iterations[0]} iterations (at most {iterations[1]})"
                           + (f"; {why_open}" if why_open else "")))
    conds += saturation_conditions(loop, params, v, assumed, closed=found or not loop.stable,
                                   surge_excess=surge_excess)
    how = ("E_v of the sway loop (lateral thrust regulates the sway to 0)" if lat else
           "hull_sway_bound over |u| <= V_u + E_u (u >= u_min − E_u under a surge floor), |r| <= V_r + E_r and Θ")
    conds.append(Condition("loop_sway", "gamma_bar finite (sway damped over the box)" if not lat else
                           "gamma_bar = E_v finite (the sway loop's error bound)", gamma, None, math.isfinite(gamma),
                           how if found else "not evaluated: no loop bound E (root cause: loop_fixed_point)"))
    if rho is not None:
        conds += rate_authority_conditions(authority, rho)
    failed = [c.condition for c in conds if c.ok is not True]
    inf = (math.inf,) * 3
    pick = (lambda o: without_sway(tuple(r[o] for r in computed), lat) if found else inf)
    per = (lambda x: without_sway(x, lat) if inputs else inf)
    return LoopBound(v_max=v, tick=h, period=d, jump_tick=jt, jump_period=jp, error=error, sway=gamma,
                     a_bound=pick(1), z_bound=pick(2), accel_bound=pick(3), assumed=tuple(tuple(r) for r in assumed),
                     w_start=per(inputs.start if inputs else None), w_rate=per(inputs.rate if inputs else None),
                     w_n=per(inputs.drag if inputs else None), gains=loop.sums, slope=loop.slope,
                     channels=loop.names,
                     authority=tuple(authority),
                     thrust_peak=tuple(c.lhs if c.lhs is not None else math.inf for c in conds
                                       if c.condition.startswith("loop_saturation")),
                     thrust_floor=tuple(c.rhs for c in conds if c.condition.startswith("loop_saturation")),
                     iterations=iterations[0], conditions=tuple(conds), first_command=first,
                     reason="" if not failed else "not certified: " + ", ".join(failed))
