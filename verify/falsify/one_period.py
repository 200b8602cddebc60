"""The falsifiers: one sampled-data period (pointwise) and whole closed-loop runs.

The certificate (:mod:`verify.theorem.sampled`) claims: from any state with ρ = 0 at a
sample (the nominal reset), one period of the sampled-data loop keeps
max_j |e_j - ê_j| / tube_j <= 1. :func:`falsify` searches the starts of one period
(e in Ē, v̂ in V̄, constant ω with ‖ω_xy‖ <= ω̄_xy and |ω_z| <= ω̄_z, p_d_dot in P)
for a ratio above 1, always with the loop's own law, plant and exact nominal arc
(:func:`verify.falsify.invariance.one_period_ratio`). Stage 1 is hypothesis (``find``
guided by ``target``; a counterexample is shrunk); if none is found, stage 2 runs a
bounded Powell search from random points of the same unit cube
(:func:`verify.falsify.strategies.period_configuration_from_unit`).

:func:`falsify_closed_loop` (:mod:`verify.falsify.closed_loop`) attacks whole runs of
:func:`tubekit.loop.pipeline.certified_run` with disturbance sequences.
"""

from __future__ import annotations

import math
import random
import time
from dataclasses import dataclass, replace

import numpy as np
from hypothesis import HealthCheck, Phase, find, settings, target
from hypothesis.errors import NoSuchExample
from scipy.optimize import minimize

from tubekit.model.ancillary import AncillaryLaw, get_law
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario

from verify.falsify.closed_loop import ClosedLoopResult, LoopRun, falsify_closed_loop
from verify.falsify.invariance import TubeConfiguration, one_period_ratio
from verify.kernel.region import Region
from verify.falsify.strategies import PERIOD_DIM, period_configuration_from_unit, period_configurations

__all__ = ["FalsifyResult", "SearchSpace", "search_space", "falsify", "VIOLATION_TOL", "falsify_closed_loop",
           "ClosedLoopResult", "LoopRun"]

#: A one-period ratio above 1 + this counts as a violation.
VIOLATION_TOL = 1e-9


@dataclass(frozen=True)
class SearchSpace:
    """What the falsifier searches over, all from a certificate (units m, m/s, rad, rad/s, s).

    ``start`` is Ē (e_d, e_z, e_o intervals an accepted plan starts from), ``tube`` the per-axis
    one-period tube, ``theta`` its bearing bound, ``omega_bar`` = (ω̄_xy, ω̄_z), ``tick`` = 1 / f and
    ``ticks`` per period.
    """

    region: Region
    law: str
    sigma: float
    tube: tuple[float, float, float]
    theta: float
    v_bar: tuple[float, float, float]
    omega_bar: tuple[float, float]
    start: tuple[tuple[float, float], ...]
    tick: float
    ticks: int
    certified: bool

    def to_dict(self) -> dict:
        """JSON form."""
        return {"region": self.region.to_dict(), "sigma": self.sigma, "tube": list(self.tube), "theta": self.theta,
                "v_bar": list(self.v_bar), "omega_bar": list(self.omega_bar),
                "start": [list(b) for b in self.start], "tick": self.tick, "ticks": self.ticks,
                "certified": self.certified}


def search_space(scenario: Scenario, law: str | None = None, *, sigma: float | None = None,
                 certificate=None) -> SearchSpace:
    """Build the search space from ``certificate`` (computed with :func:`verify.certify` if None).

    ``sigma`` overrides the gain attacked (the tube stays the certificate's).
    """
    from verify.certificate.certify import certify

    law = scenario.controller.law if law is None else law
    get_law(law)
    cert = certificate if certificate is not None else certify(scenario, law)
    tight = cert.best_effort_tightening()
    tube = tuple(float(x) for x in cert.tube.rho)
    if not all(math.isfinite(x) and x > 0 for x in tube):
        raise ConfigError("tube", "a certificate with a finite one-period tube", list(tube),
                          "the design has no tube to attack")
    ctrl = scenario.controller
    ticks = int(round(ctrl.ancillary_rate_hz * ctrl.dt))
    theta = float(cert.tube.theta)
    space = SearchSpace(
        region=cert.region, law=law, sigma=float(sigma if sigma is not None else cert.design.sigma), tube=tube,
        theta=theta if math.isfinite(theta) else math.pi, v_bar=tuple(float(x) for x in tight.v_max),
        omega_bar=(float(cert.disturbance.omega_xy), float(cert.disturbance.omega_z)),
        start=((float(tight.e_d_min), float(tight.e_d_max)), (-float(tight.e_z_max), float(tight.e_z_max)),
               (-float(tight.e_o_max), float(tight.e_o_max))),
        tick=ctrl.dt / ticks, ticks=ticks, certified=bool(cert.certified))
    if not (math.isfinite(space.sigma) and space.sigma >= 0):
        raise ConfigError("sigma", "a finite number >= 0 (0: no ancillary feedback)", space.sigma)
    return space


@dataclass(frozen=True)
class FalsifyResult:
    """Outcome of :func:`falsify`.

    Attributes
    ----------
    found : bool
        A start with one-period ratio max_j |rho_j| / tube_j > 1 was found.
    counterexample : TubeConfiguration or None
        The (shrunk, when from stage 1) counterexample.
    value : float
        The ratio at the counterexample, else at the worst configuration seen.
    worst : TubeConfiguration
        The configuration with the largest ratio seen.
    stage : str
        ``"hypothesis"``, ``"local"`` or ``"none"``.
    examples : int
        Configurations evaluated.
    space : SearchSpace
        What was searched.
    elapsed_s : float
        Wall time (s).
    """

    found: bool
    counterexample: TubeConfiguration | None
    value: float
    worst: TubeConfiguration
    worst_value: float
    stage: str
    examples: int
    space: SearchSpace
    elapsed_s: float

    def to_dict(self) -> dict:
        """JSON form (``found`` and, when found, ``counterexample`` with the issue's keys)."""
        sp = self.space
        out: dict = {"mode": "one-period", "found": self.found, "law": sp.law, "stage": self.stage,
                     "examples": self.examples, "elapsed_s": self.elapsed_s, "ratio": self.worst_value,
                     "search_space": sp.to_dict()}
        if self.found and self.counterexample is not None:
            ce = self.counterexample.to_dict()
            ce.update(sigma=sp.sigma, ratio=self.value)
            out["counterexample"] = ce
        return out

    def summary(self) -> str:
        """Readable text."""
        sp = self.space
        head = (f"one period, law '{sp.law}', sigma = {sp.sigma:.4g} 1/s, tube = {np.round(sp.tube, 6).tolist()}, "
                f"{self.examples} configurations, {self.elapsed_s:.1f} s")
        if not self.found:
            return f"no counterexample ({head}); largest ratio = {self.worst_value:.4g} <= 1"
        ce = self.counterexample.to_dict()
        return "\n".join([
            f"COUNTEREXAMPLE found by {self.stage} ({head})",
            f"  max_j |rho_j| / tube_j = {self.value:.6g} > 1 over one period from (rho = 0)",
            f"  start   {ce['real']}",
            f"  v_hat {ce['v_hat']}, omega {ce['omega']}, pd_dot {ce['pd_dot']}",
        ])


def falsify(scenario: Scenario, law: str | None = None, *, budget: int = 500, seed: int = 0,
            sigma: float | None = None, certificate=None,
            space: SearchSpace | None = None, local_iterations: int = 3000,
            controller: AncillaryLaw | None = None) -> FalsifyResult:
    """Search the starts of one sampled-data period for a deviation beyond the certified tube.

    Parameters
    ----------
    scenario : Scenario
        The design to attack.
    law : str, optional
        Ancillary law (default: the scenario's).
    budget : int
        Hypothesis examples in stage 1.
    seed : int
        Seed (the search is deterministic for a seed).
    sigma : float, optional
        Override the certificate's gain (the tube stays the certificate's).
    certificate : Certificate, optional
        Reuse a certificate instead of computing one.
    space : SearchSpace, optional
        Search this space directly (skips the certificate).
    local_iterations : int
        Function evaluations of the stage-2 local search.
    controller : AncillaryLaw, optional
        Your own law (kappa = -sigma K(J) rho with your ``gain_of_jacobian``) to attack
        instead of the named one; the search space still comes from ``space`` or the
        certificate of ``law``.
    """
    if not isinstance(budget, int) or budget < 1:
        raise ConfigError("budget", "an integer >= 1", budget)
    t0 = time.perf_counter()
    if space is None:
        space = search_space(scenario, law, sigma=sigma, certificate=certificate)
    if controller is not None:
        space = replace(space, law=controller.name)
    evaluate = _Evaluator(space, controller if controller is not None else get_law(space.law))

    def result(found: bool, counterexample: TubeConfiguration | None, value: float, stage: str) -> FalsifyResult:
        elapsed_s = time.perf_counter() - t0  # reported, never part of a verdict
        return FalsifyResult(found, counterexample, value, evaluate.worst, evaluate.worst_value, stage,
                             evaluate.count, space, elapsed_s)

    counterexample = _hypothesis_stage(space, evaluate, budget, seed)
    if counterexample is not None:
        return result(True, counterexample, evaluate.ratio(counterexample),
                      "hypothesis")
    best_unit, best_value = _local_stage(space, evaluate, seed, local_iterations)
    if best_value > 1.0 + VIOLATION_TOL:
        return result(True, _configuration(space, best_unit), best_value, "local")
    return result(False, None, evaluate.worst_value, "none")


class _Evaluator:
    """One-period ratio of a configuration (NaN as -inf), counting calls and keeping the worst seen."""

    def __init__(self, space: SearchSpace, ancillary: AncillaryLaw) -> None:
        self.space, self.ancillary = space, ancillary
        self.count = 0
        self.worst: TubeConfiguration | None = None
        self.worst_value = -math.inf

    def ratio(self, cfg: TubeConfiguration) -> float:
        """The one-period deviation/radius ratio from ``cfg`` (uncounted)."""
        sp = self.space
        return one_period_ratio(cfg, self.ancillary, sp.sigma, np.asarray(sp.tube), sp.tick, sp.ticks)

    def __call__(self, cfg: TubeConfiguration) -> float:
        self.count += 1
        value = self.ratio(cfg)
        value = -math.inf if math.isnan(value) else value
        if value > self.worst_value:
            self.worst, self.worst_value = cfg, value
        return value


def _configuration(space: SearchSpace, unit: np.ndarray) -> TubeConfiguration:
    """The configuration at a point of the strategies' unit cube."""
    return period_configuration_from_unit(space.region, space.start, space.v_bar, space.omega_bar, unit)


def _hypothesis_stage(space: SearchSpace, evaluate: _Evaluator, budget: int, seed: int) -> TubeConfiguration | None:
    """Stage 1: hypothesis ``find`` guided by ``target``; the shrunk counterexample, or None."""
    def violated(cfg: TubeConfiguration) -> bool:
        value = evaluate(cfg)
        if math.isfinite(value):
            target(value, label="one_period_ratio")
        return value > 1.0 + VIOLATION_TOL

    strategy = period_configurations(space.region, space.start, space.v_bar, space.omega_bar)
    cfg_settings = settings(max_examples=budget, database=None, deadline=None,
                            phases=[Phase.generate, Phase.target, Phase.shrink],
                            suppress_health_check=list(HealthCheck))
    try:
        return find(strategy, violated, settings=cfg_settings, random=random.Random(seed))
    except NoSuchExample:
        return None


def _local_stage(space: SearchSpace, evaluate: _Evaluator, seed: int,
                 local_iterations: int) -> tuple[np.ndarray | None, float]:
    """Stage 2: Powell from three random points of the unit cube; the best point and its ratio."""
    rng = np.random.default_rng(seed)
    starts = [rng.uniform(0, 1, PERIOD_DIM) for _ in range(3)]

    def negative_value(unit: np.ndarray) -> float:
        value = evaluate(_configuration(space, unit))
        return 1e6 if not math.isfinite(value) else -value

    best_unit, best_value = None, -math.inf
    for start in starts:
        res = minimize(negative_value, start, method="Powell", bounds=[(0.0, 1.0)] * PERIOD_DIM,
                       options={"maxfev": max(1, local_iterations // len(starts)), "xtol": 1e-6, "ftol": 1e-12})
        if -res.fun > best_value:
            best_unit, best_value = res.x, -res.fun
    return best_unit, best_value
