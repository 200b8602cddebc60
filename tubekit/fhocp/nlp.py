"""The discretised FHOCP of Section V as a nonlinear program (NLP).

This module is the single definition of the NLP that both the sequential
convex programming solver (:mod:`tubekit.fhocp.scp`) and its CasADi + IPOPT peer
(:mod:`tubekit.fhocp.ipopt`) solve; both evaluate their answers with
:meth:`FhocpNlp.evaluate`.

Discretisation
--------------
The nominal state is kept in absolute coordinates ``s = [x, y, z, psi]``
(the error e alone does not determine the bearing). Inputs are piecewise
constant over ``dt`` (zero-order hold) and each step is the *exact* flow of
the unicycle kinematics for a constant input::

    a = r dt / 2,   S(a) = sin(a) / a
    x+ = x + u dt S(a) cos(psi + a),   y+ = y + u dt S(a) sin(psi + a)
    z+ = z + w dt,                     psi+ = psi + r dt

so the local (one-step) error with respect to the continuous-time nominal
dynamics (eq. diff_mpc) under a zero-order-hold input is zero (round-off
only). The cost integral is a left rectangle rule, whose local error is
O(dt^2) per step (global O(dt)); state constraints are imposed at the N
samples k = 1..N (the inter-sample excursion ||p - p_hat|| is what
``Tightening.obstacle_margin`` covers).

NLP (k = 0..N-1 stages, e_k = error_coordinates(s_k, p_d(t + k dt)))::

    min  sum_k dt (Q1 e_d,k^2 + Q2 e_z,k^2 + Q3 e_o,k^2 + v_k' R v_k)
         + P1 e_d,N^2 + P2 e_z,N^2 + P3 e_o,N^2
         + mu sum_{k=1..N} (sig_ed,k + sig_obs,k + sig_eo,k + sig_box,k)
         + mu_T sig_T                                  (terminal "soft")
    s.t. s_0 = measured state,  s_{k+1} = F(s_k, v_k),  v_min <= v_k <= v_max,
         e_d,k >= e_d_min - sig_ed,k,
         ||p_k - c_j|| >= r_j + r_bar + margin - sig_obs,k     (each obstacle j),
         |e_o,k| <= e_o_max + sig_eo,k,
         e_d,k <= e_d_max + sig_box,k,  |e_z,k| <= e_z_max + sig_box,k,
         lo + r_bar + margin - sig_box,k <= p_k <= hi - r_bar - margin + sig_box,k,
         ||e_N||_P <= terminal_level + sig_T,   all sig >= 0.

With a certified backup (``tightening.backup``, :class:`BackupTerminal`) the last node also carries
the backup's terminal condition, softened by one slack sig_B (weight mu) shared by its rows::

         ||a - c_j|| >= r_j + hypot(R_f, H_f) - sig_B     (each obstacle j),   a = p_N + offset,
         lo + (R_f, R_f, H_f) - sig_B <= a <= hi - (R_f, R_f, H_f) + sig_B,
         hypot(||a_xy - p_0,xy|| + c, |z_N - z_0| + Z) <= R_bar - r_bar + sig_B,

(R_f, H_f) the safe set's footprint, c and Z its radius and depth, p_0 the measured position, the offset one
of the backup's anchor offsets (``BackupTerminal.best_offset``: 0 without an anchor reach): the sphere of
radius hypot(R_f, H_f) contains the footprint's cylinder, so a plan meeting these rows meets
:func:`tubekit.loop.terminal.terminal_condition` about that anchor, which ``tubekit.loop.plan_check`` checks.

The input box's lower corner v_min is -v_max unless the scenario has a minimum surge (``Tightening.v_low``).
With a rate limit the inputs also meet the rate rows of :mod:`tubekit.fhocp.rows` (hard, like the input box;
family ``rate``; the terminal rest about ``terminal_command``); the cost adds the rate penalty
lambda sum_c R_c (sum_k (v_k,c - v_{k-1},c)^2 + (v_0,c - v_last,c)^2) (lambda = ``rate_penalty``, s; 0 leaves
the cost as above).

Q, R, P are diagonal (the scenario's 3-vectors). The slacks are exact
(l1) penalties: whenever the hard-constrained problem is feasible and
``mu`` exceeds its multipliers the two have the same minimisers; the
violations are reported, never hidden. "hard" terminal mode fixes
``sig_T = 0``; "off" drops the terminal set (terminal *cost* stays).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.fhocp.rows import RATE_MARGIN, BackupTerminal, rate_penalty_cost, rate_violation
from tubekit.fhocp.linearisation import ED_FLOOR, compiled
from tubekit.model.kinematics import unicycle_step
from tubekit.model.terminal_law import TerminalLaw
from tubekit.scenario import Obstacle, Scenario, TerminalMode
from tubekit.tightening import Tightening
from tubekit.validation import as_vector, choice, positive

__all__ = ["TERMINAL_MODES", "TERMINAL_PAD", "ROW_FACE_PAD", "discrete_step", "rollout", "obstacle_array",
           "select_obstacles", "FhocpNlp", "NlpEvaluation", "BackupTerminal"]

TERMINAL_MODES: tuple[str, ...] = TerminalMode.values()
#: The share of X_f's widths (e_d band, heading room, depth band) by which the FHOCP's last node keeps inside the
#: tracking theorem's terminal set: a plan the solver ends on a face (to its tolerance) then passes the exact check.
TERMINAL_PAD = 0.01
#: The last row aims this fraction inside X_f's row faces (:meth:`FhocpNlp.last_row_box`).
ROW_FACE_PAD = 0.2


#: Exact zero-order-hold step F(s, v, dt) of the nominal kinematics (the model's own exact arc).
discrete_step = unicycle_step


def rollout(s0: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """States (N+1, 4) obtained by applying ``inputs`` (N, 3) from ``s0`` (4,) with :func:`discrete_step`
    (compiled: :func:`tubekit.model.compiled_arcs.rollout`, the same floats as chaining the step)."""
    return compiled()[0].rollout(np.asarray(s0, dtype=float), np.asarray(inputs, dtype=float), float(dt))


def obstacle_array(obstacles: Sequence[Obstacle] | np.ndarray) -> np.ndarray:
    """Obstacles as an (M, 4) array of [cx, cy, cz, radius] (m)."""
    if isinstance(obstacles, np.ndarray):
        arr = np.asarray(obstacles, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 4:
            raise ShapeError("obstacles", "(M, 4)", arr.shape)
        return arr
    rows = []
    for i, o in enumerate(obstacles):
        if not isinstance(o, Obstacle):
            raise ConfigError(f"obstacles[{i}]", "a tubekit.Obstacle", type(o).__name__)
        rows.append((*o.center, o.radius))
    return np.array(rows, dtype=float).reshape(-1, 4)


def select_obstacles(state: np.ndarray, obstacles: Sequence[Obstacle] | np.ndarray, sensing_range: float,
                     max_count: int) -> tuple[np.ndarray, int]:
    """The obstacles the FHOCP sees from ``state``: surface within ``sensing_range``, nearest first.

    Parameters
    ----------
    state : array (4,)
        Vehicle state; only its position is used (m).
    obstacles : sequence of Obstacle or array (M, 4)
        Candidates (the caller normally filters by range already).
    sensing_range : float
        R-bar (m): an obstacle is kept when ||p - c|| - radius <= R-bar.
    max_count : int
        Number of obstacle slots; the nearest ``max_count`` are kept.

    Returns
    -------
    (array (K, 4), int)
        The kept obstacles as [cx, cy, cz, radius] and how many in-range ones were dropped.
    """
    arr = obstacle_array(obstacles)
    if arr.size == 0:
        return arr.reshape(0, 4), 0
    gap = np.linalg.norm(arr[:, :3] - np.asarray(state, dtype=float)[:3], axis=1) - arr[:, 3]
    inside = np.flatnonzero(gap <= sensing_range)
    order = inside[np.argsort(gap[inside], kind="stable")]
    return arr[order[:max_count]], max(0, order.size - max_count)


@dataclass(frozen=True)
class NlpEvaluation:
    """The NLP's functions evaluated on one plan (units of the respective constraints).

    Attributes
    ----------
    cost : float
        Stage + terminal quadratic cost (no penalties).
    merit : float
        ``cost`` + the exact penalties = the NLP objective at its optimal slacks.
    violations : dict
        Largest violation per constraint family over k = 1..N: ``e_d_min``,
        ``obstacle``, ``e_o``, ``box`` (e_d_max, |e_z|, workspace),
        ``terminal`` (0 if off), ``input``, ``dynamics``.
    per_step : dict
        Per-step (N,) violations of the four slackened families.
    max_violation : float
        max over ``violations``.
    """

    cost: float
    merit: float
    violations: dict[str, float]
    per_step: dict[str, np.ndarray] = field(repr=False)
    max_violation: float


@dataclass(frozen=True)
class FhocpNlp:
    """The discretised FHOCP (see the module docstring) with all its constants.

    Attributes
    ----------
    dt : float
        Sampling period delta_t (s).
    horizon_steps : int
        N.
    q, r, p : array (3,)
        Diagonals of Q (on [e_d, e_z, e_o]), R (on [u, w, r]) and P.
    v_max : array (3,)
        Nominal input box V-bar: its upper corner (m/s, m/s, rad/s).
    e_d_min, e_d_max, e_z_max, e_o_max : float
        Tightened state bounds.
    clearance : float
        Vehicle radius + obstacle margin (m): added to each obstacle radius and
        kept from the workspace walls.
    workspace : array (2, 3) or None
        [lower, upper] corners (m).
    terminal : str
        One of :data:`TERMINAL_MODES`.
    terminal_level : float
        epsilon-bar of F = {||e||_P <= epsilon-bar}.
    penalty, terminal_penalty : float
        Exact-penalty weights mu (state-constraint slacks: obstacles, e_d, e_o, e_z,
        workspace) and mu_T (soft terminal set). Default mu_T = mu / 20: the safety
        slacks outrank the terminal set, so an unreachable F never pulls the plan into
        an obstacle (with mu_T = mu the paper's default run grazed an obstacle by 14 mm).
    backup_terminal : BackupTerminal or None
        The backup's terminal rows at the last node (None: none, the problem of a tightening
        without a backup).
    rate_jump : array (3,) or None
        The imposed J (1 - RATE_MARGIN) of the rate rows (None: no rate limit).
    terminal_rest : bool
        Impose |v_{N-1} - terminal_command| <= J (with a rate limit and a certified backup that does not blend,
        ``Tightening.terminal_rest``; a ramped backup blends from the last command instead).
    rate_penalty : float
        lambda (s, >= 0) of the rate penalty.
    tracking_terminal : (d_lo, d_hi, e_o_f, z_f) or None
        The tracking theorem's terminal set X_f at the last node (m, m, -, m): d_lo <= e_d <= d_hi,
        |e_o| <= e_o_f, |e_z| <= z_f (``Tightening.terminal_law``; :meth:`node_bounds`).
    v_min : array (3,) or None
        The box's lower corner (m/s, m/s, rad/s), in [-v_max, v_max]: ``Tightening.v_low`` (a surge floor with
        ``limits.u_min``). None (default): -v_max, the symmetric box; always an array after construction.
    terminal_command : array (3,) or None
        The command c of the terminal rest |v_{N-1} - c| <= J (m/s, m/s, rad/s): ``Tightening.terminal_command``
        (0 for station keeping, (u_l, 0, 0) for the loiter). None (default): zeros; always an array after
        construction.
    terminal_rows : TerminalLaw or None
        The tracking theorem's terminal law when its X_f has row faces (rate-limited plans): the last row is kept
        within (1 - ROW_FACE_PAD) S of the law's row at the linearisation's end (:meth:`last_row_box`; a planning
        aid like the pad on X_f, the exact check decides). None: no such rows.
    lookahead : float
        lambda_f >= 0 (``controller.lookahead``): node k's obstacle rows also keep lambda_f k/N of the backup's
        footprint (:meth:`lookahead_margins`), so a plan turns away from an obstacle before its end has to; a
        planning preference, not a certificate input (plans are accepted by the exact check alone). 0: off.
    """

    dt: float
    horizon_steps: int
    q: np.ndarray
    r: np.ndarray
    p: np.ndarray
    v_max: np.ndarray
    e_d_min: float
    e_d_max: float
    e_z_max: float
    e_o_max: float
    clearance: float
    workspace: np.ndarray | None
    terminal: TerminalMode = TerminalMode.SOFT
    terminal_level: float = 2.0
    penalty: float = 1e3
    terminal_penalty: float = 50.0
    backup_terminal: BackupTerminal | None = None
    rate_jump: np.ndarray | None = None
    terminal_rest: bool = False
    rate_penalty: float = 0.0
    tracking_terminal: tuple[float, float, float, float] | None = None
    v_min: np.ndarray | None = None
    terminal_command: np.ndarray | None = None
    lookahead: float = 0.0
    terminal_rows: TerminalLaw | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", positive("dt", self.dt))
        if not isinstance(self.horizon_steps, int) or self.horizon_steps < 1:
            raise ConfigError("horizon_steps", "an integer >= 1", self.horizon_steps)
        for name in ("q", "r", "p", "v_max"):
            vec = as_vector(name, getattr(self, name), 3)
            if np.any(vec <= 0):
                raise ConfigError(name, "three numbers > 0", getattr(self, name))
            object.__setattr__(self, name, vec)
        for name in ("e_d_min", "e_d_max", "e_z_max", "e_o_max", "terminal_level", "penalty",
                     "terminal_penalty"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        if self.e_d_max <= self.e_d_min:
            raise ConfigError("e_d_max", f"a number > e_d_min = {self.e_d_min}", self.e_d_max)
        if self.clearance < 0 or not math.isfinite(self.clearance):
            raise ConfigError("clearance", "a finite number >= 0", self.clearance)
        object.__setattr__(self, "terminal", choice("terminal", TerminalMode, self.terminal))
        if self.workspace is not None:
            ws = np.asarray(self.workspace, dtype=float)
            if ws.shape != (2, 3):
                raise ShapeError("workspace", "(2, 3)", ws.shape)
            object.__setattr__(self, "workspace", ws)
        # per-sample weights of e_d^2, e_z^2, e_o^2: dt*Q for k < N, P for k = N, shape (3, N+1)
        w = np.empty((3, self.horizon_steps + 1))
        w[:, :-1] = (self.dt * self.q)[:, None]
        w[:, -1] = self.p
        object.__setattr__(self, "_w", w)
        object.__setattr__(self, "_dt_r", self.dt * self.r)
        if self.rate_jump is not None:
            jump = as_vector("rate_jump", self.rate_jump, 3)
            if np.any(jump <= 0):
                raise ConfigError("rate_jump", "three numbers > 0", self.rate_jump)
            object.__setattr__(self, "rate_jump", jump)
        if self.rate_penalty < 0 or not math.isfinite(self.rate_penalty):
            raise ConfigError("rate_penalty", "a finite number >= 0", self.rate_penalty)
        if self.lookahead < 0 or not math.isfinite(self.lookahead):
            raise ConfigError("lookahead", "a finite number >= 0", self.lookahead)
        object.__setattr__(self, "_rate_w", self.rate_penalty * self.r)
        self._set_lower_corner()
        object.__setattr__(self, "_nodes", self._node_bounds())
        object.__setattr__(self, "_violation_bounds", np.array([self.e_d_min, self.e_d_max, self.e_z_max,
                                                                self.e_o_max, self.clearance]))
        object.__setattr__(self, "_workspace_rows", np.zeros((0, 3)) if self.workspace is None else self.workspace)

    def _set_lower_corner(self) -> None:
        """Fill ``v_min`` (-v_max when None) and ``terminal_command`` (zeros when None), validated."""
        if self.v_min is None:
            object.__setattr__(self, "v_min", -self.v_max)
        else:
            low = as_vector("v_min", self.v_min, 3)
            if not (np.all(np.isfinite(low)) and np.all(low >= -self.v_max) and np.all(low <= self.v_max)):
                raise ConfigError("v_min", f"three numbers in [-v_max, v_max], v_max = {self.v_max.tolist()}",
                                  self.v_min)
            object.__setattr__(self, "v_min", low)
        command = np.zeros(3) if self.terminal_command is None else as_vector("terminal_command",
                                                                              self.terminal_command, 3)
        if not np.all(np.isfinite(command)):
            raise ConfigError("terminal_command", "three finite numbers", self.terminal_command)
        object.__setattr__(self, "terminal_command", command)

    @classmethod
    def from_scenario(cls, scenario: Scenario, tightening: Tightening, *, terminal: TerminalMode | str = "soft",
                      penalty: float = 1e3, terminal_penalty: float | None = None,
                      rate_penalty: float = 0.0) -> "FhocpNlp":
        """The NLP of ``scenario`` (weights, horizon, workspace, rate limit) with the sets of ``tightening``."""
        if not isinstance(scenario, Scenario):
            raise ConfigError("scenario", "a tubekit.Scenario", type(scenario).__name__)
        if not isinstance(tightening, Tightening):
            raise ConfigError("tightening", "a tubekit.Tightening", type(tightening).__name__)
        c = scenario.controller
        ws = None if scenario.workspace is None else np.array(scenario.workspace, dtype=float)
        jump = scenario.limits.jump(c.dt)
        backup = BackupTerminal.of(scenario, tightening)
        margin = float(tightening.obstacle_margin)
        if not math.isfinite(margin) or margin < 0:
            raise ConfigError("tightening.obstacle_margin", "a finite number >= 0", margin)
        return cls(dt=c.dt, horizon_steps=c.horizon_steps, q=np.array(c.Q), r=np.array(c.R),
                   p=np.array(c.P), v_max=np.asarray(tightening.v_max, dtype=float),
                   e_d_min=tightening.e_d_min, e_d_max=tightening.e_d_max, e_z_max=tightening.e_z_max,
                   e_o_max=tightening.e_o_max, clearance=scenario.vehicle_radius + margin,
                   workspace=ws, terminal=terminal, terminal_level=c.terminal_level,
                   penalty=penalty,
                   terminal_penalty=penalty / 20.0 if terminal_penalty is None else terminal_penalty,
                   backup_terminal=backup, rate_jump=None if jump is None else jump * (1.0 - RATE_MARGIN),
                   terminal_rest=jump is not None and tightening.terminal_rest, rate_penalty=rate_penalty,
                   tracking_terminal=_tracking_terminal(tightening), v_min=tightening.v_low,
                   terminal_command=tightening.terminal_command, lookahead=c.lookahead,
                   terminal_rows=_terminal_rows(tightening))

    def last_row_box(self, end: np.ndarray, p_end: np.ndarray, v_end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) (3,) of the last row: the law's row at the plan's end ``end`` (4,) against the target's
        ``p_end``, ``v_end`` (3,) at that time, widened by (1 - ROW_FACE_PAD) of the row faces S
        (m/s, m/s, rad/s). Only with :attr:`terminal_rows`."""
        law = self.terminal_rows
        if law is None:
            raise ValueError("last_row_box: this NLP has no row faces")
        row = law.command(np.asarray(end, dtype=float), np.asarray(p_end, dtype=float),
                          np.asarray(v_end, dtype=float), self.dt)
        faces = (1.0 - ROW_FACE_PAD) * np.array([law.row_u, law.row_w, law.row_r])
        return row - faces, row + faces

    def lookahead_margins(self) -> np.ndarray:
        """(N,) distances (m) added to the clearance of node k = 1..N's obstacle rows: lambda_f (k/N) of the backup
        footprint's extent beyond the clearance (``backup_terminal.sphere`` - ``clearance``); zeros without a backup
        or with lookahead 0."""
        bt, n = self.backup_terminal, self.horizon_steps
        if bt is None or self.lookahead == 0.0:
            return np.zeros(n)
        return self.lookahead * max(0.0, bt.sphere - self.clearance) * np.arange(1, n + 1) / n

    def node_bounds(self) -> dict[str, np.ndarray]:
        """Per-node bounds (N,) ``e_d_lo``, ``e_d_hi``, ``e_z``, ``e_o``: the tightened sets, the last node
        narrowed to the tracking theorem's X_f when there is one (built once: the solver's step reads them)."""
        return self._nodes

    def _node_bounds(self) -> dict[str, np.ndarray]:
        n = self.horizon_steps
        out = {k: np.full(n, float(v)) for k, v in (("e_d_lo", self.e_d_min), ("e_d_hi", self.e_d_max),
                                                     ("e_z", self.e_z_max), ("e_o", self.e_o_max))}
        if self.tracking_terminal is not None:  # X_f shrunk by TERMINAL_PAD of its widths: plans that end on a
            d_lo, d_hi, e_o, z_f = self.tracking_terminal  # face pass the exact check despite the solver's tolerance
            pad = TERMINAL_PAD * (d_hi - d_lo)
            out["e_d_lo"][-1] = max(out["e_d_lo"][-1], d_lo + pad)
            out["e_d_hi"][-1] = min(out["e_d_hi"][-1], d_hi - pad)
            out["e_o"][-1] = min(out["e_o"][-1], (1 - TERMINAL_PAD) * e_o)
            out["e_z"][-1] = min(out["e_z"][-1], (1 - TERMINAL_PAD) * z_f)
        return out

    def clip(self, inputs: np.ndarray) -> np.ndarray:
        """``inputs`` (..., 3) clipped to the input box [v_min, v_max] (m/s, m/s, rad/s); a new array."""
        return np.clip(inputs, self.v_min, self.v_max)

    @property
    def n(self) -> int:
        """Horizon steps N."""
        return self.horizon_steps

    def reference(self, trajectory, t: float) -> np.ndarray:
        """p_d(t + k dt), k = 0..N, shape (N+1, 3) (m)."""
        return np.asarray(trajectory.position(t + self.dt * np.arange(self.n + 1)), dtype=float)

    def errors(self, states: np.ndarray, ref: np.ndarray) -> np.ndarray:
        """[e_d, e_z, e_o] (K, 3) of ``states`` (K, 4) w.r.t. ``ref`` (K, 3), e_d floored at 1e-9."""
        return compiled()[0].error_coordinates(np.asarray(states, dtype=float), np.asarray(ref, dtype=float), ED_FLOOR)

    def cost(self, states: np.ndarray, inputs: np.ndarray, ref: np.ndarray, v_last: np.ndarray | None = None) -> float:
        """Stage + terminal cost + the rate penalty (no exact penalties)."""
        e = self.errors(states, ref)
        return float(np.einsum("kc,kc,ck->", e, e, self._w) + np.einsum("kc,kc,c->", inputs, inputs, self._dt_r)
                     + (rate_penalty_cost(inputs, self._rate_w, v_last) if self.rate_penalty else 0.0))

    def evaluate(self, states: np.ndarray, inputs: np.ndarray, ref: np.ndarray,
                 obstacles: np.ndarray, v_last: np.ndarray | None = None, first_row: bool = True) -> NlpEvaluation:
        """Cost, merit and nonlinear-constraint violations of a plan.

        Parameters
        ----------
        states : array (N+1, 4)
        inputs : array (N, 3)
        ref : array (N+1, 3)
            p_d at the samples.
        obstacles : array (M, 4)
            [cx, cy, cz, radius] of the obstacles in the problem.
        v_last : array (3,), optional
            The command before the plan (rate penalty; with ``first_row``, the rate row (b)).
        """
        compiled_arcs, compiled_rows = compiled()
        states = np.asarray(states, dtype=float)
        inputs = np.asarray(inputs, dtype=float)
        n = self.n
        e = compiled_arcs.error_coordinates(states, np.asarray(ref, dtype=float), ED_FLOOR)
        e2 = e * e
        cost = float(np.einsum("kc,ck->", e2, self._w) + np.einsum("kc,kc,c->", inputs, inputs, self._dt_r))
        if self.rate_penalty:
            cost += rate_penalty_cost(inputs, self._rate_w, v_last)
        # per-step violations, rows: e_d_min, obstacle, e_o, box (k = 1..N)
        obstacles = np.asarray(obstacles, dtype=float).reshape(-1, 4)
        viol, inp, dyn = compiled_rows.violation_rows(states, inputs, e, obstacles, self.dt, self._violation_bounds,
                                                      self._workspace_rows, self.v_min, self.v_max)
        term = 0.0
        if self.terminal != "off":
            term = max(0.0, math.sqrt(float(e2[n] @ self.p)) - self.terminal_level)
        vmax = viol.max(axis=1)
        merit = cost + self.penalty * float(viol.sum())
        if self.terminal == "soft":
            merit += self.terminal_penalty * term
        violations = {"e_d_min": float(vmax[0]), "obstacle": float(vmax[1]), "e_o": float(vmax[2]),
                      "box": float(vmax[3]), "terminal": term, "input": inp, "dynamics": dyn}
        if self.backup_terminal is not None:
            backup = max(0.0, self.backup_terminal.violation(states[0, :3], states[n, :3], obstacles, self.workspace))
            merit += self.penalty * backup
            violations["backup_terminal"] = backup
        if self.rate_jump is not None:
            rate = max(rate_violation(inputs, self.rate_jump, v_last if first_row else None,
                                      self.terminal_rest, target=self.terminal_command).values())
            merit += self.penalty * rate
            violations["rate"] = rate
        mv = max(violations.values())
        if not (math.isfinite(cost) and math.isfinite(mv) and math.isfinite(merit)):
            cost, merit, mv = math.inf, math.inf, math.inf
        per_step = {"e_d_min": viol[0], "obstacle": viol[1], "e_o": viol[2], "box": viol[3]}
        return NlpEvaluation(cost=cost, merit=merit, violations=violations, per_step=per_step,
                             max_violation=mv)


def _terminal_rows(tightening: Tightening) -> TerminalLaw | None:
    """The tightening's terminal law when it proves tracking and its X_f has row faces, else None."""
    law = tightening.proven_terminal_law
    return law if law is not None and law.has_rows else None


def _tracking_terminal(tightening: Tightening) -> tuple[float, float, float, float] | None:
    """(d_lo, d_hi, sin α_f, z_f) of the tightening's terminal law when it proves tracking, else None."""
    law = tightening.proven_terminal_law
    if law is None:
        return None
    return (law.d_lo, law.d_hi, math.sin(law.alpha_max), law.z_max)
