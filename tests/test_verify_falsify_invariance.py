"""rho^T rho_dot against an independent finite-difference computation."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given

from tubekit.model.ancillary import LAWS
from verify.falsify import strategies as vs
from verify.falsify.invariance import TubeConfiguration, one_period_ratio, rho_dot_inner
from verify.kernel.region import Region

from .independent import fd_rho_dot_inner

REGION = Region(e_d=(0.3, 3.0), e_z=(-1.0, 1.0), e_o=(-0.8, 0.8), heading="both", pd_dot_max=(0.3, 0.3, 0.05),
                pd_dot_xy_max=0.3, omega_bar=0.15, v_max=(0.4, 0.3, 0.5))


@pytest.mark.parametrize("name", sorted(LAWS))
@given(cfg=vs.tube_configurations(REGION, rho_tilde=0.05, v_bar=[0.3, 0.2, 0.4], delta_theta=0.2))
def test_matches_finite_differences(name, cfg):
    """Property: rho_dot_inner equals the finite-difference derivative of 1/2||rho||^2 along eq. (11)."""
    law = LAWS[name]
    assert rho_dot_inner(cfg, law, 3.0) == pytest.approx(fd_rho_dot_inner(cfg, law, 3.0), rel=1e-4, abs=1e-7)


START = ((0.6, 2.5), (-0.4, 0.4), (-0.3, 0.3))


@given(cfg=vs.period_configurations(REGION, START, [0.3, 0.2, 0.4], (0.0, 0.0)))
def test_one_period_without_disturbance_stays_on_nominal(cfg):
    """Property: with omega = 0 and a still target the real vehicle follows the exact nominal arc
    (rho stays 0 up to the RK4 error), so the one-period ratio is ~0."""
    cfg = replace(cfg, pd_dot=np.zeros(3))
    assert one_period_ratio(cfg, LAWS["corrected"], 50.0, np.ones(3), 0.01, 10) < 1e-8


@pytest.mark.parametrize("sigma", [10.0, 50.0])
def test_one_period_vertical_axis_closed_form(sigma):
    """e_z is linear: under a constant omega_z, rho_z after i ticks is omega_z h sum_k (1 - sigma h)^k."""
    state = np.array([1.0, 0.0, 0.0, np.pi])
    cfg = TubeConfiguration(real=state, nominal=state.copy(), v_hat=np.zeros(3), omega=np.array([0.0, 0.0, 0.1]),
                            pd_dot=np.zeros(3))
    h, m = 0.01, 10
    exact = max(abs(0.1 * h * sum((1 - sigma * h) ** k for k in range(i))) for i in range(m + 1))
    tube = np.array([1.0, exact, 1.0])
    assert one_period_ratio(cfg, LAWS["corrected"], sigma, tube, h, m) == pytest.approx(1.0, rel=1e-9)
