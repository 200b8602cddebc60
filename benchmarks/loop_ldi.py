"""A study: the velocity loop's error bound as a polytopic differential inclusion (LDI), proved in Arb.

Usage::

    python benchmarks/loop_ldi.py

Not part of the certificate: it measures whether this bound, beside the small-gain fixed point of
:mod:`verify.vehicle.bound`, would extend what certifies (the BlueROV2 over wider coefficient boxes). Printed:
the per-channel gain from a command rate to the error with the channels decoupled, per coefficient box; then the
coupled fixed point against the small-gain bound on ``examples/bluerov2_slow.toml``'s command box for three jump
sizes, the small-gain bound with its start over V and with the first command within J of rest (``first_command``,
what the certificate uses when the backup blends).

**Model** (one channel c, y = u, w or r, as :mod:`verify.vehicle.bound`): m ẏ = τ − n(y, ν_o; θ),
τ̇ = (τ_cmd − τ)/T_thr, τ_cmd = n̂(y, ν_o) + m̂ (k_p e + k_i I), e = y* − y, İ = e, with ν_o the other body
velocities (the vehicle's, not commanded). The command y* is constant between ticks and jumps at them.
In the error coordinates about the command (scaled so every entry is an acceleration, m/s² or rad/s²)

    x = (k_p e, k_i (I − I_ss), (τ − n(y*, ν_o))/m̂),        I_ss = −d(y*, ν_o)/(m̂ k_i),  d = n̂ − n,

the integral state the mismatch needs in steady state is subtracted, so the mismatch does not enter as an
input that grows with the error (what makes the small-gain fixed point diverge). With κ̂ and κ the slopes of
n̂ and n in y averaged over [y*, y] (at ν_o),

    ẋ = A(κ̂, κ, 1/m) x + Σ_j ν̇_j g_j   between ticks,     x⁺ = x + J b(κ̂_J, κ_J)   at a jump J of y*,
    A = D [[−κ/m, 0, −m̂/m], [1, 0, 0], [(k_p − κ̂/m̂)/T, k_i/T, −1/T]] D⁻¹,   D = diag(k_p, k_i, 1),
    b = (k_p, (κ̂_J − κ_J)/m̂, −κ_J/m̂),   g_j = (0, ∂_j d/m̂, −∂_j n/m̂)   (j ≠ the channel's own speed).

The pair (κ̂, κ) is an average of pointwise slope pairs, so it lies in the convex hull of those pairs over the
velocity box and the coefficient box Θ (:func:`slope_pairs`: the own speed cut into pieces, each piece's
pair box enclosed in Arb, the hull's corners kept). A is affine in (κ̂, κ) and in 1/m, so A(t) lies in the
convex hull of the vertex matrices A_i (:func:`vertex_matrices`) at every instant.

**Lemma.** If P ≻ 0 and A_iᵀP + P A_i + 2λP ≺ 0 at every vertex (:func:`lyapunov_certified`: Sylvester's
minors in Arb), then s = √(xᵀPx) obeys ṡ <= −λ s + ‖w‖_P between ticks and s⁺ <= s⁻ + |J| ‖b‖_P at a jump.
With q = e^{−λh}, N ticks per period, per-tick jumps J_t and period jumps J_p >= J_t,

    s <= S_0 + W/λ + J_t B/(1 − q) + (J_p − J_t) B/(1 − q^N)         for all t >= 0,

S_0 = ‖x(0)‖_P (the trimmed start x(0) = (d/m̂)(0, 1, 1)), B = max_i ‖b_i‖_P, W = Σ_j Ŷ_j ‖g_j‖_P. Every
output o = c_oᵀx obeys |o| <= √(c_oᵀP⁻¹c_o) s (Cauchy–Schwarz): e (c = (1/k_p, 0, 0)), a = k_p e + k_i I
(c = (1, 1, 0), plus sup|d|/m̂), z = (τ − τ_cmd)/m̂ and ẏ (c at the vertices). P is *found* by a
semidefinite program (cvxpy + Clarabel, :class:`LyapunovSearch`); only the Arb check makes it a proof.

The box in which the slopes are taken is the command box V plus an assumed error cap E_cap: the first-exit
argument of :mod:`verify.vehicle.bound` closes it (:func:`ldi_fixed_point` certifies only when every computed
bound is strictly below its assumption).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
from flint import arb, arb_mat, ctx

from scipy.spatial import ConvexHull, QhullError

from tubekit.model.vehicle_params import VehicleParams
from tubekit.model.vehicles import VEHICLES
from verify.kernel.intervals import enclose, lower, upper
from verify.theorem.design import hull_sway_bound
from verify.vehicle.bound import _rates, velocity_loop_bound
from verify.vehicle.loop_data import loop_data_of
from verify.vehicle.model import (channel_gradient, channel_masses, channel_mismatch, channel_mismatch_gradient,
                                  hull_balls, nominal_balls, velocity_box)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from dynamic_gap import _box  # noqa: E402 - von Benzon's values ± a fraction, as the other loop studies use them

__all__ = ["LdiChannel", "LdiBound", "slope_pairs", "vertex_matrices", "LyapunovSearch", "ChannelData", "ldi_bound", "lyapunov_certified",
           "channel_lyapunov", "ldi_fixed_point", "OBJECTIVES", "unit_rate_gain", "study_bound", "main", "SLOPE_PIECES", "DECAY_GRID", "CAP_FRACTIONS"]

#: Pieces the own speed's range is cut into for the slope pairs (more: a tighter hull, more vertices).
SLOPE_PIECES = 24
#: Decay rates λ (1/s) the SDP tries; the one with the smallest jump gain √γ/(1 − e^{−λh}) is kept.
DECAY_GRID = (0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)
#: Error caps E_cap = f V tried in turn (the box the slopes are taken over); the first that closes is kept.
CAP_FRACTIONS = (0.1, 0.25, 0.5, 1.0)
#: The decay rate proved is this fraction of the one the SDP was solved at (room for the Arb check).
DECAY_MARGIN = 0.98
_OWN = (0, 2, 3)


@dataclass(frozen=True)
class LdiChannel:
    """One channel's certified Lyapunov function and its gains (all upper bounds, floats rounded up).

    Attributes
    ----------
    decay : float
        λ (1/s) proved at every vertex.
    matrix : tuple of tuples
        P (3 x 3, in the scaled coordinates of the module doc).
    vertices : int
        Number of vertex matrices A_i checked.
    jump_gain : float
        B = max ‖b_i‖_P, per unit jump of the command (m/s or rad/s).
    start_gain : float
        S_0 = ‖x(0)‖_P for the trimmed start.
    coupling_gain : (4,) floats
        ‖g_j‖_P per unit |ν̇_j| for j in (u, v, w, r) (0 for the channel's own speed).
    outputs : (4,) floats
        √(cᵀP⁻¹c) for e, a, z, ẏ.
    mismatch : float
        sup|d|/m̂ (added to the a bound).
    """

    decay: float
    matrix: tuple[tuple[float, ...], ...]
    vertices: int
    jump_gain: float
    start_gain: float
    coupling_gain: tuple[float, float, float, float]
    outputs: tuple[float, float, float, float]
    mismatch: float

    def level(self, jump_tick: float, jump_period: float, tick: float, ticks: int, coupling: float) -> float:
        """The bound on s = √(xᵀPx) of the module doc for the given jumps and W = ``coupling``:
        max(S_0 + J_p B, s_∞), s_∞ = W/λ + J_t B/(1 − q) + (J_p − J_t) B/(1 − q^N)."""
        q = math.exp(-self.decay * tick)
        steady = (coupling / self.decay + jump_tick * self.jump_gain / (1.0 - q)
                  + (jump_period - jump_tick) * self.jump_gain / (1.0 - q ** ticks))
        return max(self.start_gain + jump_period * self.jump_gain, steady) * (1.0 + 1e-12)


@dataclass(frozen=True)
class LdiBound:
    """The fixed point of :func:`ldi_fixed_point`: bounds per channel (rows e, a, z, ẏ) and what they rest on.

    ``channels[c]``: channel c's certified P's, one per objective of :data:`OBJECTIVES` (None where none was).
    ``closed`` False: ``bounds`` are +inf and ``why`` says what stood in the way.
    """

    closed: bool
    cap: tuple[float, float, float]
    bounds: tuple[tuple[float, float, float, float], ...]
    channels: tuple[tuple[LdiChannel | None, ...], ...]
    iterations: int
    why: str = ""

    @property
    def error(self) -> tuple[float, float, float]:
        """(E_u, E_w, E_r)."""
        return tuple(r[0] for r in self.bounds)


def slope_pairs(nominal: dict, hull: dict, nu: Sequence[arb], channel: int,
                pieces: int = SLOPE_PIECES) -> np.ndarray:
    """Corners of the convex hull of the pointwise slope pairs (∂n̂_c/∂y_c, ∂n_c/∂y_c) over ``nu`` and Θ.

    The own speed's range is cut into ``pieces``; on each, both slopes are enclosed in Arb (every other
    velocity over its whole range) and the four corners of the pair box kept (exact floats, rounded outward).
    """
    own = _OWN[channel]
    lo, hi = lower(nu[own]), upper(nu[own])
    corners = []
    for i in range(pieces):
        sub = list(nu)
        sub[own] = enclose(lo + (hi - lo) * i / pieces, lo + (hi - lo) * (i + 1) / pieces)
        k_hat, k = channel_gradient(nominal, sub)[channel][own], channel_gradient(hull, sub)[channel][own]
        corners += [(x, y) for x in (lower(k_hat), upper(k_hat)) for y in (lower(k), upper(k))]
    pts = np.unique(np.array(corners, dtype=float), axis=0)
    try:
        return pts[ConvexHull(pts).vertices]
    except (QhullError, ValueError):
        return pts


def _scaled_matrix(k_p: arb, k_i: arb, lag: arb, m_hat: arb, k_hat: arb, k: arb, inv_mass: arb) -> list[list[arb]]:
    """D A D⁻¹ of the module doc (1/s)."""
    a = [[-k * inv_mass, arb(0), -m_hat * inv_mass], [arb(1), arb(0), arb(0)],
         [(k_p - k_hat / m_hat) / lag, k_i / lag, -1 / lag]]
    d = (k_p, k_i, arb(1))
    return [[d[r] * a[r][c] / d[c] for c in range(3)] for r in range(3)]


def vertex_matrices(k_p: float, k_i: float, lag: float, m_hat: arb, pairs: np.ndarray,
                    inv_mass: tuple[float, float]) -> list[list[list[arb]]]:
    """The vertex matrices A_i (Arb) at every slope pair corner and both ends of 1/m."""
    kp, ki, t = arb(k_p), arb(k_i), arb(lag)
    return [_scaled_matrix(kp, ki, t, m_hat, arb(p[0]), arb(p[1]), arb(w)) for p in pairs for w in inv_mass]


def _jump_vectors(k_p: float, m_hat: arb, pairs: np.ndarray) -> list[list[arb]]:
    """b at every slope pair corner (the jump direction is affine in the pair)."""
    return [[arb(k_p), (arb(p[0]) - arb(p[1])) / m_hat, -arb(p[1]) / m_hat] for p in pairs]


def _floats(m: list[list[arb]]) -> np.ndarray:
    return np.array([[float(x.mid()) for x in row] for row in m])


class LyapunovSearch:
    """The SDP that proposes P for one vertex set, built once (λ a cvxpy Parameter, DPP) and solved per λ:
    P ≻ 0 with A_iᵀP + PA_i + 2λP ⪯ 0, ‖b_j‖_P <= 1, minimising max_c cᵀP⁻¹c over the output rows c. Only :func:`lyapunov_certified` decides.
    """

    def __init__(self, mats: Sequence[np.ndarray], jumps: Sequence[np.ndarray], outputs: Sequence[np.ndarray]) -> None:
        import cvxpy as cp
        self._cp = cp
        self.p, g, self.decay = cp.Variable((3, 3), symmetric=True), cp.Variable(), cp.Parameter(nonneg=True)
        cons = [self.p >> 1e-9 * np.eye(3)]
        cons += [a.T @ self.p + self.p @ a + 2.0 * self.decay * self.p << 0 for a in mats]
        cons += [cp.quad_form(b, self.p) <= 1.0 for b in jumps]
        cons += [cp.bmat([[cp.reshape(g, (1, 1), order="C"), c[None, :]], [c[:, None], self.p]]) >> 0 for c in outputs]
        self.problem = cp.Problem(cp.Minimize(g), cons)

    def solve(self, decay: float) -> np.ndarray | None:
        """P at decay rate ``decay`` (1/s), or None when the SDP does not solve."""
        cp = self._cp
        self.decay.value = decay
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                self.problem.solve(solver="CLARABEL")
            except cp.error.SolverError:
                return None
        if self.problem.status != cp.OPTIMAL or self.p.value is None:
            return None
        value = 0.5 * (self.p.value + self.p.value.T)
        return value if np.all(np.isfinite(value)) else None


def _positive_definite(m: list[list[arb]]) -> bool:
    """Sylvester: every leading principal minor of the symmetric 3 x 3 ``m`` is > 0 (in Arb)."""
    d1 = m[0][0]
    d2 = m[0][0] * m[1][1] - m[0][1] * m[1][0]
    d3 = arb_mat(m).det()
    return all(lower(d) > 0 for d in (d1, d2, d3))


def lyapunov_certified(p: Sequence[Sequence[float]], mats: Sequence[list[list[arb]]], decay: float) -> bool:
    """P ≻ 0 and −(A_iᵀP + PA_i + 2λP) ≻ 0 at every vertex, decided in Arb (P's floats are exact)."""
    pa = [[arb(float(x)) for x in row] for row in p]
    if any(pa[r][c] != pa[c][r] for r in range(3) for c in range(3)) or not _positive_definite(pa):
        return False
    lam = arb(decay)
    for a in mats:
        pa_a = [[sum((pa[r][k] * a[k][c] for k in range(3)), arb(0)) for c in range(3)] for r in range(3)]
        neg = [[-(pa_a[c][r] + pa_a[r][c] + 2 * lam * pa[r][c]) for c in range(3)] for r in range(3)]
        if not _positive_definite(neg):
            return False
    return True


def _p_norm(p: list[list[arb]], v: Sequence[arb]) -> float:
    """‖v‖_P = √(vᵀPv), rounded up (v's entries may be balls)."""
    q = upper(sum((v[r] * p[r][c] * v[c] for r in range(3) for c in range(3)), arb(0)))
    return upper(arb(q).sqrt()) if q > 0 else 0.0


def _dual_norm(p: list[list[arb]], c: Sequence[arb]) -> float:
    """√(cᵀP⁻¹c), rounded up."""
    col = arb_mat([[x] for x in c])
    sol = arb_mat(p).solve(col)
    q = upper(sum((c[r] * sol[r, 0] for r in range(3)), arb(0)))
    return upper(arb(q).sqrt()) if q > 0 else 0.0


@dataclass(frozen=True)
class ChannelData:
    """What a channel's Lyapunov search reads: gains, masses, the slope corners, the mismatch and couplings."""

    k_p: float
    k_i: float
    lag: float
    tick: float
    m_hat: arb
    inv_mass: tuple[float, float]
    pairs: np.ndarray
    mismatch: float
    coupling: tuple[tuple[arb, arb, arb], ...]


#: The outputs a channel's P may be shaped for: the error e (row 0 of the gains) or the acceleration ẏ (row 3).
OBJECTIVES = {"e": 0, "ydot": 3}


def _objective_rows(data: ChannelData, objective: str) -> list[np.ndarray]:
    """The output rows c the SDP minimises √(cᵀP⁻¹c) over: e's, or ẏ's at every slope corner and 1/m end."""
    if objective == "e":
        return [np.array([1.0 / data.k_p, 0.0, 0.0])]
    m_hat = float(data.m_hat.mid())
    return [np.array([w * p[1] / data.k_p, 0.0, w * m_hat]) for p in data.pairs for w in data.inv_mass]


def channel_lyapunov(data: ChannelData, objective: str = "e") -> LdiChannel | None:
    """The certified P and gains of one channel, P shaped for ``objective`` (``"e"`` or ``"ydot"``): the SDP at
    each λ of :data:`DECAY_GRID`, the smallest steady gain of that output per unit jump that the Arb check
    confirms (None when no λ is confirmed)."""
    row = OBJECTIVES[objective]
    with ctx.workprec(128):
        mats = vertex_matrices(data.k_p, data.k_i, data.lag, data.m_hat, data.pairs, data.inv_mass)
        jumps = _jump_vectors(data.k_p, data.m_hat, data.pairs)
        f_mats, f_jumps = [_floats(a) for a in mats], [np.array([float(x.mid()) for x in b]) for b in jumps]
        search = LyapunovSearch(f_mats, f_jumps, _objective_rows(data, objective))
        best, best_score = None, math.inf
        for decay in DECAY_GRID:
            p = search.solve(decay)
            if p is None:
                break
            proved = decay * DECAY_MARGIN
            if not lyapunov_certified(p, mats, proved):
                continue
            channel = _gains(data, p, proved, mats, jumps)
            score = channel.outputs[row] * channel.jump_gain / (1.0 - math.exp(-proved * data.tick))
            if score < best_score:
                best, best_score = channel, score
        return best


def _gains(data: ChannelData, p: np.ndarray, decay: float, mats: list, jumps: list) -> LdiChannel:
    """The gains of the module doc for a certified P."""
    pa = [[arb(float(x)) for x in row] for row in p]
    kp, m_hat = arb(data.k_p), data.m_hat
    jump = max(_p_norm(pa, b) for b in jumps)
    start = _p_norm(pa, [arb(0), arb(1), arb(1)]) * data.mismatch
    coupling = tuple(0.0 if g is None else _p_norm(pa, g) for g in data.coupling)
    k_hats = sorted({float(x[0]) for x in data.pairs})
    e = _dual_norm(pa, [1 / kp, arb(0), arb(0)])
    a = _dual_norm(pa, [arb(1), arb(1), arb(0)])
    z = max(_dual_norm(pa, [-(1 - arb(k) / (m_hat * kp)), arb(-1), arb(1)]) for k in (k_hats[0], k_hats[-1]))
    ydot = max(_dual_norm(pa, [arb(w) * arb(x[1]) / kp, arb(0), arb(w) * m_hat])
               for x in data.pairs for w in data.inv_mass)
    return LdiChannel(decay=decay, matrix=tuple(tuple(float(x) for x in row) for row in p), vertices=len(mats),
                      jump_gain=jump, start_gain=start, coupling_gain=coupling, outputs=(e, a, z, ydot),
                      mismatch=data.mismatch)


def _channel_bounds(shapes: Sequence[LdiChannel], c: int, rates: Sequence[float], jump_tick: float,
                    jump_period: float, tick: float, ticks: int) -> tuple[float, float, float, float]:
    """(e, a, z, ẏ) of channel ``c``: each the smallest over the certified P's ``shapes`` (each P's bound holds)."""
    rows = []
    for ch in shapes:
        coupling = sum(g * r for j, (g, r) in enumerate(zip(ch.coupling_gain, rates)) if j != _OWN[c])
        s = ch.level(jump_tick, jump_period, tick, ticks, coupling)
        e, a, z, ydot = (x * s for x in ch.outputs)
        rows.append((e, a + ch.mismatch, z, ydot))
    return tuple(min(r[o] for r in rows) for o in range(4))


def ldi_fixed_point(channels: Sequence[Sequence[LdiChannel | None]], cap: Sequence[float], sway_rate,
                    jump_tick: Sequence[float], jump_period: Sequence[float], tick: float, ticks: int,
                    max_iterations: int = 60) -> LdiBound:
    """Bounds (e, a, z, ẏ) per channel over the box with error cap ``cap``, closed by first exit.

    ``channels[c]`` holds the certified P's of channel c (one per objective; None where none was certified).
    ``sway_rate(accel)`` bounds |v̇| given (|u̇|, |ẇ|, |ṙ|) bounds. The coupling of channel c is
    W_c = Σ_j ‖g_j‖_P |ν̇_j| with the other channels' ẏ bounds and |v̇|; the accelerations are iterated from
    0 (then 5 % above the last computed) until every computed bound is strictly below its assumption and E < cap.
    """
    inf4 = (math.inf,) * 4
    shapes = [tuple(p for p in ps if p is not None) for ps in channels]
    if not all(shapes):
        missing = [ax for ax, ps in zip("uwr", shapes) if not ps]
        return LdiBound(False, tuple(cap), (inf4,) * 3, tuple(channels), 0,
                        f"no common Lyapunov function certified for channel(s) {', '.join(missing)}")
    accel = [0.0, 0.0, 0.0]
    bounds = [inf4] * 3
    for k in range(1, max_iterations + 1):
        rates = (accel[0], sway_rate(accel), accel[1], accel[2])
        bounds = [_channel_bounds(shapes[c], c, rates, jump_tick[c], jump_period[c], tick, ticks) for c in range(3)]
        if not all(math.isfinite(x) for row in bounds for x in row):
            break
        if all(bounds[c][0] < cap[c] for c in range(3)) and all(bounds[c][3] < accel[c] for c in range(3)):
            return LdiBound(True, tuple(cap), tuple(bounds), tuple(channels), k)
        accel = [max(a, 1.05 * b[3] + 1e-12) for a, b in zip(accel, bounds)]
    worst = max(range(3), key=lambda c: bounds[c][0] / cap[c] if math.isfinite(bounds[c][0]) else math.inf)
    return LdiBound(False, tuple(cap), (inf4,) * 3, tuple(channels), max_iterations,
                    f"E_{'uwr'[worst]} = {bounds[worst][0]:.4g} not below the cap {cap[worst]:.4g}")


def _channel_data(params: VehicleParams, box: Sequence[float], gamma: float, c: int, k_p: float, k_i: float,
                  lag: float, tick: float) -> ChannelData:
    """The inputs of :func:`channel_lyapunov` for channel ``c`` over |ν| <= (box_u, γ̄, box_w, box_r) and Θ."""
    nominal, hull = nominal_balls(params), hull_balls(params)
    nu = velocity_box(box[0], gamma, box[1], box[2])
    m_hat, m_true = channel_masses(nominal)[c], channel_masses(hull)[c]
    d = channel_mismatch(nominal, hull, nu)[c]
    d_grad, n_grad = channel_mismatch_gradient(nominal, hull, nu)[c], channel_gradient(hull, nu)[c]
    coupling = tuple(None if j == _OWN[c] else (arb(0), d_grad[j] / m_hat, -n_grad[j] / m_hat) for j in range(4))
    return ChannelData(k_p=k_p, k_i=k_i, lag=lag, tick=tick, m_hat=m_hat,
                       inv_mass=(lower(1 / m_true), upper(1 / m_true)), pairs=slope_pairs(nominal, hull, nu, c),
                       mismatch=upper(abs(d) / m_hat), coupling=coupling)


@functools.lru_cache(maxsize=64)
def _channels_at(params: VehicleParams, box: tuple[float, float, float], gamma: float, k_p: float, k_i: float,
                 lag: float, tick: float) -> tuple[tuple[LdiChannel | None, ...], ...]:
    """:func:`channel_lyapunov` of every channel over one box, one P per objective, memoised (the SDPs are the
    costly part)."""
    data = [_channel_data(params, box, gamma, c, k_p, k_i, lag, tick) for c in range(3)]
    return tuple(tuple(channel_lyapunov(d, objective) for objective in OBJECTIVES) for d in data)


def ldi_bound(params: VehicleParams, *, v_max: Sequence[float], k_p: float, k_i: float, lag: float, tick: float,
              ticks: int, jump_tick: Sequence[float], jump_period: Sequence[float],
              sway_bound, sway_rate) -> LdiBound:
    """The LDI bound over the command box ``v_max``: the caps E_cap = f V of :data:`CAP_FRACTIONS` in turn.

    ``sway_bound(u_bar, r_bar)`` is γ̄ over the box (m/s); ``sway_rate(box, gamma, accel)`` bounds |v̇|.
    Returns the first cap whose fixed point closes, else the last attempt (``closed`` False).
    """
    last = None
    for f in CAP_FRACTIONS:
        cap = tuple(max(f * float(v), 1e-3) for v in v_max)
        box = tuple(upper(arb(float(v)) + arb(e)) for v, e in zip(v_max, cap))
        gamma = float(sway_bound(box[0], box[2]))
        if not math.isfinite(gamma):
            last = LdiBound(False, cap, ((math.inf,) * 4,) * 3, (None,) * 3, 0, "the hull's sway is not bounded")
            continue
        channels = _channels_at(params, box, gamma, float(k_p), float(k_i), float(lag), float(tick))
        last = ldi_fixed_point(channels, cap, lambda accel, b=box, g=gamma: sway_rate(b, g, accel),
                               jump_tick, jump_period, tick, ticks)
        if last.closed:
            return last
    return last


def unit_rate_gain(channel: LdiChannel, tick: float) -> float:
    """sup|e| per unit command rate (s) with the channel decoupled: jumps of h at every tick, no start, no coupling."""
    return channel.outputs[0] * channel.jump_gain * tick / (1.0 - math.exp(-channel.decay * tick))


def study_bound(params: VehicleParams, v_max: Sequence[float], jump_tick: Sequence[float],
                jump_period: Sequence[float], tick: float = 0.01, ticks: int = 10) -> LdiBound:
    """:func:`ldi_bound` for a vehicle with the gains, lag, sway bound and sway rate of :mod:`verify.vehicle.bound`."""
    loop = loop_data_of(params, tuple(v_max), tick, ticks)

    def sway_rate(box: Sequence[float], gamma: float, accel: Sequence[float]) -> float:
        return upper(_rates(loop, velocity_box(box[0], gamma, box[1], box[2]), accel)[1])
    return ldi_bound(params, v_max=v_max, k_p=loop.k_p, k_i=loop.k_i, lag=loop.lag, tick=tick, ticks=ticks,
                     jump_tick=jump_tick, jump_period=jump_period,
                     sway_bound=lambda u, r: upper(hull_sway_bound(params, u, r)), sway_rate=sway_rate)


def _boxes():
    """(label, vehicle): von Benzon's point, ±5 %, ±10 %, ±20 %, the published box (benchmarks/dynamic_gap.py), each
    without lateral thrust (``Y_max`` = 0): this study's channels are u, w, r with the hull's free sway."""
    yield from ((f"von Benzon ±{round(f * 100)} %", dataclasses.replace(_box(f), Y_max=0.0))
                for f in (0.0, 0.05, 0.1, 0.2))
    yield "published box", dataclasses.replace(VEHICLES["bluerov2_heavy"], Y_max=0.0)


def main() -> int:
    slow_v, plans = (0.3, 0.15, 0.2), (0.003, 0.003, 0.006)
    print("decoupled gain sup|e| per unit command rate (s), u / w / r, and the decay rate proved (1/s); V = (0.4, "
          "0.3, 0.3) + 10 %")
    for label, params in _boxes():
        loop = loop_data_of(params, (0.4, 0.3, 0.3), 0.01, 10)
        box = (0.44, 0.33, 0.33)
        chans = [ps[0] for ps in _channels_at(params, box, upper(hull_sway_bound(params, box[0], box[2])),
                                              loop.k_p, loop.k_i, loop.lag, 0.01)]
        print(f"  {label:22s}", " / ".join("none" if c is None else f"{unit_rate_gain(c, 0.01):.3f}" for c in chans),
              "  decay", " / ".join("-" if c is None else f"{c.decay:.3g}" for c in chans))
    print(f"coupled fixed point on V = {slow_v}, plan jumps {plans} per period, h = 0.01 s, delta = 0.1 s")
    for label, params in _boxes():
        for jt in ((0.0, 0.0, 0.0), (0.0003, 0.0003, 0.0006), (0.001, 0.0005, 0.001)):
            jp = tuple(max(a, b) for a, b in zip(jt, plans))
            ldi = study_bound(params, slow_v, jt, jp)
            sg, near = (velocity_loop_bound(params, v_max=slow_v, tick=0.01, period=0.1, jump_tick=jt, jump_period=jp,
                                            first_command=first) for first in (None, plans))
            sg_e, near_e = ([round(x, 4) for x in b.error] if b.certified else "diverges" for b in (sg, near))
            ldi_e = [round(x, 4) for x in ldi.error] if ldi.closed else f"open ({ldi.why})"
            print(f"  {label:22s} per-tick {jt}: LDI {ldi_e} | small-gain {sg_e} | small-gain, first command "
                  f"within J of rest {near_e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
