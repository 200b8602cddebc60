"""The dynamic plant inside the theorem: the velocity loop's bound and the backup's command rate, composed.

On the dynamic plant the kinematic command v is tracked by a velocity loop (``docs/plant.md``). Its error
E = (E_u, E_w, E_r) (:func:`verify.vehicle.bound.velocity_loop_bound`) depends on how far the command
jumps; the command jumps

* at period boundaries by at most J = ρ δ (the plans' rate limit ``limits.rate``, imposed by the FHOCP and
  checked by the plan check: between nodes and against the last applied command, at t = 0 the box's point
  nearest rest, (u_min, 0, 0) under a minimum surge, else 0); not at the hand-over, where the ramped backup
  starts from the last applied command; a backup without a ramp makes plans end within J of its
  ``handover_command`` instead (``Tightening.terminal_rest``: at rest for station keeping, at the loiter's
  surge), and its first command is within :func:`handover_jump` of the plan's last, a jump charged per period;
* at every tick during the backup by at most the law's proof's ``tick_change`` (station keeping:
  :func:`verify.backup.backup_tick_change`, the command rate × h of :func:`verify.backup.backup_command_rate`,
  finite because the law is faded near its anchor, ramped after the hand-over and, with the continuous yaw law,
  free of the ridge's jump).

The run starts trimmed at its first command (``docs/plant.md`` section 2), so the loop's start transient is
d(ν(0))/m, which vanishes at rest. With a rate limit that command is within J of the loop's initial command: the
plan check compares a plan's first node with the last applied command, initially the box's point nearest rest, and a
blending backup starts from that command. The start is then bounded over |ν(0)| <= |c_0| + J per channel, c_0 the
command before t = 0 (``limits.initial``, else (u_min, 0, 0): so (u_min + J_u, J_w, J_r))
(``first_command`` of the loop bound, u_min = 0 without a minimum surge); for a law that does not blend, over V.
Under ``[plant] start = "settled"`` the run starts at the loop's equilibrium at c_0 (``settled`` of the loop bound:
no start transient), and the first command is a jump from c_0: within J for a plan or a blending backup (the
plan check, the ramp); for a law that does not blend the period's jump also covers :func:`start_jump`.
Under a minimum surge the fins' authority is taken over u >= u_min − E_u (``surge_floor``, :func:`surge_floor_of`).

A vehicle with lateral thrust regulates its sway by a loop of its own (command 0, never jumping): its error bound
E_v is the sway γ̄ in ω̄, assumed like E (``assumed_sway``) and checked the same way (E_v < its assumption).

E in turn enters ω̄ (:func:`verify.theorem.design.disturbance_bounds`), the tube, the hand-over margins and the
backup's proof, which fix the backup's command rate. :func:`solve_dynamic` closes this loop as a checked
fixed point: it *assumes* a bound E_a, derives everything from it (the backup designed so that its command
rate keeps E below E_a when it can: ``fits``, the gentle search of :mod:`verify.backup.search`), computes E
from the resulting jump bounds, and certifies only when E < E_a component-wise (condition
``loop_consistent``). Every step is
monotone in E_a, so the derived statements hold with E_a in place of E (first exit: the loop error is
continuous between jumps and the L1 bound covers the jumps).

The backup law enters only through its proof (:func:`verify.backup.proof_for`, keyed by the law's ``kind``):
its command's change per tick is :meth:`verify.backup.BackupProof.tick_change`. :func:`loop_for_law` evaluates
the loop bound and the plant's conditions for a *given* law and safe set at a given E_a (no design): the last
round of :func:`solve_dynamic` is that evaluation, and ``tubekit recheck`` runs it on the stored law
(:mod:`verify.studies.rederive`).

On the dynamic plant the ancillary feedback is off (σ = 0, κ ≡ 0): κ changes at every tick by an amount
the loop bound would have to absorb; a scenario asking for σ > 0 fails ``loop_kappa``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Sequence

from flint import arb

from tubekit.model.backup import BackupLaw, SafeSet
from tubekit.design_inputs import RATE_TOLERANCE
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario
from tubekit.validation import nonnegative

from verify.backup import BackupCertificate, Fits, proof_for
from verify.theorem.design import Condition, Design, DisturbanceBounds, disturbance_bounds
from verify.theorem.gains import GainBounds
from verify.kernel.intervals import upper
from verify.kernel.region import Region
from verify.theorem.tiers import solve_tiers
from verify.vehicle.bound import LoopBound, rate_authority_conditions, velocity_loop_bound

__all__ = ["DynamicSolution", "LawLoop", "solve_dynamic", "loop_for_law", "tracking_disturbance", "plan_jumps",
           "handover_jump", "start_jump", "surge_floor_of", "plans_only_bound", "FIXED_POINT_ROUNDS",
           "FIXED_POINT_RESTARTS", "PLAN_CHECK_TOLERANCE"]

#: The plan check's rate tolerance, carried by the proof (one number: :data:`tubekit.design_inputs.RATE_TOLERANCE`).
PLAN_CHECK_TOLERANCE = RATE_TOLERANCE
#: Rounds of the fixed point E_a -> E (a work unit: the verdict is the same on any machine).
FIXED_POINT_ROUNDS = 10
#: The first round's assumed bound over the plans-only one.
_INFLATE = 1.25
#: Further starts (× the plans-only bound) tried in turn when the fixed point from :data:`_INFLATE` does not close:
#: the gentle search and the 5 % steps make the end path-dependent (``benchmarks/fixed_point_start.py``), and every
#: start that closes is a certificate. The first that closes is kept; when none does, the first start's failure is
#: reported. Not tried when the plans' jumps alone break the loop (no round is run). A work unit, not a time budget.
FIXED_POINT_RESTARTS = (1.5, 1.65, 1.8)
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
    assumed_sway : float or None
        With lateral thrust, the sway loop's assumed bound (m/s), ω̄'s γ̄; None: the free hull's γ̄.
    dist : DisturbanceBounds
        ω̄ with E_a.
    designs, best, safe, backup
        As :func:`verify.certificate.certify.certify` computes them, with ``dist``.
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
    assumed_sway: float | None = None


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
              assumed: tuple[float, float, float], sway: float | None, plans: LoopBound):
    dist = disturbance_bounds(scenario, loop_error=assumed, loop_sway=sway)
    return (dist, *solve_tiers(scenario, region, gains, sigmas, dist, fits=_fits(scenario, dist, assumed, sway),
                               tracking_dist=tracking_disturbance(scenario, plans)))


def tracking_disturbance(scenario: Scenario, plans: LoopBound | None = None) -> DisturbanceBounds | None:
    """ω̄ of the tracking tier (``docs/verify.md`` step 17d): with the plans-only loop bound (:func:`plans_only_bound`: the
    plans' jumps J, the first command within J of rest, no backup) in place of the fixed point's E. Under the
    tracking tier a plan is accepted at every period (step 17), so every command is a plan's row and the backup
    never runs: the loop error stays within the plans-only bound, which carries the induction's premise along (at
    period k the commands so far are plans' rows, so the deviation over period k is the plans-only one, so the
    candidate passes at k + 1). None where that bound does not hold (its own conditions fail): the tracking designs
    then use the safe tier's bound. ``plans``: that bound when the caller has it (:func:`plans_only_bound`)."""
    first = plans_only_bound(scenario) if plans is None else plans
    if not first.certified or not all(math.isfinite(e) for e in first.error):
        return None
    sway = first.sway if scenario.plant.params.lateral else None
    if sway is not None and not math.isfinite(sway):
        return None
    return disturbance_bounds(scenario, loop_error=first.error, loop_sway=sway)


def _ratio(error: tuple[float, ...], assumed: tuple[float, ...]) -> float:
    """max over the channels of E / E_a (inf when E is not finite or E_a is 0 with E > 0)."""
    return max((e / a if a > 0 else (math.inf if e > 0 else 0.0)) for e, a in zip(error, assumed))


def _loop_ratio(loop: LoopBound, assumed: tuple[float, float, float], sway: float | None) -> float:
    """:func:`_ratio` over u, w, r and, with a sway loop (``sway`` its assumed bound), E_v / its assumption."""
    if sway is None:
        return _ratio(loop.error, assumed)
    return _ratio((*loop.error, loop.sway), (*assumed, sway))


def _fits(scenario: Scenario, dist: DisturbanceBounds, assumed: tuple[float, float, float],
          sway: float | None = None) -> Fits:
    """``fits(law, safe)`` for :func:`verify.backup.design_backup`: E / E_a of the loop bound the candidate's
    command rate gives (inf when the loop bound fails). The scenario's part is read once, not per candidate, and
    each (law, safe set) is bounded once: the tracking design's backup and the safe tier's try the same laws."""
    fixed = _LoopInputs.of(scenario)
    rated: dict[tuple[BackupLaw, SafeSet], float] = {}

    def ratio(law: BackupLaw, safe: SafeSet) -> float:
        if (law, safe) not in rated:
            loop = fixed.loop(law, safe, dist, assumed)
            rated[law, safe] = _loop_ratio(loop, assumed, sway) if loop.certified else math.inf
        return rated[law, safe]
    return ratio


@dataclass(frozen=True)
class _LoopInputs:
    """What the loop bound reads from the scenario: the vehicle, V, h, δ and the plans' jumps J."""

    params: object
    v_max: tuple[float, float, float]
    tick: float
    period: float
    plans: tuple[float, float, float]
    surge_floor: float = 0.0
    initial: tuple[float, float, float] = (0.0, 0.0, 0.0)
    settled: bool = False

    @classmethod
    def of(cls, scenario: Scenario) -> "_LoopInputs":
        return cls(params=scenario.plant.params, v_max=tuple(float(x) for x in scenario.limits.vector),
                   tick=1.0 / float(scenario.controller.ancillary_rate_hz), period=float(scenario.controller.dt),
                   plans=plan_jumps(scenario), surge_floor=surge_floor_of(scenario),
                   initial=tuple(float(x) for x in scenario.limits.start_command), settled=scenario.plant.settled)

    @property
    def start(self) -> tuple[float, float, float]:
        """F: the first command lies within J of the loop's initial command (``limits.initial``, else the box's
        point nearest rest: (u_min, 0, 0) under a minimum surge, 0 otherwise), so |y_c(0)| <= |c_0| + J per channel
        (m/s, m/s, rad/s)."""
        return tuple(upper(arb(abs(c)) + arb(j)) for c, j in zip(self.initial, self.plans))

    def loop(self, law: BackupLaw, safe: SafeSet, dist: DisturbanceBounds,
             assumed: tuple[float, float, float]) -> LoopBound:
        """The loop bound for the jump bounds that ``assumed`` implies (plans: J; backup: its proof's
        :meth:`~verify.backup.BackupProof.tick_change`, the command's rate × h; a law that does not blend: its
        hand-over jump, :func:`handover_jump`)."""
        proof = proof_for(law)
        per_tick = proof.tick_change(law, safe, omega_xy=dist.omega_xy, omega_z=dist.omega_z,
                                     limits=self.v_max, loop_error=assumed, tick=self.tick)
        per_period = tuple(max(j, t) for j, t in zip(self.plans, per_tick))
        if not law.blends:
            per_period = tuple(max(p, h) for p, h in zip(per_period, handover_jump(law, self.plans)))
            if self.settled:
                per_period = tuple(max(p, s) for p, s in zip(per_period, start_jump(law, self.initial)))
        sway = (0.0, 0.0, 0.0)
        if law.lateral:  # the sway command: the law's per-tick change; a plan takes over within its release of 0
            sway_tick = proof.sway_change(law, safe, omega_xy=dist.omega_xy, omega_z=dist.omega_z,
                                          limits=self.v_max, loop_error=assumed, tick=self.tick)
            sway = (law.sway_bound, sway_tick, max(sway_tick, law.sway_release))
        return velocity_loop_bound(self.params, v_max=self.v_max, tick=self.tick, period=self.period,
                                   jump_tick=per_tick, jump_period=per_period,
                                   first_command=self.start if law.blends else None, surge_floor=self.surge_floor,
                                   sway=sway, settled=self.settled)


def surge_floor_of(scenario: Scenario) -> float:
    """u_min (m/s) of ``limits.u_min``, 0 without a minimum surge (the loop bound's ``surge_floor``)."""
    return max(0.0, scenario.limits.surge_floor)


def handover_jump(law: BackupLaw, plans: tuple[float, float, float]) -> tuple[float, float, float]:
    """The command's jump at the hand-over to a law that does not blend (m/s, m/s, rad/s): the plan's last row is
    within J of the law's ``handover_command`` h (``Tightening.terminal_rest``) and the law's first command c has
    min_surge <= c_u <= u_b, |c_w| <= w_b, |c_r| <= k, so |c − v̂_{N−1}| <= J + (max(u_b − h_u, h_u − min_surge),
    w_b + |h_w|, k + |h_r|) (the loiter: J_u in surge, its surge being h_u)."""
    return tuple(upper(arb(j) + arb(x)) for j, x in zip(plans, start_jump(law, law.handover_command)))


def start_jump(law: BackupLaw, initial: Sequence[float]) -> tuple[float, float, float]:
    """How far the first command c of a law that does not blend can be from the command ``initial`` c_0 (m/s, m/s,
    rad/s; each difference rounded up): c has min_surge <= c_u <= u_b, |c_w| <= w_b, |c_r| <= k, so
    |c − c_0| <= (max(u_b − c_0u, c_0u − min_surge), w_b + |c_0w|, k + |c_0r|). With c_0 the settled start's
    command it is the jump at t = 0; with the hand-over command, :func:`handover_jump` less the plans' J."""
    b, c = [arb(x) for x in law.bounds], [arb(float(x)) for x in initial]
    return (max(upper(b[0] - c[0]), upper(c[0] - arb(law.min_surge))), upper(b[1] + abs(c[1])),
            upper(b[2] + abs(c[2])))


def _loop_at(scenario: Scenario, law: BackupLaw, safe: SafeSet, dist: DisturbanceBounds,
             assumed: tuple[float, float, float]) -> LoopBound:
    """The loop bound for ``law`` (:meth:`_LoopInputs.loop`)."""
    return _LoopInputs.of(scenario).loop(law, safe, dist, assumed)


def _consistent(loop: LoopBound, assumed: tuple[float, float, float], sway: float | None = None) -> Condition:
    ratio = _loop_ratio(loop, assumed, sway)
    ok = bool(loop.certified and ratio < 1.0)
    lateral = "" if sway is None else f"; sway loop E_v = {loop.sway:.6g}, assumed {sway:.6g}"
    return Condition("loop_consistent", "E derived from the jump bounds < E assumed by omega_bar, the tube and the "
                     "backup (largest ratio over u, w, r" + ("" if sway is None else " and the sway loop") + ")",
                     ratio if math.isfinite(ratio) else None, 1.0, ok,
                     f"E = {[round(x, 6) for x in loop.error]}, assumed {[round(x, 6) for x in assumed]}{lateral}")


def plans_only_bound(scenario: Scenario) -> LoopBound:
    """The loop bound for the plans' jumps alone (no backup), the first command within J of rest: the fixed
    point's start (a smaller start transient only lowers the bound, so a failure here is a failure with any law);
    with ``controller.backup = "none"`` the loop the certificate bounds."""
    inputs = _LoopInputs.of(scenario)
    return velocity_loop_bound(inputs.params, v_max=inputs.v_max, tick=inputs.tick, period=inputs.period,
                               jump_tick=(0.0, 0.0, 0.0), jump_period=inputs.plans, first_command=inputs.start,
                               surge_floor=inputs.surge_floor, settled=inputs.settled)


def _first_assumption(first: LoopBound, start: float = _INFLATE) -> tuple[float, float, float] | None:
    """E_a of the first round (``start`` × the plans-only E), None when the plans' jumps alone break the loop (no
    finite E: no round is run and the plans-only bound is reported)."""
    assumed = tuple(start * e if math.isfinite(e) else math.inf for e in first.error)
    return assumed if all(math.isfinite(a) for a in assumed) else None


def _first_sway(scenario: Scenario, first: LoopBound, start: float) -> float | None:
    """The sway loop's first assumed bound (``start`` × the plans-only E_v); None without lateral thrust."""
    return start * first.sway if scenario.plant.params.lateral else None


def _plant_conditions(scenario: Scenario, loop: LoopBound, assumed: tuple[float, float, float],
                      sigma: float, sway: float | None = None) -> tuple[Condition, ...]:
    """The loop's conditions, ``loop_consistent``, ``limits_rate`` / ``rate_authority[c]`` and ``loop_kappa``."""
    return (*loop.conditions, _consistent(loop, assumed, sway), *_rate_conditions(scenario, loop),
            _kappa_condition(sigma))


@dataclass(frozen=True)
class LawLoop:
    """The velocity loop evaluated for one backup law at one assumed bound (:func:`loop_for_law`).

    Attributes
    ----------
    assumed : (3,) floats
        E_a (m/s, m/s, rad/s): the bound ω̄ is derived with.
    dist : DisturbanceBounds
        ω̄ with E_a.
    loop : LoopBound
        The loop bound for the plans' jumps and the law's per-tick jumps (the plans-only bound when the plans'
        jumps alone break the loop).
    conditions : tuple of Condition
        The plant's conditions, as :attr:`DynamicSolution.conditions`.
    """

    assumed: tuple[float, float, float]
    dist: DisturbanceBounds
    loop: LoopBound
    conditions: tuple[Condition, ...]
    assumed_sway: float | None = None


def loop_for_law(scenario: Scenario, law: BackupLaw, safe: SafeSet, assumed: tuple[float, float, float],
                 sigma: float, assumed_sway: float | None = None) -> LawLoop:
    """The fixed point's check for a *given* backup law and safe set at the assumed E_a (no design).

    ω̄ = :func:`verify.theorem.design.disturbance_bounds` with E_a; the backup's per-tick jumps from the law's
    proof (:meth:`verify.backup.BackupProof.tick_change`: its ramp, fades, bands and their command rate); the loop
    bound E for them and the plans' jumps; ``loop_consistent`` (E < E_a), the rate conditions and ``loop_kappa``
    at σ (1/s). When the plans' jumps alone break the loop, the plans-only bound is reported, as
    :func:`solve_dynamic` does. For the law :func:`solve_dynamic` designed at its E_a this is its last round,
    number for number.

    Parameters
    ----------
    scenario : Scenario
        A scenario on the dynamic plant.
    law, safe : BackupLaw, SafeSet
        The backup law (any registered kind) and its safe set.
    assumed : (float, float, float)
        E_a (m/s, m/s, rad/s), finite and >= 0.
    sigma : float
        σ (1/s) of the design (the dynamic plant requires 0).
    assumed_sway : float, optional
        The sway loop's assumed bound (m/s): required with lateral thrust, refused without.
    """
    if len(tuple(assumed)) != 3:
        raise ConfigError("assumed", "three loop-error bounds (E_u, E_w, E_r)", assumed)
    e_a = tuple(nonnegative(f"assumed[{i}]", a) for i, a in enumerate(assumed))
    lateral = scenario.plant.params.lateral
    if lateral != (assumed_sway is not None):
        raise ConfigError("assumed_sway", "the sway loop's assumed bound (m/s) with lateral thrust, None without",
                          assumed_sway)
    sway = None if assumed_sway is None else nonnegative("assumed_sway", assumed_sway)
    dist = disturbance_bounds(scenario, loop_error=e_a, loop_sway=sway)
    first = plans_only_bound(scenario)
    loop = first if _first_assumption(first) is None else _LoopInputs.of(scenario).loop(law, safe, dist, e_a)
    return LawLoop(assumed=e_a, dist=dist, loop=loop, assumed_sway=sway,
                   conditions=_plant_conditions(scenario, loop, e_a, sigma, sway))


#: The last fixed points solved in this process, by their inputs (:func:`solve_dynamic` is a pure function of them;
#: a re-check and the certificate it re-checks, or a table of edits of one certificate, solve it once). At most
#: ``_SOLVED_KEEP``, the oldest dropped first: a solution and its key hold about 40 kB (bluerov2_pier, measured), so
#: a full memo holds about 10 MB.
_SOLVED: dict[str, DynamicSolution] = {}
_SOLVED_KEEP = 256


def _solved_key(scenario: Scenario, region: Region, gains: GainBounds, sigmas: tuple[float, ...]) -> str:
    """A canonical text of everything :func:`solve_dynamic` reads (the round limit and the starts included)."""
    return json.dumps([scenario.to_dict(), region.to_dict(), gains.to_dict(), [float(s) for s in sigmas],
                       FIXED_POINT_ROUNDS, _INFLATE, list(FIXED_POINT_RESTARTS)], sort_keys=True, default=str)


def solve_dynamic(scenario: Scenario, region: Region, gains: GainBounds,
                  sigmas: tuple[float, ...]) -> DynamicSolution:
    """The checked fixed point E_a -> (ω̄, tube, backup) -> jumps -> E (module doc); memoised on its inputs.

    Each round designs the backup for E_a (``fits``) and evaluates the loop bound for it; the rounds stop when
    E < E_a, when the loop bound fails or after :data:`FIXED_POINT_ROUNDS`, and the E_a returned is always the
    one ω̄, the tube and the backup were derived with (``loop_consistent`` compares E with it).

    Parameters
    ----------
    scenario : Scenario
        A scenario on the dynamic plant.
    region, gains : Region, GainBounds
        As :func:`verify.certificate.certify.certify` computes them.
    sigmas : tuple of float
        σ values to try (1/s); the dynamic plant requires 0.
    """
    key = _solved_key(scenario, region, gains, sigmas)
    if key not in _SOLVED:
        if len(_SOLVED) >= _SOLVED_KEEP:
            _SOLVED.pop(next(iter(_SOLVED)))
        _SOLVED[key] = _solve_dynamic(scenario, region, gains, sigmas)
    return _SOLVED[key]


def _closed(solution: DynamicSolution) -> bool:
    """The fixed point closed: every plant condition holds (``loop_consistent`` among them) and the backup is
    certified."""
    return solution.backup.certified and all(c.ok is True for c in solution.conditions)


def _solve_dynamic(scenario: Scenario, region: Region, gains: GainBounds,
                   sigmas: tuple[float, ...]) -> DynamicSolution:
    """:func:`solve_dynamic` without the memo: from :data:`_INFLATE`, then, when that start did not close, each of
    :data:`FIXED_POINT_RESTARTS` until one closes."""
    plans = plans_only_bound(scenario)
    first = _solve_from(scenario, region, gains, sigmas, plans, _INFLATE)
    if _closed(first) or _first_assumption(plans) is None:  # no round was run: another start changes nothing
        return first
    for start in FIXED_POINT_RESTARTS:
        again = _solve_from(scenario, region, gains, sigmas, plans, start)
        if _closed(again):
            return again
    return first


def _solve_from(scenario: Scenario, region: Region, gains: GainBounds, sigmas: tuple[float, ...],
                first: LoopBound, start: float) -> DynamicSolution:
    """The fixed point started at E_a = ``start`` × the plans-only bound ``first`` (and E_v likewise)."""
    assumed = _first_assumption(first, start)
    sway = _first_sway(scenario, first, start)
    if assumed is None:  # the plans' jumps alone already break the loop: report with a finite stand-in
        v_max = tuple(float(x) for x in scenario.limits.vector)
        assumed = tuple(e if math.isfinite(e) else x for e, x in zip(first.error, v_max))
        sway = None if sway is None else (sway if math.isfinite(sway) else v_max[0])
        dist, designs, best, safe, backup = _tiers_at(scenario, region, gains, sigmas, assumed, sway, first)
        return DynamicSolution(loop=first, assumed=assumed, dist=dist, designs=designs, best=best, safe=safe,
                               backup=backup, assumed_sway=sway,
                               conditions=_plant_conditions(scenario, first, assumed, best.sigma, sway))
    fixed = _LoopInputs.of(scenario)
    for rounds in range(1, FIXED_POINT_ROUNDS + 1):
        dist, designs, best, safe, backup = _tiers_at(scenario, region, gains, sigmas, assumed, sway, first)
        loop = fixed.loop(backup.law, backup.safe_set, dist, assumed)
        if not loop.certified or _loop_ratio(loop, assumed, sway) < 1.0 or rounds == FIXED_POINT_ROUNDS:
            break  # the last round keeps its E_a: raising it now would compare E with a bound ω̄ never used
        assumed = tuple(max(a, _STEP * e) for a, e in zip(assumed, loop.error))
        sway = None if sway is None else max(sway, _STEP * loop.sway)
    return DynamicSolution(loop=loop, assumed=assumed, dist=dist, designs=designs, best=best, safe=safe,
                           backup=backup, assumed_sway=sway,
                           conditions=_plant_conditions(scenario, loop, assumed, best.sigma, sway))
