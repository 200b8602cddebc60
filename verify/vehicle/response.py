"""Rigorous sums of a sampled impulse response in Arb: the L1 gains of the velocity loop.

For a stable LTI system ṡ = A s driven by impulses (state jumps) at the ticks t_j = j h and by
a bounded input w(t) entering through a column b, every output row c satisfies

    |c s(t)| <= Σ_j |c Φ(t − t_j) b| |J_j| + sup|w| ∫_0^∞ |c Φ(τ) b| dτ,     Φ(τ) = exp(A τ).

With g(i) = sup_{θ ∈ [0, h]} |c Φ(i h + θ) b| (the response over the i-th tick after a jump),
Σ_j |c Φ(t − t_j) b| <= Σ_{i >= 0} g(i) and ∫_0^∞ |c Φ b| <= h Σ_{i >= 0} g(i).
:func:`impulse_sums` computes, for every output row and every input column,

* ``tick``: Σ_{i >= 0} g(i) (a jump at every tick; times h it is the L1 gain of a continuous input);
* ``period``: max over the phase p of Σ_{m >= 0} g(p + m N) (a jump at one tick in N: period boundaries);
* ``peak``: sup_{i >= 0} g(i) (the free response to an initial state along b);

all in Arb: A_d = exp(A h) by ``arb_mat.exp``; g(i) through the enclosures exp(A (k h/Q)) exp(A [0, h/Q]),
k < Q, of exp(A [0, h]); the terms i < K summed; the tail i >= K bounded by the geometric series of
‖A_d^K‖_∞ = ρ < 1: Σ_{i >= K} ‖A_d^i x‖_∞ <= (Σ_{j < K} ‖A_d^j‖_∞) ‖A_d^K x‖_∞ / (1 − ρ).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Sequence

from flint import arb, arb_mat, ctx

from verify.kernel.intervals import float_top, raise_upper, upper

__all__ = ["ResponseSums", "impulse_sums", "gain_balls", "RESPONSE_PREC", "INTRA_TICK_PIECES", "MEMO_SIZE"]

#: Working precision (bits) of the response sums: the ball radii of A_d^i grow like ρ(|A_d|)^i.
RESPONSE_PREC = 128
#: Sub-intervals Q of [0, h] for the intra-tick enclosure of exp(A θ).
INTRA_TICK_PIECES = 4
#: Sums kept by :func:`impulse_sums` for calls with the same balls (a few kilobytes each).
MEMO_SIZE = 4096

_MEMO: dict[tuple, "ResponseSums"] = {}


@dataclass(frozen=True)
class ResponseSums:
    """Upper bounds of the impulse-response sums (floats rounded up), indexed ``[output][input]``.

    Attributes
    ----------
    tick : tuple of tuples
        Σ_{i >= 0} sup_{θ ∈ [0, h]} |c Φ(i h + θ) b| (dimensionless per unit jump).
    period : tuple of tuples
        max_p Σ_{m >= 0} sup_θ |c Φ((p + m N) h + θ) b| (one jump per N ticks, worst phase).
    peak : tuple of tuples
        sup_{t >= 0} |c Φ(t) b| (free response from the initial state b).
    rho : float
        ‖A_d^K‖_∞ (upper bound); the tail is certified when rho < 1.
    terms : int
        K, the number of ticks summed term by term.
    moment_tick, moment_period : tuples indexed ``[weight][output][input]``, or empty
        With ``moments``: the sums above with each term g(i) weighted by w_0(i) = i + 2 (the ticks in an age of
        i + 1 ticks, and one more) and by w_1(i) = ⌊(i + 1)/N⌋ + 1 (the period boundaries in it, and one more).
    """

    tick: tuple[tuple[float, ...], ...]
    period: tuple[tuple[float, ...], ...]
    peak: tuple[tuple[float, ...], ...]
    rho: float
    terms: int
    moment_tick: tuple[tuple[tuple[float, ...], ...], ...] = ()
    moment_period: tuple[tuple[tuple[float, ...], ...], ...] = ()

    @property
    def stable(self) -> bool:
        """‖A_d^K‖_∞ < 1: A_d is Schur stable and the tails are finite."""
        return self.rho < 1.0


def _norm_inf(m: arb_mat) -> arb:
    """‖m‖_∞ (largest absolute row sum) as an upper-bound ball (each row summed left to right from 0)."""
    entries, cols = m.entries(), m.ncols()
    rows = [sum(map(abs, entries[start:start + cols]), arb(0)) for start in range(0, len(entries), cols)]
    return functools.reduce(arb.max, rows)


def _col_norm(m: arb_mat, j: int) -> arb:
    """‖m[:, j]‖_∞."""
    out = abs(m[0, j])
    for i in range(1, m.nrows()):
        out = out.max(abs(m[i, j]))
    return out


def _intra_tick_rows(a: arb_mat, c: arb_mat, tick: arb, pieces: int) -> list[arb_mat]:
    """c exp(A (k h/Q)) exp(A [0, h/Q]) for k < Q: together they enclose c exp(A θ), θ ∈ [0, h]."""
    step = tick / pieces
    head = (a * arb(0).union(step)).exp()
    return [c * (a * (step * k)).exp() * head for k in range(pieces)]


def _stacked(rows: list[arb_mat]) -> arb_mat:
    """The Q row blocks of :func:`_intra_tick_rows` stacked into one (Q n_out) x n matrix: one product a tick."""
    return arb_mat([[r[o, j] for j in range(r.ncols())] for r in rows for o in range(r.nrows())])


def _tick_maxima(stacked: arb_mat, x: arb_mat, pieces: int) -> list[arb]:
    """max_k |(rows_k x)[o, j]| as balls (the hull of the Q pieces), flat in row-major ``[output][input]`` order;
    ``stacked`` is :func:`_stacked` of the Q row blocks (entry for entry the same products as one block at a time)."""
    prods = (stacked * x).entries()
    block = len(prods) // pieces
    hull = prods[:block]
    for k in range(1, pieces):  # piece 0 ∪ piece 1 ∪ ..., left to right
        hull = map(arb.union, hull, prods[k * block:(k + 1) * block])
    return list(map(abs, hull))


def impulse_sums(a: Sequence[Sequence[arb | float]], inputs: Sequence[Sequence[arb | float]],
                 outputs: Sequence[Sequence[arb | float]], *, tick: float, ticks_per_period: int,
                 tol: float = 1e-8, max_terms: int = 20000, moments: bool = False) -> ResponseSums:
    """The sums of the module doc for ṡ = A s, input columns ``inputs`` (n_in, n), output rows ``outputs``.

    Parameters
    ----------
    a : (n, n) numbers or arb
        The system matrix (1/s).
    inputs, outputs : sequences of n-vectors
        Columns b (jump directions / input directions) and rows c.
    tick : float
        h (s).
    ticks_per_period : int
        N >= 1, ticks between two period boundaries.
    tol : float
        Stop summing term by term once ‖A_d^i‖_∞ < ``tol``.
    max_terms : int
        Largest K; if ρ = ‖A_d^K‖_∞ is still >= 1 there the sums are +inf (not stable).
    moments : bool
        Also the weighted sums of :class:`ResponseSums` (``moment_tick``, ``moment_period``); their tail takes the
        weight i + 2 <= (b + 2) K + 2 over the b-th block of K ticks: Σ_b ρ^b ((b + 2) K + 2) = (2K + 2)/(1 − ρ)
        + K ρ/(1 − ρ)² times the unweighted tail's (1 − ρ).

    Notes
    -----
    The sums are a function of the exact balls of A, b, c, h, N, ``tol`` and K alone (formed at
    :data:`RESPONSE_PREC`): a call with the same balls returns the sums already formed (at most
    :data:`MEMO_SIZE` kept; a fixed point's rounds and a knob's bisection meet the same channels again).
    """
    with ctx.workprec(RESPONSE_PREC):
        n = len(a)
        A = arb_mat([[arb(x) for x in row] for row in a])
        B = arb_mat([[arb(inputs[j][i]) for j in range(len(inputs))] for i in range(n)])
        C = arb_mat([[arb(x) for x in row] for row in outputs])
        h = arb(tick)
        key = (_exact_entries(A), _exact_entries(B), _exact_entries(C), _exact(h), int(ticks_per_period),
               float(tol), int(max_terms), bool(moments))
        found = _MEMO.get(key)
        if found is None:
            found = _sums(A, B, C, h, int(ticks_per_period), tol, max_terms, bool(moments))
            if len(_MEMO) >= MEMO_SIZE:
                del _MEMO[next(iter(_MEMO))]
            _MEMO[key] = found
        return found


def _exact(ball: arb) -> tuple[tuple[int, int], tuple[int, int]]:
    """A ball's midpoint and radius, each as the exact (mantissa, exponent) pair: equal keys, equal balls."""
    return ball.mid().man_exp(), ball.rad().man_exp()


def _exact_entries(m: arb_mat) -> tuple[int, int, tuple[tuple[tuple[int, int], tuple[int, int]], ...]]:
    """The shape and every entry of ``m``, exactly (:func:`_exact`)."""
    return m.nrows(), m.ncols(), tuple(_exact(x) for x in m.entries())


def _sums(A: arb_mat, B: arb_mat, C: arb_mat, h: arb, ticks_per_period: int, tol: float,
          max_terms: int, moments: bool = False) -> ResponseSums:
    """:func:`impulse_sums` of the balls A (n x n), B (n x n_in), C (n_out x n), formed at the working precision."""
    n, n_in, n_out = A.nrows(), B.ncols(), C.nrows()
    weighted = _Weighted(n_out, n_in, ticks_per_period) if moments else None
    ad = (A * h).exp()
    rows = _intra_tick_rows(A, C, h, INTRA_TICK_PIECES)
    stacked = _stacked(rows)
    total_m = arb_mat(n_out, n_in)
    phase_m = [arb_mat(n_out, n_in) for _ in range(ticks_per_period)]
    peak_flat = [0.0] * (n_out * n_in)
    row_norm = [max(upper(_norm_inf(_row(r, o))) for r in rows) for o in range(n_out)]
    scales = [upper(arb(row_norm[o]) * _col_norm(B, j)) for o in range(n_out) for j in range(n_in)]
    power, norm_sum, i = arb_mat(n, n, [arb(int(r == c)) for r in range(n) for c in range(n)]), arb(0), 0
    norm = _norm_inf(power)
    top = float_top(norm)
    while i < max_terms and not (i >= ticks_per_period and _done(norm, top, tol)):
        g = _tick_maxima(stacked, power * B, INTRA_TICK_PIECES)
        g_m = arb_mat(n_out, n_in, g)
        total_m = total_m + g_m
        phase_m[i % ticks_per_period] = phase_m[i % ticks_per_period] + g_m
        if weighted is not None:
            weighted.add(i, g_m)
        peak_flat = _raise_peaks(peak_flat, g, scales, top)
        norm_sum += norm
        power = power * ad
        norm = _norm_inf(power)
        top = float_top(norm)
        i += 1
    total = [[total_m[o, j] for j in range(n_in)] for o in range(n_out)]
    phase = [[[m[o, j] for j in range(n_in)] for o in range(n_out)] for m in phase_m]
    peak = [peak_flat[o * n_in:(o + 1) * n_in] for o in range(n_out)]
    rho = upper(norm)
    if not rho < 1.0:
        inf = tuple(tuple(math.inf for _ in range(n_in)) for _ in range(n_out))
        infs = (inf, inf) if moments else ()
        return ResponseSums(tick=inf, period=inf, peak=inf, rho=rho, terms=i, moment_tick=infs, moment_period=infs)
    xk = power * B
    tails = [[arb(row_norm[o]) * norm_sum * _col_norm(xk, j) / (1 - arb(rho)) for j in range(n_in)]
             for o in range(n_out)]
    tick_sums = tuple(tuple(upper(total[o][j] + tails[o][j]) for j in range(n_in)) for o in range(n_out))
    period_sums = tuple(tuple(max(upper(phase[p][o][j] + tails[o][j]) for p in range(ticks_per_period))
                              for j in range(n_in)) for o in range(n_out))
    # a single term of the tail is at most the whole tail
    peaks = tuple(tuple(max(peak[o][j], upper(tails[o][j])) for j in range(n_in)) for o in range(n_out))
    if weighted is None:
        return ResponseSums(tick=tick_sums, period=period_sums, peak=peaks, rho=rho, terms=i)
    r, k = arb(rho), arb(i)
    factor = (2 * k + 2) + k * r / (1 - r)  # the weighted tail over the unweighted one (ResponseSums, moments)
    moment_tick, moment_period = weighted.bounds([[t * factor for t in row] for row in tails])
    return ResponseSums(tick=tick_sums, period=period_sums, peak=peaks, rho=rho, terms=i, moment_tick=moment_tick,
                        moment_period=moment_period)


class _Weighted:
    """The weighted sums of :class:`ResponseSums` (``moment_tick``, ``moment_period``) as they are summed."""

    def __init__(self, n_out: int, n_in: int, ticks_per_period: int) -> None:
        self.n_out, self.n_in, self.ticks = n_out, n_in, ticks_per_period
        self.total = [arb_mat(n_out, n_in) for _ in range(2)]
        self.phase = [[arb_mat(n_out, n_in) for _ in range(ticks_per_period)] for _ in range(2)]

    def add(self, i: int, g: arb_mat) -> None:
        """Add the i-th tick's maxima ``g`` with the weights i + 2 and ⌊(i + 1)/N⌋ + 1."""
        for w, weight in enumerate((i + 2, (i + 1) // self.ticks + 1)):
            term = g * arb(weight)
            self.total[w] = self.total[w] + term
            self.phase[w][i % self.ticks] = self.phase[w][i % self.ticks] + term

    def bounds(self, tails: list[list[arb]]) -> tuple[tuple, tuple]:
        """(tick sums, worst-phase period sums) per weight, each with the weighted tail ``tails[o][j]`` added."""
        rng_o, rng_j = range(self.n_out), range(self.n_in)
        ticks = tuple(tuple(tuple(upper(t[o, j] + tails[o][j]) for j in rng_j) for o in rng_o) for t in self.total)
        periods = tuple(tuple(tuple(max(upper(p[o, j] + tails[o][j]) for p in phases) for j in rng_j) for o in rng_o)
                        for phases in self.phase)
        return ticks, periods


def gain_balls(sums: ResponseSums, tick: float) -> tuple[tuple[arb, ...], ...]:
    """The velocity loop's sums as balls, per output row: (Σ g per tick and max-phase Σ g per period of the jump
    column 0, h Σ g of columns 1 and 2, the peak of column 1, then h Σ g of every further column), h = ``tick`` (s):
    the L1 gains of :mod:`verify.vehicle.bound` (jumps, Ẇ or r, w_n, the start along column 1, extra inputs)."""
    h = arb(tick)
    return tuple((arb(sums.tick[o][0]), arb(sums.period[o][0]), h * arb(sums.tick[o][1]), h * arb(sums.tick[o][2]),
                  arb(sums.peak[o][1]), *(h * arb(x) for x in sums.tick[o][3:]))
                 for o in range(len(sums.tick)))


#: A relative margin far above the rounding of a float's mid + rad against the ball's exact upper bound (a few ulps):
#: a test decided on the floats with it decides as the exact one would.
_NEAR = 1e-9


def _done(norm: arb, top: float, tol: float) -> bool:
    """Stop summing: ‖A_d^i‖_∞ < tol, or < 1/2 with the ball's radius above 1 % of it (precision spent).

    ``top`` is :func:`verify.kernel.intervals.float_top` of ``norm``: where it stands clear of both thresholds (by
    :data:`_NEAR`) the answer is no without the exact upper bound; near either one the exact bounds decide."""
    if top > tol * (1 + _NEAR) and (top > 0.5 * (1 + _NEAR) or float(norm.rad()) < 0.01 * top * (1 - _NEAR)):
        return False
    exact = upper(norm)
    return exact < tol or (exact < 0.5 and upper(norm.rad()) > 0.01 * exact)


def _raise_peaks(peaks: list[float], g: list[arb], scales: list[float], top: float) -> list[float]:
    """The running maxima ``peaks`` raised by this tick's maxima ``g`` (flat ``[output][input]``).

    g[o, j] = max_k |c_k,o A_d^i b_j| <= ‖c_k,o‖_1 ‖A_d^i‖_∞ ‖b_j‖_∞ = ``scales[o, j]`` ``top`` (the rows' largest
    norm over the pieces times the column's, times ‖A_d^i‖_∞ as :func:`verify.kernel.intervals.float_top`), and
    Arb's ball of g stays within its rounding (a relative 2^-30 at worst, the radii's) of that. An entry whose bound
    is below half its peak cannot raise it and is passed over without the exact upper bound; the others are
    :func:`verify.kernel.intervals.raise_upper`: the same maxima, a float comparison a tick once the response has
    decayed."""
    return [p if s * top < 0.5 * p else raise_upper(p, x) for p, x, s in zip(peaks, g, scales)]


def _row(m: arb_mat, o: int) -> arb_mat:
    """Row ``o`` of ``m`` as a 1 x n matrix."""
    return arb_mat([[m[o, j] for j in range(m.ncols())]])
