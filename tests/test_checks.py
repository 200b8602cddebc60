"""Pre-run validation (tubekit.checks): each check raises ConfigError naming its own field, before any work."""

from __future__ import annotations

import pytest

from tubekit.checks import (LOG_BYTES_PER_TICK, MAX_HORIZON_STEPS, MEMORY_BUDGET_BYTES, RUNS_PER_STUDY,
                            check_horizon_and_limits, check_log_size, check_run_inputs, check_start, log_bytes)
from tubekit.exceptions import ConfigError
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
