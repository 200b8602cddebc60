"""The backends' contract: Status and the solver-status tables, FhocpResult.check, the warm-start shift."""

from __future__ import annotations

import clarabel
import cvxpy as cp
import numpy as np
import pytest

from tubekit import SolverError
from tubekit.fhocp import FHOCP, FhocpResult
from tubekit.fhocp.convex import CVXPY_STATUS
from tubekit.fhocp.qp.clarabel import CLARABEL_STATUS
from tubekit.fhocp.ipopt import IPOPT_STATUS
from tubekit.fhocp.result import RESULT_STATUSES, Status, shift_steps, shifted_plan, status_from

from .fhocp_cases import OBSTACLES, SC, STATES, tightening

#: every return status of IPOPT 3.14 as CasADi reports it (``stats()["return_status"]``)
IPOPT_RETURN_STATUSES = (
    "Solve_Succeeded", "Solved_To_Acceptable_Level", "Infeasible_Problem_Detected",
    "Search_Direction_Becomes_Too_Small", "Diverging_Iterates", "User_Requested_Stop", "Feasible_Point_Found",
    "Maximum_Iterations_Exceeded", "Restoration_Failed", "Error_In_Step_Computation", "Maximum_CpuTime_Exceeded",
    "Maximum_WallTime_Exceeded", "Not_Enough_Degrees_Of_Freedom", "Invalid_Problem_Definition", "Invalid_Option",
    "Invalid_Number_Detected", "Unrecoverable_Exception", "NonIpopt_Exception_Thrown", "Insufficient_Memory",
    "Internal_Error",
)


@pytest.fixture(scope="module")
def rt() -> FHOCP:
    return FHOCP(SC, tightening(), mode="realtime")


# ------------------------------------------------------------------ Status
def test_status_is_its_string():
    assert Status.OPTIMAL == "optimal" and Status("fallback") is Status.FALLBACK
    assert str(Status.ITERATION_LIMIT) == "iteration_limit" and f"{Status.SOLVER_ERROR}" == "solver_error"
    assert Status.OPTIMAL in {"optimal"} and {"optimal": 1}[Status.OPTIMAL] == 1
    assert {s for s in Status if s.solved} == {Status.OPTIMAL, Status.OPTIMAL_INACCURATE}
    assert RESULT_STATUSES == {"optimal", "optimal_inaccurate", "iteration_limit", "fallback"}


@pytest.mark.parametrize("table, raw_statuses", [
    (CLARABEL_STATUS, [str(getattr(clarabel.SolverStatus, n)) for n in dir(clarabel.SolverStatus)
                       if not n.startswith("_")]),
    (CVXPY_STATUS, sorted({*cp.settings.SOLUTION_PRESENT, *cp.settings.INF_OR_UNB, *cp.settings.INACCURATE,
                           *cp.settings.ERROR})),
    (IPOPT_STATUS, IPOPT_RETURN_STATUSES),
], ids=["clarabel", "cvxpy", "ipopt"])
def test_every_solver_status_is_mapped_explicitly(table, raw_statuses):
    assert len(raw_statuses) >= 9
    for raw in raw_statuses:
        assert raw in table, raw
        assert isinstance(table[raw], Status) and table[raw] not in (Status.ITERATION_LIMIT, Status.FALLBACK)
    assert set(table) == set(raw_statuses)
    solved = {raw for raw in raw_statuses if status_from(table, raw).solved}
    assert len(solved) == 2  # the optimal and the optimal-but-inaccurate status


def test_unknown_solver_status_is_a_solver_error():
    """Documented choice: a status missing from a table is a failed solve, never a solution."""
    for table in (CLARABEL_STATUS, CVXPY_STATUS, IPOPT_STATUS):
        assert status_from(table, "SomethingNew") is Status.SOLVER_ERROR
    assert status_from(CLARABEL_STATUS, clarabel.SolverStatus.Solved) is Status.OPTIMAL


def test_fhocp_results_carry_result_statuses(rt):
    rt.reset()
    t, s = STATES[1]
    ok = rt.solve(t, np.array(s), OBSTACLES)
    assert isinstance(ok.status, Status) and ok.status in RESULT_STATUSES and not ok.fallback


# ------------------------------------------------------------------ FhocpResult
def test_result_check_raises_on_violation(rt):
    rt.reset()
    t, s = STATES[1]
    res = rt.solve(t, np.array(s), OBSTACLES)
    res.check()
    bad = FhocpResult(**{**res.__dict__, "max_violation": 0.3, "violations": {**res.violations, "obstacle": 0.3}})
    with pytest.raises(SolverError, match="obstacle"):
        bad.check()
    nan = FhocpResult(**{**res.__dict__, "inputs": np.full_like(res.inputs, np.nan)})
    with pytest.raises(SolverError, match="not finite"):
        nan.check()


# ------------------------------------------------------------------ the warm-start shift
def test_shift_steps_rounds_caps_and_refuses_the_past():
    assert shift_steps(None, 1.0, 0.1, 8) is None
    assert shift_steps(1.0, 1.0, 0.1, 8) == 0
    assert shift_steps(1.0, 1.096, 0.1, 8) == 1          # rounded to whole periods
    assert shift_steps(1.0, 1.3, 0.1, 8) == 3
    assert shift_steps(1.0, 9.0, 0.1, 8) == 8            # at most the horizon
    assert shift_steps(1.0, 0.9, 0.1, 8) is None         # before the plan


def test_shifted_plan_repeats_the_last_input():
    plan = np.arange(12.0).reshape(4, 3)
    v, warm = shifted_plan(plan, 2.0, 2.2, 0.1, 4)
    assert warm and np.array_equal(v, [[6, 7, 8], [9, 10, 11], [9, 10, 11], [9, 10, 11]])
    same, warm = shifted_plan(plan, 2.0, 2.0, 0.1, 4)
    assert warm and np.array_equal(same, plan) and same is not plan   # a copy, never the stored plan
    far, _ = shifted_plan(plan, 2.0, 5.0, 0.1, 4)
    assert np.array_equal(far, np.tile(plan[-1], (4, 1)))
    for args in ((None, None), (plan, None), (plan, 2.5)):
        zeros, warm = shifted_plan(*args, 2.0, 0.1, 4)
        assert not warm and zeros.shape == (4, 3) and not zeros.any()
