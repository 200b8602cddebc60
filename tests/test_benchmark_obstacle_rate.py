"""benchmarks/obstacle_rate.py: an obstacle near the path, the terminal law's need for fast plans against the loop."""

from __future__ import annotations

import math

import pytest

from .scripts import load_script

STUDY = load_script("benchmarks/obstacle_rate.py", "bench_obstacle_rate")
PIER, ROCK = STUDY.MISSIONS["pier"], STUDY.MISSIONS["rock"]


def test_with_a_fast_surge_rate_the_memoryless_terminal_law_holds_a_pier_three_metres_from_the_path():
    """On the kinematic plant with omega_xy 0.17 m/s (the current's 0.1 m/s and 0.07 m/s of loop error, none in yaw)
    the memoryless terminal law keeps both tiers with a pier's surface 3 m from the path once plans may change their
    surge by 0.3 m/s^2: X_f lies within the mission's 2.5 m of the target. At 0.2 m/s^2 the terminal rows' rate in
    surge is what refuses it."""
    fast = STUDY.what_if(PIER, 0.3, 0.17)
    slower = STUDY.what_if(PIER, 0.2, 0.17)
    assert fast["tiers"] == "both" and fast["failed"] == []
    assert 1.0 < fast["x_f"][0] < fast["x_f"][1] <= PIER.e_d_max
    assert slower["tiers"] == "none" and slower["failed"] == ["terminal_rate[u]"]


def test_the_loop_charges_the_plans_rate_so_the_dynamic_cell_is_refused_even_over_a_twentieth_of_the_box():
    """The same cell on the dynamic plant over the bundled box shrunk to 5 %: the loop's bound closes, its surge
    error grows with the plans' surge rate (more than fivefold from 0.05 to 0.3 m/s^2), and at 0.3 m/s^2 it
    exceeds the 0.07 m/s the what-if granted while the yaw error the kinematic plant does not have is above
    0.05 rad/s: the terminal rows' rate refuses the cell in surge and in yaw."""
    gentle, fast = STUDY.dynamic(PIER, 0.05, 0.05), STUDY.dynamic(PIER, 0.3, 0.05)
    assert all(math.isfinite(x) for x in (*gentle["error"], *fast["error"]))
    assert fast["error"][0] > 5.0 * gentle["error"][0] and fast["error"][0] > 0.07
    assert fast["error"][2] > 0.05 and fast["omega_xy"] > 0.17
    assert fast["tiers"] == "none" and {"terminal_rate[u]", "terminal_rate[r]"} <= set(fast["failed"])


def test_over_the_published_box_with_room_for_the_current_the_loop_does_not_close_even_at_the_files_rate():
    """u_max 0.5 m/s over the bundled (published) box: the loop's fixed point diverges at 0.05 m/s^2 already."""
    res = STUDY.dynamic(PIER, 0.05, 1.0)
    assert res["error"] == (math.inf,) * 3 and "loop_fixed_point" in res["failed"] and res["omega_xy"] is None


@pytest.mark.slow(16)
def test_a_rock_five_metres_from_the_survey_line_asks_the_rudder_for_several_times_what_it_has():
    """REMUS 100's survey with a rock whose surface is 5 m from the line where the vehicle passes: on the kinematic
    plant at the dynamic file's omega_xy (0.19 m/s) the law keeps both tiers with r_max 0.05 rad/s and plans turning
    at 0.02 rad/s^2 (X_f within the mission's 20 m), not at the file's 0.004; on the dynamic plant over the file's
    box those limits ask the rudder for more than three times the moment it gives at the slowest surge."""
    fast, file_rate = STUDY.what_if(ROCK, 0.02, 0.19), STUDY.what_if(ROCK, 0.004, 0.19)
    assert fast["tiers"] == "both" and fast["x_f"][1] <= ROCK.e_d_max
    assert file_rate["tiers"] == "none" and "terminal_rate[r]" in file_rate["failed"]
    res = STUDY.dynamic(ROCK, 0.02)
    need, limit = res["yaw_moment"]
    assert need > 3.0 * limit and "loop_saturation[N]" in res["failed"]


def test_the_what_if_refuses_a_disturbance_bound_below_the_current():
    with pytest.raises(ValueError, match="omega_xy: expected at least"):
        STUDY.what_if(PIER, 0.3, 0.05)
