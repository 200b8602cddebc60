"""tubekit.fhocp.qp.qoco: QOCO on the whole cone program (zero rows as A, the rest as G), its status table."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tubekit import ConfigError
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.qoco import QOCO_STATUS, QocoBackend
from tubekit.fhocp.qp.registry import make_qp_backend, qp_backends
from tubekit.fhocp.result import Status

from .qp_cases import disc, small_qp

qoco = pytest.importorskip("qoco")

#: every status the installed QOCO reports
RAW_STATUSES = sorted(qoco.QOCO().solvecodes)


@pytest.mark.parametrize("raw", RAW_STATUSES)
def test_every_qoco_status_maps_to_a_status(raw):
    assert raw in QOCO_STATUS and isinstance(QOCO_STATUS[raw], Status)


def test_the_table_has_no_other_entry_and_one_solved_status():
    assert set(QOCO_STATUS) == set(RAW_STATUSES)
    assert [raw for raw in RAW_STATUSES if QOCO_STATUS[raw] is Status.OPTIMAL] == ["QOCO_SOLVED"]


def test_qoco_agrees_with_clarabel_on_rows_and_updates_in_place():
    backend, reference = QocoBackend(), ClarabelBackend({"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9})
    data = small_qp([3.0, 1.0])
    for c in ([3.0, 1.0], [-0.5, 0.25], [-4.0, -2.0]):
        case = dataclasses.replace(data, q=-np.asarray(c), offset=0.5 * float(np.dot(c, c)), p_changed=False)
        a, b = reference.solve(case), backend.solve(case)
        assert b.status is Status.OPTIMAL and b.raw_status == "QOCO_SOLVED"
        assert b.x == pytest.approx(a.x, abs=1e-6) and b.objective == pytest.approx(a.objective, abs=1e-6)
    assert (backend.setups, backend.updates) == (1, 2)


def test_qoco_takes_the_cone_and_a_changed_right_hand_side():
    backend, data = QocoBackend(), disc(1.0)
    for radius in (1.0, 2.0, 0.5):
        sol = backend.solve(dataclasses.replace(data, b=np.array([radius, 0.0, 0.0]), p_changed=False))
        assert sol.status is Status.OPTIMAL
        assert sol.x == pytest.approx([-radius / math.sqrt(2)] * 2, abs=1e-6)
    assert (backend.setups, backend.updates) == (1, 2)
    assert make_qp_backend("qoco").takes_cones and qp_backends()["qoco"] is True


def test_an_infeasible_program_passes_no_solution_on():
    """QOCO detects no infeasibility: x_0 <= -2 and x_1 >= 2 with x_0 = x_1 ends in a failure without x."""
    sol = QocoBackend().solve(dataclasses.replace(small_qp([0.0, 0.0]), b=np.array([0.0, -2.0, -2.0])))
    assert not sol.status.solved and sol.x is None and math.isnan(sol.objective)


def test_the_iteration_cap_is_a_user_limit_without_a_solution():
    sol = QocoBackend({"max_iters": 1}).solve(disc(1.0))
    assert sol.status is Status.USER_LIMIT and sol.raw_status == "QOCO_MAX_ITER" and sol.x is None


def test_unknown_settings_are_named():
    assert QocoBackend({"abstol": 1e-6}).solve(small_qp([3.0, 1.0])).status is Status.OPTIMAL
    with pytest.raises(ConfigError, match=r"^qoco settings: expected names of QOCO settings"):
        QocoBackend({"tolerance": 1e-6})  # refused when built, before any solve
