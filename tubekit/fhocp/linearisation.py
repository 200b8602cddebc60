"""First-order models of the FHOCP's nonlinear parts, the data of each SCP subproblem
(:class:`tubekit.fhocp.convex.ConvexSubproblem`): the exact step's Jacobian at a plan
(:func:`step_linearisation`) and the bearing error's (:func:`eo_linearisation`).

Both are exact to first order (value and first derivatives) at the plan they are taken at; the step itself
is :func:`tubekit.fhocp.nlp.discrete_step` (the model's exact zero-order-hold arc). Both are computed by the
compiled routines of :mod:`tubekit.model.compiled_arcs` (numba, imported at the first call).
"""

from __future__ import annotations

import functools
from types import ModuleType

import numpy as np

__all__ = ["STEP_LINEARISATION_ROWS", "step_linearisation", "eo_linearisation", "ED_FLOOR", "compiled"]

#: Guards e_o = (...)/e_d against e_d = 0 (m) (the NLP's own floor, :mod:`tubekit.fhocp.nlp`).
ED_FLOOR = 1e-9


#: row order of :func:`step_linearisation`
STEP_LINEARISATION_ROWS: tuple[str, ...] = ("ax", "bxu", "bxr", "cx", "ay", "byu", "byr", "cy")


@functools.cache
def compiled() -> tuple[ModuleType, ModuleType]:
    """(:mod:`tubekit.model.compiled_arcs`, :mod:`tubekit.fhocp.compiled_rows`), imported at the first call and
    kept (numba is loaded by the first step, never by ``tubekit certify``; a kept module costs no import per call)."""
    from tubekit.fhocp import compiled_rows
    from tubekit.model import compiled_arcs

    return compiled_arcs, compiled_rows


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
    return compiled()[0].step_linearisation(np.asarray(states, dtype=float), np.asarray(inputs, dtype=float), float(dt))


def eo_linearisation(states: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """First-order model e_o ~ gx x + gy y + gpsi psi + h at ``states`` (K, 4), ``ref`` (K, 3).

    With c = e_x cos psi + e_y sin psi: de_o/dx = e_y c / e_d^3,
    de_o/dy = -e_x c / e_d^3, de_o/dpsi = c / e_d.

    Returns
    -------
    array (5, K)
        Rows ``gx, gy, gpsi, h, e_o``.
    """
    return compiled()[0].eo_linearisation(np.asarray(states, dtype=float), np.asarray(ref, dtype=float), ED_FLOOR)
