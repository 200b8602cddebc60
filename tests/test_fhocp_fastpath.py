"""CompiledConeProgram on small DPP problems, against cvxpy's own solve path."""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

from tubekit.exceptions import SolverError
from tubekit.fhocp.fastpath import CLARABEL_STATUS, CompiledConeProgram


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


def test_every_clarabel_status_is_mapped_explicitly():
    assert set(CLARABEL_STATUS.values()) <= {"optimal", "optimal_inaccurate", "infeasible", "infeasible_inaccurate",
                                             "unbounded", "unbounded_inaccurate", "user_limit", "solver_error"}
    assert CLARABEL_STATUS["Solved"] == "optimal" and CLARABEL_STATUS["PrimalInfeasible"] == "infeasible"
