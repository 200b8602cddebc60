"""benchmarks/hull_demand.py: the rudder and the propeller a hull needs to follow an admissible command exactly."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from tubekit.model.vehicle_sets import REMUS100

from .scripts import load_script

DEMAND = load_script("benchmarks/hull_demand.py", "hull_demand_benchmark")
TURN = load_script("benchmarks/steady_turn.py", "steady_turn_for_hull_demand")


@st.composite
def remus_points(draw):
    """A point hull of the bundled REMUS 100 box: each coefficient of the sway and yaw rows drawn in its interval."""
    names = [n for n in DEMAND.YAW_FIELDS if n in REMUS100.free_fields]
    return REMUS100.with_point({n: draw(st.floats(*REMUS100.interval(n))) for n in names})


@settings(max_examples=8, deadline=None, derandomize=True)
@given(params=remus_points(), u=st.floats(0.5, 1.9))
def test_held_at_the_hulls_own_full_rudder_turn_the_need_is_its_whole_rudder(params, u):
    """Property: with r_max the steady turn at full rudder (benchmarks/steady_turn.py: a root search on the two rows,
    not the sway's integration), the moment after the hold at +r_max is the rudder's whole moment."""
    turn = TURN.steady_turn(params, u)
    demand = DEMAND.yaw_demand(params, u, turn.r, 0.05)
    assert demand.rudder == pytest.approx(turn.moment, rel=1e-12)
    assert demand.steady == pytest.approx(turn.moment, rel=1e-6)
    assert demand.peak >= demand.steady * (1.0 - 1e-9)


def _linear_moment_peak(p, u: float, r_max: float, rho: float) -> float:
    """max |N(t)| on a dense grid for a hull whose sway and yaw rows are linear, from the closed form of its sway
    (written from body_forces' terms by hand): n2 = a v + b r, n4 = c v + d r, m22 v' = -(a v + b r) - m24 r'."""
    m11, m22, _, m44, m24, m42 = p.mass_entries
    a, b = -p.Y_v - p.Y_uv * u, (m11 - p.Y_ur_lift) * u
    c, d = (m22 - m11 - p.N_uv_lift) * u, m24 * u - p.N_r - p.N_ur_lift * u
    k, ramp = a / m22, 2.0 * r_max / rho
    slope = -b * rho / a                                   # the ramp's particular solution alpha + slope t
    alpha = (b * r_max - m24 * rho - m22 * slope) / a
    v0 = b * r_max / a                                     # steady at -r_max
    t = np.linspace(0.0, ramp, 200001)
    v = alpha + slope * t + (v0 - alpha) * np.exp(-k * t)
    r = -r_max + rho * t
    v_dot = -(a * v + b * r + m24 * rho) / m22
    ramp_moment = m42 * v_dot + m44 * rho + c * v + d * r
    s = np.linspace(0.0, DEMAND.HOLD_AFTER, 200001)
    v_ss = -b * r_max / a
    w = v_ss + (v[-1] - v_ss) * np.exp(-k * s)
    hold_moment = m42 * (-(a * w + b * r_max) / m22) + c * w + d * r_max
    return float(max(np.max(np.abs(ramp_moment)), np.max(np.abs(hold_moment))))


@pytest.mark.parametrize("u, r_max, rho", [(0.8, 0.05, 0.02), (1.2, 0.1, 0.1), (1.5, 0.02, 0.005)])
def test_on_a_hull_with_linear_rows_the_need_is_the_closed_forms(u, r_max, rho):
    """The quadratic damping removed and linear damping added: the sway is a first-order linear system under a
    ramp, solved in closed form here, and its moment's largest value is the study's."""
    p = dataclasses.replace(REMUS100.nominal, Y_vv=0.0, Y_rr=0.0, N_vv=0.0, N_rr=0.0, Y_v=-30.0, N_r=-8.0)
    assert DEMAND.yaw_demand(p, u, r_max, rho).peak == pytest.approx(_linear_moment_peak(p, u, r_max, rho), rel=1e-4)


#: The published box's corner the study finds neediest at 1.07 m/s for r_max 0.1 rad/s at 0.1 rad/s² (the weakest
#: rudder, the largest yaw inertia, the weakest sway damping): a point of the bundled box.
NEEDY = {"m": 31.93, "I_zz": 4.22, "X_udot": -0.86, "Y_vdot": -35.5, "N_rdot": -4.88, "Y_vv": -196.1, "Y_rr": 0.0,
         "N_vv": -3.18, "N_rr": -94.0, "N_uudr": -2.75}


def test_the_command_box_the_rock_five_metres_off_asks_at_one_and_a_half_metres_per_second_is_beyond_the_hull():
    """At 1.5 m/s in 0.3 m/s of current the kinematic theorem keeps the rock 5 m off from r_max 0.08 rad/s with plans
    of (0.3, 0.005, 0.1) (tests/test_benchmark_survey_frontier.py), and with no slower plans of a grid (docs/plant.md
    section 4). A point of the published box cannot follow that command: its rudder (2.75 u^2 x 0.349 rad = 1.10 N m
    at 1.07 m/s) does not turn its yaw inertia alone (4.22 + 4.88 = 9.10 kg m^2 x 0.1 rad/s^2 = 0.91 N m) plus what
    its sway then asks, and flown in the closed loop its rudder saturates; the slowest-top-speed hull's propeller at
    1.9 m/s needs m11 x 0.3 + 1.62 x 1.9^2 against 1.62 x 2.497^2 (by hand: 15.7 against 10.1 N)."""
    hull = REMUS100.with_point(NEEDY)
    demand = DEMAND.yaw_demand(hull, 1.07, 0.08, 0.1)
    assert demand.rudder == pytest.approx(2.75 * 1.07 ** 2 * REMUS100.fin_max, rel=1e-9)
    assert demand.share > 1.5 and demand.steady < demand.rudder       # the ramp, not the turn, is beyond it
    error, saturated = DEMAND.simulated_ramp(hull, 1.07, 0.08, 0.1, holds=(20.0, 10.0))
    assert saturated > 1.0 and error > 0.05
    prop = REMUS100.with_point({"m": 31.93, "X_udot": -0.86, "X_uu": -1.62})
    need, thrust = DEMAND.surge_demand(prop, 1.9, 0.3, 2.497)
    m11 = 31.93 + 0.86
    assert need == pytest.approx(m11 * 0.3 + 1.62 * 1.9 ** 2, rel=1e-9)
    assert thrust == pytest.approx(1.62 * 2.497 ** 2, rel=1e-9) and need / thrust > 1.5


def test_the_same_hull_follows_the_command_box_that_keeps_the_rock_twelve_and_a_half_metres_off_without_saturating():
    """The same corner under the box the kinematic theorem certifies with the rock 12.5 m off at 1.5 m/s (r_max
    0.05 rad/s, yaw plans at 0.02 rad/s^2, tests/test_benchmark_survey_frontier.py): its need is inside its rudder
    and the closed loop follows the ramp without saturating (the study's verdicts go both ways)."""
    hull = REMUS100.with_point(NEEDY)
    assert DEMAND.yaw_demand(hull, 1.07, 0.05, 0.02).share < 0.8
    error, saturated = DEMAND.simulated_ramp(hull, 1.07, 0.05, 0.02, holds=(20.0, 10.0))
    assert saturated == 0.0 and error < 0.01


@pytest.mark.parametrize("argv, message", [
    (["--u-min", "0"], "--u-min, --u-max: expected 0 < u_min <= u_max"),
    (["--u-min", "2.0", "--u-max", "1.0"], "--u-min, --u-max: expected 0 < u_min <= u_max"),
    (["--r-max", "-0.1"], "--r-max: expected a positive yaw rate"),
    (["--rate", "0.1", "0", "0.1"], "--rate: expected three positive rates"),
    (["--top-speed", "nan"], "--top-speed: expected 0"),
    (["--vehicle", "bluerov2_heavy"], "--vehicle: expected a vehicle with fins"),
])
def test_a_bad_argument_is_refused_before_any_demand(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        DEMAND.main(argv)
    assert exit_.value.code == 2 and message in capsys.readouterr().err
