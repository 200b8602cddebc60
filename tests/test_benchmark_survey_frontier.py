"""benchmarks/survey_frontier.py: a vehicle that must keep moving at survey speed, on the kinematic plant."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from .corners import assert_holds_share
from .scripts import load_script

STUDY = load_script("benchmarks/survey_frontier.py", "bench_survey_frontier")


def test_at_one_metre_per_second_in_the_survey_current_both_tiers_hold_with_room_and_the_loiter_refuses_a_near_rock():
    """1 m/s along a line in 0.3 m/s of current per axis, u_min 0.5 m/s, r_max 0.3 rad/s, epsilon 3 m: with the
    obstacle 30 m off the path both tiers are certified (the bearing face keeps the terminal law's surge above the
    floor); 5 m off it, tracking is refused by the path's clearance alone, the loiter's certified safe set (about
    13 m) being what the candidate's completion must keep clear."""
    far = STUDY.cell(1.0, 0.3, 30.0, r_max=0.3)
    near = STUDY.cell(1.0, 0.3, 5.0, r_max=0.3)
    assert far["tiers"] == "both" and far["failed"] == []
    assert near["tiers"] == "safe" and "path_clearance[0]" in near["failed"]
    assert set(near["failed"]) <= {"path_clearance[0]", "initial_terminal"}  # the narrowest set's start, too near
    assert near["loiter_radius"] == far["loiter_radius"] > 5.0


def test_a_target_barely_faster_than_the_surge_floor_cannot_keep_the_law_above_it():
    """0.6 m/s against u_min 0.5 m/s: P_min cos(Phi_0) less the radial correction falls below the floor."""
    res = STUDY.cell(0.6, 0.1, 30.0, r_max=0.3)
    assert res["tiers"] == "safe" and "terminal_surge_floor" in res["failed"]


def test_without_a_backup_the_sector_behind_the_target_passes_a_rock_three_metres_from_the_path():
    """The same survey with no backup law (``docs/verify.md`` step 13g): the completion's footprint is X_f's own,
    and its bearing face narrows it to the sector behind the target (step 17b), so a rock 3 m from the path keeps
    both tiers; the loiter's safe set, which the completion's end must keep clear, refuses it."""
    none = STUDY.cell(1.0, 0.3, 3.0, r_max=0.3, backup="none")
    loiter = STUDY.cell(1.0, 0.3, 3.0, r_max=0.3)
    assert none["tiers"] == "both" and none["failed"] == [] and none["loiter_radius"] is None
    assert loiter["tiers"] == "safe" and "path_clearance[0]" in loiter["failed"]
    assert set(loiter["failed"]) <= {"path_clearance[0]", "initial_terminal"}


@pytest.mark.slow
def test_under_rate_limited_plans_the_survey_keeps_both_tiers_with_a_rock_five_metres_off_in_a_current_toward_it():
    """1 m/s in 0.3 m/s of current, no backup, plans limited to (0.5, 0.5, 1.0) per second, the start 7 m behind:
    both tiers with the rock 5 m off (the row faces and the bearing face together, docs/verify.md step 17b), and
    60 s flown in a steady 0.3 m/s current toward the rock keep every promise with the solver's plan at every
    period and the surge never below u_min. At (0.3, 0.3, 0.6) both tiers hold only with the line-of-sight
    feedforward (docs/verify.md step 17e; theorem terminal/18 refused it by terminal_rate[u]); at 0.2 m/s² in surge
    the row face fails by name."""
    import tubekit
    import verify
    rated = {"r_max": 0.3, "backup": "none", "rate": (0.5, 0.5, 1.0), "start": 7.0}
    assert STUDY.cell(1.0, 0.3, 5.0, **rated) == {"tiers": "both", "failed": [], "loiter_radius": None,
                                                  "yaw_error": 0.0}       # the kinematic plant: no loop error
    shipped = tubekit.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_survey.toml")
    assert STUDY.survey(1.0, 0.3, 5.0, **rated).to_dict() == {**shipped.to_dict(), "name": "survey"}
    assert STUDY.cell(1.0, 0.3, 5.0, **{**rated, "rate": (0.3, 0.3, 0.6)})["tiers"] == "both"
    slow = STUDY.cell(1.0, 0.3, 5.0, **{**rated, "rate": (0.2, 0.2, 0.4)})
    assert slow["tiers"] == "none" and slow["failed"] == ["terminal_rate[u]"]
    toward = STUDY.survey(1.0, 0.3, 5.0, **rated).with_changes(
        **{"disturbance.amplitude": (0.0, 0.0, 0.0), "disturbance.constant": (0.0, 0.3, 0.0)})
    cert = verify.certify(toward)
    run = tubekit.simulate(toward, cert, progress=False)
    broken = [p.name for p in tubekit.check_promises(run) if p.given and not p.ok]
    assert cert.tiers.tracking and broken == [] and run.metrics["replaced_steps"] == 0
    assert float(run.metrics["min_clearance"]) > 0.0


@pytest.mark.slow
def test_at_the_yaw_rate_the_torpedos_rudder_holds_only_the_terminal_rows_and_the_missions_geometry_are_left():
    """REMUS 100's certified rudder holds |r| <= 0.02 rad/s; the yaw screen asked 0.3 / 3 = 0.1 rad/s at epsilon
    3 m in 0.3 m/s of current. Without it (docs/verify.md section 3) a 1.4 m/s survey over u in [1.0, 1.8] m/s is
    refused at the rates the loop bound takes, (0.02, 0.006, 0.005), by the surge row alone (the yaw row holds with
    the line-of-sight feedforward, step 17e), and at (0.05, 0.01, 0.02) by the rock 5 m off the path and the start
    alone: X_f lies tens of metres behind."""
    kw = dict(u_min=1.0, u_max=1.8, r_max=0.02, backup="none", start=20.0, e_d_max=60.0, sensing=150.0)
    slow = STUDY.cell(1.4, 0.3, 5.0, rate=(0.02, 0.006, 0.005), **kw)
    brisk = STUDY.cell(1.4, 0.3, 5.0, rate=(0.05, 0.01, 0.02), **kw)
    assert slow["failed"] == ["terminal_rate[u]"]
    assert set(brisk["failed"]) == {"initial_terminal", "path_clearance[0]"}


@pytest.mark.slow
def test_the_midpoint_torpedo_is_refused_only_by_where_its_terminal_set_lies_and_a_faster_yaw_loop_certifies_it():
    """REMUS 100 at its box's midpoint, 1.25 m/s in 0.15 m/s of current, u in [1.0, 1.5] m/s, |r| <= 0.02 rad/s,
    the plans' yaw rate 0.004 rad/s², on the dynamic plant. With the vehicle's own 5 rad/s loop the velocity loop's
    bound closes and every fin condition holds; the yaw loop's error E_r the tracking design carries is more than
    half of r_max (the sway's rate drives it, docs/plant.md section 4), so the only X_f whose yaw row fits lies
    farther than the start, 80 m behind the target: ``initial_terminal`` alone fails (the yaw row failed too before
    the hull's sway bound took the turn's steady sway, docs/verify.md section 9 step 4). With the yaw loop at
    10 rad/s (``yaw_loop_bandwidth``; surge and heave keep 5 rad/s: at 10 rad/s in every channel the stern planes
    saturate, ``loop_saturation[Z]``) the yaw loop's error falls below 0.6 of that and both tiers hold."""
    kw = dict(u_min=1.0, u_max=1.5, r_max=0.02, backup="none", rate=(0.05, 0.01, 0.004), start=80.0, e_d_max=100.0,
              sensing=300.0, vehicle="remus100", spread=0.0, w_max=0.015, current_z=0.005)
    own = STUDY.cell(1.25, 0.15, 40.0, **kw)
    assert own["failed"] == ["initial_terminal"]
    assert 0.5 * 0.02 < own["yaw_error"] < 0.02
    fast = STUDY.cell(1.25, 0.15, 40.0, yaw_bandwidth=10.0, **kw)
    assert fast["tiers"] == "both" and fast["yaw_error"] < 0.6 * own["yaw_error"]


def _survey_box_example(name: str):
    """The shipped REMUS example ``name``, checked to hold ±20 % of the published half-widths in every interval."""
    import tubekit
    scenario = tubekit.load_scenario(Path(__file__).resolve().parents[1] / "examples" / name)
    assert_holds_share(scenario, "remus100", 0.2)
    return scenario


@pytest.mark.slow
def test_the_shipped_survey_keeps_both_tiers_over_a_fifth_of_the_published_box_with_the_rock_in_its_way():
    """examples/remus100_survey.toml: REMUS 100 over ±20 % of the published half-widths (every interval contains
    that box: checked against the bundled vehicle), yaw loop 10 rad/s, heave 4 rad/s, 1.25 m/s in 0.15 m/s of
    current: both tiers. Flown 60 s, every promise is kept, the solver's plan at every period, the surge never below
    u_min, and the rock stands in the vehicle's way: it passes it within 21 m (the rock 20 m off the line)."""
    import numpy as np

    import tubekit
    import verify

    scenario = _survey_box_example("remus100_survey.toml")
    cert = verify.certify(scenario)
    assert cert.tiers.safe and cert.tiers.tracking
    run = tubekit.simulate(scenario, cert, progress=False)
    assert [p.name for p in tubekit.check_promises(run) if p.given and not p.ok] == []
    assert run.metrics["replaced_steps"] == 0 and float(np.min(run.inputs[:-1, 0])) >= scenario.limits.u_min > 0.5
    assert run.metrics["min_clearance"] < 21.0


@pytest.mark.slow
def test_started_settled_the_survey_keeps_both_tiers_in_twice_the_current_and_started_trimmed_it_does_not():
    """examples/remus100_tidal.toml: the survey's box (every interval contains ±20 % of the published half-widths)
    in 0.3 m/s of horizontal current at 1.25 m/s, the loop settled at the survey speed: both tiers; flown 30 s,
    every promise kept, the solver's plan at every period and the surge never below u_min. The same file started
    trimmed is refused: the start transient widens E_u and the terminal law's surge then needs less than u_min."""
    import dataclasses

    import numpy as np

    import tubekit
    import verify

    scenario = _survey_box_example("remus100_tidal.toml")
    assert min(scenario.disturbance.amplitude[:2]) >= 0.3 and scenario.trajectory.direction_velocity[0] >= 1.0
    cert = verify.certify(scenario)
    assert cert.tiers.safe and cert.tiers.tracking
    run = tubekit.simulate(scenario.with_changes(duration=30.0), cert, progress=False)
    assert [p.name for p in tubekit.check_promises(run) if p.given and not p.ok] == []
    assert run.metrics["replaced_steps"] == 0 and float(np.min(run.inputs[:-1, 0])) >= scenario.limits.u_min > 0.5
    trimmed = verify.certify(scenario.with_changes(plant=dataclasses.replace(scenario.plant, start="trimmed")))
    assert [f.condition for f in trimmed.failures] == ["terminal_surge_floor"]
    assert trimmed.velocity_loop.error[0] > cert.velocity_loop.error[0]


def test_at_one_and_a_half_metres_per_second_under_rate_limits_the_rock_lies_inside_x_f_s_sector_by_metres():
    """1.5 m/s in 0.3 m/s of current, u in [1.07, 1.9] m/s, r_max 0.13 rad/s (the torpedo's hard-over turn at
    1.07 m/s, docs/plant.md section 4), no backup, plans (0.1, 0.005, 0.02), the start 20 m behind: the rock 5 m off
    the line refuses the cell by ``path_clearance``; the refused footprint's sector (0.41 rad, 24.9 m) would clear it
    only narrowed to about 0.15 rad or shortened to about 9.5 m. By hand: the sector sweeps a strip reaching
    radius x sin(cone) beside the path, which must stay clear of the rock's centre (5 m off) by its radius and the
    arc's pads (the ball, the arc's half-run): sin(cone) x radius <= 5 − 0.5 − pads."""
    res = STUDY.clearing(1.5, 0.3, 5.0, u_min=1.07, u_max=1.9, r_max=0.13, backup="none", rate=(0.1, 0.005, 0.02),
                         start=20.0, e_d_max=30.0, sensing=250.0, current_z=0.005, w_max=0.007, rock_x=0.0)
    assert res is not None and res["cone"] == pytest.approx(0.407, abs=1e-3)
    assert res["reach"] == pytest.approx(24.88, abs=0.01)
    side = 5.0 - 0.5 - res["ball"] - res["arc_pad"]  # the rock's centre less its radius and the arc's pads
    assert res["clearing_cone"] == pytest.approx(math.asin(side / res["reach"]), abs=2e-3)
    assert res["clearing_reach"] == pytest.approx(side / math.sin(res["cone"]), abs=0.05)
    assert "horizontally it lies up to" in res["detail"]


def test_at_one_and_a_half_metres_per_second_fast_plans_keep_the_rock_five_metres_off_on_the_kinematic_plant():
    """The cell whose command box benchmarks/hull_demand.py finds beyond REMUS 100's published box: 1.5 m/s in
    0.3 m/s of current, u in [1.07, 1.9] m/s, r_max 0.08 rad/s, plans (0.3, 0.005, 0.1), X_f's room 16 m, the rock
    5 m off: both tiers on the kinematic plant (the velocity loop aside)."""
    res = STUDY.cell(1.5, 0.3, 5.0, u_min=1.07, u_max=1.9, r_max=0.08, backup="none", rate=(0.3, 0.005, 0.1),
                     start=12.0, e_d_max=16.0, sensing=250.0, current_z=0.005, w_max=0.007, rock_x=0.0)
    assert res["tiers"] == "both"


@pytest.mark.slow(12)
def test_a_command_box_the_published_hull_can_follow_keeps_the_rock_twelve_and_a_half_metres_off_at_survey_speed():
    """1.5 m/s in 0.3 m/s of current, u in [1.07, 1.9] m/s, no backup, on the kinematic plant, with the command box
    every point of REMUS 100's published box can follow (r_max 0.05 rad/s, plans (0.05, 0.005, 0.02): at most 0.75
    of its rudder and 0.74 of its propeller, benchmarks/hull_demand.py), X_f's room 45 m and the start 33 m behind:
    both tiers with the rock 12.5 m off the line; at 12 m X_f's sector (0.30 rad, 38.0 m: a strip of
    38.0 sin 0.30 = 11.1 m beside the path, plus the rock's radius and the pads) reaches it."""
    limits = dict(u_min=1.07, u_max=1.9, r_max=0.05, backup="none", rate=(0.05, 0.005, 0.02), start=33.0,
                  e_d_max=45.0, sensing=400.0, current_z=0.005, w_max=0.007, rock_x=0.0)
    assert STUDY.cell(1.5, 0.3, 12.5, **limits)["tiers"] == "both"
    assert STUDY.cell(1.5, 0.3, 12.0, **limits)["failed"] == ["path_clearance[0]"]


@given(step=st.sampled_from([0.25, 0.5, 1.0]), cells=st.integers(0, 200), edge=st.integers(0, 250))
def test_the_nearest_offset_is_the_first_grid_point_that_holds(step, cells, edge):
    """Property: for an obstacle that certifies from the grid point ``edge`` on, the search over ``cells`` grid
    points returns that point (None when it lies past the last), asking about log2(cells) + 2 cells."""
    asked = []

    def holds(offset):
        asked.append(offset)
        return offset >= edge * step - 1e-12

    found = STUDY._smallest(holds, cells * step, step)
    assert found == (edge * step if edge <= cells else None)
    assert len(asked) <= math.log2(cells + 1) + 2


def test_the_nearest_offset_refuses_a_grid_it_cannot_walk():
    with pytest.raises(ValueError, match="need step > 0 and top >= 0"):
        STUDY.nearest(1.5, 0.3, 10.0, step=0.0)
    with pytest.raises(ValueError, match="need step > 0 and top >= 0"):
        STUDY.nearest(1.5, 0.3, -1.0)


def test_the_nearest_option_prints_the_edge_under_each_cell(monkeypatch, capsys):
    """``--nearest TOP``: one line under each cell, from the study's own cells (here a stand-in certifying from 7 m
    off the path on, and nowhere at 2 m/s)."""
    def fake_cell(speed, current, offset, **limits):
        return {"tiers": "both" if speed < 2.0 and offset >= 7.0 else "none", "failed": [] if offset >= 7.0 else
                ["path_clearance[0]"], "loiter_radius": None, "yaw_error": 0.0}
    monkeypatch.setattr(STUDY, "cell", fake_cell)
    assert STUDY.main(["--speed", "1.5", "2.0", "--current", "0.3", "--offset", "5", "--nearest", "20"]) == 0
    out = capsys.readouterr().out
    assert "1.5 m/s in 0.3 m/s: both tiers with the obstacle 7 m off the path or farther" in out
    assert "2 m/s in 0.3 m/s: both tiers with the obstacle nowhere up to 20 m off the path" in out
    with pytest.raises(SystemExit):
        STUDY.main(["--nearest", "20", "--nearest-step", "0"])
