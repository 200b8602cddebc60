"""verify.falsify.strategies: every strategy builds values inside the set it promises."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.model.errors import error_coordinates
from tubekit.exceptions import ConfigError
from verify.falsify import strategies as vs
from verify.kernel.region import Region

REGION = Region(e_d=(0.2, 3.0), e_z=(-1.0, 1.0), e_o=(-0.8, 0.8), heading="both", pd_dot_max=(0.3, 0.2, 0.05),
                pd_dot_xy_max=0.3, omega_bar=0.15, v_max=(0.4, 0.3, 0.5))


def _cos_rel(state):
    return np.cos(state[3] - np.arctan2(state[1], state[0]))


@given(vs.regions())
def test_regions_are_valid(region):
    """Property: generated regions pass Region's own validation and have e_d > 0, |e_o| < 1."""
    assert isinstance(region, Region)
    assert 0 < region.e_d[0] < region.e_d[1] and -1 < region.e_o[0] < region.e_o[1] < 1


@given(st.data())
def test_error_states_lie_in_region(data):
    """Property: error_states(region) gives states whose error (and hemisphere) is in the region."""
    region = data.draw(vs.regions())
    s = data.draw(vs.error_states(region))
    e = error_coordinates(s, np.zeros(3))
    tol = 1e-9
    for x, (lo, hi) in zip(e, (region.e_d, region.e_z, region.e_o)):
        assert lo - tol <= x <= hi + tol
    assert any(sign * _cos_rel(s) > 0 for sign in region.hemisphere_signs)


@given(vs.tube_pairs(REGION, rho_tilde=0.07, delta_theta=0.3))
def test_tube_pairs_on_boundary(pair):
    """Property: ||e - e_hat|| = rho_tilde, both in the region, same hemisphere, bearings within Delta-theta."""
    real, nominal = pair
    e, e_hat = error_coordinates(real, np.zeros(3)), error_coordinates(nominal, np.zeros(3))
    assert np.linalg.norm(e - e_hat) == pytest.approx(0.07, rel=1e-9)
    for x, s in ((e, real), (e_hat, nominal)):
        assert REGION.e_d[0] - 1e-12 <= x[0] <= REGION.e_d[1] + 1e-12
        assert REGION.e_o[0] - 1e-12 <= x[2] <= REGION.e_o[1] + 1e-12
    assert np.sign(_cos_rel(real)) == np.sign(_cos_rel(nominal))
    dtheta = np.angle(np.exp(1j * (np.arctan2(real[1], real[0]) - np.arctan2(nominal[1], nominal[0]))))
    assert abs(dtheta) <= 0.3 + 1e-9


@given(vs.disturbances(0.15))
def test_constant_disturbances_in_omega(omega):
    """Property: ||omega|| <= omega_bar."""
    assert np.linalg.norm(omega) <= 0.15 + 1e-12


@given(vs.disturbance_signals(0.1), st.floats(0, 1000))
def test_signals_bounded(signal, t):
    """Property: a time-varying disturbance stays in Omega at every time."""
    assert np.linalg.norm(signal(t)) <= 0.1 + 1e-12


@given(vs.target_velocities(REGION))
def test_target_velocities_in_P(v):
    """Property: |pd_dot_i| <= pd_dot_max_i and the horizontal speed <= pd_dot_xy_max."""
    assert np.all(np.abs(v) <= np.array(REGION.pd_dot_max) + 1e-12)
    assert np.hypot(v[0], v[1]) <= REGION.pd_dot_xy_max + 1e-12


@given(vs.nominal_inputs([0.3, 0.2, 0.4]))
def test_inputs_in_box(v):
    """Property: nominal inputs lie in the V-bar box."""
    assert np.all(np.abs(v) <= [0.3, 0.2, 0.4])


@given(vs.trajectories(max_speed=0.35))
def test_trajectories_respect_speed(traj):
    """Property: sampled trajectories never exceed the requested horizontal speed."""
    t = np.linspace(0, 100, 2001)
    v = traj.velocity(t)
    assert np.hypot(v[:, 0], v[:, 1]).max() <= 0.35 + 1e-9


@given(vs.obstacle_sets(vehicle_radius=0.3, max_obstacles=5))
def test_obstacle_sets_separated(obstacles):
    """Property: every pair satisfies eq. (obstacle_dis) ||c_i - c_j|| > 2 r-bar + r_i + r_j."""
    for a, b in itertools.combinations(obstacles, 2):
        assert np.linalg.norm(np.subtract(a.center, b.center)) > 0.6 + a.radius + b.radius


def test_tube_too_wide_for_region_is_rejected():
    with pytest.raises(ConfigError, match="rho_tilde"):
        vs.tube_pairs(REGION, rho_tilde=5.0)


START = ((0.6, 2.5), (-0.4, 0.4), (-0.3, 0.3))


@given(vs.period_configurations(REGION, START, [0.3, 0.2, 0.4], (0.12, 0.05)))
def test_period_configurations_in_sets(cfg):
    """Property: a period starts at the reset (real = nominal) with e in E-bar, v_hat in V-bar,
    ||omega_xy|| <= omega_bar_xy, |omega_z| <= omega_bar_z and p_d_dot in P."""
    assert np.array_equal(cfg.real, cfg.nominal)
    e = error_coordinates(cfg.real, np.zeros(3))
    for x, (lo, hi) in zip(e, START):
        assert lo - 1e-9 <= x <= hi + 1e-9
    assert np.all(np.abs(cfg.v_hat) <= [0.3, 0.2, 0.4])
    assert np.hypot(cfg.omega[0], cfg.omega[1]) <= 0.12 + 1e-12 and abs(cfg.omega[2]) <= 0.05 + 1e-12
    assert np.hypot(cfg.pd_dot[0], cfg.pd_dot[1]) <= REGION.pd_dot_xy_max + 1e-12


def test_period_configurations_reject_empty_start():
    with pytest.raises(ConfigError, match="start"):
        vs.period_configurations(REGION, ((1.0, 0.5), (-1, 1), (-0.5, 0.5)), [0.3, 0.2, 0.4], (0.1, 0.1))


# ---- scenario families against certified designs (issue 21) ----------------------------------------------
def _family_base():
    import verify
    from tubekit import load_scenario
    return load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml").with_changes(duration=8.0)


_FAMILY_BASE = _family_base()


def _no_safety_promise_broken(scenario):
    import verify
    from tubekit.loop.pipeline import certified_run
    from verify.falsify.backup_loop import safety_broken
    cert = verify.certify(scenario)
    if not cert.certified:
        return
    sim = certified_run(scenario, cert.tightening)
    assert safety_broken(sim) == (), sim.summary()
    assert sim.check(), sim.summary()


@pytest.mark.parametrize("family", [vs.obstacles_beyond_sensing, vs.obstacles_on_path, vs.obstacle_clusters,
                                    vs.obstacles_between_end_and_target, vs.blocked_starts])
def test_scenario_families_break_no_safety_promise(family):
    """Property: on every certified design a family builds, the run keeps every promise of the safe tier
    (no collision, inside the workspace, v in V never clipped) and CertifiedRun.check() holds."""
    from hypothesis import settings

    @settings(max_examples=2)
    @given(family(_FAMILY_BASE))
    def check(scenario):
        _no_safety_promise_broken(scenario)
    check()


@given(vs.backup_attack_scenarios(_FAMILY_BASE))
def test_backup_attack_scenarios_are_valid(scenario):
    """Property: the union of the families builds scenarios that keep the base's trajectory and limits."""
    assert scenario.trajectory == _FAMILY_BASE.trajectory and scenario.limits == _FAMILY_BASE.limits
    assert len(scenario.obstacles) <= 7
