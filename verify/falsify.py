"""The falsifier: search for a configuration where the tube is not invariant.

It looks for a point on the tube boundary (||rho|| = rho-tilde) where
rho^T rho_dot > 0, always under the derived dynamics
(:func:`verify.invariance.rho_dot_inner`). Stage 1 is hypothesis (``find`` guided
by ``target`` on rho^T rho_dot; a counterexample found there is shrunk). If none is
found, stage 2 runs a bounded local optimisation (scipy Powell) from the worst
configuration seen, over exactly the set the strategies sample
(:func:`verify.strategies.configuration_from_unit`).

The search space comes from a certificate: its region, its sigma, rho-tilde and
bearing-mismatch bound Delta-theta, and V-bar for v_hat. For a design that does not
certify, the certificate's best-effort tightening supplies sigma, rho-tilde and V-bar.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, Phase, find, settings, target
from hypothesis.errors import NoSuchExample
from scipy.optimize import minimize

from tubekit.ancillary import AncillaryLaw, get_law
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario, load_scenario, paper_scenario

from .invariance import TubeConfiguration, rho_dot_inner
from .region import Region
from .strategies import CONFIGURATION_DIM, configuration_from_unit, tube_configurations

__all__ = ["FalsifyResult", "SearchSpace", "search_space", "falsify", "configure_falsify", "run_falsify"]

#: rho^T rho_dot above this (m^2/s in error units) counts as a violation.
VIOLATION_TOL = 1e-10


@dataclass(frozen=True)
class SearchSpace:
    """What the falsifier searches over: a region, the tube and the law's gain."""

    region: Region
    law: str
    sigma: float
    rho_tilde: float
    delta_theta: float
    v_bar: tuple[float, float, float]
    certified: bool


def search_space(scenario: Scenario, law: str | None = None, *, sigma: float | None = None,
                 rho_tilde: float | None = None, certificate=None) -> SearchSpace:
    """Build the search space from ``certificate`` (computed with :func:`verify.certify` if None)."""
    from .certificate import certify

    law = scenario.controller.law if law is None else law
    get_law(law)
    cert = certificate if certificate is not None else certify(scenario, law)
    tight = cert.tightening(allow_uncertified=True)
    dtheta = cert.rho.get("delta_theta")
    space = SearchSpace(
        region=cert.region, law=law,
        sigma=float(sigma if sigma is not None else tight.sigma),
        rho_tilde=float(rho_tilde if rho_tilde is not None else tight.rho_tilde),
        delta_theta=float(dtheta) if dtheta is not None and math.isfinite(dtheta) else math.pi,
        v_bar=tuple(float(x) for x in tight.v_max), certified=bool(cert.certified))
    if not space.sigma > 0:
        raise ConfigError("sigma", "a number > 0", space.sigma)
    if not space.rho_tilde > 0:
        raise ConfigError("rho_tilde", "a number > 0", space.rho_tilde)
    return space


@dataclass(frozen=True)
class FalsifyResult:
    """Outcome of :func:`falsify`.

    Attributes
    ----------
    found : bool
        A configuration with rho^T rho_dot > 0 was found.
    counterexample : TubeConfiguration or None
        The (shrunk, when from stage 1) counterexample.
    value : float
        rho^T rho_dot at the counterexample, else at the worst configuration seen.
    worst : TubeConfiguration
        The configuration with the largest rho^T rho_dot seen.
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
        out: dict = {"found": self.found, "law": sp.law, "stage": self.stage, "examples": self.examples,
                     "elapsed_s": self.elapsed_s, "worst_rho_dot_inner": self.worst_value,
                     "search_space": {"region": sp.region.to_dict(), "sigma": sp.sigma, "rho_tilde": sp.rho_tilde,
                                      "delta_theta": sp.delta_theta, "v_bar": list(sp.v_bar),
                                      "certified": sp.certified}}
        if self.found and self.counterexample is not None:
            ce = self.counterexample.to_dict()
            ce.update(sigma=sp.sigma, rho_norm=float(np.linalg.norm(self.counterexample.rho)),
                      rho_dot_inner=self.value)
            out["counterexample"] = ce
        return out

    def summary(self) -> str:
        """Readable text."""
        sp = self.space
        head = (f"law '{sp.law}', sigma = {sp.sigma:.4g} 1/s, rho_tilde = {sp.rho_tilde:.4g}, "
                f"Delta-theta = {sp.delta_theta:.4g} rad, {self.examples} configurations, {self.elapsed_s:.1f} s")
        if not self.found:
            return f"no counterexample ({head}); worst rho^T rho_dot = {self.worst_value:.4g} <= 0"
        ce = self.counterexample.to_dict()
        return "\n".join([
            f"COUNTEREXAMPLE found by {self.stage} ({head})",
            f"  rho^T rho_dot = {self.value:.6g} > 0 at ||rho|| = {np.linalg.norm(self.counterexample.rho):.6g}",
            f"  real    {ce['real']}", f"  nominal {ce['nominal']}",
            f"  v_hat {ce['v_hat']}, omega {ce['omega']}, pd_dot {ce['pd_dot']}",
        ])


def falsify(scenario: Scenario, law: str | None = None, *, budget: int = 500, seed: int = 0,
            sigma: float | None = None, rho_tilde: float | None = None, certificate=None,
            space: SearchSpace | None = None, local_iterations: int = 3000,
            controller: AncillaryLaw | None = None) -> FalsifyResult:
    """Search for a violation of pointwise tube invariance.

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
    sigma, rho_tilde : float, optional
        Override the certificate's gain / tube radius.
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
        space = search_space(scenario, law, sigma=sigma, rho_tilde=rho_tilde, certificate=certificate)
    if controller is not None:
        space = replace(space, law=controller.name)
    ancillary = controller if controller is not None else get_law(space.law)
    count = 0
    worst: list = [None, -math.inf]

    def value(cfg: TubeConfiguration) -> float:
        nonlocal count
        count += 1
        v = rho_dot_inner(cfg, ancillary, space.sigma)
        v = -math.inf if math.isnan(v) else v
        if v > worst[1]:
            worst[0], worst[1] = cfg, v
        return v

    def violated(cfg: TubeConfiguration) -> bool:
        v = value(cfg)
        if math.isfinite(v):
            target(v, label="rho_dot_inner")
        return v > VIOLATION_TOL

    strategy = tube_configurations(space.region, space.rho_tilde, space.v_bar, space.delta_theta)
    cfg_settings = settings(max_examples=budget, database=None, deadline=None,
                            phases=[Phase.generate, Phase.target, Phase.shrink],
                            suppress_health_check=list(HealthCheck))
    try:
        ce = find(strategy, violated, settings=cfg_settings, random=random.Random(seed))
        return FalsifyResult(True, ce, rho_dot_inner(ce, ancillary, space.sigma), worst[0], worst[1], "hypothesis",
                             count, space, time.perf_counter() - t0)
    except NoSuchExample:
        pass

    # Stage 2: local optimisation from the worst configuration, in the strategies' unit cube.
    rng = np.random.default_rng(seed)
    starts = [rng.uniform(0, 1, CONFIGURATION_DIM) for _ in range(3)]

    def neg(u: np.ndarray) -> float:
        v = value(configuration_from_unit(space.region, space.rho_tilde, space.v_bar, space.delta_theta, u))
        return 1e6 if not math.isfinite(v) else -v

    best_u, best_v = None, -math.inf
    for u0 in starts:
        res = minimize(neg, u0, method="Powell", bounds=[(0.0, 1.0)] * CONFIGURATION_DIM,
                       options={"maxfev": max(1, local_iterations // len(starts)), "xtol": 1e-6, "ftol": 1e-12})
        if -res.fun > best_v:
            best_u, best_v = res.x, -res.fun
    if best_v > VIOLATION_TOL:
        ce = configuration_from_unit(space.region, space.rho_tilde, space.v_bar, space.delta_theta, best_u)
        return FalsifyResult(True, ce, best_v, worst[0], worst[1], "local", count, space, time.perf_counter() - t0)
    return FalsifyResult(False, None, worst[1], worst[0], worst[1], "none", count, space, time.perf_counter() - t0)


def configure_falsify(parser: argparse.ArgumentParser) -> None:
    """Options of ``tubekit falsify``."""
    parser.add_argument("config", nargs="?", metavar="CONFIG",
                        help="scenario TOML (default: the paper's Section VI scenario)")
    parser.add_argument("--law", choices=("paper", "corrected"), help="ancillary law (default: the scenario's)")
    parser.add_argument("--budget", type=int, default=500, help="hypothesis examples (default 500)")
    parser.add_argument("--seed", type=int, default=0, help="search seed (default 0)")
    parser.add_argument("--sigma", type=float, help="override the ancillary gain sigma (1/s)")
    parser.add_argument("--rho", type=float, help="override the tube radius rho-tilde")
    parser.add_argument("--json", metavar="FILE", help="write the result as JSON")


def run_falsify(args: argparse.Namespace) -> int:
    """Exit 3 when a counterexample is found, 0 when none within the budget."""
    scenario = load_scenario(args.config) if args.config else paper_scenario()
    for name in ("sigma", "rho"):
        val = getattr(args, name)
        if val is not None and not (math.isfinite(val) and val > 0):
            raise ConfigError(f"--{name}", "a number > 0", val)
    result = falsify(scenario, args.law, budget=args.budget, seed=args.seed, sigma=args.sigma, rho_tilde=args.rho)
    print(result.summary())
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(result.to_dict(), indent=2))
    return 3 if result.found else 0
