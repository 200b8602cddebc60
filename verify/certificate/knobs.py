"""What to change when a condition fails: the scenario field and the value that makes that inequality hold.

A failed condition is one inequality with both numbers (:class:`verify.theorem.design.Condition`). Where
the inequality can be solved for ONE scenario field in closed form — every other input of the theorem left
as it is — :func:`knobs_for` names that field and the value that would pass; where it cannot, it says
nothing rather than guess. The table (:data:`KNOB_TABLE`), with ū, r̄ the surge and yaw limits, g the sway
gain and a_s its amplitude, r̄_v the vehicle radius, P / P_z the target's horizontal / vertical speed, ω̄ the
disturbance bounds:

* ``keep_up[u]`` (ū >= P + ω̄_xy): ``limits.u_max`` >= (rhs − g r̄ ū) / (1 − g r̄) (γ̄ = g ū r̄ + a_s grows
  with ū; only when g r̄ < 1), or the target's speed field (``trajectory.rate`` of a circle or helix, ``speed``
  of waypoints) times (lhs − rhs + P) / P;
* ``keep_up[w]`` (w̄ >= |ż_d| + ω̄_z): ``limits.w_max`` >= rhs, or ``trajectory.climb`` (helix; ``speed`` of
  waypoints) times (lhs − rhs + P_z) / P_z;
* ``yaw_budget`` (r̄ >= ω̄_xy / ε): ``epsilon`` >= ω̄_xy / lhs (when below ``region.e_d_max``), or
  ``limits.r_max`` >= (rhs − s r̄) / (1 − s), s = g ū / ε (γ̄ grows with r̄; only when s < 1);
* ``sensing`` (T ‖(ū, w̄)‖ + M_pos + r̄_v < R̄): ``sensing_range`` >= lhs;
* ``obstacles[i,j]`` (‖p_i − p_j‖ > 2 (r̄_v + M_pos) + r_i + r_j): ``vehicle_radius`` <= r̄_v − (rhs − lhs) / 2;
* ``sway_bound`` (declared >= γ̄): ``disturbance.sway.bound`` >= rhs;
* ``rate_authority[c]`` (ρ_c <= a_c): ``limits.rate[c]`` <= rhs (when a_c > 0);
* ``terminal_rate[c]`` (S + K(deviation) <= J = ρ_c δ, the reported set's face at its narrowest): ``limits.rate[c]``
  >= lhs / (δ (1 − FACE_ROOM)) (kinematic plant: neither K depends on the rates); exact for the reported set,
  another set of the grid may pass with less;
* ``loop_fixed_point`` (the velocity loop's bound closes) on the dynamic plant with ``controller.backup = "none"``
  (then the loop is bounded for the plans' jumps alone, ``verify.vehicle.compose.plans_only_bound``):
  ``limits.u_max`` <= the largest value a bisection over (0, ū) finds at which that bound closes, rounded down and
  checked again at the rounded value (the only rule not in closed form: the bound is a fixed point; the value
  shown passes, a smaller one is not promised to).

The rows of ``keep_up`` and ``yaw_budget`` hold only for a design at σ = 0 (then κ̄ = 0 and V̄ = V; at
σ > 0 the tube, hence κ̄, moves with every one of those fields) on the kinematic plant, with the scenario's
own region (no ``region=`` override). ``safe_only.*`` conditions are the σ = 0 design's. On the dynamic plant
ω̄, the tube and the backup are one fixed point of the velocity loop's error, which every field but the rate
limit moves: only ``rate_authority[c]`` has a knob there (the authority a_c depends on V and the vehicle), and
``loop_fixed_point`` without a backup.
Not solvable for one field, so silent: ``tube``, ``e_bar[*]`` (the margins move with the region through the
gain bounds), ``v_bar[*]``, ``initial*``, ``target_in_workspace`` (two corners), the backup's and the
velocity loop's conditions.

Each value is rounded to three significant digits in the passing direction after a relative margin of
1e-9 (the condition is evaluated in Arb with outward rounding), so setting the field to the value, or
beyond it in the direction shown, makes that inequality hold; ``tests/test_verify_certificate_knobs.py``
re-certifies with each value and checks the condition.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal
from typing import Callable

from tubekit.model.trajectory import Circle, Helix, Waypoints
from tubekit.scenario import Scenario

from verify.certificate.record import CertificateRecord
from verify.theorem.design import Condition, Design, DisturbanceBounds
from verify.theorem.terminal_rows import FACE_ROOM
from verify.theorem.tiers import SAFE_PREFIX

__all__ = ["Knob", "KnobRule", "KNOB_TABLE", "knobs_for", "failure_knobs", "DIGITS", "MARGIN"]

#: Significant digits of a suggested value.
DIGITS = 3
#: Relative margin applied before rounding (covers the Arb enclosures' outward rounding).
MARGIN = 1e-9


@dataclass(frozen=True)
class Knob:
    """A scenario field and the value that makes one failed condition hold (the other inputs unchanged).

    Attributes
    ----------
    condition : str
        The condition's name (``keep_up[u]``, ``safe_only.sensing``).
    field : str
        The dotted TOML key (``limits.u_max``, ``trajectory.rate``, ``limits.rate[0]``).
    relation : str
        ``">="`` (the value or more passes) or ``"<="`` (the value or less).
    value : float
        The value, rounded to :data:`DIGITS` significant digits in the passing direction.
    unit : str
        Its unit (``m``, ``m/s``, ``rad/s``, ``m/s^2``).
    magnitude : bool
        The bound is on ``|field|`` (a signed field such as ``trajectory.rate``: keep its sign).
    """

    condition: str
    field: str
    relation: str
    value: float
    unit: str
    magnitude: bool = False

    def clause(self) -> str:
        """``limits.u_max >= 0.503 m/s`` (``|trajectory.rate| <= 0.0933 rad/s`` for a magnitude)."""
        name = f"|{self.field}|" if self.magnitude else self.field
        return f"{name} {self.relation} {self.value:g} {self.unit}"

    def text(self) -> str:
        """``set limits.u_max >= 0.503 m/s``."""
        return f"set {self.clause()}"

    def holds(self, value: float) -> bool:
        """True when ``value`` (the field's new value; its magnitude for a magnitude knob) is on the passing side."""
        v = abs(value) if self.magnitude else value
        return v >= self.value if self.relation == ">=" else v <= self.value


def _rounded(x: float, up: bool) -> float | None:
    """``x`` after the margin, rounded to :data:`DIGITS` significant digits upward (``up``) or downward; None when
    ``x`` is not a finite positive number (every knob's field is positive)."""
    if not (math.isfinite(x) and x > 0.0):
        return None
    x = x * (1.0 + MARGIN) if up else x * (1.0 - MARGIN)
    d = Decimal(x)
    step = Decimal(1).scaleb(d.adjusted() - DIGITS + 1)
    out = float(d.quantize(step, rounding=ROUND_CEILING if up else ROUND_FLOOR))
    return out if out > 0.0 else None


@dataclass(frozen=True)
class _Context:
    """What a rule reads beside the condition: the design it belongs to, the scenario, the disturbance."""

    scenario: Scenario
    dist: DisturbanceBounds
    design: Design | None
    dynamic: bool
    own_region: bool

    def sigma_zero(self) -> Design | None:
        """The condition's design when it is a kinematic one at σ = 0 with the scenario's region (κ̄ = 0, V̄ = V,
        nothing depends on σ), else None."""
        d = self.design
        if d is None or self.dynamic or not self.own_region or d.sigma != 0.0 or any(k != 0.0 for k in d.tube.kappa):
            return None
        return d


@dataclass(frozen=True)
class _Failed:
    """A failed condition's name and its two numbers (both present)."""

    name: str
    lhs: float
    rhs: float

    def knob(self, field: str, relation: str, exact: float, unit: str, magnitude: bool = False) -> list[Knob]:
        """``[Knob]`` with ``exact`` rounded in the passing direction, or ``[]`` when it is not a positive number."""
        value = _rounded(exact, up=relation == ">=")
        return [] if value is None else [Knob(self.name, field, relation, value, unit, magnitude)]


def _target(c: _Failed, ctx: _Context, speed: float, allowed: float, vertical: bool) -> list[Knob]:
    """The trajectory's own speed field scaled by ``allowed / speed`` (both m/s; one field per kind, none for a
    line, whose velocity is a vector)."""
    if not (speed > 0.0 and allowed > 0.0):
        return []
    traj, scale = ctx.scenario.trajectory, allowed / speed
    if isinstance(traj, Waypoints):
        return c.knob("trajectory.speed", "<=", traj.speed * scale, "m/s")
    if isinstance(traj, Helix) and vertical:
        return c.knob("trajectory.climb", "<=", abs(traj.climb) * scale, "m/s", magnitude=True)
    if isinstance(traj, Circle) and not vertical:  # a helix is a circle that climbs
        return c.knob("trajectory.rate", "<=", abs(traj.rate) * scale, "rad/s", magnitude=True)
    return []


def _keep_up_u(c: _Failed, ctx: _Context) -> list[Knob]:
    """ū >= P + ω̄_xy with ω̄_xy = current + g ū r̄ + a_s (kinematic): ū (1 − g r̄) >= rhs − g r̄ ū."""
    design = ctx.sigma_zero()
    if design is None:
        return []
    lim = ctx.scenario.limits
    slope = ctx.scenario.disturbance.sway.gain * lim.r_max
    out = c.knob("limits.u_max", ">=", (c.rhs - slope * lim.u_max) / (1.0 - slope), "m/s") if slope < 1.0 else []
    speed = design.problem.pd_xy
    return out + _target(c, ctx, speed, c.lhs - (c.rhs - speed), vertical=False)


def _keep_up_w(c: _Failed, ctx: _Context) -> list[Knob]:
    """w̄ >= |ż_d| + ω̄_z; ω̄_z does not depend on w̄."""
    design = ctx.sigma_zero()
    if design is None:
        return []
    speed = design.problem.pd_z
    return (c.knob("limits.w_max", ">=", c.rhs, "m/s")
            + _target(c, ctx, speed, c.lhs - (c.rhs - speed), vertical=True))


def _yaw_budget(c: _Failed, ctx: _Context) -> list[Knob]:
    """r̄ >= ω̄_xy / ε: ε >= ω̄_xy / r̄, or r̄ (1 − s) >= rhs − s r̄ with s = g ū / ε (γ̄ grows with r̄)."""
    if ctx.sigma_zero() is None:
        return []
    sc = ctx.scenario
    eps = c.knob("epsilon", ">=", ctx.dist.omega_xy / c.lhs, "m")
    out = [k for k in eps if k.value < sc.region.e_d_max]
    slope = sc.disturbance.sway.gain * sc.limits.u_max / sc.epsilon
    if slope < 1.0:
        out += c.knob("limits.r_max", ">=", (c.rhs - slope * sc.limits.r_max) / (1.0 - slope), "rad/s")
    return out


def _sensing(c: _Failed, ctx: _Context) -> list[Knob]:
    """T ‖(ū, w̄)‖ + M_pos + r̄_v < R̄: R̄ enters nothing else."""
    return [] if ctx.dynamic else c.knob("sensing_range", ">=", c.lhs, "m")


def _obstacles(c: _Failed, ctx: _Context) -> list[Knob]:
    """‖p_i − p_j‖ > 2 (r̄_v + M_pos) + r_i + r_j: r̄_v < r̄_v,now − (rhs − lhs) / 2 (M_pos does not depend on
    r̄_v)."""
    if ctx.dynamic:
        return []
    return c.knob("vehicle_radius", "<=", ctx.scenario.vehicle_radius - (c.rhs - c.lhs) / 2.0, "m")


def _sway_bound(c: _Failed, ctx: _Context) -> list[Knob]:
    """declared >= γ̄; γ̄ does not depend on the declared bound."""
    return [] if ctx.dynamic else c.knob("disturbance.sway.bound", ">=", c.rhs, "m/s")


#: Bisection steps of the ``loop_fixed_point`` knob (each one plans-only loop bound: 1.2-1.5 s over the published
#: BlueROV2 box with its cells, so the knob costs about 20 s there, once per scenario: it is memoised).
LOOP_BISECTION_STEPS = 12


def _loop_closes(scenario: Scenario, u_max: float) -> bool:
    """True when the plans-only loop bound of ``scenario`` with ``limits.u_max`` = ``u_max`` is certified (False
    when that value is not a valid scenario, e.g. below ``limits.initial``)."""
    from tubekit.exceptions import ConfigError
    from verify.vehicle.compose import plans_only_bound
    try:
        return plans_only_bound(scenario.with_changes(**{"limits.u_max": u_max})).certified
    except ConfigError:
        return False


def _loop_fixed_point(c: _Failed, ctx: _Context) -> list[Knob]:
    """The largest ``limits.u_max`` below the scenario's at which the plans-only loop closes (module doc); with no
    backup only (any backup adds its own jumps, which the plans' bound does not cover)."""
    sc = ctx.scenario
    if not ctx.dynamic or sc.controller.backup != "none":
        return []
    value = _largest_closing_u_max(sc)
    return [] if value is None else [Knob(c.name, "limits.u_max", "<=", value, "m/s")]


@functools.lru_cache(maxsize=8)
def _largest_closing_u_max(scenario: Scenario) -> float | None:
    """The bisection of :func:`_loop_fixed_point` (m/s), rounded down and checked again; None when that value does
    not close. Memoised per scenario (frozen, hashable): a certificate's summary and report ask it again."""
    lo, hi = 0.0, float(scenario.limits.u_max)
    for _ in range(LOOP_BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _loop_closes(scenario, mid) else (lo, mid)
    value = _rounded(lo, up=False)
    if value is None or not _loop_closes(scenario, value):
        return None
    return value


def _rate_authority(c: _Failed, ctx: _Context) -> list[Knob]:
    """ρ_c <= a_c; a_c depends on V and the vehicle only."""
    axis = "uwr".index(c.name[-2])
    return c.knob(f"limits.rate[{axis}]", "<=", c.rhs, ("m/s^2", "m/s^2", "rad/s^2")[axis])


def _terminal_rate(c: _Failed, ctx: _Context) -> list[Knob]:
    """S + K(deviation) <= J with S at its narrowest (the face's K(arc): the jump left no wider one), so the
    reported set passes once J >= lhs / (1 − FACE_ROOM) (S is then J (1 − FACE_ROOM) − K(deviation) >= K(arc)).
    Kinematic plant only: on the dynamic one the deviation grows with the jumps through the velocity loop's bound."""
    if ctx.dynamic or ctx.design is None:
        return []
    axis = "uwr".index(c.name[-2])
    dt = float(ctx.scenario.controller.dt)
    return c.knob(f"limits.rate[{axis}]", ">=", c.lhs / (dt * (1.0 - FACE_ROOM)), ("m/s^2", "m/s^2", "rad/s^2")[axis])


@dataclass(frozen=True)
class KnobRule:
    """One row of :data:`KNOB_TABLE`: the condition names it matches, the fields it may name, its solver."""

    pattern: str
    fields: tuple[str, ...]
    solve: Callable[[_Failed, _Context], list[Knob]]
    numbers: bool = True  # the rule reads the condition's two numbers (a failed one may lack them)

    def matches(self, name: str) -> bool:
        """True when ``name`` (without the ``safe_only.`` prefix) is a condition of this row."""
        return re.fullmatch(self.pattern, name) is not None


#: Every condition with a closed-form knob (module doc); any other condition has none.
KNOB_TABLE: tuple[KnobRule, ...] = (
    KnobRule(r"keep_up\[u\]", ("limits.u_max", "trajectory.rate", "trajectory.speed"), _keep_up_u),
    KnobRule(r"keep_up\[w\]", ("limits.w_max", "trajectory.climb", "trajectory.speed"), _keep_up_w),
    KnobRule(r"yaw_budget", ("epsilon", "limits.r_max"), _yaw_budget),
    KnobRule(r"sensing", ("sensing_range",), _sensing),
    KnobRule(r"obstacles\[\d+,\d+\]", ("vehicle_radius",), _obstacles),
    KnobRule(r"sway_bound", ("disturbance.sway.bound",), _sway_bound),
    KnobRule(r"rate_authority\[[uwr]\]", ("limits.rate",), _rate_authority),
    KnobRule(r"terminal_rate\[[uwr]\]", ("limits.rate",), _terminal_rate),
    KnobRule(r"loop_fixed_point", ("limits.u_max",), _loop_fixed_point, numbers=False),
)


def _context(cert: CertificateRecord, name: str) -> tuple[_Context, str]:
    """The context of condition ``name`` (its design: the safe-only one for ``safe_only.*``, the chosen one for
    the tracking design's, none for the backup's and the plant's) and the name without the prefix."""
    if name.startswith(SAFE_PREFIX):
        design, base = cert.safe_design, name[len(SAFE_PREFIX):]
    else:
        design = cert.design if any(c.condition == name for c in cert.design.conditions) else None
        base = name
    inputs = cert.inputs
    return _Context(scenario=inputs.scenario, dist=cert.disturbance, design=design, dynamic=inputs.dynamic,
                    own_region=not inputs.region_override), base


def knobs_for(cert: CertificateRecord, condition: Condition) -> tuple[Knob, ...]:
    """The knobs of one failed ``condition`` of ``cert`` (empty when it holds, when a side is missing, or when its
    inequality is not solvable for one field: module doc)."""
    if condition.ok is not False:
        return ()
    ctx, base = _context(cert, condition.condition)
    rule = next((r for r in KNOB_TABLE if r.matches(base)), None)
    if rule is None:
        return ()
    if condition.lhs is None or condition.rhs is None:
        if rule.numbers:
            return ()
        return tuple(rule.solve(_Failed(condition.condition, math.nan, math.nan), ctx))
    return tuple(rule.solve(_Failed(condition.condition, float(condition.lhs), float(condition.rhs)), ctx))


def failure_knobs(cert: CertificateRecord) -> dict[str, tuple[Knob, ...]]:
    """For every failed condition of ``cert`` (in order), its knobs (possibly none)."""
    return {c.condition: knobs_for(cert, c) for c in cert.failures}
