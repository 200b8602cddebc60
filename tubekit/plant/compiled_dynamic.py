"""The dynamic plant compiled (numba): its RK4 (hull, thrusters, velocity loop, current) as one routine, and the
current and ω at the logged ticks.

:func:`rk4_dynamic` integrates the state (x, y, z, ψ, u, v, w, r, X, Z, N, I_u, I_w, I_r[, Y, I_v]) of
:class:`tubekit.plant.dynamic.DynamicPlant` over ``n`` classical RK4 steps with the command held, under the
scenario's current. It performs the floating-point operations of :func:`tubekit.plant.kinematic.rk4_tuple`
applied to ``DynamicPlant._rhs`` (with :func:`~tubekit.plant.dynamic.body_forces`,
:func:`~tubekit.plant.dynamic.body_acceleration`, ``thrust_command`` and ``sway_command``) in the same order,
so the states and the four peaks it records are bit for bit the same (``tests/test_plant_compiled_dynamic.py``).
:func:`current_at_ticks` and :func:`omega_at_ticks` are ``DynamicPlant.current_series`` and ``omega_series``, the
same floats. A plant with a current override (a Python callable) keeps the Python path.

The vehicles enter as :func:`coefficients` arrays (the truth moves the hull, the nominal model drives the
loop's feedforward); importing this module imports numba, and the machine code is cached
(:func:`tubekit.model.jit.routine`).
"""

from __future__ import annotations

import math

import numpy as np

from tubekit.model.jit import routine
from tubekit.model.vehicle_params import VehicleParams
from tubekit.plant.compiled_kinematic import current_at

__all__ = ["COEFFICIENTS", "coefficients", "actuator_limits", "rk4_dynamic", "current_at_ticks", "omega_at_ticks"]

#: the hull's coefficients in the order :func:`coefficients` packs them, then the six mass entries
COEFFICIENTS: tuple[str, ...] = ("X_u", "X_uu", "Y_v", "Y_vv", "Y_rr", "Y_uv", "Y_ur_lift", "Z_w", "Z_ww", "Z_uw",
                                 "N_r", "N_rr", "N_vv", "N_uv_lift", "N_ur_lift")
_M11, _M22, _M33, _M44, _M24, _M42 = range(len(COEFFICIENTS), len(COEFFICIENTS) + 6)



def coefficients(params: VehicleParams) -> np.ndarray:
    """The point vehicle's :data:`COEFFICIENTS` and (m11, m22, m33, m44, m24, m42) as one float array (21,)."""
    return np.array([float(getattr(params, name)) for name in COEFFICIENTS] + list(params.mass_entries), dtype=float)


def actuator_limits(params: VehicleParams, sway_limit: float) -> np.ndarray:
    """(X_max, Z_max, N_max, fins, fin_max, |Z_uuds|, |N_uudr|, Y_max) (7 + 1,): the thrust limits of
    :meth:`~tubekit.model.vehicle_params.VehicleParams.thrust_limits_at` (fins = 1: ∝ u² at the stage's surge)
    and the lateral limit ``sway_limit`` (N)."""
    fins = params.actuation == "fins"
    return np.array([float(params.X_max), float(params.Z_max), float(params.N_max), 1.0 if fins else 0.0,
                     float(params.fin_max), abs(float(params.Z_uuds)), abs(float(params.N_uudr)), float(sway_limit)])


@routine
def _forces(p: np.ndarray, u: float, v: float, w: float, r: float) -> tuple[float, float, float, float]:
    """n(ν) = C(ν)ν + D(ν)ν of the vehicle ``p`` (:func:`tubekit.plant.dynamic.body_forces`)."""
    sway_momentum = p[_M22] * v + p[_M24] * r
    d1 = -(p[0] + p[1] * abs(u)) * u
    d2 = -(p[2] + p[3] * abs(v)) * v - p[4] * r * abs(r) - p[5] * u * v - p[6] * u * r
    d3 = -(p[7] + p[8] * abs(w)) * w - p[9] * u * w
    d4 = -(p[10] + p[11] * abs(r)) * r - p[12] * v * abs(v) - p[13] * u * v - p[14] * u * r
    return (-sway_momentum * r + d1, p[_M11] * u * r + d2, d3, sway_momentum * u - p[_M11] * u * v + d4)


@routine
def _saturate(c: float, lim: float) -> float:
    """min(max(c, −lim), lim) with Python's tie and NaN rules."""
    x = -lim if -lim > c else c
    return lim if lim < x else x


@routine
def _rhs(t: float, y: np.ndarray, command: np.ndarray, truth: np.ndarray, model: np.ndarray, control: np.ndarray,
         limits: np.ndarray, current: np.ndarray, lateral: bool, out: np.ndarray, peak: np.ndarray) -> None:
    """d/dt of ``y`` into ``out`` (``DynamicPlant._rhs``); ``control`` = (k_p of u, v, w, r, k_i of u, v, w, r,
    1/T_thr, 1 to feed the model's forces forward else 0), ``command`` = (u_c, w_c, r_c[, v_c]) (v_c = 0 when
    absent)."""
    tau_inv = control[8]
    vc = command[3] if command.shape[0] > 3 else 0.0
    c1, c2, c3 = current_at(current, t)
    psi, u, v, w, r = y[3], y[4], y[5], y[6], y[7]
    cp, sp = math.cos(psi), math.sin(psi)
    # the hull (truth): ν̇ = M⁻¹(τ − n(ν))
    n1, n2, n3, n4 = _forces(truth, u, v, w, r)
    b2, b4 = (y[14] if lateral else 0.0) - n2, y[10] - n4
    det = truth[_M22] * truth[_M44] - truth[_M24] * truth[_M42]
    out[4], out[5] = (y[8] - n1) / truth[_M11], (truth[_M44] * b2 - truth[_M24] * b4) / det
    out[6], out[7] = (y[9] - n3) / truth[_M33], (truth[_M22] * b4 - truth[_M42] * b2) / det
    # the loop (model): τ_cmd = n̂(ν) + M̂ (k_p e + k_i ∫e) (loop_feedforward "none": M̂ (k_p e + k_i ∫e)), saturated
    f1, f2, f3, f4 = _forces(model, u, v, w, r)
    if control[9] == 0.0:
        f1, f2, f3, f4 = 0.0, 0.0, 0.0, 0.0
    e0, e1, e2 = command[0] - u, command[1] - w, command[2] - r
    a0, a1, a2 = control[0] * e0 + control[4] * y[11], control[2] * e1 + control[6] * y[12], \
        control[3] * e2 + control[7] * y[13]
    raw0 = f1 + model[_M11] * a0
    raw1 = f3 + model[_M33] * a1
    raw2 = f4 - model[_M42] * f2 / model[_M22] + (model[_M44] - model[_M42] * model[_M24] / model[_M22]) * a2
    if limits[3] == 1.0:
        q = u * u * limits[4]
        lim1, lim2 = limits[5] * q, limits[6] * q
    else:
        lim1, lim2 = limits[1], limits[2]
    s0, s1, s2 = _saturate(raw0, limits[0]), _saturate(raw1, lim1), _saturate(raw2, lim2)
    dv = v - vc  # the sway's error as ω sees it: exactly v at v_c = 0
    o1, o2, o3 = c1 - e0 * cp - dv * sp, c2 - e0 * sp + dv * cp, c3 - e1
    _record(peak, o1, o2, o3, c1, c2, c3)
    out[0], out[1], out[2], out[3] = u * cp - v * sp + c1, u * sp + v * cp + c2, w + c3, r
    out[8], out[9], out[10] = (s0 - y[8]) * tau_inv, (s1 - y[9]) * tau_inv, (s2 - y[10]) * tau_inv
    # conditional integration: held while its channel saturates in the error's direction
    out[11] = 0.0 if s0 != raw0 and s0 * e0 > 0.0 else e0
    out[12] = 0.0 if s1 != raw1 and s1 * e1 > 0.0 else e1
    out[13] = 0.0 if s2 != raw2 and s2 * e2 > 0.0 else e2
    if lateral:
        # Y_cmd = n̂_2 + m̂_22 (k_p e_v + k_i ∫e_v), e_v = v_c − v = −dv (exactly −v at v_c = 0)
        raw = f2 + model[_M22] * (-control[1] * dv + control[5] * y[15])
        sat = _saturate(raw, limits[7])
        out[14] = (sat - y[14]) * tau_inv
        ev = -dv
        out[15] = 0.0 if sat != raw and sat * ev > 0.0 else ev


@routine
def _record(peak: np.ndarray, o1: float, o2: float, o3: float, c1: float, c2: float, c3: float) -> None:
    """The largest ‖ω_xy‖, |ω_z|, ‖δ_xy‖, |δ_z| so far (``DynamicPlant._record``)."""
    oxy, cxy = math.sqrt(o1 * o1 + o2 * o2), math.sqrt(c1 * c1 + c2 * c2)
    if oxy > peak[0]:
        peak[0] = oxy
    if abs(o3) > peak[1]:
        peak[1] = abs(o3)
    if cxy > peak[2]:
        peak[2] = cxy
    if abs(c3) > peak[3]:
        peak[3] = abs(c3)


@routine
def rk4_dynamic(t: float, y0: np.ndarray, command: np.ndarray, h: float, n: int, truth: np.ndarray,
                model: np.ndarray, control: np.ndarray, limits: np.ndarray, current: np.ndarray, lateral: bool,
                peak: np.ndarray) -> np.ndarray:
    """``n`` RK4 steps of ``h`` (s) from ``y0`` (14,) or, with ``lateral``, (16,) at ``t`` (s), ``command``
    (u_c, w_c, r_c[, v_c]) held; ``peak`` (4,) is updated in place.

    Parameters
    ----------
    command : array (3,) or (4,)
        (u_c (m/s), w_c (m/s), r_c (rad/s)[, v_c (m/s)]): the kinematic command and the commanded body sway
        velocity, tracked by the sway loop with ``lateral`` (0 when absent; without ``lateral`` it must be 0).
    truth, model : array (21,)
        :func:`coefficients` of the vehicle as simulated and of the controller's model.
    control : array (9,)
        (k_p (1/s) of u, v, w, r, k_i (1/s²) of u, v, w, r, 1 / T_thr (1/s)).
    limits : array (8,)
        :func:`actuator_limits` of the vehicle as simulated.
    current : array (7,)
        (a_1, a_2, a_3, c_1, c_2, c_3, ω_c) of δ(t) (:func:`tubekit.plant.compiled_kinematic.current_at`).
    """
    size = y0.shape[0]
    y, tmp = y0.copy(), np.empty(size)
    k1, k2, k3, k4 = np.empty(size), np.empty(size), np.empty(size), np.empty(size)
    for _ in range(n):
        _rhs(t, y, command, truth, model, control, limits, current, lateral, k1, peak)
        for i in range(size):
            tmp[i] = y[i] + 0.5 * h * k1[i]
        _rhs(t + 0.5 * h, tmp, command, truth, model, control, limits, current, lateral, k2, peak)
        for i in range(size):
            tmp[i] = y[i] + 0.5 * h * k2[i]
        _rhs(t + 0.5 * h, tmp, command, truth, model, control, limits, current, lateral, k3, peak)
        for i in range(size):
            tmp[i] = y[i] + h * k3[i]
        _rhs(t + h, tmp, command, truth, model, control, limits, current, lateral, k4, peak)
        for i in range(size):
            y[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        t += h
    return y


@routine
def current_at_ticks(t: np.ndarray, current: np.ndarray) -> np.ndarray:
    """The water current δ (m/s) at the times ``t`` (s), shape (len(t), 3)."""
    out = np.empty((t.shape[0], 3))
    for i in range(t.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = current_at(current, t[i])
    return out


@routine
def omega_at_ticks(t: np.ndarray, states: np.ndarray, inputs: np.ndarray, body: np.ndarray,
                   current: np.ndarray, sway: np.ndarray) -> np.ndarray:
    """ω = δ + R(ψ)(u_b − u_c, v_b − v_c), δ_z + w_b − w_c (m/s) at every tick (len(t), 3) from the logged body
    velocities ``body`` (K, 4) and sway commands ``sway`` (K + 1,); NaN where u_c or r_c is NaN or past the log."""
    out = np.full((t.shape[0], 3), np.nan)
    for i in range(min(t.shape[0], body.shape[0])):
        if not (math.isfinite(inputs[i, 0]) and math.isfinite(inputs[i, 2])):
            continue
        c1, c2, c3 = current_at(current, t[i])
        du, vb = body[i, 0] - inputs[i, 0], body[i, 1] - sway[i]
        cp, sp = math.cos(states[i, 3]), math.sin(states[i, 3])
        out[i, 0] = c1 + du * cp - vb * sp
        out[i, 1] = c2 + du * sp + vb * cp
        out[i, 2] = c3 + body[i, 2] - inputs[i, 1]
    return out
