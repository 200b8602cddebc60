"""Independent reference computations shared by tests (no derived J, zeta or xi)."""

from __future__ import annotations

import numpy as np

from tubekit.model.errors import error_coordinates
from tubekit.model.kinematics import kinematics
from verify.falsify.invariance import applied_input


def fd_rho_dot_inner(cfg, law, sigma, h=1e-6):
    """d/dt 1/2||rho||^2 by central differences of the kinematics eq. (11)."""
    v = applied_input(cfg, law, sigma)

    def half_norm(s):
        real = cfg.real + s * kinematics(cfg.real, v, cfg.omega) - s * np.r_[cfg.pd_dot, 0.0]
        nom = cfg.nominal + s * kinematics(cfg.nominal, cfg.v_hat, np.zeros(3)) - s * np.r_[cfg.pd_dot, 0.0]
        rho = error_coordinates(real, np.zeros(3)) - error_coordinates(nom, np.zeros(3))
        return 0.5 * rho @ rho

    return (half_norm(h) - half_norm(-h)) / (2 * h)
