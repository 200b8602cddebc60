"""What a certificate promises, measured on a run (``simulate`` and ``reproduce`` report it; exit 4 if broken).

Each :class:`Promise` compares an observed figure with the certificate's bound:

* ``tube`` — max over the run of max_j |e_j - ê_j| / tube_j (the certificate's own box norm;
  the nominal is logged at its left limit at each sample, so every period is covered) <= 1;
* ``region`` — e in R at every tick (e_d, e_z, e_o bounds and the heading hemisphere);
* ``epsilon`` — min e_d >= ε;
* ``inputs`` — v in V and never clipped (V̄ = V - κ̄ makes saturation impossible); with a minimum surge
  (``limits.u_min``) V's lower corner too: the applied surge never below u_min;
* ``clearance`` — min vehicle-ball clearance to every obstacle at the ticks, minus the distance the
  vehicle can move in half a tick, >= 0 (so it holds between ticks too); ``workspace`` likewise;
* ``sway`` — max |v_s| applied <= γ̄ (on the dynamic plant: max |v_b| of the hull, γ̄ its ISS bound);
* ``velocity_loop`` (dynamic plant with a certified loop bound) — max |u_b - u|, |w_b - w|, |r_b - r|
  at the ticks within the certificate's derived bound ``tightening.velocity_loop`` (observed = the
  largest ratio, <= 1);
* the premises, what the certificate assumes and the run can break without breaking a promise:

  - ``disturbance``: on the kinematic plant ω = current + the sway model, both assumed, so
    ‖ω_xy‖ <= ω̄_xy and |ω_z| <= ω̄_z; on the dynamic plant ω = current + hull sway + loop error, of
    which only the water current is assumed (γ̄ and E are derived: promises ``sway`` and
    ``velocity_loop``), so ‖δ_xy‖ <= max(a_x, a_y) + ‖c_xy‖ and |δ_z| <= a_z + |c_z|
    (:func:`current_bound` of the certified design's current). Either over every evaluation the
    plant's integrator made (between ticks included) and at the logged ticks;
  - ``recursive_feasibility``: a plan accepted at t = 0, and the replayed candidate never older than
    N - 1 periods. With the tracking theorem (``Tightening.plan_always_available``, the candidate on) it is
    no premise: ``plan_available`` (tracking tier) promises a plan accepted at every period (no replay,
    recovery plan or backup), and a lapse is a broken promise (exit 4);
  - ``plant_in_box`` (dynamic plant only; absent on the kinematic plant, which has no coefficients):
    every coefficient of the vehicle as simulated (``scenario.plant.truth_params``) lies in the
    coefficient box the certificate covers (the vehicle of the tightening's design; the run's own
    vehicle for a tightening without one); it names the first coefficient outside.

Tiers (:data:`TIER_OF`). The *safe* promises (``clearance``, ``workspace``, ``inputs``, ``sway``,
``velocity_loop``) hold for all time with only the ``disturbance`` premise when the tightening has a
backup (without one, they also need ``recursive_feasibility``, the old theorem). The *tracking*
promises (``tube``, ``region``, ``epsilon``) are measured only while a plan is followed (not while the
backup law runs, column ``backup_active``) and depend on both premises. On the dynamic plant (a log
with the hull's ``body``) both tiers also depend on ``plant_in_box`` (:func:`premises_of`). Each
:class:`Promise` carries
its ``tier``, ``depends_on`` and whether the certificate ``given`` its tier (``tightening.tiers``;
None: every tier of a certified tightening). :func:`broken_promises` names the promises a run broke:
only those of a given tier whose premises held; a premise failure is never a broken promise, and a
breach of a bound the certificate derived (γ̄, E on the dynamic plant) is a broken promise, never a
failed premise. An uncertified run reports the same figures and claims nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Protocol, Sequence

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.errors import heading_cosine
from tubekit.plant.kinematic import Plant
from tubekit.scenario import HEMISPHERE_SIGN, Scenario
from tubekit.tiers import Tiers
from tubekit.tightening import Tightening

__all__ = ["Promise", "check_promises", "RunLog", "PREMISES", "TIER_OF", "premises_of", "tier_outcomes",
           "broken_promises", "current_bound", "proves_plans"]

#: Promises that are premises of the theorem: a run breaking one claims nothing of the tiers resting on it
#: (``plant_in_box`` is measured on the dynamic plant only).
PREMISES: tuple[str, ...] = ("disturbance", "recursive_feasibility", "plant_in_box")

#: The tier of every promise ("premise" for the premises).
TIER_OF: dict[str, str] = {"clearance": "safe", "workspace": "safe", "inputs": "safe", "sway": "safe",
                           "velocity_loop": "safe", "tube": "tracking", "region": "tracking",
                           "epsilon": "tracking", "plan_available": "tracking", "disturbance": "premise",
                           "recursive_feasibility": "premise",
                           "plant_in_box": "premise"}


class RunLog(Protocol):
    """What the promises and the run's metrics read of a run (``tubekit.loop.result.SimulationResult`` has it all)."""

    scenario: Scenario
    tube: bool
    tightening: Tightening
    t: np.ndarray
    states: np.ndarray
    desired: np.ndarray
    inputs: np.ndarray
    omega: np.ndarray
    saturated: np.ndarray
    backup_active: np.ndarray
    recovery: np.ndarray
    omega_peak: tuple[float, float] | None
    replaced: np.ndarray
    rejected: np.ndarray
    plan_age: np.ndarray
    omega_overridden: bool
    body: np.ndarray | None
    current: np.ndarray | None
    current_peak: tuple[float, float] | None
    sway_command: np.ndarray

    @property
    def errors(self) -> np.ndarray: ...

    @property
    def rho(self) -> np.ndarray: ...

    @property
    def velocity_error(self) -> np.ndarray | None: ...

    @property
    def facts(self) -> dict: ...

    def columns(self) -> dict[str, np.ndarray]: ...


@dataclass(frozen=True)
class Promise:
    """One promise: ``observed`` vs ``bound`` (``ok`` when observed is on the right side)."""

    name: str
    observed: float
    bound: float
    ok: bool
    detail: str
    tier: str = "safe"
    depends_on: tuple[str, ...] = ()
    given: bool = True

    def to_dict(self) -> dict:
        """JSON-ready copy (non-finite numbers as None)."""
        def num(x: float) -> float | None:
            return float(x) if math.isfinite(float(x)) else None
        return {"name": self.name, "observed": num(self.observed), "bound": num(self.bound), "ok": self.ok,
                "detail": self.detail, "tier": self.tier, "depends_on": list(self.depends_on),
                "given": self.given}


def _at_most(name: str, observed: float, bound: float, detail: str) -> Promise:
    return Promise(name, float(observed), float(bound), bool(observed <= bound), detail)


def _at_least(name: str, observed: float, bound: float, detail: str) -> Promise:
    return Promise(name, float(observed), float(bound), bool(observed >= bound), detail)


def _following(run: RunLog) -> np.ndarray:
    """Boolean mask of the ticks at which a tracking plan is followed (neither the backup law nor a recovery plan)."""
    mask = np.ones(len(run.t), dtype=bool)
    for name in ("backup_active", "recovery"):
        flags = getattr(run, name, None)
        if flags is not None and len(flags) == len(run.t):
            mask &= ~np.asarray(flags, dtype=bool)
    return mask


def _tube(run: RunLog) -> Promise:
    tube = np.asarray(run.tightening.tube, dtype=float)
    rho = np.abs(run.rho)[_following(run)]
    ratio = np.max(rho / np.where(tube > 0, tube, np.inf), axis=1) if np.all(tube > 0) else np.full(len(rho), np.inf)
    worst = float(np.nanmax(ratio)) if len(ratio) else 0.0
    return _at_most("tube", worst, 1.0, f"max_j |e_j - e_hat_j| / tube_j, tube = {np.round(tube, 6).tolist()}")


def _region(run: RunLog) -> list[Promise]:
    reg = run.tightening.region
    eps, ed_max, ez_max, eo_max = reg.epsilon, reg.e_d_max, reg.e_z_max, reg.e_o_max
    on = _following(run)
    e = run.errors[on]
    if not len(e):
        return [Promise("region", math.nan, 0.0, True, "no tick follows a plan (the backup law ran throughout)"),
                Promise("epsilon", math.nan, eps, True, "no tick follows a plan (the backup law ran throughout)")]
    slack = np.min(np.column_stack([e[:, 0] - eps, ed_max - e[:, 0], ez_max - np.abs(e[:, 1]),
                                    eo_max - np.abs(e[:, 2])]))
    cos_rel = heading_cosine(run.states[on], run.desired[on])
    sign = HEMISPHERE_SIGN.get(run.scenario.region.heading, 0)
    hem = float(np.min(sign * cos_rel)) if sign else 1.0
    return [_at_least("region", float(min(slack, hem if hem <= 0 else slack)), 0.0,
                      "smallest slack of e in R (e_d, |e_z|, |e_o| bounds, heading hemisphere) "
                      "while a plan is followed"),
            _at_least("epsilon", float(np.min(e[:, 0])), eps, "min e_d (m) >= epsilon while a plan is followed")]


def _inputs(run: RunLog) -> Promise:
    """v in V at every tick and never clipped: observed max |v_i| / V_i, and with a minimum surge u_min (where the
    applied surge fell below it) 1 + (u_min − u) / u_max, so observed <= 1 exactly when v is in V."""
    applied = run.inputs[:-1]
    limits = run.scenario.limits
    lim = limits.vector
    over = float(np.max(np.abs(applied) / lim)) if len(applied) else 0.0
    sat = int(np.sum(run.saturated))
    detail = f"max |v_i| / V_i; clipped ticks = {sat} (the certificate promises none)"
    if limits.u_min is not None:
        surge = applied[:, 0]
        low = float(np.min(surge)) if len(surge) else math.inf
        if low < limits.u_min:
            over = max(over, 1.0 + (limits.u_min - low) / limits.u_max)
        detail = (f"max |v_i| / V_i, or 1 + (u_min - u) / u_max below the surge floor u_min = {limits.u_min:g} m/s "
                  f"(min applied surge {low:.6g} m/s); clipped ticks = {sat} (the certificate promises none)")
    return Promise("inputs", over, 1.0, bool(over <= 1.0 + 1e-12 and sat == 0), detail)


def _geometry(run: RunLog) -> list[Promise]:
    sc = run.scenario
    pos = run.states[:, :3]
    dist = run.tightening.disturbance
    speed = float(np.hypot(sc.limits.u_max, sc.limits.w_max) + np.hypot(dist.omega_xy, dist.omega_z))
    half_tick = 0.5 * (run.t[1] - run.t[0]) if len(run.t) > 1 else 0.0
    pad = speed * half_tick
    clear = min((float(np.min(np.linalg.norm(pos - np.asarray(o.center), axis=1))) - o.radius - sc.vehicle_radius
                 for o in sc.obstacles), default=math.inf)
    out = [_at_least("clearance", clear - pad, 0.0, f"min clearance at the ticks minus {pad:.3g} m "
                                                     "(half a tick at the largest speed)")]
    if sc.workspace is not None:
        lo, hi = (np.asarray(b) for b in sc.workspace)
        inside = float(np.min(np.minimum(pos - lo, hi - pos))) - sc.vehicle_radius - pad
        out.append(_at_least("workspace", inside, 0.0, "vehicle ball inside the workspace box"))
    return out


#: Tolerance of the disturbance and sway comparisons (m/s): rounding of the logged figures.
_TOL = 1e-12


def _peaks(ticks: np.ndarray, stages: tuple[float, float] | None) -> tuple[float, float]:
    """Largest ‖x_xy‖ and |x_z| (m/s) of a series (n, 3) at the ticks (NaN rows skipped) and, when
    given, of the plant's peaks over every integrator stage (between ticks too)."""
    peak_xy = float(np.nanmax(np.hypot(ticks[:, 0], ticks[:, 1]), initial=0.0))
    peak_z = float(np.nanmax(np.abs(ticks[:, 2]), initial=0.0))
    if stages is not None:
        peak_xy, peak_z = max(peak_xy, float(stages[0])), max(peak_z, float(stages[1]))
    return peak_xy, peak_z


def _sway(run: RunLog) -> Promise:
    """The sway the plant applied against γ̄: the hull's |v_b − v_c| (dynamic plant; v_c the sway command, 0 but
    under a backup law with lateral thrust) or the sway model's |v_s|."""
    gamma = run.tightening.disturbance.sway
    if run.body is not None:
        vb = np.abs(run.body[:, 1] - np.asarray(run.sway_command, dtype=float)[:len(run.body)])
        bound = ("the sway loop's error bound: lateral thrust regulates the sway to its command"
                 if run.scenario.plant.params.lateral else "ISS bound of the hull's free sway")
        return _at_most("sway", float(np.nanmax(vb)) if len(vb) else 0.0, gamma + _TOL,
                        f"max |v_b - v_c| of the 4-DOF hull (m/s) vs gamma_bar ({bound})")
    if run.omega_overridden:
        return Promise("sway", math.nan, gamma, True, "not applicable: the disturbance is overridden, "
                                                      "so the sway cannot be separated from it")
    plant = Plant.of(run.scenario)
    sway = [abs(plant.sway_velocity(float(t), x, v)) for t, x, v in zip(run.t[:-1], run.states[:-1], run.inputs[:-1])]
    return _at_most("sway", max(sway, default=0.0), gamma + _TOL, "max |v_s| applied (m/s) vs gamma_bar")


def current_bound(scenario: Scenario) -> tuple[float, float]:
    """The bound on the water current δ a certificate assumes (m/s): ‖δ_xy‖ <= max(a_x, a_y) + ‖c_xy‖ and
    |δ_z| <= a_z + |c_z| for ``scenario.disturbance`` (amplitude a, constant c), the current's terms of
    ω̄_xy and ω̄_z (``verify.theorem.design.disturbance_bounds``)."""
    a, c = scenario.disturbance.amplitude, scenario.disturbance.constant
    return max(a[0], a[1]) + math.hypot(c[0], c[1]), a[2] + abs(c[2])


def _certified_scenario(run: RunLog) -> Scenario:
    """The scenario the certificate read (its current, its coefficient box): the tightening's design, or the
    run's own scenario for a tightening without one (its design is then the run's)."""
    design = run.tightening.design
    return run.scenario if design is None else design.scenario


def _water_current(run: RunLog) -> np.ndarray:
    """The water current δ (m/s, (K + 1, 3)) of a dynamic-plant run: the logged ``current``, or for a log
    without it (built by hand) ω minus the hull's part: δ_xy = ω_xy − R(ψ)(u_b − u, v_b), δ_z = ω_z − (w_b − w)."""
    if run.current is not None:
        return np.asarray(run.current, dtype=float)
    body, v, psi = run.body, run.inputs, run.states[:, 3]
    du, vb, cp, sp = body[:, 0] - v[:, 0], body[:, 1], np.cos(psi), np.sin(psi)
    return run.omega - np.column_stack([du * cp - vb * sp, du * sp + vb * cp, body[:, 2] - v[:, 1]])


def _disturbance(run: RunLog) -> Promise:
    """The premise on what the certificate assumes of the disturbance (module doc): ω on the kinematic plant,
    the water current alone on the dynamic plant."""
    bound = run.tightening.disturbance
    total_xy, total_z = _peaks(run.omega[:-1], run.omega_peak)
    if run.body is None:
        return _at_most("disturbance", max(total_xy - bound.omega_xy - _TOL, total_z - bound.omega_z - _TOL), 0.0,
                        f"premise: max over the whole run (every integrator stage) of ||omega_xy|| - omega_bar_xy "
                        f"and |omega_z| - omega_bar_z; peaks {total_xy:.4g}, {total_z:.4g} m/s")
    cur_xy, cur_z = _peaks(_water_current(run), run.current_peak)
    bound_xy, bound_z = current_bound(_certified_scenario(run))
    return _at_most("disturbance", max(cur_xy - bound_xy - _TOL, cur_z - bound_z - _TOL), 0.0,
                    f"premise: max over the whole run (every integrator stage) of ||current_xy|| - {bound_xy:.4g} "
                    f"and |current_z| - {bound_z:.4g} (the water current against the bound the certificate assumes); "
                    f"peaks {cur_xy:.4g}, {cur_z:.4g} m/s. Not a premise: the total omega (current + sway + "
                    f"loop error, derived) peaks {total_xy:.4g}, {total_z:.4g} m/s vs omega_bar "
                    f"{bound.omega_xy:.4g}, {bound.omega_z:.4g}")


def _plant_in_box(run: RunLog) -> list[Promise]:
    """Dynamic plant: every coefficient of the vehicle as simulated inside the certified coefficient box."""
    if run.body is None:
        return []
    box = _certified_scenario(run).plant.params
    simulated = run.scenario.plant.truth_params
    outside: list[str] = []
    for name in box.to_dict():
        if name in ("actuation", "loop_feedforward"):  # a choice: the same on both
            if getattr(simulated, name) != getattr(box, name):
                outside.append(f"{name} = {getattr(simulated, name)!r}, certified {getattr(box, name)!r}")
            continue
        (lo, hi), value = box.interval(name), simulated.interval(name)[0]
        if not lo <= value <= hi:
            outside.append(f"{name} = {value:.6g} outside [{lo:.6g}, {hi:.6g}]")
    detail = ("premise (dynamic plant): the vehicle as simulated lies in the certified coefficient box; "
              + (f"{len(outside)} coefficients outside, first {outside[0]}" if outside else "every coefficient inside"))
    return [Promise("plant_in_box", float(len(outside)), 0.0, not outside, detail)]


def _velocity_loop(run: RunLog) -> list[Promise]:
    """The velocity loop's error against the certificate's derived bound (dynamic plant with a loop bound only)."""
    err = run.velocity_error
    loop = getattr(run.tightening, "velocity_loop", None)
    if err is None or loop is None:
        return []
    bound = np.asarray(loop, dtype=float)
    worst = np.nanmax(np.abs(err[:-1]), axis=0) if len(err) > 1 else np.zeros(3)
    ratio = float(np.max(np.where(bound > 0, worst / np.where(bound > 0, bound, 1.0),
                                  np.where(worst > 0, np.inf, 0.0))))
    return [_at_most("velocity_loop", ratio, 1.0,
                     f"max |u_b - u|, |w_b - w|, |r_b - r| = {np.round(worst, 6).tolist()} vs the certificate's "
                     f"derived bound {np.round(bound, 6).tolist()} (observed = largest ratio)")]


def proves_plans(tightening: Tightening, scenario: Scenario) -> bool:
    """True when a plan at every period is a promise of the tracking tier, not a premise: the tightening carries
    the tracking theorem's terminal law (:attr:`Tightening.plan_always_available`) and the loop tries the
    candidate it completes (``controller.candidate``)."""
    return tightening.plan_always_available and bool(scenario.controller.candidate)


def _plans(run: RunLog) -> Promise:
    """``plan_available`` (tracking tier, with the tracking theorem): a plan accepted at every period, never a
    replay, a recovery plan or the backup."""
    age = np.asarray(run.plan_age, dtype=int)
    replays = int(np.sum(age > 0))
    flags = getattr(run, "recovery", None)
    backup_ticks = int(np.sum(np.asarray(run.backup_active, dtype=bool)[:-1]))
    recovery_ticks = int(np.sum(flags[:-1])) if flags is not None else 0
    first_ok = len(age) > 0 and age[0] == 0
    observed = float(replays + (backup_ticks > 0) + (recovery_ticks > 0) + (not first_ok))
    return Promise("plan_available", observed, 0.0, observed == 0.0,
                   f"tracking theorem (terminal law): periods without an accepted plan {replays}; backup ticks "
                   f"{backup_ticks}; recovery ticks {recovery_ticks}; rejected solver plans "
                   f"{int(np.sum(run.rejected))} (each replaced by the candidate); accepted at t = 0: {first_ok}")


def _feasibility(run: RunLog) -> Promise:
    if proves_plans(run.tightening, run.scenario):
        return _plans(run)
    n = run.tightening.horizon_arcs
    age = np.asarray(run.plan_age, dtype=int)
    first_ok = len(age) > 0 and age[0] == 0 and not bool(run.replaced[0])
    oldest = int(age.max()) if len(age) else 0
    flags = getattr(run, "recovery", None)
    recovering = float(np.sum(flags[:-1])) * float(run.t[1] - run.t[0]) if flags is not None and len(run.t) > 1 \
        else 0.0
    return Promise("recursive_feasibility", float(oldest), float(max(n - 1, 0)),
                   bool(first_ok and oldest <= max(n - 1, 0) and recovering == 0.0),
                   f"premise (of tracking; of safety too without a backup): oldest replayed plan (periods); "
                   f"rejected plans = {int(np.sum(run.rejected))}; recovery plans followed {recovering:.4g} s; "
                   f"accepted at t = 0: {first_ok}")


def premises_of(tier: str, tightening: Tightening, *, dynamic: bool = False) -> tuple[str, ...]:
    """The premises a promise of ``tier`` rests on: the safe tier needs only the disturbance bound when
    the tightening has a backup; tracking (and safety without a backup) also needs recursive feasibility.
    On the dynamic plant (``dynamic``) both also rest on ``plant_in_box``: every bound the certificate
    derived from the vehicle (γ̄, E, hence ω̄) holds for the coefficients of its box only."""
    if tier == "premise":
        return ()
    if (tier == "safe" and tightening.backup is not None) or (tier == "tracking" and tightening.plan_always_available):
        base: tuple[str, ...] = ("disturbance",)
    else:
        base = ("disturbance", "recursive_feasibility")
    return (*base, "plant_in_box") if dynamic else base


def broken_promises(promises: Sequence[Promise]) -> tuple[str, ...]:
    """Names of the promises broken: of a given tier, not ok, a figure (NaN: not applicable), every
    premise it depends on held."""
    held = {p.name: p.ok for p in promises if p.tier == "premise"}
    return tuple(p.name for p in promises
                 if p.tier != "premise" and p.given and not p.ok and not math.isnan(p.observed)
                 and all(held.get(name, True) for name in p.depends_on))


def tier_outcomes(promises: Sequence[Promise], tiers: Tiers) -> dict[str, str]:
    """What happened to each tier on the run, next to whether the certificate gives it (issue 31):

    ``"not certified"``; ``"certified, kept"``; ``"certified, BROKEN (<promises>)"`` (a promise of the tier
    broken with its premises held: exit 4); ``"certified, not in force (<premise> failed)"`` (a premise the
    tier rests on failed, so the run claims nothing of it). A certified tier is never reported without one of
    these, so a run in which its promise was not in force is never presented as "certified" alone.
    """
    broken = set(broken_promises(promises))
    failed = {p.name for p in promises if p.tier == "premise" and not p.ok}
    out = {}
    for tier in ("safe", "tracking"):
        mine = [p for p in promises if p.tier == tier]
        if not getattr(tiers, tier):
            out[tier] = "not certified"
            continue
        hit = sorted(p.name for p in mine if p.name in broken)
        lapsed = sorted({name for p in mine for name in p.depends_on if name in failed})
        out[tier] = (f"certified, BROKEN ({', '.join(hit)})" if hit
                     else f"certified, not in force ({', '.join(lapsed)} failed)" if lapsed else "certified, kept")
    return out


def _annotate(promise: Promise, tightening: Tightening, *, dynamic: bool) -> Promise:
    """``promise`` with its tier, the premises it depends on (``dynamic``: a run on the dynamic plant) and
    whether its tier was given."""
    tier = TIER_OF.get(promise.name, "safe")
    return replace(promise, tier=tier, depends_on=premises_of(tier, tightening, dynamic=dynamic),
                   given=getattr(tightening.tiers, tier) if tier != "premise" else True)


def check_promises(run: RunLog, *, uncertified: bool = False) -> list[Promise]:
    """Every promise of the module doc measured on ``run`` (a tube run with a certificate's Tightening).

    Parameters
    ----------
    run : RunLog
        A tube run (``tubekit.simulate(scenario, certificate)``).
    uncertified : bool
        Also measure a run under a best-effort tightening (no certificate): the figures a
        certificate would promise, which promise nothing (a tube-less design measures ``inf``).

    Raises
    ------
    ConfigError
        ``run`` is a run without a certificate: the baseline (no tube, nothing promised), or,
        unless ``uncertified``, a tube run under a tightening no certificate gave.
    """
    if not run.tube:
        raise ConfigError("run", "a tube run with a certificate's Tightening (tubekit.simulate(scenario, "
                          "certificate))", "a run without a certificate (the baseline)",
                          "the baseline is promised nothing")
    if not uncertified and not run.tightening.certified:
        tube = [float(x) for x in np.asarray(run.tightening.tube, dtype=float)]
        raise ConfigError("run.tightening", "a certified tightening (tubekit.simulate(scenario, certificate) with "
                          "certificate.certified)", f"a best-effort tightening, tube = {tube}",
                          "nothing is promised; check_promises(run, uncertified=True) measures the figures anyway")
    raw = [_tube(run), *_region(run), _inputs(run), *_geometry(run), _sway(run), _disturbance(run),
           *_velocity_loop(run), _feasibility(run), *_plant_in_box(run)]
    return [_annotate(p, run.tightening, dynamic=run.body is not None) for p in raw]
