"""The dynamic plant inside the theorem: the velocity loop's bound and the backup's command rate, composed.

On the dynamic plant the kinematic command v is tracked by a velocity loop (``docs/plant.md``). Its error
E = (E_u, E_w, E_r) (:func:`verify.vehicle.bound.velocity_loop_bound`) depends on how far the command
jumps; the command jumps

* at period boundaries by at most J = ρ δ (the plans' rate limit ``limits.rate``, imposed by the FHOCP and
  checked by the plan check: between nodes and against the last applied command, 0 at t = 0); not at the
  hand-over, where the ramped backup starts from the last applied command (a backup without a ramp makes
  plans end at rest instead, ``Tightening.terminal_rest``), and
* at every tick during the backup by at most :func:`verify.backup.backup_tick_change` (the backup law's
  command rate × h, :func:`verify.backup.backup_command_rate`, finite because the law is faded near its
  anchor, ramped after the hand-over and, with the continuous yaw law, free of the ridge's jump).

E in turn enters ω̄ (:func:`verify.design.disturbance_bounds`), the tube, the hand-over margins and the
backup's proof, which fix the backup's command rate. :func:`solve_dynamic` closes this loop as a checked
fixed point: it *assumes* a bound E_a, derives everything from it (the backup designed so that its command
rate keeps E below E_a when it can: ``fits``, the gentle search of :mod:`verify.backup.search`), computes E
from the resulting jump bounds, and certifies only when E < E_a component-wise (condition
``loop_consistent``). Every step is
monotone in E_a, so the derived statements hold with E_a in place of E (first exit: the loop error is
continuous between jumps and the L1 bound covers the jumps).

On the dynamic plant the ancillary feedback is off (σ = 0, κ ≡ 0): κ changes at every tick by an amount
the loop bound would have to absorb; a scenario asking for σ > 0 fails ``loop_kappa``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flint import arb

from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.scenario import Scenario

from verify.backup import BackupCertificate, backup_tick_change
from verify.design import Condition, Design, DisturbanceBounds, disturbance_bounds
from verify.gains import GainBounds
from verify.intervals import upper
from verify.region import Region
from verify.tiers import solve_tiers
from verify.vehicle.bound import LoopBound, rate_authority_conditions, velocity_loop_bound

__all__ = ["DynamicSolution", "solve_dynamic", "plan_jumps", "FIXED_POINT_ROUNDS", "PLAN_CHECK_TOLERANCE"]

#: Absolute tolerance of the plan check's rate rows (``tubekit.loop.plan_check.RATE_TOLERANCE``; verify may not
#: import the loop, a test keeps the two equal): an accepted plan jumps by at most ρ δ + this.
PLAN_CHECK_TOLERANCE = 1e-9
#: Rounds of the fixed point E_a -> E (a work unit: the verdict is the same on any machine).
FIXED_POINT_ROUNDS = 10
#: The first round's assumed bound over the plans-only one.
_INFLATE = 1.25
#: Growth of the assumed bound over the derived one between rounds (small: a larger E_a widens ω̄ and the yaw
#: error, and the gentle backups that fit at E_a may no longer certify at a much larger one).
_STEP = 1.05


@dataclass(frozen=True)
class DynamicSolution:
    """The composed bounds of a dynamic scenario.

    Attributes
    ----------
    loop : LoopBound
        The velocity loop's bound computed from the jump bounds of the last round.
    assumed : (3,) floats
        E_a (m/s, m/s, rad/s): the bound ω̄, the tube and the backup were derived with.
    dist : DisturbanceBounds
        ω̄ with E_a.
    designs, best, safe, backup
        As :func:`verify.certificate.certify` computes them, with ``dist``.
    conditions : tuple of Condition
        The loop's conditions, ``loop_consistent``, ``rate_authority[*]``, ``loop_kappa``.
    """

    loop: LoopBound
    assumed: tuple[float, float, float]
    dist: DisturbanceBounds
    designs: tuple[Design, ...]
    best: Design
    safe: Design | None
    backup: BackupCertificate
    conditions: tuple[Condition, ...]


def plan_jumps(scenario: Scenario) -> tuple[float, float, float]:
    """J = ρ δ + the plan check's tolerance per channel (m/s, m/s, rad/s): the largest command change an accepted
    plan makes per period (between nodes, against the last command; into the terminal rest where one is
    imposed); 2V without a rate limit (any two commands in V)."""
    lim, dt = scenario.limits, float(scenario.controller.dt)
    rate = getattr(lim, "rate", None)
    if rate is None:
        return tuple(2.0 * float(x) for x in lim.vector)
    return tuple(upper(arb(r) * arb(dt) + arb(PLAN_CHECK_TOLERANCE)) for r in rate)


def _rate_conditions(scenario: Scenario, loop: LoopBound) -> list[Condition]:
    """``limits_rate`` (a rate limit is set) and ``rate_authority[c]``
    (:func:`verify.vehicle.bound.rate_authority_conditions` against the loop bound's ``authority``)."""
    rate = getattr(scenario.limits, "rate", None)
    if rate is None:
        return [Condition("limits_rate", "limits.rate set (the plans' command jumps bounded by rho delta)", None,
                          None, False, "without a rate limit a plan may jump by 2V between periods; the loop "
                          "error after such a jump is of the order of V")]
    return rate_authority_conditions(loop.authority, rate)


def _kappa_condition(sigma: float) -> Condition:
    return Condition("loop_kappa", "sigma = 0 on the dynamic plant (no ancillary feedback)", float(sigma), 0.0,
                     sigma == 0.0, "kappa changes at every tick by an amount no rate limit bounds; the velocity "
                     "loop's bound covers the plans' jumps and the backup's rate only")


def _tiers_at(scenario: Scenario, region: Region, gains: GainBounds, sigmas: tuple[float, ...],
              assumed: tuple[float, float, float]):
    dist = disturbance_bounds(scenario, loop_error=assumed)
    return (dist, *solve_tiers(scenario, region, gains, sigmas, dist, fits=_fits(scenario, dist, assumed)))


def _ratio(error: tuple[float, ...], assumed: tuple[float, float, float]) -> float:
    """max over u, w, r of E / E_a (inf when E is not finite or E_a is 0 with E > 0)."""
    return max((e / a if a > 0 else (math.inf if e > 0 else 0.0)) for e, a in zip(error, assumed))


def _fits(scenario: Scenario, dist: DisturbanceBounds, assumed: tuple[float, float, float]):
    """``fits(law, safe)`` for :func:`verify.backup.design_backup`: E / E_a of the loop bound the candidate's
    command rate gives (inf when the loop bound fails). The scenario's part is read once, not per candidate."""
    fixed = _LoopInputs.of(scenario)

    def ratio(law: StationKeeping, safe: SafeSet) -> float:
        loop = fixed.loop(law, safe, dist, assumed)
        return _ratio(loop.error, assumed) if loop.certified else math.inf
    return ratio


@dataclass(frozen=True)
class _LoopInputs:
    """What the loop bound reads from the scenario: the vehicle, V, h, δ and the plans' jumps J."""

    params: object
    v_max: tuple[float, float, float]
    tick: float
    period: float
    plans: tuple[float, float, float]

    @classmethod
    def of(cls, scenario: Scenario) -> "_LoopInputs":
        return cls(params=scenario.plant.params, v_max=tuple(float(x) for x in scenario.limits.vector),
                   tick=1.0 / float(scenario.controller.ancillary_rate_hz), period=float(scenario.controller.dt),
                   plans=plan_jumps(scenario))

    def loop(self, law: StationKeeping, safe: SafeSet, dist: DisturbanceBounds,
             assumed: tuple[float, float, float]) -> LoopBound:
        """The loop bound for the jump bounds that ``assumed`` implies (plans: J; backup: its rate × h)."""
        per_tick = backup_tick_change(law, safe, omega_xy=dist.omega_xy, omega_z=dist.omega_z,
                                      limits=self.v_max, loop_error=assumed, tick=self.tick)
        per_period = tuple(max(j, t) for j, t in zip(self.plans, per_tick))
        return velocity_loop_bound(self.params, v_max=self.v_max, tick=self.tick, period=self.period,
                                   jump_tick=per_tick, jump_period=per_period)


def _loop_at(scenario: Scenario, law: StationKeeping, safe: SafeSet, dist: DisturbanceBounds,
             assumed: tuple[float, float, float]) -> LoopBound:
    """The loop bound for ``law`` (:meth:`_LoopInputs.loop`)."""
    return _LoopInputs.of(scenario).loop(law, safe, dist, assumed)


def _consistent(loop: LoopBound, assumed: tuple[float, float, float]) -> Condition:
    ratio = _ratio(loop.error, assumed)
    ok = bool(loop.certified and ratio < 1.0)
    return Condition("loop_consistent", "E derived from the jump bounds < E assumed by omega_bar, the tube and the "
                     "backup (largest ratio over u, w, r)", ratio if math.isfinite(ratio) else None, 1.0, ok,
                     f"E = {[round(x, 6) for x in loop.error]}, assumed {[round(x, 6) for x in assumed]}")


def solve_dynamic(scenario: Scenario, region: Region, gains: GainBounds,
                  sigmas: tuple[float, ...]) -> DynamicSolution:
    """The checked fixed point E_a -> (ω̄, tube, backup) -> jumps -> E (module doc).

    Parameters
    ----------
    scenario : Scenario
        A scenario on the dynamic plant.
    region, gains : Region, GainBounds
        As :func:`verify.certificate.certify` computes them.
    sigmas : tuple of float
        σ values to try (1/s); the dynamic plant requires 0.
    """
    v_max = tuple(float(x) for x in scenario.limits.vector)
    tick = 1.0 / float(scenario.controller.ancillary_rate_hz)
    first = velocity_loop_bound(scenario.plant.params, v_max=v_max, tick=tick,
                                period=float(scenario.controller.dt), jump_tick=(0.0, 0.0, 0.0),
                                jump_period=plan_jumps(scenario))
    assumed = tuple(_INFLATE * e if math.isfinite(e) else math.inf for e in first.error)
    rounds, loop = 0, first
    while rounds < FIXED_POINT_ROUNDS and all(math.isfinite(a) for a in assumed):
        rounds += 1
        dist, designs, best, safe, backup = _tiers_at(scenario, region, gains, sigmas, assumed)
        loop = _loop_at(scenario, backup.law, backup.safe_set, dist, assumed)
        if not loop.certified or all(e < a for e, a in zip(loop.error, assumed)):
            break
        assumed = tuple(max(a, _STEP * e) for a, e in zip(assumed, loop.error))
    if rounds == 0:  # the plans' jumps alone already break the loop: report with a finite stand-in
        assumed = tuple(e if math.isfinite(e) else float(x) for e, x in zip(first.error, v_max))
        dist, designs, best, safe, backup = _tiers_at(scenario, region, gains, sigmas, assumed)
    conds = (*loop.conditions, _consistent(loop, assumed), *_rate_conditions(scenario, loop),
             _kappa_condition(best.sigma))
    return DynamicSolution(loop=loop, assumed=assumed, dist=dist, designs=designs, best=best, safe=safe,
                           backup=backup, conditions=conds)
