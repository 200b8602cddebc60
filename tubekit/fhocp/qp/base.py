"""The QP-backend contract: one cone program in, one :class:`ConeSolution` out.

A backend solves the cone program of one SCP subproblem in Clarabel's standard form

    minimise   1/2 x'Px + q'x + offset
    subject to Ax + s = b,  s in K = {0}^zero x R+^nonneg x SOC(d_1) x ... x SOC(d_k)

(the rows of A and b are ordered zero, nonnegative, then one block per second-order cone, whose first
row is the cone's head). :class:`ConeProgramData` carries that program as arrays over **fixed sparsity
patterns** (cvxpy compiles the subproblem once: from one solve to the next only values change), so a
backend may keep a solver and update its data. :class:`QpBackend` is the small ABC every backend
subclasses: its ``name``, whether it ``takes_cones`` (second-order cones; a backend that does not is
used through :class:`tubekit.fhocp.qp.relaxed.RelaxedQpBackend`), ``available()`` (a try-import of its
package) and :meth:`QpBackend.solve`. A backend maps its solver's statuses to
:class:`~tubekit.fhocp.result.Status` through an explicit table, and :func:`checked_solution` makes sure
a failed or non-finite solve never passes a NaN on (``x`` is None then).
"""

from __future__ import annotations

import importlib
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from functools import cached_property
from types import MappingProxyType, ModuleType
from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp

from tubekit.exceptions import ConfigError, NotAvailableError
from tubekit.fhocp.result import Status

__all__ = ["ConeDims", "ConeProgramData", "ConeSolution", "QpBackend", "checked_solution", "row_block",
           "zero_and_cone_rows"]


@dataclass(frozen=True)
class ConeDims:
    """The cone K of a program: ``zero`` equality rows, ``nonneg`` inequality rows, then the SOC blocks.

    Attributes
    ----------
    zero : int
        Rows with s = 0 (equalities).
    nonneg : int
        Rows with s >= 0 (inequalities).
    soc : tuple of int
        The dimension of each second-order cone ||s[1:]|| <= s[0], in row order.
    """

    zero: int = 0
    nonneg: int = 0
    soc: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        for field in ("zero", "nonneg"):
            value = getattr(self, field)
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 0:
                raise ConfigError(field, "an integer >= 0", value)
        soc = tuple(self.soc)
        if not all(isinstance(d, (int, np.integer)) and not isinstance(d, bool) and d >= 1 for d in soc):
            raise ConfigError("soc", "second-order cone dimensions, integers >= 1", self.soc)
        object.__setattr__(self, "soc", tuple(int(d) for d in soc))

    @property
    def linear(self) -> int:
        """Rows of the zero and nonnegative cones (the first rows of A)."""
        return self.zero + self.nonneg

    @property
    def rows(self) -> int:
        """All rows: m of A."""
        return self.linear + sum(self.soc)


@dataclass(frozen=True, eq=False)
class ConeProgramData:
    """One cone program (module doc) as values over fixed CSC patterns.

    The arrays may be views of the caller's buffers, valid for one :meth:`QpBackend.solve` call: a backend
    that keeps data between calls copies it.

    Attributes
    ----------
    p_values : array or None
        Values of the upper triangle of P in the pattern (``p_indices``, ``p_indptr``); None: P = 0.
    p_indices, p_indptr : array of int64
        CSC pattern of P's upper triangle (n x n).
    q : array (n,)
        Linear cost.
    a_values : array
        Values of A in the pattern (``a_indices``, ``a_indptr``); explicit zeros are structural.
    a_indices, a_indptr : array of int64
        CSC pattern of A (m x n), row indices sorted within each column.
    b : array (m,)
        Right-hand side.
    dims : ConeDims
        The cone (``dims.rows == m``).
    offset : float
        Constant added to the objective.
    a_changed : array of int64 or None
        Positions in ``a_values`` that may differ from the previous call's data of the same pattern
        (None: any of them); a backend that updates its solver in place may send only these.
    p_changed : bool
        P may differ from the previous call's.
    """

    p_values: np.ndarray | None
    p_indices: np.ndarray
    p_indptr: np.ndarray
    q: np.ndarray
    a_values: np.ndarray
    a_indices: np.ndarray
    a_indptr: np.ndarray
    b: np.ndarray
    dims: ConeDims
    offset: float = 0.0
    a_changed: np.ndarray | None = None
    p_changed: bool = True

    @property
    def n(self) -> int:
        """Variables."""
        return len(self.q)

    @property
    def m(self) -> int:
        """Rows of A."""
        return len(self.b)

    def P(self) -> sp.csc_matrix:
        """P's upper triangle (n x n), a new matrix."""
        if self.p_values is None:
            return sp.csc_matrix((self.n, self.n))
        return sp.csc_matrix((self.p_values, self.p_indices, self.p_indptr), shape=(self.n, self.n))

    @cached_property
    def p_full(self) -> sp.csc_matrix:
        """The whole symmetric P (n x n), computed once per data (QP solvers take the whole matrix)."""
        upper = sp.csc_matrix((self.p_values if self.p_values is not None else np.zeros(len(self.p_indices)),
                               self.p_indices, self.p_indptr), shape=(self.n, self.n))
        return (upper + sp.triu(upper, 1).T).tocsc()

    def A(self) -> sp.csc_matrix:
        """A (m x n) with its own copy of the values, explicit zeros kept."""
        return sp.csc_matrix((self.a_values.copy(), self.a_indices, self.a_indptr), shape=(self.m, self.n))

    @classmethod
    def from_matrices(cls, P: Any, q: np.ndarray, A: Any, b: np.ndarray, dims: ConeDims,
                      offset: float = 0.0) -> ConeProgramData:
        """The data of matrices (tests, benchmarks): P square (its upper triangle is used), A (m x n).

        Raises
        ------
        ConfigError
            Shapes that do not agree with each other or with ``dims``.
        """
        q = np.asarray(q, dtype=float).ravel()
        b = np.asarray(b, dtype=float).ravel()
        A = sp.csc_matrix(A, dtype=float)
        A.sort_indices()
        P = sp.triu(sp.csc_matrix(P, dtype=float)).tocsc()
        P.sort_indices()
        n, m = len(q), len(b)
        if P.shape != (n, n):
            raise ConfigError("P", f"a {n} x {n} matrix (n = len(q))", P.shape)
        if A.shape != (m, n) or dims.rows != m:
            raise ConfigError("A", f"a {m} x {n} matrix whose rows the cone dims cover ({dims.rows})", A.shape)
        as_int = lambda a: np.asarray(a, dtype=np.int64)  # noqa: E731
        return cls(P.data, as_int(P.indices), as_int(P.indptr), q, A.data, as_int(A.indices), as_int(A.indptr),
                   b, dims, float(offset))


def row_block(a_indices: np.ndarray, a_indptr: np.ndarray, shape: tuple[int, int], lo: int,
              hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows ``lo:hi`` of a CSC pattern: (positions of their values in the full value array, indices, indptr).

    Every structural entry is kept (explicit zeros too), so a solver updated in place sees a fixed
    pattern; ``values[positions]`` are the block's values in CSC order.
    """
    nnz = len(a_indices)
    pattern = sp.csc_matrix((np.arange(1, nnz + 1, dtype=float), a_indices, a_indptr), shape=shape)
    block = pattern[lo:hi].tocsc()
    block.sort_indices()
    return block.data.astype(np.int64) - 1, block.indices.astype(np.int64), block.indptr.astype(np.int64)


def zero_and_cone_rows(data: ConeProgramData) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray],
                                                         tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """:func:`row_block` of A's zero rows and of the rest (nonnegative and cone rows): the split of solvers that
    take equalities as A x = b and every other row as G x + s = h (QOCO, the generated QOCO)."""
    shape, zero = (data.m, data.n), data.dims.zero
    return (row_block(data.a_indices, data.a_indptr, shape, 0, zero),
            row_block(data.a_indices, data.a_indptr, shape, zero, data.m))


@dataclass(frozen=True)
class ConeSolution:
    """One backend solve.

    Attributes
    ----------
    status : Status
        The solver's status through the backend's explicit table, e.g. ``Status.OPTIMAL``.
    raw_status : str
        The solver's own status.
    x : array or None
        Primal solution (n,); None unless ``status.solved`` and every entry is finite.
    objective : float
        1/2 x'Px + q'x + offset at ``x`` (nan without a solution).
    solver_time_s : float
        Wall time of the solver's own calls (s): update/setup and solve.
    iterations : int
        The solver's iterations.
    """

    status: Status
    raw_status: str
    x: np.ndarray | None
    objective: float
    solver_time_s: float
    iterations: int


def checked_solution(status: Status, raw_status: str, x: Any, objective: float, solver_time_s: float,
                     iterations: int, n: int) -> ConeSolution:
    """A :class:`ConeSolution` that passes no NaN on.

    Unless ``status`` is solved, ``x`` and ``objective`` are dropped (None, nan). A solved status with
    an ``x`` of the wrong size or a non-finite entry or objective becomes :attr:`Status.SOLVER_ERROR`.
    """
    if not status.solved or x is None:
        return ConeSolution(status=status if not status.solved else Status.SOLVER_ERROR, raw_status=raw_status,
                            x=None, objective=math.nan, solver_time_s=solver_time_s, iterations=iterations)
    x = np.asarray(x, dtype=float)
    if x.size != n or not (np.isfinite(x).all() and math.isfinite(objective)):
        return ConeSolution(status=Status.SOLVER_ERROR, raw_status=raw_status, x=None, objective=math.nan,
                            solver_time_s=solver_time_s, iterations=iterations)
    return ConeSolution(status=status, raw_status=raw_status, x=x, objective=objective,
                        solver_time_s=solver_time_s, iterations=iterations)


class QpBackend(ABC):
    """A solver of :class:`ConeProgramData` (module doc); subclasses set the class attributes below.

    Parameters
    ----------
    settings : mapping, optional
        The solver's setting overrides (names of the solver's own settings), kept as :attr:`settings`.

    Attributes
    ----------
    name : str
        The registry name (:mod:`tubekit.fhocp.qp.registry`).
    takes_cones : bool
        True when :meth:`solve` takes second-order cones; False: zero and nonnegative rows only.
    package : str or None
        The Python package the backend imports (None: none).
    pip_name : str
        What ``pip install`` needs for it (the install hint).
    realtime_settings : mapping
        The setting overrides the FHOCP's real-time mode gives the backend when it is the chosen one (empty: its
        defaults). Clarabel's real-time setting goes with the user's ``ScpOptions.clarabel_settings`` instead
        (:data:`tubekit.fhocp.convex.REALTIME_CLARABEL_SETTINGS`), since Clarabel is also the cone fallback.
    setups, updates : int
        Solver set-ups and in-place data updates so far.
    """

    name: str = ""
    takes_cones: bool = False
    package: str | None = None
    pip_name: str = ""
    realtime_settings: Mapping[str, Any] = MappingProxyType({})

    def __init__(self, settings: Mapping[str, Any] | None = None) -> None:
        if settings is not None and (not isinstance(settings, Mapping) or not all(isinstance(k, str)
                                                                                   for k in settings)):
            raise ConfigError(f"{self.name or type(self).__name__} settings", "a mapping of setting names to values",
                              settings)
        self.settings: dict[str, Any] = dict(settings or {})
        self.setups = 0
        self.updates = 0

    @classmethod
    def load(cls) -> ModuleType | None:
        """The backend's package (a try-import), or :class:`NotAvailableError` with the install hint."""
        if cls.package is None:
            return None
        try:
            return importlib.import_module(cls.package)
        except ImportError as exc:
            raise NotAvailableError(f"the QP backend '{cls.name}' needs {cls.package}: "
                                    f"pip install {cls.pip_name or cls.package}") from exc

    @classmethod
    def available(cls) -> bool:
        """True when :meth:`load` finds the package."""
        try:
            cls.load()
        except NotAvailableError:
            return False
        return True

    @abstractmethod
    def solve(self, data: ConeProgramData) -> ConeSolution:
        """Solve ``data`` (updating a kept solver when the pattern is the previous call's)."""

    def reset(self) -> None:
        """Drop any kept solver: the next :meth:`solve` sets one up from scratch."""
