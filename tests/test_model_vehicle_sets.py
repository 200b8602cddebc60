"""The shipped vehicles against their published sources, each end of an interval re-derived by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tubekit.model.vehicle_sets import (BLUEROV2_HEAVY, REMUS100, VEHICLES, bluerov2_heavy_limits,
                                        bluerov2_heavy_sway_limit)

RHO = 1026.0  # kg/m³, Fossen's remus100.m


def test_the_shipped_names():
    assert set(VEHICLES) == {"remus100", "bluerov2_heavy"}
    assert REMUS100.actuation == "fins" and BLUEROV2_HEAVY.actuation == "thrusters"


def test_remus_prestero_ends_and_lift_split():
    p = REMUS100
    assert p.interval("m")[0] == pytest.approx(299.0 / 9.81, abs=0.01)  # Prestero: W = 299 N
    ends = {n: p.interval(n) for n in ("X_uu", "Y_vv", "Z_ww", "N_rr", "X_udot", "Y_vdot", "N_rdot")}
    assert ends["X_uu"][1] == -1.62 and ends["Y_vv"][0] == -1310.0 and ends["Z_ww"][1] == -131.0
    assert ends["N_rr"][0] == -94.0 and ends["X_udot"][0] == -0.93 and ends["Y_vdot"][0] == -35.5
    # the correction: Y_uv and Z_uw are body (-28.6) + fin (-9.64) lift, as N_uv includes the fin
    assert p.Y_uv == pytest.approx(-28.6 - 9.64, abs=0.05) and p.Z_uw == p.Y_uv
    # lift-only parts + Prestero's added-mass parts give Prestero's totals back
    assert p.Y_ur_lift + (-0.93) == pytest.approx(5.22)
    assert p.N_uv_lift + (-35.5 - (-0.93)) == pytest.approx(-24.0)
    assert p.N_ur_lift + 1.93 == pytest.approx(-2.00)
    # Prestero's fin coefficients are the far ends of the fin intervals
    assert p.interval("Z_uuds")[0] == -9.64 and p.interval("N_uudr")[0] == -6.15


def test_remus_fossen_ends_rederived_from_his_model():
    """Fossen's MSS remus100.m: strip-theory cross-flow drag with Hoerner's C_d, spheroid mass, fins."""
    length, diameter = 1.6, 0.19
    # Hoerner's curve at B/2T = 0.5 between its digitised points (0.493252, 1.21082), (0.558473, 1.08356)
    cd = 1.21082 + (0.5 - 0.493252) * (1.08356 - 1.21082) / (0.558473 - 0.493252)
    dx = length / 20
    strips = [-length / 2 + i * dx for i in range(21)]     # crossFlowDrag.m sums 21 strips of dx = L/20
    y_vv = -0.5 * RHO * diameter * cd * dx * len(strips)
    n_rr = -0.5 * RHO * diameter * cd * dx * sum(abs(x) ** 3 for x in strips)
    assert REMUS100.interval("Y_vv")[1] == pytest.approx(y_vv, abs=0.05)     # about -196 (the issue)
    assert REMUS100.interval("Z_ww")[0] == pytest.approx(y_vv, abs=0.05)     # same strips in heave
    assert REMUS100.interval("N_rr")[1] == pytest.approx(n_rr, abs=0.05)
    a, b = 1.0096 * length / 2, 1.0096 * diameter / 2                      # the scaled spheroid
    mass = 4.0 / 3.0 * math.pi * RHO * a * b * b
    assert REMUS100.interval("m")[1] == pytest.approx(mass, abs=0.01)
    assert REMUS100.interval("I_zz")[1] == pytest.approx(mass * (a * a + b * b) / 5, abs=0.01)
    s_planform = 0.7 * length * diameter
    x_uu = -0.5 * RHO * s_planform * (0.42 * math.pi * b * b / s_planform)  # C_D0 from Allen et al. C_d = 0.42
    assert REMUS100.interval("X_uu")[0] == pytest.approx(x_uu, abs=0.01)
    fin_area = 2 * 0.00665
    z_uuds = -0.5 * RHO * fin_area * 0.7                                    # stern planes, C_L = 0.7
    n_uudr = a * 0.5 * RHO * fin_area * 0.5                                 # rudder at x_r = -a, C_L = 0.5
    assert REMUS100.interval("Z_uuds")[1] == pytest.approx(z_uuds, abs=0.01)
    assert -REMUS100.interval("N_uudr")[1] == pytest.approx(n_uudr, abs=0.01)
    assert REMUS100.fin_max == pytest.approx(math.radians(20.0), abs=1e-3)  # delta_max = deg2rad(20)


def test_remus_propeller_interval_ends():
    # lower end: Prestero's axial drag at the published top speed 2.5 m/s
    assert REMUS100.interval("X_max")[0] == pytest.approx(1.62 * 2.5 ** 2, abs=0.05)
    # upper end: Fossen's propeller at 1525 rpm and U = 2.5 m/s (KT linear in J, thrust deduction 0.1)
    n, d, va = 1525.0 / 60.0, 0.14, 0.944 * 2.5
    thrust = 0.9 * RHO * d ** 4 * (0.4566 * n * n + (0.1798 - 0.4566) / 0.6632 * (va / d) * n)
    assert REMUS100.interval("X_max")[1] == pytest.approx(thrust, abs=0.05)


def test_bluerov2_heavy_identification_ends():
    p = BLUEROV2_HEAVY
    # von Benzon et al. 2022 (Wu 2018) on one end, Einarsson & Lipenitis 2020 on the other
    for name, benzon, einarsson in (("X_uu", -141.0, -34.96), ("Y_vv", -217.0, -103.25), ("Z_ww", -190.0, -74.23),
                                    ("N_rr", -1.5, -0.43), ("X_u", -13.7, -0.09), ("Z_w", -33.0, -0.19),
                                    ("X_udot", -6.36, -2.6), ("Y_vdot", -7.12, -18.5), ("Z_wdot", -18.69, -13.3)):
        assert set(p.interval(name)) == {benzon, einarsson}, name
    assert p.m == 13.5 and p.I_zz == 0.37


def test_bluerov2_heavy_limits_by_hand_and_by_allocation():
    thrust = 4.1 * 9.80665                                # T200 reverse thrust at 16 V
    arm = (0.156 + 0.111) / math.sqrt(2)                  # yaw arm of a 45° thruster at (0.156, 0.111)
    x_max, z_max, n_max = bluerov2_heavy_limits()
    y_max = bluerov2_heavy_sway_limit()
    assert (x_max, z_max, n_max, y_max) == pytest.approx((0.65 * 4 * thrust / math.sqrt(2), 4 * thrust,
                                                          0.25 * 4 * thrust * arm, 0.10 * 4 * thrust / math.sqrt(2)))
    assert BLUEROV2_HEAVY.thrust_limit_floor(1.0) == pytest.approx((x_max, z_max, n_max), abs=0.01)
    assert BLUEROV2_HEAVY.Y_max == pytest.approx(y_max, abs=0.01) and BLUEROV2_HEAVY.Y_max <= y_max
    # every corner of the (X, Y, N) box is producible: minimum-norm allocation over the 4 horizontal thrusters
    positions = [(0.156, 0.111), (0.156, -0.111), (-0.156, 0.111), (-0.156, -0.111)]
    angles = [-math.pi / 4, math.pi / 4, -3 * math.pi / 4, 3 * math.pi / 4]
    b = np.array([[math.cos(a) for a in angles], [math.sin(a) for a in angles],
                  [px * math.sin(a) - py * math.cos(a) for (px, py), a in zip(positions, angles)]])
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sn in (-1, 1):
                f = np.linalg.pinv(b) @ np.array([sx * x_max, sy * y_max, sn * n_max])
                assert np.max(np.abs(f)) <= thrust * (1 + 1e-9)
    f = np.linalg.pinv(b) @ np.array([x_max, 1.02 * y_max, n_max])       # a box any wider is not producible
    assert np.max(np.abs(f)) > thrust


@pytest.mark.parametrize("vehicle", [REMUS100, BLUEROV2_HEAVY])
def test_loop_poles_are_damped_with_the_actuator_lag(vehicle):
    """ω_b T_thr = 0.5 for both vehicles: the loop's A (docs/plant.md) has damping ratio >= 0.65."""
    wb, lag = vehicle.loop_bandwidth, vehicle.thruster_time_constant
    assert wb * lag == pytest.approx(0.5)
    kp, ki = wb, wb * wb / 4
    a = np.array([[0.0, 1.0, 0.0], [-ki, -kp, -1.0], [kp * ki, kp * kp - ki, kp - 1.0 / lag]])
    poles = np.linalg.eigvals(a)
    assert np.all(poles.real < 0)
    assert min(-p.real / abs(p) for p in poles) >= 0.65
