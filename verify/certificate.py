"""The certificate: Lemma 1, the tightened sets of Section V, the horizon condition, named failures.

:func:`certify` computes the certified bounds over the region (:mod:`verify.bounds`)
and then, with every arithmetic step in Arb (outward rounding),

1. folds the bearing mismatch into xi-tilde (the nominal is reset to the
   measured state every FHOCP sample, so |theta - theta_hat| <= Delta-theta over
   one period): xi_tilde = xi_bar + zeta_theta * 2 sin(min(Delta-theta, pi) / 2);
2. picks sigma: admissible range (L1 + L2) / J_lower < sigma <= f / sup||J K||
   (eq. sigma; the upper end is the sampled-data limit of the ancillary loop at
   f = ``controller.ancillary_rate_hz``); every tightening decreases in sigma, so
   the upper end is chosen unless ``controller.sigma`` is set;
3. rho_tilde = xi_tilde / (sigma J_lower - L1 - L2) (Lemma 1);
4. V_bar = V minus sigma * sup||row_i K|| * rho_tilde per axis, E_bar = R shrunk by
   rho_tilde, terminal set F, horizon T <= R_bar / (V_bar + xi_tilde), obstacle
   separation (eq. obstacle_dis) also for obstacles inflated by the position margin,
   keep-up of nominal and real vehicle, and e(0) in E_bar.

Every condition is recorded with both sides' numbers; the failed ones become
``failures``. Conditions that need rho_tilde when no admissible sigma exists are
recorded as not evaluated (``ok = None``) and are not counted as failures.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from flint import arb

from tubekit.ancillary import AncillaryLaw, get_law, register_law
from tubekit.derivation import error_coordinates
from tubekit.exceptions import ConfigError, TubekitError
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

from .bounds import Bounds, compute_bounds, polar_model
from .intervals import lower, upper
from .region import Region

__all__ = ["Condition", "Certificate", "NotCertifiedError", "certify", "DEFAULT_TIME_BUDGET_S"]

#: Branch-and-bound budget per bound (s).
DEFAULT_TIME_BUDGET_S = 3.0


class NotCertifiedError(TubekitError):
    """Raised by :meth:`Certificate.tightening` when the design is not certified."""


@dataclass(frozen=True)
class Condition:
    """One checked inequality.

    Attributes
    ----------
    condition : str
        Short name (``"sigma"``, ``"v_bar[u]"``, ``"horizon"``, ...).
    inequality : str
        The inequality, in the paper's symbols.
    lhs, rhs : float or None
        Both sides' numbers (rounded in the conservative direction); None when not evaluable.
    ok : bool or None
        True holds, False fails, None not evaluated (needs rho_tilde, which does not exist).
    detail : str
        Where the numbers come from.
    """

    condition: str
    inequality: str
    lhs: float | None
    rhs: float | None
    ok: bool | None
    detail: str = ""

    def to_dict(self) -> dict:
        """``{condition, inequality, lhs, rhs, ok, detail}`` with non-finite numbers as None."""
        return {"condition": self.condition, "inequality": self.inequality, "lhs": _json_num(self.lhs),
                "rhs": _json_num(self.rhs), "ok": self.ok, "detail": self.detail}


def _json_num(x: Any) -> Any:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _vec(x: Any) -> list | None:
    return None if x is None else [_json_num(v) for v in x]


def _jsonable(x: Any) -> Any:
    """Recursively convert to JSON types; non-finite floats become None."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, np.ndarray)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return _json_num(x)
    return x


@dataclass(frozen=True)
class Certificate:
    """Result of :func:`certify`. ``certified`` is True only if every condition holds.

    Attributes
    ----------
    scenario_name, law : str
        What was certified.
    region : Region
        The set every bound holds over.
    bounds : Bounds
        Certified bounds with their sampled counterparts.
    gap_target : float
        Relative gap the branch-and-bound aimed for.
    sigma : dict
        ``value`` (None if no admissible sigma), ``min`` ((L1+L2)/J_lower, exclusive),
        ``max`` (f / sup||J K||), ``source``.
    rho : dict
        ``rho_tilde``, ``xi_tilde``, ``xi_bar``, ``bearing_fold``, ``delta_theta``.
    kappa_bar : array (3,) or None
        Certified bound on |kappa_i| (m/s, m/s, rad/s).
    v_bar : array (3,) or None
        V_bar = V minus kappa_bar (nominal input limits).
    e_bar : dict or None
        E_bar = R shrunk by rho_tilde: ``e_d``, ``e_z``, ``e_o`` intervals.
    obstacle_margin : float or None
        Bound on ||p - p_hat|| over one FHOCP period (m).
    horizon : dict
        ``T``, ``T_max``, ``ok``, ``V_bar``, ``xi_tilde``, ``R_bar``.
    conditions : list of Condition
        Everything checked.
    assumptions : list of str
        What the certificate relies on but does not check.
    elapsed_s : float
        Wall time of :func:`certify` (s).
    """

    scenario_name: str
    law: str
    region: Region
    bounds: Bounds
    gap_target: float
    sigma: dict
    rho: dict
    kappa_bar: np.ndarray | None
    v_bar: np.ndarray | None
    e_bar: dict | None
    obstacle_margin: float | None
    terminal: dict
    horizon: dict
    conditions: tuple[Condition, ...]
    assumptions: tuple[str, ...]
    elapsed_s: float
    v_max: np.ndarray = field(default_factory=lambda: np.zeros(3))
    dt: float = 0.1
    sigma_fallback: float = 1.0
    vehicle_radius: float = 0.2

    # ------------------------------------------------------------------ status
    @property
    def failures(self) -> list[dict]:
        """One ``{condition, inequality, lhs, rhs, detail}`` per failed condition."""
        return [{k: v for k, v in c.to_dict().items() if k != "ok"} for c in self.conditions if c.ok is False]

    @property
    def not_evaluated(self) -> list[str]:
        """Names of conditions that could not be evaluated."""
        return [c.condition for c in self.conditions if c.ok is None]

    @property
    def certified(self) -> bool:
        """True when every condition holds (none failed, none left unevaluated)."""
        return all(c.ok is True for c in self.conditions)

    @property
    def is_certified(self) -> bool:
        """Alias of :attr:`certified`."""
        return self.certified

    @property
    def rho_tilde(self) -> float | None:
        """Tube radius (error units) or None."""
        return self.rho["rho_tilde"]

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """JSON-ready dict with the keys of issue 3 item 8 plus details."""
        return _jsonable({
            "certified": self.certified,
            "law": self.law,
            "region": self.region.to_dict(),
            "bounds": self.bounds.to_dict(),
            "sigma": self.sigma,
            "rho": self.rho,
            "v_bar": self.v_bar,
            "horizon": self.horizon,
            "failures": self.failures,
            "assumptions": list(self.assumptions),
            "elapsed_s": round(self.elapsed_s, 3),
            "scenario": self.scenario_name,
            "kappa_bar": self.kappa_bar,
            "e_bar": self.e_bar,
            "obstacle_margin": self.obstacle_margin,
            "terminal": self.terminal,
            "conditions": [c.to_dict() for c in self.conditions],
            "not_evaluated": self.not_evaluated,
            "gap_target": self.gap_target,
        })

    def summary(self) -> str:
        """Human-readable certificate."""
        def f(x: Any, d: int = 4) -> str:
            if x is None:
                return "n/a"
            return f"{x:.{d}g}" if math.isfinite(x) else ("inf" if x > 0 else "-inf")

        n_fail = len(self.failures)
        status = "CERTIFIED" if self.certified else f"NOT CERTIFIED ({n_fail} failed condition{'s' * (n_fail != 1)})"
        lines = [f"tubekit certificate: scenario '{self.scenario_name}', law '{self.law}': {status}",
                 "Region R (every bound below holds over it; see 'holds over' in the JSON):",
                 self.region.describe(),
                 f"Certified bounds (sampled | certified bound, relative gap; target {self.gap_target:.0%}):"]
        for name, br in self.bounds.items.items():
            conv = "" if br.converged else "  [gap target not reached in the time budget]"
            lines.append(f"  {name:10s} {f(br.sampled, 6):>10s} | {f(br.bound, 6):>10s}  ({br.gap:.2%}){conv}")
        s = self.sigma
        rng = (f"admissible ({f(s['min'])}, {f(s['max'])}]" if s["min"] is not None and math.isfinite(s["min"])
               else "admissible range empty (J_lower <= 0)")
        lines.append(f"sigma = {f(s['value'])} 1/s ({s['source']}); {rng}")
        r = self.rho
        lines.append(f"xi_tilde = xi_bar {f(r['xi_bar'])} + bearing fold {f(r['bearing_fold'])} "
                     f"(Delta-theta {f(r['delta_theta'])} rad) = {f(r['xi_tilde'])};  rho_tilde = {f(r['rho_tilde'])}")
        if self.v_bar is not None:
            lines.append(f"V_bar = [{', '.join(f(v) for v in self.v_bar)}]  (|kappa| <= "
                         f"[{', '.join(f(v) for v in self.kappa_bar)}])")
        if self.e_bar is not None:
            eb = self.e_bar
            lines.append("E_bar: " + ", ".join(f"{k} in [{f(v[0])}, {f(v[1])}]" for k, v in eb.items())
                         + f";  obstacle margin {f(self.obstacle_margin)} m")
        h = self.horizon
        lines.append(f"Horizon: T = {f(h['T'])} s <= R_bar/(V_bar + xi_tilde) = {f(h['T_max'])} s: "
                     f"{'ok' if h['ok'] else ('FAILS' if h['ok'] is False else 'n/a')}")
        lines.append("Conditions:")
        for c in self.conditions:
            tag = {True: "ok  ", False: "FAIL", None: "n/a "}[c.ok]
            lines.append(f"  [{tag}] {c.condition}: {c.inequality}: {f(c.lhs, 6)} vs {f(c.rhs, 6)}"
                         + (f"  ({c.detail})" if c.detail and c.ok is not True else ""))
        lines.append("Assumptions (relied on, not checked):")
        lines.extend(f"  - {a}" for a in self.assumptions)
        lines.append(f"Elapsed: {self.elapsed_s:.2f} s")
        return "\n".join(lines)

    # ------------------------------------------------------------------ hand-off to the FHOCP
    def tightening(self, allow_uncertified: bool = False, min_input_fraction: float = 0.5) -> Tightening:
        """The FHOCP's tightened constraint data.

        Parameters
        ----------
        allow_uncertified : bool
            If False (default) and the design is not certified, raise
            :class:`NotCertifiedError`. If True, return a *best-effort*,
            non-empty Tightening that carries no guarantee:

            * sigma: the chosen admissible sigma, else ``controller.sigma``, else
              1 1/s (no admissible sigma exists, e.g. the paper's law pointing at the target);
            * state margin rho = min(rho_tilde, epsilon, 0.25 * the narrowest
              region width) (rho_tilde may be infinite);
            * input tightening capped so V_bar_i >= max(min_input_fraction * V_i,
              keep-up speed) (keep-up: horizontal target speed for u, |zdot_d| for w);
            * obstacle margin from the applied input tightening, capped at the vehicle radius.
        min_input_fraction : float
            Lower limit of V_bar_i / V_i in best-effort mode.
        """
        reg = self.region
        e_o_half = min(-reg.e_o[0], reg.e_o[1])
        e_z_half = min(-reg.e_z[0], reg.e_z[1])
        if self.certified:
            rho = float(self.rho["rho_tilde"])
            return Tightening(v_max=np.asarray(self.v_bar, dtype=float).copy(), e_d_min=self.e_bar["e_d"][0],
                              e_o_max=e_o_half - rho, e_z_max=e_z_half - rho, e_d_max=self.e_bar["e_d"][1],
                              obstacle_margin=float(self.obstacle_margin), rho_tilde=rho,
                              sigma=float(self.sigma["value"]))
        if not allow_uncertified:
            names = ", ".join(fl["condition"] for fl in self.failures) or ", ".join(self.not_evaluated)
            raise NotCertifiedError(f"scenario '{self.scenario_name}' with law '{self.law}' is not certified "
                                    f"(failed: {names}); pass allow_uncertified=True for a best-effort tightening")
        if not (0 < min_input_fraction <= 1):
            raise ConfigError("min_input_fraction", "a number in (0, 1]", min_input_fraction)
        sigma = self.sigma["value"] if self.sigma["value"] is not None else self.sigma_fallback
        widths = [reg.e_d[1] - reg.e_d[0], reg.e_z[1] - reg.e_z[0], reg.e_o[1] - reg.e_o[0]]
        rho_t = self.rho["rho_tilde"]
        rho = min(rho_t if rho_t is not None and math.isfinite(rho_t) else math.inf, reg.e_d[0], 0.25 * min(widths))
        v = np.asarray(self.v_max, dtype=float)
        need = np.array([min(reg.pd_dot_xy_max, v[0]), min(reg.pd_dot_max[2], v[1]), 0.0])
        floor = np.maximum(min_input_fraction * v, need)
        kb = self.kappa_bar if self.kappa_bar is not None else np.full(3, np.inf)
        v_bar = np.maximum(v - np.nan_to_num(np.asarray(kb, dtype=float), posinf=np.inf), floor)
        applied = v - v_bar
        dt = self.dt
        margin = dt * (math.hypot(applied[0] + v_bar[0] * applied[2] * dt / 2, applied[1]) + reg.omega_bar)
        margin = min(margin, self.vehicle_radius)
        return Tightening(v_max=v_bar, e_d_min=reg.e_d[0] + rho, e_o_max=e_o_half - rho, e_z_max=e_z_half - rho,
                          e_d_max=reg.e_d[1] - rho, obstacle_margin=float(margin), rho_tilde=float(rho),
                          sigma=float(sigma))


# --------------------------------------------------------------------------- certify
_ASSUMPTIONS = (
    "Dynamics: the error dynamics e_dot = J(e) v + zeta + xi are the sympy derivation from the kinematics "
    "eq. (11) (tubekit.derivation), not the printed eqs. 15-18.",
    "Every bound holds over the region R printed above; the real error e and the nominal e_hat must stay in R. "
    "This follows from e_hat in E_bar = R shrunk by rho_tilde and ||rho|| <= rho_tilde, provided the FHOCP "
    "enforces e_hat in E_bar for all times (implementations enforce it at the discretisation nodes only).",
    "The nominal is reset to the measured state at every FHOCP sample (eq. diff_mpc: e_hat(t_k) = e(t_k)); "
    "so over one period dt the bearings satisfy |theta - theta_hat| <= Delta-theta = dt (|theta_dot| + "
    "|theta_hat_dot|) with |theta_dot| <= (u_max + ||p_d_dot_xy|| + omega_bar) / e_d_min, and "
    "zeta(e_hat, theta) - zeta(e_hat, theta_hat) is folded into xi_tilde as "
    "zeta_theta * 2 sin(min(Delta-theta, pi) / 2) (zeta's bearing dependence is a rotation of p_d_dot_xy).",
    "Real and nominal share the heading hemisphere (sign of cos(psi - theta)): changing it needs |e_o| = 1, "
    "outside R; J(e) depends on e only within a hemisphere, so L1 needs no bearing term.",
    "Lemma 1 is a continuous-time result; the ancillary law runs sampled at controller.ancillary_rate_hz. "
    "sigma <= f / sup||J K|| is a sampled-data design limit, not covered by the proof.",
    "The disturbance satisfies ||omega(t)|| <= omega_bar for all t (current bound + sway bound; the sway "
    "bound of the SwayModel clip stands in for the paper's ISS argument), and p_d_dot(t) stays in P.",
    "The FHOCP is feasible at t = 0 and recursively feasible (premise of the paper's Theorem 1); the terminal "
    "set F is checked non-empty, not invariant.",
    "The horizon condition is the printed eq. (new_obstacles) with V_bar = ||[u_max, w_max, r_max]|| (mixes "
    "m/s and rad/s, as printed) and xi_tilde including the bearing fold.",
    "The obstacle margin bounds ||p - p_hat|| over one FHOCP period: dt (sqrt((kappa_u + u_bar kappa_r dt/2)^2 "
    "+ kappa_w^2) + omega_bar); the workspace boundary is not part of the certificate.",
    "Input saturation is never active: v = v_hat + kappa stays in V because v_hat in V_bar (checked).",
)


def certify(scenario: Scenario, law: str | AncillaryLaw | None = None, *, region: Region | None = None,
            time_budget_s: float = DEFAULT_TIME_BUDGET_S, gap: float = 0.05) -> Certificate:
    """Certify a scenario for an ancillary law.

    Parameters
    ----------
    scenario : Scenario
        Vehicle, limits, disturbance, trajectory, obstacles, sensing range, epsilon, horizon.
    law : str or AncillaryLaw, optional
        A registered law name (``"paper"``, ``"corrected"``, or one added with
        :func:`tubekit.ancillary.register_law`) or an :class:`AncillaryLaw` with a
        ``symbolic_gain`` (registered on the way); default ``scenario.controller.law``.
    region : Region, optional
        The set the bounds hold over; default :meth:`Region.from_scenario`.
    time_budget_s : float
        Branch-and-bound budget per bound (s).
    gap : float
        Target relative gap between sampled and certified bound values.

    Returns
    -------
    Certificate
    """
    t0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.scenario.Scenario", type(scenario).__name__)
    law = scenario.controller.law if law is None else law
    if isinstance(law, AncillaryLaw):
        law = register_law(law).name
    get_law(law)
    if region is None:
        region = Region.from_scenario(scenario)
    elif not isinstance(region, Region):
        raise ConfigError("region", "a verify.Region", type(region).__name__)
    bounds = compute_bounds(region, law, gap=gap, time_budget_s=time_budget_s)
    ctrl = scenario.controller
    conds: list[Condition] = []

    def add(name: str, ineq: str, lhs: float | None, rhs: float | None, ok: bool | None, detail: str = "") -> None:
        conds.append(Condition(name, ineq, lhs, rhs, ok, detail))

    A = arb
    L1, L2 = A(bounds["L1"].bound), A(bounds["L2"].bound)
    Jl = A(bounds["J_lower"].bound)
    xib = A(bounds["xi_bar"].bound)
    Zt = A(bounds["zeta_theta"].bound)
    krow = [A(bounds[f"K_row_{a}"].bound) for a in "uwr"]
    JKn = A(bounds["JK_norm"].bound)
    om, h, pz = A(region.omega_bar), A(region.pd_dot_xy_max), A(region.pd_dot_max[2])
    v = [A(x) for x in region.v_max]
    dt, f_anc = A(ctrl.dt), A(ctrl.ancillary_rate_hz)
    eps = A(region.e_d[0])

    # 1. bearing fold
    dtheta = dt * (2 * v[0] + 2 * h + om) / eps
    if not all(polar_model(s).zeta_rotation_form for s in region.hemisphere_signs):
        fold = Zt * dtheta                      # mean-value bound, always valid
    elif dtheta.upper() >= A.pi():
        fold = 2 * Zt
    else:
        fold = 2 * Zt * (dtheta / 2).sin()      # chord of the rotation (see bounds.PolarModel)
    xi_t = xib + fold
    xi_tilde = upper(xi_t)

    # 2. sigma
    add("J_lower", "lambda_min((J K + (J K)^T)/2) >= J_lower > 0 over R (Remark 1)",
        bounds["J_lower"].bound, 0.0, bool(Jl > 0),
        "certified lower bound of lambda_min of the symmetric part of the law's closed-loop gain J K")
    sig_max = f_anc / JKn
    sigma_max = lower(sig_max)
    sigma_min = upper((L1 + L2) / Jl) if Jl > 0 else math.inf
    sigma_value: float | None = None
    source = ""
    if ctrl.sigma is not None:
        s = A(ctrl.sigma)
        ok1 = bool(Jl > 0 and s * Jl > L1 + L2)
        add("sigma", "sigma > (L1 + L2) / J_lower (eq. sigma)", ctrl.sigma, sigma_min, ok1,
            "controller.sigma is fixed by the scenario" if bool(Jl > 0) else
            "J_lower <= 0: no sigma satisfies eq. sigma")
        ok2 = bool(s <= sig_max)
        add("sigma_sampled", "sigma <= f / sup||J K|| (sampled-data limit of the ancillary loop)", ctrl.sigma,
            sigma_max, ok2, f"f = controller.ancillary_rate_hz = {ctrl.ancillary_rate_hz:g} Hz")
        if ok1:
            sigma_value, source = float(ctrl.sigma), "controller.sigma"
    else:
        ok = bool(Jl > 0 and A(sigma_max) * Jl > L1 + L2)
        if bool(Jl > 0):
            add("sigma", "(L1 + L2) / J_lower < sigma_max = f / sup||J K|| (eq. sigma within the sampled-data limit)",
                sigma_min, sigma_max, ok, f"f = controller.ancillary_rate_hz = {ctrl.ancillary_rate_hz:g} Hz")
        else:
            add("sigma", "sup over sigma > 0 of sigma J_lower > L1 + L2 (eq. sigma has a solution)",
                0.0, upper(L1 + L2), False,
                f"J_lower <= 0, so sigma J_lower <= 0 for every sigma > 0; L1 = {bounds['L1'].bound:.6g}, "
                f"L2 = {bounds['L2'].bound:.6g}")
        if ok:
            sigma_value, source = sigma_max, "largest admissible (every tightening decreases in sigma)"
    if sigma_value is None and not source:
        source = "none admissible"

    # 3. tube radius
    rho_tilde: float | None = None
    kappa = vbar = None
    if sigma_value is not None:
        sg = A(sigma_value)
        den = sg * Jl - L1 - L2
        rho_a = xi_t / den
        rho_tilde = upper(rho_a)
        rho = A(rho_tilde)
        kap = [sg * k * rho for k in krow]
        kappa = np.array([upper(k) for k in kap])
        vb = [v[i] - A(kappa[i]) for i in range(3)]
        vbar = np.array([lower(x) for x in vb])

    # 4a. input tightening and keep-up
    axes = ("u", "w", "r")
    for i, ax in enumerate(axes):
        if vbar is None:
            add(f"v_bar[{ax}]", f"{ax}_max - sigma sup||row_{ax} K|| rho_tilde > 0 (V_bar = V - sigma o P non-empty)",
                None, 0.0, None, "needs rho_tilde")
        else:
            add(f"v_bar[{ax}]", f"{ax}_max - sigma sup||row_{ax} K|| rho_tilde > 0 (V_bar = V - sigma o P non-empty)",
                float(vbar[i]), 0.0, bool(A(vbar[i]) > 0), f"{ax}_max = {region.v_max[i]:g}, "
                f"|kappa_{ax}| <= {kappa[i]:.6g}")
    if vbar is None:
        add("keep_up_nominal[u]", "u_bar >= max horizontal target speed", None, region.pd_dot_xy_max, None,
            "needs rho_tilde")
        add("keep_up_nominal[w]", "w_bar >= max |zdot_d|", None, region.pd_dot_max[2], None, "needs rho_tilde")
    else:
        add("keep_up_nominal[u]", "u_bar >= max horizontal target speed", float(vbar[0]), region.pd_dot_xy_max,
            bool(A(vbar[0]) >= h), "the nominal must be able to follow the target")
        add("keep_up_nominal[w]", "w_bar >= max |zdot_d|", float(vbar[1]), region.pd_dot_max[2],
            bool(A(vbar[1]) >= pz), "the nominal must be able to follow the target")
    add("keep_up_real[u]", "u_max >= max horizontal target speed + omega_bar", region.v_max[0],
        upper(h + om), bool(v[0] >= h + om), "the real vehicle against a current of omega_bar")
    add("keep_up_real[w]", "w_max >= max |zdot_d| + omega_bar", region.v_max[1], upper(pz + om),
        bool(v[1] >= pz + om), "the real vehicle against a current of omega_bar")

    # 4b. tightened state set
    e_bar = None
    margin = None
    terminal: dict = {"level": ctrl.terminal_level, "P": list(ctrl.P)}
    if rho_tilde is not None:
        rho = A(rho_tilde)
        e_bar = {}
        for name, (lo_, hi_) in (("e_d", region.e_d), ("e_z", region.e_z), ("e_o", region.e_o)):
            lo_b, hi_b = A(lo_) + rho, A(hi_) - rho
            e_bar[name] = (upper(lo_b), lower(hi_b))
            add(f"e_bar[{name}]", f"{name}_lo + rho_tilde < {name}_hi - rho_tilde (E_bar = R - P non-empty)",
                upper(lo_b), lower(hi_b), bool(lo_b < hi_b), "")
        # terminal set: min over the box E_bar of ||e||_P (P diagonal)
        tot = A(0)
        for p_i, name in zip(ctrl.P, ("e_d", "e_z", "e_o")):
            lo_b, hi_b = A(e_bar[name][0]), A(e_bar[name][1])
            if lo_b > 0:
                tot += A(p_i) * lo_b * lo_b
            elif hi_b < 0:
                tot += A(p_i) * hi_b * hi_b
        min_p = tot.sqrt()
        terminal["min_norm_P_over_E_bar"] = upper(min_p)
        terminal["ok"] = bool(min_p <= A(ctrl.terminal_level))
        add("terminal", "min over E_bar of ||e||_P <= terminal_level (F non-empty)", upper(min_p),
            ctrl.terminal_level, terminal["ok"], f"P = diag{tuple(ctrl.P)}")
        # position margin over one FHOCP period
        kc = [A(min(kappa[i], 2 * region.v_max[i])) for i in range(3)]
        ubar = A(max(float(vbar[0]), 0.0))
        dev = ((kc[0] + ubar * kc[2] * dt / 2) ** 2 + kc[1] ** 2).sqrt()
        margin = upper(dt * (dev + om))
    else:
        for name in ("e_d", "e_z", "e_o"):
            add(f"e_bar[{name}]", f"{name}_lo + rho_tilde < {name}_hi - rho_tilde (E_bar = R - P non-empty)",
                None, None, None, "needs rho_tilde")
        add("terminal", "min over E_bar of ||e||_P <= terminal_level (F non-empty)", None, ctrl.terminal_level,
            None, "needs rho_tilde")
        terminal["ok"] = None

    # 4c. horizon
    Vn = (v[0] ** 2 + v[1] ** 2 + v[2] ** 2).sqrt()
    T = A(ctrl.horizon)
    tmax = A(scenario.sensing_range) / (Vn + xi_t)
    horizon_ok = bool(T <= tmax)
    horizon = {"T": ctrl.horizon, "T_max": lower(tmax), "ok": horizon_ok, "V_bar": upper(Vn),
               "xi_tilde": xi_tilde, "R_bar": scenario.sensing_range}
    add("horizon", "T <= R_bar / (V_bar + xi_tilde) (eq. new_obstacles)", ctrl.horizon, lower(tmax), horizon_ok,
        f"R_bar = {scenario.sensing_range:g} m, V_bar = {upper(Vn):.6g}, xi_tilde = {xi_tilde:.6g}")

    # 4d. obstacles
    rbar = A(scenario.vehicle_radius)
    for (i, a), (j, b) in itertools.combinations(enumerate(scenario.obstacles), 2):
        dist = sum(((A(x) - A(y)) ** 2 for x, y in zip(a.center, b.center)), A(0)).sqrt()
        need = 2 * rbar + A(a.radius) + A(b.radius)
        add(f"obstacles[{i},{j}]", "||p_i - p_j|| > 2 r_bar + r_i + r_j (eq. obstacle_dis)", lower(dist),
            upper(need), bool(dist > need), "")
        if margin is None:
            add(f"obstacles[{i},{j}] inflated", "||p_i - p_j|| > 2 (r_bar + margin) + r_i + r_j", lower(dist),
                None, None, "needs rho_tilde")
        else:
            need2 = need + 2 * A(margin)
            add(f"obstacles[{i},{j}] inflated", "||p_i - p_j|| > 2 (r_bar + margin) + r_i + r_j", lower(dist),
                upper(need2), bool(dist > need2), f"margin = {margin:.6g} m")

    # 4e. initial error inside E_bar (FHOCP feasible at t = 0)
    p0 = scenario.trajectory.position(0.0)
    x0 = np.asarray(scenario.initial_state, dtype=float)
    e0 = error_coordinates(x0, p0)
    cos_rel = math.cos(x0[3] - math.atan2(x0[1] - p0[1], x0[0] - p0[0]))
    if rho_tilde is None:
        add("initial", "e(0) in E_bar (FHOCP feasible at t = 0)", None, 0.0, None, "needs rho_tilde")
    else:
        viol = max(max(e_bar[n][0] - e0[k], e0[k] - e_bar[n][1]) for k, n in enumerate(("e_d", "e_z", "e_o")))
        hem_ok = region.contains(float(np.clip(e0[0], *region.e_d)), float(np.clip(e0[1], *region.e_z)),
                                 float(np.clip(e0[2], *region.e_o)), cos_rel)
        add("initial", "max distance of e(0) outside E_bar <= 0, same hemisphere", float(viol), 0.0,
            bool(viol <= 0 and hem_ok),
            f"e(0) = [{e0[0]:.4g}, {e0[1]:.4g}, {e0[2]:.4g}], cos(psi - theta) = {cos_rel:.3g}")

    rho_info = {"rho_tilde": rho_tilde, "xi_tilde": xi_tilde, "xi_bar": bounds["xi_bar"].bound,
                "bearing_fold": upper(fold), "delta_theta": upper(dtheta)}
    sigma_info = {"value": sigma_value, "min": sigma_min, "max": sigma_max, "source": source}
    return Certificate(
        scenario_name=scenario.name, law=law, region=region, bounds=bounds, gap_target=gap, sigma=sigma_info,
        rho=rho_info, kappa_bar=kappa, v_bar=vbar, e_bar=e_bar, obstacle_margin=margin, terminal=terminal,
        horizon=horizon, conditions=tuple(conds), assumptions=_ASSUMPTIONS,
        elapsed_s=time.perf_counter() - t0, v_max=np.asarray(region.v_max, dtype=float), dt=ctrl.dt,
        sigma_fallback=float(ctrl.sigma) if ctrl.sigma is not None else 1.0, vehicle_radius=scenario.vehicle_radius)
