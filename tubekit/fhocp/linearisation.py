"""First-order models of the FHOCP's nonlinear parts, the data of each SCP subproblem
(:class:`tubekit.fhocp.convex.ConvexSubproblem`): the exact step's Jacobian at a plan
(:func:`step_linearisation`) and the bearing error's (:func:`eo_linearisation`).

Both are exact to first order (value and first derivatives) at the plan they are taken at; the step itself
is :func:`tubekit.fhocp.nlp.discrete_step` (the model's exact zero-order-hold arc).
"""

from __future__ import annotations

import numpy as np

from tubekit.model.kinematics import dsinc, sinc

__all__ = ["STEP_LINEARISATION_ROWS", "step_linearisation", "eo_linearisation", "ED_FLOOR"]

#: Guards e_o = (...)/e_d against e_d = 0 (m) (the NLP's own floor, :mod:`tubekit.fhocp.nlp`).
ED_FLOOR = 1e-9


#: row order of :func:`step_linearisation`
STEP_LINEARISATION_ROWS: tuple[str, ...] = ("ax", "bxu", "bxr", "cx", "ay", "byu", "byr", "cy")


def step_linearisation(states: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """Jacobian entries of F at a plan; the only non-constant ones are in the x and y rows.

    The linearised step is::

        x_{k+1} = x_k + ax psi_k + bxu u_k + bxr r_k + cx
        y_{k+1} = y_k + ay psi_k + byu u_k + byr r_k + cy
        z_{k+1} = z_k + dt w_k,   psi_{k+1} = psi_k + dt r_k

    exact (value and first derivatives) at the plan.

    Parameters
    ----------
    states : array (N+1, 4) or (N, 4)
        Linearisation states (only the first N are used).
    inputs : array (N, 3)
        Linearisation inputs.
    dt : float
        Step (s).

    Returns
    -------
    array (8, N)
        Rows ``ax, bxu, bxr, cx, ay, byu, byr, cy`` (:data:`STEP_LINEARISATION_ROWS`).
    """
    n = inputs.shape[0]
    psi = states[:n, 3]
    u = inputs[:, 0]
    r = inputs[:, 2]
    a = 0.5 * dt * r
    sa = sinc(a)
    dsa = dsinc(a)
    th = psi + a
    c, s = np.cos(th), np.sin(th)
    out = np.empty((8, n))
    out[1] = dt * sa * c            # bxu
    out[5] = dt * sa * s            # byu
    dx = u * out[1]
    dy = u * out[5]
    out[0] = -dy                    # ax
    out[4] = dx                     # ay
    half = 0.5 * dt * dt * u
    out[2] = half * (dsa * c - sa * s)   # bxr
    out[6] = half * (dsa * s + sa * c)   # byr
    out[3] = dy * psi - out[2] * r    # cx = dx - ax psi - bxu u - bxr r  (bxu u = dx)
    out[7] = -dx * psi - out[6] * r   # cy = dy - ay psi - byu u - byr r  (byu u = dy)
    return out


def eo_linearisation(states: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """First-order model e_o ~ gx x + gy y + gpsi psi + h at ``states`` (K, 4), ``ref`` (K, 3).

    With c = e_x cos psi + e_y sin psi: de_o/dx = e_y c / e_d^3,
    de_o/dy = -e_x c / e_d^3, de_o/dpsi = c / e_d.

    Returns
    -------
    array (5, K)
        Rows ``gx, gy, gpsi, h, e_o``.
    """
    ex = states[:, 0] - ref[:, 0]
    ey = states[:, 1] - ref[:, 1]
    psi = states[:, 3]
    ed = np.maximum(np.sqrt(ex * ex + ey * ey), ED_FLOOR)
    cp_, sp_ = np.cos(psi), np.sin(psi)
    out = np.empty((5, states.shape[0]))
    c = ex * cp_ + ey * sp_
    out[4] = (ex * sp_ - ey * cp_) / ed
    cd = c / (ed * ed * ed)
    out[0] = ey * cd
    out[1] = -ex * cd
    out[2] = c / ed
    out[3] = out[4] - out[0] * states[:, 0] - out[1] * states[:, 1] - out[2] * psi
    return out
