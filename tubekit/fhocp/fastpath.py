"""Re-solving a DPP cvxpy problem without cvxpy's solve path: the compiled map + a persistent QP backend.

cvxpy compiles a DPP problem once into an affine map from the parameter vector
to the solver's data (``ParamConeProg``). :class:`CompiledConeProgram` takes
that map (``problem.get_problem_data(cp.CLARABEL)``, called once: the cone program
Ax + s = b, s in K of Clarabel's standard form), keeps the parameter vector as one
numpy array whose slices are writeable views per parameter, and on each solve

1. multiplies the reduced parameter-to-data tensors by that vector (three
   sparse mat-vecs; the sparsity pattern is structural, hence fixed),
2. hands the new values of q, A, b (and P, if parametric) to its QP backend as a
   :class:`~tubekit.fhocp.qp.base.ConeProgramData` (default: Clarabel, which keeps one
   solver and updates it in place, :mod:`tubekit.fhocp.qp.clarabel`),
3. returns the backend's :class:`~tubekit.fhocp.qp.base.ConeSolution`; :meth:`CompiledConeProgram.value`
   splits its x into the problem's variables by their column offsets.

No cvxpy reduction runs after construction. :meth:`CompiledConeProgram.verify`
compares the data with cvxpy's own ``ParamConeProg.apply_parameters``.
"""

from __future__ import annotations

import time
from typing import Any

import cvxpy as cp
import numpy as np
import scipy.sparse as sp
from cvxpy.lin_ops.lin_op import CONSTANT_ID

from tubekit.exceptions import ConfigError, SolverError
from tubekit.fhocp.linearisation import compiled
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData, ConeSolution, QpBackend
from tubekit.fhocp.qp.registry import make_qp_backend

__all__ = ["CompiledConeProgram", "cone_dims"]


def cone_dims(dims: Any) -> ConeDims:
    """:class:`ConeDims` of cvxpy's cone dimensions (zero, nonnegative, second-order only).

    Raises
    ------
    SolverError
        Another cone (exponential, PSD, power).
    """
    if dims.exp or dims.psd or dims.p3d or getattr(dims, "pnd", []):
        raise SolverError("only zero, nonnegative and second-order cones are supported")
    return ConeDims(int(dims.zero), int(dims.nonneg), tuple(int(d) for d in dims.soc))


class CompiledConeProgram:
    """A DPP ``cvxpy.Problem`` compiled once, re-solved by data updates through a QP backend.

    Parameters
    ----------
    problem : cvxpy.Problem
        Must satisfy ``problem.is_dcp(dpp=True)``.
    settings : dict, optional
        Clarabel setting overrides of the default backend (only without ``backend``).
    backend : QpBackend, optional
        The backend that solves the compiled cone program (it must take second-order cones when the
        problem has some: wrap a QP solver in :class:`~tubekit.fhocp.qp.relaxed.RelaxedQpBackend`, as
        :func:`~tubekit.fhocp.qp.registry.make_qp_backend` does); default Clarabel with ``settings``.

    Attributes
    ----------
    backend : QpBackend
        The backend every :meth:`solve` goes through.
    dims : ConeDims
        The cone of the compiled program.
    n, m : int
        Variables and rows of the compiled program.
    """

    def __init__(self, problem: cp.Problem, settings: dict | None = None, *,
                 backend: QpBackend | None = None) -> None:
        if not problem.is_dcp(dpp=True):
            raise SolverError("the problem is not DPP; it cannot be compiled once")
        if backend is not None and settings is not None:
            raise ConfigError("settings", "None when a backend is given (the backend holds its settings)", settings)
        if backend is not None and not isinstance(backend, QpBackend):
            raise ConfigError("backend", "a tubekit.fhocp.qp.base.QpBackend", backend)
        t0 = time.perf_counter()
        data, _chain, _inv = problem.get_problem_data(cp.CLARABEL)
        pp = data[cp.settings.PARAM_PROB]
        self._pp = pp
        self.n = int(pp.x.size)
        # the parameter vector (F-order values of each parameter at its column, then 1)
        self.param_vector = np.zeros(pp.total_param_size + 1)
        self.views: dict[int, np.ndarray] = {}
        for pid, col in pp.param_id_to_col.items():
            if pid == CONSTANT_ID:
                self.param_vector[col] = 1.0
                continue
            size = pp.param_id_to_size[pid]
            self.views[pid] = self.param_vector[col:col + size]
        # A and b: reduced tensor, fixed CSC pattern of [A | b]
        pp.reduced_A.cache(keep_zeros=True)
        if pp.reduced_A.problem_data_index is None:
            raise SolverError("cvxpy returned no reduced constraint tensor")
        indices, indptr, shape = pp.reduced_A.problem_data_index
        self.m = int(shape[0])
        nnz_a = int(indptr[self.n])
        a_map = sp.csr_matrix(pp.reduced_A.reduced_mat)
        self._nnz_a = nnz_a
        self._A_indices = np.asarray(indices[:nnz_a], dtype=np.int64)
        self._A_indptr = np.asarray(indptr[:self.n + 1], dtype=np.int64)
        self._b_rows = np.asarray(indices[nnz_a:], dtype=np.int64)
        # entries of A that depend on a parameter; the others are constant
        top = a_map[:nnz_a]
        self._a_par = np.flatnonzero(top[:, :-1].getnnz(axis=1)).astype(np.int64)
        self._a_data = -np.asarray(top[:, -1].toarray()).ravel()
        # one CSR map of A's parametric entries, b's and q's (with the offset d as its last row)
        stacked = sp.vstack([top[self._a_par], a_map[nnz_a:], sp.csr_matrix(pp.q)], format="csr")
        self._stacked = (stacked.indptr.astype(np.int64), stacked.indices.astype(np.int64), stacked.data.astype(float))
        self._compile_quadratic(pp)
        self.dims = cone_dims(data[cp.reductions.solvers.conic_solvers.conic_solver.ConicSolver.DIMS])
        self.var_id_to_col = dict(pp.var_id_to_col)
        if backend is None:
            backend = make_qp_backend("clarabel", {"clarabel": settings})
        if self.dims.soc and not backend.takes_cones:
            raise ConfigError("backend", "a QpBackend that takes second-order cones (or a RelaxedQpBackend)",
                              backend.name)
        self.backend = backend
        self.compile_time_s = time.perf_counter() - t0

    def _compile_quadratic(self, pp: Any) -> None:
        """P: the reduced tensor restricted to the upper triangle (a constant when no parameter enters)."""
        self._P_map = None
        self._P_const = None
        self._P_indices = np.zeros(0, dtype=np.int64)
        self._P_indptr = np.zeros(self.n + 1, dtype=np.int64)
        if pp.P is None:
            return
        pp.reduced_P.cache(keep_zeros=True)
        p_idx, p_ptr, _ = pp.reduced_P.problem_data_index
        cols = np.repeat(np.arange(self.n), np.diff(p_ptr))
        keep = np.asarray(p_idx) <= cols
        red = sp.csr_matrix(pp.reduced_P.reduced_mat)[np.flatnonzero(keep)]
        counts = np.bincount(cols[keep], minlength=self.n)
        self._P_indices = np.asarray(p_idx)[keep].astype(np.int64)
        self._P_indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        if red[:, :-1].nnz == 0:  # no parameter enters P
            self._P_const = np.asarray(red[:, -1].toarray()).ravel()
        else:
            self._P_map = red

    # ------------------------------------------------------------------ data
    def load_parameter_values(self, problem: cp.Problem) -> None:
        """Copy the current ``.value`` of every parameter of ``problem`` into the vector."""
        for p in problem.parameters():
            if p.id in self.views:
                if p.value is None:
                    raise SolverError(f"parameter {p.name()} has no value")
                self.views[p.id][:] = np.asarray(p.value, dtype=float).ravel(order="F")

    def columns(self, parameter: cp.Parameter) -> np.ndarray:
        """Indices of ``parameter``'s entries (F order) in :attr:`param_vector`."""
        col = self._pp.param_id_to_col.get(parameter.id)
        if col is None:
            raise SolverError(f"parameter {parameter.name()} is not part of the compiled problem")
        return np.arange(col, col + parameter.size)

    def _vectors(self) -> tuple[np.ndarray, np.ndarray, float]:
        """(b, q, d) for the current parameter vector (one compiled mat-vec of the stacked maps,
        :func:`tubekit.fhocp.compiled_rows.scatter_matvec`); also refreshes A's parametric values."""
        b = np.empty(self.m)
        q = np.empty(self.n)
        d = compiled()[1].scatter_matvec(*self._stacked, self.param_vector, self._a_data, self._a_par, b,
                                         self._b_rows, q)
        return b, q, d

    def data(self) -> tuple[sp.csc_matrix, np.ndarray, sp.csc_matrix, np.ndarray, float]:
        """(P upper triangle, q, A, b, d) for the current parameter vector; Clarabel's Ax + s = b."""
        prog = self.program()
        return prog.P(), prog.q, prog.A(), prog.b, prog.offset

    def _p_data(self) -> np.ndarray | None:
        if self._P_const is not None:
            return self._P_const
        if self._P_map is not None:
            return self._P_map @ self.param_vector
        return None

    def verify(self, atol: float = 1e-12) -> float:
        """Largest difference between this data and cvxpy's ``apply_parameters`` (same values)."""
        id_to_value = {pid: view.copy() for pid, view in self.views.items()}
        out = self._pp.apply_parameters(id_to_value, keep_zeros=True, quad_obj=self._pp.P is not None)
        if self._pp.P is not None:
            P_ref, q_ref, d_ref, A_ref, b_ref = out
            P_ref = sp.triu(P_ref).tocsc()
        else:
            q_ref, d_ref, A_ref, b_ref = out
            P_ref = sp.csc_matrix((self.n, self.n))
        P, q, A, b, d = self.data()
        errs = [abs(d - d_ref), np.max(np.abs(q - q_ref), initial=0.0),
                np.max(np.abs(b - b_ref), initial=0.0),
                abs(A + A_ref).max() if A.nnz or A_ref.nnz else 0.0,
                abs(P - P_ref).max() if P.nnz or P_ref.nnz else 0.0]
        return float(max(errs))

    # ----------------------------------------------------------------- solve
    def program(self) -> ConeProgramData:
        """The cone program at the current parameter vector, as the backend gets it (views of the buffers)."""
        b, q, d = self._vectors()
        return ConeProgramData(self._p_data(), self._P_indices, self._P_indptr, q, self._a_data, self._A_indices,
                               self._A_indptr, b, self.dims, d, self._a_par, self._P_map is not None)

    def solve(self) -> ConeSolution:
        """Solve the cone program at the current parameter vector with :attr:`backend`."""
        return self.backend.solve(self.program())

    def columns_of(self, variable: cp.Variable) -> np.ndarray:
        """Indices of ``variable``'s entries (F order) in the backend's x."""
        col = self.var_id_to_col[variable.id]
        return np.arange(col, col + variable.size)

    def value(self, solution: ConeSolution, variable: cp.Variable) -> np.ndarray | None:
        """``variable``'s value in ``solution`` (shaped like the variable), or None."""
        if solution.x is None:
            return None
        return solution.x[self.columns_of(variable)].reshape(variable.shape, order="F")

    @property
    def updates(self) -> int:
        """In-place data updates of the backend's solver so far."""
        return self.backend.updates

    @property
    def rebuilds(self) -> int:
        """Set-ups of the backend's solver so far (the first one included)."""
        return self.backend.setups

    def reset_solver(self) -> None:
        """Drop the backend's persistent solver (the next solve sets one up)."""
        self.backend.reset()
