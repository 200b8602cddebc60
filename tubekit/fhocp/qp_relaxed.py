"""An opt-in QP path beside Clarabel: PIQP on the QP relaxation, certified against the cones, else Clarabel.

The SCP subproblem is a second-order cone program (the terminal set, and with a backup the sensed-region
rows). PIQP (like DAQP) takes no cones, so :class:`RelaxedQpProgram` solves the **QP relaxation** of the
very canonical data Clarabel gets (:class:`~tubekit.fhocp.fastpath.CompiledConeProgram`: Ax + s = b,
s in K): the zero and nonnegative rows only. Its answer is then *completed* and *checked*:

1. completion: every epigraph variable (no cost, no quadratic term, in some cone row) is set to the
   smallest value its nonnegative rows allow, then raised to meet the cones it heads (two passes);
2. check: every row of the original problem, cones included, holds to :data:`FEASIBILITY_TOL`.

A relaxation's optimum that is feasible for the original problem is optimal for it, with the same
objective (the completed variables cost nothing). When the check fails (a cone binds, or PIQP did not
solve), the same data go to Clarabel, so the answer is always the SOCP's. Select it with
``ScpOptions(qp_solver="piqp")`` or the backend ``"scp-piqp"`` (:mod:`tubekit.fhocp.registry`); it needs
``pip install piqp`` (:class:`~tubekit.exceptions.NotAvailableError` with the hint otherwise).
"""

from __future__ import annotations

import math
import time
from typing import Any

import clarabel
import numpy as np
import scipy.sparse as sp

from tubekit.exceptions import NotAvailableError
from tubekit.fhocp.fastpath import CompiledConeProgram, ConeSolution
from tubekit.fhocp.result import Status

__all__ = ["RelaxedQpProgram", "import_piqp", "FEASIBILITY_TOL"]

#: Absolute tolerance of the check of the completed relaxation against every row of the SOCP.
FEASIBILITY_TOL = 1e-7


def import_piqp() -> Any:
    """The ``piqp`` module, or :class:`NotAvailableError` with the install hint."""
    try:
        import piqp
    except ImportError as exc:
        raise NotAvailableError("the FHOCP QP backend 'piqp' needs PIQP: pip install piqp") from exc
    return piqp


def _row_block(pattern: sp.csc_matrix, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(value positions in the full A, indices, indptr) of rows lo:hi, every structural entry kept."""
    block = pattern[lo:hi].tocsc()
    block.sort_indices()
    return block.data.astype(np.int64) - 1, block.indices.astype(np.int64), block.indptr.astype(np.int64)


class RelaxedQpProgram:
    """:class:`CompiledConeProgram`'s ``solve`` through PIQP on the QP relaxation (module doc).

    Parameters
    ----------
    compiled : CompiledConeProgram
        The compiled subproblem; its parameter vector stays the one the subproblem writes.
    """

    def __init__(self, compiled: CompiledConeProgram) -> None:
        self._piqp = import_piqp()
        self.compiled = compiled
        n, m = compiled.n, compiled.m
        dims = {type(c).__name__: c.dim for c in compiled.cones if not isinstance(c, clarabel.SecondOrderConeT)}
        self.zero, self.nonneg = dims.get("ZeroConeT", 0), dims.get("NonnegativeConeT", 0)
        self.soc = [c.dim for c in compiled.cones if isinstance(c, clarabel.SecondOrderConeT)]
        lin = self.zero + self.nonneg
        nnz = len(compiled._A_indices)
        pattern = sp.csc_matrix((np.arange(1, nnz + 1, dtype=float), compiled._A_indices, compiled._A_indptr),
                                shape=(m, n))
        self._eq = _row_block(pattern, 0, self.zero)
        self._ineq = _row_block(pattern, self.zero, lin)
        self._cone_rows = pattern[lin:].tocsr()
        p_upper = compiled._p_data()
        has_p = np.zeros(n, dtype=bool)
        if p_upper is not None:
            has_p[np.repeat(np.arange(n), np.diff(compiled._P_indptr))[p_upper != 0.0]] = True
            has_p[compiled._P_indices[p_upper != 0.0]] = True
        self._aux_candidates = np.flatnonzero(~has_p & (np.diff(self._cone_rows.tocsc().indptr) > 0))
        self._solver: Any = None
        self._bound_cone: int | None = None
        self.qp_solves = 0
        self.clarabel_solves = 0

    def __getattr__(self, name: str) -> Any:
        """Everything else (columns, value, verify, ...) is the compiled program's."""
        return getattr(self.compiled, name)

    def _matrices(self) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix]:
        """(whole symmetric P, A_eq, G) at the current parameter vector (fixed sparsity patterns)."""
        c, n = self.compiled, self.compiled.n
        p_upper = c._p_data()
        P = sp.csc_matrix((p_upper if p_upper is not None else np.zeros(len(c._P_indices)), c._P_indices,
                           c._P_indptr), shape=(n, n))
        P = (P + sp.triu(P, 1).T).tocsc()
        vals = c._a_data
        (pe, ie, qe), (pi, ii, qi) = self._eq, self._ineq
        A_eq = sp.csc_matrix((vals[pe], ie, qe), shape=(self.zero, n))
        G = sp.csc_matrix((vals[pi], ii, qi), shape=(self.nonneg, n))
        return P, A_eq, G

    def _dense_a(self) -> np.ndarray:
        """A (m, n) at the current parameter vector, dense (a few hundred rows: cheaper than sparse slicing)."""
        c = self.compiled
        a = np.zeros((c.m, c.n))
        cols = np.repeat(np.arange(c.n), np.diff(c._A_indptr))
        a[c._A_indices, cols] = c._a_data
        return a

    def _complete(self, x: np.ndarray, q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Epigraph variables at their smallest value allowed by their rows (module doc, step 1)."""
        lin = self.zero + self.nonneg
        aux = [int(j) for j in self._aux_candidates if q[j] == 0.0]
        x = x.copy()
        for _ in range(2):
            for j in aux:
                col = a[self.zero:lin, j]
                rows = np.flatnonzero(col < 0.0)
                x[j] = 0.0
                if len(rows):  # s_i = b_i - a_i x >= 0 with a_ij < 0: x_j >= (b_i - rest_i) / a_ij
                    rest = b[self.zero + rows] - a[self.zero + rows] @ x
                    x[j] = float(np.max(rest / col[rows]))
                i, lowest = lin, -math.inf if len(rows) else None
                for d in self.soc:
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
        s = b - a @ x
        lin = self.zero + self.nonneg
        if np.max(np.abs(s[:self.zero]), initial=0.0) > FEASIBILITY_TOL or \
                np.min(s[self.zero:lin], initial=0.0) < -FEASIBILITY_TOL:
            return -1
        i = lin
        for k, d in enumerate(self.soc):
            if s[i] + FEASIBILITY_TOL < float(np.linalg.norm(s[i + 1:i + d])):
                return k
            i += d
        return None

    def _cone_slack(self, k: int, x: np.ndarray, b: np.ndarray) -> float:
        """Slack s_0 - |s_1:| of cone ``k`` at ``x``."""
        i = self.zero + self.nonneg + sum(self.soc[:k])
        d = self.soc[k]
        s = b[i:i + d] - self._dense_a()[i:i + d] @ x
        return float(s[0] - np.linalg.norm(s[1:]))

    def solve(self) -> ConeSolution:
        """PIQP on the relaxation; its completed answer when it meets every row, else Clarabel's.

        After a subproblem whose relaxation broke a cone (e.g. the soft terminal set during a catch-up)
        the next ones go to Clarabel directly while that cone binds at Clarabel's optimum (slack <=
        :data:`FEASIBILITY_TOL`): the relaxation would fail the check there.
        """
        c = self.compiled
        if self._bound_cone is not None:
            sol = c.solve()
            self.clarabel_solves += 1
            if sol.x is not None:
                _, b, _, _ = c._vectors()
                if self._cone_slack(self._bound_cone, sol.x, b) > FEASIBILITY_TOL:
                    self._bound_cone = None
            return sol
        _, b, q, d = c._vectors()
        P, A_eq, G = self._matrices()
        args = (P, q, A_eq, b[:self.zero], G, None, b[self.zero:self.zero + self.nonneg])
        t0 = time.perf_counter()
        if self._solver is None:
            self._solver = self._piqp.SparseSolver()
            self._solver.settings.eps_abs = self._solver.settings.eps_rel = 1e-9
            self._solver.setup(*args)
        else:
            self._solver.update(*args)
        status = self._solver.solve()
        wall = time.perf_counter() - t0
        if status == self._piqp.PIQP_SOLVED:
            a = self._dense_a()
            x = self._complete(np.asarray(self._solver.result.x, dtype=float), q, a, b)
            failing = self._failing(x, a, b) if np.all(np.isfinite(x)) else -1
            if failing is None:
                self.qp_solves += 1
                objective = float(0.5 * x @ (P @ x) + q @ x) + d
                return ConeSolution(status=Status.OPTIMAL, raw_status="PIQP_SOLVED (cones checked)", x=x,
                                    objective=objective, solver_time_s=wall,
                                    iterations=int(self._solver.result.info.iter))
            self._bound_cone = failing if failing >= 0 else None
        self.clarabel_solves += 1
        sol = c.solve()
        return ConeSolution(status=sol.status, raw_status=sol.raw_status, x=sol.x, objective=sol.objective,
                            solver_time_s=wall + sol.solver_time_s, iterations=sol.iterations)
