"""Peer solver: the same discretised FHOCP NLP solved by CasADi + IPOPT.

:class:`IpoptFHOCP` transcribes :class:`tubekit.fhocp.nlp.FhocpNlp` exactly
(multiple shooting with the exact zero-order-hold step, the same cost, the
same exact-penalty slacks, the *nonlinear* constraints e_d >= e_d_min,
||p - c_j|| >= r_j + r_bar + margin, |e_o| <= e_o_max, e_d <= e_d_max,
|e_z| <= e_z_max, both walls of the workspace, the same terminal handling)
and is used to check the SCP's optimum and as the timing baseline. It honours
the backends' contract of :mod:`tubekit.fhocp.result`: a :class:`FhocpResult`
whose status is a :class:`Status`, warm start by :func:`shifted_plan`.

CasADi is an optional dependency (``pip install "tubekit[bench]"``); it is
imported lazily and its absence raises :class:`NotAvailableError`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from tubekit.exceptions import ConfigError, NotAvailableError
from tubekit.scenario import Obstacle, Scenario
from tubekit.tightening import Tightening
from tubekit.validation import as_vector, finite
from tubekit.fhocp.nlp import FhocpNlp, rollout, select_obstacles
from tubekit.model.kinematics import SINC_SERIES_THRESHOLD
from tubekit.fhocp.options import DEFAULT_RATE_PENALTY
from tubekit.fhocp.result import FhocpResult, Status, shifted_plan, status_from
from tubekit.fhocp.rows import rate_project

__all__ = ["IpoptFHOCP", "import_casadi", "IPOPT_STATUS", "SQP_OPTIONS", "NLP_SOLVERS"]

#: The CasADi ``nlpsol`` plugins this backend can use.
NLP_SOLVERS = ("ipopt", "sqpmethod")
#: The ``sqpmethod`` peer: exact Hessian, eigenvalue clipping, ``qrqp`` as the QP solver, quiet.
SQP_OPTIONS: dict[str, Any] = {
    "qpsol": "qrqp", "convexify_strategy": "eigen-clip", "max_iter": 100, "tol_pr": 1e-8, "tol_du": 1e-8,
    "print_header": False, "print_iteration": False, "print_status": False,
    "qpsol_options": {"print_iter": False, "print_header": False, "print_info": False, "error_on_fail": False},
}

#: IPOPT's return status (CasADi ``stats()["return_status"]``) -> :class:`Status`; any other is SOLVER_ERROR
IPOPT_STATUS: dict[str, Status] = {
    "Solve_Succeeded": Status.OPTIMAL,
    "Solved_To_Acceptable_Level": Status.OPTIMAL_INACCURATE,
    "Feasible_Point_Found": Status.SOLVER_ERROR,
    "Infeasible_Problem_Detected": Status.INFEASIBLE,
    "Diverging_Iterates": Status.UNBOUNDED,
    "Maximum_Iterations_Exceeded": Status.USER_LIMIT,
    "Maximum_CpuTime_Exceeded": Status.USER_LIMIT,
    "Maximum_WallTime_Exceeded": Status.USER_LIMIT,
    "User_Requested_Stop": Status.USER_LIMIT,
    "Search_Direction_Becomes_Too_Small": Status.SOLVER_ERROR,
    "Restoration_Failed": Status.SOLVER_ERROR,
    "Error_In_Step_Computation": Status.SOLVER_ERROR,
    "Not_Enough_Degrees_Of_Freedom": Status.SOLVER_ERROR,
    "Invalid_Problem_Definition": Status.SOLVER_ERROR,
    "Invalid_Option": Status.SOLVER_ERROR,
    "Invalid_Number_Detected": Status.SOLVER_ERROR,
    "Unrecoverable_Exception": Status.SOLVER_ERROR,
    "NonIpopt_Exception_Thrown": Status.SOLVER_ERROR,
    "Insufficient_Memory": Status.SOLVER_ERROR,
    "Internal_Error": Status.SOLVER_ERROR,
}
_B_FLOOR = 1e-3  # m: smallest reach of the smooth sensed-region row (backup terminal rows)
_TINY = 1e-12  # inside square roots: keeps them smooth at 0 (changes values by < 1e-11)


def import_casadi() -> Any:
    """Import CasADi or raise :class:`NotAvailableError` with the install hint."""
    try:
        import casadi  # noqa: PLC0415
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise NotAvailableError(
            "the IPOPT peer needs CasADi, an optional dependency: pip install -e \".[bench]\" "
            "(or pip install casadi)") from exc
    return casadi


def _sinc(ca: Any, a: Any) -> Any:
    """sin(a)/a, smooth at 0 (Taylor series below the same threshold as the numpy version)."""
    a2 = a * a
    series = 1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362880.0
                         + a2 * (-1.0 / 39916800.0)))))
    small = ca.fabs(a) < SINC_SERIES_THRESHOLD
    safe = ca.if_else(small, 1.0, a)
    return ca.if_else(small, series, ca.sin(safe) / safe)


def _errors(ca: Any, ref: Any, s: Any, k: int) -> tuple[Any, Any, Any]:
    """Symbolic (e_d, e_z, e_o) of state ``s`` w.r.t. column ``k`` of ``ref`` (e_d smoothed at 0)."""
    ex, ey = s[0] - ref[0, k], s[1] - ref[1, k]
    ed = ca.sqrt(ex * ex + ey * ey + _TINY)
    eo = (ex * ca.sin(s[3]) - ey * ca.cos(s[3])) / ed
    return ed, s[2] - ref[2, k], eo


@dataclass
class _Rows:
    """Constraints g(x, p) of the transcription with their bounds lbg <= g <= ubg."""

    g: list = field(default_factory=list)
    lbg: list = field(default_factory=list)
    ubg: list = field(default_factory=list)

    def equal_zero(self, row: Any, size: int) -> None:
        """Append ``row`` (``size`` entries) == 0."""
        self.g.append(row)
        self.lbg += [0.0] * size
        self.ubg += [0.0] * size

    def nonpositive(self, rows: list) -> None:
        """Append each scalar of ``rows`` <= 0."""
        self.g += rows
        self.lbg += [-math.inf] * len(rows)
        self.ubg += [0.0] * len(rows)


class IpoptFHOCP:
    """CasADi + IPOPT on the NLP of :class:`tubekit.fhocp.nlp.FhocpNlp`.

    Parameters
    ----------
    scenario, tightening :
        As for :class:`tubekit.fhocp.scp.FHOCP`.
    max_obstacles : int
        Obstacle slots (inactive slots are switched off by a 0/1 parameter).
    terminal : {"soft", "hard", "off"}
        Terminal-set handling (as the SCP).
    penalty, terminal_penalty : float
        Exact-penalty weights (as the SCP).
    warm_start_duals : bool
        Also pass the previous multipliers and IPOPT's warm-start options.
    ipopt_options : dict, optional
        Extra ``ipopt.*`` options (keys without the prefix).
    rate_penalty : float
        lambda (s) of the rate penalty, as :class:`~tubekit.fhocp.options.ScpOptions` (same default).
    nlp_solver : {"ipopt", "sqpmethod"}
        CasADi plugin. ``"sqpmethod"`` uses :data:`SQP_OPTIONS` updated by ``ipopt_options`` (keys as
        CasADi's sqpmethod takes them); its warm start passes the previous multipliers. Its QP
        solver (qrqp, eigen-clip) fails on the node-to-node coupling of the rate penalty: use it
        with ``rate_penalty=0`` (a failed QP is a fallback, never an exception).
    """

    def __init__(self, scenario: Scenario, tightening: Tightening, *, max_obstacles: int = 4,
                 terminal: str = "soft", penalty: float = 1e3, terminal_penalty: float | None = None,
                 warm_start_duals: bool = False, ipopt_options: dict | None = None,
                 nlp_solver: str = "ipopt", rate_penalty: float = DEFAULT_RATE_PENALTY) -> None:
        ca = import_casadi()
        if nlp_solver not in NLP_SOLVERS:
            raise ConfigError("nlp_solver", f"one of {NLP_SOLVERS}", nlp_solver)
        self.nlp_solver = nlp_solver
        t0 = time.perf_counter()
        if not isinstance(max_obstacles, int) or isinstance(max_obstacles, bool) or max_obstacles < 0:
            raise ConfigError("max_obstacles", "an integer >= 0", max_obstacles)
        self.scenario = scenario
        self.nlp = FhocpNlp.from_scenario(scenario, tightening, terminal=terminal, penalty=penalty,
                                          terminal_penalty=terminal_penalty, rate_penalty=rate_penalty)
        self.max_obstacles = max_obstacles
        self.warm_start_duals = bool(warm_start_duals)
        self._build(ca, ipopt_options or {})
        self._plan_t: float | None = None
        self._plan_inputs: np.ndarray | None = None
        self._lam_x: np.ndarray | None = None
        self._lam_g: np.ndarray | None = None
        self._last = np.concatenate([np.zeros(3), 2.0 * self.nlp.v_max])  # v_last and row (b)'s bound
        self._anchor, self._first_row = np.zeros(3), False
        self.build_time_s = time.perf_counter() - t0

    # ------------------------------------------------------------ building
    def _build(self, ca: Any, extra: dict) -> None:
        """Transcribe the NLP (multiple shooting), create the IPOPT solver and the variable bounds."""
        nlp = self.nlp
        N, M = nlp.n, self.max_obstacles
        n_t = 1 if nlp.terminal == "soft" else 0
        n_b = 1 if nlp.backup_terminal is not None else 0
        sym = {"V": ca.SX.sym("v", 3, N), "S": ca.SX.sym("s", 4, N),       # S: s_1..s_N
               "sig": ca.SX.sym("sig", 4, N),                              # e_d_min, obstacle, e_o, box
               "sig_t": ca.SX.sym("sig_t", n_t), "sig_b": ca.SX.sym("sig_b", n_b), "s0": ca.SX.sym("s0", 4),
               "ref": ca.SX.sym("ref", 3, N + 1), "obs": ca.SX.sym("obs", 5, M),  # cx, cy, cz, radius, active
               "last": ca.SX.sym("last", 6)}  # v_last, bound of rate row (b)
        states = [sym["s0"]] + [sym["S"][:, k] for k in range(N)]
        rows = _Rows()
        cost = self._shooting(ca, sym, states, rows)
        self._path_constraints(ca, sym, states, rows)
        cost = self._terminal(ca, sym, states[N], rows, cost)
        if n_b:
            cost = self._backup_rows(ca, sym, states[N], rows, cost)
        cost = self._rate_rows(ca, sym, rows, cost)
        x = ca.vertcat(ca.vec(sym["V"]), ca.vec(sym["S"]), ca.vec(sym["sig"]), sym["sig_t"], sym["sig_b"])
        p = ca.vertcat(sym["s0"], ca.vec(sym["ref"]), ca.vec(sym["obs"]), sym["last"])
        self._solver = ca.nlpsol(f"fhocp_{self.nlp_solver}", self.nlp_solver,
                                 {"x": x, "p": p, "f": cost, "g": ca.vertcat(*rows.g)}, self._options(extra))
        nx = x.shape[0]
        self._lbx = np.full(nx, -np.inf)
        self._ubx = np.full(nx, np.inf)
        self._lbx[:3 * N] = np.tile(nlp.v_min, N)  # the input box [v_min, v_max]
        self._ubx[:3 * N] = np.tile(nlp.v_max, N)
        self._lbx[7 * N:] = 0.0  # slacks
        self._lbg = np.array(rows.lbg)
        self._ubg = np.array(rows.ubg)
        self._n_t, self._n_b = n_t, n_b

    def _shooting(self, ca: Any, sym: dict, states: list, rows: _Rows) -> Any:
        """Exact-step defects s_{k+1} - F(s_k, v_k) = 0 and the stage cost (left rectangle rule)."""
        nlp, dt, V = self.nlp, self.nlp.dt, sym["V"]
        wq = nlp.q
        cost = 0
        for k in range(nlp.n):
            s, v = states[k], V[:, k]
            a = 0.5 * dt * v[2]
            kk = v[0] * dt * _sinc(ca, a)
            th = s[3] + a
            nxt = ca.vertcat(s[0] + kk * ca.cos(th), s[1] + kk * ca.sin(th), s[2] + dt * v[1], s[3] + dt * v[2])
            rows.equal_zero(states[k + 1] - nxt, 4)
            ed, ez, eo = _errors(ca, sym["ref"], s, k)
            cost += dt * (wq[0] * ed * ed + wq[1] * ez * ez + wq[2] * eo * eo
                          + nlp.r[0] * v[0] ** 2 + nlp.r[1] * v[1] ** 2 + nlp.r[2] * v[2] ** 2)
        return cost

    def _path_constraints(self, ca: Any, sym: dict, states: list, rows: _Rows) -> None:
        """The slackened state constraints at k = 1..N (e_d, e_o, e_z, obstacles, workspace walls)."""
        nlp, sig, obs = self.nlp, sym["sig"], sym["obs"]
        ahead = nlp.lookahead_margins()  # controller.lookahead: the nodes keep a growing share of the footprint
        for k in range(1, nlp.n + 1):
            s = states[k]
            ed, ez, eo = _errors(ca, sym["ref"], s, k)
            se, so, seo, sb = sig[0, k - 1], sig[1, k - 1], sig[2, k - 1], sig[3, k - 1]
            rows.nonpositive([nlp.e_d_min - ed - se, ed - nlp.e_d_max - sb, eo - nlp.e_o_max - seo,
                              -eo - nlp.e_o_max - seo, ez - nlp.e_z_max - sb, -ez - nlp.e_z_max - sb])
            for j in range(self.max_obstacles):
                d = s[:3] - obs[:3, j]
                dist = ca.sqrt(ca.dot(d, d) + _TINY)
                rows.nonpositive([obs[4, j] * (obs[3, j] + nlp.clearance + float(ahead[k - 1]) - dist) - so])
            if nlp.workspace is not None:
                lo = nlp.workspace[0] + nlp.clearance
                hi = nlp.workspace[1] - nlp.clearance
                for i in range(3):
                    rows.nonpositive([lo[i] - s[i] - sb, s[i] - hi[i] - sb])

    def _terminal(self, ca: Any, sym: dict, s_n: Any, rows: _Rows, cost: Any) -> Any:
        """Terminal cost, the exact penalties and the terminal set; returns the full cost."""
        nlp, wp, sig_t = self.nlp, self.nlp.p, sym["sig_t"]
        n_t = sig_t.shape[0]
        ed, ez, eo = _errors(ca, sym["ref"], s_n, nlp.n)
        cost += wp[0] * ed * ed + wp[1] * ez * ez + wp[2] * eo * eo
        cost += nlp.penalty * ca.sum1(ca.vec(sym["sig"]))
        if nlp.terminal != "off":
            tnorm = ca.sqrt(wp[0] * ed * ed + wp[1] * ez * ez + wp[2] * eo * eo + _TINY)
            rows.nonpositive([tnorm - nlp.terminal_level - (sig_t[0] if n_t else 0)])
        if n_t:
            cost += nlp.terminal_penalty * sig_t[0]
        return cost

    def _backup_rows(self, ca: Any, sym: dict, s_n: Any, rows: _Rows, cost: Any) -> Any:
        """The backup's terminal rows at s_N with their shared slack (as :class:`FhocpNlp` states them)."""
        nlp, obs, sig_b, s0 = self.nlp, sym["obs"], sym["sig_b"][0], sym["s0"]
        bt = nlp.backup_terminal
        for j in range(self.max_obstacles):
            d = s_n[:3] - obs[:3, j]
            rows.nonpositive([obs[4, j] * (obs[3, j] + bt.sphere - ca.sqrt(ca.dot(d, d) + _TINY)) - sig_b])
        if nlp.workspace is not None:
            pad = (bt.footprint[0], bt.footprint[0], bt.footprint[1])
            for i in range(3):
                rows.nonpositive([nlp.workspace[0][i] + pad[i] - s_n[i] - sig_b,
                                  s_n[i] - nlp.workspace[1][i] + pad[i] - sig_b])
        # the sensed-region row, smooth: hypot(d + c, |dz| + Z) <= ||s_N - s_0|| + hypot(c, Z) (triangle
        # inequality), so ||s_N - s_0|| <= b = R_bar - r - hypot(c, Z) suffices; written as (||.||^2 - b^2) / 2b,
        # which is ||.|| - b to first order (m), with b floored at 1 mm and the shortfall added
        b = max(bt.sensed_bound - math.hypot(*bt.safe), _B_FLOOR)
        reach2 = (s_n[0] - s0[0]) ** 2 + (s_n[1] - s0[1]) ** 2 + (s_n[2] - s0[2]) ** 2
        shortfall = b - (bt.sensed_bound - math.hypot(*bt.safe))
        rows.nonpositive([(reach2 - b * b) / (2.0 * b) + shortfall - sig_b])
        return cost + nlp.penalty * sig_b

    def _rate_rows(self, ca: Any, sym: dict, rows: _Rows, cost: Any) -> Any:
        """The rate rows and the rate penalty (:mod:`tubekit.fhocp.rows`; the terminal rest about
        ``nlp.terminal_command``); returns the full cost."""
        nlp, V, last = self.nlp, sym["V"], sym["last"]
        N = nlp.n
        if nlp.rate_penalty > 0:
            for c in range(3):
                d0 = V[c, 0] - last[c]
                steps = sum((V[c, k + 1] - V[c, k]) ** 2 for k in range(N - 1))
                cost += nlp.rate_penalty * nlp.r[c] * (d0 * d0 + steps)
        if nlp.rate_jump is None:
            return cost
        for c in range(3):
            jump = float(nlp.rate_jump[c])
            for k in range(N - 1):
                rows.nonpositive([V[c, k + 1] - V[c, k] - jump, V[c, k] - V[c, k + 1] - jump])
            rows.nonpositive([V[c, 0] - last[c] - last[3 + c], last[c] - V[c, 0] - last[3 + c]])
            if nlp.terminal_rest:
                command = float(nlp.terminal_command[c])
                rows.nonpositive([V[c, N - 1] - command - jump, command - V[c, N - 1] - jump])
        return cost

    def _options(self, extra: dict) -> dict:
        """CasADi/IPOPT options: quiet, tol 1e-8, optional dual warm start, then ``extra``."""
        if self.nlp_solver == "sqpmethod":
            return {"print_time": False, **SQP_OPTIONS, **extra}
        opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-8,
                "ipopt.max_iter": 500}
        if self.warm_start_duals:
            opts.update({"ipopt.warm_start_init_point": "yes", "ipopt.warm_start_bound_push": 1e-9,
                         "ipopt.warm_start_mult_bound_push": 1e-9, "ipopt.mu_init": 1e-4})
        opts.update({f"ipopt.{k}": v for k, v in extra.items()})
        return opts

    # -------------------------------------------------------------- public
    def reset(self) -> None:
        """Forget the warm start."""
        self._plan_t = self._plan_inputs = self._lam_x = self._lam_g = None

    def solve(self, t: float, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray = (),
              initial_inputs: np.ndarray | None = None, *, v_last: np.ndarray | None = None) -> FhocpResult:
        """Solve the NLP at ``t`` from ``state``; warm-started from the shifted previous solution.

        Parameters
        ----------
        t : float
            Time (s).
        state : array (4,)
            Initial state.
        obstacles : sequence of Obstacle or array (M, 4)
            Detected obstacles (same selection rule as the SCP).
        initial_inputs : array (N, 3), optional
            Initial guess for the inputs (overrides the warm start).
        v_last : array (3,), optional
            The command before the plan (rate row (b) and the rate penalty, as :meth:`FHOCP.solve`).

        Returns
        -------
        FhocpResult
            ``states`` are the rollout of the returned inputs; ``status`` is
            ``"optimal"`` or ``"optimal_inaccurate"``, or ``"fallback"`` (``fallback``
            True, the guess returned, IPOPT's own status in ``message``).
        """
        t_start = time.perf_counter()
        t = finite("t", t)
        s0 = as_vector("state", state, 4)
        nlp, N = self.nlp, self.nlp.n
        obs, _ = select_obstacles(s0, obstacles, self.scenario.sensing_range, self.max_obstacles)
        ref = nlp.reference(self.scenario.trajectory, t)
        if initial_inputs is None:
            guess = shifted_plan(self._plan_inputs, self._plan_t, t, nlp.dt, N)[0]
        else:
            guess = np.asarray(initial_inputs, dtype=float)
        if guess.shape != (N, 3):
            raise ConfigError("initial_inputs", f"an array of shape ({N}, 3)", guess.shape)
        last = None if v_last is None else nlp.clip(as_vector("v_last", v_last, 3))
        guess = self._fit(nlp.clip(guess), last)
        anchor = guess[0].copy() if last is None else last
        bound = nlp.rate_jump if last is not None and nlp.rate_jump is not None else 2.0 * nlp.v_max
        self._last = np.concatenate([anchor, bound])
        self._anchor, self._first_row = anchor, last is not None
        args = {"x0": self._initial_point(s0, guess, ref, obs), "p": self._parameters(s0, ref, obs),
                "lbx": self._lbx, "ubx": self._ubx, "lbg": self._lbg, "ubg": self._ubg}
        if self.warm_start_duals and self._lam_x is not None and initial_inputs is None:
            args["lam_x0"] = self._lam_x
            args["lam_g0"] = self._lam_g
        ts = time.perf_counter()
        sol = self._solver(**args)
        solver_time = time.perf_counter() - ts
        try:
            stats = self._solver.stats()
        except RuntimeError:  # sqpmethod whose QP failed outright has no readable stats: a failed solve
            stats = {}
        raw = str(stats.get("return_status", "unknown"))
        v = np.asarray(sol["x"]).ravel()[:3 * N].reshape(N, 3)
        status = status_from(IPOPT_STATUS, raw)
        fallback = not status.solved or not np.all(np.isfinite(v))
        if fallback:
            v = guess
        else:
            self._lam_x = np.asarray(sol["lam_x"]).ravel()
            self._lam_g = np.asarray(sol["lam_g"]).ravel()
        v = self._fit(nlp.clip(v), last)
        s = rollout(s0, v, nlp.dt)
        ev = nlp.evaluate(s, v, ref, obs, anchor, last is not None)
        self._plan_t, self._plan_inputs = t, v.copy()
        return FhocpResult(status=Status.FALLBACK if fallback else status, states=s, inputs=v, cost=ev.cost,
                           iterations=int(stats.get("iter_count", 0)),
                           solve_time_s=time.perf_counter() - t_start, setup_time_s=0.0,
                           max_violation=ev.max_violation, fallback=fallback, merit=ev.merit,
                           violations=ev.violations, solver_time_s=solver_time, t=t,
                           message="" if not fallback else f"IPOPT returned {raw}")

    def _fit(self, v: np.ndarray, last: np.ndarray | None) -> np.ndarray:
        """``v`` (N, 3), inside the box, projected on the rate rows (:func:`rate_project`; as is without them)."""
        nlp = self.nlp
        if nlp.rate_jump is None:
            return v
        return rate_project(v, nlp.rate_jump, nlp.v_max, last, nlp.terminal_rest, v_min=nlp.v_min,
                            target=nlp.terminal_command)

    def _initial_point(self, s0: np.ndarray, guess: np.ndarray, ref: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """x0: the guess, its rollout, and the slacks at their optimal values for that plan."""
        nlp = self.nlp
        s_guess = rollout(s0, guess, nlp.dt)
        ev = nlp.evaluate(s_guess, guess, ref, obs, self._anchor, self._first_row)
        ps = ev.per_step
        return np.concatenate([guess.ravel(), s_guess[1:].ravel(),
                               np.stack([ps["e_d_min"], ps["obstacle"], ps["e_o"], ps["box"]], axis=1).ravel(),
                               [ev.violations["terminal"]] * self._n_t,
                               [ev.violations.get("backup_terminal", 0.0)] * self._n_b])

    def _parameters(self, s0: np.ndarray, ref: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """p: the measured state, the reference and the obstacle slots (inactive: far away, switched off)."""
        obs_p = np.zeros((self.max_obstacles, 5))
        obs_p[:, 3] = 1.0
        obs_p[:, :3] = s0[:3] + 1e3
        if len(obs):
            obs_p[:len(obs), :4] = obs
            obs_p[:len(obs), 4] = 1.0
        return np.concatenate([s0, ref.ravel(), obs_p.ravel(), self._last])
