"""The error geometry in numbers (numpy only): e = [e_d, e_z, e_o], the bearing, c = cos(ψ − θ),
and the derived J, ζ, ξ, ė as vectorised callables.

The callables come from :mod:`tubekit.model._generated_dynamics`, printed once from the sympy
derivation (:mod:`tubekit.model.derivation`), so importing this module loads no sympy.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from tubekit.model import _generated_dynamics as gen

__all__ = ["error_coordinates", "bearing", "heading_cosine", "numeric", "NumericDynamics"]


def bearing(e_x: np.ndarray, e_y: np.ndarray) -> np.ndarray:
    """Bearing theta = atan2(e_y, e_x) (rad) of the vehicle as seen from the target."""
    return np.arctan2(e_y, e_x)


def error_coordinates(state: np.ndarray, p_d: np.ndarray, floor: float = 0.0) -> np.ndarray:
    """Error e = [e_d, e_z, e_o] (eqs. 12-14) of ``state`` (..., 4) w.r.t. ``p_d`` (..., 3).

    The one implementation (the FHOCP, the ancillary law, the loop's log and the checks
    all call it). ``e_d = sqrt(max(e_x^2 + e_y^2, floor^2))`` (m); with ``floor`` = 0 (default)
    e_o is NaN where e_d = 0; the FHOCP passes a tiny floor to keep e_o finite there.
    """
    state = np.asarray(state, dtype=float)
    p_d = np.asarray(p_d, dtype=float)
    ex = state[..., 0] - p_d[..., 0]
    ey = state[..., 1] - p_d[..., 1]
    psi = state[..., 3]
    out = np.empty(ex.shape + (3,))
    np.sqrt(np.maximum(ex * ex + ey * ey, floor * floor), out=out[..., 0])
    np.subtract(state[..., 2], p_d[..., 2], out=out[..., 1])
    num = ex * np.sin(psi) - ey * np.cos(psi)
    if floor > 0.0:
        np.divide(num, out[..., 0], out=out[..., 2])
    else:
        with np.errstate(invalid="ignore", divide="ignore"):
            np.divide(num, out[..., 0], out=out[..., 2])
    return out


def heading_cosine(state: np.ndarray, p_d: np.ndarray) -> np.ndarray:
    """c = cos(psi - theta), theta = atan2(e_y, e_x): its sign is the heading hemisphere (< 0: toward)."""
    state = np.asarray(state, dtype=float)
    p_d = np.asarray(p_d, dtype=float)
    return np.cos(state[..., 3] - np.arctan2(state[..., 1] - p_d[..., 1], state[..., 0] - p_d[..., 0]))


def _vectorised(fn: Callable[..., list], shape: tuple[int, int]) -> Callable[..., np.ndarray]:
    """Wrap a generated function returning a flat list into one returning a broadcast array."""

    def call(*values: np.ndarray) -> np.ndarray:
        arrays = [np.asarray(v, dtype=float) for v in values]
        out = fn(*arrays)
        b = np.broadcast_shapes(*(a.shape for a in arrays))
        stacked = np.stack([np.broadcast_to(np.asarray(o, dtype=float), b) for o in out], axis=-1)
        if shape[1] == 1:
            return stacked.reshape(b + (shape[0],))
        return stacked.reshape(b + shape)

    return call


@dataclass(frozen=True)
class NumericDynamics:
    """Vectorised numeric versions of the derived J, zeta, xi and e_dot.

    Each callable takes arrays (broadcastable) in the order given; the trailing
    axes of the result are (3, 3) for ``J`` and (3,) for the vectors.

    * ``J(e_x, e_y, psi)``
    * ``zeta(e_x, e_y, psi, xdot_d, ydot_d, zdot_d)``
    * ``xi(e_x, e_y, psi, omega_1, omega_2, omega_3)``
    * ``e_dot(e_x, e_y, psi, u, w, r, omega_1, omega_2, omega_3, xdot_d, ydot_d, zdot_d)``
    """

    J: Callable[..., np.ndarray]
    zeta: Callable[..., np.ndarray]
    xi: Callable[..., np.ndarray]
    e_dot: Callable[..., np.ndarray]


@lru_cache(maxsize=1)
def numeric() -> NumericDynamics:
    """The numeric callables, from the generated module (no sympy work)."""
    return NumericDynamics(J=_vectorised(gen.J, (3, 3)), zeta=_vectorised(gen.zeta, (3, 1)),
                           xi=_vectorised(gen.xi, (3, 1)), e_dot=_vectorised(gen.e_dot, (3, 1)))
