"""Pre-run validation (tubekit.checks): each check raises ConfigError naming its own field, before any work."""

from __future__ import annotations

import re

import pytest

from tubekit.checks import (LOG_BYTES_PER_TICK, MAX_HORIZON_STEPS, MEMORY_BUDGET_BYTES, RUNS_PER_STUDY,
                            check_horizon_and_limits, check_log_size, check_run_inputs, check_start, check_target,
                            horizon_reach, log_bytes, require_one_period, workspace_fits, workspace_rule)
from tubekit.exceptions import ConfigError
from tubekit.model.trajectory import Circle, Line
from tubekit.scenario import paper_scenario, scenario_from_dict


def _field(scenario, duration=None) -> str:
    with pytest.raises(ConfigError) as exc:
        check_run_inputs(scenario, duration)
    return exc.value.field


def test_paper_scenario_passes():
    check_run_inputs(paper_scenario())


def test_log_bytes_counts_every_tick_of_both_runs():
    sc = paper_scenario()  # 100 s at 100 Hz
    assert log_bytes(sc) == RUNS_PER_STUDY * LOG_BYTES_PER_TICK * (100 * 100 + 1)
    assert log_bytes(sc, 1.0) == RUNS_PER_STUDY * LOG_BYTES_PER_TICK * 101


def test_duration_beyond_the_memory_budget_names_duration():
    sc = paper_scenario()
    with pytest.raises(ConfigError) as exc:
        check_log_size(sc, 1e9)
    assert exc.value.field == "duration" and "GiB" in str(exc.value) and "TiB" in str(exc.value)
    longest = MEMORY_BUDGET_BYTES / (RUNS_PER_STUDY * LOG_BYTES_PER_TICK) / 100.0
    check_log_size(sc, 0.9 * longest)  # just inside the budget


@pytest.mark.parametrize("state, words", [
    ((3.0, 0.0, 0.0, 0.0), "obstacles[0]"),          # on the obstacle
    ((3.0, 0.55, 0.0, 0.0), "obstacles[0]"),         # outside the obstacle, inside its inflation by r-bar
    ((-3.0, 0.59, 0.0, 0.0), "obstacles[1]"),
    ((50.0, 3.0, 0.0, 0.0), "workspace"),
    ((0.0, 3.0, 0.0, 0.0), "e_d(0)"),                # on the target: e_o undefined
    ((0.05, 3.0, 0.0, 0.0), "e_d(0)"),               # closer than epsilon = 0.1 m
])
def test_bad_start_names_initial_state(state, words):
    sc = paper_scenario().with_changes(initial_state=state)
    with pytest.raises(ConfigError) as exc:
        check_start(sc)
    assert exc.value.field == "initial_state" and words in str(exc.value)


def test_start_just_clear_of_the_inflated_obstacle_passes():
    check_start(paper_scenario().with_changes(initial_state=(3.0, 0.61, 0.0, 0.0)))


@pytest.mark.parametrize("table, field", [
    ({"controller": {"horizon_steps": 100000}}, "controller.horizon_steps"),
    ({"controller": {"horizon_steps": MAX_HORIZON_STEPS + 1}}, "controller.horizon_steps"),
    ({"controller": {"horizon_steps": 400}}, "controller.horizon_steps"),   # u_max N dt = 16 m > workspace
    ({"limits": {"u_max": 40}}, "limits.u_max"),
    ({"workspace": [[-0.8, 2.7, -1.0], [-0.2, 3.3, 1.0]], "obstacles": []}, "workspace"),
])
def test_horizon_and_limits_name_their_own_field(table, field):
    sc = scenario_from_dict(table)
    with pytest.raises(ConfigError) as exc:
        check_horizon_and_limits(sc)
    assert exc.value.field == field
    assert "array(" not in str(exc.value) and "np.float64" not in str(exc.value)


def test_no_workspace_only_caps_the_horizon():
    check_horizon_and_limits(scenario_from_dict({"workspace": None, "limits": {"u_max": 40}}))
    assert _field(scenario_from_dict({"workspace": None, "controller": {"horizon_steps": 10 ** 5}})) == \
        "controller.horizon_steps"


def test_check_run_inputs_rejects_a_bad_duration_argument():
    assert _field(paper_scenario(), float("nan")) == "duration"
    assert _field(paper_scenario(), -1.0) == "duration"
    assert _field(paper_scenario(), 1e9) == "duration"


@pytest.mark.parametrize("duration, dt", [(0.04, 0.1), (0.0, 0.1), (-1.0, 0.1), (0.9, 2.0)])
def test_require_one_period_refuses_a_run_without_a_period(duration, dt):
    with pytest.raises(ConfigError, match=rf"^--duration: expected at least one FHOCP period \({dt:g} s\)"):
        require_one_period("--duration", duration, dt)


@pytest.mark.parametrize("duration, dt", [(0.1, 0.1), (0.06, 0.1), (100.0, 0.1), (1.2, 2.0)])
def test_require_one_period_accepts_a_run_of_one_period_or_more(duration, dt):
    require_one_period("duration", duration, dt)  # the loop runs round(duration / dt) >= 1 periods


def test_workspace_rule_is_strict_on_both_horizontal_axes():
    box = ((-2.0, -3.0, -1.0), (2.0, 3.0, 1.0))        # x extent 4 m, y extent 6 m; z is not read
    assert horizon_reach(0.5, 0.1, 8) == pytest.approx(0.4)
    assert workspace_fits(box, 0.5, 1.4)                 # 4 - 1 = 3 > 2.8
    assert not workspace_fits(box, 0.5, 1.5)             # 3 > 3 fails: strict
    assert not workspace_fits(box, 1.0, 1.0)             # x: 4 - 2 = 2 > 2 fails
    assert workspace_fits(((-5.0, -5.0, 0.0), (5.0, 5.0, 0.1)), 1.0, 3.9)
    assert workspace_rule(0.2, 0.3) == "x and y extents > 2 (vehicle_radius + u_max N dt) = 1 m"


def test_fhocp_and_pre_run_check_share_the_workspace_rule():
    """The FHOCP's check (tightened speed and clearance) is the same rule as the pre-run check's."""
    from tubekit.fhocp import FHOCP
    from tubekit.tightening import Tightening
    narrow = paper_scenario().with_changes(workspace=((-0.5, -5.0, -1.0), (0.5, 5.0, 1.0)))  # 1 - 0.4 < 0.64
    with pytest.raises(ConfigError, match=r"^workspace: expected .*x and y extents > 2"):
        check_run_inputs(narrow)
    with pytest.raises(ConfigError, match=r"^scenario\.workspace: expected x and y extents > 2 \(vehicle_radius \+ "
                                          r"obstacle_margin \+ u_max T\)"):
        FHOCP(narrow, Tightening.untightened(narrow))


@pytest.mark.parametrize("trajectory, instant", [
    (Circle(radius=1e6), "p_d(0 s) = [0, 1e+06, 0] m is 1e+06 m outside"),        # the circle
    (Line(start=(0.0, 0.0, 0.0), direction_velocity=(1.0, 0.0, 0.0)), "p_d(100 s) = [100, 0, 0] m is 90 m outside"),
])
def test_a_target_path_that_leaves_the_workspace_is_refused(trajectory, instant):
    """Issue 24 item 2: the target must stay in the workspace box over the run (x in [-10, 10] m, by hand)."""
    sc = paper_scenario().with_changes(trajectory=trajectory, obstacles=(), initial_state=(-2.0, 0.0, 0.0, 0.0))
    with pytest.raises(ConfigError, match=r"^trajectory: expected a target path p_d\(t\) inside the workspace") as err:
        check_target(sc)
    assert instant in str(err.value)


def test_a_target_path_inside_the_workspace_passes():
    line = Line(start=(0.0, 0.0, 0.0), direction_velocity=(0.05, 0.0, 0.0))  # 5 m in 100 s: inside
    check_target(paper_scenario().with_changes(trajectory=line))
    check_target(paper_scenario().with_changes(workspace=None, trajectory=Circle(radius=1e6)))  # no box: no check


@pytest.mark.parametrize("duration", [1e308, 1.7976931348623157e308, 1e10])
def test_require_one_period_refuses_counts_that_overflow(duration):
    """Issue 24 item 1: duration / dt beyond MAX_PERIODS (or beyond a float) is a ConfigError, not OverflowError."""
    with pytest.raises(ConfigError, match=r"^--duration: expected at most 1e\+09 FHOCP periods of 0\.1 s"):
        require_one_period("--duration", duration, 0.1)


@pytest.mark.parametrize("changes, named", [
    ({"limits.r_max": 30.0}, r"limits\.r_max = 30 rad/s .*30 deg/s = 0\.5236 rad/s"),
    ({"initial_state": (-0.5, 3.0, 0.2, 90.0)}, r"initial_state\[3\] .* = 90 rad .*90 deg = 1\.571 rad"),
    ({"limits.rate": (0.1, 0.1, 10.0)}, r"limits\.rate\[2\] = 10 rad/s\^2"),
])
def test_a_value_that_looks_like_degrees_gets_a_hint(changes, named):
    """Issue 35, item 7: r_max = 30 meant as deg/s and a heading of 90 meant as degrees now say so."""
    from tubekit.checks import unit_hints
    hints = unit_hints(paper_scenario().with_changes(**changes))
    assert len(hints) == 1 and re.search(named, hints[0])
    assert unit_hints(paper_scenario()) == ()


def test_the_api_warns_and_the_cli_logs_the_hint(tmp_path, caplog):
    import tubekit
    from tubekit.app.commands_verify import load_checked
    sc = paper_scenario().with_changes(**{"limits.r_max": 30.0})
    with pytest.warns(UserWarning, match="limits.r_max = 30 rad/s"):
        tubekit.simulate(sc, None, duration=0.1, progress=False)
    path = tmp_path / "deg.toml"
    path.write_text("[limits]\nr_max = 30.0\n")
    with caplog.at_level("WARNING"):
        load_checked(str(path))
    assert any("hint: limits.r_max = 30 rad/s" in r.getMessage() for r in caplog.records)
