"""The velocity loop without a model feedforward (``loop_feedforward = "none"``): a frozen-slope bound.

With τ_cmd = m̂_c a, a = k_p e + k_i I, the plant m_c ẏ = τ − n_c(ν) and the lag T τ̇ = τ_cmd − τ, put
D* = −n_c(ν*)/m̂_c (the force the integrator must hold at the command ν*, constant between the command's jumps),
Ĩ = I + D*/k_i, z = (τ − τ_cmd)/m̂_c and μ = m̂_c/m_c. By the mean value theorem along the channel's own direction,
then the others, (n_c(ν*) − n_c(ν))/m̂_c = κ e + r_0 with κ = ∂_c n_c(ν*)/m̂_c (the true drag's own slope at the
command), |r_0| <= Σ_{j≠c} sup|∂_j n_c| |ν*_j − ν_j| / m̂_c + sup|∂²_cc n_c| e² / (2 m̂_c). Then x = (Ĩ, e, z) obeys,
between the command's jumps and for any constant κ̄,

    ẋ = A(μ, κ̄) x + μ (0, −1, k_p) ((κ − κ̄) e + r_0),    ẏ = μ (k_i, k_p + κ, 1) x + μ r_0,
    A(μ, κ̄) = [[0, 1, 0], [−μ k_i, −μ (k_p + κ̄), −μ], [μ k_p k_i, μ k_p (k_p + κ̄) − k_i, μ k_p − 1/T]],

and a command jump (ΔJ in the channel, Δn_c = n_c(ν*⁺) − n_c(ν*⁻)) moves x by ΔJ (0, 1, −k_p) − Δn_c/(m̂_c k_i)
(1, 0, 0): e jumps, τ does not, the integrator's target moves. At a time t freeze κ̄ = κ(t): the drag is damping
(κ >= 0 on a passive hull) and it changes only as the command moves, so |κ(s) − κ(t)| <= Σ_j H_j |ν*_j(s) − ν*_j(t)|
(H_j = sup|∂_j ∂_c n_c| / m̂_c over the command box), at most the command's jumps between s and t; the residual is
the product of that with |e| <= E, not of a slope range with the acceleration. The response sums of
:func:`verify.vehicle.response.impulse_sums` are taken over balls of (μ, κ̄) covering their ranges
(:data:`MASS_PIECES` x :data:`SLOPE_PIECES`), with the moments (``moments=True``) weighting each tick by the jumps an
age holds (``docs/verify.md`` section 9, step 5d). Nothing here depends on sup|ẏ|: the channels couple only
through r_0's E_j, and the fixed point of :func:`verify.vehicle.bound.velocity_loop_bound` closes where the
jumps' own response does.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Callable, Protocol, Sequence

from flint import arb, ctx

from verify.kernel.intervals import upper
from verify.theorem.design import Condition
from verify.vehicle.cells import split_ball
from verify.vehicle.model import channel_forces, channel_gradient, channel_hessian, velocity_box
from verify.vehicle.response import RESPONSE_PREC, ResponseSums, impulse_sums

__all__ = ["MASS_STEP", "MASS_PIECES", "SLOPE_STEP", "SLOPE_PIECES", "TAIL_TOLERANCE", "BOX_PIECES", "OWN_PIECES",
           "Piece", "ChannelFacts", "channel_facts", "free_start", "free_bounds", "free_stability", "free_why_open"]

#: Width of the pieces the mass ratio μ = m̂_c/m_c is cut into (at most :data:`MASS_PIECES`; a point: one).
MASS_STEP = 0.05
MASS_PIECES = 8
#: Width (1/s) of the pieces the own slope κ̄ is cut into over its range at the command box (at most
#: :data:`SLOPE_PIECES`).
SLOPE_STEP = 0.8
SLOPE_PIECES = 12
#: The response sums stop term by term once ‖A_d^i‖_∞ is below this (the tail is bounded beyond).
TAIL_TOLERANCE = 1e-6


class _Loop(Protocol):
    """What the bound reads of the loop's fixed data (:class:`verify.vehicle.loop_data.LoopData`)."""

    lateral: bool
    names: str
    own: tuple[int, ...]
    hull: dict
    m_hat: tuple[arb, ...]
    m_true: tuple[arb, ...]
    v_int: tuple[float, ...]
    gains: tuple[tuple[float, float], ...]
    lag: float
    tick: float
    ticks: int

    @property
    def free(self) -> tuple["ChannelFacts", ...] | None: ...

    def box(self, error: Sequence[float]) -> tuple[tuple[float, float, float], float]: ...


@dataclasses.dataclass(frozen=True)
class Piece:
    """One comparison system A(μ_m, κ̄) at the midpoints of a piece of the mass ratio's and the own slope's ranges,
    with what the piece leaves: ``mass_residual`` = sup|1 − μ_m/μ| over its μ, ``slope_half`` = the half-width of its
    κ (1/s). Its sums' columns: the jump (−κ̄/k_i, 1, −k_p), the integrator's kick (1/k_i, 0, 0), the residual
    (0, −1, k_p); rows: e, (k_i, k_p, 0), z, μ_m (k_i, k_p + κ̄, 1)."""

    mu: float
    kappa: float
    mass_residual: float
    slope_half: float
    sums: ResponseSums


@dataclasses.dataclass(frozen=True)
class ChannelFacts:
    """A channel's data that the fixed point does not change (per unit of m̂_c where a force).

    Attributes
    ----------
    pieces : tuple of Piece
    slope_range : float
        κ_hi − κ_lo (1/s): no two own slopes at commands in V differ by more.
    mu_max : float
        sup μ.
    curvature : (4,) floats
        H_j = sup|∂_j ∂_c n_c| / m̂_c over the command box (1/s per m/s or per rad/s), j over ν = (u, v, w, r).
    cross : (4,) floats
        sup|∂_j n_c| / m̂_c over the command box, j ≠ c (0 at the channel's own index).
    drive : float
        sup|n_c(ν*)| / m̂_c over the command box (m/s², rad/s²): the integrator's largest hold, |D*|.
    """

    pieces: tuple[Piece, ...]
    slope_range: float
    mu_max: float
    curvature: tuple[float, float, float, float]
    cross: tuple[float, float, float, float]
    drive: float

    @property
    def stable(self) -> bool:
        """Every piece's sampled loop is proved stable."""
        return all(p.sums.stable for p in self.pieces)


def _command_box(loop: _Loop) -> tuple[arb, arb, arb, arb]:
    """The commands' box ν* (u, v, w, r): V, the sway command's |v_c| <= V_v (0 without lateral thrust)."""
    v = loop.v_int
    return velocity_box(v[0], v[1], v[2], v[3]) if loop.lateral else velocity_box(v[0], 0.0, v[1], v[2])


#: Pieces each body velocity of a box is cut into where an enclosure is taken piece by piece (:func:`_hull`): a
#: product of two wide balls (a coefficient's interval times a speed's) is enclosed loosely, a narrow speed's tightly.
BOX_PIECES = 3
#: Pieces of the channel's own speed: the drag's own slope −2 X_uu |u| is enclosed within about
#: sup|X_uu| (range of |u| in a piece) of its true range, so a fine cut keeps the slope's ball near its lower end 0.
OWN_PIECES = 48


def _hull(values: Callable[[tuple[arb, ...]], Sequence[arb]], box: Sequence[arb], own: int | None) -> list[arb]:
    """The union, entry by entry, of ``values`` over the sub-boxes of ``box`` cut into :data:`BOX_PIECES` per
    velocity (:data:`OWN_PIECES` along the channel's own, index ``own``, if any): every point of the box lies in one
    sub-box, so the union encloses the values over the box."""
    cuts = [split_ball(x, OWN_PIECES if j == own else BOX_PIECES) for j, x in enumerate(box)]
    out: list[arb] | None = None
    for sub in itertools.product(*cuts):
        got = list(values(sub))
        out = got if out is None else [a.union(b) for a, b in zip(out, got)]
    return out if out is not None else []


def _pieces(ball: arb, step: float, most: int) -> list[tuple[float, arb]]:
    """``ball`` cut into pieces of width at most ``step`` (at most ``most``, :func:`verify.vehicle.cells.split_ball`),
    each with its midpoint as a float."""
    width = float(ball.upper()) - float(ball.lower())
    return [(float(b.mid()), b) for b in split_ball(ball, max(1, min(most, math.ceil(width / step))))]


def channel_facts(loop: _Loop, c: int) -> ChannelFacts:
    """:class:`ChannelFacts` of channel ``c`` (an index into ``loop.names``)."""
    nu = _command_box(loop)
    own, m_hat = loop.own[c], loop.m_hat[c]
    lat = loop.lateral
    grads = _hull(lambda b: channel_gradient(loop.hull, b, lat)[c], nu, own)
    hess = _hull(lambda b: channel_hessian(loop.hull, b, lat)[c][own], nu, None)
    kappa = grads[own] / m_hat
    mu = m_hat / loop.m_true[c]
    kp, ki = loop.gains[c]
    pieces = tuple(Piece(m, k, upper(abs(1 - arb(m) / mu_ball)), upper(abs(k_ball - arb(k))),
                         _piece_sums(m, k, kp, ki, loop.lag, loop.tick, loop.ticks))
                   for m, mu_ball in _pieces(mu, MASS_STEP, MASS_PIECES)
                   for k, k_ball in _pieces(kappa, SLOPE_STEP, SLOPE_PIECES))
    drive = abs(_hull(lambda b: (channel_forces(loop.hull, b, lat)[c],), nu, None)[0]) / m_hat
    return ChannelFacts(pieces=pieces, slope_range=upper(kappa.upper() - kappa.lower()), mu_max=upper(mu),
                        curvature=tuple(upper(abs(x) / m_hat) for x in hess),
                        cross=tuple(0.0 if j == own else upper(abs(g) / m_hat) for j, g in enumerate(grads)),
                        drive=upper(drive))


def _piece_sums(mu: float, kappa: float, k_p: float, k_i: float, lag: float, tick: float,
                ticks: int) -> ResponseSums:
    """The response sums and moments of A(μ_m, κ̄) (module doc) at the points μ_m and κ̄."""
    with ctx.workprec(RESPONSE_PREC):
        kp, ki, t, m, k = arb(k_p), arb(k_i), arb(lag), arb(mu), arb(kappa)
        zero, one = arb(0), arb(1)
        a = [[zero, one, zero], [-m * ki, -m * (kp + k), -m], [m * kp * ki, m * kp * (kp + k) - ki, m * kp - 1 / t]]
        columns = [[-k / ki, one, -kp], [1 / ki, zero, zero], [zero, -one, kp]]
        rows = [[zero, one, zero], [ki, kp, zero], [zero, zero, one], [m * ki, m * (kp + k), m]]
        return impulse_sums(a, columns, rows, tick=tick, ticks_per_period=ticks, moments=True, tol=TAIL_TOLERANCE)


def free_start(loop: _Loop, first_command: Sequence[float], settled: bool) -> tuple[float, ...]:
    """sup|n_c(ν(0))| / m̂_c per channel over the first command's box, v(0) = 0 (m/s², rad/s²): the trimmed start
    holds τ = 0 and I = 0, so Ĩ(0) = D*(0)/k_i; zeros for a settled start (x(0) = 0)."""
    if settled:
        return (0.0,) * len(loop.names)
    nu = velocity_box(first_command[0], 0.0, first_command[1], first_command[2])
    forces = channel_forces(loop.hull, nu, loop.lateral)
    return tuple(upper(abs(f) / m) for f, m in zip(forces, loop.m_hat))


def _by_velocity(loop: _Loop, per_channel: Sequence[float]) -> tuple[float, float, float, float]:
    """Per-channel values (``loop.names`` order) as values per body velocity (u, v, w, r); 0 for the free sway."""
    out = [0.0, 0.0, 0.0, 0.0]
    for c, j in enumerate(loop.own):
        out[j] = float(per_channel[c])
    return out[0], out[1], out[2], out[3]


def free_bounds(loop: _Loop, facts: Sequence[ChannelFacts], jump_tick: Sequence[float],
                jump_period: Sequence[float], error: Sequence[float], accel: Sequence[float],
                start: Sequence[float]) -> list[list[float]]:
    """[sup|e|, sup|a|, sup|z|, sup|ẏ|] per channel (module doc), given the assumed errors ``error`` and
    accelerations ``accel`` (per channel, ``loop.names`` order): the largest over each channel's pieces."""
    box, gamma = loop.box(error)
    if not math.isfinite(gamma) or not all(math.isfinite(x) for x in (*box, *error)):
        return [[math.inf] * 4 for _ in loop.names]
    nu = velocity_box(box[0], gamma, box[1], box[2])
    grads = channel_gradient(loop.hull, nu, loop.lateral)
    hess = channel_hessian(loop.hull, nu, loop.lateral)
    apart = list(_by_velocity(loop, error))
    if not loop.lateral:
        apart[1] = gamma  # the free sway: |v − 0| <= γ̄
    jt_nu, jp_nu = _by_velocity(loop, jump_tick), _by_velocity(loop, jump_period)
    out = []
    for c, f in enumerate(facts):
        own, m_hat, e_c = loop.own[c], loop.m_hat[c], arb(error[c])
        r0 = sum((abs(g) / m_hat * arb(apart[j]) for j, g in enumerate(grads[c]) if j != own), arb(0))
        r0 += abs(hess[c][own][own]) / m_hat * e_c * e_c / 2
        drives = _Drives.of(f, own, jt_nu, jp_nu, jump_tick[c], jump_period[c])
        y_dot = arb(accel[c])
        rows = [max(_output(p, o, drives, r0, e_c, y_dot, arb(start[c]), arb(loop.tick), arb(f.slope_range))
                    for p in f.pieces) for o in range(4)]
        rows[1] = upper(arb(rows[1]) + arb(f.drive))
        out.append(rows)
    return out


@dataclasses.dataclass(frozen=True)
class _Drives:
    """A channel's jumps per tick and per period (own, then the cross force's X), and the own slope's spread per
    tick and per period boundary of an age (S_t, S_p: Σ_j H_j J_j)."""

    own_tick: arb
    own_rest: arb
    cross_tick: arb
    cross_rest: arb
    spread_tick: arb
    spread_period: arb

    @classmethod
    def of(cls, f: ChannelFacts, own: int, jt: Sequence[float], jp: Sequence[float], own_tick: float,
           own_period: float) -> _Drives:
        cross_t = sum((arb(x) * arb(j) for x, j in zip(f.cross, jt)), arb(0))
        cross_p = sum((arb(x) * arb(j) for x, j in zip(f.cross, jp)), arb(0))
        spread_t = sum((arb(x) * arb(j) for x, j in zip(f.curvature, jt)), arb(0))
        spread_p = sum((arb(x) * (arb(b) - arb(a)) for x, a, b in zip(f.curvature, jt, jp)), arb(0))
        return cls(arb(own_tick), arb(own_period) - arb(own_tick), cross_t, cross_p - cross_t, spread_t, spread_p)


def _output(p: Piece, o: int, d: _Drives, r0: arb, e_c: arb, y_dot: arb, start: arb, h: arb,
            slope_range: arb) -> float:
    """Output row ``o`` of one piece: the jumps, their integrator kicks (cross, and the own slope's move since the jump
    and within the piece), the residual (the mass within the piece times sup|ẏ|, the own slope's age-weighted change
    times E, r_0), the start; the ẏ row adds the residual at the instant itself (module doc)."""
    s = p.sums
    if not s.stable:
        return math.inf
    tick, period, mt, mp = s.tick[o], s.period[o], s.moment_tick, s.moment_period
    half, mu = arb(p.slope_half), arb(p.mu)

    def moved(col: int, sums_: Sequence[float], ticks_w: tuple, periods_w: tuple) -> arb:
        weighted = d.spread_tick * arb(ticks_w[o][col]) + d.spread_period * arb(periods_w[o][col])
        return weighted.min(slope_range * arb(sums_[col])) + half * arb(sums_[col])
    steady = arb(p.mass_residual) * y_dot + mu * r0  # the residual's part that does not move with the age
    x = d.own_tick * arb(tick[0]) + d.own_rest * arb(period[0])
    x += d.cross_tick * arb(tick[1]) + d.cross_rest * arb(period[1])
    x += d.own_tick * moved(1, tick, mt[0], mt[1]) + d.own_rest * moved(1, period, mp[0], mp[1])
    x += h * (steady * arb(tick[2]) + mu * e_c * moved(2, tick, mt[0], mt[1]))
    x += start * arb(s.peak[o][1])
    if o == 3:
        x += steady + mu * half * e_c
    return upper(x)


def free_stability(loop: _Loop) -> list[Condition]:
    """``loop_stable[c]``: every piece's A_d(μ_m, κ̄) is proved Schur stable (the largest ‖A_d^K‖_∞ over them)."""
    out = []
    for ax, f in zip(loop.names, loop.free or ()):
        worst = max(f.pieces, key=lambda p: p.sums.rho)
        out.append(Condition(f"loop_stable[{ax}]", "||A_d^K||_inf < 1 for every piece (mu, kappa) of the loop without "
                             "a model feedforward (geometric tail)", worst.sums.rho, 1.0, f.stable,
                             f"{len(f.pieces)} pieces, the largest at mu = {worst.mu:.4g}, kappa = {worst.kappa:.4g} "
                             f"1/s: K = {worst.sums.terms} ticks summed term by term, A_d = exp(A h) in Arb"))
    return out


def free_why_open(loop: _Loop, head: str) -> str:
    """Why the frozen-slope bound's fixed point did not close, in words an owner can act on (``head``: how it
    stopped)."""
    unstable = [ax for ax, f in zip(loop.names, loop.free or ()) if not f.stable]
    if unstable:
        return (f"{head}; the loop without a model feedforward is not proved stable in channel(s) {unstable} at some "
                "pieces of its drag slope and mass ratio (docs/verify.md section 9, step 5d): a faster loop "
                "(plant.vehicle.loop_bandwidth) or a narrower coefficient box")
    return (f"{head}; the channels drive one another through the cross forces' slopes times the other channels' "
            "errors, and each channel's own drag slope moves with the command (docs/verify.md section 9, step 5d): "
            "smaller command jumps (a lower plan rate), a smaller V or a narrower coefficient box lower it")
