"""Step 5c of the velocity loop's bound: a channel's own constant coefficients split into cells.

The coefficients θ are constant in a run; only the velocities change. The decompositions of
:mod:`verify.vehicle.bound` still charge a channel's own mass and damping mismatch as inputs whose size is the
whole box's: the mass mismatch as (1 − 1/μ) ẏ, the drag mismatch's own slope as ∂d_c/∂y_c ẏ / m̂_c. Here the
channel's own mass entry and its linear and quadratic damping coefficients (:data:`OWN_COEFFICIENTS`) are each
split into sub-intervals (:func:`own_splits`: at most :data:`CELL_BUDGET` cells a channel, none where a split lowers
the residual by less than :data:`CELL_GAIN_STEP`); every θ lies in one cell (a product of sub-intervals, the other
coefficients over the whole box), so a bound that holds in every cell holds for the vehicle.

**Per cell** k, with μ_k the centre of μ = m̂_c/m_c and δ_k the centre of ∂d_c/∂y_c / m̂_c over the cell and
the command box V (1/s), write Ḋ = δ_k ẏ + r with D = d_c/m̂_c. In the second decomposition's coordinates
x = (Ĩ, e, z), Ĩ = I + D/k_i, q = (k_i, k_p, 1) (ẏ = μ q x), u_0 = (0, −1, k_p − λ_c) and
v_k = (δ_k/k_i, −1, k_p − λ_c), the loop is exactly

    ẋ = A_k x + (1/k_i, 0, 0) r + (0, 0, −1) w_n + (1 − μ_k/μ) ẏ v_k,     A_k = A(λ_c) + (μ_k v_k − u_0) q,

so the cell's centre is in the loop's matrix and only the residuals are inputs: the mass residual
(1 − μ_k/μ) ẏ along v_k, and r = (∂d_c/∂y_c/m̂_c − δ_k) ẏ + Σ_{j ≠ c} ∂d_c/∂ν_j ν̇_j / m̂_c. The jumps,
w_n, the trimmed start x(0) = (D(0)/k_i, 0, 0) and the outputs are those of the second decomposition
(ẏ = μ q x, a = (k_i, k_p, 0) x − D). :func:`channel_cells` builds each cell's response sums
(:func:`verify.vehicle.response.impulse_sums` of A_k; a cell whose A_k is not proved stable makes the step
unavailable for that channel); :func:`cell_inputs` bounds the residuals over the cell each round;
:func:`cell_bound` is the output's bound in one cell; the channel's bound is the maximum over its cells, and
:func:`verify.vehicle.bound.computed_bounds` keeps the smallest of the three decompositions.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Mapping, NamedTuple, Protocol, Sequence

import numpy as np
from flint import arb, ctx

from verify.kernel.intervals import _abs, enclose, lower, raise_upper, upper
from verify.vehicle.model import channel_masses, channel_mismatch, channel_mismatch_gradient, velocity_box
from verify.vehicle.response import RESPONSE_PREC, gain_balls, impulse_sums

__all__ = ["LoopFacts", "OWN_COEFFICIENTS", "CELL_BUDGET", "CELL_GAIN_STEP", "own_splits", "Cell", "CellInputs",
           "split_ball", "channel_cells", "cell_starts", "cell_inputs", "cell_own_gains", "cell_bound",
           "channel_bounds"]

#: Per channel name: its mass entry, linear and quadratic damping coefficient (the names of
#: :func:`verify.vehicle.model.hull_balls`).
OWN_COEFFICIENTS = {"u": ("m11", "X_u", "X_uu"), "v": ("m22", "Y_v", "Y_vv"), "w": ("m33", "Z_w", "Z_ww"),
                    "r": ("m44", "N_r", "N_rr")}
#: Cells per channel at most: the sub-intervals are given greedily to the own coefficient whose residual they
#: shrink most (:func:`own_splits`); a point coefficient is not split.
CELL_BUDGET = 64
#: A split is made only while it lowers its coefficient's share of the own residual gain by at least this much
#: (dimensionless): a narrow box gets no cells, and its bound is the second decomposition's.
CELL_GAIN_STEP = 0.015


class LoopFacts(Protocol):
    """What the cells read of the loop (:class:`verify.vehicle.loop_data.LoopData` has it)."""

    names: str
    own: tuple[int, ...]
    lateral: bool
    hull: Mapping[str, arb]
    nominal: Mapping[str, arb]
    m_hat: tuple[arb, ...]
    slope: tuple[float, ...]
    tick: float
    ticks: int
    cells: tuple[tuple["Cell", ...], ...]
    gain_balls: tuple[tuple[tuple[arb, ...], ...], ...]
    mass_gain_balls: tuple[tuple[arb, ...], ...]

    def box(self, error: Sequence[float]) -> tuple[tuple[float, float, float], float]: ...

    def channel_gains(self, c: int) -> tuple[arb, arb]: ...


@dataclass(frozen=True)
class Cell:
    """One cell of a channel: its own damping mismatch, its centre (μ_k, δ_k) and the response sums of A_k.

    Attributes
    ----------
    damping : (2,) arb
        Δa, Δb: the nominal minus the cell's linear and quadratic damping coefficient (balls; the channel's own
        damping in :func:`verify.vehicle.model.arb_body_forces`).
    mu : arb
        m̂_c / m_c over the cell (dimensionless).
    mass_residual : arb
        |1 − μ_k/μ| over the cell (dimensionless): the mass residual's size per unit Ŷ_c.
    mu_centre, slope : float
        μ_k and δ_k (1/s), in A_k.
    gains : tuple
        Per output row (e, a + D, z, q x): (Σ g_J per tick, max-phase Σ g_J per period, h Σ g_r, h Σ g_n,
        peak g_r, h Σ g_v) as balls (s or dimensionless, as the rows of :class:`verify.vehicle.loop_data.LoopData`).
    pieces : (3,) ints
        Which sub-interval of the mass entry, the linear and the quadratic damping coefficient the cell is: cells
        with the same damping pieces share their damping's residuals, cells with the same mass piece their μ
        (:func:`cell_inputs` forms each once).
    """

    damping: tuple[arb, arb]
    mu: arb
    mass_residual: arb
    mu_centre: float
    slope: float
    gains: tuple[tuple[arb, ...], ...]
    pieces: tuple[int, int, int]

    @cached_property
    def gain_tops(self) -> np.ndarray:
        """(4, 6) floats: sup|g| of each ball of :attr:`gains` (rounded up); what :func:`channel_bounds` screens
        with."""
        return np.array([[upper(_abs(g)) for g in row] for row in self.gains], dtype=float)

    @cached_property
    def mu_top(self) -> float:
        """sup|μ| (rounded up): the ẏ row's factor in :func:`channel_bounds`' screen."""
        return upper(_abs(self.mu))


@dataclass(frozen=True)
class CellInputs:
    """One cell's residual inputs over the assumed box (see the module doc).

    Attributes
    ----------
    rate : float
        sup|r| (m/s³, rad/s³).
    mass : float
        sup|1 − μ_k/μ| Ŷ_c (m/s², rad/s²).
    mismatch : float
        sup|D| = sup|d_c|/m̂_c over the box (m/s², rad/s²).
    start : float
        sup|d_c(ν(0))|/m̂_c over the first command's box (m/s², rad/s²).
    """

    rate: float
    mass: float
    mismatch: float
    start: float


def split_ball(x: arb, pieces: int) -> list[arb]:
    """``pieces`` balls whose union covers ``x`` (x itself when it is a point or ``pieces`` is 1)."""
    lo, hi = lower(x), upper(x)
    if pieces <= 1 or x.rad() == 0 or not lo < hi:
        return [x]
    edges = [lo + (hi - lo) * k / pieces for k in range(pieces)] + [hi]
    return [enclose(a, b) for a, b in zip(edges[:-1], edges[1:])]


def _cell_matrix(base: Sequence[Sequence[arb]], k_i: arb, k_p: arb, lam: arb, mu_k: arb, delta_k: arb) -> list:
    """A_k = A(λ_c) + (μ_k v_k − u_0) q (module doc)."""
    q = (k_i, k_p, arb(1))
    v = (delta_k / k_i, arb(-1), k_p - lam)
    u0 = (arb(0), arb(-1), k_p - lam)
    col = [mu_k * a - b for a, b in zip(v, u0)]
    return [[base[i][j] + col[i] * q[j] for j in range(3)] for i in range(3)]


def own_splits(loop: LoopFacts, c: int, budget: int = CELL_BUDGET) -> tuple[int, int, int]:
    """Sub-intervals of channel ``c``'s mass entry, linear and quadratic damping coefficient (at most ``budget``
    cells in all): each split goes to the coefficient whose share of the ẏ row's own residual gain, at the command
    box V, it lowers most (the mass: L1 gain × the spread of μ; the linear and the quadratic coefficient: L1 gain ×
    their half-width × 1 and × 2 V_c, per m̂_c), as long as it lowers that share by :data:`CELL_GAIN_STEP` or more.
    A point coefficient keeps 1."""
    names = OWN_COEFFICIENTS[loop.names[c]]
    box, gamma = loop.box((0.0,) * len(loop.names))
    speed = (box[0], gamma, box[1], box[2])[loop.own[c]]
    mass = loop.hull[names[0]]
    mu_spread = upper(mass.rad() / abs(mass.mid())) if mass.rad() != 0 else 0.0
    h_rate, mass_gain = upper(loop.gain_balls[c][3][2]), upper(loop.mass_gain_balls[c][3])
    m_hat = upper(loop.m_hat[c])
    weights = [mass_gain * mu_spread, h_rate * upper(loop.hull[names[1]].rad()) / m_hat,
               h_rate * 2 * speed * upper(loop.hull[names[2]].rad()) / m_hat]
    splits = [1, 1, 1]
    while True:
        gains = [w / k - w / (k + 1) if w > 0 else 0.0 for w, k in zip(weights, splits)]
        best = max(range(3), key=lambda i: gains[i])
        trial = splits[:best] + [splits[best] + 1] + splits[best + 1:]
        if gains[best] < CELL_GAIN_STEP or trial[0] * trial[1] * trial[2] > budget:
            return tuple(splits)
        splits = trial


def channel_cells(loop: LoopFacts, c: int, base: Sequence[Sequence[arb]],
                  budget: int = CELL_BUDGET) -> tuple[Cell, ...]:
    """The cells of channel ``c`` of ``loop`` (:func:`own_splits`), whose A(λ_c) is ``base`` (1/s); empty when the
    channel has no own coefficient with a width or some cell's A_k is not proved stable (the step is then not used
    for it)."""
    names = OWN_COEFFICIENTS[loop.names[c]]
    pieces = [split_ball(loop.hull[name], k) for name, k in zip(names, own_splits(loop, c, budget))]
    if all(len(p) == 1 for p in pieces):
        return ()
    box, gamma = loop.box((0.0,) * len(loop.names))
    nu = velocity_box(box[0], gamma, box[1], box[2])
    with ctx.workprec(RESPONSE_PREC):
        (k_p, k_i), lam = loop.channel_gains(c), arb(loop.slope[c])
        out = []
        for index in itertools.product(*(range(len(p)) for p in pieces)):
            combo = [p[i] for p, i in zip(pieces, index)]
            hull = {**loop.hull, **dict(zip(names, combo))}
            mu = loop.m_hat[c] / channel_masses(hull, loop.lateral)[c]
            own = channel_mismatch_gradient(loop.nominal, hull, nu, loop.lateral)[c][loop.own[c]] / loop.m_hat[c]
            mu_k, delta_k = float(mu.mid()), float(own.mid())
            a = _cell_matrix(base, k_i, k_p, lam, arb(mu_k), arb(delta_k))
            sums = impulse_sums(a, [[0, 1, -k_p], [1 / k_i, 0, 0], [0, 0, -1], [arb(delta_k) / k_i, -1, k_p - lam]],
                                [[0, 1, 0], [k_i, k_p, 0], [0, 0, 1], [k_i, k_p, 1]], tick=loop.tick,
                                ticks_per_period=loop.ticks)
            if not sums.stable:
                return ()
            damping = (loop.nominal[names[1]] - combo[1], loop.nominal[names[2]] - combo[2])
            out.append(Cell(damping=damping, mu=mu, mass_residual=abs(1 - arb(mu_k) / mu), mu_centre=mu_k,
                            slope=delta_k, gains=gain_balls(sums, loop.tick), pieces=index))
        return tuple(out)


def _own_damping(cell: Cell, speed: arb, size: arb | None = None) -> tuple[arb, arb]:
    """The own damping's part of d_c and of ∂d_c/∂y_c in ``cell``: −(Δa + Δb |y|) y and −(Δa + 2 Δb |y|) (Δ: the
    cell's :attr:`Cell.damping`), y over the ball ``speed`` (as :func:`verify.vehicle.model.arb_body_forces` writes
    every channel's own damping); ``size`` |y| when the caller has it."""
    d_a, d_b = cell.damping
    size = _abs(speed) if size is None else size
    return -(d_a + d_b * size) * speed, -(d_a + 2 * d_b * size)


def _rest(loop: LoopFacts, c: int, nu: Sequence[arb]) -> tuple[arb, tuple[arb, ...]]:
    """d_c and ∂d_c/∂ν over ``nu`` without the channel's own damping (its coefficients at the nominal): n is linear in
    the coefficients and the own damping enters only row c's own term, so a cell's d_c is this plus
    :func:`_own_damping` (the own mass entry does not enter n_c)."""
    _, lin, quad = OWN_COEFFICIENTS[loop.names[c]]
    rest = {**loop.hull, lin: loop.nominal[lin], quad: loop.nominal[quad]}
    return (channel_mismatch(loop.nominal, rest, nu, loop.lateral)[c],
            channel_mismatch_gradient(loop.nominal, rest, nu, loop.lateral)[c])


def cell_starts(loop: LoopFacts, first_command: Sequence[float]) -> tuple[tuple[float, ...], ...]:
    """Per channel and cell, sup|d_c(ν(0))|/m̂_c over the first command's box |y_c| <= F_c, v = 0 (m/s², rad/s²)."""
    first = velocity_box(first_command[0], 0.0, first_command[1], first_command[2])
    out = []
    for c, cells in enumerate(loop.cells):
        d_rest = _rest(loop, c, first)[0] if cells else arb(0)
        out.append(tuple(upper(abs(d_rest + _own_damping(cell, first[loop.own[c]])[0]) / loop.m_hat[c])
                         for cell in cells))
    return tuple(out)


def cell_inputs(loop: LoopFacts, c: int, nu: Sequence[arb], rates: Sequence[arb], accel: float,
                starts: Sequence[float] | None) -> tuple[CellInputs, ...]:
    """The residuals of every cell of channel ``c`` over the velocity box ``nu`` given the body rates' bounds
    ``rates`` (|u̇|, |v̇|, |ẇ|, |ṙ|) and Ŷ_c = ``accel``; ``starts`` the channel's :func:`cell_starts` (None: sup|D|
    over ``nu``)."""
    cells = loop.cells[c]
    if not cells:
        return ()
    own, m_hat, y_dot = loop.own[c], loop.m_hat[c], arb(accel)
    d_rest, g_rest = _rest(loop, c, nu)
    cross = sum((abs(g) * x for j, (g, x) in enumerate(zip(g_rest, rates)) if j != own), arb(0)) / m_hat
    size, table = _abs(nu[own]), _table(cells)
    damped = []
    for cell in table.damping_cells:
        d_own, g_own = _own_damping(cell, nu[own], size)
        damped.append((upper(abs((g_rest[own] + g_own) / m_hat - arb(cell.slope)) * y_dot + cross),
                       upper(abs(d_rest + d_own) / m_hat)))
    massed = [upper(cell.mass_residual * y_dot) for cell in table.mass_cells]
    return tuple(CellInputs(rate=damped[i][0], mass=massed[j], mismatch=damped[i][1],
                            start=damped[i][1] if starts is None else starts[k])
                 for k, (i, j) in enumerate(table.index))


def cell_own_gains(loop: LoopFacts, c: int, nu: Sequence[arb], drag_slope: arb) -> tuple[float, float, float] | None:
    """The three parts of channel ``c``'s own loop gain in its worst cell over the velocity box ``nu`` (the ẏ row,
    per unit Ŷ_c, dimensionless): sup μ × (h Σ g_r |∂d_c/∂y_c/m̂_c − δ_k|, h Σ g_n ``drag_slope``, h Σ g_v
    |1 − μ_k/μ|), ``drag_slope`` = sup|∂n̂_c/∂y_c/m̂_c − λ_c| (1/s); None without cells."""
    worst = None
    g_rest = _rest(loop, c, nu)[1][loop.own[c]] if loop.cells[c] else arb(0)
    for cell in loop.cells[c]:
        grad = g_rest + _own_damping(cell, nu[loop.own[c]])[1]
        _, _, h_rate, h_drag, _, h_mass = cell.gains[3]
        parts = (upper(cell.mu * h_rate * abs(grad / loop.m_hat[c] - arb(cell.slope))),
                 upper(cell.mu * h_drag * drag_slope),
                 upper(cell.mu * h_mass * cell.mass_residual))
        if worst is None or sum(parts) > sum(worst):
            worst = parts
    return worst


def cell_bound(cell: Cell, o: int, jump_tick: arb, jump_period: arb, w_n: float, inputs: CellInputs) -> float:
    """Output ``o`` (e, a, z, ẏ) of one cell for the jumps J_tick, J_period (m/s, rad/s), sup|w_n| and the cell's
    residuals."""
    return channel_bounds((cell,), jump_tick, jump_period, w_n, (inputs,), (o,))[0]


def channel_bounds(cells: Sequence[Cell], jump_tick: arb, jump_period: arb, w_n: float,
                   inputs: Sequence[CellInputs], outputs: Sequence[int] = (0, 1, 2, 3)) -> tuple[float, ...]:
    """Per output of ``outputs``, the largest over ``cells`` of :func:`cell_bound`, the same floats as one cell at a
    time: each output's ball is formed in Arb, in the same order, only for the cells a float screen cannot rule out.

    The screen (:func:`_screen_tops`) sums sup|g| × sup|input| over a cell's terms, every factor rounded up, which
    is >= sup|x| of the cell's ball up to the floats' and Arb's rounding (a relative 1e-14 for these few terms).
    Cells are visited from the largest screen down, and a cell whose screen × (1 + 1e-9) is below the running
    largest :func:`verify.kernel.intervals.upper` is skipped: its ball cannot raise it. -inf without cells."""
    jump_rest, drag = jump_period - jump_tick, arb(w_n)
    tops = _screen_tops(cells, upper(_abs(jump_tick)), upper(_abs(jump_rest)), float(w_n), inputs)
    best = []
    for o in outputs:
        out = -math.inf
        for k in np.argsort(-tops[:, o], kind="stable"):
            if tops[k, o] * (1.0 + 1e-9) < out:
                break
            out = raise_upper(out, abs(_cell_ball(cells[k], o, jump_tick, jump_rest, drag, inputs[k])))
        best.append(out)
    return tuple(best)


def _cell_ball(cell: Cell, o: int, jump_tick: arb, jump_rest: arb, drag: arb, ins: CellInputs) -> arb:
    """Output ``o``'s ball in ``cell`` (before |.|), the module doc's row o for the cell's residuals ``ins``."""
    g_tick, g_period, h_rate, h_drag, peak, h_mass = cell.gains[o]
    x = (jump_tick * g_tick + jump_rest * g_period + h_rate * arb(ins.rate) + h_drag * drag
         + h_mass * arb(ins.mass) + peak * arb(ins.start))
    if o == 1:
        x += arb(ins.mismatch)
    if o == 3:
        x *= cell.mu
    return x


def _screen_tops(cells: Sequence[Cell], jump_tick: float, jump_rest: float, w_n: float,
                 inputs: Sequence[CellInputs]) -> np.ndarray:
    """(cells, 4) floats: per cell and output, Σ sup|g| × sup|input| (+ sup|D| in row 1, × sup|μ| in row 3); +inf
    where a product is not a number (an infinite input against a zero gain), so that such a cell is formed."""
    table = _table(cells)
    ins = np.array([[jump_tick, jump_rest, i.rate, w_n, i.start, i.mass] for i in inputs], dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        x = np.einsum("kog,kg->ko", table.tops, ins)
        x[:, 1] += np.array([i.mismatch for i in inputs], dtype=float)
        x[:, 3] *= table.mu_tops
    return np.where(np.isnan(x), np.inf, x)


class _CellTable(NamedTuple):
    """What the fixed point's rounds read of one channel's cells, formed once per tuple of cells (:func:`_table`)."""

    damping_cells: list[Cell]      # the first cell of each damping key (its pieces and δ_k fix Δa, Δb)
    mass_cells: list[Cell]         # the first cell of each mass key (its piece and μ_k fix μ)
    index: list[tuple[int, int]]   # per cell, its damping key's and mass key's index
    tops: np.ndarray               # (cells, 4, 6): each cell's Cell.gain_tops
    mu_tops: np.ndarray            # (cells,): each cell's Cell.mu_top


#: :func:`_table` of the channels' cell tuples met last, by id (each entry holds its tuple, so the id stays its own).
_TABLES: dict[int, tuple[Sequence[Cell], _CellTable]] = {}


def _table(cells: Sequence[Cell]) -> _CellTable:
    """The :class:`_CellTable` of ``cells``: cells sharing a damping key share the residuals :func:`cell_inputs`
    forms for it, cells sharing a mass key their mass residual, and :func:`_screen_tops` reads the stacked tops. Kept
    for tuples of more than one cell (a channel's, met in every round; :func:`cell_bound`'s one-cell tuples are
    new each time)."""
    entry = _TABLES.get(id(cells))
    if entry is not None and entry[0] is cells:
        return entry[1]
    damping: dict[tuple, int] = {}
    mass: dict[tuple, int] = {}
    table = _CellTable([], [], [], np.array([cell.gain_tops for cell in cells]),
                       np.array([cell.mu_top for cell in cells], dtype=float))
    for cell in cells:
        key, mass_key = (cell.pieces[1:], cell.slope), (cell.pieces[0], cell.mu_centre)
        if key not in damping:
            damping[key] = len(table.damping_cells)
            table.damping_cells.append(cell)
        if mass_key not in mass:
            mass[mass_key] = len(table.mass_cells)
            table.mass_cells.append(cell)
        table.index.append((damping[key], mass[mass_key]))
    if len(cells) > 1:
        if len(_TABLES) >= 64:
            del _TABLES[next(iter(_TABLES))]
        _TABLES[id(cells)] = (cells, table)
    return table
