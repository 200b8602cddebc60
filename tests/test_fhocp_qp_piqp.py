"""tubekit.fhocp.qp.piqp: PIQP on the zero and nonnegative rows, its explicit status table, no cones."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tubekit import ConfigError, SolverError
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.piqp import DEFAULT_PIQP_SETTINGS, PIQP_STATUS, PiqpBackend
from tubekit.fhocp.result import Status

from .qp_cases import small_qp

piqp = pytest.importorskip("piqp")

#: every status of the installed PIQP
RAW_STATUSES = sorted(piqp.Status.__members__)


@pytest.mark.parametrize("raw", RAW_STATUSES)
def test_every_piqp_status_maps_to_a_status(raw):
    assert raw in PIQP_STATUS and isinstance(PIQP_STATUS[raw], Status)
    assert PIQP_STATUS[raw] not in (Status.ITERATION_LIMIT, Status.FALLBACK)


def test_the_table_has_no_other_entry_and_one_solved_status():
    assert set(PIQP_STATUS) == set(RAW_STATUSES)
    assert [raw for raw in RAW_STATUSES if PIQP_STATUS[raw].solved] == ["PIQP_SOLVED"]


def test_piqp_agrees_with_clarabel_and_updates_in_place():
    backend, reference = PiqpBackend(), ClarabelBackend({"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9})
    data = small_qp([3.0, 1.0])
    for c in ([3.0, 1.0], [-0.5, 0.25], [-4.0, -2.0]):
        case = dataclasses.replace(data, q=-np.asarray(c), offset=0.5 * float(np.dot(c, c)))
        a, b = reference.solve(case), backend.solve(case)
        assert b.status is Status.OPTIMAL and b.raw_status == "PIQP_SOLVED"
        assert b.x == pytest.approx(a.x, abs=1e-6) and b.objective == pytest.approx(a.objective, abs=1e-6)
    assert (backend.setups, backend.updates) == (1, 2)
    assert backend.solve(small_qp([0.0, 0.0])).x == pytest.approx([0.0, 0.0], abs=1e-7) and backend.setups == 2


def test_an_infeasible_program_passes_no_solution_on():
    data = small_qp([0.0, 0.0])
    sol = PiqpBackend().solve(dataclasses.replace(data, b=np.array([0.0, -2.0, -2.0])))  # x_0 <= -2, x_1 >= 2
    assert sol.status is Status.INFEASIBLE and sol.x is None and math.isnan(sol.objective)


def test_the_iteration_cap_is_a_user_limit_without_a_solution():
    sol = PiqpBackend({"max_iter": 1}).solve(small_qp([3.0, 1.0]))
    assert sol.status is Status.USER_LIMIT and sol.raw_status == "PIQP_MAX_ITER_REACHED" and sol.x is None


def test_cones_are_refused():
    A = np.array([[0.0, 0.0], [-1.0, 0.0], [0.0, -1.0]])
    cone = ConeProgramData.from_matrices(np.eye(2), np.zeros(2), A, [1.0, 0.0, 0.0], ConeDims(soc=(3,)))
    with pytest.raises(SolverError, match="no second-order cones.*RelaxedQpBackend"):
        PiqpBackend().solve(cone)


def test_settings_default_and_unknown_ones_are_named():
    assert PiqpBackend().settings == DEFAULT_PIQP_SETTINGS
    assert PiqpBackend({"eps_abs": 1e-6}).settings == {**DEFAULT_PIQP_SETTINGS, "eps_abs": 1e-6}
    with pytest.raises(ConfigError, match=r"^piqp settings: expected names of PIQP settings"):
        PiqpBackend({"tolerance": 1e-6}).solve(small_qp([3.0, 1.0]))
