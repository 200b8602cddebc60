"""The closed loop: plant + sensing + FHOCP + ancillary feedback (issue 5, items 1-3).

Timeline (dt = FHOCP period, h = 1 / ancillary_rate_hz, m = dt / h ticks):

* at every sampling instant t_k = k dt the position is sensed
  (:class:`tubekit.loop.sensing.ObstacleMap`), the FHOCP is solved from the measured
  state (nominal reset, ê(t_k) = e(t_k), paper eq. diff_mpc) and its first input
  v̂ is held over [t_k, t_k + dt);
* the nominal state x̂ is propagated from x(t_k) with v̂ and the nominal
  kinematics (eq. 3), in closed form (exact unicycle arcs, :func:`nominal_arc`);
* at every tick t_i = i h the ancillary law gives κ(e, ê) (zero-order hold over
  [t_i, t_i + h)), the applied input is v = v̂ + κ; only when v leaves V (either corner: with
  ``limits.u_min`` the surge never goes below it) is it clipped to V (saturation, counted per tick and per
  sampling period);
* the plant ẋ = f(x) v + ω(t, x, v) (eq. 11, :class:`tubekit.plant.kinematic.Plant`), or the
  4-DOF vehicle whose velocity loop tracks v (``[plant] kind = "dynamic"``,
  :class:`tubekit.plant.dynamic.DynamicPlant`), is integrated with classical RK4 at a
  fixed step h / plant_substeps (5 ms by default: 100 Hz ticks, 2 substeps).

:func:`run_closed_loop` is a pipeline of named steps: :func:`validate_inputs` →
:func:`build_solver` → per sampling period (:meth:`_ClosedLoop.run_period`):
sense → solve (:meth:`_ClosedLoop.solve`, :class:`PlanMemory`) → nominal arc →
ticks (:meth:`_ClosedLoop.run_ticks`: ancillary law, :func:`saturate`, plant) →
log (:class:`_Log`).

What runs is the scenario's: the ancillary law ``controller.law`` (a registered name), the FHOCP backend
``controller.fhocp_backend`` in mode ``controller.fhocp_mode`` (:func:`tubekit.fhocp.registry.make_solver`),
the plant ``plant.kind``; σ is the tightening's. A variant is a changed scenario
(``scenario.with_changes(...)``) or tightening (``dataclasses.replace(tightening, sigma=...)``).

Fallbacks: a FHOCP result flagged ``fallback`` is used (its first input) and
counted; a result whose first input is not finite, a :class:`SolverError` or a plan
the arc check (with the terminal condition) rejects is replaced by the last accepted
plan shifted by the steps elapsed and counted as ``replaced``. Once that plan is exhausted the backup
law (``tightening.backup.law.command``, a :class:`tubekit.model.backup.BackupLaw`, held over each tick, no κ) runs
about the anchor
p* = the nominal end of the last accepted plan (:class:`tubekit.loop.memory.PlanMemory`), logged as
``backup_active``, until a plan is accepted again; only a tightening without a backup keeps the zero
input (logged as a warning). A non-finite κ (J singular) is replaced by zero and counted. Nothing
non-finite reaches the plant.

Rate limit (``scenario.limits.rate``): every solve gets ``v_last``, the command of the last tick
before the plan starts (the previous plan's node, the replayed node, the backup's last command; 0 at t = 0:
the run starts at rest), when the solver's ``solve`` takes that keyword; the exact check verifies the rate
rows against it (:func:`tubekit.loop.plan_check.check_rates`), so no command jumps by more than J = rate · dt
between periods. A ramped backup blends the last applied command into its law: the hand-over does not jump.

Logging: one row per tick plus a final row at t = duration (inputs NaN there).
The nominal x̂ logged at a sampling instant is the left limit x̂(t_k⁻), before the
reset, so ‖ρ‖ = ‖e - ê‖ shows the largest deviation of every interval; the κ
applied at that tick uses the reset nominal (ρ = 0).
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable

import numpy as np

from tubekit.model.ancillary import AncillaryLaw
from tubekit.exceptions import ConfigError, SolverError
from tubekit.loop.candidate import candidate_plan, settle_last_row
from tubekit.loop.memory import ZERO_INPUT, PlanMemory
from tubekit.loop.plan_check import PlanCheck, check_plan, check_rates, check_sway
from tubekit.loop.setup import (Clock, build_solver, progress_bar, saturate, silence_fallback_warnings, status_text,
                                takes_v_last, validate_inputs)
from tubekit.plant.base import OmegaOverride, PlantModel
from tubekit.plant.factory import make_plant
from tubekit.plant.kinematic import nominal_arc
from tubekit.scenario import HEMISPHERE_SIGN, Obstacle, Scenario
from tubekit.loop.sensing import ObstacleMap
from tubekit.loop.result import LogArrays, SimulationResult, allocate_log
from tubekit.tightening import Tightening

if TYPE_CHECKING:  # the solver package (cvxpy) is loaded only when a solver is built
    from tubekit.fhocp.result import FhocpResult, FhocpSolver, SolverFactory

__all__ = [
    "run_closed_loop",
    "PlanMemory",
    "validate_inputs",
    "build_solver",
    "saturate",
    "TickObserver",
]

#: ``observer(state, nominal, p_d)``: told the state (4,), the nominal arc's point (4,) and the target (3,) at a tick.
TickObserver = Callable[[np.ndarray, np.ndarray, np.ndarray], None]


_ZERO_INPUT = ZERO_INPUT
#: Where the candidate's completion aims e_d: this fraction of the way from the nominal's e_d bound up (m / m).
CANDIDATE_GOAL = 0.1
_LOG = logging.getLogger(__name__)


# ---- the log ----------------------------------------------------------------------------

@dataclass
class _Log(LogArrays):
    """Preallocated per-tick (K + 1 rows) and per-period arrays: the fields of :data:`LOG_FIELDS`."""

    statuses: list[str] = field(default_factory=list)
    kappa_failures: int = 0

    @classmethod
    def allocate(cls, clock: Clock) -> _Log:
        return cls(**allocate_log(len(clock.t), clock.steps))

    def record_solve(self, k: int, i0: int, result: FhocpResult | None, elapsed_s: float) -> None:
        """Record the solver's answer at period ``k`` (first tick ``i0``); ``None`` when it raised."""
        if result is None:
            self.statuses.append("exception")
            self.solve_ms[i0] = 1e3 * elapsed_s
            return
        self.statuses.append(status_text(result.status))
        self.iterations[k] = float(result.iterations)
        self.max_violation[k] = float(result.max_violation)
        self.solve_ms[i0] = 1e3 * float(result.solve_time_s)


@dataclass
class _Period:
    """What one sampling period applies: the held v̂, its flags, the nominal arc (ticks + 1, 4) and,
    while the backup law runs, its anchor p* (m; the arc is NaN then)."""

    v_hat: np.ndarray
    fallback: bool
    replaced: bool
    arc: np.ndarray
    anchor: tuple[float, float, float] | None = None


# ---- the loop ---------------------------------------------------------------------------

class _ClosedLoop:
    """One run's fixed context (scenario, sets, clock, solver, law, plant, map) and its log."""

    def __init__(self, scenario: Scenario, tightening: Tightening, clock: Clock, solver: FhocpSolver,
                 law: AncillaryLaw, sigma: float, plant: PlantModel, obstacle_map: ObstacleMap) -> None:
        self.scenario, self.tightening, self.clock, self.solver = scenario, tightening, clock, solver
        self.law, self.sigma, self.plant, self.map = law, sigma, plant, obstacle_map
        self.desired = np.asarray(scenario.trajectory.position(clock.t), dtype=float)
        self.limits = tuple(float(c) for c in scenario.limits.vector)
        self.lower = tuple(float(c) for c in scenario.limits.lower)  # V's lower corner (the surge floor)
        self.v_bar = np.asarray(tightening.v_max, dtype=float)  # V̄: the plans' box (V for the baseline)
        self.v_low = np.asarray(tightening.v_low, dtype=float)  # its lower corner
        self.recovers = tightening.recovers and scenario.controller.recovery
        self.memory = PlanMemory()
        self.log = _Log.allocate(clock)
        self.sign = HEMISPHERE_SIGN[scenario.region.heading]
        # the last tick's command: initially the plans' box's point nearest rest (0, or (u_min + κ̄_u, 0, 0))
        self.v_last = (None if scenario.limits.rate is None
                       else np.clip(scenario.limits.start_command, self.v_low, self.v_bar))
        self.passes_v_last = takes_v_last(solver)
        self.t_h, self.v_h = 0.0, (0.0, 0.0, 0.0)  # the last hand-over to the backup: time (s), applied command
        self.sway_last = 0.0  # the last tick's sway command (m/s): a lateral backup's, else 0
        self.release = math.inf if tightening.backup is None else tightening.backup.law.sway_release
        self.observer: TickObserver | None = None  # told (state, nominal, target) at every tick a plan is followed

    def sense(self, xk: np.ndarray) -> tuple[Obstacle, ...]:
        """Obstacles known after sensing at the position of ``xk``."""
        return self.map.update(xk[:3])

    def solve(self, k: int, tk: float, xk: np.ndarray,
              known: tuple[Obstacle, ...]) -> tuple[np.ndarray, bool, bool]:
        """Solve the FHOCP at ``tk`` and decide v̂; never pass NaN on. Returns (v̂, fallback, replaced).

        In order: the solver's plan passing the check; the shifted candidate passing it; the replay of the last
        tracking plan while it lasts; with :attr:`Tightening.recovers`, the solver's plan or the candidate
        passing the safe part of the check (a recovery plan: tracking not in force); the replay; the backup.
        """
        result, plan, check = self.ask(k, tk, xk, known)
        if result is not None and plan is not None and check is not None and check.ok:
            fallback = bool(result.fallback)
            return self.follow(k, plan, fallback, check, tracking=True), fallback, False
        shifted = self.candidate(k, tk, xk, known, recovery=False)
        if shifted is not None:
            return shifted, True, True
        memory = self.memory
        if self.recovers and (memory.exhausted or not memory.tracking):
            if result is not None and plan is not None and check is not None and check.safe:
                return self.follow(k, plan, bool(result.fallback), check, tracking=False), bool(result.fallback), \
                    False
            shifted = self.candidate(k, tk, xk, known, recovery=True)
            if shifted is not None:
                return shifted, True, True
        v_hat = memory.replacement()
        self.log.plan_age[k] = memory.age
        return v_hat, True, True

    def ask(self, k: int, tk: float, xk: np.ndarray, known: tuple[Obstacle, ...]
            ) -> tuple[FhocpResult | None, np.ndarray | None, PlanCheck | None]:
        """The solver's result at ``tk``, the plan the loop may use of it (:meth:`plan_of`) and its check (None
        where the solver failed or its result was refused)."""
        c0 = time.perf_counter()
        result: FhocpResult | None = None
        plan: np.ndarray | None = None
        try:
            if self.passes_v_last:
                result = self.solver.solve(tk, xk.copy(), known, v_last=self.v_last)
            else:
                result = self.solver.solve(tk, xk.copy(), known)
            plan = self.plan_of(result)
            plan = settle_last_row(self.scenario, self.tightening.proven_terminal_law, plan, xk, tk, self.v_bar,
                                   self.scenario.limits.jump(self.scenario.controller.dt), v_min=self.v_low)
        except SolverError as exc:
            _LOG.debug("period %d: solver result refused: %s", k, exc)
        self.log.record_solve(k, k * self.clock.ticks, result, time.perf_counter() - c0)
        return result, plan, self.accept(k, tk, xk, plan, known) if plan is not None else None

    def follow(self, k: int, plan: np.ndarray, fallback: bool, check: PlanCheck, tracking: bool) -> np.ndarray:
        """Accept ``plan`` (N, 3): remember it (the anchor its terminal condition was met about, else its nominal
        end, is the backup's anchor) and return its first input; ``tracking`` False: a recovery plan (followed for
        safety, tracking not in force)."""
        checked = self.tightening.horizon_arcs > 0
        end = check.end if check.anchor is None else np.asarray(check.anchor, dtype=float)
        self.memory.remember(plan, fallback, accepted=checked, end=end, tracking=tracking)
        self.log.plan_age[k] = self.memory.age
        return plan[0].copy()

    def candidate(self, k: int, tk: float, xk: np.ndarray, known: tuple[Obstacle, ...],
                  recovery: bool) -> np.ndarray | None:
        """v̂ of the shifted candidate (:mod:`tubekit.loop.candidate`) when it passes the exact check (with
        ``recovery``: its safe part) — it is then the accepted plan — else None. Only where plans are checked."""
        memory, tight = self.memory, self.tightening
        law = tight.proven_terminal_law
        if not self.scenario.controller.candidate or tight.horizon_arcs == 0:
            return None
        previous = None if memory.plan is None or memory.exhausted else memory.plan
        if previous is None and law is None:
            return None
        goal = tight.e_d_min + CANDIDATE_GOAL * (tight.e_d_max - tight.e_d_min)
        plan = candidate_plan(self.scenario, previous, memory.age, xk, tk, self.v_bar,
                              self.scenario.limits.jump(self.scenario.controller.dt), goal, law=law, v_min=self.v_low,
                              v_last=self.v_last)
        if plan is None:
            return None
        check = check_sway(self.sway_last, self.release) or \
            check_plan(self.scenario, tight, tk, xk, plan, known, self.sign, v_last=self.v_last)
        if not (check.ok or (recovery and check.safe)):
            return None
        self.log.candidate[k] = True
        return self.follow(k, plan, False, check, tracking=check.ok)

    def plan_of(self, result: FhocpResult) -> np.ndarray:
        """The plan the loop may use: exactly N finite rows, the first equal to ``first_input``, projected onto V̄.

        The projection (each input clipped to V̄ = [v_low, v_max], ``Tightening.v_low``) removes the solver's
        tolerance: the plan check then verifies, against V̄ exactly, the inputs that run (module doc).

        Raises
        ------
        SolverError
            A result with another number of rows than N, a non-finite input, or a ``first_input`` that is not
            its first row (handled like any failed solve: the previous plan is replayed).
        """
        n = self.scenario.controller.horizon_steps
        inputs = np.asarray(result.inputs, dtype=float)
        if inputs.shape != (n, 3) or not np.all(np.isfinite(inputs)):
            raise SolverError(f"a plan of exactly {n} finite rows of 3 inputs expected, got shape {inputs.shape}")
        first = np.asarray(result.first_input, dtype=float).reshape(-1)
        if first.shape != (3,) or not np.array_equal(first, inputs[0]):
            raise SolverError(f"first_input {first.tolist()} differs from the plan's first row {inputs[0].tolist()}")
        return np.clip(inputs, self.v_low, self.v_bar)

    def backup_anchor(self, k: int, xk: np.ndarray) -> np.ndarray | None:
        """p* (3,) for period ``k`` when the replayed plan is exhausted and a backup exists, else None.

        Without an accepted plan yet, p* is the measured position (no terminal condition was checked
        there). Without a backup the loop keeps the zero input and logs it.
        """
        if not self.memory.exhausted:
            return None
        if self.tightening.backup is None:
            if self.tightening.horizon_arcs > 0 and self.memory.age == (len(self.memory.plan) if
                                                                         self.memory.plan is not None else 1):
                _LOG.warning("period %d: the replayed plan is exhausted and the tightening has no backup: "
                             "zero input until a plan is accepted (no certified input)", k)
            return None
        if self.memory.anchor is None:
            self.memory.anchor = np.asarray(xk, dtype=float)[:3].copy()
        return self.memory.anchor

    def accept(self, k: int, tk: float, xk: np.ndarray, plan: np.ndarray,
               known: tuple[Obstacle, ...]) -> PlanCheck:
        """Exact arc check of the plan (N, 3) against the certificate's margins (ok, with no end, without margins).

        The check's ``end`` is the accepted plan's nominal end: the backup's anchor.
        """
        gate = check_sway(self.sway_last, self.release)
        if gate is not None:
            check = gate
        elif self.tightening.horizon_arcs == 0:
            if self.scenario.limits.rate is None:
                return PlanCheck(True, math.inf, "no margins")
            check = check_rates(self.scenario, self.tightening, plan, self.v_last)
        else:
            check = check_plan(self.scenario, self.tightening, tk, xk, plan, known, self.sign, v_last=self.v_last)
        self.log.plan_slack[k] = check.slack
        self.log.rejected[k] = not check.ok
        if not check.ok:
            _LOG.debug("period %d: plan rejected by '%s' (slack %.3g)", k, check.where, check.slack)
        return check

    def ancillary(self, i: int, xs: np.ndarray, x_hat: np.ndarray) -> np.ndarray:
        """κ (3,) at tick ``i``; zero (and counted) when the law fails."""
        try:
            return self.law(xs, x_hat, self.desired[i], self.sigma)
        except (ConfigError, FloatingPointError, np.linalg.LinAlgError):
            self.log.kappa_failures += 1
            return _ZERO_INPUT

    def run_ticks(self, k: int, x: tuple, period: _Period) -> tuple[tuple, float]:
        """Ticks of period ``k``: ancillary law (or the backup law), saturation, plant.

        Returns (state, controller time spent on the law in s).
        """
        clock, log = self.clock, self.log
        i0, h = k * clock.ticks, clock.plant_step
        vh = tuple(float(c) for c in period.v_hat)
        law_s = 0.0
        backup = None if self.tightening.backup is None else self.tightening.backup.law
        if period.anchor is not None and not (i0 and log.backup_active[i0 - 1]):
            self.t_h = clock.t[i0]  # the hand-over: the backup starts this period, from the last applied command
            self.v_h = tuple(float(c) for c in log.inputs[i0 - 1]) if i0 else (0.0, 0.0, 0.0)
        for j in range(clock.ticks):
            i = i0 + j
            xs = np.asarray(x)
            log.states[i] = xs
            sway = 0.0
            if self.observer is not None and period.anchor is None:  # a plan is followed: told before its command
                self.observer(xs, period.arc[j], self.desired[i])
            if period.anchor is not None:  # the backup law; its sway command is 0 but for a lateral law
                u_c, w_c, r_c, sway = backup.lateral_command(x, period.anchor, float(clock.t[i] - self.t_h), self.v_h)
                v = (u_c, w_c, r_c)
                log.sway_command[i] = sway
                log.kappa[i] = 0.0
                log.v_hat[i] = v
            elif self.sigma > 0.0:
                a0 = time.perf_counter()
                kap = self.ancillary(i, xs, period.arc[j])
                law_s += time.perf_counter() - a0
                log.kappa[i] = kap
                v = (vh[0] + float(kap[0]), vh[1] + float(kap[1]), vh[2] + float(kap[2]))
            else:
                log.kappa[i] = 0.0
                v = vh
            v, log.saturated[i] = saturate(v, self.limits, self.lower)
            log.inputs[i] = v
            x = self.plant.step_tuple(float(clock.t[i]), x, v, h, clock.substeps, sway)
        self.sway_last = sway
        return x, law_s

    def log_period(self, k: int, xk: np.ndarray, period: _Period, nominal_before: np.ndarray) -> None:
        """Per-tick copies of the period's v̂, flags, map size and nominal (left limit at the sample)."""
        m, log = self.clock.ticks, self.log
        i0 = k * m
        log.fallback[i0:i0 + m] = period.fallback
        log.replaced[i0:i0 + m] = period.replaced
        log.n_detected[i0:i0 + m] = self.map.count
        log.nominal[i0] = nominal_before if k > 0 else xk
        log.nominal[i0 + 1:i0 + m] = period.arc[1:m]
        log.v_hat[i0:i0 + m] = period.v_hat
        log.backup_active[i0:i0 + m] = period.anchor is not None
        if period.anchor is not None:
            log.backup_anchor[i0:i0 + m] = period.anchor

    def run_period(self, k: int, x: tuple, nominal_before: np.ndarray,
                   wall0: float) -> tuple[tuple, np.ndarray]:
        """Sense → solve → nominal arc → ticks → log for period ``k``.

        Returns (state at the next sample, nominal x̂ at its left limit there).
        """
        i0, m = k * self.clock.ticks, self.clock.ticks
        xk = np.asarray(x)
        c0 = time.perf_counter()
        known = self.sense(xk)
        v_hat, flagged, replaced = self.solve(k, float(self.clock.t[i0]), xk, known)
        anchor = self.backup_anchor(k, xk) if replaced else None
        self.log.recovery[i0:i0 + m] = anchor is None and not self.memory.tracking
        if anchor is None:
            period = _Period(v_hat, flagged, replaced, nominal_arc(xk, v_hat, self.clock.tau))
        else:  # phase 3: no nominal is followed while the backup law runs
            period = _Period(v_hat, flagged, replaced, np.full((m + 1, 4), np.nan), tuple(map(float, anchor)))
        control_s = time.perf_counter() - c0
        self.log_period(k, xk, period, nominal_before)
        x, law_s = self.run_ticks(k, x, period)
        self.log.step_ms[i0] = 1e3 * (control_s + law_s)
        self.v_last = np.array(self.log.v_hat[i0 + m - 1], dtype=float)  # v̂, or the backup's command
        self.log.wall[i0:i0 + m] = time.perf_counter() - wall0
        return x, period.arc[m]

    def omega_log(self) -> np.ndarray:
        """ω = ẋ − f(x) v (m/s) at the start of every tick (NaN where the input is NaN)."""
        return self.plant.omega_series(self.clock.t, self.log.states, self.log.inputs, self.log.sway_command)


def run_closed_loop(scenario: Scenario, tightening: Tightening | None = None, *, tube: bool = True,
                    progress: bool = True, label: str | None = None, solver_factory: SolverFactory | None = None,
                    disturbance: OmegaOverride | None = None, plant_substeps: int = 2,
                    remember_obstacles: bool = True, observer: TickObserver | None = None) -> SimulationResult:
    """Run the closed loop on ``scenario`` for ``scenario.duration`` seconds.

    The ancillary law is ``scenario.controller.law``, the FHOCP the scenario's backend
    in ``scenario.controller.fhocp_mode``, the plant ``scenario.plant.kind``, σ is
    ``tightening.sigma`` (module doc). The short public API is :func:`tubekit.simulate`.

    Parameters
    ----------
    scenario : Scenario
        What to simulate.
    tightening : Tightening, optional
        Sets of the FHOCP and the gain σ (1/s). Required when ``tube``; the baseline
        defaults to :meth:`Tightening.untightened`.
    tube : bool
        ``False`` runs the baseline: nominal MPC alone, κ = 0.
    progress : bool
        Show a tqdm bar (only on a TTY).
    label : str, optional
        Progress-bar label.
    solver_factory : callable, optional
        ``factory(scenario, tightening)`` returning a :class:`FhocpSolver`; default the
        scenario's backend (:func:`tubekit.fhocp.registry.make_solver`).
    disturbance : callable, optional
        ``disturbance(t) -> omega`` (3,) replacing the scenario's current + sway
        (e.g. a :class:`verify.falsify.strategies.DisturbanceSignal` in property tests);
        on the dynamic plant it replaces the current (the sway is the hull's).
    plant_substeps : int
        RK4 steps per ancillary tick (plant step = 1 / (rate * substeps) s).
    remember_obstacles : bool
        Keep obstacles in the map once detected (see :mod:`tubekit.loop.sensing`).
    observer : callable, optional
        ``observer(state, nominal, p_d)`` (each (4,), (4,), (3,)) at every tick a plan is followed, before its
        command: what an adversary may read (the closed-loop falsifier's greedy attack).

    Returns
    -------
    SimulationResult
    """
    wall0 = time.perf_counter()
    tightening, law_obj, sig = validate_inputs(scenario, tightening, tube, plant_substeps)
    solver = build_solver(scenario, tightening, solver_factory)
    clock = Clock.of(scenario, plant_substeps)
    loop = _ClosedLoop(scenario, tightening, clock, solver, law_obj, sig, make_plant(scenario, disturbance),
                       ObstacleMap(scenario.obstacles, scenario.sensing_range, remember=remember_obstacles))
    loop.observer = observer
    x = tuple(float(c) for c in scenario.initial_state)
    nominal_end = np.asarray(x)
    bar = progress_bar(clock.steps, progress, label or ("tube" if tube else "baseline"))
    with warnings.catch_warnings():
        silence_fallback_warnings()  # fallbacks are counted; one warning each would flood the terminal
        try:
            for k in range(clock.steps):
                x, nominal_end = loop.run_period(k, x, nominal_end, wall0)
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
    loop.log.states[-1] = np.asarray(x)
    loop.log.nominal[-1] = nominal_end
    loop.log.backup_active[-1] = loop.log.backup_active[-2]  # the final state is reached under the last period's law
    loop.log.recovery[-1] = loop.log.recovery[-2]
    loop.log.backup_anchor[-1] = loop.log.backup_anchor[-2]
    loop.log.sway_command[-1] = loop.log.sway_command[-2]
    return _result(loop, tube, wall0, disturbance is not None)


def _result(loop: _ClosedLoop, tube: bool, wall0: float, overridden: bool) -> SimulationResult:
    """Pack the log of a finished run."""
    log, clock = loop.log, loop.clock
    omega = loop.omega_log()
    wall_s = time.perf_counter() - wall0
    log.wall[-1] = wall_s
    step_idx = np.minimum(np.arange(len(clock.t)) // clock.ticks, clock.steps)
    body, thrust = loop.plant.history()
    return SimulationResult(
        scenario=loop.scenario, tube=tube, law=loop.law.name if tube else "none", sigma=loop.sigma,
        tightening=loop.tightening, plant_step_s=clock.plant_step, ticks_per_step=clock.ticks,
        t=clock.t, step=step_idx, states=log.states, desired=loop.desired, nominal=log.nominal, v_hat=log.v_hat,
        kappa=log.kappa, inputs=log.inputs, omega=omega, saturated=log.saturated, fallback=log.fallback,
        replaced=log.replaced, n_detected=log.n_detected, solve_ms=log.solve_ms, step_ms=log.step_ms,
        wall=log.wall, statuses=log.statuses, iterations=log.iterations, max_violation=log.max_violation,
        kappa_failures=log.kappa_failures, wall_s=wall_s, rejected=log.rejected, plan_age=log.plan_age,
        candidate=log.candidate, recovery=log.recovery,
        plan_slack=log.plan_slack, backup_active=log.backup_active, backup_anchor=log.backup_anchor,
        sway_command=log.sway_command,
        omega_overridden=overridden, body=body, current=loop.plant.current_series(clock.t),
        thrust=thrust, omega_peak=loop.plant.omega_peak(), current_peak=loop.plant.current_peak())
