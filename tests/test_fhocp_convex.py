"""The convex subproblem: DPP, built once, fast path equal to cvxpy's own solve path, terminal modes."""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

from tubekit.fhocp import FHOCP, ScpOptions

from .fhocp_cases import OBSTACLES, SC, STATES, tightening


@pytest.fixture(scope="module")
def rt() -> FHOCP:
    return FHOCP(SC, tightening(), mode="realtime")


def test_problem_is_dpp(rt):
    assert isinstance(rt.problem, cp.Problem)
    assert rt.problem.is_dcp(dpp=True)
    assert rt.problem.is_dpp()


def test_fast_path_data_equals_cvxpy_apply_parameters(rt):
    rt.reset()
    t, s = STATES[2]
    rt.solve(t, np.array(s), OBSTACLES)
    assert rt.compiled.verify() < 1e-12


def test_resolve_does_not_recanonicalise(monkeypatch):
    solver = FHOCP(SC, tightening(), mode="converged")
    t, s = STATES[1]
    solver.solve(t, np.array(s), OBSTACLES)
    clarabel_obj = solver.compiled.backend._solver
    rebuilds = solver.compiled.rebuilds

    def forbidden(*args, **kwargs):
        raise AssertionError("cvxpy re-canonicalised the problem")

    from cvxpy.reductions.cvx_attr2constr import CvxAttr2Constr
    from cvxpy.reductions.dcp2cone.cone_matrix_stuffing import ConeMatrixStuffing
    from cvxpy.reductions.dcp2cone.dcp2cone import Dcp2Cone
    from cvxpy.reductions.solvers.solving_chain import SolvingChain
    for cls in (Dcp2Cone, ConeMatrixStuffing, CvxAttr2Constr, SolvingChain):
        monkeypatch.setattr(cls, "apply", forbidden)
    monkeypatch.setattr(cp.Problem, "get_problem_data", forbidden)
    updates = solver.compiled.updates
    for k, (t, s) in enumerate(STATES):
        res = solver.solve(t, np.array(s), OBSTACLES if k % 2 else ())
        assert not res.fallback
    assert solver.compiled.backend._solver is clarabel_obj  # persistent Clarabel solver
    assert solver.compiled.rebuilds == rebuilds              # never rebuilt
    assert solver.compiled.updates > updates                 # data updates instead


def test_cvxpy_path_reuses_its_compiled_map(monkeypatch):
    solver = FHOCP(SC, tightening(), mode="realtime", options=ScpOptions(fast_path=False))
    t, s = STATES[1]
    solver.solve(t, np.array(s), OBSTACLES)
    prog = solver.problem._cache.param_prog
    assert prog is not None

    from cvxpy.reductions.dcp2cone.dcp2cone import Dcp2Cone
    from cvxpy.reductions.solvers.solving_chain import SolvingChain

    def forbidden(*args, **kwargs):
        raise AssertionError("cvxpy re-canonicalised the problem")

    monkeypatch.setattr(Dcp2Cone, "apply", forbidden)
    monkeypatch.setattr(SolvingChain, "apply", forbidden)
    for t, s in STATES[2:4]:
        assert not solver.solve(t, np.array(s), OBSTACLES).fallback
    assert solver.problem._cache.param_prog is prog


@pytest.mark.parametrize("mode", ["realtime", "converged"])
def test_fast_path_equals_problem_solve_path(mode):
    fast = FHOCP(SC, tightening(), mode=mode)
    slow = FHOCP(SC, tightening(), mode=mode, options=ScpOptions(fast_path=False))
    assert fast.compiled is not None and slow.compiled is None
    for t, s in STATES[:4]:
        a = fast.solve(t, np.array(s), OBSTACLES)
        b = slow.solve(t, np.array(s), OBSTACLES)
        assert a.iterations == b.iterations
        assert np.allclose(a.inputs, b.inputs, atol=1e-5)
        assert a.merit == pytest.approx(b.merit, rel=1e-6)


def test_subproblem_objective_equals_cvxpy_value(rt):
    rt.reset()
    t, s = STATES[3]
    rt.solve(t, np.array(s), OBSTACLES)
    status, v, obj, _ = rt._solve_subproblem()
    assert status == "optimal"
    rt.push_parameters()
    rt.problem.solve(solver=cp.CLARABEL, presolve_enable=False)
    assert obj == pytest.approx(rt.problem.value, rel=1e-6)
    vv = np.stack([rt.variables[k].value for k in ("u", "w", "r")], axis=1)
    assert np.allclose(v, vv, atol=1e-5)


@pytest.mark.parametrize("terminal", ["soft", "hard", "off"])
def test_terminal_modes_build_and_solve(terminal):
    solver = FHOCP(SC, tightening(), options=ScpOptions(terminal=terminal))
    assert solver.problem.is_dcp(dpp=True)
    t, s = STATES[1]
    res = solver.solve(t, np.array(s), OBSTACLES)
    assert not res.fallback
    if terminal == "off":
        assert res.violations["terminal"] == 0.0


def test_the_lookahead_moves_only_the_known_obstacles_rows_by_its_margins():
    """With controller.lookahead the nodes' obstacle rows of the obstacles in the problem move by the margins of
    FhocpNlp.lookahead_margins, the inactive slots and the terminal rows stay as without it."""
    import dataclasses

    from .fhocp_cases import backup_plan
    tight = dataclasses.replace(tightening(), backup=backup_plan())
    plain = FHOCP(SC, tight, mode="realtime")
    ahead = FHOCP(SC.with_changes(**{"controller.lookahead": 1.5}), tight, mode="realtime")
    t, s = STATES[2]
    for solver in (plain, ahead):
        solver.reset()
        solver.solve(t, np.array(s), OBSTACLES)
    sub_p, sub_a = plain.subproblem, ahead.subproblem
    # the same linearisation point for both: write the rows once more from the plain solver's last point
    obs = np.array([[*o.center, o.radius] for o in OBSTACLES[:plain.max_obstacles]], dtype=float)
    state = np.array(s, dtype=float)
    from tubekit.fhocp.nlp import rollout
    v = np.zeros((plain.nlp.n, 3))
    for sub in (sub_p, sub_a):
        sub.linearise(state, rollout(state, v, plain.nlp.dt), v, np.zeros((plain.nlp.n + 1, 3)), obs, 0.1)
    m, n = plain.max_obstacles, plain.nlp.n
    rows_p = sub_p.param_vector[sub_p._gidx["obs"]].reshape(m, 4, n).copy()
    rows_a = sub_a.param_vector[sub_a._gidx["obs"]].reshape(m, 4, n).copy()
    k = len(obs)
    assert k >= 1 and ahead.nlp.lookahead_margins()[-1] > 1.0
    np.testing.assert_allclose(rows_a[:k, 3, :] - rows_p[:k, 3, :],
                               np.broadcast_to(ahead.nlp.lookahead_margins(), (k, n)), atol=1e-12)
    np.testing.assert_array_equal(rows_a[:, :3, :], rows_p[:, :3, :])
    np.testing.assert_array_equal(sub_a.param_vector[sub_a._gidx["obsT"]], sub_p.param_vector[sub_p._gidx["obsT"]])
    # no obstacle known: no row moves
    for sub in (sub_p, sub_a):
        sub.linearise(state, rollout(state, v, plain.nlp.dt), v, np.zeros((n + 1, 3)), obs[:0], 0.1)
    np.testing.assert_array_equal(sub_a.param_vector[sub_a._gidx["obs"]], sub_p.param_vector[sub_p._gidx["obs"]])


def test_the_last_rows_bounds_meet_the_row_faces_or_pin_to_the_nearest_trust_edge():
    """With a tracking tightening whose X_f has row faces (examples/smooth_line.toml), the last row's bounds are the
    trust box intersected with the faces' box about the law's row at the linearisation's end; where the two are
    apart, both bounds sit on the trust box's end nearest the faces; the other rows' bounds are the trust box's."""
    from pathlib import Path

    import verify
    from tubekit import load_scenario
    from tubekit.fhocp.nlp import rollout
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "smooth_line.toml")
    solver = FHOCP(sc, verify.certify(sc).tightening, mode="realtime")
    sub, nlp = solver.subproblem, solver.nlp
    assert nlp.terminal_rows is not None
    state = np.asarray(sc.initial_state, dtype=float)
    ref = np.asarray(nlp.reference(sc.trajectory, 0.0), dtype=float)
    velocity = np.asarray(sc.trajectory.velocity(nlp.n * nlp.dt), dtype=float).reshape(3)
    sub.write_target_velocity(velocity)
    names = (("ulo", "uhi"), ("wlo", "whi"), ("rlo", "rhi"))
    seen = set()
    for cruise, radius in ((0.15, 1.0), (0.0, 0.05)):       # near the law's surge; far from it with a small trust box
        v = np.tile([cruise, 0.0, 0.0], (nlp.n, 1))
        s = rollout(state, v, nlp.dt)
        sub.linearise(state, s, v, ref, np.zeros((0, 4)), radius)
        lo, hi = nlp.last_row_box(s[-1], ref[-1], velocity)
        for c, (a, b) in enumerate(names):
            low, high = sub.param_vector[sub._cols[a]], sub.param_vector[sub._cols[b]]
            reach = radius * nlp.v_max[c]
            trust = (max(nlp.v_min[c], v[-1, c] - reach), min(nlp.v_max[c], v[-1, c] + reach))
            assert low[0] == pytest.approx(trust[0]) and high[0] == pytest.approx(trust[1])   # the first row: the trust box
            if lo[c] <= trust[1] and hi[c] >= trust[0]:
                assert low[-1] == pytest.approx(max(trust[0], lo[c])) and high[-1] == pytest.approx(min(trust[1], hi[c]))
                seen.add("meet")
            else:
                edge = trust[1] if lo[c] > trust[1] else trust[0]
                assert low[-1] == pytest.approx(edge) and high[-1] == pytest.approx(edge)
                seen.add("apart")
    assert seen == {"meet", "apart"}
