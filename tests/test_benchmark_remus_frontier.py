"""benchmarks/remus_frontier.py: where REMUS 100's velocity loop closes under a minimum surge (docs/plant.md §4)."""

from __future__ import annotations

import pytest

from tubekit.model.vehicles import vehicle_params

from .scripts import load_script


def _module():
    return load_script("benchmarks/remus_frontier.py", "bench_remus_frontier")


def test_the_midpoint_closes_at_a_crawl_and_diverges_in_yaw_at_survey_speed():
    """At u_max 0.6 m/s (u_min 0.3) the midpoint vehicle's loop closes, and the fins' floor is positive but far
    below what the loop commands; at 1.5 m/s the yaw channel's fixed point diverges (the sway coupling)."""
    mod = _module()
    params = vehicle_params("remus100").shrunk(0.0)
    slow = mod.cell(params, 0.6, 0.1, 0.02, (0.05, 0.01, 0.02))
    assert slow.startswith("E = (") and "N need" in slow
    need, floor = (float(x) for x in slow.split("N need ")[1].split(";")[0].split(" vs "))
    assert 0.0 < floor < need and "loop_saturation[N]" in slow.split("short: ")[1]
    assert mod.cell(params, 1.5, 0.1, 0.02, (0.05, 0.01, 0.02)).startswith("diverges (x")
    assert "channel r" in mod.cell(params, 1.5, 0.1, 0.02, (0.05, 0.01, 0.02))


def test_the_simulated_midpoint_follows_a_yaw_sweep_at_survey_speed_within_a_hundredth():
    """What the vehicle does (no bound): the midpoint REMUS 100 at 1.5 m/s follows a yaw command rising at
    0.02 rad/s^2 with a lag error of about T_lag x rate (0.1 s x 0.02 = 0.002 rad/s) plus the loop's own, and
    the hull sways a few cm/s: far inside what the bound cannot close."""
    mod = _module()
    params = vehicle_params("remus100").shrunk(0.0)
    du, dr, sway, rudder = mod.simulated(params, 1.5, 0.1, 0.02, None, seconds=6.0)
    assert 0.0 <= du < 0.01 and 0.001 < dr < 0.01 and 0.0 < sway < 0.1 and 0.0 < rudder < 1.0


def test_the_simulated_rudder_saturates_at_half_a_metre_per_second_and_not_at_survey_speed():
    """What the vehicle does (no bound): with the yaw command switching +-0.1 rad/s at 0.02 rad/s^2, the midpoint
    REMUS 100's rudder reaches its whole moment at 0.5 m/s (the moment grows with u^2) and well under it at
    1 m/s: a torpedo's command box must keep its surge up (docs/plant.md section 4)."""
    mod = _module()
    params = vehicle_params("remus100").shrunk(0.0)
    slow = mod.simulated(params, 0.5, 0.1, 0.02, None, seconds=20.0)[3]
    brisk = mod.simulated(params, 1.0, 0.1, 0.02, None, seconds=20.0)[3]
    assert slow >= 0.99 and brisk < 0.5


def test_at_survey_speed_with_a_high_floor_and_gentle_yaw_the_loop_closes_and_the_fins_hold_up_to_a_fifth():
    """u_max 1.3 m/s, u_min 1.0 m/s, |r| <= 0.02 rad/s, |w| <= 0.01 m/s, plans' rate (0.02, 0.005, 0.005)
    (docs/plant.md section 4): the loop's bound closes and every fin condition holds at the midpoint and over a
    fifth of the published half-widths; over the published box the fixed point still diverges, now first in surge
    (the drag's fourfold spread, X_uu in [-6.23, -1.62]; in yaw before the hull's sway bound took the turn's steady
    sway)."""
    mod = _module()
    base = vehicle_params("remus100")
    args = (1.3, 0.02, 0.01, (0.02, 0.005, 0.005), 1.0)
    for fraction in (0.0, 0.2):
        row = mod.cell(base.shrunk(fraction), *args)
        assert row.endswith("**closes, fins hold**"), row
        need, floor = (float(x) for x in row.split("N need ")[1].split(";")[0].split(" vs "))
        assert 0.0 < need < floor
    published = mod.cell(base.shrunk(1.0), *args)
    assert "diverges" in published and "channel u" in published
    with pytest.raises(SystemExit):
        mod.main(["--u-max", "1.0", "--u-min", "1.2"])


def test_with_the_surveys_loop_bandwidths_the_published_box_closes_and_only_the_propeller_and_rudder_are_short():
    """The survey file's loops (yaw 10 rad/s, heave 4 rad/s), u in [1.0, 1.2] m/s, |r| <= 0.02 rad/s, plans' rate
    (0.05, 0.005, 0.004) (docs/plant.md section 4): over the published box the loop's bound closes, the stern
    planes hold, and what is short is the surge thrust (the need above Prestero's 10.1 N, the box's weakest
    propeller) and the rudder; with the vehicle's own 5 rad/s loops the same cell's fixed point diverges."""
    mod = _module()
    args = ([1.2], [1.0], 0.02, 0.01, (0.05, 0.005, 0.004), 1.0)
    row = mod.table(*args, {"yaw_loop_bandwidth": 10.0, "heave_loop_bandwidth": 4.0})[1]
    assert "E = (" in row and row.endswith("short: loop_saturation[X], loop_saturation[N]"), row
    needs = {ch: tuple(float(x) for x in row.split(f"{ch} need ")[1].split(";")[0].split(" vs ")) for ch in "XZN"}
    assert needs["X"][1] == vehicle_params("remus100").interval("X_max")[0] < needs["X"][0]
    assert needs["Z"][0] < needs["Z"][1] and needs["N"][0] > needs["N"][1] > 0.0
    assert "diverges" in mod.table(*args)[1]
    with pytest.raises(SystemExit):
        mod.main(["--u-max", "1.2", "--yaw-bandwidth", "0"])
