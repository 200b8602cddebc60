"""Tightened constraint data handed from the verifier to the FHOCP.

The verifier (:func:`verify.certify`) produces one :class:`Tightening` from a
certificate; :meth:`Tightening.untightened` is the baseline (no tube).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .scenario import Scenario

__all__ = ["Tightening"]


@dataclass(frozen=True)
class Tightening:
    """Constraints of the FHOCP on the nominal system.

    Attributes
    ----------
    v_max : array (3,)
        V-bar: nominal input box [u, w, r] limits (m/s, m/s, rad/s).
    e_d_min : float
        Nominal e_d >= e_d_min = epsilon + rho-tilde (m).
    e_o_max : float
        Nominal |e_o| <= e_o_max (region bound shrunk by the tube).
    e_z_max : float
        Nominal |e_z| <= e_z_max (m).
    e_d_max : float
        Nominal e_d <= e_d_max (m).
    obstacle_margin : float
        Added to vehicle radius + obstacle radius for the nominal position (m):
        the bound on ||p - p_hat|| between FHOCP samples.
    rho_tilde : float
        Tube radius (error units); 0 for the baseline.
    sigma : float
        Ancillary gain (1/s); 0 disables the feedback (baseline).
    """

    v_max: np.ndarray
    e_d_min: float
    e_o_max: float
    e_z_max: float
    e_d_max: float
    obstacle_margin: float
    rho_tilde: float
    sigma: float

    @classmethod
    def untightened(cls, scenario: Scenario) -> "Tightening":
        """The baseline's sets: V, e_d >= epsilon, region bounds, no margin, no feedback."""
        reg = scenario.region
        return cls(v_max=scenario.limits.vector.copy(), e_d_min=scenario.epsilon, e_o_max=reg.e_o_max,
                   e_z_max=reg.e_z_max, e_d_max=reg.e_d_max, obstacle_margin=0.0, rho_tilde=0.0, sigma=0.0)
