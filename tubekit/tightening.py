"""Tightened constraint data handed from the verifier to the FHOCP and the closed loop.

The verifier (:func:`verify.certify`) produces one :class:`Tightening` from a
certificate; :meth:`Tightening.untightened` is the baseline (no tube).

Two layers of data:

* the FHOCP's node constraints (scalars ``e_d_min`` ... ``obstacle_margin``,
  uniform over the horizon and at least the largest per-arc margin plus an
  inter-node allowance, so a plan meeting them usually passes the arc check);
* the certificate's per-arc margins ``margins`` (N, 4) (columns e_d, e_z, e_o,
  position), its nominal-arc rate bounds ``rates`` (4,) and its one-period tube
  ``tube`` (3,) per axis, used by :mod:`tubekit.loop.plan_check` to accept a plan
  exactly along its arcs and by the run's promise checks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tubekit.scenario import Scenario

__all__ = ["Tightening", "MARGIN_COLUMNS"]

#: Columns of :attr:`Tightening.margins` and :attr:`Tightening.rates`.
MARGIN_COLUMNS: tuple[str, ...] = ("e_d", "e_z", "e_o", "position")


def _zeros(n: int, k: int = 4) -> np.ndarray:
    return np.zeros((n, k)) if n else np.zeros(k)


@dataclass(frozen=True)
class Tightening:
    """Constraints of the FHOCP on the nominal system, and the certificate's tube.

    Attributes
    ----------
    v_max : array (3,)
        V-bar: nominal input box [u, w, r] limits (m/s, m/s, rad/s).
    e_d_min, e_d_max : float
        Nominal e_d bounds at the FHOCP nodes (m).
    e_o_max : float
        Nominal |e_o| bound at the nodes.
    e_z_max : float
        Nominal |e_z| bound at the nodes (m).
    obstacle_margin : float
        Added to vehicle radius + obstacle radius for the nominal position at the nodes (m).
    rho_tilde : float
        Euclidean norm of the per-axis tube ``tube`` (plots); 0 for the baseline.
    sigma : float
        Ancillary gain (1/s); 0 disables the feedback.
    margins : array (N, 4)
        Per-arc margins (e_d, e_z, e_o, position) relative to the state a plan starts from;
        empty for the baseline (no arc check).
    rates : array (4,)
        Bounds on |ė_d|, |ė_z|, |ė_o|, ‖ṗ‖ along a nominal arc (spacing margin of the arc check).
    tube : array (3,)
        Certified one-period per-axis bounds on |e - ê| (m, m, -); zeros for the baseline.
    region : array (4,)
        R: e_d lower (epsilon), e_d upper, |e_z| bound, |e_o| bound.
    disturbance : array (3,)
        The certificate's ω̄_xy, ω̄_z and sway bound γ̄ (m/s); zeros for the baseline.
    certified : bool
        True only when it comes from a certified certificate.
    """

    v_max: np.ndarray
    e_d_min: float
    e_o_max: float
    e_z_max: float
    e_d_max: float
    obstacle_margin: float
    rho_tilde: float
    sigma: float
    margins: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    rates: np.ndarray = field(default_factory=lambda: np.zeros(4))
    tube: np.ndarray = field(default_factory=lambda: np.zeros(3))
    region: np.ndarray = field(default_factory=lambda: np.zeros(4))
    disturbance: np.ndarray = field(default_factory=lambda: np.zeros(3))
    certified: bool = False

    @property
    def horizon_arcs(self) -> int:
        """Number of arcs with certified margins (0: no arc check)."""
        return int(np.asarray(self.margins).shape[0])

    @classmethod
    def untightened(cls, scenario: Scenario) -> "Tightening":
        """The baseline's sets: V, e_d >= epsilon, region bounds, no margin, no feedback."""
        reg = scenario.region
        return cls(v_max=scenario.limits.vector.copy(), e_d_min=scenario.epsilon, e_o_max=reg.e_o_max,
                   e_z_max=reg.e_z_max, e_d_max=reg.e_d_max, obstacle_margin=0.0, rho_tilde=0.0, sigma=0.0,
                   region=np.array([scenario.epsilon, reg.e_d_max, reg.e_z_max, reg.e_o_max]))
