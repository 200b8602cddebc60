"""The tracking theorem's terminal ingredients: a terminal set and law under which the candidate always exists.

Recursive feasibility is proved here, at certify time, instead of checked in the run (``docs/verify.md``,
step 17). A plan accepted at t_k ends in the terminal set X_f of :class:`tubekit.model.terminal_law.TerminalLaw`
(the exact check asks it, :mod:`tubekit.loop.plan_check`). At t_{k+1} the candidate is that plan shifted by one
period, replayed from the measured state, and completed by one row of the terminal law. Step 8 gives the
shifted rows their margins; what is left is the completion, from a state within the replay's deviation
(D_xy = p_xy + ū ψ (N − 1) δ, D_z = p_z, D_ψ = ψ of the one-period tube) of X_f. With A_xy, A_z the target's
acceleration bounds, P, W its speed bounds, ū̄, w̄̄, r̄̄ = V̄, and the completion held over δ along the exact
unicycle arc (``tubekit.model.terminal_law`` for the law), in the line-of-sight frame of the completion's start:

* q'_x = d − λδ (d − d*) + ρ_x and |q'_y| <= Y = δP / cos β + tan β λδ Δ + A_xy δ² / 2 (Cauchy–Schwarz on the
  target's velocity), β = A_0 (1 − g / 2), A_0 = α_f + D_ψ + asin(D_xy / d_lo), Δ = the largest |d − d*|;
* so d' >= x_min = (d_lo − D_xy)(1 − λδ) + λδ d* − A_xy δ² / 2 >= d_lo (``terminal_invariant[d_lo]``),
  d' <= hypot(x_max, Y) <= d_hi (``terminal_invariant[d_hi]``), and the new angle to the line of sight
  |α'| <= (1 − g) A_0 + atan(Y / x_min) <= α_f (``terminal_invariant[alpha]``);
* e_z' = (1 − λ_z δ) e_z − ρ_z: (1 − λ_z δ)(z_f + D_z) + A_z δ² / 2 <= z_f (``terminal_invariant[e_z]``);
* the row is in V̄: (P + λΔ) / (S(g A_0 / 2) cos β) <= ū̄, W + λ_z (z_f + D_z) <= w̄̄, g A_0 / δ <= r̄̄
  (``terminal_inputs[u|w|r]``);
* along the arc (a Lipschitz function between two ends in an interval leaves it by at most rate · δ / 2):
  d ∈ [d_lo − D_xy − Lδ/2, d_hi + D_xy + Lδ/2], L = ū̄ + P; |α| <= A_0 + asin(Lδ / (d_lo − D_xy)) and
  |e_z| <= z_f + D_z + (w̄̄ + W) δ / 2, each inside R shrunk by the last arc's margins and the check's pad
  (``terminal_in_region[e_d_lo|e_d_hi|e_o|e_z]``), the heading in the `toward` hemisphere;
* the completion's end within the sensed region: hypot(N δ ū̄ + c, N δ w̄̄ + Z) <= R̄ − r̄ (``terminal_sensing``);
* the obstacles and the workspace along the target's path (:mod:`verify.theorem.path_clearance`);
* at t = 0, the law's own plan from the start passes the exact check (``initial_terminal``,
  :mod:`verify.theorem.initial_plan`): it is the candidate when the solver's plan is rejected.

Under a minimum surge the completion's surge must stay above u_min + κ̄_u: X_f gets a bearing face, a cone behind a
target whose speed has a positive floor (:mod:`verify.theorem.terminal_bearing`, step 17b); a target that may stop
is refused (``terminal_surge_floor``). Under rate-limited plans X_f gets row faces that keep the completion's row
within the plans' jump (:mod:`verify.theorem.terminal_rows`, step 17c), composed with the bearing face under a
surge floor (:func:`verify.theorem.terminal_bearing.bearing_row_sets`). Where no set of the grid fits the row faces,
the same grid is tried with the line-of-sight feedforward in the yaw row (step 17e): the turn then follows the line
of sight's turn at the completion's start, so atan(Y / x_min) above becomes the residual E of
:func:`verify.theorem.completion_bounds.feedforward_residual`, β and the turn's bound grow by δΩ / 2 and δΩ, and the
feedforward's own change enters the rows. Every inequality is evaluated in Arb
and must hold with the slack :data:`FLOAT_SLACK`, so that the run's float check of the same set agrees.
:func:`design_terminal` searches a small grid of sets, largest first, and keeps the first that meets every
condition.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
from typing import Callable, Iterator

from flint import arb, ctx

from tubekit.design_inputs import ARC_SAMPLES
from tubekit.model.backup import SafeSet
from tubekit.model.terminal_law import TerminalLaw
from tubekit.scenario import Scenario

from verify.kernel.intervals import lower, upper
from verify.kernel.region import Region
from verify.theorem.design import Condition, Design
from verify.theorem.initial_plan import initial_plan_condition, start_distance
from verify.theorem.path_clearance import (PathFootprint, contains, horizon_end, path_clearance, path_samples,
                                          path_workspace)
from verify.theorem.completion_bounds import FLOAT_SLACK, CompletionArc, TerminalBounds, completion_arc
from verify.theorem.completion_bounds import slack_condition as _cond  # lhs + FLOAT_SLACK <= rhs, in Arb
from verify.theorem.terminal_bearing import bearing_conditions, iter_bearing_row_sets, iter_bearing_sets
from verify.theorem.terminal_rows import iter_row_sets, row_conditions

__all__ = ["TerminalBounds", "terminal_bounds", "law_conditions", "footprint_of", "sensing_condition",
           "design_terminal", "with_terminal", "proves_feasibility", "FLOAT_SLACK", "TERMINAL_PREFIXES",
           "FEEDFORWARD_CANNOT_LOWER"]

#: Name prefixes of the terminal ingredients' conditions (tracking tier).
TERMINAL_PREFIXES = ("terminal_", "path_", "initial_terminal")
#: Conditions the line-of-sight feedforward (step 17e) cannot lower: the e_d and depth rooms, the radial and depth
#: invariance, the heave row, the surge floor and the sensed region. Where the best memoryless set fails one of them,
#: its laws are not searched (a search effort, not a proof step).
FEEDFORWARD_CANNOT_LOWER = frozenset((
    "terminal_in_region[e_d_lo]", "terminal_in_region[e_d_hi]", "terminal_in_region[e_z]", "terminal_in_region[room]",
    "terminal_invariant[e_z]", "terminal_invariant[d_lo]", "terminal_invariant[d_hi]", "terminal_inputs[w]",
    "terminal_rate[w]", "terminal_invariant[row_w]", "terminal_gains", "terminal_surge_floor", "terminal_sensing",
    "terminal_backup"))
#: Fractions of the free e_d band X_f's width is tried at, largest first.
WIDTHS = (1.0, 0.6, 0.35, 0.2, 0.1)
#: Where X_f's lower end d_lo is tried, as fractions of the free e_d band above its least value (a larger d_lo
#: lets the line of sight turn slower than r̄̄ allows, at the price of a wider footprint).
LOWER_ENDS = (0.0, 0.1, 0.2, 0.35, 0.5)
#: Fractions of the free heading room α_f is tried at, largest first.
ANGLES = (1.0, 0.6, 0.3)
#: The refinement, tried under rate-limited plans when no set of the grid above meets every condition: X_f's lower
#: end at every twentieth of the free band and a narrower width (the row faces need the gentlest law a set allows,
#: and its gains move with both ends; ``python benchmarks/terminal_rate.py`` measured what the coarse grid misses).
FINE_LOWER_ENDS = tuple(i / 20 for i in range(20))
FINE_WIDTHS = (1.0, 0.6, 0.35, 0.2, 0.1, 0.05)


def terminal_bounds(scenario: Scenario, design: Design, region: Region) -> TerminalBounds:
    """The :class:`TerminalBounds` of ``design`` (a design with margins and V̄)."""
    p, tube, m = design.problem, design.tube, design.margins
    dt, n = float(scenario.controller.dt), int(scenario.controller.horizon_steps)
    pad = [upper(arb(0.5) * arb(dt) / ARC_SAMPLES * arb(r)) for r in design.rates]
    dev_xy = upper(arb(tube.p_xy) + arb(p.u_max) * arb(tube.psi) * arb(dt) * (n - 1))
    md, mz, mo = m.e_d[-1], m.e_z[-1], m.e_o[-1]
    ax, az = scenario.trajectory.acceleration_bound()
    jump = scenario.limits.jump(dt)
    return TerminalBounds(
        dt=dt, steps=n, v_bar=tuple(float(v) for v in design.v_bar), speed_xy=p.pd_xy, speed_z=p.pd_z,
        accel_xy=float(ax), accel_z=float(az), dev_xy=dev_xy, dev_z=tube.p_z, dev_psi=tube.psi,
        room_d=(upper(arb(region.e_d[0]) + arb(md) + arb(pad[0])), lower(arb(region.e_d[1]) - arb(md) - arb(pad[0]))),
        room_o=lower(arb(min(-region.e_o[0], region.e_o[1])) - arb(mo) - arb(pad[2])),
        room_z=lower(arb(min(-region.e_z[0], region.e_z[1])) - arb(mz) - arb(pad[1])),
        speed_floor_xy=float(scenario.trajectory.horizontal_speed_floor()),
        surge_floor=None if scenario.limits.u_min is None else upper(arb(scenario.limits.u_min)
                                                                    + arb(design.tube.kappa[0])),
        jumps=None if jump is None else (float(jump[0]), float(jump[1]), float(jump[2])))


def _input_conditions(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> list[Condition]:
    dt = arb(b.dt)
    ub, wb, rb = (arb(v) for v in b.v_bar)
    u_peak = (arb(b.speed_xy) + arb(law.gain_d) * arc.spread) / ((arc.turn_max / 2).sinc() * arc.beta.cos())
    w_peak = arb(b.speed_z) + arb(law.gain_z) * (arb(law.z_max) + arb(b.dev_z))
    return [_cond("terminal_inputs[u]", "(P + lambda Delta) / (S(T_max/2) cos beta) <= u_bar_bar", u_peak, ub),
            _cond("terminal_inputs[w]", "W + lambda_z (z_f + D_z) <= w_bar_bar", w_peak, wb),
            _cond("terminal_inputs[r]", "T_max / delta = g A_0 / delta (+ Omega) <= r_bar_bar", arc.turn_max / dt, rb),
            _cond("terminal_gains", "lambda delta <= 1 and lambda_z delta <= 1 (no overshoot past d*, z_d)",
                  max(arb(law.gain_d), arb(law.gain_z)) * dt, arb(1))]


def _invariance_conditions(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> list[Condition]:
    dt, g = arb(b.dt), arb(law.turn)
    d_hi, alpha_f, z_f = arb(law.d_hi), arb(law.alpha_max), arb(law.z_max)
    alpha_next = (1 - g) * arc.a0 + arc.residual if arc.x_min > 0 else arb("inf")
    lam_z = arb(law.gain_z) * dt
    z_next = (1 - lam_z) * (z_f + arb(b.dev_z)) + arb(b.accel_z) * dt * dt / 2
    return [_cond("terminal_invariant[d_lo]", "d_lo <= x_min (the completion ends no nearer than d_lo)",
                  arb(law.d_lo), arc.x_min),
            _cond("terminal_invariant[d_hi]", "hypot(x_max, Y) <= d_hi", (arc.x_max ** 2 + arc.lateral ** 2).sqrt(),
                  d_hi),
            _cond("terminal_invariant[alpha]", "(1 - g) A_0 + atan(Y / x_min) (with the feedforward: + E) <= alpha_f",
                  alpha_next, alpha_f),
            _cond("terminal_invariant[e_z]", "(1 - lambda_z delta)(z_f + D_z) + A_z delta^2 / 2 <= z_f", z_next, z_f)]


def _region_conditions(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> list[Condition]:
    dt, dxy = arb(b.dt), arb(b.dev_xy)
    ub, wb = arb(b.v_bar[0]), arb(b.v_bar[1])
    run = (ub + arb(b.speed_xy)) * dt
    d_in_lo = arc.start_min - run / 2
    d_in_hi = arb(law.d_hi) + dxy + run / 2
    turn = (run / arc.start_min).asin() if run < arc.start_min else arb("inf")
    alpha_in = arc.a0 + dt * arc.omega + turn  # the feedforward may turn the heading past the line of sight by δΩ
    e_o_in = alpha_in.sin() if alpha_in < arb.pi() / 2 else arb("inf")
    z_in = arb(law.z_max) + arb(b.dev_z) + (wb + arb(b.speed_z)) * dt / 2
    return [_cond("terminal_in_region[e_d_lo]", "epsilon + M_d + pad <= d_lo - D_xy - L delta / 2",
                  arb(b.room_d[0]), d_in_lo),
            _cond("terminal_in_region[e_d_hi]", "d_hi + D_xy + L delta / 2 <= e_d_max - M_d - pad", d_in_hi,
                  arb(b.room_d[1])),
            _cond("terminal_in_region[e_o]", "sin(A_0 + asin(L delta / (d_lo - D_xy))) <= e_o_max - M_o - pad "
                  "(heading toward the target)", e_o_in, arb(b.room_o)),
            _cond("terminal_in_region[e_z]", "z_f + D_z + (w_bar_bar + W) delta / 2 <= e_z_max - M_z - pad", z_in,
                  arb(b.room_z))]


@functools.lru_cache(maxsize=1 << 15)
def law_conditions(b: TerminalBounds, law: TerminalLaw) -> tuple[Condition, ...]:
    """The completion's conditions for ``law`` (module doc): inputs, invariance and the region along the arc."""
    arc = completion_arc(b, law)
    if arc is None:
        return (Condition("terminal_invariant[geometry]", "D_xy < d_lo and beta < pi/2", None, None, False,
                          f"the replay's deviation {b.dev_xy:.4g} m or the heading room does not fit this set"),)
    bearing = bearing_conditions(b, law, arc) if b.surge_floor is not None or law.has_bearing else []
    return tuple(_input_conditions(b, law, arc) + _invariance_conditions(b, law, arc) + _region_conditions(b, law, arc)
                 + bearing + _rate_conditions(b, law, arc))


def _rate_conditions(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> list[Condition]:
    """Under rate-limited plans the row faces' conditions (:mod:`verify.theorem.terminal_rows`, step 17c); a set
    without them fails by name."""
    if b.jumps is None:
        return []
    if not law.has_rows:
        return [Condition("terminal_rate", "row faces |v_(N-1) - kappa_f(x_N)| <= S (the completion's row within "
                          "the plans' jump J of the plan's last)", None, None, False, "this set has none")]
    return row_conditions(b, law, arc, b.jumps)


def footprint_of(scenario: Scenario, design: Design, b: TerminalBounds, law: TerminalLaw,
                 safe: SafeSet) -> PathFootprint:
    """The cylinders about the target a completion of ``law`` occupies (:class:`PathFootprint`)."""
    dt = arb(b.dt)
    reach = arb(law.d_hi) + arb(b.dev_xy) + (arb(b.v_bar[0]) + arb(b.speed_xy)) * dt / 2
    rise = arb(law.z_max) + arb(b.dev_z) + (arb(b.v_bar[1]) + arb(b.speed_z)) * dt / 2
    pad = arb(0.5) * dt / ARC_SAMPLES * arb(design.rates[3])
    rv = arb(scenario.vehicle_radius)
    cone = {}
    if law.bearing_max < math.pi and b.speed_floor_xy > 0.0:  # step 17b's face: the sector behind the target
        start = arb(law.bearing_max) + (arb(b.dev_xy) / arb(law.d_lo)).asin()
        if start < arb(math.pi):
            cone = {"cone": upper(start), "cone_reach": upper(arb(law.d_hi) + arb(b.dev_xy)),
                    "cone_outer": upper(arb(law.d_hi)), "turn_rate": upper(arb(b.accel_xy) / arb(b.speed_floor_xy))}
    return PathFootprint(reach=upper(reach), rise=upper(rise),
                         ball=upper(rv + arb(design.margins.position[-1]) + pad),
                         outer=upper(arb(safe.radius) + rv + arb(law.d_hi)),
                         outer_height=upper(arb(safe.depth) + rv + arb(law.z_max)), **cone)


def sensing_condition(scenario: Scenario, b: TerminalBounds, safe: SafeSet) -> Condition:
    """``terminal_sensing``: the completion's end, N arcs from the measured start, keeps the safe set in the
    sensed region: hypot(N δ ū̄ + c, N δ w̄̄ + Z) <= R̄ − r̄ (step 11 (c) for every candidate)."""
    run = arb(b.steps) * arb(b.dt)
    spread = ((run * arb(b.v_bar[0]) + arb(safe.radius)) ** 2 + (run * arb(b.v_bar[1]) + arb(safe.depth)) ** 2).sqrt()
    return _cond("terminal_sensing", "hypot(N delta u_bar_bar + c, N delta w_bar_bar + Z) <= sensing_range - r_bar",
                 spread, arb(scenario.sensing_range) - arb(scenario.vehicle_radius))


def _sets(b: TerminalBounds, fine: bool = False, feedforward: bool = False) -> tuple[TerminalLaw, ...]:
    """:func:`_grid_sets`, every set built (the search itself takes them as it goes)."""
    return tuple(_grid_sets(b, fine, feedforward))


def _grid_sets(b: TerminalBounds, fine: bool = False, feedforward: bool = False) -> _BuiltSets:
    """The grid of terminal sets and their gains, largest first (module doc); under a surge floor each with its
    bearing face (:func:`verify.theorem.terminal_bearing.bearing_sets`). ``fine``: the refinement's sets that the
    coarse grid does not have (:data:`FINE_LOWER_ENDS`, :data:`FINE_WIDTHS`); ``feedforward``: the laws with the
    line-of-sight feedforward (step 17e). Memoized on the bounds and the grid as it stands (the dynamic plant's fixed
    point derives the same bounds in each of its rounds; a study may replace the grid)."""
    if fine:
        coarse = set(_grid_points(WIDTHS, LOWER_ENDS))
        points = tuple(p for p in _grid_points(FINE_WIDTHS, FINE_LOWER_ENDS) if p not in coarse)
    else:
        points = tuple(_grid_points(WIDTHS, LOWER_ENDS))
    return _built_sets(b, points, tuple(ANGLES), feedforward)


class _BuiltSets:
    """A grid's sets, each built when a search first reaches it and kept: a search that stops at the first set
    meeting its conditions builds none past it (the gentle gains and faces of a set are most of the work), and a
    later search over the same grid replays the built ones, then builds on at the working precision they began at.
    The same sets in the same order as building them all at once."""

    def __init__(self, source: Iterator[TerminalLaw]) -> None:
        self._source: Iterator[TerminalLaw] | None = source
        self._built: list[TerminalLaw] = []
        self._prec = ctx.prec

    def __iter__(self) -> Iterator[TerminalLaw]:
        i = 0
        while i < len(self._built) or self._more():
            yield self._built[i]
            i += 1

    def _more(self) -> bool:
        """Build the next set; False when the grid is spent."""
        if self._source is None:
            return False
        with ctx.workprec(self._prec):
            law = next(self._source, None)
        if law is None:
            self._source = None
            return False
        self._built.append(law)
        return True


@functools.lru_cache(maxsize=64)
def _built_sets(b: TerminalBounds, points: tuple[tuple[float, float], ...], angles: tuple[float, ...],
                feedforward: bool) -> _BuiltSets:
    """:func:`_grid_sets` for the grid ``points`` and heading fractions ``angles``."""
    laws = _grid(b, list(points), angles)
    if feedforward:
        laws = [dataclasses.replace(law, los_feedforward=True) for law in laws]
    if b.jumps is not None:
        return _BuiltSets(iter_bearing_row_sets(b, laws) if b.surge_floor is not None else iter_row_sets(b, laws))
    return _BuiltSets(iter_bearing_sets(b, laws) if b.surge_floor is not None else iter(laws))


def _refined(b: TerminalBounds, wanted: Callable[[], bool]) -> Iterator[TerminalLaw]:
    """The refinement's sets under rate-limited plans (the row faces: their gains must be the gentlest a set
    allows), built only when the loop asks for them (the coarse grid found none), then, when ``wanted()`` says so
    once the memoryless sets are spent, the same grid's laws with the line-of-sight feedforward, coarse and fine
    (step 17e: the yaw row follows the line of sight's turn instead of catching it up); none without rate limits."""
    if b.jumps is not None:
        yield from _grid_sets(b, fine=True)
        if wanted():
            yield from _grid_sets(b, feedforward=True)
            yield from _grid_sets(b, fine=True, feedforward=True)


def _started(b: TerminalBounds, distance: float, wanted: Callable[[], bool]) -> Iterator[TerminalLaw]:
    """The sets centred on the start's distance from the target (m; d* = ``distance``, each width of
    :data:`FINE_WIDTHS` whose lower end lies in the free band), tried after every set of the grid: the grid's sets
    may all miss the start (``initial_terminal``) where one about it fits. The same laws with the line-of-sight
    feedforward follow when ``wanted()`` says so; a search effort only, as the grid (the proof does not depend on
    which sets are tried)."""
    band = _free_band(b)
    if band is None:
        return
    lo_min, hi_max = band
    points = []
    for width in FINE_WIDTHS:
        d_lo = (distance - width * hi_max / 2) / (1 - width / 2)  # d* = d_lo + width (hi_max − d_lo) / 2
        lower_end = (d_lo - lo_min) / (hi_max - lo_min)
        if 0.0 <= lower_end < 1.0:
            points.append((width, lower_end))
    if points:
        grid, angles = tuple(points), tuple(ANGLES)  # hashable for the memo, whatever a study put there
        yield from _built_sets(b, grid, angles, False)
        if b.jumps is not None and wanted():
            yield from _built_sets(b, grid, angles, True)


def _free_band(b: TerminalBounds) -> tuple[float, float] | None:
    """(least d_lo, largest d_hi) (m) a set may take: R's e_d room less the replay's deviation and half a run; None
    when nothing is left (the same band :func:`_grid` places its sets in)."""
    half_run = _half_run(b)
    lo_min = b.room_d[0] + b.dev_xy + half_run + 1e-6
    hi_max = b.room_d[1] - b.dev_xy - half_run - 1e-6
    return (lo_min, hi_max) if hi_max > lo_min else None


def _half_run(b: TerminalBounds) -> float:
    """Half of one period's relative run at the top surge and the target's speed, (ū + P) δ / 2 (m)."""
    return (b.v_bar[0] + b.speed_xy) * b.dt / 2


def _grid_points(widths: tuple[float, ...], lower_ends: tuple[float, ...]) -> list[tuple[float, float]]:
    """(width, lower end) fractions in the grid's order: widest first, then the lower end upward."""
    return [(w, f) for w in widths for f in lower_ends]


def _grid(b: TerminalBounds, points: list[tuple[float, float]], angles: tuple[float, ...] = ANGLES
          ) -> list[TerminalLaw]:
    """The grid of terminal sets without the bearing face at the (width, lower end) fractions ``points`` and the
    fractions ``angles`` of the free heading room."""
    dt, (ub, wb, rb) = b.dt, b.v_bar
    half_run = _half_run(b)
    band = _free_band(b)
    z_f = b.room_z - b.dev_z - (wb + b.speed_z) * dt / 2 - 1e-6
    if band is None or z_f <= 0.0 or band[0] <= b.dev_xy:
        return []
    lo_min, hi_max = band
    out = []
    for width, lower_end in points:
        d_lo = lo_min + lower_end * (hi_max - lo_min)
        d_hi = d_lo + width * (hi_max - d_lo)
        seen = b.dev_psi + math.asin(min(1.0, b.dev_xy / d_lo))
        turn = math.asin(min(1.0, 2 * half_run / (d_lo - b.dev_xy)))
        room = math.asin(min(b.room_o, 0.999)) - seen - turn if b.room_o > 0 else -1.0
        for frac in angles:
            alpha_f = min(frac * room, 1.2)
            if alpha_f <= 0.0:
                continue
            a0 = alpha_f + seen
            g = min(1.0, rb * dt / a0 * (1 - 1e-6))
            beta = a0 * (1 - g / 2)
            spread = (d_hi - d_lo) / 2 + b.dev_xy
            lam = max(0.0, min(1.0 / dt, (ub * math.sin(g * a0 / 2) / (g * a0 / 2) * math.cos(beta) - b.speed_xy)
                               / spread) * (1 - 1e-6))
            lam_z = max(0.0, min(1.0 / dt, (wb - b.speed_z) / (z_f + b.dev_z)) * (1 - 1e-6))
            out.append(TerminalLaw(d_lo=d_lo, d_hi=d_hi, d_star=(d_lo + d_hi) / 2, alpha_max=alpha_f, z_max=z_f,
                                   gain_d=lam, gain_z=lam_z, turn=g))
    return out


def _no_set(b: TerminalBounds) -> Condition:
    return Condition("terminal_in_region[room]", "R shrunk by the last arc's margins, the replay's deviation and "
                     "half an arc leaves room for a terminal set", None, None, False,
                     f"e_d room [{b.room_d[0]:.4g}, {b.room_d[1]:.4g}] m, |e_o| room {b.room_o:.4g}, "
                     f"|e_z| room {b.room_z:.4g} m, deviation {b.dev_xy:.4g} m")


def _not_covered(scenario: Scenario, region: Region) -> tuple[Condition, ...]:
    """The designs the theorem does not cover yet, named (whatever the backup): a minimum surge after a target
    that may stop, a region whose heading is not ``toward``."""
    if scenario.limits.u_min is not None and not scenario.trajectory.horizontal_speed_floor() > 0.0:
        return (Condition("terminal_surge_floor", "under a minimum surge, a target whose horizontal speed has a "
                          "positive floor (the terminal law's surge follows the target's speed along the line of "
                          "sight; a target that stops or turns toward the vehicle makes it negative)", None, None,
                          False, f"limits.u_min = {scenario.limits.u_min:g} m/s, trajectory "
                          f"{scenario.trajectory.kind!r} has no speed floor; the safe tier does not need it"),)
    if region.heading != "toward":
        return (Condition("terminal_heading", "region.heading = toward (the terminal law points at the "
                          "target)", None, None, False, f"heading {region.heading!r}"),)
    return ()


def proves_feasibility(scenario: Scenario, region: Region) -> bool:
    """True when step 17 covers the design of ``scenario`` (:func:`_not_covered` names none): its terminal
    ingredients are then the conditions under which a plan exists at every period of the loop with the candidate.
    A run without it (``controller.candidate = false``, a run setting, not part of the design) falls back to the
    run-time premise ``recursive_feasibility``."""
    return not _not_covered(scenario, region)


def design_terminal(scenario: Scenario, design: Design, region: Region, safe: SafeSet | None
                    ) -> tuple[TerminalLaw | None, tuple[Condition, ...]]:
    """(law, conditions): the first set of the grid meeting every condition (module doc), else None and the
    conditions of the set most favourable to the path (the invariant one with the smallest reach), or, when no
    set meets its own conditions, those of the set closest to it (:func:`_shortfall`; they do not read the backup,
    so they are the verdict whatever ``safe`` is). ``safe`` None (no certified backup): ``terminal_backup`` once a
    set meets its own conditions."""
    refused = _not_covered(scenario, region)
    if refused:
        return None, refused
    b = terminal_bounds(scenario, design, region)
    sensing = None if safe is None else sensing_condition(scenario, b, safe)
    path = path_samples(scenario, horizon_end(scenario))

    def geometry(foot: PathFootprint, explain: bool = False) -> tuple[Condition, ...]:
        return path_clearance(scenario, foot, path, explain=explain) + path_workspace(scenario, foot, path)

    closest: tuple[tuple[int, float], tuple[Condition, ...]] | None = None
    narrowest: tuple[float, TerminalLaw, tuple[Condition, ...]] | None = None
    blocked: list[PathFootprint] = []  # footprints whose path failed: one that contains any of them fails too

    def fed() -> bool:
        """Whether the feedforward's laws are worth a search (the proof does not depend on it): the rest of the
        design holds, and the best memoryless set fails nothing the feedforward cannot lower."""
        best = narrowest[2] if narrowest is not None else closest[1] if closest is not None else ()
        return all(c.ok for c in design.conditions) and not any(
            not c.ok and c.condition in FEEDFORWARD_CANNOT_LOWER for c in best)

    for law in itertools.chain(_grid_sets(b), _refined(b, fed), _started(b, start_distance(scenario), fed)):
        own = law_conditions(b, law)
        if not all(c.ok for c in own):
            miss = _shortfall(own)
            if closest is None or miss < closest[0]:
                closest = (miss, own)
            continue
        if safe is None or sensing is None:
            return None, (Condition("terminal_backup", "a backup safe set for the terminal condition", None, None,
                                    False, "no backup"),)
        conds = own + (sensing, initial_plan_condition(scenario, design, region, law, safe))
        if all(c.ok for c in conds):  # the path is sampled only for sets that pass the rest, and are not blocked
            foot = footprint_of(scenario, design, b, law, safe)
            if not any(contains(foot, small) for small in blocked):
                conds = conds + geometry(foot)
                if all(c.ok for c in conds):
                    return law, conds
                blocked.append(foot)
        if narrowest is None or law.d_hi < narrowest[0]:
            narrowest = (law.d_hi, law, conds)
    if narrowest is not None:  # its path measured again, explained (the search's pass did not say why it failed)
        _, law, conds = narrowest
        rest = tuple(c for c in conds if not c.condition.startswith("path_"))
        return None, rest + geometry(footprint_of(scenario, design, b, law, safe), explain=True)
    return None, closest[1] if closest is not None else (_no_set(b),)


def _shortfall(conds: tuple[Condition, ...]) -> tuple[int, float]:
    """How far a set is from meeting its conditions: the number that fail, then the largest lhs / rhs among
    them (inf where a side is not finite or positive): the set reported when none of the grid holds."""
    failed = [c for c in conds if not c.ok]
    worst = max((c.lhs / c.rhs if c.lhs is not None and c.rhs is not None and c.rhs > 0 and math.isfinite(c.lhs)
                 else math.inf for c in failed), default=0.0)
    return len(failed), worst


def with_terminal(scenario: Scenario, design: Design, region: Region, safe: SafeSet | None,
                  rests: bool = False) -> Design:
    """``design`` with the terminal ingredients' conditions appended and its ``terminal`` law set when they all
    hold; unchanged when it has no finite margins or V̄ (nothing to complete). ``rests``: the backup does not blend
    from the last command, so rate-limited plans must end within J of its hand-over command (refused by name
    under a rate limit: the terminal law's row does not end there)."""
    m = design.margins
    if m is None or design.v_bar is None or not all(math.isfinite(x) for x in m.position + m.e_d + m.e_z + m.e_o):
        return design
    refused = _not_covered(scenario, region)
    if scenario.limits.rate is not None and rests:
        refused = refused + (Condition("terminal_rate", "under rate-limited plans a backup that blends from the "
                                       "last command (a plan's last row need not end at the backup's hand-over "
                                       "command, where the terminal law's row is not)", None, None, False,
                                       f"controller.backup = {scenario.controller.backup!r} starts from its own "
                                       "command"),)
    if refused:
        return dataclasses.replace(design, conditions=design.conditions + refused)
    law, conds = design_terminal(scenario, design, region, safe)
    return dataclasses.replace(design, conditions=design.conditions + conds, terminal=law)
