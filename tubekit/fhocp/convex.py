"""The convex subproblem of one SCP iteration, built once in cvxpy with Parameters (DPP).

:class:`ConvexSubproblem` convexifies :class:`tubekit.fhocp.nlp.FhocpNlp` around a plan:

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
* with a backup (``nlp.backup_terminal``), its terminal rows at the last node about the anchor
  p_N + offset (the offset chosen at the linearisation's end, Parameter ``aT``), sharing one
  exact-penalty slack: each obstacle's half-space with the radius enlarged by the footprint's
  sphere (the same normal as the node's obstacle row), the workspace box shrunk by the
  footprint, and the sensed region as second-order cones; none of it is built without a backup;
* a box trust region on the input step, intersected with the input box [v_min, v_max] (Parameters
  ``ulo`` .. ``rhi``, written per linearisation);
* with a rate limit (``nlp.rate_jump``), the rate rows of :mod:`tubekit.fhocp.rows` (hard): the
  node-to-node steps and the terminal rest |v_{N-1} - c| <= J with constant J and constant c
  (``nlp.terminal_command``, fixed for the problem's life), the first node against the Parameter
  ``vlast`` with the Parameter bound ``jb`` (J, or a non-binding 2 V-bar when no v_last is given);
* with a rate penalty (``nlp.rate_penalty`` > 0), its quadratic in the objective (``vlast`` again).

The problem is built once; :meth:`ConvexSubproblem.linearise` writes every parameter
into one vector, which the fast path (:class:`tubekit.fhocp.fastpath.CompiledConeProgram`)
maps straight to its QP backend's data (:mod:`tubekit.fhocp.qp`), and
:meth:`ConvexSubproblem.push_parameters` copies into the cvxpy Parameters for ``problem.solve``.
"""

from __future__ import annotations

import math
from typing import Callable

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from tubekit.exceptions import ConfigError
from tubekit.fhocp.fastpath import CompiledConeProgram
from tubekit.fhocp.linearisation import ED_FLOOR, compiled
from tubekit.fhocp.nlp import FhocpNlp, rollout
from tubekit.fhocp.qp.base import ConeSolution, QpBackend
from tubekit.fhocp.qp.registry import DEFAULT_QP_BACKEND, make_qp_backend
from tubekit.fhocp.result import Status, status_from
from tubekit.fhocp.rows import backup_rows

__all__ = ["ConvexSubproblem", "DEFAULT_CLARABEL_SETTINGS", "REALTIME_CLARABEL_SETTINGS", "CVXPY_STATUS"]


#: Clarabel settings used by default (looser than Clarabel's 1e-8: the SCP's own tolerance is 1e-5)
DEFAULT_CLARABEL_SETTINGS: dict = {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7}
#: What the real-time mode puts on top (``tubekit.fhocp.scp.FHOCP``, before the user's overrides): gap and
#: feasibility 1e-6 without iterative refinement. Chosen on 15,025 recorded real-time subproblems of every shipped
#: scenario (``benchmarks/clarabel_settings.py``): 0 failures, 1 ``AlmostSolved``, plans within 0.031 of the 1e-7
#: setting's, the bare solve about 40 % faster; the exact plan check decides every plan. Tolerance and refinement
#: move together: 1e-7 without refinement ended 695 of them ``AlmostSolved``. The converged mode keeps the
#: default (at 1e-6 its SCP stopped 4.6 % above IPOPT's optimum on a state where 1e-7 reaches it).
REALTIME_CLARABEL_SETTINGS: dict = {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-6,
                                    "iterative_refinement_enable": False}

#: cvxpy's ``problem.status`` -> :class:`Status`; any other is SOLVER_ERROR
CVXPY_STATUS: dict[str, Status] = {
    cp.settings.OPTIMAL: Status.OPTIMAL,
    cp.settings.OPTIMAL_INACCURATE: Status.OPTIMAL_INACCURATE,
    cp.settings.INFEASIBLE: Status.INFEASIBLE,
    cp.settings.INFEASIBLE_INACCURATE: Status.INFEASIBLE_INACCURATE,
    cp.settings.UNBOUNDED: Status.UNBOUNDED,
    cp.settings.UNBOUNDED_INACCURATE: Status.UNBOUNDED_INACCURATE,
    cp.settings.INFEASIBLE_OR_UNBOUNDED: Status.INFEASIBLE_OR_UNBOUNDED,
    cp.settings.USER_LIMIT: Status.USER_LIMIT,
    cp.settings.SOLVER_ERROR: Status.SOLVER_ERROR,
}

_DYN_KEYS = ("ax", "bxu", "bxr", "cx", "ay", "byu", "byr", "cy")
_SLACKS = ("e_d_min", "obstacle", "e_o", "box")
_Par = Callable[[str, int], cp.Parameter]


class ConvexSubproblem:
    """The parametrised convex subproblem (DPP), built once, re-solved with new parameter values.

    The variables are the samples k = 1..N in a frame translated to the measured
    position, with the heading measured from the measured heading (the measured
    state itself is not a variable); the translation and the heading offset move
    into the parameters, so every datum is O(1) near the solution.

    Parameters
    ----------
    nlp : FhocpNlp
        The nonlinear program being convexified.
    max_obstacles : int
        Obstacle slots (inactive slots get a constraint 0 >= -1).
    neutral_state : array (4,)
        A state (m, rad) to give every parameter a first value from (a zero-input plan).
    neutral_reference : array (N+1, 3)
        p_d along that plan (m).
    trust_radius : float
        Trust radius (fraction of V-bar) of that first linearisation.
    fast_path : bool
        Re-solve through the compiled map + a persistent QP backend (``qp_backend``); False uses
        ``problem.solve(solver=cp.CLARABEL)``.
    clarabel_settings : dict, optional
        Overrides of :data:`DEFAULT_CLARABEL_SETTINGS` (for Clarabel on either path, including as the
        cone fallback of a QP backend without cones).
    qp_backend : str or QpBackend
        The fast path's backend (:mod:`tubekit.fhocp.qp`): a registered name (default ``"clarabel"``;
        ``"piqp"`` is wrapped in the relaxation wrapper since it takes no cones) or an instance, through
        :func:`tubekit.fhocp.qp.registry.make_qp_backend`. Only ``"clarabel"`` without the fast path.
    backend_settings : dict, optional
        Per backend name, its setting overrides for a named ``qp_backend`` other than Clarabel (whose are
        ``clarabel_settings``), e.g. ``{"qocogen": {"abstol": 1e-6}}``.

    Attributes
    ----------
    problem : cvxpy.Problem
        The subproblem.
    compiled : CompiledConeProgram or None
        The fast path (None when ``fast_path=False``).
    param_vector : array
        Every parameter's value, written by :meth:`linearise`.
    """

    def __init__(self, nlp: FhocpNlp, max_obstacles: int, neutral_state: np.ndarray,
                 neutral_reference: np.ndarray, trust_radius: float, *, fast_path: bool = True,
                 clarabel_settings: dict | None = None, qp_backend: str | QpBackend = DEFAULT_QP_BACKEND,
                 backend_settings: dict[str, dict] | None = None) -> None:
        if not fast_path and qp_backend != DEFAULT_QP_BACKEND:
            raise ConfigError("qp_backend", f"{DEFAULT_QP_BACKEND!r} when fast_path=False (the QP backends read "
                              "the compiled data)", qp_backend)
        self.nlp = nlp
        self.max_obstacles = max_obstacles
        N = nlp.n
        # weights: dt*Q on samples 0..N-1, P on sample N (left rectangle rule + terminal cost)
        self._weights = np.vstack([np.tile(nlp.dt * nlp.q, (N, 1)), nlp.p])   # (N+1, 3) for k = 0..N
        self._wref = self._weights[1:, (0, 0, 1)].T  # (3, N) weights of x, y, z at k = 1..N
        self._anchor_offset = np.zeros(3)  # the backup anchor's offset from p_N in this linearisation (m)
        self._end_velocity: np.ndarray | None = None  # the target's velocity at the plan's end (m/s), for the row faces
        self._lookahead = nlp.lookahead_margins()  # (N,) m added to the nodes' obstacle rows (controller.lookahead)
        self._build()
        self.clarabel_settings = {**DEFAULT_CLARABEL_SETTINGS, **(clarabel_settings or {})}
        self.compiled: CompiledConeProgram | None = None
        if fast_path:
            backend = make_qp_backend(qp_backend, {**(backend_settings or {}), "clarabel": self.clarabel_settings})
            self.compiled = CompiledConeProgram(self.problem, backend=backend)
        self._layout()
        self.linearise(neutral_state, rollout(neutral_state, np.zeros((N, 3)), nlp.dt), np.zeros((N, 3)),
                       neutral_reference, np.zeros((0, 4)), trust_radius)
        self.write_last_command(np.zeros(3), False)
        self.push_parameters()

    # ------------------------------------------------------------- building
    def _build(self) -> None:
        """Build the cvxpy problem (once); creation order fixes the compiled data layout."""
        N = self.nlp.n
        params: dict[str, cp.Parameter] = {}
        self._params = params

        def par(name: str, size: int) -> cp.Parameter:
            params[name] = cp.Parameter(size, name=name)
            return params[name]

        v = {n: cp.Variable(N, name=n) for n in ("x", "y", "z", "psi", "u", "w", "r")}
        v["e_o"] = cp.Variable(N, name="e_o")
        slack = {n: cp.Variable(N, name=f"slack_{n}") for n in _SLACKS}
        cons = self._model_rows(par, v, slack)
        if self.nlp.rate_jump is not None or self.nlp.rate_penalty > 0:
            par("vlast", 3)
        if self.nlp.rate_jump is not None:
            cons += self._rate_rows(par, v)
        for j in range(self.max_obstacles):
            ox, oy, oz, ro = par(f"ox{j}", N), par(f"oy{j}", N), par(f"oz{j}", N), par(f"ro{j}", N)
            cons.append(cp.multiply(ox, v["x"]) + cp.multiply(oy, v["y"]) + cp.multiply(oz, v["z"])
                        + slack["obstacle"] >= ro)
        cons += self._box_rows(par, v, slack)
        terminal_rows, sig_t = self._terminal_rows(par, v)
        cons += terminal_rows
        objective = self._objective(par, v, slack, sig_t)
        if self.nlp.backup_terminal is not None:
            backup_rows, sig_b = self._backup_rows(par, v)
            cons += backup_rows
            objective = objective + self.nlp.penalty * sig_b
        self.problem = cp.Problem(cp.Minimize(objective), cons)
        self._params = params
        self._vars = v

    def _model_rows(self, par: _Par, v: dict, slack: dict) -> list:
        """Linearised dynamics, the e_o model, the input box / trust region and the e_d half-spaces."""
        N, dt = self.nlp.n, self.nlp.dt
        x, y, z, psi, u, w, r, eo = (v[k] for k in ("x", "y", "z", "psi", "u", "w", "r", "e_o"))
        dyn = {k: par(k, N) for k in _DYN_KEYS}
        gx, gy, gpsi, h = par("gx", N), par("gy", N), par("gpsi", N), par("h", N)
        nx, ny, red, rdx = par("nx", N), par("ny", N), par("red", N), par("rdx", N)
        bounds = {k: par(k, N) for k in ("ulo", "uhi", "wlo", "whi", "rlo", "rhi")}
        shift = sp.diags(np.ones(N - 1), -1, shape=(N, N), format="csc") if N > 1 else sp.csc_matrix((1, 1))
        diff = sp.identity(N, format="csc") - shift   # (D s)_k = s_k - s_{k-1}, s_0 = 0 in this frame
        return [
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
            cp.multiply(nx, x) + cp.multiply(ny, y) + slack["e_d_min"] >= red,
            cp.multiply(nx, x) + cp.multiply(ny, y) - slack["box"] <= rdx,
        ]

    def _rate_rows(self, par: _Par, v: dict) -> list:
        """|v_{k+1} - v_k| <= J, |v_0 - vlast| <= jb and (terminal rest) |v_{N-1} - c| <= J, per component
        (c = ``nlp.terminal_command``: constants, as J, so the problem stays DPP)."""
        nlp, N = self.nlp, self.nlp.n
        vlast, jb = self._params["vlast"], par("jb", 3)
        cons = []
        for c, name in enumerate(("u", "w", "r")):
            var, jump = v[name], float(nlp.rate_jump[c])
            if N > 1:
                cons += [var[1:] - var[:-1] <= jump, var[:-1] - var[1:] <= jump]
            cons += [var[0] - vlast[c] <= jb[c], vlast[c] - var[0] <= jb[c]]
            if nlp.terminal_rest:
                command = float(nlp.terminal_command[c])
                cons += [var[N - 1] <= command + jump, -var[N - 1] <= jump - command]
        return cons

    def _box_rows(self, par: _Par, v: dict, slack: dict) -> list:
        """|e_o| <= e_o_max, |e_z| <= e_z_max with the z walls, the nearer x/y walls, slacks >= 0."""
        nlp, N = self.nlp, self.nlp.n
        eo, z, sig_box = v["e_o"], v["z"], slack["box"]
        cap = nlp.node_bounds()["e_o"]
        cons = [
            eo <= cap + slack["e_o"],
            -eo <= cap + slack["e_o"],
            # |e_z| <= e_z_max and the z walls share a row: z <= min(zd + e_z_max, hi_z - c), etc.
            z - sig_box <= par("zhi", N),
            z + sig_box >= par("zlo", N),
        ]
        if nlp.workspace is not None:
            # x/y walls: only the nearer wall per axis can be reached within the horizon
            # (checked by FHOCP), so one row per axis: sgn * p <= bound.
            cons += [cp.multiply(par("wsx", N), v["x"]) - sig_box <= par("wbx", N),
                     cp.multiply(par("wsy", N), v["y"]) - sig_box <= par("wby", N)]
        cons += [slack[n] >= 0 for n in _SLACKS]
        return cons

    def _terminal_rows(self, par: _Par, v: dict) -> tuple[list, cp.Variable | None]:
        """The terminal set as a second-order cone ("soft": with its slack), or nothing ("off")."""
        nlp, N = self.nlp, self.nlp.n
        if nlp.terminal == "off":
            return [], None
        pdn = par("pdN", 3)
        sp_ = np.sqrt(nlp.p)
        x, y, z, eo = v["x"], v["y"], v["z"], v["e_o"]
        terminal_vec = cp.hstack([sp_[0] * (x[N - 1] - pdn[0]), sp_[0] * (y[N - 1] - pdn[1]),
                                  sp_[1] * (z[N - 1] - pdn[2]), sp_[2] * eo[N - 1]])
        if nlp.terminal == "soft":
            sig_t = cp.Variable(name="slack_terminal")
            return [sig_t >= 0, cp.SOC(nlp.terminal_level + sig_t, terminal_vec)], sig_t
        return [cp.SOC(cp.Constant(nlp.terminal_level), terminal_vec)], None

    def _backup_rows(self, par: _Par, v: dict) -> tuple[list, cp.Variable]:
        """The backup's terminal rows at the last node (module doc, :func:`tubekit.fhocp.rows.backup_rows`)."""
        N = self.nlp.n
        normals = [tuple(self._params[f"{a}{j}"][N - 1] for a in ("ox", "oy", "oz")) for j in range(self.max_obstacles)]
        return backup_rows(self.nlp.backup_terminal, (v["x"][N - 1], v["y"][N - 1], v["z"][N - 1]), normals, par,
                           self.nlp.workspace is not None)

    def _objective(self, par: _Par, v: dict, slack: dict, sig_t: cp.Variable | None) -> cp.Expression:
        """Quadratic tracking cost + input cost + exact penalties.

        (x - xd)' W (x - xd) = x' W x + lx' x + c0 with lx = -2 W xd and c0 = xd' W xd (plus
        the constant k = 0 terms) as parameters: quad_form with a constant matrix and a bare
        variable needs no auxiliary variables, and the objective stays DPP.
        """
        nlp, N, dt = self.nlp, self.nlp.n, self.nlp.dt
        x, y, z, u, w, r, eo = (v[k] for k in ("x", "y", "z", "u", "w", "r", "e_o"))
        lin = {k: par(k, N) for k in ("lx", "ly", "lz")}
        c0 = par("c0", 1)
        w1 = self._weights[1:]
        cost = (cp.quad_form(x, np.diag(w1[:, 0])) + cp.quad_form(y, np.diag(w1[:, 0]))
                + cp.quad_form(z, np.diag(w1[:, 1])) + cp.quad_form(eo, np.diag(w1[:, 2]))
                + lin["lx"] @ x + lin["ly"] @ y + lin["lz"] @ z + cp.sum(c0)
                + dt * (nlp.r[0] * cp.sum_squares(u) + nlp.r[1] * cp.sum_squares(w)
                        + nlp.r[2] * cp.sum_squares(r))
                + nlp.penalty * (cp.sum(slack["e_d_min"]) + cp.sum(slack["obstacle"]) + cp.sum(slack["e_o"])
                                 + cp.sum(slack["box"])))
        if sig_t is not None:
            cost = cost + nlp.terminal_penalty * sig_t
        if nlp.rate_penalty > 0:
            vlast = self._params["vlast"]
            for c, var in enumerate((u, w, r)):
                steps = cp.sum_squares(var[1:] - var[:-1]) if N > 1 else 0
                cost = cost + nlp.rate_penalty * nlp.r[c] * (steps + cp.square(var[0] - vlast[c]))
        return cost

    def _layout(self) -> None:
        """Columns of every parameter in :attr:`param_vector`, grouped as :meth:`linearise` writes them."""
        used = {p.id for p in self.problem.parameters()}
        if self.compiled is not None:
            self.param_vector = self.compiled.param_vector
            self._cols = {name: self.compiled.columns(p) for name, p in self._params.items() if p.id in used}
            self._uwr_cols = np.stack([self.compiled.columns_of(self._vars[k]) for k in ("u", "w", "r")])
        else:
            live = {name: p for name, p in self._params.items() if p.id in used}
            self.param_vector = np.zeros(sum(p.size for p in live.values()))
            self._cols, start = {}, 0
            for name, p in live.items():
                self._cols[name] = np.arange(start, start + p.size)
                start += p.size
        nlp, M = self.nlp, self.max_obstacles
        groups = {"dyn": list(_DYN_KEYS), "lin": ["lx", "ly", "lz"],
                  "pdN": ["pdN"] if nlp.terminal != "off" else [],
                  "eo": ["gx", "gy", "gpsi", "h"], "step": ["nx", "ny", "red", "rdx", "zlo", "zhi"],
                  "bounds": ["ulo", "uhi", "wlo", "whi", "rlo", "rhi"],
                  "obs": [f"{a}{j}" for j in range(M) for a in ("ox", "oy", "oz", "ro")],
                  "walls": ["wsx", "wbx", "wsy", "wby"] if nlp.workspace is not None else [],
                  "c0": ["c0"],
                  "obsT": [f"rt{j}" for j in range(M)] if nlp.backup_terminal is not None else [],
                  "vlast": ["vlast"] if "vlast" in self._cols else [], "jb": ["jb"] if "jb" in self._cols else [],
                  "wallT": ["wT"] if nlp.backup_terminal is not None and nlp.workspace is not None else [],
                  "anchorT": ["aT"] if nlp.backup_terminal is not None else []}
        self._gidx = {g: np.concatenate([self._cols[n] for n in names]) if names else np.zeros(0, dtype=int)
                      for g, names in groups.items()}
        self._write_at = np.concatenate([self._gidx[g] for g in ("dyn", "lin", "eo", "step", "obs", "bounds")])
        nodes = nlp.node_bounds()
        self._node_rows = np.stack([nodes["e_d_lo"], nodes["e_d_hi"], nodes["e_z"]])

    def push_parameters(self) -> None:
        """Copy :attr:`param_vector` into the cvxpy Parameters' values (for ``problem.solve``)."""
        for name, p in self._params.items():
            if name in self._cols:
                p.value = self.param_vector[self._cols[name]].reshape(p.shape, order="F")
            else:  # not in the compiled problem (unused): any value
                p.value = np.zeros(p.shape)

    # ------------------------------------------------------- linearisation
    def linearise(self, s0: np.ndarray, s: np.ndarray, v: np.ndarray, ref: np.ndarray,
                  obs: np.ndarray, radius: float) -> None:
        """Write the parameters for the plan (s, v) into :attr:`param_vector`.

        Parameters
        ----------
        s0 : array (4,)
            Measured state (m, rad): the origin of the frame and of the heading variable.
        s, v : array (N+1, 4), array (N, 3)
            The plan (states, inputs) to linearise around.
        ref : array (N+1, 3)
            p_d at the samples (m).
        obs : array (K, 4)
            Obstacles [cx, cy, cz, radius] (m), K <= max_obstacles.
        radius : float
            Trust radius, a fraction of V-bar per input component.
        """
        o = s0[:3]
        psi0 = s0[3]
        nlp = self.nlp
        bt = nlp.backup_terminal
        self._anchor_offset = (np.zeros(3) if bt is None
                               else bt.best_offset(o, np.asarray(s[-1, :3], dtype=float), obs, nlp.workspace))
        if bt is not None:
            self.param_vector[self._gidx["anchorT"]] = self._anchor_offset[:2]
        s = s.copy()
        s[:, :3] -= o
        ref = ref - o
        z_lo, z_hi = -math.inf, math.inf
        if nlp.workspace is not None:
            z_lo, z_hi = self._write_walls(o)
        eo0 = compiled()[1].subproblem_rows(self.param_vector, self._write_at, s, v, ref, psi0, nlp.dt, self._wref,
                                            self._node_rows, z_lo, z_hi, obs[:, :3] - o,
                                            np.ascontiguousarray(obs[:, 3]), nlp.clearance, self.max_obstacles,
                                            radius, nlp.v_min, nlp.v_max, ED_FLOOR)
        self._write_cost_constants(ref, eo0)
        if bt is not None and self.max_obstacles:
            self._write_backup_obstacles(len(obs))
        if nlp.terminal_rows is not None and self._end_velocity is not None:
            self._write_last_row(s[-1] + np.array([o[0], o[1], o[2], 0.0]), ref[-1] + o)

    def write_target_velocity(self, velocity: np.ndarray | None) -> None:
        """The target's velocity (3,) at the plan's end (m/s), read by the last row's face box
        (:meth:`tubekit.fhocp.nlp.FhocpNlp.last_row_box`); None: the box is not written."""
        self._end_velocity = None if velocity is None else np.asarray(velocity, dtype=float).reshape(3)

    def _write_last_row(self, end: np.ndarray, p_end: np.ndarray) -> None:
        """The last row's bounds intersected with the row faces' box about the law's row at the linearisation's
        end; where they do not meet, pinned to the end of the trust box nearest the faces (the subproblem stays
        feasible and the plan moves toward them)."""
        lo, hi = self.nlp.last_row_box(end, p_end, self._end_velocity)
        pv, last = self.param_vector, self.nlp.n - 1
        for c, (name_lo, name_hi) in enumerate((("ulo", "uhi"), ("wlo", "whi"), ("rlo", "rhi"))):
            i_lo, i_hi = self._cols[name_lo][last], self._cols[name_hi][last]
            a, b = pv[i_lo], pv[i_hi]
            new_lo = min(max(a, lo[c]), b)
            pv[i_lo], pv[i_hi] = new_lo, max(min(b, hi[c]), new_lo)

    def _write_cost_constants(self, ref: np.ndarray, eo0: float) -> None:
        """p_d(N) of the terminal set and the cost's constant term (node 0 and the reference's squares)."""
        pvec, gidx = self.param_vector, self._gidx
        r1 = ref[1:]
        if self.nlp.terminal != "off":
            pvec[gidx["pdN"]] = ref[self.nlp.n]
        e0 = (ref[0, 0] ** 2 + ref[0, 1] ** 2, ref[0, 2] ** 2, eo0 ** 2)  # k = 0 (constant)
        pvec[gidx["c0"]] = float(np.einsum("ck,kc->", self._wref, r1 * r1) + self._weights[0] @ e0)

    def _write_walls(self, o: np.ndarray) -> tuple[float, float]:
        """The nearer wall per horizontal axis and the backup's footprint inside the box; returns the depth
        bounds (m) relative to the measured position ``o``."""
        nlp, N = self.nlp, self.nlp.n
        lo = nlp.workspace[0] + nlp.clearance - o
        hi = nlp.workspace[1] - nlp.clearance - o
        walls = [1.0, hi[0], 1.0, hi[1]]  # the nearer wall per axis (the origin is the measured position)
        for i in (0, 1):
            if -lo[i] < hi[i]:
                walls[2 * i], walls[2 * i + 1] = -1.0, -lo[i]
        self.param_vector[self._gidx["walls"]] = np.repeat(walls, N)
        if nlp.backup_terminal is not None:
            r_f, h_f = nlp.backup_terminal.footprint
            pad = np.array([r_f, r_f, h_f])
            shift = o + self._anchor_offset  # the rows hold the anchor p_N + offset inside the box
            self.param_vector[self._gidx["wallT"]] = np.concatenate([nlp.workspace[0] + pad - shift,
                                                                     nlp.workspace[1] - pad - shift])
        return float(lo[2]), float(hi[2])

    def _write_backup_obstacles(self, k: int) -> None:
        """The last node's obstacle half-spaces moved to the footprint's sphere about the anchor (``k`` obstacles
        in the problem; the other slots stay inactive)."""
        ob = self.param_vector[self._gidx["obs"]].reshape(self.max_obstacles, 4, self.nlp.n)
        shift = ob[:, 0, -1] * self._anchor_offset[0] + ob[:, 1, -1] * self._anchor_offset[1]
        self.param_vector[self._gidx["obsT"]] = ob[:, 3, -1] + np.where(
            np.arange(self.max_obstacles) < k, self.nlp.backup_terminal.sphere - self.nlp.clearance - shift, 0.0)
        if self.nlp.lookahead > 0.0 and k:  # the nodes' rows keep a growing share of the footprint too
            ob[:k, 3, :] += self._lookahead
            self.param_vector[self._gidx["obs"]] = ob.reshape(-1)

    def write_last_command(self, v_last: np.ndarray, first_row: bool) -> None:
        """Write ``vlast`` (the rate rows' and the rate penalty's v_last, (3,)) and the bound ``jb`` of
        row (b): J when ``first_row``, else 2 V-bar (never binding); no-op without those rows."""
        gidx, nlp = self._gidx, self.nlp
        if gidx["vlast"].size:
            self.param_vector[gidx["vlast"]] = v_last
        if gidx["jb"].size:
            self.param_vector[gidx["jb"]] = nlp.rate_jump if first_row else 2.0 * nlp.v_max

    # ---------------------------------------------------------------- solve
    def solve(self) -> tuple[Status, np.ndarray | None, float, float]:
        """Solve at the current parameters: (status, inputs (N, 3) or None, model objective, solver time (s))."""
        if self.compiled is not None:
            sol: ConeSolution = self.compiled.solve()
            if sol.x is None:
                return sol.status, None, math.nan, sol.solver_time_s
            return sol.status, sol.x[self._uwr_cols].T, sol.objective, sol.solver_time_s
        self.push_parameters()
        opts = {"presolve_enable": False, "chordal_decomposition_enable": False}
        opts.update(self.clarabel_settings)
        try:
            self.problem.solve(solver=cp.CLARABEL, **opts)
        except cp.error.SolverError:
            return Status.SOLVER_ERROR, None, math.nan, 0.0
        status = status_from(CVXPY_STATUS, self.problem.status)
        stime = float(self.problem.solver_stats.solve_time or 0.0)
        if not status.solved:
            return status, None, math.nan, stime
        v = np.stack([self._vars[k].value for k in ("u", "w", "r")], axis=1)
        return status, v, float(self.problem.value), stime

    @property
    def parameters(self) -> dict[str, cp.Parameter]:
        """The cvxpy Parameters by name."""
        return dict(self._params)

    @property
    def variables(self) -> dict[str, cp.Variable]:
        """The main cvxpy Variables (x, y, z, psi, u, w, r, e_o) by name."""
        return dict(self._vars)
