"""tubekit.loop.candidate: the shifted candidate and its completion law."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import verify
from tubekit import SolverError, load_scenario, paper_scenario
from tubekit.loop.candidate import SETTLE_MARGIN, candidate_plan, pursuit_input, settle_last_row
from tubekit.fhocp.registry import make_solver
from tubekit.loop.pipeline import certified_run
from tubekit.model.errors import error_coordinates

SC = paper_scenario()
V = SC.limits.vector


def test_the_candidate_is_the_plan_shifted_by_its_age_plus_one_then_completed():
    plan = np.column_stack([np.linspace(0.1, 0.3, 8), np.zeros(8), np.full(8, 0.1)])
    x0 = np.asarray(SC.initial_state, dtype=float)
    cand = candidate_plan(SC, plan, 2, x0, 0.3, V, None, 0.5)
    assert cand.shape == (8, 3)
    np.testing.assert_array_equal(cand[:5], plan[3:])                 # rows age + 1 .. N - 1, unchanged
    assert np.all(np.abs(cand[5:]) <= V)                              # the completion stays in V_bar
    assert candidate_plan(SC, plan, 7, x0, 0.8, V, None, 0.5) is None  # nothing left to shift


def test_the_completion_respects_the_rate_rows():
    plan = np.tile([0.0, 0.0, 0.0], (8, 1))
    jump = np.array([0.01, 0.01, 0.02])
    cand = candidate_plan(SC, plan, 0, np.asarray(SC.initial_state, dtype=float), 0.1, V, jump, 0.5)
    assert np.all(np.abs(np.diff(cand, axis=0)) <= jump + 1e-15)


@pytest.mark.parametrize("state, want", [
    ((-0.5, 3.0, 0.2, 0.0), "ahead"),      # the target (0, 3, 0) dead ahead: surge, no turn, dive to its depth
    ((0.5, 3.0, 0.0, 0.0), "behind"),      # the target behind: turn towards it, no surge while facing away
])
def test_pursuit_turns_onto_the_line_of_sight_and_closes_in(state, want):
    """Property of the completion law: it turns towards the target within a period and surges only facing it."""
    u, w, r = pursuit_input(SC, np.asarray(state), 0.0, V, 0.1)
    if want == "ahead":
        assert u > 0 and abs(r) < 1e-9 and w < 0
    else:
        assert u == 0.0 and abs(r) == pytest.approx(V[2])



def test_a_surge_floor_bounds_the_completion_from_below():
    """With V_bar's lower corner a surge floor (0.15 m/s), the completion that would stop facing away surges at the
    floor, and every completed row of the candidate keeps it; the other axes keep their symmetric bounds."""
    floor = np.array([0.15, -V[1], -V[2]])
    u, _, r = pursuit_input(SC, np.array([0.5, 3.0, 0.0, 0.0]), 0.0, V, 0.1, v_min=floor)   # the target behind
    assert u == 0.15 and abs(r) == pytest.approx(V[2])
    plan = np.tile([0.2, 0.0, 0.0], (8, 1))
    cand = candidate_plan(SC, plan, 2, np.array([0.5, 3.0, 0.0, 0.0]), 0.3, V, None, 0.1, v_min=floor)
    assert np.all(cand[:, 0] >= 0.15) and np.all(cand <= V)
    free = candidate_plan(SC, plan, 2, np.array([0.5, 3.0, 0.0, 0.0]), 0.3, V, None, 0.1)
    assert free[5:, 0].min() < 0.15     # without the floor the completion slows below it


def _spinning_in(periods: range):
    """A solver factory: the scenario's FHOCP, except that in ``periods`` its plan yaws at the full rate the way
    the heading error already leans, for the whole horizon (a plan the exact check rejects for |e_o|)."""
    def factory(scenario, tightening):
        solver = make_solver(scenario, tightening)

        class Spinning:
            def solve(self, t, state, obstacles, v_last=None):
                result = solver.solve(t, state, obstacles, v_last=v_last)
                k = int(round(t / scenario.controller.dt))
                if k not in periods:
                    return result
                lean = error_coordinates(state[None, :], np.asarray(scenario.trajectory.position(t))[None, :])[0, 2]
                inputs = np.array(result.inputs, dtype=float)
                inputs[:, 2] = math.copysign(float(tightening.v_max[2]), lean)
                return dataclasses.replace(result, inputs=inputs)
        return Spinning()
    return factory


def test_a_rejected_plan_is_replaced_by_the_candidate_and_tracking_is_kept(pc_cert):
    """Issue 31: on the certified ``paper_currents``, the solver's plans of periods 30-33 are rejected by the exact
    check; the candidate — the last plan shifted and completed by the certified terminal law — passes it in their
    place (the tracking theorem says it always does), so the backup never runs, no plan is replayed and both
    tiers' promises are kept, ``plan_available`` included. Without the candidate the rejections are replayed."""
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml").with_changes(duration=5.0)
    assert pc_cert.tightening.plan_always_available
    forced = range(30, 34)
    done = certified_run(sc, pc_cert.tightening, solver_factory=_spinning_in(forced))
    run = done.run
    assert run.rejected[list(forced)].all()
    assert run.candidate[list(forced)].all() and (run.plan_age == 0).all()
    assert not run.backup_active.any() and not run.recovery.any()
    assert done.broken == () and done.metrics["outcome"] == {"safe": "certified, kept", "tracking": "certified, kept"}
    kept = {p.name: p for p in done.promises}["plan_available"]
    assert kept.ok and kept.tier == "tracking" and kept.depends_on == ("disturbance",)
    off = sc.with_changes(**{"controller.candidate": False})
    replayed = certified_run(off, pc_cert.tightening, solver_factory=_spinning_in(forced)).run
    assert not replayed.candidate.any() and replayed.plan_age[33] >= 4


def test_under_a_surge_floor_the_bearing_faced_law_keeps_a_plan_and_the_surge_above_u_min():
    """examples/keep_moving_tracked.toml (u_min 0.2 m/s, a line target at 0.4 m/s): both tiers certified with the
    bearing face (docs/verify.md step 17b). Flown for 20 s every period has an accepted plan (the candidate where
    the solver's plan is rejected), no command falls below u_min and both tiers' promises are kept."""
    from pathlib import Path
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_tracked.toml").with_changes(
        duration=20.0)
    cert = verify.certify(sc)
    assert cert.tiers.tracking and cert.tightening.terminal_law.has_bearing
    done = certified_run(sc, cert.tightening)
    assert done.broken == () and done.metrics["outcome"] == {"safe": "certified, kept", "tracking": "certified, kept"}
    assert {p.name: p for p in done.promises}["plan_available"].ok
    assert not done.run.backup_active.any() and float(np.nanmin(done.run.inputs[:-1, 0])) >= sc.limits.u_min


SMOOTH_LINE = "smooth_line.toml"


@pytest.fixture(scope="module")
def smooth():
    from pathlib import Path
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / SMOOTH_LINE)
    return sc, verify.certify(sc)


def test_under_rate_limited_plans_the_row_faced_law_keeps_a_solver_plan_and_the_rate_rows(smooth):
    """examples/smooth_line.toml (plans limited to 0.5 m/s², 0.5 m/s², 1 rad/s²): both tiers certified with the
    row faces (docs/verify.md step 17c). Flown for 20 s every period has an accepted plan, the solver's own at all
    but a few periods (the FHOCP's last row is kept inside the faces, and its last row settled onto them), every
    command within J of the one before it, and both tiers' promises kept."""
    sc, cert = smooth
    sc = sc.with_changes(duration=20.0)
    assert cert.tiers.tracking and cert.tightening.terminal_law.has_rows
    done = certified_run(sc, cert.tightening)
    run = done.run
    assert done.broken == () and done.metrics["outcome"] == {"safe": "certified, kept", "tracking": "certified, kept"}
    assert {p.name: p for p in done.promises}["plan_available"].ok and not run.backup_active.any()
    assert int(run.rejected.sum()) <= 0.05 * len(run.rejected)
    jump = sc.limits.jump(sc.controller.dt)
    v_hat = run.v_hat[:-1]                       # held over each period: it changes at period boundaries only
    assert np.all(np.abs(np.diff(v_hat, axis=0)) <= jump + 1e-9) and np.all(np.abs(v_hat[0]) <= jump + 1e-9)


def test_the_last_row_is_settled_onto_the_faces_within_the_jump(smooth):
    """A plan whose last row is far from the law's row at its end, where the jump from the row before allows the
    faces: settled, the row lies inside the faces and within the jump; the other rows are untouched."""
    sc, cert = smooth
    law, dt = cert.tightening.terminal_law, sc.controller.dt
    x0 = np.asarray(sc.initial_state, dtype=float)
    jump = sc.limits.jump(dt)
    plan = np.tile(np.array([0.2, 0.0, 0.0]), (sc.controller.horizon_steps, 1))
    plan[-1] = [0.2 + 0.9 * jump[0], 0.9 * jump[1], -0.9 * jump[2]]
    out = settle_last_row(sc, law, plan, x0, 0.0, np.asarray(cert.tightening.v_max), jump)
    assert np.array_equal(out[:-1], plan[:-1]) and np.all(np.abs(out[-1] - out[-2]) <= jump + 1e-15)
    from tubekit.loop.plan_check import plan_arcs
    end = plan_arcs(x0, out, dt, 1)[-1, -1]
    t_end = dt * len(out)
    slacks = law.row_slacks(end, np.ravel(sc.trajectory.position(t_end)), np.ravel(sc.trajectory.velocity(t_end)),
                            out[-1], dt)
    faces = np.array([law.row_u, law.row_w, law.row_r])
    assert min(slacks.values()) >= 0.5 * SETTLE_MARGIN * float(faces.min())
    assert settle_last_row(sc, None, plan, x0, 0.0, np.asarray(cert.tightening.v_max), jump) is plan


def test_where_the_jump_cannot_reach_the_faces_the_rows_before_follow_the_settled_last_row(smooth):
    """Every row 0.3 m/s of surge above the law's row at the plan's end (more than J + S away): the last row goes
    onto the faces and the rows before it follow, each within J of the next and inside V̄; the first rows, already
    within reach, are untouched."""
    sc, cert = smooth
    law, dt = cert.tightening.terminal_law, sc.controller.dt
    x0 = np.asarray(sc.initial_state, dtype=float)
    jump, v_max = sc.limits.jump(dt), np.asarray(cert.tightening.v_max)
    plan = np.tile(np.array([0.2, 0.0, 0.0]), (sc.controller.horizon_steps, 1))
    plan[:, 0] += np.linspace(0.0, 0.3, len(plan))          # a ramp up to 0.5 m/s, J_u = 0.05 a row
    plan[:, 0] = np.minimum(plan[:, 0], v_max[0])
    out = settle_last_row(sc, law, plan, x0, 0.0, v_max, jump)
    from tubekit.loop.plan_check import plan_arcs
    end = plan_arcs(x0, out, dt, 1)[-1, -1]
    t_end = dt * len(out)
    slacks = law.row_slacks(end, np.ravel(sc.trajectory.position(t_end)), np.ravel(sc.trajectory.velocity(t_end)),
                            out[-1], dt)
    assert min(slacks.values()) >= 0.0
    assert np.all(np.abs(np.diff(out, axis=0)) <= jump + 1e-12) and np.all(np.abs(out) <= v_max + 1e-12)
    assert not np.array_equal(out[-2], plan[-2]) and np.array_equal(out[0], plan[0])


def test_at_the_start_the_law_s_rows_leave_rest_by_at_most_the_jump(smooth):
    sc, cert = smooth
    jump = sc.limits.jump(sc.controller.dt)
    x0 = np.asarray(sc.initial_state, dtype=float)
    plan = candidate_plan(sc, None, 0, x0, 0.0, np.asarray(cert.tightening.v_max), jump, 1.0,
                          law=cert.tightening.terminal_law, v_last=np.zeros(3))
    steps = np.diff(np.vstack([np.zeros(3), plan]), axis=0)
    assert np.all(np.abs(steps) <= jump + 1e-15) and np.any(np.isclose(np.abs(steps[0]), jump))


def test_a_run_under_way_starts_its_first_plan_within_the_jump_of_the_initial_command(smooth):
    """``limits.initial`` = (0.2, 0, 0): the loop's first ``v_last`` is that command, so the first plan's surge lies
    within J of 0.2 m/s (from rest it would be at most J); both tiers are certified and kept for 5 s."""
    sc, _ = smooth
    moving = sc.with_changes(duration=5.0, **{"limits.initial": (0.2, 0.0, 0.0)})
    cert = verify.certify(moving)
    done = certified_run(moving, cert.tightening)
    jump = moving.limits.jump(moving.controller.dt)
    first = done.run.v_hat[0]
    assert np.all(np.abs(first - np.array([0.2, 0.0, 0.0])) <= jump + 1e-9) and first[0] > jump[0]
    assert done.broken == () and done.metrics["outcome"] == {"safe": "certified, kept", "tracking": "certified, kept"}


class _OnceThenNothing:
    """The solver answers at t = 0 and never again: every later plan is the candidate."""

    def __init__(self, scenario, tightening):
        self.solver, self.calls = make_solver(scenario, tightening), 0

    def solve(self, t, state, obstacles, v_last=None):
        self.calls += 1
        if self.calls > 1:
            raise SolverError("refused on purpose")
        return self.solver.solve(t, state, obstacles, v_last=v_last)


@pytest.mark.parametrize("current", [None, (0.0, 0.3, 0.0)])
def test_the_feedforward_law_alone_carries_a_survey_with_the_plans_rate_and_surge_floor(current):
    """``examples/keep_moving_survey.toml`` with plans limited to (0.3, 0.3, 0.6) certifies both tiers only with
    the line-of-sight feedforward (``docs/verify.md`` step 17e). With the solver answering once, every later plan
    is the shifted candidate completed by that law: for 60 s (in the file's current, and in a steady 0.3 m/s
    current toward the rock) each passes the exact check, no backup runs, the surge stays above u_min and
    every promise holds."""
    from pathlib import Path

    import tubekit
    from tubekit.loop.closed_loop import run_closed_loop
    survey = Path(__file__).resolve().parents[1] / "examples" / "keep_moving_survey.toml"
    sc = load_scenario(survey).with_changes(**{"limits.rate": (0.3, 0.3, 0.6)})
    if current is not None:
        sc = sc.with_changes(**{"disturbance.amplitude": (0.0, 0.0, 0.0), "disturbance.constant": current})
    cert = verify.certify(sc)
    assert cert.tiers.tracking and cert.design.terminal.los_feedforward
    res = run_closed_loop(sc, cert.tightening, solver_factory=_OnceThenNothing, progress=False)
    assert np.all(res.candidate[1:]) and not np.any(res.backup_active) and np.all(res.plan_age == 0)
    assert np.min(res.inputs[:-1, 0]) >= sc.limits.u_min
    assert [p.name for p in tubekit.check_promises(res) if p.given and not p.ok] == []
