"""tubekit.fhocp.qp.base: the cone program's data, the checked solution, the QpBackend ABC."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
import scipy.sparse as sp

from tubekit import ConfigError, NotAvailableError
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData, ConeSolution, QpBackend, checked_solution, row_block
from tubekit.fhocp.result import Status


class Echo(QpBackend):
    """A backend that needs no package and returns q (enough to exercise the ABC)."""

    name = "echo"
    takes_cones = True

    def solve(self, data: ConeProgramData) -> ConeSolution:
        return checked_solution(Status.OPTIMAL, "done", data.q, 0.0, 0.0, 1, data.n)


class Missing(Echo):
    """A backend whose package is not installed."""

    name = "missing"
    package = "tubekit_no_such_package"
    pip_name = "no-such-package"


@pytest.mark.parametrize("kwargs, message", [
    ({"zero": -1}, r"^zero: expected an integer >= 0"),
    ({"nonneg": 1.5}, r"^nonneg: expected an integer >= 0"),
    ({"zero": True}, r"^zero: expected an integer >= 0"),
    ({"soc": (3, 0)}, r"^soc: expected second-order cone dimensions"),
])
def test_cone_dims_are_validated(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        ConeDims(**kwargs)


def test_cone_dims_count_rows():
    dims = ConeDims(2, 3, [4, 3])
    assert dims.soc == (4, 3) and dims.linear == 5 and dims.rows == 12


def test_from_matrices_keeps_the_upper_triangle_and_checks_shapes():
    P = np.array([[2.0, 1.0], [1.0, 3.0]])
    A = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    data = ConeProgramData.from_matrices(P, [1.0, 2.0], A, [1.0, 2.0, 3.0], ConeDims(1, 2), offset=4.0)
    assert (data.n, data.m, data.offset) == (2, 3, 4.0)
    assert np.array_equal(data.P().toarray(), np.triu(P)) and np.array_equal(data.p_full.toarray(), P)
    assert np.array_equal(data.A().toarray(), A) and data.A().data is not data.a_values  # a copy
    assert data.a_changed is None and data.p_changed
    with pytest.raises(ConfigError, match=r"^P: expected a 2 x 2 matrix"):
        ConeProgramData.from_matrices(np.eye(3), [1.0, 2.0], A, [1.0, 2.0, 3.0], ConeDims(1, 2))
    with pytest.raises(ConfigError, match=r"^A: expected a 3 x 2 matrix"):
        ConeProgramData.from_matrices(P, [1.0, 2.0], A, [1.0, 2.0, 3.0], ConeDims(1, 1))
    zero_p = ConeProgramData(None, np.zeros(0, np.int64), np.zeros(3, np.int64), data.q, data.a_values,
                             data.a_indices, data.a_indptr, data.b, data.dims)
    assert zero_p.P().nnz == 0 and zero_p.p_full.nnz == 0


def test_a_row_block_keeps_explicit_zeros_in_csc_order():
    A = sp.csc_matrix((np.array([1.0, 0.0, 2.0, 3.0]), np.array([0, 2, 1, 2]), np.array([0, 2, 4])), shape=(3, 2))
    positions, indices, indptr = row_block(A.indices, A.indptr, A.shape, 1, 3)
    block = sp.csc_matrix((A.data[positions], indices, indptr), shape=(2, 2))
    assert np.array_equal(block.toarray(), A.toarray()[1:3]) and block.nnz == 3  # the explicit zero stays


def test_a_checked_solution_passes_no_nan_on():
    ok = checked_solution(Status.OPTIMAL_INACCURATE, "AlmostSolved", [1.0, 2.0], 3.0, 0.1, 4, 2)
    assert ok.status is Status.OPTIMAL_INACCURATE and np.array_equal(ok.x, [1.0, 2.0]) and ok.objective == 3.0
    for x, objective, n in (([1.0, math.nan], 3.0, 2), ([1.0, 2.0], math.inf, 2), ([1.0], 3.0, 2), (None, 3.0, 2)):
        bad = checked_solution(Status.OPTIMAL, "Solved", x, objective, 0.1, 4, n)
        assert bad.status is Status.SOLVER_ERROR and bad.x is None and math.isnan(bad.objective)
    failed = checked_solution(Status.INFEASIBLE, "PrimalInfeasible", [1.0, 2.0], 3.0, 0.1, 4, 2)
    assert failed.status is Status.INFEASIBLE and failed.x is None and math.isnan(failed.objective)
    assert failed.iterations == 4 and failed.solver_time_s == 0.1


def test_the_abc_declares_and_try_imports():
    with pytest.raises(TypeError):
        QpBackend()  # abstract: no solve
    assert Echo.available() and Echo.load() is None and Echo().settings == {}
    assert Echo({"a": 1}).settings == {"a": 1} and (Echo().setups, Echo().updates) == (0, 0)
    assert not Missing.available()
    with pytest.raises(NotAvailableError, match=r"QP backend 'missing' needs tubekit_no_such_package: "
                                                r"pip install no-such-package"):
        Missing.load()
    with pytest.raises(ConfigError, match=r"^echo settings: expected a mapping"):
        Echo({1: 2})
    Echo().reset()  # the default reset keeps nothing


def test_a_package_made_missing_is_unavailable(monkeypatch):
    from tubekit.fhocp.qp.clarabel import ClarabelBackend
    assert ClarabelBackend.available()
    monkeypatch.setitem(sys.modules, "clarabel", None)
    assert not ClarabelBackend.available()
    with pytest.raises(NotAvailableError, match="pip install clarabel"):
        ClarabelBackend()
