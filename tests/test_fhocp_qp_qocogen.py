"""tubekit.fhocp.qp.qocogen: a QOCO solver generated for the pattern, its status table, settings and availability."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit import ConfigError, NotAvailableError
from tubekit.fhocp.qp import generated, qocogen as qocogen_module
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.qocogen import QOCOGEN_STATUS, QocogenBackend
from tubekit.fhocp.qp.registry import make_qp_backend, qp_backends
from tubekit.fhocp.result import Status

from .qp_cases import disc, small_qp

pytest.importorskip("qocogen")
if generated.compiler() is None:
    pytest.skip("no C compiler for the generated solver", allow_module_level=True)


@pytest.fixture(scope="module", autouse=True)
def cache(tmp_path_factory):
    """One cache for the module: each pattern is built once."""
    with pytest.MonkeyPatch.context() as mp:
        root = tmp_path_factory.mktemp("qocogen")
        mp.setenv("TUBEKIT_QOCOGEN_CACHE", str(root))
        yield root


def test_the_table_follows_the_generated_solvers_status_enum(cache):
    """The raw status is the enum's name at the returned code: the table's keys in the generated header's order."""
    QocogenBackend().solve(small_qp([1.0, 0.0]))
    header = next(cache.glob("*/utils.h")).read_text()
    names = re.findall(r"(QOCO_CUSTOM_[A-Z_]+)", re.search(r"enum qoco_custom_solve_status \{(.*?)\}", header,
                                                             re.S).group(1))
    assert tuple(QOCOGEN_STATUS) == tuple(names)
    assert [raw for raw, status in QOCOGEN_STATUS.items() if status is Status.OPTIMAL] == ["QOCO_CUSTOM_SOLVED"]


def test_it_agrees_with_clarabel_on_rows_and_updates_in_place():
    backend, reference = QocogenBackend(), ClarabelBackend({"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9})
    data = small_qp([3.0, 1.0])
    for c in ([3.0, 1.0], [-0.5, 0.25], [-4.0, -2.0]):
        case = dataclasses.replace(data, q=-np.asarray(c), offset=0.5 * float(np.dot(c, c)), p_changed=False)
        a, b = reference.solve(case), backend.solve(case)
        assert b.status is Status.OPTIMAL and b.raw_status == "QOCO_CUSTOM_SOLVED"
        assert b.x == pytest.approx(a.x, abs=1e-6) and b.objective == pytest.approx(a.objective, abs=1e-6)
    assert (backend.setups, backend.updates) == (1, 2)


def test_it_takes_the_cone_and_a_changed_right_hand_side():
    backend, data = QocogenBackend(), disc(1.0)
    for radius in (1.0, 2.0, 0.5):
        sol = backend.solve(dataclasses.replace(data, b=np.array([radius, 0.0, 0.0]), p_changed=False))
        assert sol.status is Status.OPTIMAL
        assert sol.x == pytest.approx([-radius / math.sqrt(2)] * 2, abs=1e-4)
    assert make_qp_backend("qocogen").takes_cones and qp_backends()["qocogen"] is True


def test_an_infeasible_program_passes_no_solution_on():
    """The generated QOCO detects no infeasibility: x_0 <= -2 and x_1 >= 2 with x_0 = x_1 ends without x."""
    sol = QocogenBackend().solve(dataclasses.replace(small_qp([0.0, 0.0]), b=np.array([0.0, -2.0, -2.0])))
    assert not sol.status.solved and sol.x is None and math.isnan(sol.objective)


def test_the_iteration_cap_is_a_user_limit_without_a_solution():
    sol = QocogenBackend({"max_iters": 1}).solve(disc(1.0))
    assert sol.status is Status.USER_LIMIT and sol.raw_status == "QOCO_CUSTOM_MAX_ITER" and sol.x is None


@pytest.mark.parametrize(("settings", "match"), [
    ({"tolerance": 1e-6}, r"^qocogen settings: expected names of the generated solver's settings"),
    ({"abstol": 0.0}, r"^qocogen settings\.abstol: expected a number > 0"),
    ({"max_iters": True}, r"^qocogen settings\.max_iters: expected a number > 0"),
    ({"reltol": "1e-6"}, r"^qocogen settings\.reltol: expected a number > 0"),
])
def test_bad_settings_are_named_before_any_solve(settings, match):
    with pytest.raises(ConfigError, match=match):
        QocogenBackend(settings)


def test_looser_tolerances_reach_the_generated_solver():
    """Property: the settings are the solver's own; at 1e-2 the answer is farther from the exact one than at 1e-9."""
    exact = np.array([-1.0, -1.0]) / math.sqrt(2)
    loose = QocogenBackend({"abstol": 1e-2, "reltol": 1e-2}).solve(disc(1.0))
    tight = QocogenBackend({"abstol": 1e-9, "reltol": 1e-9}).solve(disc(1.0))
    assert loose.iterations < tight.iterations
    assert np.max(np.abs(tight.x - exact)) < np.max(np.abs(loose.x - exact))


def test_without_a_compiler_it_is_unavailable_with_the_hint(monkeypatch):
    monkeypatch.setattr(qocogen_module, "compiler", lambda: None)
    assert qp_backends()["qocogen"] is False
    with pytest.raises(NotAvailableError, match="needs a C compiler"):
        QocogenBackend()


@given(center=st.lists(st.floats(-5.0, 5.0), min_size=2, max_size=2),
       bounds=st.lists(st.floats(0.1, 3.0), min_size=2, max_size=2))
def test_on_random_data_of_one_pattern_it_agrees_with_clarabel_or_passes_nothing_on(center, bounds):
    """Property: over one pattern (built once), any values give Clarabel's objective within 1e-6 and its solution
    within 1e-3 (at 1e-7 an interior point lands about sqrt(1e-7) from a degenerate optimum, where a bound meets
    the unconstrained minimum; QOCO itself does the same), or a failure without a solution (the next test)."""
    data = dataclasses.replace(small_qp(center), b=np.array([0.0, bounds[0], bounds[1]]))
    a = ClarabelBackend({"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9, "tol_feas": 1e-9}).solve(data)
    b = QocogenBackend().solve(data)
    if not b.status.solved:
        assert b.x is None and math.isnan(b.objective)
        return
    assert b.x == pytest.approx(a.x, abs=1e-3) and b.objective == pytest.approx(a.objective, abs=1e-6)


def test_a_degenerate_program_qoco_solves_is_a_numerical_error_of_the_generated_solver():
    """Found by the property above (qocogen 0.1.9): min 1/2|x|^2 with x_0 = x_1, x_0 <= 1, x_1 >= -1 (optimum 0,
    every inequality slack) ends in QOCO_CUSTOM_NUMERICAL_ERROR, while QOCO itself solves it; a failure, never a
    wrong answer."""
    data = small_qp([0.0, 0.0])
    sol = QocogenBackend().solve(data)
    assert sol.raw_status == "QOCO_CUSTOM_NUMERICAL_ERROR" and sol.x is None
    qoco = pytest.importorskip("tubekit.fhocp.qp.qoco")
    assert qoco.QocoBackend().solve(data).status is Status.OPTIMAL


def test_the_real_time_fhocp_runs_the_generated_solver_at_its_real_time_tolerance():
    """The real-time mode hands the generated solver REALTIME_QOCOGEN_SETTINGS (as it hands Clarabel its own); the
    converged mode keeps the defaults."""
    from tubekit import paper_scenario
    from tubekit.fhocp.options import ScpOptions
    from tubekit.fhocp.qp.qocogen import REALTIME_QOCOGEN_SETTINGS
    from tubekit.fhocp.scp import FHOCP
    from tubekit.tightening import Tightening

    sc = paper_scenario()
    tg = Tightening.untightened(sc)
    options = ScpOptions(qp_solver="qocogen")
    realtime = FHOCP(sc, tg, mode="realtime", options=options).subproblem.compiled.backend
    converged = FHOCP(sc, tg, mode="converged", options=options).subproblem.compiled.backend
    assert dict(realtime.settings) == REALTIME_QOCOGEN_SETTINGS == {"abstol": 1e-6, "reltol": 1e-6}
    assert dict(converged.settings) == {}
