"""Peer solver: the same discretised FHOCP NLP solved by CasADi + IPOPT.

:class:`IpoptFHOCP` transcribes :class:`tubekit.fhocp_nlp.FhocpNlp` exactly
(multiple shooting with the exact zero-order-hold step, the same cost, the
same exact-penalty slacks, the *nonlinear* constraints e_d >= e_d_min,
||p - c_j|| >= r_j + r_bar + margin, |e_o| <= e_o_max, e_d <= e_d_max,
|e_z| <= e_z_max, both walls of the workspace, the same terminal handling)
and is used to check the SCP's optimum and as the timing baseline.

CasADi is an optional dependency (``pip install "tubekit[bench]"``); it is
imported lazily and its absence raises :class:`NotAvailableError`.
"""

from __future__ import annotations

import math
import time
from typing import Any, Sequence

import numpy as np

from .exceptions import ConfigError, NotAvailableError
from .fhocp import FhocpResult
from .fhocp_nlp import FhocpNlp, rollout, select_obstacles
from .scenario import Obstacle, Scenario
from .tightening import Tightening
from .validation import as_vector, finite

__all__ = ["IpoptFHOCP", "import_casadi", "IPOPT_STATUS"]

IPOPT_STATUS: dict[str, str] = {
    "Solve_Succeeded": "optimal",
    "Solved_To_Acceptable_Level": "optimal_inaccurate",
}
_TINY = 1e-12  # inside square roots: keeps them smooth at 0 (changes values by < 1e-11)


def import_casadi() -> Any:
    """Import CasADi or raise :class:`NotAvailableError` with the install hint."""
    try:
        import casadi  # noqa: PLC0415
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise NotAvailableError(
            "the IPOPT peer needs CasADi, an optional dependency: pip install \"tubekit[bench]\" "
            "(or pip install casadi)") from exc
    return casadi


def _sinc(ca: Any, a: Any) -> Any:
    """sin(a)/a, smooth at 0 (Taylor series below the same threshold as the numpy version)."""
    a2 = a * a
    series = 1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362880.0
                         + a2 * (-1.0 / 39916800.0)))))
    small = ca.fabs(a) < 0.1
    safe = ca.if_else(small, 1.0, a)
    return ca.if_else(small, series, ca.sin(safe) / safe)


class IpoptFHOCP:
    """CasADi + IPOPT on the NLP of :class:`tubekit.fhocp_nlp.FhocpNlp`.

    Parameters
    ----------
    scenario, tightening :
        As for :class:`tubekit.fhocp.FHOCP`.
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
    """

    def __init__(self, scenario: Scenario, tightening: Tightening, *, max_obstacles: int = 4,
                 terminal: str = "soft", penalty: float = 1e3, terminal_penalty: float | None = None,
                 warm_start_duals: bool = False, ipopt_options: dict | None = None) -> None:
        ca = import_casadi()
        t0 = time.perf_counter()
        if not isinstance(max_obstacles, int) or isinstance(max_obstacles, bool) or max_obstacles < 0:
            raise ConfigError("max_obstacles", "an integer >= 0", max_obstacles)
        self.scenario = scenario
        self.nlp = FhocpNlp.from_scenario(scenario, tightening, terminal=terminal, penalty=penalty,
                                          terminal_penalty=terminal_penalty)
        self.max_obstacles = max_obstacles
        self.warm_start_duals = bool(warm_start_duals)
        self._build(ca, ipopt_options or {})
        self._plan_t: float | None = None
        self._plan_inputs: np.ndarray | None = None
        self._lam_x: np.ndarray | None = None
        self._lam_g: np.ndarray | None = None
        self.build_time_s = time.perf_counter() - t0

    def _build(self, ca: Any, extra: dict) -> None:
        nlp = self.nlp
        N, dt, M = nlp.n, nlp.dt, self.max_obstacles
        V = ca.SX.sym("v", 3, N)
        S = ca.SX.sym("s", 4, N)          # s_1..s_N
        sig = ca.SX.sym("sig", 4, N)      # e_d_min, obstacle, e_o, box
        n_t = 1 if nlp.terminal == "soft" else 0
        sig_t = ca.SX.sym("sig_t", n_t)
        s0 = ca.SX.sym("s0", 4)
        ref = ca.SX.sym("ref", 3, N + 1)
        obs = ca.SX.sym("obs", 5, M)      # cx, cy, cz, radius, active
        states = [s0] + [S[:, k] for k in range(N)]
        g, lbg, ubg = [], [], []
        cost = 0
        wq, wp = nlp.q, nlp.p

        def errors(s: Any, k: int) -> tuple[Any, Any, Any]:
            ex, ey = s[0] - ref[0, k], s[1] - ref[1, k]
            ed = ca.sqrt(ex * ex + ey * ey + _TINY)
            eo = (ex * ca.sin(s[3]) - ey * ca.cos(s[3])) / ed
            return ed, s[2] - ref[2, k], eo

        for k in range(N):
            s, v = states[k], V[:, k]
            a = 0.5 * dt * v[2]
            kk = v[0] * dt * _sinc(ca, a)
            th = s[3] + a
            nxt = ca.vertcat(s[0] + kk * ca.cos(th), s[1] + kk * ca.sin(th), s[2] + dt * v[1], s[3] + dt * v[2])
            g.append(states[k + 1] - nxt)
            lbg += [0.0] * 4
            ubg += [0.0] * 4
            ed, ez, eo = errors(s, k)
            cost += dt * (wq[0] * ed * ed + wq[1] * ez * ez + wq[2] * eo * eo
                          + nlp.r[0] * v[0] ** 2 + nlp.r[1] * v[1] ** 2 + nlp.r[2] * v[2] ** 2)
        inf = math.inf
        for k in range(1, N + 1):
            s = states[k]
            ed, ez, eo = errors(s, k)
            se, so, seo, sb = sig[0, k - 1], sig[1, k - 1], sig[2, k - 1], sig[3, k - 1]
            g += [nlp.e_d_min - ed - se, ed - nlp.e_d_max - sb, eo - nlp.e_o_max - seo,
                  -eo - nlp.e_o_max - seo, ez - nlp.e_z_max - sb, -ez - nlp.e_z_max - sb]
            lbg += [-inf] * 6
            ubg += [0.0] * 6
            for j in range(M):
                d = s[:3] - obs[:3, j]
                dist = ca.sqrt(ca.dot(d, d) + _TINY)
                g.append(obs[4, j] * (obs[3, j] + nlp.clearance - dist) - so)
                lbg.append(-inf)
                ubg.append(0.0)
            if nlp.workspace is not None:
                lo = nlp.workspace[0] + nlp.clearance
                hi = nlp.workspace[1] - nlp.clearance
                for i in range(3):
                    g += [lo[i] - s[i] - sb, s[i] - hi[i] - sb]
                    lbg += [-inf, -inf]
                    ubg += [0.0, 0.0]
        ed, ez, eo = errors(states[N], N)
        cost += wp[0] * ed * ed + wp[1] * ez * ez + wp[2] * eo * eo
        cost += nlp.penalty * ca.sum1(ca.vec(sig))
        if nlp.terminal != "off":
            tnorm = ca.sqrt(wp[0] * ed * ed + wp[1] * ez * ez + wp[2] * eo * eo + _TINY)
            g.append(tnorm - nlp.terminal_level - (sig_t[0] if n_t else 0))
            lbg.append(-inf)
            ubg.append(0.0)
        if n_t:
            cost += nlp.terminal_penalty * sig_t[0]
        x = ca.vertcat(ca.vec(V), ca.vec(S), ca.vec(sig), sig_t)
        p = ca.vertcat(s0, ca.vec(ref), ca.vec(obs))
        opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-8,
                "ipopt.max_iter": 500}
        if self.warm_start_duals:
            opts.update({"ipopt.warm_start_init_point": "yes", "ipopt.warm_start_bound_push": 1e-9,
                         "ipopt.warm_start_mult_bound_push": 1e-9, "ipopt.mu_init": 1e-4})
        opts.update({f"ipopt.{k}": v for k, v in extra.items()})
        self._solver = ca.nlpsol("fhocp_ipopt", "ipopt", {"x": x, "p": p, "f": cost, "g": ca.vertcat(*g)}, opts)
        nx = x.shape[0]
        self._lbx = np.full(nx, -np.inf)
        self._ubx = np.full(nx, np.inf)
        vm = np.tile(nlp.v_max, N)
        self._lbx[:3 * N] = -vm
        self._ubx[:3 * N] = vm
        self._lbx[7 * N:] = 0.0  # slacks
        self._lbg = np.array(lbg)
        self._ubg = np.array(ubg)
        self._n_t = n_t

    # -------------------------------------------------------------- public
    def reset(self) -> None:
        """Forget the warm start."""
        self._plan_t = self._plan_inputs = self._lam_x = self._lam_g = None

    def _guess(self, t: float) -> np.ndarray:
        n = self.nlp.n
        if self._plan_inputs is None or self._plan_t is None:
            return np.zeros((n, 3))
        shift = int(round((t - self._plan_t) / self.nlp.dt))
        if shift < 0:
            return np.zeros((n, 3))
        shift = min(shift, n)
        v = self._plan_inputs
        return np.vstack([v[shift:], np.repeat(v[-1:], shift, axis=0)]) if shift else v.copy()

    def solve(self, t: float, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray = (),
              initial_inputs: np.ndarray | None = None) -> FhocpResult:
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

        Returns
        -------
        FhocpResult
            ``states`` are the rollout of the returned inputs; ``status`` is
            ``"optimal"``, ``"optimal_inaccurate"`` or ``"ipopt:<return status>"``
            (then ``fallback`` is True and the guess is returned).
        """
        t_start = time.perf_counter()
        t = finite("t", t)
        s0 = as_vector("state", state, 4)
        nlp, N, M = self.nlp, self.nlp.n, self.max_obstacles
        obs, _ = select_obstacles(s0, obstacles, self.scenario.sensing_range, M)
        ref = nlp.reference(self.scenario.trajectory, t)
        guess = self._guess(t) if initial_inputs is None else np.asarray(initial_inputs, dtype=float)
        if guess.shape != (N, 3):
            raise ConfigError("initial_inputs", f"an array of shape ({N}, 3)", guess.shape)
        guess = np.clip(guess, -nlp.v_max, nlp.v_max)
        s_guess = rollout(s0, guess, nlp.dt)
        ev = nlp.evaluate(s_guess, guess, ref, obs)
        ps = ev.per_step
        x0 = np.concatenate([guess.ravel(), s_guess[1:].ravel(),
                             np.stack([ps["e_d_min"], ps["obstacle"], ps["e_o"], ps["box"]], axis=1).ravel(),
                             [ev.violations["terminal"]] * self._n_t])
        obs_p = np.zeros((M, 5))
        obs_p[:, 3] = 1.0
        obs_p[:, :3] = s0[:3] + 1e3  # inactive slots: far away and switched off
        if len(obs):
            obs_p[:len(obs), :4] = obs
            obs_p[:len(obs), 4] = 1.0
        p = np.concatenate([s0, ref.ravel(), obs_p.ravel()])
        args = {"x0": x0, "p": p, "lbx": self._lbx, "ubx": self._ubx, "lbg": self._lbg, "ubg": self._ubg}
        if self.warm_start_duals and self._lam_x is not None and initial_inputs is None:
            args["lam_x0"] = self._lam_x
            args["lam_g0"] = self._lam_g
        ts = time.perf_counter()
        sol = self._solver(**args)
        solver_time = time.perf_counter() - ts
        stats = self._solver.stats()
        raw = str(stats.get("return_status", "unknown"))
        status = IPOPT_STATUS.get(raw, f"ipopt:{raw}")
        xs = np.asarray(sol["x"]).ravel()
        v = xs[:3 * N].reshape(N, 3)
        fallback = status not in ("optimal", "optimal_inaccurate") or not np.all(np.isfinite(v))
        if fallback:
            v = guess
        else:
            self._lam_x = np.asarray(sol["lam_x"]).ravel()
            self._lam_g = np.asarray(sol["lam_g"]).ravel()
        v = np.clip(v, -nlp.v_max, nlp.v_max)
        s = rollout(s0, v, nlp.dt)
        ev = nlp.evaluate(s, v, ref, obs)
        self._plan_t, self._plan_inputs = t, v.copy()
        return FhocpResult(status=status, states=s, inputs=v, cost=ev.cost,
                           iterations=int(stats.get("iter_count", 0)),
                           solve_time_s=time.perf_counter() - t_start, setup_time_s=0.0,
                           max_violation=ev.max_violation, fallback=fallback, merit=ev.merit,
                           violations=ev.violations, solver_time_s=solver_time, t=t,
                           message="" if not fallback else f"IPOPT returned {raw}")
