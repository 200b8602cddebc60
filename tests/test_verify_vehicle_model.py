"""The velocity loop's vehicle in Arb (verify.vehicle.model) against the simulated plant's own functions."""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.vehicle_params import VehicleParams
from tubekit.model.vehicle_sets import BLUEROV2_HEAVY, REMUS100
from tubekit.plant.dynamic import body_forces
from verify.kernel.intervals import lower, upper
from verify.vehicle.model import (arb_body_forces, body_force_gradient, channel_forces, channel_gradient, channel_masses,
                               channel_mismatch, channel_mismatch_gradient, field_ball, hull_balls, nominal_balls,
                               point_time_constant, thrust_floor, velocity_box)

POINTS = [REMUS100.nominal, BLUEROV2_HEAVY.nominal]


def _nu(rng: np.random.Generator) -> tuple[float, float, float, float]:
    return tuple(float(x) for x in rng.uniform(-0.8, 0.8, 4))


def _yaw_channel(p: VehicleParams, nu) -> tuple[float, float, float]:
    """(n_u, n_w, n_r) as the plant's thrust command forms them (sway row eliminated)."""
    n1, n2, n3, n4 = body_forces(p, nu)
    _, m22, _, _, _, m42 = p.mass_entries
    return n1, n3, n4 - m42 * n2 / m22


@pytest.mark.parametrize("p", POINTS)
def test_the_arb_forces_contain_the_plants_forces_at_points(p):
    rng = np.random.default_rng(3)
    c = nominal_balls(p)
    for _ in range(20):
        nu = _nu(rng)
        for ball, x in zip(arb_body_forces(c, nu), body_forces(p, nu)):
            assert lower(ball) - 1e-12 <= x <= upper(ball) + 1e-12
        for ball, x in zip(channel_forces(c, nu), _yaw_channel(p, nu)):
            assert lower(ball) - 1e-12 <= x <= upper(ball) + 1e-12


def test_over_a_box_the_munk_moment_is_charged_once_not_as_two_moments_that_add():
    """Over u in [1.0, 1.3] m/s, |v| <= 0.03 m/s, w = r = 0, REMUS 100's midpoint yaw force is
    u v (m22 - m11 - N_uv,lift) - N_vv v|v|: its enclosure is at most the hand bound
    1.3 x 0.03 x |m22 - m11 - N_uv,lift| + |N_vv| 0.03^2 (from the vehicle's numbers), where charging m22 u v
    and m11 u v apart would give 1.3 x 0.03 x (m22 + m11 + |N_uv,lift|); every sampled point lies inside."""
    p = REMUS100.nominal
    m11, m22, *_ = p.mass_entries
    nu = (arb(1.15, 0.15), arb(0, 0.03), arb(0), arb(0))
    n4 = arb_body_forces(nominal_balls(p), nu)[3]
    hand = 1.3 * 0.03 * abs(m22 - m11 - p.N_uv_lift) + abs(p.N_vv) * 0.03 ** 2
    assert upper(abs(n4)) <= hand * (1 + 1e-6)
    assert hand < 0.5 * 1.3 * 0.03 * (m22 + m11 + abs(p.N_uv_lift))
    rng = np.random.default_rng(5)
    for u, v in zip(rng.uniform(1.0, 1.3, 200), rng.uniform(-0.03, 0.03, 200)):
        assert lower(n4) <= body_forces(p, (u, v, 0.0, 0.0))[3] <= upper(n4)


@pytest.mark.parametrize("p", POINTS)
def test_the_hand_gradient_matches_central_differences_of_the_plant(p):
    rng = np.random.default_rng(4)
    c, step = nominal_balls(p), 1e-6
    for _ in range(10):
        nu = np.array(_nu(rng))
        grad, chan = body_force_gradient(c, nu), channel_gradient(c, nu)
        for j in range(4):
            d = np.zeros(4)
            d[j] = step
            fd = (np.array(body_forces(p, nu + d)) - np.array(body_forces(p, nu - d))) / (2 * step)
            fc = (np.array(_yaw_channel(p, nu + d)) - np.array(_yaw_channel(p, nu - d))) / (2 * step)
            assert [float(grad[i][j].mid()) for i in range(4)] == pytest.approx(fd, rel=1e-5, abs=1e-5)
            assert [float(chan[i][j].mid()) for i in range(3)] == pytest.approx(fc, rel=1e-5, abs=1e-5)


def test_the_channel_masses_are_the_plants():
    m11, m22, m33, m44, m24, m42 = REMUS100.nominal.mass_entries
    mu, mw, mr = channel_masses(nominal_balls(REMUS100))
    assert float(mu.mid()) == m11 and float(mw.mid()) == m33
    assert float(mr.mid()) == pytest.approx(m44 - m24 * m42 / m22, rel=1e-14)


def test_a_point_vehicle_has_no_mismatch():
    c = nominal_balls(BLUEROV2_HEAVY.nominal)
    d = channel_mismatch(c, hull_balls(BLUEROV2_HEAVY.nominal), velocity_box(0.5, 0.2, 0.3, 0.6))
    assert all(upper(abs(x)) < 1e-10 for x in d)


@pytest.mark.parametrize("p", [REMUS100, BLUEROV2_HEAVY])
def test_the_mismatch_and_its_gradient_contain_every_sampled_truth(p):
    rng = np.random.default_rng(5)
    nom, hull = nominal_balls(p), hull_balls(p)
    box = velocity_box(0.5, 0.2, 0.3, 0.6)
    d, dg = channel_mismatch(nom, hull, box), channel_mismatch_gradient(nom, hull, box)
    step = 1e-6
    for _ in range(15):
        truth = p.sample(rng)
        nu = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.2, 0.2), rng.uniform(-0.3, 0.3), rng.uniform(-0.6, 0.6)])
        diff = np.array(_yaw_channel(p.nominal, nu)) - np.array(_yaw_channel(truth, nu))
        for c in range(3):
            assert lower(d[c]) - 1e-9 <= diff[c] <= upper(d[c]) + 1e-9
        for j in range(4):
            e = np.zeros(4)
            e[j] = step
            fd = ((np.array(_yaw_channel(p.nominal, nu + e)) - np.array(_yaw_channel(truth, nu + e)))
                  - (np.array(_yaw_channel(p.nominal, nu - e)) - np.array(_yaw_channel(truth, nu - e)))) / (2 * step)
            for c in range(3):
                assert lower(dg[c][j]) - 1e-4 <= fd[c] <= upper(dg[c][j]) + 1e-4


def test_field_balls_are_the_intervals_and_the_points():
    lo, hi = REMUS100.interval("Y_vv")
    ball = field_ball(REMUS100, "Y_vv")
    assert lower(ball) <= lo and upper(ball) >= hi and upper(ball) < hi + 1e-5
    assert field_ball(REMUS100.nominal, "Y_vv") == arb(0.5 * (lo + hi))


def test_the_thrust_floor_of_a_finned_vehicle_is_zero_in_yaw_and_heave():
    assert thrust_floor(REMUS100, 0.4)[1:] == (0.0, 0.0)
    assert thrust_floor(BLUEROV2_HEAVY, 0.4) == tuple(BLUEROV2_HEAVY.interval(n)[0] for n in ("X_max", "Z_max", "N_max"))


def test_an_interval_thruster_lag_is_refused():
    p = BLUEROV2_HEAVY.with_overrides({"thruster_time_constant": [0.04, 0.06]})
    with pytest.raises(ConfigError, match="plant.vehicle.thruster_time_constant"):
        point_time_constant(p)
    assert point_time_constant(BLUEROV2_HEAVY) == 0.05


@pytest.mark.parametrize("vehicle", ["remus100", "bluerov2_heavy"])
def test_the_force_hessian_is_the_gradients_central_difference_off_zero(vehicle):
    """Property: at random velocities away from 0 (where the |x| terms are smooth) every ∂²n_i/∂ν_j∂ν_k of
    body_force_hessian matches the central difference of body_force_gradient (an independent derivative)."""
    from flint import arb
    from tubekit.model.vehicles import vehicle_params
    from verify.vehicle.model import body_force_gradient, body_force_hessian, nominal_balls
    c = nominal_balls(vehicle_params(vehicle))
    rng = np.random.default_rng(7)
    for _ in range(10):
        nu = rng.uniform(0.05, 1.0, 4) * rng.choice([-1.0, 1.0], 4)
        hess = body_force_hessian(c, [arb(x) for x in nu])
        for j in range(4):
            step = np.zeros(4)
            step[j] = 1e-6
            up, down = (body_force_gradient(c, [arb(x) for x in nu + sgn * step]) for sgn in (1, -1))
            for i in range(4):
                for m in range(4):
                    diff = (float(up[i][m].mid()) - float(down[i][m].mid())) / 2e-6
                    assert float(hess[i][m][j].mid()) == pytest.approx(diff, rel=1e-6, abs=1e-6)
