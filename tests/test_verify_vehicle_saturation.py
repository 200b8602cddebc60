"""What the actuators can do for the velocity loop (verify.vehicle.saturation): saturation and authority."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.vehicle_sets import BLUEROV2_HEAVY
from tubekit.model.vehicles import vehicle_params
from tubekit.plant.dynamic import body_forces
from verify.vehicle.bound import velocity_loop_bound
from verify.vehicle.saturation import _top_speed_note, actuator_authority, straight_top_speed, triple

V, H, TICKS = (0.4, 0.3, 0.5), 0.01, 10
JT, JP = (0.002, 0.002, 0.002), (0.02, 0.02, 0.02)


@pytest.fixture(scope="module")
def bluerov_point():
    return velocity_loop_bound(BLUEROV2_HEAVY.nominal, v_max=V, tick=H, period=H * TICKS, jump_tick=JT,
                               jump_period=JP)


@pytest.mark.parametrize("value, match", [
    ((0.1, 0.2), r"v_max: expected three numbers \(u, w, r\)"),
    ("abc", r"v_max: expected three numbers"),
    ((0.1, -0.2, 0.3), r"v_max\[1\]"),
    ((0.1, float("nan"), 0.3), r"v_max\[1\]"),
])
def test_three_numbers_are_validated_by_name(value, match):
    with pytest.raises(ConfigError, match=match):
        triple("v_max", value)
    with pytest.raises(ConfigError, match=match):
        actuator_authority(BLUEROV2_HEAVY.nominal, value)


def test_a_smaller_sway_box_gives_at_least_the_authority_of_the_hulls():
    """The authority is taken over |v| <= sway: the sway loop's small E_v leaves the yaw channel more than the free
    hull's γ̄ does (here the Heavy has no sway-yaw drag coupling, so they are equal; surge and heave too)."""
    p = BLUEROV2_HEAVY.nominal
    hull = actuator_authority(p, V)
    tight = actuator_authority(p, V, sway=0.001)
    assert all(t >= h for t, h in zip(tight, hull))
    n1, _, _, _ = body_forces(p, (V[0], 0.001, 0.0, V[2]))
    assert tight[0] <= (p.X_max - abs(n1)) / p.mass_entries[0]


def test_the_lateral_thrust_limit_is_the_sway_loops_saturation_condition(bluerov_point):
    """The sway loop's need sup|n̂_2| + m̂_22 sup|a_v| against Y_max: a lateral limit below the need fails
    ``loop_saturation[Y]`` by name (the hand check: the Coriolis force m̂_11 u r alone at the box's corner)."""
    sat = {c.condition: c for c in bluerov_point.conditions}["loop_saturation[Y]"]
    p = BLUEROV2_HEAVY.nominal
    coriolis = p.mass_entries[0] * V[0] * V[2]
    assert sat.ok and coriolis <= sat.lhs < sat.rhs == p.Y_max
    weak = dataclasses.replace(p, Y_max=0.5 * coriolis)
    b = velocity_loop_bound(weak, v_max=V, tick=H, period=H * TICKS, jump_tick=JT, jump_period=JP)
    assert not b.certified
    assert {c.condition: c.ok for c in b.conditions}["loop_saturation[Y]"] is False


def test_under_a_surge_floor_the_rudders_authority_is_taken_band_by_band_and_stays_below_the_sampled_one():
    """REMUS 100's midpoint at V = (1.3 m/s, 0.01 m/s, 0.02 rad/s) under a 1 m/s surge floor: each surge band's
    drag against its own fin force, with the hull's sway over u >= u_min, leaves the rudder a positive yaw
    acceleration (over the whole range against the slowest force and the unfloored sway it was negative, which
    refused every such plan); and it is a lower bound: below (|N_uudr| u^2 delta_max - |n_r|)/m_r at every sampled
    point of the box, the plant's own forces."""
    from tubekit.model.vehicle_sets import REMUS100
    from verify.theorem.design import hull_sway_bound
    p = REMUS100.nominal
    v_box, floor = (1.3, 0.01, 0.02), 1.0
    a_r = actuator_authority(p, v_box, floor)[2]
    assert a_r > 0.0
    gamma = float(hull_sway_bound(p, v_box[0], v_box[2], floor).mid())
    m11, m22, m33, m44, m24, m42 = p.mass_entries
    m_r = m44 - m24 * m42 / m22
    rng = np.random.default_rng(11)
    sampled = math.inf
    draws = zip(rng.uniform(floor, 1.3, 400), rng.uniform(-gamma, gamma, 400), rng.uniform(-0.01, 0.01, 400),
                rng.uniform(-0.02, 0.02, 400))
    for u, v, w, r in draws:
        _, n2, _, n4 = body_forces(p, (u, v, w, r))
        sampled = min(sampled, (abs(p.N_uudr) * u * u * p.fin_max - abs(n4 - m42 / m22 * n2)) / m_r)
    assert a_r <= sampled


def test_the_weakest_hulls_top_speed_is_the_smallest_thrust_against_the_largest_drag():
    """REMUS 100's bundled box pairs Prestero's propeller thrust (10.1 N, his drag at 2.5 m/s) with Fossen's drag
    (X_u|u| = -6.23 kg/m, docs/plant.md section 3.1): that hull tops out at sqrt(10.1 / 6.23) m/s; a box with a
    linear drag too solves the quadratic; a box without drag has none."""
    assert straight_top_speed(vehicle_params("remus100")) == pytest.approx(math.sqrt(10.1 / 6.23), rel=1e-9)
    nominal = vehicle_params("remus100").nominal
    linear = dataclasses.replace(nominal, X_u=-2.0, X_uu=-4.0, X_max=10.0)
    assert straight_top_speed(linear) == pytest.approx(1.350781059358212, rel=1e-9)  # 4 u^2 + 2 u = 10
    assert straight_top_speed(dataclasses.replace(nominal, X_u=0.0, X_uu=0.0)) == math.inf


def test_a_thrust_tied_to_the_drag_tops_out_at_the_slowest_top_speed_and_the_surge_note_says_nothing_below_it():
    """With top_speed [2.497, 2.571] every hull's thrust holds it at 2.497 m/s or faster (the thrust is tied to its
    own drag), so a diverging loop at V_u = 1.9 m/s over the published box is not told its hull tops out at
    sqrt(10.1 / 6.23) = 1.27 m/s (that pair is the untied box's); above 2.497 m/s the note still comes."""
    tied = dataclasses.replace(vehicle_params("remus100"), top_speed=(2.497, 2.571))
    assert straight_top_speed(tied) == 2.497
    bound = velocity_loop_bound(tied, v_max=(1.9, 0.007, 0.05), tick=0.01, period=0.1, jump_tick=(0.0, 0.0, 0.0),
                                jump_period=(0.005, 0.0005, 0.002), surge_floor=1.07)
    x = {c.condition: c for c in bound.conditions}["loop_saturation[X]"]
    assert not bound.certified and "top speed" not in x.detail
    assert "top speed, about 2.497 m/s" in _top_speed_note(tied, 2.6)


def test_a_loop_that_does_not_close_names_the_top_speed_it_asks_for_and_no_overflowed_number():
    """Over REMUS 100's published box with V_u = 1.7 m/s beyond its weakest hull's top speed (1.27 m/s) under a
    0.78 m/s surge floor, the fixed point diverges: loop_saturation[X] says by how much V_u exceeds the top speed,
    the fins' conditions are taken over the design's surge band (no 'at u = 0' while u_min holds the vehicle off
    it) and no failure prints the diverged bounds (no number of 1e+100 or more)."""
    bound = velocity_loop_bound(vehicle_params("remus100"), v_max=(1.7, 0.01, 0.013), tick=0.01, period=0.1,
                                jump_tick=(0.0003, 0.00005, 0.00002), jump_period=(0.003, 0.0005, 0.0002),
                                rate=(0.03, 0.005, 0.002), surge_floor=0.78)
    failed = {c.condition: c for c in bound.conditions if c.ok is not True}
    assert "loop_fixed_point" in failed
    x = failed["loop_saturation[X]"]
    assert x.lhs is None and "top speed, about 1.273 m/s" in x.detail and "at least 0.427 m/s" in x.detail
    assert all("at u = 0" not in c.detail for c in failed.values())
    numbers = [float(t) for c in failed.values() for t in re.findall(r"\d+(?:\.\d+)?e\+\d+", c.detail)]
    assert not [n for n in numbers if n >= 1e100]
