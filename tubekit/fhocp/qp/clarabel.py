"""Clarabel, the default QP backend: an interior-point solver that takes second-order cones.

One ``clarabel.DefaultSolver`` is set up on the first solve and then updated in place
(``solver.update(q=..., A=(positions, values), b=...)``: no re-allocation, no new symbolic
factorisation). Presolve and chordal decomposition are off because they forbid data updates
(:func:`clarabel_settings`); should an update be refused, the solver is set up again.
"""

from __future__ import annotations

import time
from typing import Any, Mapping

from tubekit.exceptions import ConfigError
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData, ConeSolution, QpBackend, checked_solution
from tubekit.fhocp.result import Status, status_from

__all__ = ["CLARABEL_STATUS", "ClarabelBackend", "clarabel_cones", "clarabel_settings"]

#: Clarabel's status (``str(clarabel.SolverStatus.X)``) -> :class:`Status`; any other is SOLVER_ERROR
CLARABEL_STATUS: dict[str, Status] = {
    "Solved": Status.OPTIMAL,
    "AlmostSolved": Status.OPTIMAL_INACCURATE,
    "PrimalInfeasible": Status.INFEASIBLE,
    "AlmostPrimalInfeasible": Status.INFEASIBLE_INACCURATE,
    "DualInfeasible": Status.UNBOUNDED,
    "AlmostDualInfeasible": Status.UNBOUNDED_INACCURATE,
    "MaxIterations": Status.USER_LIMIT,
    "MaxTime": Status.USER_LIMIT,
    "CallbackTerminated": Status.USER_LIMIT,
    "NumericalError": Status.SOLVER_ERROR,
    "InsufficientProgress": Status.SOLVER_ERROR,
    "Unsolved": Status.SOLVER_ERROR,
}


def clarabel_settings(overrides: Mapping[str, Any] | None = None) -> Any:
    """``clarabel.DefaultSettings`` that allow data updates (presolve/chordal off), quiet, plus ``overrides``.

    Raises
    ------
    NotAvailableError
        Clarabel is not installed (with the install hint).
    ConfigError
        An override that is not one of Clarabel's settings.
    """
    clarabel = ClarabelBackend.load()
    st = clarabel.DefaultSettings()
    st.verbose = False
    st.presolve_enable = False
    st.chordal_decomposition_enable = False
    st.input_sparse_dropzeros = False
    for key, value in (overrides or {}).items():
        if not hasattr(st, key):
            raise ConfigError("clarabel_settings", "names of Clarabel settings", key)
        setattr(st, key, value)
    return st


def clarabel_cones(dims: ConeDims) -> list:
    """Clarabel's cone list for ``dims`` (zero, nonnegative, then each second-order cone)."""
    clarabel = ClarabelBackend.load()
    cones: list = []
    if dims.zero:
        cones.append(clarabel.ZeroConeT(dims.zero))
    if dims.nonneg:
        cones.append(clarabel.NonnegativeConeT(dims.nonneg))
    cones.extend(clarabel.SecondOrderConeT(d) for d in dims.soc)
    return cones


class ClarabelBackend(QpBackend):
    """Clarabel through one persistent solver updated in place (module doc).

    Parameters
    ----------
    settings : mapping, optional
        Overrides of Clarabel's settings (e.g. ``{"tol_feas": 1e-7}``), on top of :func:`clarabel_settings`.
    """

    name = "clarabel"
    takes_cones = True
    package = "clarabel"
    pip_name = "clarabel"

    def __init__(self, settings: Mapping[str, Any] | None = None) -> None:
        super().__init__(settings)
        self._clarabel = self.load()
        self._solver: Any = None
        self._key: Any = None

    def solve(self, data: ConeProgramData) -> ConeSolution:
        """Update (or, the first time or on a new pattern, set up) the solver and solve ``data``."""
        if self._solver is None or self._key is not data.a_indices:
            self._setup(data)
        else:
            changed = data.a_changed
            kw: dict[str, Any] = {"q": data.q, "b": data.b,
                                  "A": data.a_values.copy() if changed is None else (changed, data.a_values[changed])}
            if data.p_changed and data.p_values is not None:
                kw["P"] = data.p_values
            try:
                self._solver.update(**kw)
                self.updates += 1
            except Exception:  # noqa: BLE001 - Clarabel refused the update (pattern, dimensions): set up again
                self._setup(data)
        t0 = time.perf_counter()
        sol = self._solver.solve()
        wall = time.perf_counter() - t0
        raw = str(sol.status)
        status = status_from(CLARABEL_STATUS, raw)
        if not status.solved:
            return checked_solution(status, raw, None, float("nan"), wall, int(sol.iterations), data.n)
        return checked_solution(status, raw, sol.x, float(sol.obj_val) + data.offset, wall, int(sol.iterations),
                                data.n)

    def _setup(self, data: ConeProgramData) -> None:
        """A new ``clarabel.DefaultSolver`` on ``data`` (its own copy of A's values)."""
        self._solver = self._clarabel.DefaultSolver(data.P(), data.q, data.A(), data.b, clarabel_cones(data.dims),
                                                    clarabel_settings(self.settings))
        self._key = data.a_indices
        self.setups += 1

    def reset(self) -> None:
        """Drop the persistent solver (the next solve sets one up)."""
        self._solver = None
        self._key = None
