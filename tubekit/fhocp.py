"""The FHOCP of Section V (eqs. mpc_cost_function - terminal_set_F) by sequential convex programming.

The nonlinear program is :class:`tubekit.fhocp_nlp.FhocpNlp` (exact
zero-order-hold discretisation, diagonal Q/R/P, exact-penalty slacks). Each
SCP iteration solves one convex subproblem, built **once** in cvxpy with
Parameters (DPP) and re-solved by Clarabel data updates
(:class:`tubekit.fhocp_fastpath.CompiledConeProgram`):

* dynamics linearised around the current plan (its nonlinear rollout);
* e_d^2 and e_z^2 are exact convex quadratics in position; e_o is replaced by
  its first-order model (Gauss-Newton);
* e_d >= e_d_min and each ball exclusion ||p - c_j|| >= r_j + r_bar + margin
  become the half-spaces n'(p - c) >= ... with n the unit direction at the
  plan: the half-space lies inside the nonconvex feasible set (conservative);
* |e_o| <= e_o_max (linearised), |e_z| <= e_z_max and the z walls (one row
  each side), e_d <= e_d_max (the same half-space normal as e_d_min: an outer
  approximation, exact at the linearisation point) and the nearer x and y
  walls, all with l1 exact-penalty slacks (one per constraint family and
  step), so a subproblem is feasible whenever the input box is non-empty
  (unless the terminal set is "hard");
* terminal set F = {||e_N||_P <= terminal_level} as a second-order cone,
  "soft" (default, exact penalty), "hard" or "off";
* a box trust region on the input step, intersected with the input box.

Modes: ``"realtime"`` does one convex solve per control step from the shifted
previous plan (real-time iteration); ``"converged"`` iterates with a
ratio-test trust region on the exact merit (cost + penalties) until the model
predicts a relative decrease below ``tolerance`` or ``max_iterations``; an
accurately predicted step is stretched by a merit line search (the convex
model omits the concave constraints' curvature and would otherwise slide
along an obstacle in many short steps). A cold start (no previous plan)
always runs the converged loop.

Every returned plan is the rollout of the returned inputs through the exact
discrete model, so ``states`` and ``inputs`` are consistent; its nonlinear
constraint violations are measured, not assumed.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Sequence

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from .exceptions import ConfigError, SolverError
from .fhocp_fastpath import CompiledConeProgram, ConeSolution
from .fhocp_nlp import (TERMINAL_MODES, FhocpNlp, eo_linearisation, rollout, select_obstacles,
                        step_linearisation)
from .scenario import Obstacle, Scenario
from .tightening import Tightening
from .validation import as_vector, finite, positive

__all__ = ["FHOCP", "FhocpResult", "FallbackWarning", "MODES", "obstacle_slots",
           "DEFAULT_CLARABEL_SETTINGS"]

MODES: tuple[str, ...] = ("realtime", "converged")
_OK = ("optimal", "optimal_inaccurate")
_DYN_KEYS = ("ax", "bxu", "bxr", "cx", "ay", "byu", "byr", "cy")


#: Clarabel settings used by default (looser than Clarabel's 1e-8: the SCP's own tolerance is 1e-5)
DEFAULT_CLARABEL_SETTINGS: dict = {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7}


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


class FallbackWarning(UserWarning):
    """The FHOCP failed; the shifted previous plan with a searched tail is returned."""


@dataclass(frozen=True)
class FhocpResult:
    """One FHOCP solve.

    Attributes
    ----------
    status : str
        ``"optimal"``, ``"optimal_inaccurate"``, ``"iteration_limit"`` (converged
        mode stopped at ``max_iterations``; the plan is valid) or ``"fallback"``.
    states : array (N+1, 4)
        Nominal states [x, y, z, psi] (m, rad): the rollout of ``inputs`` from
        the measured state.
    inputs : array (N, 3)
        Nominal inputs [u, w, r] (m/s, m/s, rad/s); finite and inside V-bar.
    cost : float
        Stage + terminal cost of the NLP on this plan (penalties excluded).
    iterations : int
        Convex subproblems solved.
    solve_time_s : float
        Wall time of the whole ``solve`` call (s).
    setup_time_s : float
        Part of ``solve_time_s`` spent linearising and writing parameters (s).
    max_violation : float
        Largest violation of the nonlinear constraints on this plan (e_d >=
        e_d_min, obstacles, |e_o|, box/e_d_max/workspace, terminal unless
        "off", input box, dynamics defect), k = 1..N (m or error units).
    fallback : bool
        True when the solve failed and the shifted previous plan was returned.
    merit : float
        cost + exact penalties (the NLP objective at its optimal slacks).
    violations : dict
        Per-family largest violations (see :class:`tubekit.fhocp_nlp.NlpEvaluation`).
    solver_time_s : float
        Clarabel's own time summed over the subproblems (s).
    t : float
        Time of the solve (s).
    message : str
        Why a fallback happened (empty otherwise).
    """

    status: str
    states: np.ndarray
    inputs: np.ndarray
    cost: float
    iterations: int
    solve_time_s: float
    setup_time_s: float
    max_violation: float
    fallback: bool
    merit: float = math.nan
    violations: dict = field(default_factory=dict)
    solver_time_s: float = 0.0
    t: float = 0.0
    message: str = ""

    @property
    def first_input(self) -> np.ndarray:
        """The input to apply now, ``inputs[0]`` (3,)."""
        return self.inputs[0]

    def check(self, tol: float = 1e-6) -> None:
        """Raise :class:`SolverError` unless the plan is finite and violates nothing by more than ``tol``."""
        if not (np.all(np.isfinite(self.states)) and np.all(np.isfinite(self.inputs))):
            raise SolverError(f"FHOCP plan at t={self.t} is not finite")
        if not self.max_violation <= tol:
            worst = max(self.violations, key=self.violations.get) if self.violations else "?"
            raise SolverError(f"FHOCP plan at t={self.t} violates '{worst}' by {self.max_violation:.3g} "
                              f"(> {tol:g}); status {self.status}")


class FHOCP:
    """Sequential convex programming solver of the tube-MPC FHOCP.

    Parameters
    ----------
    scenario : Scenario
        Trajectory, weights (Q, R, P diagonals), horizon, dt, terminal level,
        vehicle radius, sensing range, workspace.
    tightening : Tightening
        Tightened sets (V-bar, e_d_min, e_o_max, e_z_max, e_d_max, obstacle margin).
    mode : {"realtime", "converged"}, optional
        One convex solve per warm-started step, or SCP to convergence; default
        ``scenario.controller.fhocp_mode``.
    max_obstacles : int, optional
        Obstacle slots in the compiled problem (the nearest detected obstacles are kept,
        with a warning when some do not fit). Default: :func:`obstacle_slots` of the
        scenario (1 for the paper's).
    terminal : {"soft", "hard", "off"}
        Terminal-set handling (see module docstring); default ``scenario.controller.terminal_mode``.
    penalty : float
        Exact-penalty weight mu on the state-constraint slacks.
    terminal_penalty : float, optional
        mu_T for the soft terminal set (default ``penalty / 20``: safety slacks outrank F).
    max_iterations : int, optional
        Converged-mode cap (default 30).
    cold_start_iterations : int
        Cap for a solve without a previous plan (any mode).
    tolerance : float
        Converged mode stops when the predicted merit decrease, or the decrease of
        an accepted step, is below ``tolerance * max(1, |merit|)``, or the input
        step below ``tolerance * V-bar`` (default 1e-5).
    trust_radius : float, optional
        Input trust region as a fraction of V-bar per component (default 0.5;
        in converged mode the initial radius, adapted by the ratio test).
    extrapolate : bool
        Converged mode: stretch accurately predicted steps by a merit line search.
    fast_path : bool
        Re-solve through the compiled map + persistent Clarabel (default);
        False uses ``problem.solve(solver=cp.CLARABEL)`` (same problem, slower).
    clarabel_settings : dict, optional
        Overrides of :data:`DEFAULT_CLARABEL_SETTINGS` / Clarabel's settings.

    Attributes
    ----------
    problem : cvxpy.Problem
        The parametrised convex subproblem (DPP), built once.
    compiled : CompiledConeProgram or None
        The fast path (None when ``fast_path=False``).
    nlp : FhocpNlp
        The nonlinear program being solved.
    build_time_s : float
        Construction time: cvxpy build + compilation (s).
    """

    def __init__(self, scenario: Scenario, tightening: Tightening, mode: str | None = None, *,
                 max_obstacles: int | None = None, terminal: str | None = None, penalty: float = 1e3,
                 terminal_penalty: float | None = None, max_iterations: int | None = None,
                 cold_start_iterations: int = 30, tolerance: float = 1e-5,
                 trust_radius: float | None = None, extrapolate: bool = True, fast_path: bool = True,
                 clarabel_settings: dict | None = None) -> None:
        t0 = time.perf_counter()
        mode = scenario.controller.fhocp_mode if mode is None else mode
        terminal = scenario.controller.terminal_mode if terminal is None else terminal
        if mode not in MODES:
            raise ConfigError("mode", f"one of {MODES}", mode)
        if terminal not in TERMINAL_MODES:
            raise ConfigError("terminal", f"one of {TERMINAL_MODES}", terminal)
        if max_obstacles is None:
            max_obstacles = obstacle_slots(scenario)
        if not isinstance(max_obstacles, int) or isinstance(max_obstacles, bool) or max_obstacles < 0:
            raise ConfigError("max_obstacles", "an integer >= 0 or None", max_obstacles)
        if max_iterations is None:
            max_iterations = 30
        for name, val in (("max_iterations", max_iterations), ("cold_start_iterations", cold_start_iterations)):
            if not isinstance(val, int) or isinstance(val, bool) or val < 1:
                raise ConfigError(name, "an integer >= 1", val)
        self.scenario = scenario
        self.tightening = tightening
        self.nlp = FhocpNlp.from_scenario(scenario, tightening, terminal=terminal, penalty=penalty,
                                          terminal_penalty=terminal_penalty)
        if self.nlp.workspace is not None:
            reach = float(self.nlp.v_max[0]) * self.nlp.dt * self.nlp.n  # farthest horizontal travel (m)
            width = self.nlp.workspace[1, :2] - self.nlp.workspace[0, :2] - 2 * self.nlp.clearance
            if np.any(width <= 2 * reach):
                raise ConfigError("scenario.workspace",
                                  f"x and y extents > 2 (vehicle_radius + obstacle_margin + u_max T) = "
                                  f"{2 * (self.nlp.clearance + reach):.4g} m", scenario.workspace,
                                  "the FHOCP keeps one wall row per axis (the nearer wall)")
        self.mode = mode
        self.max_obstacles = max_obstacles
        self.max_iterations = max_iterations
        self.cold_start_iterations = cold_start_iterations
        self.tolerance = positive("tolerance", tolerance)
        self.trust_radius = positive("trust_radius", 0.5 if trust_radius is None else trust_radius)
        self.extrapolate = bool(extrapolate)
        self._plan_t: float | None = None
        self._plan_inputs: np.ndarray | None = None
        self._dropped_warned = False
        self._build()
        self.fast_path = bool(fast_path)
        self.compiled: CompiledConeProgram | None = None
        self._clarabel_settings = {**DEFAULT_CLARABEL_SETTINGS, **(clarabel_settings or {})}
        if self.fast_path:
            self.compiled = CompiledConeProgram(self.problem, self._clarabel_settings)
            self._pvec = self.compiled.param_vector
            used = {p.id for p in self.problem.parameters()}
            self._cols = {name: self.compiled.columns(p) for name, p in self._params.items() if p.id in used}
            self._uwr_cols = np.stack([self.compiled.columns_of(self._vars[k]) for k in ("u", "w", "r")])
        else:
            used = {p.id for p in self.problem.parameters()}
            live = {name: p for name, p in self._params.items() if p.id in used}
            self._pvec = np.zeros(sum(p.size for p in live.values()))
            self._cols, start = {}, 0
            for name, p in live.items():
                self._cols[name] = np.arange(start, start + p.size)
                start += p.size
        M = self.max_obstacles
        groups = {"dyn": list(_DYN_KEYS), "lin": ["lx", "ly", "lz"],
                  "pdN": ["pdN"] if self.nlp.terminal != "off" else [],
                  "eo": ["gx", "gy", "gpsi", "h"], "step": ["nx", "ny", "red", "rdx", "zlo", "zhi"],
                  "bounds": ["ulo", "uhi", "wlo", "whi", "rlo", "rhi"],
                  "obs": [f"{a}{j}" for j in range(M) for a in ("ox", "oy", "oz", "ro")],
                  "walls": ["wsx", "wbx", "wsy", "wby"] if self.nlp.workspace is not None else [],
                  "c0": ["c0"]}
        self._gidx = {g: np.concatenate([self._cols[n] for n in names]) if names else np.zeros(0, dtype=int)
                      for g, names in groups.items()}

        self._set_neutral_parameters()
        self.build_time_s = time.perf_counter() - t0

    # ------------------------------------------------------------- building
    def _build(self) -> None:
        """Build the parametrised convex subproblem (once).

        The variables are the samples k = 1..N in a frame translated to the measured
        position, with the heading measured from the measured heading (the measured
        state itself is not a variable); the translation and the heading offset move
        into the parameters, so every datum is O(1) near the solution.
        """
        nlp = self.nlp
        N, dt = nlp.n, nlp.dt
        params: dict[str, cp.Parameter] = {}

        def par(name: str, size: int) -> cp.Parameter:
            params[name] = cp.Parameter(size, name=name)
            return params[name]

        x, y, z, psi = (cp.Variable(N, name=n) for n in ("x", "y", "z", "psi"))
        u, w, r = (cp.Variable(N, name=n) for n in ("u", "w", "r"))
        eo = cp.Variable(N, name="e_o")
        sig_ed, sig_obs, sig_eo, sig_box = (cp.Variable(N, name=f"slack_{n}")
                                            for n in ("e_d_min", "obstacle", "e_o", "box"))
        dyn = {k: par(k, N) for k in _DYN_KEYS}
        gx, gy, gpsi, h = par("gx", N), par("gy", N), par("gpsi", N), par("h", N)
        nx, ny, red, rdx = par("nx", N), par("ny", N), par("red", N), par("rdx", N)
        bounds = {k: par(k, N) for k in ("ulo", "uhi", "wlo", "whi", "rlo", "rhi")}
        shift = sp.diags(np.ones(N - 1), -1, shape=(N, N), format="csc") if N > 1 else sp.csc_matrix((1, 1))
        diff = sp.identity(N, format="csc") - shift   # (D s)_k = s_k - s_{k-1}, s_0 = 0 in this frame

        cons = [
            diff @ x == cp.multiply(dyn["ax"], shift @ psi) + cp.multiply(dyn["bxu"], u)
            + cp.multiply(dyn["bxr"], r) + dyn["cx"],
            diff @ y == cp.multiply(dyn["ay"], shift @ psi) + cp.multiply(dyn["byu"], u)
            + cp.multiply(dyn["byr"], r) + dyn["cy"],
            diff @ z == dt * w,
            diff @ psi == dt * r,
            eo == cp.multiply(gx, x) + cp.multiply(gy, y) + cp.multiply(gpsi, psi) + h,
            u >= bounds["ulo"], u <= bounds["uhi"],
            w >= bounds["wlo"], w <= bounds["whi"],
            r >= bounds["rlo"], r <= bounds["rhi"],
            cp.multiply(nx, x) + cp.multiply(ny, y) + sig_ed >= red,
            cp.multiply(nx, x) + cp.multiply(ny, y) - sig_box <= rdx,
        ]
        for j in range(self.max_obstacles):
            ox, oy, oz, ro = par(f"ox{j}", N), par(f"oy{j}", N), par(f"oz{j}", N), par(f"ro{j}", N)
            cons.append(cp.multiply(ox, x) + cp.multiply(oy, y) + cp.multiply(oz, z) + sig_obs >= ro)
        cons += [
            eo <= nlp.e_o_max + sig_eo,
            -eo <= nlp.e_o_max + sig_eo,
            # |e_z| <= e_z_max and the z walls share a row: z <= min(zd + e_z_max, hi_z - c), etc.
            z - sig_box <= par("zhi", N),
            z + sig_box >= par("zlo", N),
        ]
        if nlp.workspace is not None:
            # x/y walls: only the nearer wall per axis can be reached within the horizon
            # (checked in __init__), so one row per axis: sgn * p <= bound.
            cons += [cp.multiply(par("wsx", N), x) - sig_box <= par("wbx", N),
                     cp.multiply(par("wsy", N), y) - sig_box <= par("wby", N)]
        cons += [sig_ed >= 0, sig_obs >= 0, sig_eo >= 0, sig_box >= 0]
        sig_t = None
        if nlp.terminal != "off":
            pdn = par("pdN", 3)
            sp_ = np.sqrt(nlp.p)
            terminal_vec = cp.hstack([sp_[0] * (x[N - 1] - pdn[0]), sp_[0] * (y[N - 1] - pdn[1]),
                                      sp_[1] * (z[N - 1] - pdn[2]), sp_[2] * eo[N - 1]])
            if nlp.terminal == "soft":
                sig_t = cp.Variable(name="slack_terminal")
                cons += [sig_t >= 0, cp.SOC(nlp.terminal_level + sig_t, terminal_vec)]
            else:
                cons.append(cp.SOC(cp.Constant(nlp.terminal_level), terminal_vec))

        # weights: dt*Q on samples 0..N-1, P on sample N (left rectangle rule + terminal cost).
        # (x - xd)' W (x - xd) = x' W x + lx' x + c0 with lx = -2 W xd and c0 = xd' W xd (plus
        # the constant k = 0 terms) as parameters: quad_form with a constant matrix and a bare
        # variable needs no auxiliary variables, and the objective stays DPP.
        wts = np.vstack([np.tile(dt * nlp.q, (N, 1)), nlp.p])   # (N+1, 3) for k = 0..N
        lin = {k: par(k, N) for k in ("lx", "ly", "lz")}
        c0 = par("c0", 1)
        self._weights = wts
        self._wref = wts[1:, (0, 0, 1)].T  # (3, N) weights of x, y, z at k = 1..N
        w1 = wts[1:]
        cost = (cp.quad_form(x, np.diag(w1[:, 0])) + cp.quad_form(y, np.diag(w1[:, 0]))
                + cp.quad_form(z, np.diag(w1[:, 1])) + cp.quad_form(eo, np.diag(w1[:, 2]))
                + lin["lx"] @ x + lin["ly"] @ y + lin["lz"] @ z + cp.sum(c0)
                + dt * (nlp.r[0] * cp.sum_squares(u) + nlp.r[1] * cp.sum_squares(w)
                        + nlp.r[2] * cp.sum_squares(r))
                + nlp.penalty * (cp.sum(sig_ed) + cp.sum(sig_obs) + cp.sum(sig_eo) + cp.sum(sig_box)))
        if sig_t is not None:
            cost = cost + nlp.terminal_penalty * sig_t
        self.problem = cp.Problem(cp.Minimize(cost), cons)
        self._params = params
        self._vars = {"x": x, "y": y, "z": z, "psi": psi, "u": u, "w": w, "r": r, "e_o": eo}

    def _set_neutral_parameters(self) -> None:
        """Give every parameter a value (needed by the cvxpy path) from a zero-input plan."""
        s0 = np.asarray(self.scenario.initial_state, dtype=float)
        ref = self.nlp.reference(self.scenario.trajectory, 0.0)
        v = np.zeros((self.nlp.n, 3))
        self._linearise(s0, rollout(s0, v, self.nlp.dt), v, ref, np.zeros((0, 4)), self.trust_radius)
        self.push_parameters()

    def push_parameters(self) -> None:
        for name, p in self._params.items():
            if name in self._cols:
                p.value = self._pvec[self._cols[name]].reshape(p.shape, order="F")
            else:  # not in the compiled problem (unused): any value
                p.value = np.zeros(p.shape)

    # ------------------------------------------------------- linearisation
    def _linearise(self, s0: np.ndarray, s: np.ndarray, v: np.ndarray, ref: np.ndarray,
                   obs: np.ndarray, radius: float) -> None:
        """Write the subproblem's parameters for the plan (s, v) into the parameter vector.

        The frame is translated to the measured position and the heading variable is
        psi - psi_0 (see :meth:`_build`); each group of parameters is computed as one
        array and written with one indexed assignment.
        """
        nlp, pvec, gidx = self.nlp, self._pvec, self._gidx
        N = nlp.n
        o = s0[:3]
        psi0 = s0[3]
        s = s.copy()
        s[:, :3] -= o
        ref = ref - o
        dyn = step_linearisation(s, v, nlp.dt)
        dyn[3] += dyn[0] * psi0          # offsets for the heading variable psi - psi_0
        dyn[7] += dyn[4] * psi0
        pvec[gidx["dyn"]] = dyn.ravel()
        r1 = ref[1:]
        blk = -2.0 * self._wref * r1.T
        pvec[gidx["lin"]] = blk.ravel()
        if self.nlp.terminal != "off":
            pvec[gidx["pdN"]] = ref[N]
        eo_all = eo_linearisation(s, ref)
        wts = self._weights
        e0 = (ref[0, 0] ** 2 + ref[0, 1] ** 2, ref[0, 2] ** 2, eo_all[4, 0] ** 2)  # k = 0 (constant)
        pvec[gidx["c0"]] = float(np.einsum("ck,kc->", self._wref, r1 * r1) + wts[0] @ e0)
        eo = eo_all[:4, 1:]
        eo[3] += eo[2] * psi0
        pvec[gidx["eo"]] = eo.ravel()
        # e_d >= e_d_min (and <= e_d_max): n'(p - p_d) with n the horizontal unit error direction
        ex = s[1:, 0] - r1[:, 0]
        ey = s[1:, 1] - r1[:, 1]
        ed = np.sqrt(ex * ex + ey * ey)
        if ed.min() < 1e-9:  # on the target: use the direction behind the heading
            tiny = ed < 1e-9
            ex = np.where(tiny, -np.cos(s[1:, 3]), ex)
            ey = np.where(tiny, -np.sin(s[1:, 3]), ey)
            ed = np.sqrt(ex * ex + ey * ey)
        st = np.empty((6, N))
        st[0] = ex / ed
        st[1] = ey / ed
        npd = st[0] * r1[:, 0] + st[1] * r1[:, 1]
        st[2] = nlp.e_d_min + npd
        st[3] = nlp.e_d_max + npd
        st[4] = r1[:, 2] - nlp.e_z_max
        st[5] = r1[:, 2] + nlp.e_z_max
        if nlp.workspace is not None:
            lo = nlp.workspace[0] + nlp.clearance - o
            hi = nlp.workspace[1] - nlp.clearance - o
            np.maximum(st[4], lo[2], out=st[4])
            np.minimum(st[5], hi[2], out=st[5])
            # the nearer wall per axis (the origin is the measured position)
            walls = [1.0, hi[0], 1.0, hi[1]]
            for i in (0, 1):
                if -lo[i] < hi[i]:
                    walls[2 * i], walls[2 * i + 1] = -1.0, -lo[i]
            pvec[gidx["walls"]] = np.repeat(walls, N)
        pvec[gidx["step"]] = st.ravel()
        # obstacles: n'(p - c) >= r + clearance, n the unit direction from c to the plan
        if self.max_obstacles:
            ob = np.zeros((self.max_obstacles, 4, N))
            ob[:, 3] = -1.0  # inactive slot: 0 >= -1
            k = len(obs)
            if k:
                c = obs[:, :3] - o                       # (k, 3)
                d = s[None, 1:, :3] - c[:, None, :]      # (k, N, 3)
                dist = np.sqrt(np.einsum("jnc,jnc->jn", d, d))
                if dist.min() < 1e-9:
                    bad = dist < 1e-9
                    d[bad] = (0.0, 0.0, 1.0)
                    dist[bad] = 1.0
                n = d / dist[..., None]
                ob[:k, :3] = n.transpose(0, 2, 1)
                ob[:k, 3] = obs[:, 3:4] + nlp.clearance + np.einsum("jnc,jc->jn", n, c)
            pvec[gidx["obs"]] = ob.ravel()
        vmax = nlp.v_max
        bd = np.empty((6, N))
        bd[0::2] = np.maximum(-vmax, v - radius * vmax).T
        bd[1::2] = np.minimum(vmax, v + radius * vmax).T
        pvec[gidx["bounds"]] = bd.ravel()

    # ---------------------------------------------------------- subproblem
    def _solve_subproblem(self) -> tuple[str, np.ndarray | None, float, float]:
        """Solve the convex subproblem at the current parameters.

        Returns (status, inputs (N, 3) or None, model objective, Clarabel time (s)).
        """
        if self.compiled is not None:
            sol: ConeSolution = self.compiled.solve()
            if sol.x is None:
                return sol.status, None, math.nan, sol.solver_time_s
            return sol.status, sol.x[self._uwr_cols].T, sol.objective, sol.solver_time_s
        self.push_parameters()
        opts = {"presolve_enable": False, "chordal_decomposition_enable": False}
        opts.update(self._clarabel_settings)
        try:
            self.problem.solve(solver=cp.CLARABEL, **opts)
        except cp.error.SolverError:
            return "solver_error", None, math.nan, 0.0
        status = self.problem.status
        stime = float(self.problem.solver_stats.solve_time or 0.0)
        if status not in _OK:
            return status, None, math.nan, stime
        v = np.stack([self._vars[k].value for k in ("u", "w", "r")], axis=1)
        return status, v, float(self.problem.value), stime

    # --------------------------------------------------------------- public
    def reset(self) -> None:
        """Forget the warm start (the next solve is a cold start)."""
        self._plan_t = None
        self._plan_inputs = None

    @property
    def plan_inputs(self) -> np.ndarray | None:
        """The stored plan's inputs (N, 3) or None after :meth:`reset`."""
        return None if self._plan_inputs is None else self._plan_inputs.copy()

    def _shift(self, t: float) -> int | None:
        """Steps from the stored plan to ``t`` (at most N), or None without a usable plan."""
        if self._plan_inputs is None or self._plan_t is None:
            return None
        shift = int(round((t - self._plan_t) / self.nlp.dt))
        return None if shift < 0 else min(shift, self.nlp.n)

    def warm_start_inputs(self, t: float) -> tuple[np.ndarray, bool]:
        """The previous plan shifted to time ``t`` (last input repeated), or zeros and False."""
        shift = self._shift(t)
        if shift is None:
            return np.zeros((self.nlp.n, 3)), False
        v = self._plan_inputs
        if shift:
            v = np.vstack([v[shift:], np.repeat(v[-1:], shift, axis=0)])
        return v.copy(), True

    def select_obstacles(self, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray) -> np.ndarray:
        """The obstacles this solver puts in the problem at ``state`` (K, 4), K <= max_obstacles."""
        kept, dropped = select_obstacles(state, obstacles, self.scenario.sensing_range, self.max_obstacles)
        if dropped and not self._dropped_warned:
            warnings.warn(f"{dropped} obstacle(s) within sensing range ignored: only the nearest "
                          f"max_obstacles={self.max_obstacles} fit the compiled problem", RuntimeWarning,
                          stacklevel=3)
            self._dropped_warned = True
        return kept

    def solve(self, t: float, state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray = ()) -> FhocpResult:
        """Solve the FHOCP at time ``t`` (s) from the measured ``state`` (4,).

        Parameters
        ----------
        t : float
            Current time t_k (s).
        state : array (4,)
            Measured state [x, y, z, psi]; the nominal is reset to it (e_hat(t_k) = e(t_k)).
        obstacles : sequence of Obstacle
            Currently detected obstacles (filtered again by sensing range).

        Returns
        -------
        FhocpResult
            Never contains NaN; ``fallback`` is set (with a :class:`FallbackWarning`)
            when no subproblem could be solved.
        """
        t_start = time.perf_counter()
        t = finite("t", t)
        s0 = as_vector("state", state, 4)
        obs = self.select_obstacles(s0, obstacles)
        nlp = self.nlp
        ref = nlp.reference(self.scenario.trajectory, t)
        guess, warm = self.warm_start_inputs(t)
        guess = np.clip(guess, -nlp.v_max, nlp.v_max)
        realtime = warm and self.mode == "realtime"
        cap = 1 if realtime else (self.max_iterations if warm else self.cold_start_iterations)

        v, s = guess, rollout(s0, guess, nlp.dt)
        ev = None if realtime else nlp.evaluate(s, v, ref, obs)
        radius = self.trust_radius
        setup = solver_time = 0.0
        iters = accepted = 0
        worst_status = "optimal"
        failure = ""
        converged = False
        for _ in range(cap):
            ts = time.perf_counter()
            self._linearise(s0, s, v, ref, obs, radius)
            setup += time.perf_counter() - ts
            status, v_new, model_obj, stime = self._solve_subproblem()
            iters += 1
            solver_time += stime
            if v_new is None or not np.all(np.isfinite(v_new)):
                failure = f"convex subproblem {iters} returned status '{status}'"
                break
            v_new = np.clip(v_new, -nlp.v_max, nlp.v_max)
            s_new = rollout(s0, v_new, nlp.dt)
            if realtime:
                v, s, accepted = v_new, s_new, 1
                worst_status = status
                break
            ev_new = nlp.evaluate(s_new, v_new, ref, obs)
            pred = ev.merit - model_obj
            actual = ev.merit - ev_new.merit
            if pred <= self.tolerance * max(1.0, abs(ev.merit)):
                if actual > 0:
                    v, s, ev = v_new, s_new, ev_new
                    accepted += 1
                converged = True
                break
            step = float(np.max(np.abs(v_new - v) / nlp.v_max))
            if actual >= 0.1 * pred:
                if self.extrapolate and actual >= 0.9 * pred:
                    v_new, s_new, ev_new = self._extrapolate(s0, v, v_new, ev_new, ref, obs)
                    actual = ev.merit - ev_new.merit
                v, s, ev = v_new, s_new, ev_new
                accepted += 1
                if status != "optimal":
                    worst_status = status
                if actual >= 0.75 * pred and step >= 0.5 * radius:
                    radius = min(2.0 * radius, 2.0)
                # an accepted step that changed the merit (or the inputs) by less than the
                # tolerance: the next model could not predict a larger decrease
                if step <= self.tolerance or actual <= self.tolerance * max(1.0, abs(ev.merit)):
                    converged = True
                    break
            else:
                radius = 0.5 * min(radius, max(step, self.tolerance))
                if radius <= self.tolerance:
                    converged = True
                    break

        if failure and accepted == 0:
            return self._fallback(t, s0, guess, ref, obs, failure, iters, setup, solver_time, t_start)
        if failure:
            worst_status = "optimal_inaccurate"
        elif not realtime and not converged:
            worst_status = "iteration_limit"
        if ev is None:
            ev = nlp.evaluate(s, v, ref, obs)
        self._plan_t, self._plan_inputs = t, v.copy()
        return FhocpResult(status=worst_status, states=s, inputs=v, cost=ev.cost, iterations=iters,
                           solve_time_s=time.perf_counter() - t_start, setup_time_s=setup,
                           max_violation=ev.max_violation, fallback=False, merit=ev.merit,
                           violations=ev.violations, solver_time_s=solver_time, t=t)

    def _extrapolate(self, s0: np.ndarray, v: np.ndarray, v_new: np.ndarray, ev_new, ref: np.ndarray,
                     obs: np.ndarray):
        """Line search beyond an accurately modelled step: v + 2^j (v_new - v) while the merit falls.

        The convex model omits the negative curvature of the concave constraints (ball
        exclusion, e_d >= e_d_min), so where such a constraint is active the model's steps
        are too short (the convex-concave procedure's slow slide along the boundary); a
        step whose prediction was accurate is therefore stretched while the exact merit
        keeps decreasing. Costs one rollout and one evaluation per trial.
        """
        nlp = self.nlp
        best = (v_new, None, ev_new)
        d = v_new - v
        for j in range(1, 6):
            cand = np.clip(v + (2.0 ** j) * d, -nlp.v_max, nlp.v_max)
            s_c = rollout(s0, cand, nlp.dt)
            ev_c = nlp.evaluate(s_c, cand, ref, obs)
            if not ev_c.merit < best[2].merit:
                break
            best = (cand, s_c, ev_c)
        v_b, s_b, ev_b = best
        if s_b is None:
            s_b = rollout(s0, v_b, nlp.dt)
        return v_b, s_b, ev_b

    def shifted_candidate(self, t: float, state: np.ndarray,
                          obstacles: Sequence[Obstacle] | np.ndarray = ()) -> tuple[np.ndarray, np.ndarray, object]:
        """Tube MPC's candidate at ``t``: the stored plan shifted, its new tail input searched.

        The inputs the previous plan still covers are kept; each appended input is
        the point of a grid over V-bar (7 x 5 x 7) whose plan violates the state
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

        Returns
        -------
        states (N+1, 4), inputs (N, 3), evaluation (:class:`tubekit.fhocp_nlp.NlpEvaluation`)
        """
        s0 = as_vector("state", state, 4)
        obs = self.select_obstacles(s0, obstacles)
        ref = self.nlp.reference(self.scenario.trajectory, finite("t", t))
        guess, _ = self.warm_start_inputs(t)
        return self._searched_tail(s0, np.where(np.isfinite(guess), guess, 0.0), self._kept_steps(t), ref, obs)

    def _kept_steps(self, t: float) -> int:
        """Inputs of the stored plan still covering [t, t + T] (0 without a usable plan)."""
        shift = self._shift(t)
        return 0 if shift is None else self.nlp.n - shift

    def _searched_tail(self, s0: np.ndarray, v: np.ndarray, kept: int, ref: np.ndarray, obs: np.ndarray):
        nlp = self.nlp
        v = np.clip(v, -nlp.v_max, nlp.v_max)
        grid = np.stack(np.meshgrid(*[np.linspace(-b, b, k) for b, k in zip(nlp.v_max, (7, 5, 7))],
                                    indexing="ij"), axis=-1).reshape(-1, 3)
        for j in range(kept, nlp.n):
            best_key, best_u = None, v[j]
            for cand in grid:
                v[j:] = cand
                ev = nlp.evaluate(rollout(s0, v, nlp.dt), v, ref, obs)
                viol = max(val for key, val in ev.violations.items() if key != "terminal")
                key = (round(viol, 9), ev.merit)
                if best_key is None or key < best_key:
                    best_key, best_u = key, cand.copy()
            v[j:] = best_u
        s = rollout(s0, v, nlp.dt)
        return s, v, nlp.evaluate(s, v, ref, obs)

    def _fallback(self, t: float, s0: np.ndarray, guess: np.ndarray, ref: np.ndarray, obs: np.ndarray,
                  reason: str, iters: int, setup: float, solver_time: float, t_start: float) -> FhocpResult:
        """The shifted previous plan with a searched tail (zeros without one), rolled out from ``s0``, flagged."""
        s, v, ev = self._searched_tail(s0, np.where(np.isfinite(guess), guess, 0.0), self._kept_steps(t), ref, obs)
        msg = f"FHOCP at t={t:.3f} s failed ({reason}); returning the shifted previous plan"
        warnings.warn(msg, FallbackWarning, stacklevel=3)
        self._plan_t, self._plan_inputs = t, v.copy()
        return FhocpResult(status="fallback", states=s, inputs=v, cost=ev.cost, iterations=iters,
                           solve_time_s=time.perf_counter() - t_start, setup_time_s=setup,
                           max_violation=ev.max_violation, fallback=True, merit=ev.merit,
                           violations=ev.violations, solver_time_s=solver_time, t=t, message=msg)

    @property
    def parameters(self) -> dict[str, cp.Parameter]:
        """The cvxpy Parameters of the subproblem by name."""
        return dict(self._params)

    @property
    def variables(self) -> dict[str, cp.Variable]:
        """The main cvxpy Variables (x, y, z, psi, u, w, r, e_o) by name."""
        return dict(self._vars)
