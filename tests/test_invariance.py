"""rho^T rho_dot against an independent finite-difference computation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from tubekit.ancillary import LAWS
from tubekit.derivation import error_coordinates
from tubekit.model import kinematics
from verify import strategies as vs
from verify.invariance import applied_input, rho_dot_inner
from verify.region import Region

REGION = Region(e_d=(0.3, 3.0), e_z=(-1.0, 1.0), e_o=(-0.8, 0.8), heading="both", pd_dot_max=(0.3, 0.3, 0.05),
                pd_dot_xy_max=0.3, omega_bar=0.15, v_max=(0.4, 0.3, 0.5))


def _fd_inner(cfg, law, sigma, h=1e-6):
    """d/dt 1/2||rho||^2 by central differences of the kinematics (no derived J/zeta/xi)."""
    v = applied_input(cfg, law, sigma)

    def half_norm(s):
        real = cfg.real + s * kinematics(cfg.real, v, cfg.omega) - s * np.r_[cfg.pd_dot, 0.0]
        nom = cfg.nominal + s * kinematics(cfg.nominal, cfg.v_hat, np.zeros(3)) - s * np.r_[cfg.pd_dot, 0.0]
        rho = error_coordinates(real, np.zeros(3)) - error_coordinates(nom, np.zeros(3))
        return 0.5 * rho @ rho

    return (half_norm(h) - half_norm(-h)) / (2 * h)


@pytest.mark.parametrize("name", sorted(LAWS))
@given(cfg=vs.tube_configurations(REGION, rho_tilde=0.05, v_bar=[0.3, 0.2, 0.4], delta_theta=0.2))
def test_matches_finite_differences(name, cfg):
    """Property: rho_dot_inner equals the finite-difference derivative of 1/2||rho||^2 along eq. (11)."""
    law = LAWS[name]
    assert rho_dot_inner(cfg, law, 3.0) == pytest.approx(_fd_inner(cfg, law, 3.0), rel=1e-4, abs=1e-7)
