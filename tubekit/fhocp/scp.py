"""The FHOCP of Section V (eqs. mpc_cost_function - terminal_set_F) by sequential convex programming.

The nonlinear program is :class:`tubekit.fhocp.nlp.FhocpNlp` (exact
zero-order-hold discretisation, diagonal Q/R/P, exact-penalty slacks). Each
SCP iteration solves one convex subproblem
(:class:`tubekit.fhocp.convex.ConvexSubproblem`: built **once** in cvxpy with
Parameters (DPP) and re-solved by data updates through
:class:`tubekit.fhocp.fastpath.CompiledConeProgram` and its QP backend, Clarabel unless
``ScpOptions.qp_solver`` names another (:mod:`tubekit.fhocp.qp`)).

Modes: ``"realtime"`` does one convex solve per control step from the shifted
previous plan (real-time iteration); ``"converged"`` iterates with a
ratio-test trust region on the exact merit (cost + penalties) until the model
predicts a relative decrease below ``tolerance`` or ``max_iterations``; an
accurately predicted step is stretched by a merit line search (the convex
model omits the concave constraints' curvature and would otherwise slide
along an obstacle in many short steps). A cold start (no previous plan)
always runs the converged loop.

When no subproblem can be solved the result is the fallback: the shifted
previous plan with a searched tail (:meth:`FHOCP.shifted_candidate`), flagged,
with a :class:`tubekit.fhocp.result.FallbackWarning`.

Every returned plan is the rollout of the returned inputs through the exact
discrete model, so ``states`` and ``inputs`` are consistent; its nonlinear
constraint violations are measured, not assumed.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Sequence

import cvxpy as cp
import numpy as np

from tubekit.checks import horizon_reach, workspace_fits, workspace_rule
from tubekit.exceptions import ConfigError
from tubekit.scenario import FhocpMode, Obstacle, Scenario
from tubekit.tightening import Tightening
from tubekit.validation import as_vector, choice, finite
from tubekit.fhocp.convex import REALTIME_CLARABEL_SETTINGS, ConvexSubproblem
from tubekit.fhocp.fastpath import CompiledConeProgram
from tubekit.fhocp.nlp import FhocpNlp, NlpEvaluation, rollout, select_obstacles
from tubekit.fhocp.options import ScpOptions
from tubekit.fhocp.qp.registry import DEFAULT_QP_BACKEND, get_qp_backend
from tubekit.fhocp.result import FallbackWarning, FhocpResult, Status, shift_steps, shifted_plan
from tubekit.fhocp.rows import rate_project

__all__ = ["FHOCP", "MODES", "TAIL_GRID", "obstacle_slots", "search_tail"]

MODES: tuple[str, ...] = FhocpMode.values()
#: grid points per input component [u, w, r] of the fallback's tail search over V-bar [v_min, v_max]
TAIL_GRID: tuple[int, int, int] = (7, 5, 7)


def obstacle_slots(scenario: Scenario) -> int:
    """Upper bound on how many of the scenario's obstacles can be within sensing range at once (>= 1).

    Two obstacles can both be detected only if their sensing balls B(c, r + R-bar)
    intersect; the bound is the largest number of obstacles whose balls meet one
    obstacle's ball (itself included).
    """
    obs = scenario.obstacles
    if not obs:
        return 1
    c = np.array([o.center for o in obs])
    r = np.array([o.radius for o in obs]) + scenario.sensing_range
    meet = np.linalg.norm(c[:, None] - c[None], axis=-1) <= r[:, None] + r[None]
    return int(max(1, meet.sum(axis=1).max()))


def _grid(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The :data:`TAIL_GRID` points of the box [``low``, ``high``] (3,) each, shape (K, 3)."""
    return np.stack(np.meshgrid(*[np.linspace(a, b, k) for a, b, k in zip(low, high, TAIL_GRID)],
                                indexing="ij"), axis=-1).reshape(-1, 3)


def _rate_fit(nlp: FhocpNlp, v: np.ndarray, v_last: np.ndarray | None) -> np.ndarray:
    """``v`` projected on the rate rows (:func:`rate_project`; unchanged without a rate limit)."""
    if nlp.rate_jump is None:
        return v
    return rate_project(v, nlp.rate_jump, nlp.v_max, v_last, nlp.terminal_rest, v_min=nlp.v_min,
                        target=nlp.terminal_command)


def _tail_candidates(nlp: FhocpNlp, grid: np.ndarray, prev: np.ndarray | None) -> np.ndarray:
    """The inputs the tail search tries after ``prev``: the grid over the box without a rate limit, else the
    grid of steps +- J about ``prev`` (about the box point nearest 0 without one) clipped to the box."""
    if nlp.rate_jump is None:
        return grid
    centre = nlp.clip(np.zeros(3)) if prev is None else prev
    return nlp.clip(centre + grid)


def search_tail(nlp: FhocpNlp, s0: np.ndarray, v: np.ndarray, kept: int, ref: np.ndarray,
                obs: np.ndarray, v_last: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, NlpEvaluation]:
    """Keep ``v[:kept]`` and choose each later input on a grid over V-bar [v_min, v_max], one step at a time.

    Each appended input is the grid point (:data:`TAIL_GRID`) whose plan violates the
    state constraints least (terminal set excluded), ties broken by the merit. With a rate
    limit the grid spans the previous node +- J instead (clipped to the box) and the plan is projected on
    the rate rows (:func:`tubekit.fhocp.rows.rate_project`; the rows are not part of the key).

    Returns
    -------
    states (N+1, 4), inputs (N, 3), their :class:`NlpEvaluation`
    """
    v = _rate_fit(nlp, nlp.clip(v), v_last)
    grid = _grid(nlp.v_min, nlp.v_max) if nlp.rate_jump is None else _grid(-nlp.rate_jump, nlp.rate_jump)
    for j in range(kept, nlp.n):
        best_key, best_u = None, v[j]
        cands = _tail_candidates(nlp, grid, v[j - 1] if j else v_last)
        for cand in cands:
            v[j:] = cand
            ev = nlp.evaluate(rollout(s0, v, nlp.dt), v, ref, obs, v_last)
            viol = max(val for key, val in ev.violations.items() if key not in ("terminal", "rate"))
            key = (round(viol, 9), ev.merit)
            if best_key is None or key < best_key:
                best_key, best_u = key, cand.copy()
        v[j:] = best_u
    v = _rate_fit(nlp, v, v_last)
    s = rollout(s0, v, nlp.dt)
    return s, v, nlp.evaluate(s, v, ref, obs, v_last)


@dataclass
class _Iterate:
    """The state of one :meth:`FHOCP.solve`: current plan, trust radius and bookkeeping."""

    v: np.ndarray
    s: np.ndarray
    ev: NlpEvaluation | None
    radius: float
    anchor: np.ndarray | None = None   # v_last, else the warm start's first input (rate penalty)
    first_row: bool = False            # v_last given: rate row (b) imposed
    setup_s: float = 0.0
    solver_s: float = 0.0
    iterations: int = 0
    accepted: int = 0
    status: Status = Status.OPTIMAL
    failure: str = ""
    converged: bool = False


class FHOCP:
    """Sequential convex programming solver of the tube-MPC FHOCP.

    Parameters
    ----------
    scenario : Scenario
        Trajectory, weights (Q, R, P diagonals), horizon, dt, terminal level,
        vehicle radius, sensing range, workspace.
    tightening : Tightening
        Tightened sets (V-bar, e_d_min, e_o_max, e_z_max, e_d_max, obstacle margin).
    mode : FhocpMode or {"realtime", "converged"}, optional
        One convex solve per warm-started step, or SCP to convergence; default
        ``scenario.controller.fhocp_mode``.
    options : ScpOptions, optional
        Solver options (:class:`tubekit.fhocp.options.ScpOptions`); default ``ScpOptions()``.
        Its ``terminal`` defaults to ``scenario.controller.terminal_mode``, its
        ``max_obstacles`` to :func:`obstacle_slots` of the scenario.

    Attributes
    ----------
    subproblem : ConvexSubproblem
        The convex subproblem (its ``problem``, ``compiled``, parameters).
    nlp : FhocpNlp
        The nonlinear program being solved.
    build_time_s : float
        Construction time: cvxpy build + compilation (s).
    """

    def __init__(self, scenario: Scenario, tightening: Tightening, mode: FhocpMode | str | None = None, *,
                 options: ScpOptions | None = None) -> None:
        t0 = time.perf_counter()
        if not isinstance(scenario, Scenario):
            raise ConfigError("scenario", "a tubekit.Scenario", type(scenario).__name__)
        opts = ScpOptions() if options is None else options
        if not isinstance(opts, ScpOptions):
            raise ConfigError("options", "a tubekit.fhocp.ScpOptions", type(opts).__name__)
        self.mode = choice("mode", FhocpMode, scenario.controller.fhocp_mode if mode is None else mode)
        terminal = scenario.controller.terminal_mode if opts.terminal is None else opts.terminal
        self.options = opts
        self.max_obstacles = obstacle_slots(scenario) if opts.max_obstacles is None else opts.max_obstacles
        self.max_iterations = opts.max_iterations
        self.cold_start_iterations = opts.cold_start_iterations
        self.scenario = scenario
        self.tightening = tightening
        self.nlp = FhocpNlp.from_scenario(scenario, tightening, terminal=terminal, penalty=opts.penalty,
                                          terminal_penalty=opts.terminal_penalty, rate_penalty=opts.rate_penalty)
        self._check_workspace()
        self.tolerance = opts.tolerance
        self.trust_radius = opts.trust_radius
        self.extrapolate = opts.extrapolate
        self._plan_t: float | None = None
        self._plan_inputs: np.ndarray | None = None
        self._dropped_warned = False
        self.fast_path = opts.fast_path
        s0 = np.asarray(scenario.initial_state, dtype=float)
        self.subproblem = ConvexSubproblem(self.nlp, self.max_obstacles, s0,
                                           self.nlp.reference(scenario.trajectory, 0.0), self.trust_radius,
                                           fast_path=self.fast_path, clarabel_settings=self._clarabel_settings(opts),
                                           qp_backend=opts.qp_solver, backend_settings=self._backend_settings(opts))
        self.build_time_s = time.perf_counter() - t0

    def _clarabel_settings(self, opts: ScpOptions) -> dict | None:
        """Clarabel's overrides: :data:`~tubekit.fhocp.convex.REALTIME_CLARABEL_SETTINGS` in the real-time mode,
        then the user's (``opts.clarabel_settings``)."""
        if self.mode is not FhocpMode.REALTIME:
            return opts.clarabel_overrides()
        return {**REALTIME_CLARABEL_SETTINGS, **(opts.clarabel_overrides() or {})}

    def _backend_settings(self, opts: ScpOptions) -> dict[str, dict] | None:
        """The chosen QP backend's ``realtime_settings`` in the real-time mode (Clarabel's go through
        :meth:`_clarabel_settings`); None in the converged mode or when it has none."""
        if self.mode is not FhocpMode.REALTIME or opts.qp_solver == DEFAULT_QP_BACKEND:
            return None
        settings = get_qp_backend(opts.qp_solver).realtime_settings
        return {opts.qp_solver: dict(settings)} if settings else None

    def _check_workspace(self) -> None:
        """The subproblem keeps one wall row per axis: the workspace must be wide enough for that."""
        nlp = self.nlp
        if nlp.workspace is None:
            return
        reach = horizon_reach(float(nlp.v_max[0]), nlp.dt, nlp.n)  # farthest horizontal travel (m)
        if not workspace_fits(nlp.workspace, nlp.clearance, reach):
            raise ConfigError("scenario.workspace", workspace_rule(nlp.clearance, reach, "vehicle_radius + "
                              "obstacle_margin + u_max T"), self.scenario.workspace,
                              "the FHOCP keeps one wall row per axis (the nearer wall)")

    # ------------------------------------------------------- the subproblem
    @property
    def problem(self) -> cp.Problem:
        """The parametrised convex subproblem (DPP), built once."""
        return self.subproblem.problem

    @property
    def compiled(self) -> CompiledConeProgram | None:
        """The fast path (None when ``fast_path=False``)."""
        return self.subproblem.compiled

    @property
    def parameters(self) -> dict[str, cp.Parameter]:
        """The cvxpy Parameters of the subproblem by name."""
        return self.subproblem.parameters

    @property
    def variables(self) -> dict[str, cp.Variable]:
        """The main cvxpy Variables (x, y, z, psi, u, w, r, e_o) by name."""
        return self.subproblem.variables

    def push_parameters(self) -> None:
        """Copy the current parameter vector into the cvxpy Parameters (for ``problem.solve``)."""
        self.subproblem.push_parameters()

    def _solve_subproblem(self) -> tuple[Status, np.ndarray | None, float, float]:
        """Solve the convex subproblem: (status, inputs (N, 3) or None, model objective, solver time (s))."""
        return self.subproblem.solve()

    # ----------------------------------------------------------- warm start
    def reset(self) -> None:
        """Forget the warm start (the next solve is a cold start)."""
        self._plan_t = None
        self._plan_inputs = None

    @property
    def plan_inputs(self) -> np.ndarray | None:
        """The stored plan's inputs (N, 3) or None after :meth:`reset`."""
        return None if self._plan_inputs is None else self._plan_inputs.copy()

    def warm_start_inputs(self, t: float) -> tuple[np.ndarray, bool]:
        """The previous plan shifted to time ``t`` (last input repeated), or zeros and False."""
        return shifted_plan(self._plan_inputs, self._plan_t, t, self.nlp.dt, self.nlp.n)

    def _kept_steps(self, t: float) -> int:
        """Inputs of the stored plan still covering [t, t + T] (0 without a usable plan)."""
        shift = None if self._plan_inputs is None else shift_steps(self._plan_t, t, self.nlp.dt, self.nlp.n)
        return 0 if shift is None else self.nlp.n - shift

    def select_obstacles(self, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray) -> np.ndarray:
        """The obstacles this solver puts in the problem at ``state`` (K, 4), K <= max_obstacles."""
        kept, dropped = select_obstacles(state, obstacles, self.scenario.sensing_range, self.max_obstacles)
        if dropped and not self._dropped_warned:
            warnings.warn(f"{dropped} obstacle(s) within sensing range ignored: only the nearest "
                          f"max_obstacles={self.max_obstacles} fit the compiled problem", RuntimeWarning,
                          stacklevel=3)
            self._dropped_warned = True
        return kept

    # ---------------------------------------------------------------- solve
    def solve(self, t: float, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray = (), *,
              v_last: np.ndarray | None = None) -> FhocpResult:
        """Solve the FHOCP at time ``t`` (s) from the measured ``state`` (4,).

        Parameters
        ----------
        t : float
            Current time t_k (s).
        state : array (4,)
            Measured state [x, y, z, psi]; the nominal is reset to it (e_hat(t_k) = e(t_k)).
        obstacles : sequence of Obstacle
            Currently detected obstacles (filtered again by sensing range).
        v_last : array (3,), optional
            The command applied in the last tick before this plan starts (m/s, m/s, rad/s): the
            rate row (b) with a rate limit, and the rate penalty's v_0 term (without it the warm
            start's first input stands in for the penalty and row (b) is not imposed).

        Returns
        -------
        FhocpResult
            Never contains NaN; ``fallback`` is set (with a :class:`FallbackWarning`)
            when no subproblem could be solved.
        """
        t_start = time.perf_counter()
        t = finite("t", t)
        s0 = as_vector("state", state, 4)
        last = None if v_last is None else self.nlp.clip(as_vector("v_last", v_last, 3))
        obs = self.select_obstacles(s0, obstacles)
        nlp = self.nlp
        ref = nlp.reference(self.scenario.trajectory, t)
        if nlp.terminal_rows is not None:
            self.subproblem.write_target_velocity(self.scenario.trajectory.velocity(t + nlp.n * nlp.dt))
        guess, warm = self.warm_start_inputs(t)
        guess = _rate_fit(nlp, nlp.clip(guess), last)
        realtime = warm and self.mode is FhocpMode.REALTIME
        cap = 1 if realtime else (self.max_iterations if warm else self.cold_start_iterations)
        s = rollout(s0, guess, nlp.dt)
        anchor = guess[0].copy() if last is None else last
        it = _Iterate(v=guess, s=s, ev=None if realtime else nlp.evaluate(s, guess, ref, obs, anchor, last is not None),
                      radius=self.trust_radius, anchor=anchor, first_row=last is not None)
        for _ in range(cap):
            if self._iteration(it, s0, ref, obs, realtime):
                break
        if it.failure and it.accepted == 0:
            return self._fallback(t, s0, guess, ref, obs, it, t_start, last)
        return self._result(t, ref, obs, it, realtime, t_start)

    def _iteration(self, it: _Iterate, s0: np.ndarray, ref: np.ndarray, obs: np.ndarray, realtime: bool) -> bool:
        """Linearise at the current plan, solve one subproblem, take or reject its step; True to stop."""
        nlp = self.nlp
        ts = time.perf_counter()
        self.subproblem.linearise(s0, it.s, it.v, ref, obs, it.radius)
        self.subproblem.write_last_command(it.anchor, it.first_row)
        it.setup_s += time.perf_counter() - ts
        status, v_new, model_obj, stime = self._solve_subproblem()
        it.iterations += 1
        it.solver_s += stime
        if v_new is None or not np.all(np.isfinite(v_new)):
            it.failure = f"convex subproblem {it.iterations} returned status '{status}'"
            return True
        v_new = _rate_fit(nlp, nlp.clip(v_new), it.anchor if it.first_row else None)
        s_new = rollout(s0, v_new, nlp.dt)
        if realtime:
            it.v, it.s, it.accepted, it.status = v_new, s_new, 1, status
            return True
        return self._ratio_test(it, s0, v_new, s_new, model_obj, status, ref, obs)

    def _ratio_test(self, it: _Iterate, s0: np.ndarray, v_new: np.ndarray, s_new: np.ndarray, model_obj: float,
                    status: Status, ref: np.ndarray, obs: np.ndarray) -> bool:
        """Trust-region step on the exact merit: accept/extrapolate or shrink; True when converged."""
        nlp, tol = self.nlp, self.tolerance
        ev_new = nlp.evaluate(s_new, v_new, ref, obs, it.anchor, it.first_row)
        pred = it.ev.merit - model_obj
        actual = it.ev.merit - ev_new.merit
        if pred <= tol * max(1.0, abs(it.ev.merit)):
            if actual > 0:
                it.v, it.s, it.ev = v_new, s_new, ev_new
                it.accepted += 1
            it.converged = True
            return True
        step = float(np.max(np.abs(v_new - it.v) / nlp.v_max))
        if actual < 0.1 * pred:  # poor model: shrink the trust region
            it.radius = 0.5 * min(it.radius, max(step, tol))
            it.converged = it.radius <= tol
            return it.converged
        if self.extrapolate and actual >= 0.9 * pred:
            v_new, s_new, ev_new = self._extrapolate(s0, it, v_new, ev_new, ref, obs)
            actual = it.ev.merit - ev_new.merit
        it.v, it.s, it.ev = v_new, s_new, ev_new
        it.accepted += 1
        if status != Status.OPTIMAL:
            it.status = status
        if actual >= 0.75 * pred and step >= 0.5 * it.radius:
            it.radius = min(2.0 * it.radius, 2.0)
        # an accepted step that changed the merit (or the inputs) by less than the
        # tolerance: the next model could not predict a larger decrease
        it.converged = step <= tol or actual <= tol * max(1.0, abs(it.ev.merit))
        return it.converged

    def _extrapolate(self, s0: np.ndarray, it: _Iterate, v_new: np.ndarray, ev_new: NlpEvaluation,
                     ref: np.ndarray, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray, NlpEvaluation]:
        """Line search beyond an accurately modelled step: v + 2^j (v_new - v) while the merit falls.

        The convex model omits the negative curvature of the concave constraints (ball
        exclusion, e_d >= e_d_min), so where such a constraint is active the model's steps
        are too short (the convex-concave procedure's slow slide along the boundary); a
        step whose prediction was accurate is therefore stretched while the exact merit
        keeps decreasing. Costs one rollout and one evaluation per trial. With a rate limit each
        trial is projected on the rate rows.
        """
        nlp, v = self.nlp, it.v
        best = (v_new, None, ev_new)
        d = v_new - v
        for j in range(1, 6):
            cand = _rate_fit(nlp, nlp.clip(v + (2.0 ** j) * d), it.anchor if it.first_row else None)
            s_c = rollout(s0, cand, nlp.dt)
            ev_c = nlp.evaluate(s_c, cand, ref, obs, it.anchor, it.first_row)
            if not ev_c.merit < best[2].merit:
                break
            best = (cand, s_c, ev_c)
        v_b, s_b, ev_b = best
        if s_b is None:
            s_b = rollout(s0, v_b, nlp.dt)
        return v_b, s_b, ev_b

    def _result(self, t: float, ref: np.ndarray, obs: np.ndarray, it: _Iterate, realtime: bool,
                t_start: float) -> FhocpResult:
        """Store the plan of a successful solve and report it."""
        status = it.status
        if it.failure:
            status = Status.OPTIMAL_INACCURATE
        elif not realtime and not it.converged:
            status = Status.ITERATION_LIMIT
        ev = it.ev if it.ev is not None else self.nlp.evaluate(it.s, it.v, ref, obs, it.anchor, it.first_row)
        self._plan_t, self._plan_inputs = t, it.v.copy()
        return FhocpResult(status=status, states=it.s, inputs=it.v, cost=ev.cost, iterations=it.iterations,
                           solve_time_s=time.perf_counter() - t_start, setup_time_s=it.setup_s,
                           max_violation=ev.max_violation, fallback=False, merit=ev.merit,
                           violations=ev.violations, solver_time_s=it.solver_s, t=t)

    # ------------------------------------------------------------- fallback
    def shifted_candidate(self, t: float, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray = (), *,
                          v_last: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, NlpEvaluation]:
        """Tube MPC's candidate at ``t``: the stored plan shifted, its new tail input searched.

        The inputs the previous plan still covers are kept; each appended input is
        the point of a grid over V-bar [v_min, v_max] (7 x 5 x 7) whose plan violates the state
        constraints least (terminal set excluded), ties broken by the merit. Without
        a stored plan the search starts from zero inputs.

        Parameters
        ----------
        t : float
            Time of the candidate (s), normally the previous solve's t + dt.
        state : array (4,)
            State the candidate starts from (m, rad).
        obstacles : sequence of Obstacle
            Obstacles to check against (filtered like :meth:`solve`).
        v_last : array (3,), optional
            The command before the candidate (rate rows, as :meth:`solve`).

        Returns
        -------
        states (N+1, 4), inputs (N, 3), evaluation (:class:`tubekit.fhocp.nlp.NlpEvaluation`)
        """
        s0 = as_vector("state", state, 4)
        obs = self.select_obstacles(s0, obstacles)
        ref = self.nlp.reference(self.scenario.trajectory, finite("t", t))
        guess, _ = self.warm_start_inputs(t)
        last = None if v_last is None else as_vector("v_last", v_last, 3)
        return search_tail(self.nlp, s0, np.where(np.isfinite(guess), guess, 0.0), self._kept_steps(t), ref, obs,
                           last)

    def _fallback(self, t: float, s0: np.ndarray, guess: np.ndarray, ref: np.ndarray, obs: np.ndarray,
                  it: _Iterate, t_start: float, v_last: np.ndarray | None) -> FhocpResult:
        """The shifted previous plan with a searched tail (zeros without one), rolled out from ``s0``, flagged."""
        s, v, ev = search_tail(self.nlp, s0, np.where(np.isfinite(guess), guess, 0.0), self._kept_steps(t),
                               ref, obs, v_last)
        msg = f"FHOCP at t={t:.3f} s failed ({it.failure}); returning the shifted previous plan"
        warnings.warn(msg, FallbackWarning, stacklevel=3)
        self._plan_t, self._plan_inputs = t, v.copy()
        return FhocpResult(status=Status.FALLBACK, states=s, inputs=v, cost=ev.cost, iterations=it.iterations,
                           solve_time_s=time.perf_counter() - t_start, setup_time_s=it.setup_s,
                           max_violation=ev.max_violation, fallback=True, merit=ev.merit,
                           violations=ev.violations, solver_time_s=it.solver_s, t=t, message=msg)
