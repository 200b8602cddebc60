"""The relaxation wrapper: a QP backend without cones on a cone program, checked against the cones, else a cone backend.

The SCP subproblem is a second-order cone program (the terminal set, and with a backup the sensed-region
rows). A QP solver such as PIQP takes no cones, so :class:`RelaxedQpBackend` hands it the **QP
relaxation** of the very data the cone backend gets (:class:`~tubekit.fhocp.qp.base.ConeProgramData`:
Ax + s = b, s in K): the zero and nonnegative rows only. Its answer is then *completed* and *checked*:

1. completion: every epigraph variable (no cost, no quadratic term, in some cone row) is set to the
   smallest value its nonnegative rows allow, then raised to meet the cones it heads (two passes);
2. check: every row of the original problem, cones included, holds to :data:`FEASIBILITY_TOL`.

A relaxation's optimum that is feasible for the original problem is optimal for it, with the same
objective (the completed variables cost nothing). When the check fails (a cone binds, or the QP solver
did not solve), the same data go to the cone backend (Clarabel), so the answer is always the SOCP's.
After a subproblem whose relaxation broke a cone, the next ones go to the cone backend directly while
that cone binds at its optimum. ``ScpOptions(qp_solver="piqp")`` and the FHOCP backend ``"scp-piqp"``
select it through :func:`tubekit.fhocp.qp.registry.make_qp_backend`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData, ConeSolution, QpBackend, row_block
from tubekit.fhocp.result import Status

__all__ = ["RelaxedQpBackend", "FEASIBILITY_TOL"]

#: Absolute tolerance of the check of the completed relaxation against every row of the SOCP.
FEASIBILITY_TOL = 1e-7


class _Structure:
    """What the wrapper derives once from a pattern: the relaxation's rows and the epigraph candidates."""

    def __init__(self, data: ConeProgramData) -> None:
        n, m, dims = data.n, data.m, data.dims
        self.key = data.a_indices
        self.zero, self.nonneg, self.soc, self.lin = dims.zero, dims.nonneg, list(dims.soc), dims.linear
        self.positions, self.indices, self.indptr = row_block(data.a_indices, data.a_indptr, (m, n), 0, self.lin)
        self.dims = ConeDims(dims.zero, dims.nonneg)
        cone_cols = np.zeros(n, dtype=bool)
        cols = np.repeat(np.arange(n), np.diff(data.a_indptr))
        cone_cols[cols[np.asarray(data.a_indices) >= self.lin]] = True
        has_p = np.zeros(n, dtype=bool)
        if data.p_values is not None:
            nonzero = data.p_values != 0.0
            has_p[np.repeat(np.arange(n), np.diff(data.p_indptr))[nonzero]] = True
            has_p[data.p_indices[nonzero]] = True
        self.aux_candidates = np.flatnonzero(~has_p & cone_cols)

    def relaxation(self, data: ConeProgramData) -> ConeProgramData:
        """``data`` without its cone rows (the QP relaxation), over the fixed pattern of the linear rows."""
        return replace(data, a_values=data.a_values[self.positions], a_indices=self.indices, a_indptr=self.indptr,
                       b=data.b[:self.lin], dims=self.dims, a_changed=None)


class RelaxedQpBackend(QpBackend):
    """A cone program through a QP backend on its relaxation, checked, else a cone backend (module doc).

    Parameters
    ----------
    qp : QpBackend
        A backend that takes no cones (``takes_cones`` False), e.g. PIQP.
    cones : QpBackend
        A backend that takes them (Clarabel): the fallback, and the answer while a cone binds.

    Attributes
    ----------
    relaxed_solves : int
        Solves answered by the checked relaxation.
    cone_solves : int
        Solves answered by the cone backend.
    """

    takes_cones = True

    def __init__(self, qp: QpBackend, cones: QpBackend) -> None:
        if not isinstance(qp, QpBackend) or qp.takes_cones:
            raise ConfigError("qp", "a QpBackend that takes no cones (one that does needs no relaxation)", qp)
        if not isinstance(cones, QpBackend) or not cones.takes_cones:
            raise ConfigError("cones", "a QpBackend that takes second-order cones", cones)
        super().__init__()
        self.qp, self.cones = qp, cones
        self.name = f"{qp.name} (relaxed, else {cones.name})"
        self._structure: _Structure | None = None
        self._bound_cone: int | None = None
        self.relaxed_solves = 0
        self.cone_solves = 0

    def solve(self, data: ConeProgramData) -> ConeSolution:
        """The QP backend on the relaxation; its completed answer when it meets every row, else the cone backend's."""
        if self._structure is None or self._structure.key is not data.a_indices:
            self._structure = _Structure(data)
            self._bound_cone = None
        if self._bound_cone is not None:
            return self._while_bound(data)
        st = self._structure
        relaxed = st.relaxation(data)
        sol = self.qp.solve(relaxed)
        if sol.status is Status.OPTIMAL and sol.x is not None:
            a = self._dense_a(data)
            x = self._complete(sol.x, data.q, a, data.b)
            failing = self._failing(x, a, data.b) if np.all(np.isfinite(x)) else -1
            if failing is None:
                self.relaxed_solves += 1
                objective = float(0.5 * x @ (relaxed.p_full @ x) + data.q @ x) + data.offset
                return ConeSolution(status=Status.OPTIMAL, raw_status=f"{sol.raw_status} (cones checked)", x=x,
                                    objective=objective, solver_time_s=sol.solver_time_s, iterations=sol.iterations)
            self._bound_cone = failing if failing >= 0 else None
        self.cone_solves += 1
        cone = self.cones.solve(data)
        return ConeSolution(status=cone.status, raw_status=cone.raw_status, x=cone.x, objective=cone.objective,
                            solver_time_s=sol.solver_time_s + cone.solver_time_s, iterations=cone.iterations)

    def _while_bound(self, data: ConeProgramData) -> ConeSolution:
        """The cone backend while cone ``_bound_cone`` binds; released once its slack exceeds the tolerance."""
        sol = self.cones.solve(data)
        self.cone_solves += 1
        if sol.x is not None and self._cone_slack(self._bound_cone, sol.x, data) > FEASIBILITY_TOL:
            self._bound_cone = None
        return sol

    @staticmethod
    def _dense_a(data: ConeProgramData) -> np.ndarray:
        """A (m, n), dense (a few hundred rows: cheaper than sparse slicing)."""
        a = np.zeros((data.m, data.n))
        cols = np.repeat(np.arange(data.n), np.diff(data.a_indptr))
        a[data.a_indices, cols] = data.a_values
        return a

    def _complete(self, x: np.ndarray, q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Epigraph variables at their smallest value allowed by their rows (module doc, step 1)."""
        st = self._structure
        zero, lin = st.zero, st.lin
        aux = [int(j) for j in st.aux_candidates if q[j] == 0.0]
        x = x.copy()
        for _ in range(2):
            for j in aux:
                col = a[zero:lin, j]
                rows = np.flatnonzero(col < 0.0)
                x[j] = 0.0
                if len(rows):  # s_i = b_i - a_i x >= 0 with a_ij < 0: x_j >= (b_i - rest_i) / a_ij
                    rest = b[zero + rows] - a[zero + rows] @ x
                    x[j] = float(np.max(rest / col[rows]))
                i, lowest = lin, -math.inf if len(rows) else None
                for d in st.soc:
                    head = a[i, j]
                    if head < 0.0:  # s_0 = b_0 - a_0 x grows with x_j: the cone's smallest x_j
                        s = b[i:i + d] - a[i:i + d] @ x
                        need = x[j] + (float(np.linalg.norm(s[1:])) - s[0]) / -head
                        lowest = need if lowest is None else max(lowest, need)
                    i += d
                if lowest is not None and lowest > x[j]:
                    x[j] = lowest
        return x

    def _failing(self, x: np.ndarray, a: np.ndarray, b: np.ndarray) -> int | None:
        """None when every row of the SOCP (zero, nonnegative, cones) holds at ``x`` to
        :data:`FEASIBILITY_TOL`; else the index of the first cone it breaks (-1: a linear row)."""
        st = self._structure
        s = b - a @ x
        if np.max(np.abs(s[:st.zero]), initial=0.0) > FEASIBILITY_TOL or \
                np.min(s[st.zero:st.lin], initial=0.0) < -FEASIBILITY_TOL:
            return -1
        i = st.lin
        for k, d in enumerate(st.soc):
            if s[i] + FEASIBILITY_TOL < float(np.linalg.norm(s[i + 1:i + d])):
                return k
            i += d
        return None

    def _cone_slack(self, k: int, x: np.ndarray, data: ConeProgramData) -> float:
        """Slack s_0 - |s_1:| of cone ``k`` at ``x`` (length units of the cone's rows)."""
        st = self._structure
        i = st.lin + sum(st.soc[:k])
        d = st.soc[k]
        s = data.b[i:i + d] - self._dense_a(data)[i:i + d] @ x
        return float(s[0] - np.linalg.norm(s[1:]))

    def reset(self) -> None:
        """Drop both backends' solvers and the binding cone."""
        self.qp.reset()
        self.cones.reset()
        self._bound_cone = None
