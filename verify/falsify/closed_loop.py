"""The closed-loop falsifier: disturbance *sequences* against the loop that runs (issue 11).

The certificate promises, for the sampled-data loop of :mod:`tubekit.loop.closed_loop`
(reset every δt, κ held at the ancillary rate, plans accepted by
:mod:`tubekit.loop.plan_check`), that max_j |e_j - ê_j| / tube_j <= 1 and that e stays in
R and v in V, as long as ‖ω_xy‖ <= ω̄_xy and |ω_z| <= ω̄_z. This module attacks
that claim with the loop that runs: every run is :func:`tubekit.loop.pipeline.certified_run`
(the same pipeline as the studies and the campaign; ``disturbance=`` override), which measures
the promises with :func:`tubekit.loop.promises.check_promises`:

* **starts** on the boundary of Ē: the initial error on a face of R shrunk by the
  first arc margin, in the certified hemisphere (:func:`start_state`);
* **greedy**: at every tick ω maximises d/dt of the tube Lyapunov function in the
  box norm, i.e. the growth of |ρ_j| on the axis with the largest |ρ_j| / tube_j
  (or on one fixed axis), read from the loop's own state (the loop's tick observer);
* **evolution**: piecewise-constant sequences (one ω per FHOCP period, and the
  start) optimised by a seeded (1 + λ) evolution strategy.

The budget counts simulations, never seconds; the search is deterministic for a seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Callable

import numpy as np

from tubekit.design_inputs import DesignInputs
from tubekit.model.ancillary import AncillaryLaw, get_law
from tubekit.model.errors import error_coordinates, numeric
from tubekit.exceptions import ConfigError
from tubekit.loop.pipeline import certified_run
from tubekit.plant.base import PiecewiseOmega
from verify.falsify.outcome import SearchOutcome
from tubekit.loop.promises import PREMISES, Promise, current_bound
from tubekit.scenario import HEMISPHERE_SIGN, Scenario
from tubekit.tightening import Tightening
from tubekit.validation import duration_seconds

from verify.falsify.strategies import state_from_error

if TYPE_CHECKING:
    from verify.certificate.artefact import Certificate

__all__ = ["LoopRun", "ClosedLoopResult", "falsify_closed_loop", "start_state", "greedy_disturbance",
           "piecewise_disturbance", "PREMISE_NAMES", "GREEDY_AXES"]

#: Promises that are premises of the theorem (a run breaking one claims nothing).
PREMISE_NAMES = PREMISES
#: Greedy variants: the axis with the largest |ρ_j| / tube_j, or one fixed axis (0: e_d, 1: e_z, 2: e_o).
GREEDY_AXES: tuple[int | None, ...] = (None, 0, 1, 2)
#: Offspring per generation of the evolution strategy, and its mutation step (unit cube).
_LAMBDA, _STEP = 4, 0.2
#: Unit numbers of a start state: face, three coordinates, bearing.
_START_DIM = 5


@dataclass(frozen=True)
class LoopRun:
    """One simulated run: what was applied and what :func:`check_promises` measured.

    ``ratio`` is max_j |e_j - ê_j| / tube_j over the run (1 = the certified tube);
    ``broken`` names the non-premise promises broken (``sway`` is NaN under an
    override and skipped); ``vacuous`` is True when a premise failed; ``claims_tube`` is False when the
    run's start is one the design's certificate for that start gives no tracking tier, so its tube is
    not promised there and a ratio above 1 refutes nothing.
    """

    strategy: str
    initial_state: tuple[float, float, float, float]
    ratio: float
    broken: tuple[str, ...]
    vacuous: bool
    promises: tuple[Promise, ...]
    sequence: tuple[tuple[float, float, float], ...] | None = None
    axis_ratios: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    claims_tube: bool = True

    @property
    def measures_tube(self) -> bool:
        """Its premises held and its tube is promised: its ratio measures the certificate."""
        return not self.vacuous and self.claims_tube

    @property
    def counterexample(self) -> bool:
        """The run breaks the certificate (ratio > 1 where the tube is promised, or a promise broken, premises
        holding)."""
        return not self.vacuous and ((self.ratio > 1.0 and self.claims_tube) or bool(self.broken))

    def fitness(self) -> float:
        """What the search maximises: the ratio (at most 1 where the tube is not promised), plus 10 for a broken
        promise."""
        ratio = self.ratio if math.isfinite(self.ratio) else 1e6
        return (ratio if self.claims_tube else min(ratio, 1.0)) + (10.0 if self.broken else 0.0) - \
            (100.0 if self.vacuous else 0.0)

    def to_dict(self) -> dict:
        """JSON form."""
        return {"strategy": self.strategy, "initial_state": list(self.initial_state), "ratio": self.ratio,
                "axis_ratios": list(self.axis_ratios),
                "broken": list(self.broken), "vacuous": self.vacuous, "claims_tube": self.claims_tube,
                "promises": [p.to_dict() for p in self.promises],
                "sequence": None if self.sequence is None else [list(w) for w in self.sequence]}


@dataclass(frozen=True)
class ClosedLoopResult(SearchOutcome):
    """Outcome of :func:`falsify_closed_loop`: the worst run and the tightness figure."""

    scenario: str
    law: str
    certified: bool
    tube: tuple[float, float, float]
    omega_bar: tuple[float, float]
    duration: float
    seed: int
    simulations: int
    vacuous_runs: int
    worst: LoopRun
    runs: tuple[LoopRun, ...] = field(repr=False, default=())

    @property
    def ratio(self) -> float:
        """Largest deviation/radius ratio observed over the runs whose premises held."""
        return self.worst.ratio

    @property
    def axis_ratios(self) -> tuple[float, float, float]:
        """Largest |rho_j| / tube_j per axis over the runs whose premises held and whose tube is promised
        (tightness per axis)."""
        valid = [r.axis_ratios for r in self.runs if r.measures_tube] or [self.worst.axis_ratios]
        return tuple(float(np.nanmax([a[j] for a in valid])) for j in range(3))

    def summary(self) -> str:
        """Readable text."""
        w = self.worst
        head = (f"closed loop, law '{self.law}', {self.simulations} simulations of {self.duration:g} s, "
                f"seed {self.seed}, ||omega_xy|| <= {self.omega_bar[0]:.4g}, |omega_z| <= {self.omega_bar[1]:.4g}")
        lines = [("COUNTEREXAMPLE found" if self.found else "no counterexample") + f" ({head})",
                 f"  largest deviation/radius ratio = {w.ratio:.6f} (tube = {np.round(self.tube, 6).tolist()}), "
                 f"by {w.strategy} from {np.round(w.initial_state, 4).tolist()}",
                 "  per axis (e_d, e_z, e_o), largest over all runs: "
                 + ", ".join(f"{x:.4f}" for x in self.axis_ratios)]
        if w.broken:
            lines.append("  broken: " + ", ".join(f"{p.name} {p.observed:.4g} vs {p.bound:.4g}"
                                                   for p in w.promises if p.name in w.broken))
        if self.vacuous_runs:
            lines.append(f"  {self.vacuous_runs} run(s) broke a premise (disturbance or recursive feasibility) "
                         "and claim nothing")
        unclaimed = sum(1 for r in self.runs if not r.vacuous and not r.claims_tube)
        if unclaimed:
            lines.append(f"  {unclaimed} run(s) started where the design certifies no tracking tier: their tube "
                         "is not promised (only their broken promises count)")
        if not self.certified:
            lines.append("  the scenario is not certified: these figures claim nothing")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON form (``found``, ``ratio``, ``worst`` with its sequence and promises)."""
        return {"mode": "closed-loop", "found": self.found, "ratio": self.ratio, "scenario": self.scenario,
                "law": self.law, "certified": self.certified, "tube": list(self.tube),
                "omega_bar": list(self.omega_bar), "duration": self.duration, "seed": self.seed,
                "simulations": self.simulations, "vacuous_runs": self.vacuous_runs,
                "axis_ratios": list(self.axis_ratios), "worst": self.worst.to_dict()}


# --------------------------------------------------------------------------- starts and disturbances
def start_state(scenario: Scenario, tightening: Tightening, unit: np.ndarray) -> tuple[float, ...]:
    """Initial state whose error lies on a face of Ē as the FHOCP enforces it (unit in [0,1]^5).

    Ē = R shrunk by the largest arc margin plus the inter-node allowance (the Tightening's
    node bounds e_d_min..e_d_max, |e_z| <= e_z_max, |e_o| <= e_o_max); a face of R shrunk by the
    first margin only is outside what an accepted plan may start from, so runs from there break the
    recursive-feasibility premise and claim nothing.

    ``unit[0]`` picks the face (e_d low/high, e_z low/high, e_o low/high), ``unit[1:4]`` the
    coordinates, ``unit[4]`` the bearing; the heading is in the certified hemisphere.
    """
    u = np.clip(np.asarray(unit, dtype=float), 0.0, 1.0)
    t = tightening
    box = np.array([[t.e_d_min, t.e_d_max], [-t.e_z_max, t.e_z_max], [-t.e_o_max, t.e_o_max]], dtype=float)
    e = box[:, 0] + (box[:, 1] - box[:, 0]) * u[1:4]
    face = min(int(u[0] * 6), 5)
    e[face // 2] = box[face // 2, face % 2]
    sign = HEMISPHERE_SIGN[scenario.region.heading] or (-1 if u[4] < 0.5 else 1)
    rel = state_from_error(e[0], e[1], e[2], 2 * math.pi * u[4], sign)
    target = np.asarray(scenario.trajectory.position(np.array([0.0]))[0], dtype=float)
    return tuple(float(x) for x in (rel + np.append(target, 0.0)))


def _omega_from_unit(omega_xy: float, omega_z: float, u: np.ndarray) -> tuple[float, float, float]:
    """ω with ‖ω_xy‖ <= ω̄_xy, |ω_z| <= ω̄_z from u in [0,1]^3 (u[1] > 0.5: on the circle)."""
    a = 2 * math.pi * float(u[0])
    mag = omega_xy * min(1.0, 2.0 * float(u[1]))
    return mag * math.cos(a), mag * math.sin(a), omega_z * (2.0 * float(u[2]) - 1.0)


def piecewise_disturbance(omega_xy: float, omega_z: float, dt: float, units: np.ndarray) -> PiecewiseOmega:
    """``disturbance(t)``: one ω per FHOCP period (``units`` (periods, 3) in [0,1])."""
    return PiecewiseOmega(tuple(_omega_from_unit(omega_xy, omega_z, u) for u in np.clip(units, 0.0, 1.0)), dt)


def greedy_disturbance(tap: list, tube: np.ndarray, omega_xy: float, omega_z: float,
                       axis: int | None = None) -> Callable:
    """``disturbance(t)`` maximising d/dt |ρ_j| / tube_j at the state the loop last told its observer (``tap``:
    state, nominal, target).

    ė is affine in ω (ė = J v + ζ + ξ(ω)), so ∂ė_j/∂ω = g_j and the best ω is ω̄ along s_j g_j,
    s_j = sign(ρ_j). ``axis`` None: j = argmax |ρ_j| / tube_j (right after the reset, ρ = 0: the
    axis with the fastest normalised growth).
    """
    e_dot = numeric().e_dot
    tube = np.asarray(tube, dtype=float)

    def omega(t: float) -> tuple[float, float, float]:
        if not tap:
            return 0.0, 0.0, 0.0
        x, x_hat, p_d = tap
        rel = x[:2] - p_d[:2]
        zero = np.asarray(e_dot(rel[0], rel[1], x[3], 0, 0, 0, 0, 0, 0, 0, 0, 0), dtype=float).ravel()
        g = np.column_stack([np.asarray(e_dot(rel[0], rel[1], x[3], 0, 0, 0, *np.eye(3)[k], 0, 0, 0),
                                        dtype=float).ravel() - zero for k in range(3)])
        ratio = np.abs(error_coordinates(x, p_d) - error_coordinates(x_hat, p_d)) / tube
        rho = error_coordinates(x, p_d) - error_coordinates(x_hat, p_d)
        if axis is not None:
            j = axis
        elif ratio.max() > 1e-9:
            j = int(np.argmax(ratio))
        else:
            j = int(np.argmax((omega_xy * np.hypot(g[:, 0], g[:, 1]) + omega_z * np.abs(g[:, 2])) / tube))
        s = 1.0 if rho[j] >= 0 else -1.0
        gx, gy, gz = s * g[j]
        n = math.hypot(gx, gy)
        wx, wy = (omega_xy * gx / n, omega_xy * gy / n) if n > 0 else (0.0, 0.0)
        return wx, wy, omega_z * (1.0 if gz >= 0 else -1.0)
    return omega


# --------------------------------------------------------------------------- one run
def _recorder(tap: list) -> Callable[[np.ndarray, np.ndarray, np.ndarray], None]:
    """The loop's tick observer that keeps only the last (state, nominal, target) in ``tap`` (the greedy reads it)."""
    def observe(state: np.ndarray, nominal: np.ndarray, p_d: np.ndarray) -> None:
        tap[:] = [state, nominal, p_d]
    return observe


@dataclass(frozen=True)
class _Attack:
    """Fixed context of a search: the short scenario (naming the law), the certificate's Tightening and bounds."""

    scenario: Scenario
    tightening: Tightening
    law: AncillaryLaw
    omega_xy: float
    omega_z: float

    def run(self, strategy: str, start: tuple[float, ...], disturbance: Callable, tap: list | None = None,
            sequence: tuple | None = None) -> LoopRun:
        """Simulate from ``start`` under ``disturbance`` (:func:`certified_run`) and measure the promises."""
        sc = self.scenario.with_changes(initial_state=start)
        done = certified_run(sc, self.tightening_at(sc), disturbance=disturbance,
                             observer=None if tap is None else _recorder(tap))
        axes = np.nanmax(np.abs(np.asarray(done.run.rho)) / np.asarray(self.tightening.tube), axis=0)
        ratio = float(np.max(axes)) if np.all(np.isfinite(axes)) else math.inf  # against the attacked tube
        claimed = any(p.name == "tube" and p.given for p in done.promises)
        return LoopRun(strategy, tuple(float(x) for x in start), ratio, done.broken,
                       not done.premises_held, done.promises, sequence, tuple(float(a) for a in axes), claimed)


    def tightening_at(self, scenario: Scenario) -> Tightening:
        """The tightening of a run of ``scenario``: the attacked one from its own start; from another start, the
        same design at the same σ certified for that start (the start is part of the design, so a certificate
        covers its own start only). A start the design does not cover gives a best-effort tightening: its runs
        claim nothing."""
        if self.tightening.design is None or scenario.initial_state == self.scenario.initial_state:
            return self.tightening
        from verify.certificate.certify import certify
        return certify(DesignInputs.of(scenario, sigma=self.tightening.sigma)).best_effort_tightening()


def _setup(scenario: Scenario, law: str | None, duration: float, certificate: Certificate | None,
           tightening: Tightening | None) -> tuple[_Attack, Certificate]:
    from verify.certificate.certify import certify

    name = scenario.controller.law if law is None else law
    law_obj = get_law(name)
    duration_seconds("duration", duration)
    cert = certificate if certificate is not None else certify(scenario, name)
    tight = tightening if tightening is not None else cert.best_effort_tightening()
    if not np.all(np.asarray(tight.tube) > 0):
        raise ConfigError("tube", "a certificate with a finite one-period tube", list(tight.tube),
                          "the design has no tube to attack")
    short = scenario.with_changes(duration=float(max(duration, scenario.controller.dt)),
                                  controller=replace(scenario.controller, law=name))
    wxy, wz = tight.disturbance.omega_xy, tight.disturbance.omega_z
    if scenario.plant.dynamic:  # the override replaces the water current only: its bound is the premise
        wxy, wz = current_bound(scenario)
    return _Attack(short, tight, law_obj, wxy, wz), cert


def falsify_closed_loop(scenario: Scenario, law: str | None = None, *, budget: int = 20, seed: int = 0,
                        duration: float = 3.0, certificate: Certificate | None = None,
                        tightening: Tightening | None = None) -> ClosedLoopResult:
    """Search disturbance sequences and boundary starts for a run that breaks the certificate.

    Parameters
    ----------
    scenario : Scenario
        The design to attack (its duration is replaced by ``duration``).
    law : str, optional
        Ancillary law (default: the scenario's).
    budget : int
        Simulations (>= 1): a quarter greedy (the four :data:`GREEDY_AXES` variants from
        boundary starts), the rest a (1 + 4) evolution strategy on piecewise-constant sequences.
    seed : int
        Seed; the search is deterministic for a seed.
    duration : float
        Seconds simulated per run (2-5 s keeps a budget of 20 under a minute).
    certificate : Certificate, optional
        Reuse a certificate instead of computing one.
    tightening : Tightening, optional
        Attack these sets instead of the certificate's (e.g. a deliberately shrunk tube).
    """
    if not isinstance(budget, int) or isinstance(budget, bool) or budget < 1:
        raise ConfigError("budget", "an integer >= 1 (simulations)", budget)
    attack, cert = _setup(scenario, law, duration, certificate, tightening)
    rng = np.random.default_rng(seed)
    runs: list[LoopRun] = []
    n_greedy = max(1, budget // 4)
    for k in range(n_greedy):
        tap: list = []
        axis = GREEDY_AXES[k % len(GREEDY_AXES)]
        start = attack.scenario.initial_state if k == 0 else start_state(scenario, attack.tightening,
                                                                         rng.uniform(0, 1, _START_DIM))
        omega = greedy_disturbance(tap, attack.tightening.tube, attack.omega_xy, attack.omega_z, axis)
        runs.append(attack.run(f"greedy:{'max' if axis is None else ('e_d', 'e_z', 'e_o')[axis]}",
                               tuple(start), omega, tap=tap))
    runs.extend(_evolve(attack, scenario, rng, budget - n_greedy))
    valid = [r for r in runs if r.measures_tube] or [r for r in runs if not r.vacuous] or runs
    worst = max(valid, key=LoopRun.fitness)
    return ClosedLoopResult(scenario=scenario.name, law=attack.law.name, certified=bool(cert.certified),
                            tube=tuple(float(x) for x in attack.tightening.tube),
                            omega_bar=(attack.omega_xy, attack.omega_z), duration=float(attack.scenario.duration),
                            seed=seed, simulations=len(runs), vacuous_runs=sum(r.vacuous for r in runs),
                            worst=worst, runs=tuple(runs))


def _evolve(attack: _Attack, scenario: Scenario, rng: np.random.Generator, budget: int) -> list[LoopRun]:
    """(1 + λ) evolution strategy over (start, one ω per period) in the unit cube; ``budget`` simulations."""
    periods = attack.scenario.steps
    dt = attack.scenario.controller.dt

    def evaluate(genome: np.ndarray) -> LoopRun:
        start = start_state(scenario, attack.tightening, genome[:_START_DIM])
        units = genome[_START_DIM:].reshape(periods, 3)
        omega = piecewise_disturbance(attack.omega_xy, attack.omega_z, dt, units)
        return attack.run("evolution", start, omega, sequence=tuple(omega.table))

    runs: list[LoopRun] = []
    if budget < 1:
        return runs
    parent = rng.uniform(0, 1, _START_DIM + 3 * periods)
    parent[_START_DIM + 1::3] = 1.0  # start with every ω on the circle ‖ω_xy‖ = ω̄_xy
    best = evaluate(parent)
    runs.append(best)
    while len(runs) < budget:
        children = [np.clip(parent + rng.normal(0, _STEP, parent.size), 0, 1)
                    for _ in range(min(_LAMBDA, budget - len(runs)))]
        for child in children:
            run = evaluate(child)
            runs.append(run)
            if run.fitness() >= best.fitness():
                parent, best = child, run
    return runs
