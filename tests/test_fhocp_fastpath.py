"""CompiledConeProgram on small DPP problems, against cvxpy's own solve path."""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

from tubekit.exceptions import ConfigError, SolverError
from tubekit.fhocp.fastpath import CompiledConeProgram
from tubekit.fhocp.qp.base import ConeDims
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.piqp import PiqpBackend


def _problem():
    x = cp.Variable(3, name="x")
    p = cp.Parameter(3, name="p")
    a = cp.Parameter(nonneg=True, name="a")
    L = np.diag([1.0, 2.0, 0.5])
    prob = cp.Problem(cp.Minimize(cp.sum_squares(L @ (x - p)) + a * cp.norm1(x)),
                      [cp.abs(x) <= 1.0, cp.sum(x) >= -0.5])
    return prob, x, p, a


def test_resolves_match_cvxpy_with_changing_parameters():
    prob, x, p, a = _problem()
    assert prob.is_dcp(dpp=True)
    rng = np.random.default_rng(0)
    p.value, a.value = rng.normal(size=3), 0.1
    comp = CompiledConeProgram(prob)
    for _ in range(5):
        p.value, a.value = rng.normal(size=3) * 2, rng.uniform(0, 1)
        comp.load_parameter_values(prob)
        assert comp.verify() < 1e-12
        sol = comp.solve()
        prob.solve(solver=cp.CLARABEL)
        assert sol.status == "optimal"
        assert np.allclose(comp.value(sol, x), x.value, atol=1e-6)
        assert sol.objective == pytest.approx(prob.value, abs=1e-6)
    assert comp.updates == 4  # built once, then updated in place


def test_infeasible_maps_status_and_gives_no_solution():
    x = cp.Variable(2)
    b = cp.Parameter()
    prob = cp.Problem(cp.Minimize(cp.sum(x)), [x >= b, x <= 0])
    b.value = -1.0
    comp = CompiledConeProgram(prob)
    assert comp.solve().status == "optimal"
    b.value = 1.0  # now x >= 1 and x <= 0
    comp.load_parameter_values(prob)
    sol = comp.solve()
    assert sol.status in ("infeasible", "infeasible_inaccurate") and sol.x is None
    assert np.isnan(sol.objective)


def test_parameter_without_value_is_an_error():
    prob, x, p, a = _problem()
    p.value, a.value = np.zeros(3), 0.0
    comp = CompiledConeProgram(prob)
    a.value = None
    with pytest.raises(SolverError, match="no value"):
        comp.load_parameter_values(prob)


def _socp():
    x = cp.Variable(2)
    c = cp.Parameter(2)
    c.value = np.array([2.0, 0.0])
    return cp.Problem(cp.Minimize(cp.sum_squares(x - c)), [cp.norm(x) <= 1.0]), x, c


def test_the_program_is_the_data_the_backend_gets():
    prob, x, c = _socp()
    comp = CompiledConeProgram(prob)
    comp.load_parameter_values(prob)
    assert isinstance(comp.backend, ClarabelBackend) and comp.dims.soc and comp.dims.rows == comp.m
    prog = comp.program()
    P, q, A, b, d = comp.data()
    assert (prog.P() != P).nnz == 0 and (prog.A() != A).nnz == 0
    assert np.array_equal(prog.q, q) and np.array_equal(prog.b, b) and prog.offset == d
    assert prog.p_changed is False  # P is a constant of this problem: never sent again


def test_the_backend_is_a_constructor_argument():
    prob, x, c = _socp()
    backend = ClarabelBackend({"tol_feas": 1e-9})
    comp = CompiledConeProgram(prob, backend=backend)
    assert comp.backend is backend
    comp.load_parameter_values(prob)
    sol = comp.solve()
    assert comp.value(sol, x) == pytest.approx([1.0, 0.0], abs=1e-6) and comp.rebuilds == 1
    with pytest.raises(ConfigError, match="^settings: "):
        CompiledConeProgram(prob, {"tol_feas": 1e-9}, backend=backend)
    with pytest.raises(ConfigError, match="^backend: "):
        CompiledConeProgram(prob, backend="clarabel")  # type: ignore[arg-type]


def test_a_backend_without_cones_is_refused_on_a_cone_program():
    pytest.importorskip("piqp")
    prob, _x, _c = _socp()
    with pytest.raises(ConfigError, match="takes second-order cones"):
        CompiledConeProgram(prob, backend=PiqpBackend())


def test_only_zero_nonnegative_and_second_order_cones_compile():
    from types import SimpleNamespace

    from tubekit.fhocp.fastpath import cone_dims
    dims = SimpleNamespace(zero=1, nonneg=2, soc=[3], exp=0, psd=[], p3d=[])
    assert cone_dims(dims) == ConeDims(1, 2, (3,))
    with pytest.raises(SolverError, match="second-order"):
        cone_dims(SimpleNamespace(zero=1, nonneg=2, soc=[], exp=1, psd=[], p3d=[]))
