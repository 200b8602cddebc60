"""tubekit.fhocp.qp.relaxed: a QP backend without cones on the relaxation, checked, else the cone backend."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.fhocp import FHOCP
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.piqp import PiqpBackend
from tubekit.fhocp.qp.relaxed import FEASIBILITY_TOL, RelaxedQpBackend
from tubekit.fhocp.registry import make_solver

from .fhocp_cases import RUN_STATES, SC, tightening

pytest.importorskip("piqp")  # every test here solves with PIQP


def _wrapper() -> RelaxedQpBackend:
    return RelaxedQpBackend(PiqpBackend(), ClarabelBackend({"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9}))


def _ball(center, radius: float = 1.0) -> ConeProgramData:
    """min 1/2 |x - c|^2 s.t. |x| <= radius: rows s = (radius, x) in one 3-dimensional cone."""
    A = np.array([[0.0, 0.0], [-1.0, 0.0], [0.0, -1.0]])
    return ConeProgramData.from_matrices(np.eye(2), -np.asarray(center, dtype=float), A, [radius, 0.0, 0.0],
                                         ConeDims(soc=(3,)), offset=0.5 * float(np.dot(center, center)))


def _epigraph(cap: float) -> ConeProgramData:
    """Variables (x, t): min 1/2 (x - 3)^2 s.t. t >= 0, t <= cap, |x| <= t (t costs nothing: an epigraph)."""
    A = np.array([[0.0, -1.0], [0.0, 1.0], [0.0, -1.0], [-1.0, 0.0]])
    return ConeProgramData.from_matrices(np.diag([1.0, 0.0]), [-3.0, 0.0], A, [0.0, cap, 0.0, 0.0],
                                         ConeDims(nonneg=2, soc=(2,)))


def test_the_wrapper_takes_a_qp_backend_and_a_cone_backend():
    clarabel = ClarabelBackend()
    with pytest.raises(ConfigError, match=r"^qp: expected a QpBackend that takes no cones"):
        RelaxedQpBackend(clarabel, ClarabelBackend())
    with pytest.raises(ConfigError, match=r"^cones: expected a QpBackend that takes second-order cones"):
        RelaxedQpBackend(PiqpBackend(), PiqpBackend())
    with pytest.raises(ConfigError, match=r"^qp: "):
        RelaxedQpBackend("piqp", clarabel)  # type: ignore[arg-type]
    wrapper = RelaxedQpBackend(PiqpBackend(), clarabel)
    assert wrapper.takes_cones and "piqp" in wrapper.name and "clarabel" in wrapper.name


def test_a_slack_cone_is_answered_by_the_relaxation():
    wrapper = _wrapper()
    sol = wrapper.solve(_ball([0.3, -0.4]))
    assert sol.status == "optimal" and sol.raw_status == "PIQP_SOLVED (cones checked)"
    assert sol.x == pytest.approx([0.3, -0.4], abs=1e-7) and sol.objective == pytest.approx(0.0, abs=1e-9)
    assert (wrapper.relaxed_solves, wrapper.cone_solves) == (1, 0)


def test_a_violated_cone_falls_back_and_stays_with_the_cone_backend_while_it_binds():
    wrapper = _wrapper()
    data = _ball([2.0, 0.0])
    sol = wrapper.solve(data)  # the relaxation's answer (2, 0) is outside the ball
    assert sol.status == "optimal" and sol.raw_status == "Solved"
    assert sol.x == pytest.approx([1.0, 0.0], abs=1e-6) and sol.objective == pytest.approx(0.5, abs=1e-6)
    assert (wrapper.relaxed_solves, wrapper.cone_solves) == (0, 1)
    # same pattern, the cone still binds: the cone backend directly (no relaxation tried)
    wrapper.solve(dataclasses.replace(data, q=np.array([0.0, -3.0])))
    assert (wrapper.relaxed_solves, wrapper.cone_solves) == (0, 2)
    # the centre moves inside: the cone backend answers once more, its slack releases the cone ...
    inside = dataclasses.replace(data, q=np.array([-0.2, 0.0]), offset=0.02)
    assert wrapper.solve(inside).x == pytest.approx([0.2, 0.0], abs=1e-6)
    assert (wrapper.relaxed_solves, wrapper.cone_solves) == (0, 3)
    # ... and the relaxation is tried again
    assert wrapper.solve(inside).raw_status.endswith("(cones checked)")
    assert (wrapper.relaxed_solves, wrapper.cone_solves) == (1, 3)


def test_epigraph_variables_are_completed_to_their_smallest_value():
    wrapper = _wrapper()
    sol = wrapper.solve(_epigraph(cap=5.0))
    assert sol.raw_status.endswith("(cones checked)")
    assert sol.x == pytest.approx([3.0, 3.0], abs=1e-7)  # t at |x|, the least its rows allow
    # the completed t = 3 breaks t <= 2 (a linear row): the cone backend's answer
    sol = _wrapper().solve(_epigraph(cap=2.0))
    assert sol.raw_status == "Solved" and sol.x[0] == pytest.approx(2.0, abs=1e-6)
    assert sol.x[1] <= 2.0 + FEASIBILITY_TOL


def test_a_failed_relaxation_falls_back_to_the_cone_backend():
    """PIQP stopped by its iteration cap: the cone backend answers, no NaN passes."""
    wrapper = RelaxedQpBackend(PiqpBackend({"max_iter": 1}), ClarabelBackend())
    sol = wrapper.solve(_epigraph(cap=5.0))
    assert sol.raw_status == "Solved" and np.all(np.isfinite(sol.x)) and wrapper.cone_solves == 1


def test_relaxed_piqp_agrees_with_clarabel_on_the_run_subproblems():
    """The subproblems of a real-time SCP at the run states, each solved by Clarabel and by the wrapper."""
    solver = FHOCP(SC, tightening(), mode="realtime")
    clarabel, wrapper = ClarabelBackend(solver.subproblem.clarabel_settings), _wrapper()
    compiled = solver.subproblem.compiled
    for t, s in RUN_STATES[::3]:
        solver.solve(t, np.asarray(s), SC.obstacles)  # leaves the parameters of its subproblem in place
        data = compiled.program()
        a, b = clarabel.solve(data), wrapper.solve(data)
        assert a.status == b.status == "optimal"
        assert b.x[compiled.columns_of(solver.variables["u"])] == pytest.approx(
            a.x[compiled.columns_of(solver.variables["u"])], abs=1e-5)
        assert b.objective == pytest.approx(a.objective, rel=1e-6, abs=1e-6)
    assert wrapper.relaxed_solves + wrapper.cone_solves == len(RUN_STATES[::3])


def test_the_piqp_path_returns_clarabels_plans_on_the_run_states():
    """Same warm start, same state: the plans agree to the solvers' tolerances, and both the QP path
    (terminal cone slack) and the Clarabel fallback (terminal cone binding) are exercised."""
    tg = tightening()
    ref, alt = FHOCP(SC, tg, mode="realtime"), make_solver(SC, tg, "scp-piqp")
    alt.mode = ref.mode
    assert isinstance(alt.subproblem.compiled.backend, RelaxedQpBackend)
    for t, s in RUN_STATES:
        for dt in (0.0, 0.1, 0.2):  # a cold start, then two warm real-time steps
            alt._plan_t, alt._plan_inputs = ref._plan_t, ref._plan_inputs
            a = ref.solve(t + dt, np.asarray(s), SC.obstacles)
            b = alt.solve(t + dt, np.asarray(s), SC.obstacles)
            # PIQP at 1e-9 against the real-time mode's Clarabel at 1e-6 (REALTIME_CLARABEL_SETTINGS)
            np.testing.assert_allclose(b.inputs, a.inputs, atol=1e-4)
            # cold starts run the converged loop: the tolerance 1e-5 on its stopping test, with exact
            # penalties of weight 1e3, leaves the merit equal to ~1e-4 between two solvers; the real-time
            # Clarabel at 1e-6 adds up to ~2e-4 (measured 2.1e-4 on these states)
            assert b.merit == pytest.approx(a.merit, rel=1e-3)
            assert not b.fallback
    backend = alt.subproblem.compiled.backend
    assert backend.relaxed_solves > 0 and backend.cone_solves > 0
