"""One design (law, σ) of a scenario checked against the sampled-data theorem: named steps, named conditions.

:func:`evaluate_design` is the pipeline for one σ:

1. :func:`disturbance_bounds` — ω̄_xy, ω̄_z from the current and the sway model over V
   (γ̄ = gain ū r̄ + amplitude: the sway the model produces, no clip); on the dynamic
   plant γ̄ is the hull's ISS sway bound and the velocity loop's error enters ω̄;
2. :func:`verify.theorem.sampled.one_period_tube` — the one-period tube under the reset;
3. :func:`verify.theorem.sampled.horizon_margins` — per-arc margins of the replayed candidate;
4. :func:`input_tightening` — V̄ = V - κ̄ and the necessary feasibility conditions
   (keep-up, yaw budget);
5. :func:`state_conditions` — Ē non-empty on every arc, sensing, obstacle separation,
   the initial state.

Every number is computed in Arb (outward rounding) and stored as a float rounded
in the conservative direction. :func:`verify.certificate.certify.certify` sweeps σ.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from flint import arb

from tubekit.model.errors import error_coordinates, heading_cosine
from tubekit.scenario import Scenario
from tubekit.model.terminal_law import TerminalLaw
from tubekit.model.vehicles import VehicleParams

from verify.theorem.gains import GainBounds
from verify.kernel.intervals import enclose, lower, upper
from verify.kernel.parts import bound, flag, item, number, text
from verify.kernel.region import Region
from verify.theorem.sampled import HorizonMargins, PeriodTube, TubeProblem, horizon_margins, one_period_tube

__all__ = ["Condition", "Design", "DisturbanceBounds", "disturbance_bounds", "hull_sway_bound", "relative_surge_floor",
           "tube_problem", "evaluate_design", "arc_rates", "sway_condition", "input_tightening", "state_conditions",
           "choose_design", "FEASIBILITY_SCREENS"]

#: Conditions that screen a design for recursive feasibility without being a step of any proof: ``yaw_budget``
#: (:func:`input_tightening`) asks the yaw to follow the line of sight at e_d = ε, where no plan need go. Where
#: step 17 proves a plan at every period (:func:`verify.theorem.terminal.proves_feasibility`) the design is
#: evaluated without them (``screens=False``, :func:`verify.theorem.tiers.tracking_design`): the terminal law's own
#: yaw row (``terminal_inputs[r]``, at X_f's distance) is what the proof asks.
FEASIBILITY_SCREENS = ("yaw_budget",)


@dataclass(frozen=True)
class Condition:
    """One checked inequality: ``lhs`` vs ``rhs`` with both numbers; ``ok`` None = not evaluated."""

    condition: str
    inequality: str
    lhs: float | None
    rhs: float | None
    ok: bool | None
    detail: str = ""

    def __post_init__(self) -> None:
        # the JSON keeps finite numbers only: a non-finite side is "no number" here too (exact round trip)
        for k in ("lhs", "rhs"):
            v = getattr(self, k)
            object.__setattr__(self, k, None if v is None or not math.isfinite(float(v)) else float(v))

    def to_dict(self) -> dict:
        """``{condition, inequality, lhs, rhs, ok, detail}`` (non-finite numbers as None)."""
        def num(x: float | None) -> float | None:
            return None if x is None or not math.isfinite(float(x)) else float(x)
        return {"condition": self.condition, "inequality": self.inequality, "lhs": num(self.lhs),
                "rhs": num(self.rhs), "ok": self.ok, "detail": self.detail}

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.conditions[]") -> "Condition":
        """Inverse of :meth:`to_dict`."""
        sides = {k: None if item(d, k, where) is None else number(d, k, where) for k in ("lhs", "rhs")}
        return cls(condition=text(d, "condition", where), inequality=text(d, "inequality", where), **sides,
                   ok=flag(d, "ok", where, allow_none=True), detail=text(d, "detail", where))


@dataclass(frozen=True)
class DisturbanceBounds:
    """Bounds of ω = δ(t) + g(x, v_s) (m/s): horizontal, vertical, and the sway part γ̄."""

    omega_xy: float
    omega_z: float
    gamma: float
    declared_sway: float
    yaw_rate_error: float = 0.0

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return dict(self.__dict__)

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.disturbance") -> "DisturbanceBounds":
        """Inverse of :meth:`to_dict` (``null`` bounds read as +inf)."""
        return cls(omega_xy=bound(d, "omega_xy", where), omega_z=bound(d, "omega_z", where),
                   gamma=bound(d, "gamma", where), declared_sway=bound(d, "declared_sway", where),
                   yaw_rate_error=bound(d, "yaw_rate_error", where))


def hull_sway_bound(params: VehicleParams, u_bar: float, r_bar: float, u_low: float | None = None) -> arb:
    """γ̄ (m/s): ISS bound of the hull's sway for ``u_low`` <= u <= u_bar, |r| <= r_bar (body velocities), v(0) = 0;
    ``u_low`` None: |u| <= u_bar.

    Sway row of M ν̇ + C(ν)ν + D(ν)ν = τ (no sway force) for q = m22 v + m24 r:
    q̇ = (Y_ur_lift − m11) u r + Y_rr r|r| + (Y_v + Y_uv u) v + Y_vv v|v|. With
    F = |Y_ur_lift − m11| ū r̄ + |Y_rr| r̄² and b = −sup(Y_v + Y_uv u) over the surge range (−Y_v − |Y_uv| ū for
    |u| <= ū; under a surge floor u >= u_low > 0 the lift term Y_uv u <= 0 damps: b = −Y_v − Y_uv u_low for a
    point vehicle, ``docs/verify.md`` section 9, step 4), q q̇ < 0 whenever
    |v| > v*, the positive root of |Y_vv| v² + b v − F = 0; |v| >= v* whenever
    |q| >= q* = m22 v* + |m24| r̄. So |q| <= q* (q(0) = m24 r(0)) and
    |v| <= (q* + |m24| r̄) / m22 = v* + 2 |m24| r̄ / m22. Infinite when nothing damps sway.

    Under a surge floor with lift (sup Y_uv < 0) the surge factors out of the two u-terms, whose sum is
    u (|Y_ur_lift − m11| r̄ − |Y_uv| |v|) at worst: for |v| >= v_c = |Y_ur_lift − m11| r̄ / |Y_uv| it is <= 0, so
    largest at u = u_low (root v_low of F = |Y_ur_lift − m11| u_low r̄ + |Y_rr| r̄², b = −Y_v − |Y_uv| u_low), and
    below v_c largest at u = ū (root v_high of F at ū, b = −Y_v − |Y_uv| ū): v* = max(v_low, min(v_c, v_high)),
    never above the root of F at ū over b at u_low. The steady sway of a turn, v ≈ (m11 − Y_ur_lift) r / |Y_uv|,
    does not grow with u (REMUS 100 at 1.0–1.5 m/s: 1.5 times less than F at ū over b at u_low).

    A vehicle with coefficient intervals (``params.interval``) gets the bound for every point
    of its box: v* = 2F / (b + √(b² + 4 a F)) grows with F and falls with a = |Y_vv| and b, so
    it is evaluated at the worst ends (largest F, smallest a and b, each from Arb balls of
    the intervals) and the mass ratio 2|m24| r̄ / m22 over the balls of m, x_g and the added masses.
    """
    def ball(name: str) -> arb:  # the coefficient's interval as a ball (a point: a zero-radius ball)
        return enclose(*params.interval(name))

    m = ball("m")
    m11, m22, m24 = m - ball("X_udot"), m - ball("Y_vdot"), m * ball("x_g") - ball("Y_rdot")
    ub, rb = arb(u_bar), arb(r_bar)
    turn, lift, a = abs(ball("Y_ur_lift") - m11), ball("Y_uv"), arb(lower(abs(ball("Y_vv"))))
    yaw_drag = abs(ball("Y_rr")) * rb * rb

    def root(force: arb, b: arb) -> arb:  # the positive root of a v² + b v = F (+inf when nothing damps)
        force, b = arb(upper(force)), arb(lower(b))
        if a > 0:
            return (-b + (b * b + 4 * a * force).sqrt()) / (2 * a)
        return force / b if b > 0 else arb(math.inf)

    floored = u_low is not None and 0.0 < u_low < u_bar
    if floored and upper(lift) < 0.0:  # the surge factors out of the u-terms (docstring)
        ul = arb(u_low)
        low = root(turn * ul * rb + yaw_drag, -ball("Y_v") - lift * ul)  # |v| >= v_c: the worst surge is u_low
        high = root(turn * ub * rb + yaw_drag, -ball("Y_v") - lift * ub)  # |v| < v_c: the worst surge is ū
        v_c = upper(turn * rb / arb(lower(-lift)))
        v_star = arb(max(upper(low), min(v_c, upper(high))))
    else:
        v_star = root(turn * ub * rb + yaw_drag,
                      -ball("Y_v") - (lift * enclose(u_low, u_bar) if floored else abs(lift) * ub))
    if not v_star.is_finite():
        return arb(math.inf)
    return v_star + 2 * abs(m24) * rb / m22


def relative_surge_floor(u_min: float, surge_error: float | arb) -> float | None:
    """u_min − E_u (m/s), rounded down: the relative surge's floor under a minimum surge command (the loop keeps
    |u_b − u_c| <= E_u); None without one (``u_min`` <= 0). The ``u_low`` of :func:`hull_sway_bound`."""
    return lower(arb(u_min) - arb(surge_error)) if u_min > 0 else None


def disturbance_bounds(scenario: Scenario, loop_error: tuple[float, float, float] | None = None,
                       loop_sway: float | None = None) -> DisturbanceBounds:
    """ω̄_xy = max(a_x, a_y) + ‖c_xy‖ + γ̄, ω̄_z = a_z + |c_z|, γ̄ = gain ū r̄ + amplitude (over V).

    On the dynamic plant (``[plant] kind = "dynamic"``) ω = δ + R(ψ)(u_b − u, v_b) in the
    plane and δ_z + w_b − w in heave, so with the velocity loop's error bound
    ``loop_error`` = (E_u, E_w, E_r) (m/s, m/s, rad/s; derived by :mod:`verify.vehicle.bound`,
    composed by :func:`verify.vehicle.compose.solve_dynamic`): γ̄ = :func:`hull_sway_bound` over
    |u_b| <= ū + E_u, |r_b| <= r̄ + E_r and the vehicle's coefficient box,
    ω̄_xy = max(a_x, a_y) + ‖c_xy‖ + ‖(E_u, γ̄)‖, ω̄_z = a_z + |c_z| + E_w, and the yaw-rate
    error E_r; under a minimum surge γ̄ is taken over u >= u_min − E_u. A vehicle with lateral thrust regulates
    its sway to 0: γ̄ = ``loop_sway``, the sway loop's error bound E_v (m/s, required then). The sway table is
    unused there (declared = γ̄).
    """
    d, lim = scenario.disturbance, scenario.limits
    a, c = d.amplitude, d.constant
    cxy = (arb(c[0]) ** 2 + arb(c[1]) ** 2).sqrt()
    wz = arb(a[2]) + abs(arb(c[2]))
    if scenario.plant.dynamic:
        if loop_error is None:
            raise ValueError("disturbance_bounds on the dynamic plant needs the velocity loop's error bound "
                             "(verify.vehicle.compose.solve_dynamic composes them)")
        du, dw, dr = (arb(x) for x in loop_error)
        if scenario.plant.params.lateral:
            if loop_sway is None:
                raise ValueError("disturbance_bounds: a vehicle with lateral thrust needs the sway loop's error bound "
                                 "(loop_sway, verify.vehicle.compose.solve_dynamic composes it)")
            gamma = arb(loop_sway)
        else:
            gamma = hull_sway_bound(scenario.plant.params, upper(arb(lim.u_max) + du), upper(arb(lim.r_max) + dr),
                                    relative_surge_floor(lim.surge_floor, du))
        wxy = arb(max(a[0], a[1])) + cxy + (du * du + gamma * gamma).sqrt()
        return DisturbanceBounds(omega_xy=upper(wxy), omega_z=upper(wz + dw), gamma=upper(gamma),
                                 declared_sway=upper(gamma), yaw_rate_error=upper(dr))
    gamma = arb(d.sway.gain) * arb(lim.u_max) * arb(lim.r_max) + arb(d.sway.amplitude)
    wxy = arb(max(a[0], a[1])) + cxy + gamma
    return DisturbanceBounds(omega_xy=upper(wxy), omega_z=upper(wz), gamma=upper(gamma),
                             declared_sway=float(d.sway.bound))


def tube_problem(scenario: Scenario, region: Region, gains: GainBounds, sigma: float,
                 dist: DisturbanceBounds) -> TubeProblem:
    """The one-period theorem's inputs for ``scenario`` at gain ``sigma`` (1/s)."""
    ctrl = scenario.controller
    ticks = int(round(ctrl.ancillary_rate_hz * ctrl.dt))
    v = region.v_max
    return TubeProblem(eps=region.e_d[0], e_o_max=max(-region.e_o[0], region.e_o[1]), u_max=v[0], w_max=v[1],
                       r_max=v[2], omega_xy=dist.omega_xy, omega_z=dist.omega_z, pd_xy=region.pd_dot_xy_max,
                       pd_z=region.pd_dot_max[2], sigma=float(sigma), tick=ctrl.dt / ticks, ticks=ticks,
                       yaw_rate_error=dist.yaw_rate_error,
                       k_abs=gains.k_abs, g_lo=gains.g_lo, g_hi=gains.g_hi, g_off=gains.g_off)


def arc_rates(p: TubeProblem) -> tuple[float, float, float, float]:
    """Bounds on |ė_d|, |ė_z|, |ė_o|, ‖ṗ‖ along a nominal arc with v̂ in V (no disturbance)."""
    eps, u, P = arb(p.eps), arb(p.u_max), arb(p.pd_xy)
    return (upper(u + P), upper(arb(p.w_max) + arb(p.pd_z)), upper(arb(p.r_max) + (u + P) / eps),
            upper((u * u + arb(p.w_max) ** 2).sqrt()))


@dataclass(frozen=True)
class Design:
    """One (law, σ) checked: the tube, the margins, V̄, the conditions."""

    sigma: float
    problem: TubeProblem
    tube: PeriodTube
    margins: HorizonMargins | None
    v_bar: tuple[float, float, float] | None
    conditions: tuple[Condition, ...]
    score: float
    rates: tuple[float, float, float, float] = field(default=(0.0, 0.0, 0.0, 0.0))
    terminal: TerminalLaw | None = None

    @property
    def certified(self) -> bool:
        """Every condition holds."""
        return all(c.ok is True for c in self.conditions)

    @property
    def failures(self) -> list[Condition]:
        """The failed conditions."""
        return [c for c in self.conditions if c.ok is False]


def input_tightening(p: TubeProblem, tube: PeriodTube, dist: DisturbanceBounds,
                     u_min: float | None = None, screens: bool = True) -> tuple[list[Condition], list]:
    """V̄ = V - κ̄ (so v̂ + κ never saturates) and the necessary conditions for recursive feasibility, with the
    screens of :data:`FEASIBILITY_SCREENS` when ``screens``.

    With a minimum surge ``u_min`` (m/s; ``limits.u_min``) the nominal surge lies in [u_min + κ̄_u, u_max − κ̄_u],
    so v = v̂ + κ never commands less than u_min: condition ``v_bar[surge_floor]`` (that band non-empty)."""
    conds: list[Condition] = []
    vmax = (p.u_max, p.w_max, p.r_max)
    vb = [arb(vmax[i]) - arb(tube.kappa[i]) for i in range(3)]
    for i, ax in enumerate("uwr"):
        conds.append(Condition(f"v_bar[{ax}]", f"{ax}_max - sup|kappa_{ax}| > 0 (V_bar = V - kappa_bar non-empty)",
                               lower(vb[i]), 0.0, bool(vb[i] > 0), f"sup|kappa_{ax}| <= {tube.kappa[i]:.6g}"))
    if u_min is not None:
        floor = arb(u_min) + arb(tube.kappa[0])
        conds.append(Condition("v_bar[surge_floor]", "u_min + sup|kappa_u| < u_max - sup|kappa_u| (the nominal "
                               "surge band non-empty)", upper(floor), lower(vb[0]), bool(floor < vb[0]),
                               f"u_min = {u_min:g} m/s, sup|kappa_u| <= {tube.kappa[0]:.6g} m/s"))
    need_u = arb(p.pd_xy) + arb(dist.omega_xy)
    need_w = arb(p.pd_z) + arb(dist.omega_z)
    conds.append(Condition("keep_up[u]", "u_bar >= horizontal target speed + omega_bar_xy", lower(vb[0]),
                           upper(need_u), bool(vb[0] >= need_u),
                           "necessary: otherwise target and current outrun the vehicle, e_d leaves R"))
    conds.append(Condition("keep_up[w]", "w_bar >= |zdot_d| + omega_bar_z", lower(vb[1]), upper(need_w),
                           bool(vb[1] >= need_w), "necessary: otherwise e_z leaves R"))
    if not screens:
        return conds, [lower(x) for x in vb]
    need_r = arb(dist.omega_xy) / arb(p.eps)
    conds.append(Condition("yaw_budget", "r_bar >= omega_bar_xy / epsilon (bearing rate the current causes)",
                           lower(vb[2]), upper(need_r), bool(vb[2] >= need_r),
                           "a screen, not a proof step: at e_d = epsilon a cross current turns the line of sight "
                           "at omega_bar_xy / epsilon, faster than the yaw follows; dropped where the terminal "
                           "set proves a plan at every period (docs/verify.md step 17)"))
    return conds, [lower(x) for x in vb]


def sway_condition(dist: DisturbanceBounds) -> Condition:
    # the proof uses the derived gamma_bar; 1e-12 only forgives the binary rounding of e.g. 0.1 * 0.4 * 0.5
    return Condition("sway_bound", "declared sway bound >= gain u_max r_max + amplitude (the model's own sway)",
                     dist.declared_sway, dist.gamma, dist.declared_sway >= dist.gamma * (1 - 1e-12),
                     "gamma_bar is derived from the sway model over V; a smaller declared bound would be a clip, "
                     "not physics")


def state_conditions(scenario: Scenario, region: Region, p: TubeProblem, m: HorizonMargins,
                     v_bar: list[float]) -> list[Condition]:
    """Ē non-empty on the last arc, unknown obstacles out of reach of every arc, separation, e(0)."""
    conds: list[Condition] = []
    last = -1
    ed_lo, ed_hi = arb(region.e_d[0]) + arb(m.e_d[last]), arb(region.e_d[1]) - arb(m.e_d[last])
    conds.append(Condition("e_bar[e_d]", "epsilon + M_d < e_d_max - M_d (last arc)", upper(ed_lo), lower(ed_hi),
                           bool(ed_lo < ed_hi), f"M_d = {m.e_d[last]:.4g} m"))
    for name, half, mg in (("e_z", max(-region.e_z[0], region.e_z[1]), m.e_z[last]),
                           ("e_o", p.e_o_max, m.e_o[last])):
        conds.append(Condition(f"e_bar[{name}]", f"M_{name[-1]} < {name}_max (last arc)", mg, half, mg < half,
                               "Ē = R shrunk by the margin of the last arc"))
    T = arb(scenario.controller.horizon)
    reach = T * (arb(max(v_bar[0], 0.0)) ** 2 + arb(max(v_bar[1], 0.0)) ** 2).sqrt() + arb(m.position[last])
    need = reach + arb(scenario.vehicle_radius)
    conds.append(Condition("sensing", "T ||(u_bar, w_bar)|| + M_pos + r_bar < R_bar (no unseen obstacle reachable)",
                           upper(need), scenario.sensing_range, bool(need < arb(scenario.sensing_range)),
                           "an obstacle is seen when its surface is within R_bar; every arc of a plan stays "
                           "within T ||(u_bar, w_bar)|| + M_pos of where it was planned"))
    rb = arb(scenario.vehicle_radius) + arb(m.position[last])
    for (i, a), (j, b) in itertools.combinations(enumerate(scenario.obstacles), 2):
        dist = sum(((arb(x) - arb(y)) ** 2 for x, y in zip(a.center, b.center)), arb(0)).sqrt()
        gap = 2 * rb + arb(a.radius) + arb(b.radius)
        conds.append(Condition(f"obstacles[{i},{j}]", "||p_i - p_j|| > 2 (r_bar + M_pos) + r_i + r_j",
                               lower(dist), upper(gap), bool(dist > gap), "the tube passes between them"))
    conds.append(_initial_condition(scenario, region, m))
    return conds


def _initial_condition(scenario: Scenario, region: Region, m: HorizonMargins) -> Condition:
    p0 = scenario.trajectory.position(0.0)
    x0 = np.asarray(scenario.initial_state, dtype=float)
    e0 = error_coordinates(x0, p0)
    box = ((region.e_d[0] + m.e_d[0], region.e_d[1] - m.e_d[0]),
           (region.e_z[0] + m.e_z[0], region.e_z[1] - m.e_z[0]),
           (region.e_o[0] + m.e_o[0], region.e_o[1] - m.e_o[0]))
    viol = max(max(lo - e0[k], e0[k] - hi) for k, (lo, hi) in enumerate(box))
    cos_rel = float(heading_cosine(x0, p0))
    hem = any(s * cos_rel > 0 for s in region.hemisphere_signs)
    clear = min((float(np.linalg.norm(x0[:3] - np.asarray(o.center))) - o.radius - scenario.vehicle_radius
                 - m.position[0] for o in scenario.obstacles), default=math.inf)
    return Condition("initial", "e(0) in R shrunk by M_0, same hemisphere, clear of obstacles by M_pos",
                     float(max(viol, -clear)), 0.0, bool(viol <= 0 and hem and clear > 0),
                     f"e(0) = [{e0[0]:.4g}, {e0[1]:.4g}, {e0[2]:.4g}], cos(psi - theta) = {cos_rel:.3g}, "
                     f"clearance margin {clear:.4g} m")


def _score(p: TubeProblem, region: Region, m: HorizonMargins | None, v_bar: list | None) -> float:
    """Smallest normalised slack of V̄ and Ē (the design with the largest one is preferred)."""
    if m is None or v_bar is None:
        return -math.inf
    vmax = (p.u_max, p.w_max, p.r_max)
    widths = (region.e_d[1] - region.e_d[0], region.e_z[1] - region.e_z[0], region.e_o[1] - region.e_o[0])
    used = (2 * m.e_d[-1], 2 * m.e_z[-1], 2 * m.e_o[-1])
    return min(min(v / vm for v, vm in zip(v_bar, vmax)), min(1 - u / w for u, w in zip(used, widths)))


def evaluate_design(scenario: Scenario, region: Region, gains: GainBounds, sigma: float,
                    dist: DisturbanceBounds, screens: bool = True) -> Design:
    """Steps 2-5 of the module doc for one σ (1/s); ``screens``: with :data:`FEASIBILITY_SCREENS`."""
    p = tube_problem(scenario, region, gains, sigma, dist)
    tube = one_period_tube(p)
    conds = [sway_condition(dist),
             Condition("tube", "max_j F_j(x) / x_j < 1: the one-period box x is a strict post-fixed point of the "
                               "sampled-data map (verify.theorem.sampled)", tube.contraction, 1.0, tube.certified,
                       tube.reason or f"verified in Arb after {tube.iterations} fixed-point iterations")]
    if not tube.certified:
        return Design(sigma=sigma, problem=p, tube=tube, margins=None, v_bar=None, conditions=tuple(conds),
                      score=-math.inf)
    m = horizon_margins(p, tube, scenario.controller.horizon_steps)
    inp, v_bar = input_tightening(p, tube, dist, scenario.limits.u_min, screens)
    conds += inp
    conds += state_conditions(scenario, region, p, m, v_bar)
    return Design(sigma=sigma, problem=p, tube=tube, margins=m, v_bar=tuple(v_bar), conditions=tuple(conds),
                  score=_score(p, region, m, v_bar), rates=arc_rates(p))


def choose_design(designs: list[Design]) -> Design:
    """The certified σ with the largest normalised slack of V̄ and Ē (ties: the larger σ); when none certifies,
    the design with a finite tube, the fewest failures and the largest slack (deterministic).

    Slack, not the strongest feedback: under the reset a larger σ shrinks the per-period tube but asks for
    input and turns the heading, which the replayed plan's margins must absorb; the slack is what keeps
    plans acceptable (the recursive-feasibility premise). Measured on 24 sampled campaign runs of
    paper_currents: premises held in 24/24 (largest slack) against 20/24 (largest certified σ).
    """
    certified = [d for d in designs if d.certified]
    if certified:
        return max(certified, key=lambda d: (d.score, d.sigma))
    return min(designs, key=lambda d: (not d.tube.certified, len(d.failures), -d.score, d.sigma))
