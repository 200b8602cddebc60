"""The FHOCP by sequential convex programming: solutions, warm start, fallback, validation."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit import ConfigError, Obstacle, ShapeError
from tubekit.fhocp import FHOCP, FallbackWarning, FhocpResult, ScpOptions
from tubekit.fhocp.nlp import rollout, select_obstacles
from tubekit.fhocp.rows import RATE_MARGIN
from tubekit.loop.plan_check import plan_arcs
from tubekit.loop.terminal import terminal_condition

from .fhocp_cases import OBSTACLES, SC, STATES, backup_plan, tightening


@pytest.fixture(scope="module")
def rt() -> FHOCP:
    return FHOCP(SC, tightening(), mode="realtime")


@pytest.fixture(scope="module")
def conv() -> FHOCP:
    return FHOCP(SC, tightening(), mode="converged")


# ------------------------------------------------------------------ solutions
def test_result_shapes_and_consistency(rt):
    rt.reset()
    t, s = STATES[1]
    res = rt.solve(t, np.array(s), OBSTACLES)
    N = SC.controller.horizon_steps
    assert isinstance(res, FhocpResult)
    assert res.states.shape == (N + 1, 4) and res.inputs.shape == (N, 3)
    assert np.array_equal(res.first_input, res.inputs[0])
    assert np.allclose(res.states[0], s)
    assert np.allclose(res.states, rollout(np.array(s), res.inputs, SC.controller.dt))
    assert res.status == "optimal" and not res.fallback
    assert res.iterations >= 1 and res.solve_time_s > 0 and 0 <= res.setup_time_s <= res.solve_time_s
    assert set(res.violations) == {"e_d_min", "obstacle", "e_o", "box", "terminal", "input", "dynamics"}


def test_converged_plans_satisfy_the_nonlinear_constraints(conv):
    for t, s in STATES:
        conv.reset()
        res = conv.solve(t, np.array(s), OBSTACLES)
        res.check(1e-6)
        assert res.status in ("optimal", "optimal_inaccurate")
        assert np.all(np.abs(res.inputs) <= tightening().v_max)


def test_realtime_plans_along_a_run_keep_conservative_constraints():
    solver = FHOCP(SC, tightening(), mode="realtime")
    t, s = STATES[1]
    s = np.array(s)
    for k in range(25):  # drive the nominal model with the plan's first input
        res = solver.solve(t, s, OBSTACLES)
        assert not res.fallback and (k == 0 or res.iterations == 1)
        v = res.violations
        # half-spaces are inner approximations of the linearised step: what remains is the rollout's
        # departure from it, second order in the one real-time step (measured 1.4e-6 m at most here)
        assert v["obstacle"] <= 1e-5 and v["e_d_min"] <= 1e-5
        assert v["input"] == 0.0 and v["dynamics"] <= 1e-12
        s, t = res.states[1], t + SC.controller.dt


def test_converged_cost_not_above_realtime(conv, rt):
    for t, s in STATES[1:4]:
        conv.reset()
        rt.reset()
        a = conv.solve(t, np.array(s), OBSTACLES)
        b = rt.solve(t, np.array(s), OBSTACLES)   # cold start: runs the converged loop too
        assert a.merit <= b.merit * (1 + 1e-6)


def test_obstacle_is_avoided_when_the_target_passes_through_it(conv):
    # target at the obstacle centre (t = 12.5 s): the plan stays outside the inflated ball
    conv.reset()
    t, s = 12.0, np.array((2.780420, 0.612101, -0.094783, -1.160212))
    res = conv.solve(t, s, OBSTACLES)
    d = np.linalg.norm(res.states[1:, :3] - np.array(OBSTACLES[0].center), axis=1)
    assert np.all(d >= 0.4 + SC.vehicle_radius + 0.05 - 1e-6)


# ------------------------------------------------------------------ warm start
def test_warm_start_is_the_shifted_previous_plan(rt):
    rt.reset()
    t, s = STATES[1]
    res = rt.solve(t, np.array(s), OBSTACLES)
    v, warm = rt.warm_start_inputs(t + SC.controller.dt)
    assert warm
    assert np.array_equal(v[:-1], res.inputs[1:]) and np.array_equal(v[-1], res.inputs[-1])
    v0, warm0 = rt.warm_start_inputs(t - 1.0)
    assert not warm0 and not v0.any()
    rt.reset()
    assert rt.plan_inputs is None
    assert not rt.warm_start_inputs(t)[1]


def test_realtime_warm_step_is_one_convex_solve(rt):
    rt.reset()
    t, s = STATES[1]
    first = rt.solve(t, np.array(s), OBSTACLES)
    assert first.iterations >= 1  # cold start: converged loop
    nxt = rt.solve(t + SC.controller.dt, first.states[1], OBSTACLES)
    assert nxt.iterations == 1


# ------------------------------------------------------------------ fallback
def _hard_terminal_solver() -> FHOCP:
    """Hard terminal set F = {||e_N||_P <= 2}: reachable near the target, not from 2.8 m away."""
    return FHOCP(SC, tightening(), mode="realtime", options=ScpOptions(terminal="hard"))


def test_forced_infeasible_subproblem_returns_shifted_previous_plan():
    solver = _hard_terminal_solver()
    t, s = STATES[1]
    ok = solver.solve(t, np.array(s), OBSTACLES)
    assert not ok.fallback and ok.violations["terminal"] <= 1e-6
    far = np.array(s) + np.array([2.0, 2.0, 0.0, 0.0])   # 2.8 m away: F unreachable in 0.8 s
    with pytest.warns(FallbackWarning, match="failed"):
        res = solver.solve(t + SC.controller.dt, far, OBSTACLES)
    assert res.fallback and res.status == "fallback"
    assert "infeasible" in res.message
    assert np.all(np.isfinite(res.inputs)) and np.all(np.isfinite(res.states))
    assert np.array_equal(res.inputs[:-1], ok.inputs[1:])
    assert np.allclose(res.states[0], far)
    assert res.max_violation > 0.1                       # reported, not hidden
    # the appended input is searched over V-bar: never worse than repeating the last input
    repeat = np.vstack([ok.inputs[1:], ok.inputs[-1:]])
    assert np.all(np.abs(res.inputs) <= solver.nlp.v_max + 1e-12)
    assert _state_violation(solver, far, res.inputs, t + SC.controller.dt) <= \
        _state_violation(solver, far, repeat, t + SC.controller.dt) + 1e-12


def _state_violation(solver, s0, inputs, t):
    """Largest non-terminal violation of a plan, via the NLP's own evaluation of a rollout."""
    nlp = solver.nlp
    ev = nlp.evaluate(rollout(s0, inputs, nlp.dt), inputs, nlp.reference(SC.trajectory, t),
                      solver.select_obstacles(s0, OBSTACLES))
    return max(v for k, v in ev.violations.items() if k != "terminal")


def test_fallback_without_previous_plan_is_searched_from_rest():
    solver = _hard_terminal_solver()
    t, s = STATES[1]
    far = np.array(s) + np.array([2.0, 2.0, 0.0, 0.0])
    with pytest.warns(FallbackWarning):
        res = solver.solve(t, far, OBSTACLES)
    assert res.fallback and np.all(np.isfinite(res.inputs))
    assert np.all(np.abs(res.inputs) <= solver.nlp.v_max + 1e-12)
    assert np.allclose(res.states[0], far)
    assert _state_violation(solver, far, res.inputs, t) <= _state_violation(solver, far, np.zeros_like(res.inputs), t)


def test_nan_from_the_solver_never_reaches_the_plant(monkeypatch):
    solver = FHOCP(SC, tightening(), mode="realtime")
    t, s = STATES[1]
    ok = solver.solve(t, np.array(s), OBSTACLES)
    N = SC.controller.horizon_steps
    monkeypatch.setattr(solver, "_solve_subproblem",
                        lambda: ("optimal", np.full((N, 3), np.nan), math.nan, 0.0))
    with pytest.warns(FallbackWarning):
        res = solver.solve(t + SC.controller.dt, ok.states[1], OBSTACLES)
    assert res.fallback and np.all(np.isfinite(res.inputs)) and np.all(np.isfinite(res.first_input))
    assert np.array_equal(res.inputs[0], ok.inputs[1])


def test_clarabel_failure_status_triggers_fallback(monkeypatch):
    """A Clarabel NumericalError (mapped to 'solver_error') gives the fallback plan."""
    solver = FHOCP(SC, tightening(), mode="realtime")
    t, s = STATES[1]
    solver.solve(t, np.array(s), OBSTACLES)

    class Failed:
        status = "NumericalError"
        x = [math.nan] * solver.compiled.n
        obj_val = math.nan
        iterations = 3

    stub = type("Stub", (), {"update": lambda self, **kw: None, "solve": lambda self: Failed()})()
    monkeypatch.setattr(solver.compiled.backend, "_solver", stub)
    with pytest.warns(FallbackWarning, match="solver_error"):
        res = solver.solve(t + SC.controller.dt, np.array(s), OBSTACLES)
    assert res.fallback and np.all(np.isfinite(res.inputs))


# ------------------------------------------------------------------ validation
def test_validation_errors():
    tg = tightening()
    with pytest.raises(ConfigError, match="mode"):
        FHOCP(SC, tg, mode="fast")
    with pytest.raises(ConfigError, match="terminal"):
        FHOCP(SC, tg, options=ScpOptions(terminal="sometimes"))
    with pytest.raises(ConfigError, match="max_obstacles"):
        FHOCP(SC, tg, options=ScpOptions(max_obstacles=-1))
    with pytest.raises(ConfigError, match="max_iterations"):
        FHOCP(SC, tg, options=ScpOptions(max_iterations=0))
    with pytest.raises(ConfigError, match="tolerance"):
        FHOCP(SC, tg, options=ScpOptions(tolerance=-1.0))
    with pytest.raises(ConfigError, match="tightening"):
        FHOCP(SC, object())
    with pytest.raises(ConfigError, match="workspace"):
        FHOCP(SC.with_changes(workspace=((-0.5, -0.5, -1.0), (0.5, 0.5, 1.0))), tg)


def test_solve_argument_errors(rt):
    with pytest.raises(ShapeError, match="state"):
        rt.solve(0.0, np.zeros(3), ())
    with pytest.raises(ConfigError, match="state"):
        rt.solve(0.0, np.array([0.0, np.nan, 0.0, 0.0]), ())
    with pytest.raises(ConfigError, match="t"):
        rt.solve(float("nan"), np.zeros(4), ())
    with pytest.raises(ConfigError, match=r"obstacles\[0\]"):
        rt.solve(0.0, np.array(SC.initial_state), [((3.0, 0.0, 0.0), 0.4)])


def test_obstacle_selection_and_slots():
    s = np.array([0.0, 0.0, 0.0, 0.0])
    obs = [Obstacle((5.0, 0.0, 0.0), 0.4), Obstacle((1.0, 0.0, 0.0), 0.4), Obstacle((0.0, 1.2, 0.0), 0.4)]
    kept, dropped = select_obstacles(s, obs, sensing_range=1.5, max_count=4)
    assert dropped == 0 and kept.shape == (2, 4)
    assert np.allclose(kept[0, :3], (1.0, 0.0, 0.0))     # nearest first; the far one is out of range
    kept, dropped = select_obstacles(s, obs, sensing_range=1.5, max_count=1)
    assert dropped == 1 and kept.shape == (1, 4)
    solver = FHOCP(SC, tightening(), options=ScpOptions(max_obstacles=1))
    with pytest.warns(RuntimeWarning, match="max_obstacles=1"):
        solver.select_obstacles(s, obs)
    none = FHOCP(SC, tightening(), options=ScpOptions(max_obstacles=0))
    res = none.solve(2.0, np.array(STATES[0][1]), ())
    assert not res.fallback


def test_cold_start_cap_reports_iteration_limit():
    solver = FHOCP(SC, tightening(), mode="converged", options=ScpOptions(cold_start_iterations=1))
    t, s = STATES[2]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = solver.solve(t, np.array(s), OBSTACLES)
    assert res.status == "iteration_limit" and not res.fallback and res.iterations == 1


def test_default_obstacle_slots_from_the_scenario():
    from tubekit.fhocp import obstacle_slots
    assert obstacle_slots(SC) == 1                       # (+-3, 0, 0) are 6 m apart, R-bar = 1.5 m
    assert FHOCP(SC, tightening()).max_obstacles == 1
    close = SC.with_changes(obstacles=(Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((3.0, 2.0, 0.0), 0.4)))
    assert obstacle_slots(close) == 2
    assert obstacle_slots(SC.with_changes(obstacles=())) == 1


# ---- the backup's terminal condition as a constraint (issue 21) -------------------------------------------

def _end_check(sc, state, res, obstacles):
    end = plan_arcs(state, res.inputs, sc.controller.dt, 1)[-1, -1]
    return terminal_condition(end[:3], backup_plan(), sc.vehicle_radius, obstacles, sc.workspace, state[:3],
                              sc.sensing_range)


@pytest.mark.parametrize("mode", ["realtime", "converged"])
def test_the_terminal_rows_keep_the_plan_end_in_the_sensed_region(mode):
    """With a 1.2 m sensing range the safe set fits only within 0.195 m of the start: the free plan goes 0.32 m."""
    sc = SC.with_changes(sensing_range=1.2)
    t, s = STATES[0]
    s = np.asarray(s, dtype=float)
    free = FHOCP(sc, tightening(sc), mode=mode).solve(t, s, ())
    bound = FHOCP(sc, dataclasses.replace(tightening(sc), backup=backup_plan()), mode=mode).solve(t, s, ())
    assert _end_check(sc, s, free, ()).reason == "sensed region" and not _end_check(sc, s, free, ()).ok
    held = _end_check(sc, s, bound, ())
    assert held.ok and held.slack < 1e-3          # it binds
    assert bound.violations["backup_terminal"] <= 1e-9 and "backup_terminal" not in free.violations


def _obstacle_ahead():
    """(t, state, (obstacle,)): the first case's state and a 0.3 m obstacle 0.9 m beyond the free plan's end."""
    t, s = STATES[0]
    s = np.asarray(s, dtype=float)
    free = FHOCP(SC, tightening(SC), mode="converged").solve(t, s, ())
    end = plan_arcs(s, free.inputs, SC.controller.dt, 1)[-1, -1]
    ahead = (end[:2] - s[:2]) / np.linalg.norm(end[:2] - s[:2])
    return t, s, (Obstacle((end[0] + 0.9 * ahead[0], end[1] + 0.9 * ahead[1], end[2]), 0.3),)


@pytest.mark.parametrize("mode", ["realtime", "converged"])
def test_the_terminal_rows_keep_the_footprint_off_an_obstacle_ahead(mode):
    """An obstacle 0.9 m beyond the free plan's end, clear of every node: only the terminal rows see it."""
    t, s, ob = _obstacle_ahead()
    without = FHOCP(SC, tightening(SC), mode=mode).solve(t, s, ob)
    with_rows = FHOCP(SC, dataclasses.replace(tightening(SC), backup=backup_plan()), mode=mode).solve(t, s, ob)
    assert without.violations["obstacle"] == 0.0 and not _end_check(SC, s, without, ob).ok
    assert _end_check(SC, s, with_rows, ob).ok and with_rows.violations["backup_terminal"] <= 1e-9


@pytest.mark.parametrize("mode", ["realtime", "converged"])
def test_an_anchor_that_may_move_lets_the_plan_end_nearer_and_still_meets_the_exact_check(mode):
    """The same obstacle ahead, the backup proved for an anchor 0.2 m from the plan's end: the rows hold about
    one anchor of the shared ring, the plan ends nearer the obstacle than with the anchor fixed, and the exact check
    (which tries the same anchors) accepts it."""
    t, s, ob = _obstacle_ahead()
    movable = dataclasses.replace(backup_plan(), anchor_reach=0.2)
    fixed = FHOCP(SC, dataclasses.replace(tightening(SC), backup=backup_plan()), mode=mode).solve(t, s, ob)
    moved = FHOCP(SC, dataclasses.replace(tightening(SC), backup=movable), mode=mode).solve(t, s, ob)
    gap = [float(np.linalg.norm(plan_arcs(s, r.inputs, SC.controller.dt, 1)[-1, -1][:2] - ob[0].center[:2]))
           for r in (fixed, moved)]
    assert gap[1] < gap[0] - 0.05 and moved.violations["backup_terminal"] <= 1e-9
    end = plan_arcs(s, moved.inputs, SC.controller.dt, 1)[-1, -1]
    check = terminal_condition(end[:3], movable, SC.vehicle_radius, ob, SC.workspace, s[:3], SC.sensing_range)
    assert check.ok and math.hypot(check.anchor[0] - end[0], check.anchor[1] - end[1]) <= 0.2 + 1e-12


def test_without_a_backup_the_problem_is_unchanged():
    solver = FHOCP(SC, tightening(SC))
    names = {v.name() for v in solver.problem.variables()}
    assert "slack_backup" not in names and not any(n.startswith("rt") for n in solver.parameters)
    with_backup = FHOCP(SC, dataclasses.replace(tightening(SC), backup=backup_plan()))
    assert "slack_backup" in {v.name() for v in with_backup.problem.variables()}


# ---- the command-rate rows and the rate penalty (issue 22 item 2, issue 24 item 8) -------------------------

RATED = SC.with_changes(**{"limits.rate": [1.0, 1.0, 2.0]})   # J = (0.1, 0.1, 0.2): (N + 1) J covers V


def _rows_by_hand(inputs, v_last, jump, rest):
    """Largest excess of |step|, |v_0 - v_last| and (rest) |v_{N-1}| over J, computed here from the plan."""
    steps = np.abs(np.diff(np.vstack([v_last, inputs]), axis=0)) - jump
    worst = float(steps.max())
    return max(worst, float(np.max(np.abs(inputs[-1]) - jump))) if rest else worst


@pytest.fixture(scope="module")
def rated():
    tight = dataclasses.replace(tightening(RATED), backup=backup_plan())
    return {m: FHOCP(RATED, tight, mode=m) for m in ("realtime", "converged")}


@given(v_last=st.tuples(st.floats(-0.4, 0.4), st.floats(-0.3, 0.3), st.floats(-0.5, 0.5)),
       case=st.sampled_from(range(len(STATES))), mode=st.sampled_from(["realtime", "converged"]))
@settings(max_examples=20)
def test_every_plan_meets_the_rate_rows_from_any_last_command(rated, v_last, case, mode):
    """Property: from any v_last inside V, the plan meets (a) steps, (b) the first node and (c) the terminal
    rest against J, within 1e-7 of the imposed J (1 - RATE_MARGIN) (Clarabel's tolerance is 1e-7 in the converged
    mode and 1e-6 in the real-time one; the rows' own scale keeps both within 1e-7 here)."""
    solver = rated[mode]
    solver.reset()
    t, s = STATES[case]
    jump = np.array(RATED.limits.rate) * RATED.controller.dt
    res = solver.solve(t, np.array(s), OBSTACLES, v_last=np.array(v_last))
    assert _rows_by_hand(res.inputs, np.array(v_last), jump * (1 - RATE_MARGIN), True) <= 1e-7
    assert _rows_by_hand(res.inputs, np.array(v_last), jump, True) <= 0.0 and res.violations["rate"] <= 1e-7
    nxt = solver.solve(t + RATED.controller.dt, res.states[1], OBSTACLES, v_last=res.inputs[0])  # warm start
    assert _rows_by_hand(nxt.inputs, res.inputs[0], jump, True) <= 0.0


def test_without_a_backup_there_is_no_terminal_rest_and_without_a_rate_no_rows():
    t, s = STATES[2]
    free = FHOCP(RATED, tightening(RATED)).solve(t, np.array(s), OBSTACLES, v_last=np.zeros(3))
    jump = np.array(RATED.limits.rate) * RATED.controller.dt
    assert _rows_by_hand(free.inputs, np.zeros(3), jump, False) <= 0.0
    assert not FHOCP(RATED, tightening(RATED)).nlp.terminal_rest
    plain = FHOCP(SC, tightening(SC))
    assert plain.nlp.rate_jump is None and "jb" not in plain.parameters


def test_the_rate_penalty_smooths_the_plan_and_zero_restores_the_paper_cost():
    t, s = STATES[1]
    plain = FHOCP(SC, tightening(), mode="converged", options=ScpOptions(rate_penalty=0.0))
    smooth = FHOCP(SC, tightening(), mode="converged", options=ScpOptions(rate_penalty=100.0))
    a = plain.solve(t, np.array(s), OBSTACLES, v_last=np.zeros(3))
    b = smooth.solve(t, np.array(s), OBSTACLES, v_last=np.zeros(3))
    rough = lambda v: float(np.sum(np.diff(np.vstack([np.zeros(3), v]), axis=0) ** 2))  # noqa: E731
    assert rough(b.inputs) < rough(a.inputs)
    # lambda = 0: the cost is the stage + terminal cost alone, recomputed here from the plan
    e = plain.nlp.errors(a.states, plain.nlp.reference(SC.trajectory, t))
    w = np.vstack([np.tile(SC.controller.dt * np.array(SC.controller.Q), (len(a.inputs), 1)), SC.controller.P])
    by_hand = float(np.sum(w * e * e) + SC.controller.dt * np.sum(np.array(SC.controller.R) * a.inputs ** 2))
    assert a.cost == pytest.approx(by_hand, rel=1e-12)
    with pytest.raises(ConfigError, match="rate_penalty"):
        ScpOptions(rate_penalty=-1.0)


# ---- a minimum surge (limits.u_min): the input box's lower corner and the loiter's terminal command ----------

def _facing_away():
    """(t, state): the second case turned round, the target behind: the free plan backs up at up to -V_bar_u."""
    t, s = STATES[1]
    s = np.array(s)
    s[3] += math.pi
    return t, s


@pytest.mark.parametrize("mode", ["realtime", "converged"])
def test_a_surge_floor_keeps_every_planned_surge_above_it(mode):
    t, s = _facing_away()
    tight = tightening()
    floor = np.array([0.15, -tight.v_max[1], -tight.v_max[2]])
    free = FHOCP(SC, tight, mode=mode).solve(t, s, OBSTACLES)
    assert free.inputs[:, 0].min() < 0.15 - 0.1            # without the floor it slows and backs up
    solver = FHOCP(SC, dataclasses.replace(tight, v_min=floor), mode=mode)
    assert np.array_equal(solver.nlp.v_min, floor)
    res = solver.solve(t, s, OBSTACLES)
    assert not res.fallback and np.all(res.inputs[:, 0] >= 0.15 - 1e-7) and res.violations["input"] == 0.0
    assert np.all(res.inputs <= tight.v_max)
    _, tail, _ = solver.shifted_candidate(t + SC.controller.dt, s, OBSTACLES)   # the fallback's grid search too
    assert np.all(tail[:, 0] >= 0.15)


def test_the_loiters_plans_end_within_j_of_its_surge():
    """A loiter backup (no ramp, surge u_l = 0.25 m/s): the terminal rest holds about (u_l, 0, 0), so the plan's
    last row is within J of it, where station keeping's plan ends within J of rest (0.15 m/s apart: never both)."""
    from tubekit.model.loiter import Loiter
    loiter = dataclasses.replace(backup_plan(), law=Loiter(0.25, 0.3, 0.5, 0.05, 0.3))
    jump = np.array(RATED.limits.rate) * RATED.controller.dt
    t, s = STATES[2]
    last = {}
    for name, backup in (("loiter", loiter), ("station", backup_plan())):
        tight = dataclasses.replace(tightening(RATED), backup=backup)
        res = FHOCP(RATED, tight, mode="converged").solve(t, np.array(s), OBSTACLES, v_last=np.zeros(3))
        assert not res.fallback and res.violations["rate"] <= 1e-7
        last[name] = res.inputs[-1]
    assert np.all(np.abs(last["loiter"] - [0.25, 0.0, 0.0]) <= jump)
    assert np.all(np.abs(last["station"]) <= jump)
