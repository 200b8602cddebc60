"""The FHOCP backends' contract: result type, status vocabulary, fallback warning, warm-start shift.

Every FHOCP backend (:class:`tubekit.fhocp.scp.FHOCP`, :class:`tubekit.fhocp.ipopt.IpoptFHOCP`)
returns a :class:`FhocpResult` whose ``status`` is a :class:`Status`, and warm-starts
from its previous plan shifted by :func:`shifted_plan`.

Statuses
--------
:class:`Status` is a ``str`` enum: its values are the plain strings tubekit has always
reported (``"optimal"``, ``"fallback"``, ...), so ``result.status == "optimal"`` and
``str(result.status)`` behave as before. A result carries one of
:data:`RESULT_STATUSES`; ``fallback`` is True exactly when the status is
:attr:`Status.FALLBACK`. The other members describe one *solver call* (a convex
subproblem, an IPOPT run) and appear in messages. Each backend translates its
solver's own status through an explicit table with :func:`status_from`; a raw status
missing from the table maps to :attr:`Status.SOLVER_ERROR` (treated as a failed
solve, never as a solution).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Mapping, Protocol, Sequence

import numpy as np

from tubekit.exceptions import SolverError

if TYPE_CHECKING:
    from tubekit.scenario import Obstacle, Scenario
    from tubekit.tightening import Tightening

__all__ = ["Status", "RESULT_STATUSES", "status_from", "FhocpResult", "FallbackWarning",
           "shift_steps", "shifted_plan", "FhocpSolver", "SolverFactory"]


class Status(str, enum.Enum):
    """Outcome of an FHOCP solve or of one solver call; compares equal to its string value."""

    OPTIMAL = "optimal"
    OPTIMAL_INACCURATE = "optimal_inaccurate"
    ITERATION_LIMIT = "iteration_limit"
    FALLBACK = "fallback"
    INFEASIBLE = "infeasible"
    INFEASIBLE_INACCURATE = "infeasible_inaccurate"
    UNBOUNDED = "unbounded"
    UNBOUNDED_INACCURATE = "unbounded_inaccurate"
    INFEASIBLE_OR_UNBOUNDED = "infeasible_or_unbounded"
    USER_LIMIT = "user_limit"
    SOLVER_ERROR = "solver_error"

    def __str__(self) -> str:
        return self.value

    @property
    def solved(self) -> bool:
        """True for a solver call that returned a usable solution (optimal, possibly inaccurate)."""
        return self in (Status.OPTIMAL, Status.OPTIMAL_INACCURATE)


#: the statuses an :class:`FhocpResult` can carry
RESULT_STATUSES: frozenset[Status] = frozenset(
    {Status.OPTIMAL, Status.OPTIMAL_INACCURATE, Status.ITERATION_LIMIT, Status.FALLBACK})


def status_from(table: Mapping[str, Status], raw: object) -> Status:
    """The :class:`Status` of a solver's raw status through ``table``; unknown ones are SOLVER_ERROR."""
    return table.get(str(raw), Status.SOLVER_ERROR)


class FallbackWarning(UserWarning):
    """The FHOCP failed; the shifted previous plan with a searched tail is returned."""


@dataclass(frozen=True)
class FhocpResult:
    """One FHOCP solve.

    Attributes
    ----------
    status : Status
        One of :data:`RESULT_STATUSES`: ``"optimal"``, ``"optimal_inaccurate"``,
        ``"iteration_limit"`` (converged mode stopped at ``max_iterations``; the plan
        is valid) or ``"fallback"``.
    states : array (N+1, 4)
        Nominal states [x, y, z, psi] (m, rad): the rollout of ``inputs`` from
        the measured state.
    inputs : array (N, 3)
        Nominal inputs [u, w, r] (m/s, m/s, rad/s); finite and inside V-bar.
    cost : float
        Stage + terminal cost of the NLP on this plan (penalties excluded).
    iterations : int
        Convex subproblems solved (IPOPT: interior-point iterations).
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
        Per-family largest violations (see :class:`tubekit.fhocp.nlp.NlpEvaluation`).
    solver_time_s : float
        The solver's own time summed over its calls (s).
    t : float
        Time of the solve (s).
    message : str
        Why a fallback happened (empty otherwise).
    """

    status: Status
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


def shift_steps(plan_t: float | None, t: float, dt: float, horizon: int) -> int | None:
    """Whole sampling periods from a plan made at ``plan_t`` to ``t`` (s), at most ``horizon``.

    None without a plan (``plan_t`` None) or when ``t`` is before the plan.
    """
    if plan_t is None:
        return None
    shift = int(round((t - plan_t) / dt))
    return None if shift < 0 else min(shift, horizon)


def shifted_plan(plan_inputs: np.ndarray | None, plan_t: float | None, t: float, dt: float,
                 horizon: int) -> tuple[np.ndarray, bool]:
    """The warm start at ``t``: the stored plan's inputs shifted to ``t``, its last input repeated.

    Parameters
    ----------
    plan_inputs : array (N, 3) or None
        Inputs of the stored plan (m/s, m/s, rad/s).
    plan_t : float or None
        Time the plan was made (s).
    t : float
        Time of the new solve (s).
    dt : float
        Sampling period (s).
    horizon : int
        N.

    Returns
    -------
    (array (N, 3), bool)
        A new array of the shifted inputs and True, or zeros and False without a usable plan.
    """
    shift = None if plan_inputs is None else shift_steps(plan_t, t, dt, horizon)
    if shift is None:
        return np.zeros((horizon, 3)), False
    v = plan_inputs
    if shift:
        v = np.vstack([v[shift:], np.repeat(v[-1:], shift, axis=0)])
    return v.copy(), True


class FhocpSolver(Protocol):
    """What the closed loop needs from a FHOCP solver (e.g. :class:`tubekit.fhocp.FHOCP`).

    The keyword ``v_last`` (the command applied in the last tick before the plan, (3,) or None) is
    optional: the loop passes it to a ``solve`` that takes it (the built-in backends do).
    """

    def solve(self, t: float, state: np.ndarray, obstacles: Sequence[Obstacle], *,
              v_last: np.ndarray | None = None) -> FhocpResult:
        """Plan from ``state`` [x, y, z, psi] (m, rad) at time ``t`` (s) around the known ``obstacles``."""
        ...


#: ``factory(scenario, tightening)`` returning a :class:`FhocpSolver`.
SolverFactory = Callable[["Scenario", "Tightening"], FhocpSolver]
