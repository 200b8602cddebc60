"""Pointwise tube invariance: the sign of d/dt (1/2 ||rho||^2) at one configuration.

A :class:`TubeConfiguration` fixes everything the derivative depends on: the real
and nominal states relative to the target (p_d = 0), the nominal input v_hat, the
disturbance omega and the target velocity p_d_dot. With rho = e - e_hat,

    rho^T rho_dot = rho^T [ e_dot(real, v_hat + kappa, omega, p_d_dot) - e_dot(nominal, v_hat, 0, p_d_dot) ],

always with the *derived* dynamics (:mod:`tubekit.model.derivation`). The tube is
invariant at a configuration on its boundary (||rho|| = rho-tilde) when this is <= 0.

That pointwise sign is no longer what the certificate claims (the sampled-data
theorem, :mod:`verify.theorem.sampled`): :func:`one_period_ratio` runs one FHOCP period of
the loop as it runs — reset ê(t_k) = e(t_k) (so ``real`` = ``nominal``), v̂ held,
κ held over each tick, the plant of :mod:`tubekit.plant.kinematic` under a constant ω and a
target moving at p_d_dot — and returns max_j |e_j - ê_j| / tube_j over the period,
which the certificate bounds by 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import math

from tubekit.model.ancillary import AncillaryLaw
from tubekit.model.errors import error_coordinates, numeric
from tubekit.exceptions import ConfigError
from tubekit.plant.kinematic import Plant, nominal_arc
from tubekit.scenario import Disturbance

__all__ = ["TubeConfiguration", "rho_dot_inner", "applied_input", "one_period_ratio"]

_STATE_KEYS = ("e_x", "e_y", "e_z", "psi")


@dataclass(frozen=True)
class TubeConfiguration:
    """One point of the tube-invariance question (units m, m/s, rad, rad/s).

    Attributes
    ----------
    real, nominal : array (4,)
        [e_x, e_y, e_z, psi] of the real and nominal vehicle relative to the target.
    v_hat : array (3,)
        Nominal input [u, w, r].
    omega : array (3,)
        Disturbance [omega_1, omega_2, omega_3].
    pd_dot : array (3,)
        Target velocity [xdot_d, ydot_d, zdot_d].
    """

    real: np.ndarray
    nominal: np.ndarray
    v_hat: np.ndarray
    omega: np.ndarray
    pd_dot: np.ndarray

    @property
    def rho(self) -> np.ndarray:
        """rho = e - e_hat in error coordinates [e_d, e_z, e_o]."""
        zero = np.zeros(3)
        return error_coordinates(self.real, zero) - error_coordinates(self.nominal, zero)

    def to_dict(self) -> dict:
        """JSON form: ``real``/``nominal`` as {e_x, e_y, e_z, psi}, vectors as lists."""
        return {
            "real": dict(zip(_STATE_KEYS, map(float, self.real))),
            "nominal": dict(zip(_STATE_KEYS, map(float, self.nominal))),
            "v_hat": [float(x) for x in self.v_hat],
            "omega": [float(x) for x in self.omega],
            "pd_dot": [float(x) for x in self.pd_dot],
        }


def applied_input(config: TubeConfiguration, law: AncillaryLaw, sigma: float) -> np.ndarray:
    """v = v_hat + kappa(e, e_hat) applied to the real vehicle (3,)."""
    zero = np.zeros(3)
    return config.v_hat + law(config.real, config.nominal, zero, sigma)


def rho_dot_inner(config: TubeConfiguration, law: AncillaryLaw, sigma: float) -> float:
    """rho^T rho_dot at ``config`` under ``law`` with gain ``sigma`` (1/s); > 0 is a violation.

    Returns ``nan`` where the law is undefined (e_d = 0).
    """
    try:
        v = applied_input(config, law, sigma)
    except ConfigError:  # the law is undefined here (e_d = 0 or J singular)
        return float("nan")
    dyn = numeric().e_dot
    with np.errstate(all="ignore"):
        e_dot = dyn(config.real[0], config.real[1], config.real[3], *v, *config.omega, *config.pd_dot)
        e_hat_dot = dyn(config.nominal[0], config.nominal[1], config.nominal[3], *config.v_hat, 0.0, 0.0, 0.0,
                        *config.pd_dot)
    return float(config.rho @ (e_dot - e_hat_dot))


def one_period_ratio(config: TubeConfiguration, law: AncillaryLaw, sigma: float, tube: np.ndarray,
                     tick: float, ticks: int, substeps: int = 2) -> float:
    """max over one period of max_j |e_j - ê_j| / tube_j from the reset state ``config.real`` (-).

    The target starts at the origin and moves at ``config.pd_dot``; κ is held over each tick of
    ``tick`` s (``ticks`` per period), the plant integrated with RK4 (``substeps`` per tick) under
    the constant ``config.omega``. Returns ``nan`` where the law is undefined.
    """
    omega = tuple(float(w) for w in config.omega)
    plant = Plant(Disturbance(), override=lambda t: omega)
    tube = np.asarray(tube, dtype=float)
    pd_dot = np.asarray(config.pd_dot, dtype=float)
    arc = nominal_arc(config.real, config.v_hat, np.arange(ticks + 1) * tick)
    x = tuple(float(c) for c in config.real)
    worst = 0.0
    for i in range(ticks + 1):
        p_d = pd_dot * (i * tick)
        rho = error_coordinates(np.asarray(x), p_d) - error_coordinates(arc[i], p_d)
        worst = max(worst, float(np.max(np.abs(rho) / tube)))
        if i == ticks:
            break
        try:
            v = config.v_hat + law(np.asarray(x), arc[i], p_d, sigma)
        except ConfigError:
            return math.nan
        x = plant.step_tuple(i * tick, x, tuple(float(c) for c in v), tick / substeps, substeps)
    return worst
