"""The two tiers of promise, the safe-only design at σ = 0 and the backup of a certificate.

* **tracking** (e ∈ R, e_d >= ε, the tube, while a plan is followed): every condition of the
  tracking design (:func:`tracking_design` = :func:`verify.theorem.design.evaluate_design` plus the
  workspace conditions of :mod:`verify.theorem.workspace`) and the backup's conditions;
* **safe** (no collision, inside the workspace, v ∈ V never clipped, for all time; premise: the
  disturbance bound only): the backup's conditions (:func:`backup_of`) and, from the design
  whose margins the loop uses, the conditions in :data:`SAFE_CONDITIONS` (the sway bound, the
  tube, V̄ non-empty, sensing, obstacle separation).

When the tracking design does not certify, :func:`safe_only_design` gives the safe tier its own
design at σ = 0: no ancillary feedback, so v = v̂ ∈ V = V̄ and nothing saturates; under the reset
the heading of the kinematic plant sees no disturbance (|ψ − ψ̂| <= Δr δ, Δr the dynamic plant's
yaw error, 0 on the kinematic one), so the one-period position tube is ‖Δp_xy‖ <= (ω̄_xy + ū Δr δ) δ,
|Δz| <= ω̄_z δ (:func:`position_tube`) and the replay margins follow from
:func:`verify.theorem.sampled.horizon_margins`; its e-columns are reported, never required.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np
from flint import arb

from tubekit.model.backup import BackupLaw, SafeSet
from tubekit.model.no_backup import NO_BACKUP_KIND
from tubekit.scenario import Scenario
from tubekit.tiers import Tiers

from verify.backup import BackupCertificate, Fits, proof_for
from verify.theorem.design import Condition, Design, DisturbanceBounds, arc_rates, choose_design, evaluate_design, \
    input_tightening, state_conditions, sway_condition, tube_problem
from verify.theorem.gains import GainBounds
from verify.kernel.intervals import lower, upper
from verify.kernel.region import Region
from verify.theorem.sampled import HorizonMargins, PeriodTube, _asin_ratio, horizon_margins
from verify.theorem.terminal import proves_feasibility, with_terminal
from verify.theorem.workspace import initial_workspace, target_in_workspace

__all__ = ["SAFE_CONDITIONS", "SAFE_PREFIX", "is_safe_condition", "tracking_design", "position_tube",
           "safe_only_design", "backup_of", "anchor_reach", "solve_tiers", "recertify_backup", "initial_backup",
           "surge_floor_condition", "tier_conditions",
           "tiers_of"]

#: Names (or name prefixes ending in "[") of the tracking design's conditions the safe tier depends on.
SAFE_CONDITIONS = ("sway_bound", "tube", "v_bar[", "sensing", "obstacles[")
#: Prefix of the safe-only design's conditions in a certificate's list.
SAFE_PREFIX = "safe_only."


def is_safe_condition(name: str) -> bool:
    """True when the condition ``name`` of a design is one the safe tier depends on."""
    base = name[len(SAFE_PREFIX):] if name.startswith(SAFE_PREFIX) else name
    return base in SAFE_CONDITIONS or any(base.startswith(p) for p in SAFE_CONDITIONS if p.endswith("["))


def tracking_design(scenario: Scenario, region: Region, gains: GainBounds, sigma: float,
                    dist: DisturbanceBounds) -> Design:
    """:func:`verify.theorem.design.evaluate_design` plus ``initial_workspace`` and ``target_in_workspace``; where
    step 17 proves a plan at every period (:func:`verify.theorem.terminal.proves_feasibility`) without the
    screens of :data:`verify.theorem.design.FEASIBILITY_SCREENS`, which no step of that proof uses."""
    d = evaluate_design(scenario, region, gains, sigma, dist, screens=not proves_feasibility(scenario, region))
    m0 = d.margins.position[0] if d.margins is not None else 0.0
    extra = (initial_workspace(scenario, m0), target_in_workspace(scenario))
    return dataclasses.replace(d, conditions=d.conditions + extra)


def position_tube(p) -> PeriodTube:
    """The one-period tube at σ = 0 (module doc): Cartesian bounds, and ρ from them (ρ_d <= ‖Δp_xy‖,
    ρ_z <= |Δz|, ρ_o <= |Δψ| + asin(‖Δp_xy‖ / ε))."""
    d = arb(p.period)
    psi = arb(p.yaw_rate_error) * d
    pxy = (arb(p.omega_xy) + arb(p.u_max) * psi) * d
    pz = arb(p.omega_z) * d
    theta = _asin_ratio(pxy, arb(p.eps))
    rho_o = psi + theta if theta.is_finite() else arb("inf")
    return PeriodTube(rho=(upper(pxy), upper(pz), upper(rho_o)), theta=upper(theta), p_xy=upper(pxy),
                      p_z=upper(pz), psi=upper(psi), kappa=(0.0, 0.0, 0.0), certified=True, iterations=0,
                      reason="", contraction=0.0)


def _renamed(conds: list[Condition]) -> tuple[Condition, ...]:
    return tuple(dataclasses.replace(c, condition=SAFE_PREFIX + c.condition) for c in conds)


def safe_only_design(scenario: Scenario, region: Region, gains: GainBounds, dist: DisturbanceBounds) -> Design:
    """The safe tier's design at σ = 0 (module doc); its conditions are prefixed :data:`SAFE_PREFIX`."""
    p = tube_problem(scenario, region, gains, 0.0, dist)
    tube = position_tube(p)
    m = horizon_margins(p, tube, scenario.controller.horizon_steps)
    inp, v_bar = input_tightening(p, tube, dist, scenario.limits.u_min)
    states = state_conditions(scenario, region, p, m, v_bar)
    pos = m.position[-1]
    conds = [sway_condition(dist),
             Condition("position_tube", "M_pos,N-1 finite: ||dp_xy|| <= (omega_bar_xy + u_max dr delta) delta, "
                       "|dz| <= omega_bar_z delta per period at sigma = 0", pos, math.inf, math.isfinite(pos),
                       f"p_xy {tube.p_xy:.4g} m, p_z {tube.p_z:.4g} m per period")]
    conds += [c for c in inp if c.condition.startswith("v_bar[")]
    conds += [c for c in states if c.condition == "sensing" or c.condition.startswith("obstacles[")]
    return Design(sigma=0.0, problem=p, tube=tube, margins=m, v_bar=tuple(v_bar), conditions=_renamed(conds),
                  score=-math.inf, rates=arc_rates(p))


def _handover(m: HorizonMargins | None) -> tuple[float, float]:
    """(horizontal, depth) hand-over distance (m): the last arc's position and e_z margins."""
    if m is None or not (math.isfinite(m.position[-1]) and math.isfinite(m.e_z[-1])):
        return (math.inf, math.inf)
    return (m.position[-1], m.e_z[-1])


def initial_backup(scenario: Scenario, law: BackupLaw, safe: SafeSet) -> Condition:
    """``backup_initial``: the backup anchored at the start keeps the vehicle clear and inside the workspace.

    The start is the anchor (d = 0: in S); the cylinder of the safe set inflated by the vehicle ball,
    (R_f, H_f) = (c + r̄, Z + r̄), is clear of every obstacle of the scenario:
    hypot(max(0, ‖o_xy − p0_xy‖ − R_f), max(0, |o_z − z0| − H_f)) − r_o > 0, and inside the workspace.
    """
    p0 = [arb(x) for x in scenario.initial_state[:3]]
    rf, hf = arb(safe.level) + arb(scenario.vehicle_radius), arb(safe.depth) + arb(scenario.vehicle_radius)
    slack = math.inf
    for o in scenario.obstacles:
        h = ((arb(o.center[0]) - p0[0]) ** 2 + (arb(o.center[1]) - p0[1]) ** 2).sqrt() - rf
        v = abs(arb(o.center[2]) - p0[2]) - hf
        h, v = (h if h > 0 else arb(0)), (v if v > 0 else arb(0))
        slack = min(slack, lower((h * h + v * v).sqrt() - arb(o.radius)))
    if scenario.workspace is not None:
        lo, hi = scenario.workspace
        for j, half in ((0, rf), (1, rf), (2, hf)):
            slack = min(slack, lower(p0[j] - half - arb(lo[j])), lower(arb(hi[j]) - p0[j] - half))
    return Condition("backup_initial", "the safe set about the start, inflated by r_bar, clear of every obstacle "
                     "and inside the workspace (smallest clearance > 0)", slack, 0.0, slack > 0.0,
                     "the backup anchored at the start is safe: no plan is needed at t = 0")


def anchor_reach(safe: SafeSet, margin: float) -> float:
    """The largest distance (m) the anchor may be moved from the plan's end: a float <= c − β − M_pos,N−1 (Arb,
    rounded down, less a relative 1e-9), 0 when there is no room (``docs/verify.md`` step 12)."""
    room = lower(arb(safe.level) - arb(safe.shape) - arb(margin))
    return max(0.0, room * (1.0 - 1e-9) - 1e-12)


def _with_reach(bc: BackupCertificate, certify: Callable[[float], BackupCertificate],
                margin: float) -> BackupCertificate:
    """``bc`` proved again with the hand-over at the last arc's margin plus :func:`anchor_reach`, when that
    certifies (a law that blends keeps the whole window for its ramp: reach 0)."""
    if not bc.certified or bc.law.blends:
        return bc
    reach = anchor_reach(bc.safe_set, margin)
    if reach <= 0.0:
        return bc
    moved = certify(reach)
    return dataclasses.replace(moved, anchor_reach=reach) if moved.certified else bc


def _smooth(scenario: Scenario) -> bool:
    """True when the backup is designed smooth (faded, ramped from the last command, continuous yaw): on the
    dynamic plant, whose velocity loop pays for the command's jumps, and under rate-limited plans, whose last row
    the terminal law's completion must stay within J of (a backup without the ramp makes plans end at rest)."""
    return scenario.plant.dynamic or scenario.limits.rate is not None


def backup_of(scenario: Scenario, dist: DisturbanceBounds, margins: HorizonMargins | None,
              fits: Fits | None = None, kind: str | None = None) -> BackupCertificate:
    """The backup law of ``kind`` designed by its proof (:meth:`verify.backup.BackupProof.design`, found by
    :func:`verify.backup.proof_for`) for ``scenario`` (ω̄ of ``dist``, V, tick 1/f, hand-over from ``margins``;
    ``fits``: the dynamic plant's gentle design), with ``backup_initial`` appended to its conditions. Where the
    safe set leaves room beyond the hand-over margin, the law is proved again for an anchor that the loop may move
    up to :func:`anchor_reach` from the plan's end (``BackupCertificate.anchor_reach``). ``kind`` None: the
    scenario's ``controller.backup``."""
    proof = proof_for(scenario.controller.backup if kind is None else kind)
    limits = tuple(float(x) for x in scenario.limits.vector)
    tick = 1.0 / float(scenario.controller.ancillary_rate_hz)
    hand = _handover(margins)
    bc = proof.design(omega_xy=dist.omega_xy, omega_z=dist.omega_z, limits=limits, tick=tick,
                      handover=hand if math.isfinite(hand[0]) else (0.0, 0.0),
                      yaw_rate_error=dist.yaw_rate_error, smooth=_smooth(scenario), fits=fits,
                      surge_floor=scenario.limits.u_min)
    if not math.isfinite(hand[0]):
        bc = proof.certify(bc.law, bc.safe_set, omega_xy=dist.omega_xy, omega_z=dist.omega_z, limits=limits,
                           tick=tick, handover=(np.finfo(float).max, np.finfo(float).max),
                           yaw_rate_error=dist.yaw_rate_error)
    else:
        law, safe = bc.law, bc.safe_set
        bc = _with_reach(bc, lambda reach: proof.certify(
            law, safe, omega_xy=dist.omega_xy, omega_z=dist.omega_z, limits=limits, tick=tick,
            handover=(hand[0] + reach, hand[1]), yaw_rate_error=dist.yaw_rate_error), hand[0])
    return _with_initial(scenario, bc)


def solve_tiers(scenario: Scenario, region: Region, gains: GainBounds, sigmas: tuple[float, ...],
                dist: DisturbanceBounds, fits: Fits | None = None, tracking_dist: DisturbanceBounds | None = None,
                ) -> tuple[tuple[Design, ...], Design, Design | None, BackupCertificate]:
    """(designs, best, safe, backup) at ``dist``: the tracking design per σ (1/s) of ``sigmas``, the chosen one
    (:func:`verify.theorem.design.choose_design`; when it certifies, with the terminal ingredients of
    :func:`verify.theorem.terminal.with_terminal` proved against the backup designed for its margins), the
    safe-only design when it does not certify, and the backup (:func:`backup_of` at ``dist``, ``fits`` passed on).
    ``tracking_dist``: the bound the tracking designs are derived at instead of ``dist`` (on the dynamic plant the
    plans-only loop bound's, :func:`verify.vehicle.compose.tracking_disturbance`: under the tracking tier the
    loop never leaves the plans, ``docs/verify.md`` step 17d)."""
    at = dist if tracking_dist is None else tracking_dist
    designs = tuple(tracking_design(scenario, region, gains, s, at) for s in sigmas)
    best = choose_design(list(designs))
    if best.certified:
        ranked = sorted((d for d in designs if d.certified), key=lambda d: (d.score, d.sigma), reverse=True)
        completed = {}
        for d in ranked:  # the first certified σ, by choose_design's order, whose terminal ingredients hold
            backup = backup_of(scenario, dist, d.margins, fits)
            completed[id(d)] = with_terminal(scenario, d, region, backup.safe_set if backup.certified else None,
                                             rests=backup.certified and not backup.law.blends)
            if completed[id(d)].certified:
                best = completed[id(d)]
                break
        else:
            best = completed[id(best)]
        designs = tuple(completed.get(id(d), d) for d in designs)
        if best.certified:
            return designs, best, None, backup
    safe = safe_only_design(scenario, region, gains, dist)
    return designs, best, safe, backup_of(scenario, dist, safe.margins, fits)


def recertify_backup(scenario: Scenario, law: BackupLaw, safe: SafeSet, dist: DisturbanceBounds,
                     margins: HorizonMargins | None, anchor_reach: float = 0.0) -> BackupCertificate:
    """A stored law and safe set proved again by the law's proof (:meth:`verify.backup.BackupProof.certify`,
    :func:`verify.backup.proof_for`) with the derived bounds and margins, the hand-over moved out by the stored
    ``anchor_reach`` (m), ``backup_initial`` appended."""
    hand = _handover(margins)
    big = np.finfo(float).max
    hand = (hand[0] + anchor_reach, hand[1]) if math.isfinite(hand[0]) else (big, big)
    bc = proof_for(law).certify(law, safe, omega_xy=dist.omega_xy, omega_z=dist.omega_z,
                                limits=tuple(float(x) for x in scenario.limits.vector),
                                tick=1.0 / float(scenario.controller.ancillary_rate_hz),
                                handover=hand, yaw_rate_error=dist.yaw_rate_error)
    return _with_initial(scenario, dataclasses.replace(bc, anchor_reach=anchor_reach) if anchor_reach else bc)


def surge_floor_condition(scenario: Scenario, law: BackupLaw) -> Condition:
    """``backup_min_surge``: with a minimum surge (``limits.u_min``) the backup never commands less,
    law.min_surge >= u_min (station keeping, which stops and backs up, fails it; the loiter keeps u_l)."""
    floor = float(scenario.limits.u_min)
    return Condition("backup_min_surge", "the backup law's smallest surge >= limits.u_min (a vehicle that must "
                     "keep moving needs a backup that never stops)", float(law.min_surge), floor,
                     bool(law.min_surge >= floor), f"{law.kind}: smallest surge {law.min_surge:g} m/s" +
                     ("; controller.backup = \"loiter\" keeps its surge" if law.min_surge < 0 else ""))


def _with_initial(scenario: Scenario, bc: BackupCertificate) -> BackupCertificate:
    """``bc`` with ``backup_initial`` (and ``backup_min_surge`` under a minimum surge) appended; without a backup
    law (``"none"``) nothing: the start is the tracking theorem's ``initial_terminal``."""
    if bc.law.kind == NO_BACKUP_KIND:
        return bc
    extra = (initial_backup(scenario, bc.law, bc.safe_set),)
    if scenario.limits.u_min is not None:
        extra += (surge_floor_condition(scenario, bc.law),)
    return dataclasses.replace(bc, conditions=bc.conditions + extra)


def tier_conditions(design: Design, safe_design: Design | None, backup: BackupCertificate | None,
                    plant: tuple[Condition, ...] = ()) -> dict[str, tuple[Condition, ...]]:
    """The conditions each tier depends on (module doc); ``safe_design`` replaces the tracking design's
    safe conditions when given; without a backup law (``"none"``, step 13g) the safe tier depends on every tracking
    condition. A missing backup leaves both tiers uncertified (an empty backup part is
    represented by a failed ``backup`` condition). ``plant``: the dynamic plant's conditions
    (:func:`verify.vehicle.compose.solve_dynamic`), which both tiers depend on (ω̄ holds only with the loop's bound)."""
    bk = backup.conditions if backup is not None else (
        Condition("backup", "a certified backup law", None, None, False, "no backup"),)
    if backup is not None and backup.law.kind == NO_BACKUP_KIND:  # step 13g: safety is tracking's corollary
        return {"safe": tuple(design.conditions) + tuple(bk) + tuple(plant),
                "tracking": tuple(design.conditions) + tuple(bk) + tuple(plant)}
    safe_src = safe_design.conditions if safe_design is not None else tuple(
        c for c in design.conditions if is_safe_condition(c.condition))
    return {"safe": tuple(safe_src) + tuple(bk) + tuple(plant),
            "tracking": tuple(design.conditions) + tuple(bk) + tuple(plant)}


def tiers_of(design: Design, safe_design: Design | None, backup: BackupCertificate | None,
             plant: tuple[Condition, ...] = ()) -> Tiers:
    """The tiers given: a tier is certified when every condition it depends on holds."""
    held = {k: all(c.ok is True for c in v) for k, v in tier_conditions(design, safe_design, backup, plant).items()}
    return Tiers(safe=held["safe"], tracking=held["tracking"] and held["safe"])
