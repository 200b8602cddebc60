"""The derived error dynamics in polar form, the symbolic input of :mod:`verify.lemma1.bounds`.

The dynamics are always the *derived* ones (:func:`tubekit.model.derivation.derive`).
They are rewritten in polar form (:func:`polar_model`) by substituting

    e_x = e_d cos(theta),  e_y = e_d sin(theta),  psi = theta + phi,
    sin(phi) = e_o,  cos(phi) = c = s sqrt(1 - e_o^2)   (s = -1 toward, +1 away),
    [xdot_d, ydot_d] = a n_theta + b t_theta,  [omega_1, omega_2] = alpha n_theta + beta t_theta,

with n_theta = (cos theta, sin theta), t_theta = (-sin theta, cos theta). sympy
then cancels theta, and derivatives w.r.t. e are taken at fixed theta and fixed
Cartesian velocities (dc/de_o = -e_o / c).

:func:`law_gain` gives the symbolic closed-loop gain (K(e), J(e) K(e)) of an
ancillary law in the same coordinates. Both are cached: deriving them takes
seconds of sympy time.
"""

from __future__ import annotations

import hashlib
import inspect
import sys
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from tubekit.model.ancillary import LAWS
from tubekit.model.derivation import derivation_hash, derive, symbols
from tubekit.exceptions import ConfigError, TubekitError

from verify.lemma1.forms import simplified, stored_polar

__all__ = [
    "PolarModel",
    "polar_model",
    "polar_hash",
    "law_gain",
    "E_D",
    "E_Z",
    "E_O",
    "THETA",
    "A_V",
    "B_V",
    "ALPHA",
    "BETA",
    "GAMMA",
    "H_XY",
    "P_Z",
    "U_M",
    "W_M",
    "R_M",
]

# polar-form symbols
E_D = sp.Symbol("e_d", positive=True)
E_Z = sp.Symbol("e_z", real=True)
E_O = sp.Symbol("e_o", real=True)
_C = sp.Symbol("c", real=True)          # cos(psi - theta), eliminated before evaluation
THETA = sp.Symbol("theta", real=True)
A_V, B_V = sp.symbols("a b", real=True)              # target velocity along n_theta, t_theta
ALPHA, BETA = sp.symbols("alpha beta", real=True)    # disturbance along n_theta, t_theta
GAMMA = sp.Symbol("gamma", real=True)                # angle on the velocity disc
H_XY, P_Z = sp.symbols("h_xy p_z", nonnegative=True)  # velocity-set parameters
U_M, W_M, R_M = sp.symbols("u_max w_max r_max", positive=True)  # input-box parameters
_PHI = sp.Symbol("phi", real=True)


@dataclass(frozen=True)
class PolarModel:
    """The derived error dynamics in polar form for one hemisphere sign ``s``.

    All matrices are sympy expressions in ``e_d, e_z, e_o`` (c already replaced
    by s sqrt(1 - e_o^2)) and the named parameters.

    Attributes
    ----------
    s : int
        Hemisphere sign.
    J : Matrix (3, 3)
        Input matrix J(e).
    zeta : Matrix (3, 1)
        Drift in terms of a, b, zdot_d.
    xi : Matrix (3, 1)
        Disturbance term in terms of alpha, beta, omega_3.
    dh_de : Matrix (3, 3)
        d (J(e) v_hat) / d e in terms of u, w, r.
    dzeta_de : Matrix (3, 3)
        d zeta / d e at fixed bearing and Cartesian velocity.
    dzeta_dtheta : Matrix (3, 1)
        d zeta / d theta at fixed e and Cartesian velocity.
    dxi_domega : Matrix (3, 3)
        d xi / d (alpha, beta, omega_3); xi is linear in omega.
    zeta_rotation_form : bool
        zeta = zeta_0(e, zdot_d) + G(e) [a, b]^T with no other bearing dependence
        (verified symbolically), so zeta(e, theta) - zeta(e, theta_hat) =
        G (R_theta - R_theta_hat)^T p_d_dot_xy and its norm is at most
        sup||d zeta/d theta|| * 2 |sin((theta - theta_hat)/2)|.
    """

    s: int
    J: sp.Matrix
    zeta: sp.Matrix
    xi: sp.Matrix
    dh_de: sp.Matrix
    dzeta_de: sp.Matrix
    dzeta_dtheta: sp.Matrix
    dxi_domega: sp.Matrix
    zeta_rotation_form: bool = False


def _c_expr(s: int) -> sp.Expr:
    """cos(psi - theta) = s sqrt(1 - e_o^2) in hemisphere ``s``."""
    return s * sp.sqrt(1 - E_O**2)


def _polar_position() -> dict[sp.Symbol, sp.Expr]:
    """e_x, e_y, psi in terms of e_d, theta and phi = psi - theta."""
    sy = symbols()
    return {sy["e_x"]: E_D * sp.cos(THETA), sy["e_y"]: E_D * sp.sin(THETA), sy["psi"]: THETA + _PHI}


def _rotated(x: sp.Symbol, y: sp.Symbol, along: sp.Symbol, across: sp.Symbol) -> dict[sp.Symbol, sp.Expr]:
    """Cartesian (x, y) = along n_theta + across t_theta."""
    return {x: along * sp.cos(THETA) - across * sp.sin(THETA), y: along * sp.sin(THETA) + across * sp.cos(THETA)}


def _to_polar(M: sp.Matrix, extra: dict) -> sp.Matrix:
    """Substitute the polar coordinates and the rotated velocities; simplify with c kept symbolic."""
    out = M.subs(_polar_position()).subs(extra)
    out = out.applyfunc(lambda x: sp.expand_trig(sp.expand(x)))
    out = out.subs({sp.sin(_PHI): E_O, sp.cos(_PHI): _C})
    out = out.applyfunc(lambda x: sp.simplify(sp.trigsimp(x)))
    if _PHI in out.free_symbols:
        raise TubekitError("polar_model: psi - theta did not reduce to (e_o, c)")
    return out


def _d_de(M: sp.Matrix) -> sp.Matrix:
    """d M / d [e_d, e_z, e_o] at fixed theta with c = c(e_o), dc/de_o = -e_o / c."""
    cols = [M.diff(E_D), M.diff(E_Z), M.diff(E_O) + M.diff(_C) * (-E_O / _C)]
    return sp.Matrix.hstack(*cols)


def _finish(M: sp.Matrix, s: int) -> sp.Matrix:
    """Eliminate c in hemisphere ``s`` and simplify."""
    return M.subs(_C, _c_expr(s)).applyfunc(sp.simplify)


def _is_rotation_form(zeta: sp.Matrix, dzeta_dtheta: sp.Matrix) -> bool:
    """True if zeta = zeta_0(e, zdot_d) + G(e) [a, b]^T (see :attr:`PolarModel.zeta_rotation_form`)."""
    G = zeta.jacobian([A_V, B_V])
    return (THETA not in zeta.free_symbols and THETA not in G.free_symbols
            and A_V not in G.free_symbols and B_V not in G.free_symbols
            and (dzeta_dtheta - G * sp.Matrix([B_V, -A_V])).applyfunc(sp.simplify) == sp.zeros(3, 1))


@lru_cache(maxsize=1)
def polar_hash() -> str:
    """sha-256 of :func:`tubekit.model.derivation.derivation_hash` and this module's source (no sympy work):
    the key under which :mod:`verify.lemma1.forms` ships the derived polar model."""
    return hashlib.sha256((derivation_hash() + inspect.getsource(sys.modules[__name__])).encode()).hexdigest()


@lru_cache(maxsize=4)
def polar_model(s: int) -> PolarModel:
    """The polar-form model for hemisphere sign ``s`` (-1 toward, +1 away); cached.

    Read from the shipped forms (:mod:`verify.lemma1.forms`) when they were generated from this
    derivation and this module, else derived (seconds of sympy time).
    """
    if s not in (-1, 1):
        raise ConfigError("hemisphere sign", "-1 or +1", s)
    stored = stored_polar(s, polar_hash())
    if stored is not None:
        return PolarModel(s=s, **stored)
    d = derive()
    sy = symbols()
    vel = _rotated(sy["xdot_d"], sy["ydot_d"], A_V, B_V)
    om = _rotated(sy["omega_1"], sy["omega_2"], ALPHA, BETA)
    J = _to_polar(d.J, {})
    zeta = _to_polar(d.zeta, vel)
    xi = _to_polar(d.xi, om)
    # d zeta / d theta at fixed Cartesian velocity: differentiate before rotating the velocity.
    dth = _to_polar(d.zeta.subs(_polar_position()).diff(THETA), vel)
    u, w, r = sy["u"], sy["w"], sy["r"]
    dh = _d_de(J * sp.Matrix([u, w, r]))
    dz = _d_de(zeta)
    om_vec = [ALPHA, BETA, sy["omega_3"]]
    dxi = xi.jacobian(om_vec)
    if (xi - dxi * sp.Matrix(om_vec)).applyfunc(sp.simplify) != sp.zeros(3, 1):
        raise TubekitError("polar_model: xi is not linear in omega; the ball formula does not apply")
    return PolarModel(s=s, J=_finish(J, s), zeta=_finish(zeta, s), xi=_finish(xi, s), dh_de=_finish(dh, s),
                      dzeta_de=_finish(dz, s), dzeta_dtheta=_finish(dth, s), dxi_domega=_finish(dxi, s),
                      zeta_rotation_form=bool(_is_rotation_form(zeta, dth)))


@lru_cache(maxsize=8)
def law_gain(law: str, s: int) -> tuple[sp.Matrix, sp.Matrix]:
    """Symbolic (K(e), J(e) K(e)) of an ancillary law in hemisphere ``s``.

    The symbolic gain is the law's ``symbolic_gain`` in :data:`tubekit.model.ancillary.LAWS`
    (K = I for ``paper``, K = J^-1 for ``corrected``, or a registered user law); the
    tests cross-check it against the numeric gain.
    """
    if law not in LAWS:
        raise ConfigError("law", f"one of {tuple(LAWS)}", law)
    gain = LAWS[law].symbolic_gain
    if gain is None:
        raise ConfigError("law", "a law with a symbolic gain (AncillaryLaw.symbolic_gain)", law,
                          "a law without one can be simulated and falsified, not certified")
    J = polar_model(s).J
    K = sp.Matrix(gain(J))
    if K.shape != (3, 3):
        raise ConfigError("law.symbolic_gain", "a map returning a 3x3 sympy Matrix", K.shape)
    JK = simplified("jk", J * K, lambda M: M.applyfunc(sp.simplify))
    return K, JK
