"""VehicleParams: coefficients as numbers or intervals, validation over the box, the point-only API, limits."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.vehicle_params import VehicleParams

#: A point vehicle with thrusters, every value by hand (no interval).
POINT = dict(m=10.0, I_zz=1.0, x_g=0.0, X_udot=-1.0, Y_vdot=-5.0, Z_wdot=-5.0, N_rdot=-0.5, Y_rdot=0.2,
             N_vdot=0.2, X_u=-1.0, Y_v=-2.0, Z_w=-2.0, N_r=-0.1, X_uu=-10.0, Y_vv=-50.0, Y_rr=0.0, Z_ww=-50.0,
             N_vv=0.0, N_rr=-1.0, Y_uv=0.0, Y_ur_lift=0.0, Z_uw=0.0, N_uv_lift=0.0, N_ur_lift=0.0, X_max=40.0,
             Z_max=60.0, N_max=5.0, Z_uuds=0.0, N_uudr=0.0, fin_max=0.0, thruster_time_constant=0.05,
             loop_bandwidth=8.0, actuation="thrusters")
FINS = {**POINT, "actuation": "fins", "Z_max": 0.0, "N_max": 0.0, "Z_uuds": [-8.0, -4.0], "N_uudr": -3.0,
        "fin_max": 0.3}


def test_a_point_vehicle_keeps_numbers_and_the_point_api():
    p = VehicleParams(**POINT)
    assert p.is_point and p.interval_fields == () and p.nominal == p
    assert p.interval("X_uu") == (-10.0, -10.0)
    # M by hand: m11 = 10 + 1, m22 = 10 + 5, m33 = 15, m44 = 1 + 0.5, m24 = m42 = 0 - 0.2
    assert p.mass_entries == pytest.approx((11.0, 15.0, 15.0, 1.5, -0.2, -0.2))
    assert p.thrust_limits == (40.0, 60.0, 5.0) == p.thrust_limits_at(0.0) == p.thrust_limits_at(3.0)
    assert p.thrust_limit_floor(1.0) == (40.0, 60.0, 5.0)


def test_an_interval_is_stored_as_a_tuple_and_its_midpoint_is_the_nominal():
    p = VehicleParams(**{**POINT, "X_uu": [-12.0, -8.0], "Y_vv": (-60, -40), "Z_ww": [-50.0, -50.0]})
    assert p.X_uu == (-12.0, -8.0) and p.Y_vv == (-60.0, -40.0)
    assert p.Z_ww == -50.0  # [lo, lo] is the number
    assert p.interval_fields == ("X_uu", "Y_vv") and not p.is_point
    nominal = p.nominal
    assert nominal.is_point and nominal.X_uu == -10.0 and nominal.Y_vv == -50.0
    assert nominal == VehicleParams(**POINT)


@pytest.mark.parametrize("attribute", ["mass_entries", "thrust_limits"])
def test_point_only_properties_refuse_a_box(attribute):
    p = VehicleParams(**{**POINT, "m": [9.0, 11.0]})
    with pytest.raises(ValueError, match=r"\.nominal.*\.interval\(name\)"):
        getattr(p, attribute)
    with pytest.raises(ValueError, match="point vehicle"):
        p.thrust_limits_at(0.5)


def test_interval_of_an_unknown_or_non_numeric_name_is_a_value_error():
    p = VehicleParams(**POINT)
    with pytest.raises(ValueError, match="not a numeric vehicle parameter"):
        p.interval("actuation")
    with pytest.raises(ValueError, match="not a numeric vehicle parameter"):
        p.interval("mass")


@pytest.mark.parametrize("change, field, match", [
    ({"X_uu": [-5.0, -10.0]}, "plant.vehicle.X_uu", "lo <= hi"),                 # reversed
    ({"X_uu": [-5.0, float("nan")]}, "plant.vehicle.X_uu", "two finite numbers"),
    ({"X_uu": [-5.0, -4.0, -3.0]}, "plant.vehicle.X_uu", "two finite numbers"),
    ({"X_uu": ["-5", -4.0]}, "plant.vehicle.X_uu", "two finite numbers"),
    ({"X_uu": "-5"}, "plant.vehicle.X_uu", "finite number"),
    ({"X_uu": [-5.0, 1.0]}, "plant.vehicle.X_uu", "damping removes energy"),    # the box reaches > 0
    ({"N_r": [-1.0, 0.5]}, "plant.vehicle.N_r", "damping removes energy"),
    ({"m": [0.0, 10.0]}, "plant.vehicle.m", "> 0 at every point"),
    ({"loop_bandwidth": [-1.0, 5.0]}, "plant.vehicle.loop_bandwidth", "> 0"),
    ({"yaw_loop_bandwidth": -1.0}, "plant.vehicle.yaw_loop_bandwidth", "0 \\(the loop_bandwidth\\) or a number > 0"),
    ({"sway_loop_bandwidth": [0.0, 5.0]}, "plant.vehicle.sway_loop_bandwidth", "at every point of the box"),
    ({"Z_max": 0.0}, "plant.vehicle.Z_max", "> 0"),                              # thrusters need it
    ({"fin_max": 0.2}, "plant.vehicle.fin_max", "unused with actuation = 'thrusters'"),
    ({"actuation": "oars"}, "plant.vehicle.actuation", "thrusters"),
    ({"loop_feedforward": "measured"}, "plant.vehicle.loop_feedforward", "'model', 'none'"),
    ({"loop_feedforward": 0}, "plant.vehicle.loop_feedforward", "'model', 'none'"),
    ({"N_vdot": [0.1, 0.3]}, "plant.vehicle.N_vdot", "M symmetric"),            # box: not symmetric
    ({"Y_rdot": [0.1, 0.3], "N_vdot": [0.1, 0.25]}, "plant.vehicle.N_vdot", "M symmetric"),
    # m22 = m - Y_vdot > 0 at the nominal but not at the worst end: 10 - (-5 .. 12) reaches -2
    ({"Y_vdot": [-5.0, 12.0]}, "plant.vehicle.M", "every point of the box"),
    # det = m22 m44 - m24²: 15 * 1.5 = 22.5 < 5² at the end Y_rdot = -5 (m24 = 5) only
    ({"Y_rdot": [-5.0, 0.2], "N_vdot": [-5.0, 0.2]}, "plant.vehicle.M", "worst-case ends"),
    ({"N_rdot": [-0.5, 1.5]}, "plant.vehicle.M", "I_zz - N_rdot"),              # m44 = 1 - 1.5 at one end
])
def test_bad_coefficients_name_the_field(change, field, match):
    with pytest.raises(ConfigError, match=match) as err:
        VehicleParams(**{**POINT, **change})
    assert err.value.field == field


def test_the_positive_definite_check_passes_just_inside_the_box():
    # det at the worst end: 15 * 1.5 - m24² > 0 needs |m24| < 4.74: Y_rdot in [-4.7, 0.2] passes
    p = VehicleParams(**{**POINT, "Y_rdot": [-4.7, 0.2], "N_vdot": [-4.7, 0.2]})
    assert p.interval_fields == ("Y_rdot", "N_vdot")


@pytest.mark.parametrize("change, field", [
    ({"Z_uuds": [-1.0, 1.0]}, "plant.vehicle.Z_uuds"),     # a fin whose sign is unknown has no floor
    ({"N_uudr": 0.0}, "plant.vehicle.N_uudr"),
    ({"fin_max": 0.0}, "plant.vehicle.fin_max"),
    ({"N_max": 5.0}, "plant.vehicle.N_max"),               # unused with fins: must be 0
])
def test_bad_fin_vehicles_name_the_field(change, field):
    with pytest.raises(ConfigError) as err:
        VehicleParams(**{**FINS, **change})
    assert err.value.field == field


def test_fins_limits_grow_with_the_square_of_the_speed_and_vanish_at_rest():
    p = VehicleParams(**FINS)
    point = p.nominal  # Z_uuds = -6
    # by hand: Z = 6 * 0.5² * 0.3 = 0.45 N, N = 3 * 0.25 * 0.3 = 0.225 N m; X is the propeller's 40 N
    assert point.thrust_limits_at(0.5) == pytest.approx((40.0, 0.45, 0.225))
    assert point.thrust_limits_at(-0.5) == point.thrust_limits_at(0.5)
    assert point.thrust_limits_at(0.0) == (40.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="thrust_limits_at"):
        point.thrust_limits  # noqa: B018  a finned vehicle has no constant limits
    # floor over the box and |u| <= 1: the fins give nothing at u = 0
    assert p.thrust_limit_floor(1.0) == (40.0, 0.0, 0.0)
    # over 0.5 <= |u| <= 1: the smallest |Z_uuds| = 4: 4 * 0.25 * 0.3 = 0.3 N
    assert p.thrust_limit_floor(1.0, 0.5) == pytest.approx((40.0, 0.3, 0.225))
    for bad in ((-1.0,), (1.0, 2.0), (float("inf"),)):
        with pytest.raises(ValueError, match="u_abs_min <= u_abs_max"):
            p.thrust_limit_floor(*bad)


def test_to_dict_writes_intervals_as_lists_and_round_trips_through_json():
    p = VehicleParams(**{**FINS, "X_uu": [-12.0, -8.0]})
    d = json.loads(json.dumps(p.to_dict()))
    assert d["X_uu"] == [-12.0, -8.0] and d["Z_uuds"] == [-8.0, -4.0] and d["actuation"] == "fins"
    assert VehicleParams(**d) == p


def test_with_point_sets_truth_values_and_ties_the_symmetric_pair():
    p = VehicleParams(**{**POINT, "X_uu": [-12.0, -8.0], "Y_rdot": [0.0, 0.4], "N_vdot": [0.0, 0.4]})
    q = p.with_point({"X_uu": -11.0, "N_vdot": 0.1})
    assert q.is_point and q.X_uu == -11.0 and q.Y_rdot == q.N_vdot == 0.1
    for values, field in (({"X_uu": -13.0}, "plant.truth.X_uu"), ({"Y_vv": -50.0}, "plant.truth.Y_vv"),
                          ({"X_uu": "-10"}, "plant.truth.X_uu"),
                          ({"Y_rdot": 0.1, "N_vdot": 0.2}, "plant.truth.N_vdot")):
        with pytest.raises(ConfigError) as err:
            p.with_point(values)
        assert err.value.field == field


@given(seed=st.integers(0, 2 ** 32 - 1))
def test_sample_stays_in_the_box(seed):
    """Property: every coefficient of sample(rng) lies in its interval, the sample is a valid point vehicle
    (its mass matrix is positive definite) and M stays symmetric."""
    box = VehicleParams(**{**FINS, "X_uu": [-12.0, -8.0], "m": [9.0, 11.0], "Y_rdot": [0.0, 0.4],
                           "N_vdot": [0.0, 0.4], "I_zz": [0.8, 1.2]})
    s = box.sample(np.random.default_rng(seed))
    assert s.is_point
    for name in box.interval_fields:
        lo, hi = box.interval(name)
        assert lo <= getattr(s, name) <= hi
    m11, m22, m33, m44, m24, m42 = s.mass_entries
    assert m24 == m42
    assert np.all(np.linalg.eigvalsh(np.array([[m22, m24], [m42, m44]])) > 0) and min(m11, m33) > 0


def test_a_box_is_shrunk_about_its_midpoint_and_points_stay_points():
    """shrunk(f): each interval about its midpoint to f of its half-width; 0 is the nominal point, 1 the box."""
    from tubekit.model.vehicles import vehicle_params
    remus = vehicle_params("remus100")
    lo, hi = remus.interval("N_uudr")
    assert remus.shrunk(0.0).to_dict()["N_uudr"] == pytest.approx((lo + hi) / 2) and remus.shrunk(0.0).is_point
    assert remus.shrunk(0.5).interval("N_uudr") == pytest.approx((lo + (hi - lo) / 4, hi - (hi - lo) / 4))
    assert remus.shrunk(1.0).interval("N_uudr") == pytest.approx((lo, hi))
    assert remus.shrunk(0.5).to_dict()["fin_max"] == remus.to_dict()["fin_max"]       # a number stays a number
    assert remus.shrunk(0.5).interval("Y_rdot") == remus.shrunk(0.5).interval("N_vdot")  # M stays symmetric


@pytest.mark.parametrize("fraction", [-0.1, 1.5, float("nan"), "half", True])
def test_a_box_is_shrunk_only_by_a_fraction_of_its_half_width(fraction):
    from tubekit.model.vehicles import vehicle_params
    with pytest.raises(ConfigError, match=r"fraction: expected a number in \[0, 1\]"):
        vehicle_params("remus100").shrunk(fraction)


def test_each_channel_runs_at_its_own_bandwidth_or_the_loop_bandwidth():
    """PI gains by hand, per body velocity (u, v, w, r): loop_bandwidth 8 gives k_p = 8, k_i = 16 wherever a channel
    has no bandwidth of its own; a yaw loop at 12 rad/s gives k_p = 12, k_i = 36; a box's gains are its midpoint's."""
    assert VehicleParams(**POINT).loop_gains == ((8.0, 16.0),) * 4
    own = VehicleParams(**{**POINT, "yaw_loop_bandwidth": 12.0, "heave_loop_bandwidth": [2.0, 6.0]})
    assert own.loop_gains == ((8.0, 16.0), (8.0, 16.0), (4.0, 4.0), (12.0, 36.0))
    assert VehicleParams(**{**POINT, "yaw_loop_bandwidth": 12.0}).to_dict()["yaw_loop_bandwidth"] == 12.0


#: REMUS 100's bundled box with the thrust tied to the drag by each source's own top speed (m/s).
TIED = (2.497, 2.571)


@pytest.mark.parametrize("change, field, match", [
    ({"top_speed": -1.0}, "plant.vehicle.top_speed", "speed > 0 at every point"),
    ({"top_speed": [0.0, 2.5]}, "plant.vehicle.top_speed", "speed > 0 at every point"),
    # 6.23 kg/m x 2.6² = 42.1 N: more than the published 41.2 N, so the tie would widen X_max's interval
    ({"top_speed": [2.5, 2.6]}, "plant.vehicle.X_max", "holding every thrust the top speed ties"),
    ({"top_speed": [2.4, 2.5]}, "plant.vehicle.X_max", r"in \[9\.33"),       # 1.62 x 2.4² = 9.33 N < 10.1
])
def test_a_top_speed_that_is_not_a_speed_or_leaves_x_max_s_interval_names_the_field(change, field, match):
    with pytest.raises(ConfigError, match=match) as err:
        VehicleParams(**change)
    assert err.value.field == field


def test_a_tied_vehicle_s_points_take_the_thrust_that_holds_them_at_their_top_speed():
    """The nominal, a truth point and a sample each have X_max = |X_uu| s² (REMUS 100 has no linear surge drag):
    at the midpoint 3.925 kg/m x 2.534² = 25.20 N (by hand), not the midpoint of X_max's interval (25.65 N)."""
    box = VehicleParams(top_speed=TIED)
    assert box.tied and not VehicleParams().tied
    assert box.nominal.X_max == pytest.approx(3.925 * 2.534 ** 2, rel=1e-12)
    weakest = box.with_point({"X_uu": -1.62, "top_speed": 2.497})
    assert weakest.X_max == pytest.approx(1.62 * 2.497 ** 2) and weakest.X_max > 10.1
    for seed in range(20):
        point = box.sample(np.random.default_rng(seed))
        assert point.X_max == pytest.approx(abs(point.X_uu) * point.top_speed ** 2, rel=1e-12)
        assert 10.1 <= point.X_max <= 41.2


def test_a_tied_vehicle_s_truth_may_not_set_its_thrust():
    with pytest.raises(ConfigError, match="tied to the drag by top_speed") as err:
        VehicleParams(top_speed=TIED).with_point({"X_max": 20.0})
    assert err.value.field == "plant.truth.X_max"
