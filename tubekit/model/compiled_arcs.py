"""The period's arc numerics as compiled routines (numba): the exact unicycle arc, a plan's rollout and arcs,
the arc's Jacobian, the bearing error's first-order model and the error coordinates.

Each routine performs the floating-point operations of its numpy reference in the same order (no fast-math,
no reassociation, libm's sin and cos as numpy's float64 ufuncs call them), so its results are bit for bit
those of the reference (``tests/test_model_compiled_arcs.py``, ``tests/test_benchmark_compiled_period.py``):

==========================  =====================================================================================
routine                     numpy reference
==========================  =====================================================================================
:func:`rollout`             :func:`tubekit.model.kinematics.unicycle_step` chained step by step (and the vectorised
                            rollout it replaced, ``numpy_rollout`` of ``benchmarks/compiled_period.py``)
:func:`unicycle_steps`      :func:`tubekit.model.kinematics.unicycle_step` on (N, 4), (N, 3), a scalar dt
:func:`plan_arcs`           the arcs of ``unicycle_step`` chained (``tubekit.loop.plan_check._plan_arcs_chained``)
:func:`arc`                 ``unicycle_step`` at every elapsed time
:func:`step_linearisation`  ``numpy_step_linearisation`` of ``benchmarks/compiled_period.py`` (the code it replaced;
                            its columns are dt S(a) (cos, sin)(ψ + a) and the derivatives of the model's ``sinc``)
:func:`eo_linearisation`    ``numpy_eo_linearisation`` of the same benchmark (its e_o row is ``error_coordinates``')
:func:`error_coordinates`   :func:`tubekit.model.errors.error_coordinates` on (K, 4), (K, 3)
==========================  =====================================================================================

Importing this module imports numba; the callers import it when they first run (``tubekit certify`` loads no
numba). The machine code is cached (:func:`tubekit.model.jit.routine`), so a machine compiles each routine once.
"""

from __future__ import annotations

import math

import numpy as np

from tubekit.model.jit import routine
from tubekit.model.kinematics import SINC_SERIES_THRESHOLD

__all__ = ["rollout", "unicycle_steps", "plan_arcs", "arc", "step_linearisation", "eo_linearisation",
           "error_coordinates"]


_SERIES_LIMIT = SINC_SERIES_THRESHOLD ** 2


@routine
def _sinc(a: float) -> float:
    """sin(a)/a with S(0) = 1 (as :func:`tubekit.model.kinematics.sinc`: sin(1e-300)/1e-300 is 1.0)."""
    if a == 0.0:
        return 1.0
    return math.sin(a) / a


@routine
def _dsinc(a: float) -> float:
    """S'(a) as :func:`tubekit.model.kinematics.dsinc` (the Taylor series below the threshold)."""
    a2 = a * a
    if a2 < _SERIES_LIMIT:
        return a * (-1.0 / 3.0 + a2 * (1.0 / 30.0 + a2 * (-1.0 / 840.0 + a2 * (1.0 / 45360.0
                    + a2 * (-1.0 / 3991680.0)))))
    return (a * math.cos(a) - math.sin(a)) / (a * a)


@routine
def _exact_step(x: float, y: float, z: float, psi: float, u: float, w: float, r: float,
                dt: float) -> tuple[float, float, float, float]:
    """The exact arc's end after ``dt`` (s) from (x, y, z, ψ) under (u, w, r) held
    (:func:`tubekit.model.kinematics.unicycle_step`'s operations: a = (dt/2) r, x + dt u S(a) cos(ψ + a), ...)."""
    a = (0.5 * dt) * r
    th = psi + a
    step = (dt * u) * _sinc(a)
    return x + step * math.cos(th), y + step * math.sin(th), z + dt * w, psi + dt * r


@routine
def rollout(s0: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """States (N+1, 4) of the exact steps of ``inputs`` (N, 3) from ``s0`` (4,), ``dt`` (s) each."""
    out = np.empty((inputs.shape[0] + 1, 4))
    x, y, z, psi = s0[0], s0[1], s0[2], s0[3]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = x, y, z, psi
    for k in range(inputs.shape[0]):
        x, y, z, psi = _exact_step(x, y, z, psi, inputs[k, 0], inputs[k, 1], inputs[k, 2], dt)
        out[k + 1, 0], out[k + 1, 1], out[k + 1, 2], out[k + 1, 3] = x, y, z, psi
    return out


@routine
def unicycle_steps(states: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """The exact step (N, 4) of every row of ``states`` (N, 4) under the same row of ``inputs`` (N, 3)."""
    out = np.empty((inputs.shape[0], 4))
    for k in range(inputs.shape[0]):
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = _exact_step(states[k, 0], states[k, 1], states[k, 2],
                                                                 states[k, 3], inputs[k, 0], inputs[k, 1],
                                                                 inputs[k, 2], dt)
    return out


@routine
def _arc_into(x: float, y: float, z: float, psi: float, u: float, w: float, r: float, tau: np.ndarray,
              out: np.ndarray) -> None:
    """The exact arc from (x, y, z, ψ) under (u, w, r) at the elapsed times ``tau``, written into ``out``."""
    for j in range(tau.shape[0]):
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = _exact_step(x, y, z, psi, u, w, r, tau[j])


@routine
def arc(x0: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """States (len(tau), 4) of the exact arc from ``x0`` (4,) under ``v`` (3,) at the times ``tau`` (s)."""
    out = np.empty((tau.shape[0], 4))
    _arc_into(x0[0], x0[1], x0[2], x0[3], v[0], v[1], v[2], tau, out)
    return out


@routine
def plan_arcs(x0: np.ndarray, inputs: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """States (N, len(tau), 4) along the arcs of ``inputs`` (N, 3) from ``x0``; each arc lasts ``tau[-1]``.

    An arc starts where the previous one's exact step over ``tau[-1]`` ends (as chaining the arcs does).
    """
    out = np.empty((inputs.shape[0], tau.shape[0], 4))
    span = tau[tau.shape[0] - 1]
    x, y, z, psi = x0[0], x0[1], x0[2], x0[3]
    for k in range(inputs.shape[0]):
        u, w, r = inputs[k, 0], inputs[k, 1], inputs[k, 2]
        _arc_into(x, y, z, psi, u, w, r, tau, out[k])
        x, y, z, psi = _exact_step(x, y, z, psi, u, w, r, span)
    return out


@routine
def step_linearisation(states: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """Rows ``ax, bxu, bxr, cx, ay, byu, byr, cy`` (8, N) of the exact step's Jacobian at a plan."""
    n = inputs.shape[0]
    out = np.empty((8, n))
    half_dt = 0.5 * dt
    for k in range(n):
        psi, u, r = states[k, 3], inputs[k, 0], inputs[k, 2]
        a = half_dt * r
        sa = _sinc(a)
        dsa = _dsinc(a)
        th = psi + a
        c, s = math.cos(th), math.sin(th)
        bxu = dt * sa * c
        byu = dt * sa * s
        dx = u * bxu
        dy = u * byu
        half = half_dt * dt * u
        bxr = half * (dsa * c - sa * s)
        byr = half * (dsa * s + sa * c)
        out[0, k], out[1, k], out[2, k], out[3, k] = -dy, bxu, bxr, dy * psi - bxr * r
        out[4, k], out[5, k], out[6, k], out[7, k] = dx, byu, byr, -dx * psi - byr * r
    return out


@routine
def eo_linearisation(states: np.ndarray, ref: np.ndarray, floor: float) -> np.ndarray:
    """Rows ``gx, gy, gpsi, h, e_o`` (5, K) of the bearing error's first-order model, e_d floored at ``floor``."""
    k_all = states.shape[0]
    out = np.empty((5, k_all))
    for k in range(k_all):
        ex = states[k, 0] - ref[k, 0]
        ey = states[k, 1] - ref[k, 1]
        psi = states[k, 3]
        ed = math.sqrt(ex * ex + ey * ey)
        if ed < floor:
            ed = floor
        cp, sp = math.cos(psi), math.sin(psi)
        c = ex * cp + ey * sp
        eo = (ex * sp - ey * cp) / ed
        cd = c / (ed * ed * ed)
        gx, gy, gpsi = ey * cd, -ex * cd, c / ed
        out[0, k], out[1, k], out[2, k], out[4, k] = gx, gy, gpsi, eo
        out[3, k] = eo - gx * states[k, 0] - gy * states[k, 1] - gpsi * psi
    return out


@routine
def error_coordinates(states: np.ndarray, ref: np.ndarray, floor: float) -> np.ndarray:
    """[e_d, e_z, e_o] (K, 3) of ``states`` (K, 4) w.r.t. ``ref`` (K, 3), e_d = sqrt(max(e_x² + e_y², floor²))."""
    k_all = states.shape[0]
    out = np.empty((k_all, 3))
    floor2 = floor * floor
    for k in range(k_all):
        ex = states[k, 0] - ref[k, 0]
        ey = states[k, 1] - ref[k, 1]
        psi = states[k, 3]
        q = ex * ex + ey * ey
        if q < floor2:
            q = floor2
        ed = math.sqrt(q)
        out[k, 0] = ed
        out[k, 1] = states[k, 2] - ref[k, 2]
        out[k, 2] = (ex * math.sin(psi) - ey * math.cos(psi)) / ed
    return out
