"""verify.theorem.initial_plan: the terminal law's own plan from the start, checked once at certify time."""

from __future__ import annotations

import numpy as np
import pytest

import verify
from tubekit import load_scenario
from tubekit.loop.plan_check import check_plan
from verify.theorem.initial_plan import initial_plan_condition, law_plan, start_distance

PC = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


def test_the_plan_is_the_loops_candidate_at_t0_and_passes_the_loops_check(pc_cert):
    """The certify-time evaluation agrees with the loop: the same rows (``candidate_plan`` with no plan) pass the
    loop's own exact check (``tubekit.loop.plan_check``, independent code) when ``initial_terminal`` holds."""
    from tubekit.loop.candidate import candidate_plan
    tight = pc_cert.tightening
    rows, arcs, _ = law_plan(PC, pc_cert.design.terminal, np.asarray(pc_cert.design.v_bar))
    x0 = np.asarray(PC.initial_state, float)
    loop_rows = candidate_plan(PC, None, 0, x0, 0.0, tight.v_max, None, 1.0, law=tight.terminal_law)
    np.testing.assert_allclose(loop_rows, rows, rtol=0, atol=1e-12)
    cond = initial_plan_condition(PC, pc_cert.design, pc_cert.region, pc_cert.design.terminal,
                                  pc_cert.backup.safe_set)
    check = check_plan(PC, tight, 0.0, x0, loop_rows, PC.obstacles, -1)
    assert cond.ok and check.ok and cond.lhs == pytest.approx(check.slack, abs=1e-9)


def test_a_start_pointing_away_is_refused_naming_the_tightest_row(pc_cert):
    sc = PC.with_changes(initial_state=(-0.8, 3.0, 0.2, 2.0))
    cond = initial_plan_condition(sc, pc_cert.design, pc_cert.region, pc_cert.design.terminal,
                                  pc_cert.backup.safe_set)
    assert not cond.ok and cond.lhs < 0 and "tightest:" in cond.detail


def test_under_rate_limited_plans_the_plan_leaves_rest_by_the_jump_and_is_the_loops_candidate():
    """examples/smooth_line.toml: the law's rows from the start are clipped to within J of the row before them,
    the first of rest (the run starts at rest), as the loop's candidate is; the loop's check (the row faces
    against the last row included) accepts them and agrees with ``initial_terminal``."""
    from pathlib import Path
    from tubekit.loop.candidate import candidate_plan
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "smooth_line.toml")
    cert = verify.certify(sc)
    tight, jump = cert.tightening, sc.limits.jump(sc.controller.dt)
    rows, _, _ = law_plan(sc, cert.design.terminal, np.asarray(cert.design.v_bar))
    assert np.all(np.abs(np.diff(np.vstack([np.zeros(3), rows]), axis=0)) <= jump + 1e-15)
    x0 = np.asarray(sc.initial_state, float)
    loop_rows = candidate_plan(sc, None, 0, x0, 0.0, tight.v_max, jump, 1.0, law=tight.terminal_law,
                               v_last=np.zeros(3))
    np.testing.assert_allclose(loop_rows, rows, rtol=0, atol=1e-12)
    cond = initial_plan_condition(sc, cert.design, cert.region, cert.design.terminal, cert.backup.safe_set)
    check = check_plan(sc, tight, 0.0, x0, loop_rows, sc.obstacles, -1, v_last=np.zeros(3))
    assert cond.ok and check.ok and cond.lhs == pytest.approx(check.slack, abs=1e-9)


def test_the_start_distance_is_horizontal_and_taken_from_the_target_at_t0():
    """A line target from the origin, the start 3 m behind, 4 m beside and 7 m below it: 5 m (depth not counted)."""
    from pathlib import Path
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "line.toml")
    p0 = np.asarray(sc.trajectory.position(0.0), dtype=float).reshape(3)
    moved = sc.with_changes(initial_state=(p0[0] - 3.0, p0[1] + 4.0, p0[2] - 7.0, 0.0))
    assert start_distance(moved) == pytest.approx(5.0, rel=1e-12)

