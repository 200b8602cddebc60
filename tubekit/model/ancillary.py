"""Ancillary (tube) feedback laws kappa(e, e_hat) = -sigma K(e) (e - e_hat).

* ``paper``: K = I, eq. (kappa_law). Its closed-loop gain J(e) K = J(e) has a
  symmetric part that is negative definite when the vehicle points at the
  target (see :mod:`tubekit.paper.audit`), so it cannot be certified there.
* ``corrected``: K = J(e)^-1 (inverse-Jacobian law). The closed-loop gain is
  J K = I, so rho^T J kappa = -sigma ||rho||^2 in *both* heading hemispheres
  wherever J is non-singular (|e_o| < 1). The price is input usage
  |kappa_i| <= sigma ||row_i(J^-1)|| ||rho||, which the verifier bounds.

J is always the *derived* J of :mod:`tubekit.model.derivation`, evaluated at the real
state (the real state is measured; the law is full-state feedback). For the
built-in laws, :meth:`AncillaryLaw.__call__` on one state evaluates κ as closed-form
scalars generated from that derivation (:mod:`tubekit.model._generated_dynamics`); other
laws and batched states go through J and ``gain_of_jacobian``.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:  # sympy is loaded only when a symbolic gain is evaluated (verify)
    import sympy as sp

from tubekit.model import _generated_dynamics as generated
from tubekit.model.errors import error_coordinates, numeric
from tubekit.exceptions import ConfigError

__all__ = ["AncillaryLaw", "get_law", "register_law", "jacobian_at", "LAWS", "BUILTIN_LAWS", "is_builtin"]


def _identity_gain(J: np.ndarray) -> np.ndarray:
    return np.broadcast_to(np.eye(3), J.shape).copy()


def _inverse_gain(J: np.ndarray) -> np.ndarray:
    return np.linalg.inv(J)


#: Closed-form kappa of a law: (e_x, e_y, psi, rho_d, rho_z, rho_o, sigma) -> (3 floats).
ClosedFormKappa = Callable[[float, float, float, float, float, float, float], tuple[float, float, float]]


def _paper_kappa(e_x: float, e_y: float, psi: float, rho_d: float, rho_z: float, rho_o: float,
                 sigma: float) -> tuple[float, float, float]:
    """kappa = -sigma rho (K = I); the arguments are floats (m, rad, 1/s)."""
    return (-sigma * rho_d, -sigma * rho_z, -sigma * rho_o)


@dataclass(frozen=True)
class AncillaryLaw:
    """An ancillary law kappa = -sigma K(J(e)) rho.

    Attributes
    ----------
    name : str
        ``"paper"`` or ``"corrected"``.
    gain_of_jacobian : callable
        Maps J (..., 3, 3) to K (..., 3, 3).
    description : str
        One line for reports.
    symbolic_gain : callable, optional
        The same map on a sympy Matrix, J -> K. Needed for :func:`verify.certify`,
        which bounds K(e) and J(e) K(e) with interval arithmetic; a law without it
        can be simulated and falsified, not certified.
    closed_form : callable, optional
        kappa as scalars, (e_x, e_y, psi, rho_d, rho_z, rho_o, sigma) -> 3 floats, raising
        ZeroDivisionError where the law is undefined; used by ``__call__`` on a single state. It must
        equal ``-sigma K(J) rho`` (the built-in ones are tested against it).
    """

    name: str
    gain_of_jacobian: Callable[[np.ndarray], np.ndarray]
    description: str
    symbolic_gain: Callable[[Any], Any] | None = None
    closed_form: ClosedFormKappa | None = None

    def gain(self, state: np.ndarray, p_d: np.ndarray) -> np.ndarray:
        """K(e) at the real state (..., 4) w.r.t. p_d (..., 3)."""
        J = jacobian_at(state, p_d)
        return self.gain_of_jacobian(J)

    def closed_loop_matrix(self, J: np.ndarray) -> np.ndarray:
        """J K, whose symmetric part's lambda_min is the certificate's J_lower."""
        return J @ self.gain_of_jacobian(J)

    def __call__(self, state: np.ndarray, state_hat: np.ndarray, p_d: np.ndarray, sigma: float) -> np.ndarray:
        """kappa (3,) in [u, w, r] units for real ``state`` and nominal ``state_hat``.

        Parameters
        ----------
        state, state_hat : array (4,)
            Real and nominal [x, y, z, psi].
        p_d : array (3,)
            Desired position at this time (m).
        sigma : float
            Gain (1/s).
        """
        if self.closed_form is not None and np.shape(state) == (4,) and np.shape(state_hat) == (4,):
            return self._closed_form_call(state, state_hat, p_d, sigma)
        rho = error_coordinates(state, p_d) - error_coordinates(state_hat, p_d)
        with np.errstate(invalid="ignore", divide="ignore"):
            try:
                K = self.gain(state, p_d)
            except np.linalg.LinAlgError:
                K = np.full((3, 3), np.nan)
            out = -sigma * (K @ rho)
        if not np.all(np.isfinite(out)):
            raise _undefined(state)
        return out

    def _closed_form_call(self, state: np.ndarray, state_hat: np.ndarray, p_d: np.ndarray,
                          sigma: float) -> np.ndarray:
        """kappa (3,) by the closed-form scalars: no arrays until the result."""
        x, y, z, psi = state.tolist() if isinstance(state, np.ndarray) else map(float, state)
        xh, yh, zh, psih = state_hat.tolist() if isinstance(state_hat, np.ndarray) else map(float, state_hat)
        xd, yd, zd = p_d.tolist() if isinstance(p_d, np.ndarray) else map(float, p_d)
        try:
            e_d, e_z, e_o = generated.error_scalar(x - xd, y - yd, z - zd, psi)
            h_d, h_z, h_o = generated.error_scalar(xh - xd, yh - yd, zh - zd, psih)
            out = self.closed_form(x - xd, y - yd, psi, e_d - h_d, e_z - h_z, e_o - h_o, float(sigma))
        except (ZeroDivisionError, OverflowError, ValueError):
            raise _undefined(state) from None
        if not (math.isfinite(out[0]) and math.isfinite(out[1]) and math.isfinite(out[2])):
            raise _undefined(state)
        return np.array(out, dtype=float)


def _undefined(state: np.ndarray) -> ConfigError:
    """The error for a state where e_o or J^-1 is undefined."""
    return ConfigError("state", "a state with e_d > 0 and |e_o| < 1 (J non-singular)", np.asarray(state).tolist())


def jacobian_at(state: np.ndarray, p_d: np.ndarray) -> np.ndarray:
    """The derived J (..., 3, 3) at ``state`` (..., 4) w.r.t. ``p_d`` (..., 3)."""
    state = np.asarray(state, dtype=float)
    p_d = np.asarray(p_d, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return numeric().J(state[..., 0] - p_d[..., 0], state[..., 1] - p_d[..., 1], state[..., 3])


def _identity_symbolic(J: sp.Matrix) -> sp.Matrix:
    """K = I as a sympy Matrix (sympy imported here, on first use)."""
    import sympy

    return sympy.eye(3)


def _inverse_symbolic(J: sp.Matrix) -> sp.Matrix:
    """K = J^-1 = adj(J) / det(J) as a sympy Matrix."""
    return J.adjugate() / J.det()


#: The law registry: the two built-in laws plus any added with :func:`register_law`.
LAWS: dict[str, AncillaryLaw] = {
    "paper": AncillaryLaw("paper", _identity_gain, "kappa = -sigma (e - e_hat)   [paper, eq. kappa_law]",
                          symbolic_gain=_identity_symbolic, closed_form=_paper_kappa),
    "corrected": AncillaryLaw("corrected", _inverse_gain,
                              "kappa = -sigma J(e)^-1 (e - e_hat)   [inverse-Jacobian law]",
                              symbolic_gain=_inverse_symbolic,
                              closed_form=generated.corrected_kappa),
}

#: The built-in laws, whose certificate objectives ship compiled (``verify.kernel.compiled``).
BUILTIN_LAWS: tuple[str, ...] = tuple(LAWS)
_BUILTIN: dict[str, AncillaryLaw] = dict(LAWS)


def is_builtin(name: str) -> bool:
    """True when ``name`` is registered as the built-in law of that name (its symbolic gain is the shipped one)."""
    return name in _BUILTIN and LAWS.get(name) is _BUILTIN[name]


def register_law(law: AncillaryLaw) -> AncillaryLaw:
    """Add ``law`` to :data:`LAWS` so it can be selected by name (scenarios, CLI, verify).

    Raises :class:`ConfigError` if a *different* law already has that name.
    """
    if not isinstance(law, AncillaryLaw):
        raise ConfigError("law", "an AncillaryLaw", type(law).__name__)
    if not law.name or not isinstance(law.name, str):
        raise ConfigError("law.name", "a non-empty string", law.name)
    known = LAWS.get(law.name)
    if known is not None and known is not law:
        raise ConfigError("law.name", f"a name not already registered ({tuple(LAWS)})", law.name,
                          "choose another name")
    LAWS[law.name] = law
    return law


def get_law(name: str) -> AncillaryLaw:
    """Look up a law by name; raises :class:`ConfigError` for an unknown name."""
    try:
        return LAWS[name]
    except KeyError:
        raise ConfigError("law", f"one of {tuple(LAWS)}", name) from None
