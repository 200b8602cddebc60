"""Tightening: the baseline's sets and the fields a certificate hands over."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import verify
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from tubekit.tiers import Tiers
from tubekit.tightening import MARGIN_COLUMNS, DisturbanceBound, RegionBounds, Tightening


def test_untightened_is_the_scenario():
    sc = paper_scenario()
    t = Tightening.untightened(sc)
    assert np.array_equal(t.v_max, sc.limits.vector)
    assert t.e_d_min == sc.epsilon and t.e_d_max == sc.region.e_d_max
    assert t.e_o_max == sc.region.e_o_max and t.e_z_max == sc.region.e_z_max
    assert t.obstacle_margin == 0 and t.rho_tilde == 0 and t.sigma == 0
    assert t.horizon_arcs == 0 and not t.certified
    assert t.region == RegionBounds(epsilon=sc.epsilon, e_d_max=sc.region.e_d_max, e_z_max=sc.region.e_z_max,
                                    e_o_max=sc.region.e_o_max)
    assert np.all(t.tube == 0) and t.disturbance == DisturbanceBound(0.0, 0.0, 0.0) and t.margins.shape == (0, 4)
    assert t.law is None and t.design_key is None and t.design is None   # the baseline is not checked


def test_untightened_does_not_share_the_limits_array():
    sc = paper_scenario()
    t = Tightening.untightened(sc)
    t.v_max[0] = 99.0
    assert sc.limits.vector[0] == 0.4


def test_margin_columns():
    assert MARGIN_COLUMNS == ("e_d", "e_z", "e_o", "position")


def test_horizon_arcs_is_the_number_of_margin_rows():
    t = Tightening(v_max=np.ones(3), e_d_min=0.5, e_o_max=0.4, e_z_max=0.9, e_d_max=2.9, obstacle_margin=0.1,
                   sigma=1.0, margins=np.zeros((5, 4)))
    assert t.horizon_arcs == 5


def test_certified_tightening_is_the_pontryagin_difference():
    """V_bar = V - kappa_bar and the per-axis tube of the sampled-data certificate."""
    free = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    assert np.array_equal(verify.certify(free).tightening.v_max, free.limits.vector)  # sigma = 0: no kappa
    sc = load_scenario(verify.SCENARIOS_DIR / "certifiable.toml")    # sigma = 100 declared, both tiers
    cert = verify.certify(sc)
    t = cert.tightening
    assert t.certified and t.horizon_arcs == sc.controller.horizon_steps
    np.testing.assert_allclose(t.v_max, sc.limits.vector - np.asarray(cert.kappa_bar), rtol=1e-12)
    assert np.all(t.v_max > 0) and np.all(t.v_max < sc.limits.vector)
    assert t.rho_tilde == float(np.linalg.norm(t.tube)) > 0
    assert t.e_d_min > sc.epsilon and t.e_d_max < sc.region.e_d_max and t.e_o_max < sc.region.e_o_max


def _plain(**changes) -> Tightening:
    return Tightening(v_max=np.ones(3), e_d_min=0.5, e_o_max=0.4, e_z_max=0.9, e_d_max=2.9, obstacle_margin=0.1,
                      sigma=1.0, **changes)


def test_region_and_disturbance_are_named_and_accept_numbers_in_order():
    t = _plain(region=np.array([0.5, 3.0, 1.0, 0.4]), disturbance=(0.04, 0.02, 0.01))
    assert (t.region.epsilon, t.region.e_d_max, t.region.e_z_max, t.region.e_o_max) == (0.5, 3.0, 1.0, 0.4)
    assert (t.disturbance.omega_xy, t.disturbance.omega_z, t.disturbance.sway) == (0.04, 0.02, 0.01)
    again = dataclasses.replace(t, sigma=2.0)
    assert again.region == t.region and again.disturbance == t.disturbance


@pytest.mark.parametrize("changes, field", [
    (dict(region=[0.5, 3.0, 1.0]), "tightening.region"),
    (dict(region=[0.5, 3.0, 1.0, float("nan")]), "tightening.region"),
    (dict(region="abcd"), "tightening.region"),
    (dict(disturbance=[0.1, 0.2]), "tightening.disturbance"),
    (dict(disturbance=[0.1, float("inf"), 0.0]), "tightening.disturbance"),
])
def test_bad_region_or_disturbance_is_refused(changes, field):
    with pytest.raises(ConfigError, match=field):
        _plain(**changes)


def test_only_a_certified_backup_imposes_the_terminal_condition():
    """A best-effort backup (tiers say safe: False) replaces the zero input but does not gate plans."""
    from dataclasses import replace

    from tubekit.model.backup import BackupPlan, SafeSet, StationKeeping
    from tubekit.scenario import paper_scenario

    plan = BackupPlan(StationKeeping(0.2, 0.5, 0.05, 0.3, 0.04), SafeSet(0.75, 0.4, 0.08), (0.1, 0.05))
    base = Tightening.untightened(paper_scenario())
    assert replace(base, backup=plan).terminal_backup is None  # no tier given (the baseline's): not enforced
    assert replace(base, backup=plan, tiers=Tiers(True, False)).terminal_backup is plan
    assert replace(base, backup=plan, tiers=Tiers(False, False)).terminal_backup is None
    assert base.terminal_backup is None
    assert replace(base, backup=plan, tiers=Tiers(True, True)).terminal_rest and not base.terminal_rest
    ramped = BackupPlan(replace(plan.law, surge_fade=0.1, yaw_fade=0.1, ramp=1.0), plan.safe_set, plan.handover)
    assert not replace(base, backup=ramped).terminal_rest  # it blends from the last command instead
    assert not replace(base, backup=plan, tiers=Tiers(False, False)).terminal_rest
