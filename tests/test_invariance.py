"""rho^T rho_dot against an independent finite-difference computation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from tubekit.ancillary import LAWS
from verify import strategies as vs
from verify.invariance import rho_dot_inner
from verify.region import Region

from .independent import fd_rho_dot_inner

REGION = Region(e_d=(0.3, 3.0), e_z=(-1.0, 1.0), e_o=(-0.8, 0.8), heading="both", pd_dot_max=(0.3, 0.3, 0.05),
                pd_dot_xy_max=0.3, omega_bar=0.15, v_max=(0.4, 0.3, 0.5))


@pytest.mark.parametrize("name", sorted(LAWS))
@given(cfg=vs.tube_configurations(REGION, rho_tilde=0.05, v_bar=[0.3, 0.2, 0.4], delta_theta=0.2))
def test_matches_finite_differences(name, cfg):
    """Property: rho_dot_inner equals the finite-difference derivative of 1/2||rho||^2 along eq. (11)."""
    law = LAWS[name]
    assert rho_dot_inner(cfg, law, 3.0) == pytest.approx(fd_rho_dot_inner(cfg, law, 3.0), rel=1e-4, abs=1e-7)
