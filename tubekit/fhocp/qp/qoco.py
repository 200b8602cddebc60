"""QOCO, an opt-in QP backend that takes second-order cones (a primal-dual interior point for SOCPs).

QOCO (Chari & Açıkmeşe 2025) solves min 1/2 x'Px + c'x s.t. A x = b, G x + s = h, s in R+^l x SOC(q_1) x ...
x SOC(q_nsoc), each cone's first entry its head: the form of :class:`~tubekit.fhocp.qp.base.ConeProgramData`
with the zero rows as A, b and the nonnegative and cone rows as G, h. One ``qoco.QOCO`` is set up on the first
solve and its data updated in place afterwards (``update_vector_data``, ``update_matrix_data``: the patterns are
structural, explicit zeros kept; a new pattern or a changed P sets it up again). QOCO detects no infeasibility:
an infeasible subproblem ends at its iteration cap or in a numerical error, both a failure that passes no
solution on. Needs ``pip install qoco``.
"""

from __future__ import annotations

import math
import time
from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp

from tubekit.exceptions import ConfigError
from tubekit.fhocp.qp.base import ConeProgramData, ConeSolution, QpBackend, checked_solution, zero_and_cone_rows
from tubekit.fhocp.result import Status, status_from

__all__ = ["QOCO_STATUS", "QocoBackend"]

#: QOCO's status (``qoco.QOCO().solvecodes``) -> :class:`Status`; any other is SOLVER_ERROR
QOCO_STATUS: dict[str, Status] = {
    "QOCO_SOLVED": Status.OPTIMAL,
    "QOCO_SOLVED_INACCURATE": Status.OPTIMAL_INACCURATE,
    "QOCO_MAX_ITER": Status.USER_LIMIT,
    "QOCO_NUMERICAL_ERROR": Status.SOLVER_ERROR,
    "QOCO_UNSOLVED": Status.SOLVER_ERROR,
}


class QocoBackend(QpBackend):
    """QOCO on a cone program (module doc).

    Parameters
    ----------
    settings : mapping, optional
        Overrides of QOCO's settings (``abstol``, ``reltol``, ``max_iters``, ...; QOCO's defaults otherwise).
    """

    name = "qoco"
    takes_cones = True
    package = "qoco"
    pip_name = "qoco"

    def __init__(self, settings: Mapping[str, Any] | None = None) -> None:
        super().__init__(settings)
        self._qoco = self.load()
        known = {k for k in dir(self._qoco.QOCO().ext.QOCOSettings()) if not k.startswith("_")}
        for key in self.settings:
            if key not in known:
                raise ConfigError("qoco settings", "names of QOCO settings", key)
        self._solver: Any = None
        self._key: Any = None
        self._blocks: tuple | None = None

    def _split(self, data: ConeProgramData) -> tuple[np.ndarray, np.ndarray]:
        """Values of (A, G) in their CSC patterns: the zero rows, then the nonnegative and cone rows."""
        if self._blocks is None or self._key is not data.a_indices:
            self._blocks = zero_and_cone_rows(data)
        (pe, _, _), (pg, _, _) = self._blocks
        return data.a_values[pe], data.a_values[pg]

    def solve(self, data: ConeProgramData) -> ConeSolution:
        """Set up or update the solver with ``data`` and solve."""
        new_pattern = self._solver is None or self._key is not data.a_indices or data.p_changed
        a_vals, g_vals = self._split(data)
        zero = data.dims.zero
        if new_pattern:
            self._setup(data, a_vals, g_vals)
        else:
            self._solver.update_vector_data(c=data.q, b=data.b[:zero], h=data.b[zero:])
            self._solver.update_matrix_data(A=a_vals if zero else None, G=g_vals)
            self.updates += 1
        t0 = time.perf_counter()  # the bare solve, as Clarabel's backend times it
        result = self._solver.solve()
        wall = time.perf_counter() - t0
        raw = str(result.status)
        status = status_from(QOCO_STATUS, raw)
        if not status.solved:
            return checked_solution(status, raw, None, math.nan, wall, int(result.iters), data.n)
        return checked_solution(status, raw, np.array(result.x, dtype=float), float(result.obj) + data.offset, wall,
                                int(result.iters), data.n)

    def _setup(self, data: ConeProgramData, a_vals: np.ndarray, g_vals: np.ndarray) -> None:
        """A new ``qoco.QOCO`` on ``data`` with :attr:`settings` (their names checked when the backend was built)."""
        (_, ie, qe), (_, ig, qg) = self._blocks
        zero, dims = data.dims.zero, data.dims
        solver = self._qoco.QOCO()
        a = sp.csc_matrix((a_vals, ie, qe), shape=(zero, data.n)) if zero else None
        g = sp.csc_matrix((g_vals, ig, qg), shape=(data.m - zero, data.n))
        solver.setup(data.n, data.m - zero, zero, data.P(), np.asarray(data.q, dtype=float), a,
                     np.asarray(data.b[:zero], dtype=float), g, np.asarray(data.b[zero:], dtype=float),
                     dims.nonneg, len(dims.soc), np.asarray(dims.soc, dtype=np.int32), verbose=0, **self.settings)
        self._solver = solver
        self._key = data.a_indices
        self.setups += 1

    def reset(self) -> None:
        """Drop the persistent solver (the next solve sets one up)."""
        self._solver = None
        self._key = None
        self._blocks = None
