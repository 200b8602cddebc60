"""What a certificate promises, measured on a run (``simulate`` and ``reproduce`` report it; exit 4 if broken).

Each :class:`Promise` compares an observed figure with the certificate's bound:

* ``tube`` — max over the run of max_j |e_j - ê_j| / tube_j (the certificate's own box norm;
  the nominal is logged at its left limit at each sample, so every period is covered) <= 1;
* ``region`` — e in R at every tick (e_d, e_z, e_o bounds and the heading hemisphere);
* ``epsilon`` — min e_d >= ε;
* ``inputs`` — v in V and never clipped (V̄ = V - κ̄ makes saturation impossible);
* ``clearance`` — min vehicle-ball clearance to every obstacle at the ticks, minus the distance the
  vehicle can move in half a tick, >= 0 (so it holds between ticks too); ``workspace`` likewise;
* ``sway`` — max |v_s| applied <= γ̄ (on the dynamic plant: max |v_b| of the hull, γ̄ its ISS bound);
* ``velocity_loop`` (dynamic plant only) — the assumption of ``docs/plant.md``: max |u_b - u|,
  |w_b - w|, |r_b - r| within ``scenario.plant.tracking_bound`` (observed = the largest ratio, <= 1);
* the premises: ``disturbance`` (‖ω_xy‖ <= ω̄_xy, |ω_z| <= ω̄_z) and ``recursive_feasibility``
  (a plan accepted at t = 0, and the replayed candidate never older than N - 1 periods).

A run of a *certified* scenario that breaks any of them is a broken promise; an uncertified run
reports the same figures and claims nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.errors import heading_cosine
from tubekit.plant.kinematic import Plant
from tubekit.scenario import HEMISPHERE_SIGN, Scenario
from tubekit.tightening import Tightening

__all__ = ["Promise", "check_promises", "RunLog", "PREMISES"]

#: Promises that are premises of the theorem: a run breaking one claims nothing.
PREMISES: tuple[str, ...] = ("disturbance", "recursive_feasibility")


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
    replaced: np.ndarray
    rejected: np.ndarray
    plan_age: np.ndarray
    omega_overridden: bool
    body: np.ndarray | None

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

    def to_dict(self) -> dict:
        """JSON-ready copy (non-finite numbers as None)."""
        def num(x: float) -> float | None:
            return float(x) if math.isfinite(float(x)) else None
        return {"name": self.name, "observed": num(self.observed), "bound": num(self.bound), "ok": self.ok,
                "detail": self.detail}


def _at_most(name: str, observed: float, bound: float, detail: str) -> Promise:
    return Promise(name, float(observed), float(bound), bool(observed <= bound), detail)


def _at_least(name: str, observed: float, bound: float, detail: str) -> Promise:
    return Promise(name, float(observed), float(bound), bool(observed >= bound), detail)


def _tube(run: RunLog) -> Promise:
    tube = np.asarray(run.tightening.tube, dtype=float)
    rho = np.abs(run.rho)
    ratio = np.max(rho / np.where(tube > 0, tube, np.inf), axis=1) if np.all(tube > 0) else np.full(len(rho), np.inf)
    worst = float(np.nanmax(ratio)) if len(ratio) else 0.0
    return _at_most("tube", worst, 1.0, f"max_j |e_j - e_hat_j| / tube_j, tube = {np.round(tube, 6).tolist()}")


def _region(run: RunLog) -> list[Promise]:
    reg = run.tightening.region
    eps, ed_max, ez_max, eo_max = reg.epsilon, reg.e_d_max, reg.e_z_max, reg.e_o_max
    e = run.errors
    slack = np.min(np.column_stack([e[:, 0] - eps, ed_max - e[:, 0], ez_max - np.abs(e[:, 1]),
                                    eo_max - np.abs(e[:, 2])]))
    cos_rel = heading_cosine(run.states, run.desired)
    sign = HEMISPHERE_SIGN.get(run.scenario.region.heading, 0)
    hem = float(np.min(sign * cos_rel)) if sign else 1.0
    return [_at_least("region", float(min(slack, hem if hem <= 0 else slack)), 0.0,
                      "smallest slack of e in R (e_d, |e_z|, |e_o| bounds, heading hemisphere)"),
            _at_least("epsilon", float(np.min(e[:, 0])), eps, "min e_d (m) >= epsilon")]


def _inputs(run: RunLog) -> Promise:
    applied = run.inputs[:-1]
    lim = run.scenario.limits.vector
    over = float(np.max(np.abs(applied) / lim)) if len(applied) else 0.0
    sat = int(np.sum(run.saturated))
    return Promise("inputs", over, 1.0, bool(over <= 1.0 + 1e-12 and sat == 0),
                   f"max |v_i| / V_i; clipped ticks = {sat} (the certificate promises none)")


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


def _disturbance(run: RunLog) -> list[Promise]:
    bound = run.tightening.disturbance
    wxy, wz, gamma = bound.omega_xy, bound.omega_z, bound.sway
    om = run.omega[:-1]
    tol = 1e-12
    if run.body is not None:
        vb = np.abs(run.body[:, 1])
        sway_promise = _at_most("sway", float(np.nanmax(vb)) if len(vb) else 0.0, gamma + tol,
                                "max |v_b| of the 4-DOF hull (m/s) vs gamma_bar (ISS bound of the sway dynamics)")
    elif run.omega_overridden:
        sway_promise = Promise("sway", math.nan, gamma, True, "not applicable: the disturbance is overridden, "
                                                              "so the sway cannot be separated from it")
    else:
        plant = Plant.of(run.scenario)
        sway = [abs(plant.sway_velocity(float(t), x, v))
                for t, x, v in zip(run.t[:-1], run.states[:-1], run.inputs[:-1])]
        sway_promise = _at_most("sway", max(sway, default=0.0), gamma + tol, "max |v_s| applied (m/s) vs gamma_bar")
    return [sway_promise,
            _at_most("disturbance", float(max(np.max(np.hypot(om[:, 0], om[:, 1]) - wxy - tol),
                                              np.max(np.abs(om[:, 2]) - wz - tol))), 0.0,
                     "premise: max over the run of ||omega_xy|| - omega_bar_xy and |omega_z| - omega_bar_z")]


def _velocity_loop(run: RunLog) -> list[Promise]:
    """The velocity loop's error against its assumed bound (dynamic plant only)."""
    err = run.velocity_error
    if err is None:
        return []
    bound = np.asarray(run.scenario.plant.tracking_bound, dtype=float)
    worst = np.nanmax(np.abs(err[:-1]), axis=0) if len(err) > 1 else np.zeros(3)
    ratio = float(np.max(np.where(bound > 0, worst / np.where(bound > 0, bound, 1.0),
                                  np.where(worst > 0, np.inf, 0.0))))
    return [_at_most("velocity_loop", ratio, 1.0,
                     f"assumption: max |u_b - u|, |w_b - w|, |r_b - r| = {np.round(worst, 6).tolist()} vs "
                     f"plant.tracking_bound = {bound.tolist()} (observed = largest ratio)")]


def _feasibility(run: RunLog) -> Promise:
    n = run.tightening.horizon_arcs
    age = np.asarray(run.plan_age, dtype=int)
    first_ok = len(age) > 0 and age[0] == 0 and not bool(run.replaced[0])
    oldest = int(age.max()) if len(age) else 0
    return Promise("recursive_feasibility", float(oldest), float(max(n - 1, 0)),
                   bool(first_ok and oldest <= n - 1),
                   f"premise: oldest replayed plan (periods); rejected plans = {int(np.sum(run.rejected))}; "
                   f"accepted at t = 0: {first_ok}")


def check_promises(run: RunLog) -> list[Promise]:
    """Every promise of the module doc measured on ``run`` (a tube run with a certificate's Tightening).

    Raises
    ------
    ConfigError
        ``run`` is a run without a certificate (the baseline: no tube, nothing promised).
    """
    if not run.tube:
        raise ConfigError("run", "a tube run with a certificate's Tightening (tubekit.simulate(scenario, "
                          "certificate))", "a run without a certificate (the baseline)",
                          "the baseline is promised nothing")
    return [_tube(run), *_region(run), _inputs(run), *_geometry(run), *_disturbance(run), *_velocity_loop(run),
            _feasibility(run)]
