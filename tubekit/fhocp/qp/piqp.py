"""PIQP, an opt-in QP backend (proximal interior point): equality and inequality rows, no cones.

PIQP solves min 1/2 x'Px + c'x s.t. A_eq x = b_eq, G x <= h with the whole symmetric P. The zero rows
of a :class:`~tubekit.fhocp.qp.base.ConeProgramData` are its equalities, the nonnegative rows (s = b -
Ax >= 0) its inequalities; a program with second-order cones is refused: the SCP subproblem reaches
PIQP through :class:`tubekit.fhocp.qp.relaxed.RelaxedQpBackend`, which hands it the QP relaxation.
One ``piqp.SparseSolver`` is set up on the first solve and updated in place afterwards (the patterns
are structural, explicit zeros kept). Needs ``pip install piqp``.
"""

from __future__ import annotations

import math
import time
from typing import Any, Mapping

import scipy.sparse as sp

from tubekit.exceptions import ConfigError, SolverError
from tubekit.fhocp.qp.base import ConeProgramData, ConeSolution, QpBackend, checked_solution, row_block
from tubekit.fhocp.result import Status, status_from

__all__ = ["PIQP_STATUS", "PiqpBackend", "DEFAULT_PIQP_SETTINGS"]

#: PIQP's status (the member name of ``piqp.Status``) -> :class:`Status`; any other is SOLVER_ERROR
PIQP_STATUS: dict[str, Status] = {
    "PIQP_SOLVED": Status.OPTIMAL,
    "PIQP_MAX_ITER_REACHED": Status.USER_LIMIT,
    "PIQP_PRIMAL_INFEASIBLE": Status.INFEASIBLE,
    "PIQP_DUAL_INFEASIBLE": Status.UNBOUNDED,
    "PIQP_NUMERICS": Status.SOLVER_ERROR,
    "PIQP_UNSOLVED": Status.SOLVER_ERROR,
    "PIQP_INVALID_SETTINGS": Status.SOLVER_ERROR,
}

#: PIQP settings used by default (tighter than PIQP's 1e-8: the relaxation's answer is checked to 1e-7)
DEFAULT_PIQP_SETTINGS: dict[str, Any] = {"eps_abs": 1e-9, "eps_rel": 1e-9}


class PiqpBackend(QpBackend):
    """PIQP on the zero and nonnegative rows of a cone program (module doc).

    Parameters
    ----------
    settings : mapping, optional
        Overrides of :data:`DEFAULT_PIQP_SETTINGS` / PIQP's settings (``piqp.SparseSolver().settings``).
    """

    name = "piqp"
    takes_cones = False
    package = "piqp"
    pip_name = "piqp"

    def __init__(self, settings: Mapping[str, Any] | None = None) -> None:
        super().__init__({**DEFAULT_PIQP_SETTINGS, **dict(settings or {})})
        self._piqp = self.load()
        self._solver: Any = None
        self._key: Any = None
        self._blocks: tuple | None = None

    def _split(self, data: ConeProgramData) -> tuple[Any, Any]:
        """(A_eq, G) of ``data`` as CSC matrices over fixed patterns (computed once per pattern)."""
        if self._blocks is None or self._key is not data.a_indices:
            zero, lin = data.dims.zero, data.dims.linear
            shape = (data.m, data.n)
            self._blocks = (row_block(data.a_indices, data.a_indptr, shape, 0, zero),
                            row_block(data.a_indices, data.a_indptr, shape, zero, lin))
        (pe, ie, qe), (pi, ii, qi) = self._blocks
        vals = data.a_values
        return (sp.csc_matrix((vals[pe], ie, qe), shape=(data.dims.zero, data.n)),
                sp.csc_matrix((vals[pi], ii, qi), shape=(data.dims.nonneg, data.n)))

    def solve(self, data: ConeProgramData) -> ConeSolution:
        """Set up or update the solver with ``data`` and solve.

        Raises
        ------
        SolverError
            ``data`` has second-order cones (use :class:`tubekit.fhocp.qp.relaxed.RelaxedQpBackend`).
        """
        if data.dims.soc:
            raise SolverError("PIQP takes no second-order cones: solve the QP relaxation through "
                              "tubekit.fhocp.qp.relaxed.RelaxedQpBackend")
        new_pattern = self._key is not data.a_indices
        A_eq, G = self._split(data)
        b, zero, lin = data.b, data.dims.zero, data.dims.linear
        args = (data.p_full, data.q, A_eq, b[:zero], G, None, b[zero:lin])
        t0 = time.perf_counter()
        if self._solver is None or new_pattern:
            self._setup(args, data)
        else:
            try:
                self._solver.update(*args)
                self.updates += 1
            except Exception:  # noqa: BLE001 - PIQP refused the update: set up again
                self._setup(args, data)
        raw_status = self._solver.solve()
        wall = time.perf_counter() - t0
        raw = getattr(raw_status, "name", str(raw_status))
        status = status_from(PIQP_STATUS, raw)
        result = self._solver.result
        iterations = int(result.info.iter)
        if not status.solved:
            return checked_solution(status, raw, None, math.nan, wall, iterations, data.n)
        return checked_solution(status, raw, result.x, float(result.info.primal_obj) + data.offset, wall,
                                iterations, data.n)

    def _setup(self, args: tuple, data: ConeProgramData) -> None:
        """A new ``piqp.SparseSolver`` with :attr:`settings`, set up on ``args``."""
        solver = self._piqp.SparseSolver()
        for key, value in self.settings.items():
            if not hasattr(solver.settings, key):
                raise ConfigError("piqp settings", "names of PIQP settings", key)
            setattr(solver.settings, key, value)
        solver.setup(*args)
        self._solver = solver
        self._key = data.a_indices
        self.setups += 1

    def reset(self) -> None:
        """Drop the persistent solver (the next solve sets one up)."""
        self._solver = None
        self._key = None
        self._blocks = None
