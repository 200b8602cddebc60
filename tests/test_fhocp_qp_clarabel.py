"""tubekit.fhocp.qp.clarabel: the default backend, its explicit status table, one solver updated in place."""

from __future__ import annotations

import dataclasses
import math

import clarabel
import numpy as np
import pytest

from tubekit import ConfigError
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData
from tubekit.fhocp.qp.clarabel import CLARABEL_STATUS, ClarabelBackend, clarabel_cones, clarabel_settings
from tubekit.fhocp.result import Status, status_from

#: every status of the installed Clarabel
RAW_STATUSES = [str(getattr(clarabel.SolverStatus, n)) for n in dir(clarabel.SolverStatus) if not n.startswith("_")]


def _ball(center, radius: float = 1.0) -> ConeProgramData:
    """min 1/2 |x - c|^2 s.t. |x| <= radius (one 3-dimensional cone) and x_0 + x_1 <= 10."""
    A = np.array([[1.0, 1.0], [0.0, 0.0], [-1.0, 0.0], [0.0, -1.0]])
    return ConeProgramData.from_matrices(np.eye(2), -np.asarray(center, dtype=float), A, [10.0, radius, 0.0, 0.0],
                                         ConeDims(nonneg=1, soc=(3,)), offset=0.5 * float(np.dot(center, center)))


@pytest.mark.parametrize("raw", RAW_STATUSES)
def test_every_clarabel_status_maps_to_a_status(raw):
    assert raw in CLARABEL_STATUS and isinstance(CLARABEL_STATUS[raw], Status)
    assert CLARABEL_STATUS[raw] not in (Status.ITERATION_LIMIT, Status.FALLBACK)


def test_the_table_has_no_other_entry_and_two_solved_statuses():
    assert set(CLARABEL_STATUS) == set(RAW_STATUSES)
    assert {raw for raw in RAW_STATUSES if CLARABEL_STATUS[raw].solved} == {"Solved", "AlmostSolved"}
    assert status_from(CLARABEL_STATUS, clarabel.SolverStatus.PrimalInfeasible) is Status.INFEASIBLE


def test_solves_and_then_updates_one_solver_in_place():
    backend = ClarabelBackend()
    data = _ball([2.0, 0.0])
    sol = backend.solve(data)
    assert sol.status is Status.OPTIMAL and sol.raw_status == "Solved"
    # on the cone's boundary an interior point is accurate to about the square root of its gap tolerance
    assert sol.x == pytest.approx([1.0, 0.0], abs=1e-4) and sol.objective == pytest.approx(0.5, abs=1e-6)
    solver = backend._solver
    for c in ([0.0, 0.5], [0.0, -3.0]):  # same pattern object: data updates, no new set-up
        sol = backend.solve(dataclasses.replace(data, q=-np.asarray(c), offset=0.5 * float(np.dot(c, c))))
        assert sol.x == pytest.approx(np.asarray(c) / max(1.0, np.linalg.norm(c)), abs=1e-4)
    assert backend._solver is solver and (backend.setups, backend.updates) == (1, 2)
    backend.solve(_ball([0.0, 0.5]))  # a new pattern: a new solver
    assert backend.setups == 2
    backend.reset()
    assert backend._solver is None


def test_an_infeasible_program_passes_no_solution_on():
    # x_0 + x_1 <= -10 while |x| <= 1
    data = _ball([0.0, 0.0])
    sol = ClarabelBackend().solve(dataclasses.replace(data, b=np.array([-10.0, 1.0, 0.0, 0.0])))
    assert sol.status in (Status.INFEASIBLE, Status.INFEASIBLE_INACCURATE)
    assert sol.x is None and math.isnan(sol.objective)


def test_a_numerical_failure_passes_no_nan_on(monkeypatch):
    backend = ClarabelBackend()
    data = _ball([2.0, 0.0])
    backend.solve(data)

    class Claimed:  # a solver that says "Solved" but returns NaN
        status = "Solved"
        x = [math.nan, 0.0]
        obj_val = 0.0
        iterations = 1

    monkeypatch.setattr(backend, "_solver", type("Stub", (), {"update": lambda self, **kw: None,
                                                              "solve": lambda self: Claimed()})())
    sol = backend.solve(data)
    assert sol.status is Status.SOLVER_ERROR and sol.x is None and math.isnan(sol.objective)


def test_settings_reach_clarabel_and_unknown_ones_are_named():
    assert ClarabelBackend({"max_iter": 1}).solve(_ball([2.0, 0.0])).status is Status.USER_LIMIT
    st = clarabel_settings({"tol_feas": 1e-5})
    assert st.tol_feas == 1e-5 and not st.presolve_enable and not st.chordal_decomposition_enable
    with pytest.raises(ConfigError, match=r"^clarabel_settings: expected names of Clarabel settings"):
        clarabel_settings({"tolerance": 1e-5})


def test_the_cone_list_follows_the_dims():
    cones = clarabel_cones(ConeDims(2, 3, (3, 4)))
    assert [type(c).__name__ for c in cones] == ["ZeroConeT", "NonnegativeConeT", "SecondOrderConeT",
                                                 "SecondOrderConeT"]
    assert clarabel_cones(ConeDims(nonneg=1)) and len(clarabel_cones(ConeDims(nonneg=1))) == 1
