"""The dynamic plant: a 4-DOF (surge, sway, heave, yaw) vehicle with thrusters and a velocity loop.

Fossen (2011), body velocities ν = (u, v, w, r) relative to the water (m/s, rad/s):

    M ν̇ + C(ν) ν + D(ν) ν = τ = (X, Y, Z, N),     Y = 0 without lateral thrust,

* M = M_RB + M_A (rigid body + added mass, :class:`tubekit.model.vehicles.VehicleParams`);
* C(ν) = C_RB + C_A, skew-symmetric, with the added-mass (Munk) terms:
  C(ν)ν = (−(m22 v + m24 r) r, m11 u r, 0, (m22 v + m24 r) u − m11 u v);
* D(ν)ν: linear + quadratic cross-flow drag and body/fin lift (Prestero 2001);
* neutral buoyancy (W = B, no restoring force in heave); no roll or pitch.

Kinematics: ṗ_xy = R(ψ)(u, v) + δ_xy(t), ż = w + δ_z(t), ψ̇ = r, with the
scenario's current δ (:class:`tubekit.plant.kinematic.Plant`); the current's acceleration
is neglected in the relative-velocity dynamics (documented in ``docs/plant.md``).

Thrust: τ̇ = (sat(τ_cmd) − τ) / T_thr (first-order actuators on every channel,
saturation at the limits of the vehicle at its current surge speed,
:meth:`~tubekit.model.vehicle_params.VehicleParams.thrust_limits_at`: constant for
thrusters, ∝ u² for REMUS' stern planes and rudder). The low-level velocity loop turns
the kinematic command v = v̂ + κ = (u_c, w_c, r_c) into τ_cmd: model feedforward
n̂(ν) = Ĉ(ν)ν + D̂(ν)ν of the NOMINAL vehicle (the midpoints of the coefficient box;
feedback linearisation, the sway row eliminated from the yaw row) plus PI on
e = (u_c − u, w_c − w, r_c − r) with k_p = ω_b, k_i = ω_b²/4 and conditional
integration while saturated. A vehicle with lateral thrust (``Y_max`` > 0,
:attr:`~tubekit.model.vehicle_params.VehicleParams.lateral`; M diagonal in sway and yaw) tracks a commanded sway
velocity v_c (``step_tuple(..., sway=v_c)``, 0 by default) by a fourth loop of the same form:
Y_cmd = n̂_2(ν) + m̂_22 (k_p e_v + k_i ∫e_v), e_v = v_c − v, its thrust lagging like the others; without it
Y = 0, v_c must be 0 and the hull's sway is free. The vehicle itself moves
with the TRUTH (a point of the box, ``[plant.truth]``). Positions, ν, τ and the integrators are integrated together by
classical RK4 at the closed loop's fixed step; without a current override as one compiled routine
(:mod:`tubekit.plant.compiled_dynamic`, the very floats of :func:`~tubekit.plant.kinematic.rk4_tuple` on ``_rhs``).
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.plant.base import OmegaOverride
from tubekit.plant.kinematic import Plant, rk4_tuple
from tubekit.scenario import Scenario
from tubekit.model.vehicles import VehicleParams

#: Indices of u, w, r in ν = (u, v, w, r): the commanded channels.
_SURGE_HEAVE_YAW = (0, 2, 3)

__all__ = ["DynamicPlant", "body_forces", "body_acceleration", "kinetic_energy"]

Floats4 = tuple[float, float, float, float]


def body_forces(p: VehicleParams, nu: Sequence[float]) -> Floats4:
    """n(ν) = C(ν)ν + D(ν)ν (N, N, N, N m) at body velocities ``nu`` = (u, v, w, r)."""
    u, v, w, r = nu
    m11, m22, _, _, m24, _ = p.mass_entries
    sway_momentum = m22 * v + m24 * r
    d1 = -(p.X_u + p.X_uu * abs(u)) * u
    d2 = -(p.Y_v + p.Y_vv * abs(v)) * v - p.Y_rr * r * abs(r) - p.Y_uv * u * v - p.Y_ur_lift * u * r
    d3 = -(p.Z_w + p.Z_ww * abs(w)) * w - p.Z_uw * u * w
    d4 = -(p.N_r + p.N_rr * abs(r)) * r - p.N_vv * v * abs(v) - p.N_uv_lift * u * v - p.N_ur_lift * u * r
    return (-sway_momentum * r + d1, m11 * u * r + d2, d3, sway_momentum * u - m11 * u * v + d4)


def body_acceleration(p: VehicleParams, nu: Sequence[float], tau: Sequence[float], sway: float = 0.0) -> Floats4:
    """ν̇ = M⁻¹(τ − n(ν)) for thrust ``tau`` = (X, Z, N) (N, N, N m) and the lateral force ``sway`` = Y (N; 0 without
    lateral thrust); returns (u̇, v̇, ẇ, ṙ)."""
    m11, m22, m33, m44, m24, m42 = p.mass_entries
    n1, n2, n3, n4 = body_forces(p, nu)
    b2, b4 = sway - n2, tau[2] - n4
    det = m22 * m44 - m24 * m42
    return ((tau[0] - n1) / m11, (m44 * b2 - m24 * b4) / det, (tau[1] - n3) / m33, (m22 * b4 - m42 * b2) / det)


def kinetic_energy(p: VehicleParams, nu: Sequence[float]) -> float:
    """½ νᵀ M ν (J)."""
    u, v, w, r = nu
    m11, m22, m33, m44, m24, m42 = p.mass_entries
    return 0.5 * (m11 * u * u + m22 * v * v + m33 * w * w + m44 * r * r + (m24 + m42) * v * r)


class DynamicPlant:
    """The 4-DOF vehicle, its thrusters and its velocity loop, driven by the kinematic command v.

    Same interface as :class:`tubekit.plant.kinematic.Plant` for the closed loop
    (:meth:`step_tuple` on the pose [x, y, z, ψ]); the body velocities, thrusts
    and integrators are internal state, initialised on the first step to the
    trimmed start ν = (u_c, 0, w_c, r_c), τ = sat(n̂(ν)) (the vehicle already
    moving at the first command, as the kinematic plant assumes); with lateral thrust the sway force Y and its
    integrator follow them in the state (Y starts trimmed too, at sat(n̂_2(ν))). Under ``[plant] start =
    "settled"`` the loop starts instead at its equilibrium at ``limits.initial`` = (u_0, 0, 0):
    ν = (u_0, 0, 0, 0), τ = n(ν) of the truth and the surge integrator holding the model's mismatch
    (:meth:`settled_state`); the first command is then a jump from u_0. Each call of
    :meth:`step_tuple` (one tick) logs ν and τ at its start (:meth:`history`). The water current it
    applies is reported apart from the total ω = current + hull sway + loop error (:meth:`omega_series`,
    :meth:`omega_peak`): :meth:`current_series` at the ticks and :meth:`current_peak` over every stage.

    Parameters
    ----------
    scenario : Scenario
        Supplies the current (``disturbance``) and the vehicle (``plant``).
    override : callable, optional
        ``override(t) -> current`` (3,) m/s replacing the scenario's current.
    params : VehicleParams, optional
        The vehicle as simulated, a point (default ``scenario.plant.truth_params``).

    Attributes
    ----------
    params : VehicleParams
        The plant as simulated (a point of the coefficient box).
    model : VehicleParams
        The controller's model: ``scenario.plant.params.nominal`` (feedforward and PI gains).
    """

    def __init__(self, scenario: Scenario, override: OmegaOverride | None = None,
                 params: VehicleParams | None = None) -> None:
        if params is not None and not params.is_point:
            raise ValueError(f"DynamicPlant(params=...) needs a point vehicle; {list(params.interval_fields)} "
                             "are intervals: pass .nominal or .sample(rng)")
        self.params = params if params is not None else scenario.plant.truth_params
        self.model = scenario.plant.params.nominal
        self.override = override
        self._current_model = Plant(scenario.disturbance)
        self._mass = self.model.mass_entries
        self._model_feedforward = self.model.loop_feedforward == "model"
        # per body velocity (u, v, w, r): the PI gains k_p = ω_c, k_i = ω_c²/4 of each channel's loop
        gains = self.model.loop_gains
        self._kp, self._ki = tuple(g[0] for g in gains), tuple(g[1] for g in gains)
        self._tau_inv = 1.0 / self.params.thruster_time_constant
        # thrusters' limits are constant: read once, not at every integrator stage (fins: per stage)
        self._limits = self.params.thrust_limits if self.params.actuation == "thrusters" else None
        # a sway loop where the vehicle has lateral thrust (the controller's model and the truth share Y_max > 0)
        self.lateral = self.model.lateral
        self._sway_limit = float(self.params.Y_max) if self.lateral else 0.0
        self.state: tuple[float, ...] | None = None  # (u, v, w, r, X, Z, N, I_u, I_w, I_r[, Y, I_v])
        self._settled_at = float(scenario.limits.start_command[0]) if scenario.plant.settled else None
        self._log: list[tuple[float, ...]] = []
        # largest ||omega_xy||, |omega_z|, then ||delta_xy||, |delta_z| of the current, over every evaluation (m/s)
        self._peak = [0.0, 0.0, 0.0, 0.0]
        self._compiled: tuple[np.ndarray, ...] | None = None  # the compiled RK4's arrays, packed at the first step

    # ---- the model ---------------------------------------------------------------------
    def current_at(self, t: float) -> tuple[float, float, float]:
        """The water's velocity δ(t) (m/s): the override or the scenario's current."""
        if self.override is not None:
            o = self.override(t)
            return float(o[0]), float(o[1]), float(o[2])
        return self._current_model.current_at(t)

    def feedforward(self, nu: Sequence[float]) -> Floats4:
        """The forces the loop feeds forward at body velocities ``nu`` (N, N, N, N m): the nominal n̂(ν) with
        ``loop_feedforward = "model"``, zeros with ``"none"`` (the integrators hold the drag)."""
        return body_forces(self.model, nu) if self._model_feedforward else (0.0, 0.0, 0.0, 0.0)

    def thrust_command(self, nu: Sequence[float], command: Sequence[float], integral: Sequence[float],
                       forces: Floats4 | None = None) -> tuple[tuple[float, float, float], tuple[bool, bool, bool]]:
        """τ_cmd (saturated at the truth's limits at surge ``nu[0]``) and which channels saturate.

        Feedforward n̂(ν) + M̂ (k_p e + k_i ∫e) of the nominal model (``forces``: n̂(ν) already evaluated).
        """
        m11, m22, m33, m44, m24, m42 = self._mass
        n1, n2, n3, n4 = forces if forces is not None else self.feedforward(nu)
        e = (command[0] - nu[0], command[1] - nu[2], command[2] - nu[3])
        a = [self._kp[c] * ei + self._ki[c] * ii for c, ei, ii in zip(_SURGE_HEAVE_YAW, e, integral)]
        raw = (n1 + m11 * a[0], n3 + m33 * a[1], n4 - m42 * n2 / m22 + (m44 - m42 * m24 / m22) * a[2])
        sat = tuple(min(max(c, -lim), lim) for c, lim in zip(raw, self._limits or self.params.thrust_limits_at(nu[0])))
        return sat, tuple(s != c for s, c in zip(sat, raw))

    def sway_command(self, nu: Sequence[float], integral: float, forces: Floats4 | None = None,
                     sway: float = 0.0) -> tuple[float, bool]:
        """Y_cmd = n̂_2(ν) + m̂_22 (k_p (v_c − v) + k_i ∫(v_c − v)) saturated at ±Y_max (N), and whether it
        saturates.

        Parameters
        ----------
        nu : sequence of 4 floats
            Body velocities (u, v, w, r) (m/s, m/s, m/s, rad/s).
        integral : float
            The sway integrator ∫(v_c − v) (m).
        forces : tuple of 4 floats, optional
            n̂(ν) already evaluated (N, N, N, N m).
        sway : float
            The commanded body sway velocity v_c (m/s).
        """
        n2 = (forces if forces is not None else self.feedforward(nu))[1]
        # −k_p (v − v_c): at v_c = 0 the very floats of −k_p v (signed zeros too)
        raw = n2 + self._mass[1] * (-self._kp[1] * (nu[1] - sway) + self._ki[1] * integral)
        sat = min(max(raw, -self._sway_limit), self._sway_limit)
        return sat, sat != raw

    def _rhs(self, t: float, y: Sequence[float], command: Sequence[float]) -> tuple[float, ...]:
        """d/dt of (x, y, z, ψ, u, v, w, r, X, Z, N, I_u, I_w, I_r[, Y, I_v]) under ``command`` = (u_c, w_c, r_c[, v_c])
        (m/s, m/s, rad/s[, m/s]; v_c = 0 when absent)."""
        psi, nu, tau, integral = y[3], y[4:8], y[8:11], y[11:14]
        vc = command[3] if len(command) > 3 else 0.0
        c1, c2, c3 = self.current_at(t)
        cp, sp = math.cos(psi), math.sin(psi)
        u, v, w, r = nu
        acc = body_acceleration(self.params, nu, tau, y[14] if self.lateral else 0.0)
        model_forces = self.feedforward(nu)
        cmd, saturated = self.thrust_command(nu, command, integral, model_forces)
        err = (command[0] - u, command[1] - w, command[2] - r)
        # conditional integration: hold the integral while its channel saturates in the error's direction
        integ = tuple(0.0 if s and c * e > 0.0 else e for s, c, e in zip(saturated, cmd, err))
        dv = v - vc  # the sway's error as ω sees it: exactly v at v_c = 0
        self._record(c1 - err[0] * cp - dv * sp, c2 - err[0] * sp + dv * cp, c3 - err[1], c1, c2, c3)
        out = (u * cp - v * sp + c1, u * sp + v * cp + c2, w + c3, r, *acc,
               *((ci - ti) * self._tau_inv for ci, ti in zip(cmd, tau)), *integ)
        if not self.lateral:
            return out
        y_cmd, y_sat = self.sway_command(nu, y[15], model_forces, vc)
        ev = -dv  # e_v = v_c − v, exactly −v at v_c = 0; held while Y saturates in the error's direction
        return (*out, (y_cmd - y[14]) * self._tau_inv, 0.0 if y_sat and y_cmd * ev > 0.0 else ev)

    def _record(self, o1: float, o2: float, o3: float, c1: float, c2: float, c3: float) -> None:
        """Keep the largest ‖ω_xy‖, |ω_z| of ω = ẋ − f(x) v and ‖δ_xy‖, |δ_z| of the current δ (m/s) seen by
        the integrator (one call per stage: the hot loop pays one call for both)."""
        peak = self._peak
        oxy, cxy = math.sqrt(o1 * o1 + o2 * o2), math.sqrt(c1 * c1 + c2 * c2)  # as the compiled RK4
        if oxy > peak[0]:
            peak[0] = oxy
        if abs(o3) > peak[1]:
            peak[1] = abs(o3)
        if cxy > peak[2]:
            peak[2] = cxy
        if abs(c3) > peak[3]:
            peak[3] = abs(c3)

    def omega_peak(self) -> tuple[float, float]:
        """Largest ‖ω_xy‖ and |ω_z| (m/s) over every evaluation the integrator made (every RK4 stage)."""
        return self._peak[0], self._peak[1]

    def current_peak(self) -> tuple[float, float]:
        """Largest ‖δ_xy‖ and |δ_z| (m/s) of the water current the plant applied (the override, if any), over
        every evaluation the integrator made (every RK4 stage): the part of ω the certificate assumes."""
        return self._peak[2], self._peak[3]

    def _start(self, command: Sequence[float]) -> tuple[float, ...]:
        nu = (float(command[0]), 0.0, float(command[1]), float(command[2]))
        tau, _ = self.thrust_command(nu, command, (0.0, 0.0, 0.0))
        if self.lateral:
            return (*nu, *tau, 0.0, 0.0, 0.0, self.sway_command(nu, 0.0)[0], 0.0)
        return (*nu, *tau, 0.0, 0.0, 0.0)

    def settled_state(self, surge: float) -> tuple[float, ...]:
        """The loop's equilibrium on a straight run at ``surge`` u_0 (m/s), the state's layout of :attr:`state`.

        ν = (u_0, 0, 0, 0) makes every body force but the truth's surge drag n_1(ν) vanish, so the thrust is
        τ = (n_1, 0, 0) (and Y = 0) and the surge integrator I_u = (n_1 − n̂_1)/(m̂_11 k_i) makes τ_cmd = τ with
        e = 0; every other integrator is 0.

        Raises
        ------
        ConfigError
            ``plant.start``: n_1 exceeds the truth's surge thrust at u_0 (no equilibrium there).
        """
        nu = (float(surge), 0.0, 0.0, 0.0)
        drag, nominal = body_forces(self.params, nu)[0], self.feedforward(nu)[0]
        limit = (self._limits or self.params.thrust_limits_at(nu[0]))[0]
        if abs(drag) > limit:
            raise ConfigError("plant.start", f"'trimmed': the vehicle cannot hold {surge:g} m/s (its drag "
                              f"{abs(drag):.4g} N exceeds its surge thrust {limit:.4g} N)", "settled")
        integral = (drag - nominal) / (self._mass[0] * self._ki[0])
        if self.lateral:
            return (*nu, drag, 0.0, 0.0, integral, 0.0, 0.0, 0.0, 0.0)
        return (*nu, drag, 0.0, 0.0, integral, 0.0, 0.0)

    # ---- the closed loop's interface ----------------------------------------------------
    def step_tuple(self, t: float, x: Sequence[float], v: Sequence[float], h: float, n: int,
                   sway: float = 0.0) -> Floats4:
        """Pose after ``n`` RK4 steps of ``h`` (s) from pose ``x`` at ``t`` (s), command ``v`` held.

        Parameters
        ----------
        t : float
            Time at the step's start (s).
        x : sequence of 4 floats
            Pose (x, y, z, ψ) (m, m, m, rad).
        v : sequence of 3 floats
            Kinematic command (u_c, w_c, r_c) (m/s, m/s, rad/s), held over the step.
        h : float
            RK4 step (s).
        n : int
            Number of RK4 steps.
        sway : float
            Commanded body sway velocity v_c (m/s), held over the step; nonzero only with lateral thrust.

        Returns
        -------
        tuple of 4 floats
            The pose after ``n`` steps (m, m, m, rad).

        Raises
        ------
        ConfigError
            ``sway`` is nonzero on a vehicle without lateral thrust.
        """
        if sway != 0.0 and not self.lateral:
            raise ConfigError("sway", "0 on a vehicle without lateral thrust (Y_max = 0)", sway)
        if self.state is None:
            self.state = self._start(v) if self._settled_at is None else self.settled_state(self._settled_at)
        self._log.append(self.state[:7])
        command = (v[0], v[1], v[2], float(sway))
        if self.override is not None:
            y = rk4_tuple(self._rhs, t, (*x, *self.state), command, h, n)
            self.state = y[4:]
            return y[0], y[1], y[2], y[3]
        return self._compiled_step(t, x, command, h, n)

    def _compiled_step(self, t: float, x: Sequence[float], command: Sequence[float], h: float, n: int) -> Floats4:
        """:func:`rk4_tuple` of :meth:`_rhs` (no override) in one compiled routine,
        :func:`tubekit.plant.compiled_dynamic.rk4_dynamic` (the same floats); ``command`` = (u_c, w_c, r_c, v_c)."""
        from tubekit.plant import compiled_dynamic

        truth, model, control, limits, current = self._packed()
        peak = np.array(self._peak)
        y = compiled_dynamic.rk4_dynamic(float(t), np.array((*x, *self.state), dtype=float),
                                         np.array(command, dtype=float), float(h), int(n), truth, model, control,
                                         limits, current, self.lateral, peak)
        self._peak[:] = peak.tolist()
        values = y.tolist()
        self.state = tuple(values[4:])
        return values[0], values[1], values[2], values[3]

    def _packed(self) -> tuple[np.ndarray, ...]:
        """The compiled routines' arrays, packed once: the truth's and the model's coefficients, (k_p per channel u,
        v, w, r, then k_i, then 1/T, then 1 where the model's forces are fed forward, else 0),
        the actuator limits and the current."""
        if self._compiled is None:
            from tubekit.plant import compiled_dynamic

            self._compiled = (compiled_dynamic.coefficients(self.params), compiled_dynamic.coefficients(self.model),
                              np.array([*self._kp, *self._ki, self._tau_inv, float(self._model_feedforward)]),
                              compiled_dynamic.actuator_limits(self.params, self._sway_limit),
                              np.array(self._current_model.current_parameters))
        return self._compiled

    def step(self, t: float, x: np.ndarray, v: np.ndarray, h: float, n: int, sway: float = 0.0) -> np.ndarray:
        """:meth:`step_tuple` on arrays (pose (4,), command (3,)); ``sway`` the commanded sway velocity v_c (m/s)."""
        return np.array(self.step_tuple(float(t), tuple(map(float, x)), tuple(map(float, v)), float(h), n,
                                        sway=float(sway)))

    def history(self) -> tuple[np.ndarray, np.ndarray]:
        """Body velocities (K + 1, 4) and thrusts (K + 1, 3) at the start of every tick, plus the final state."""
        rows = [*self._log, self.state[:7]] if self.state is not None else []
        data = np.asarray(rows, dtype=float).reshape(-1, 7)
        return data[:, :4], data[:, 4:7]

    def current_series(self, t: np.ndarray) -> np.ndarray:
        """The water current δ (m/s) the plant applied at the times ``t`` (s), shape (len(t), 3): the override or
        the scenario's current (computed after the run, nothing in the integrator; compiled without an override)."""
        if self.override is None:
            from tubekit.plant.compiled_dynamic import current_at_ticks

            return current_at_ticks(np.asarray(t, dtype=float).reshape(-1), self._packed()[4])
        return np.array([self.current_at(float(ti)) for ti in np.asarray(t, dtype=float)], dtype=float).reshape(-1, 3)

    def omega_series(self, t: np.ndarray, states: np.ndarray, inputs: np.ndarray,
                     sway: np.ndarray | None = None) -> np.ndarray:
        """ω = ẋ − f(x) v at every tick (K + 1, 3), m/s: δ + R(ψ)(u_b − u_c, v_b − v_c), δ_z + w_b − w_c.

        Parameters
        ----------
        t : array (K + 1,)
            Tick times (s).
        states : array (K + 1, 4)
            Poses at the ticks (m, m, m, rad).
        inputs : array (K + 1, 3)
            Commands (u_c, w_c, r_c) at the ticks (m/s, m/s, rad/s); NaN rows give NaN.
        sway : array (K + 1,), optional
            Commanded sway velocities v_c at the ticks (m/s); None: zeros.
        """
        body, _ = self.history()
        vc = np.zeros(len(t)) if sway is None else np.asarray(sway, dtype=float).reshape(-1)
        if vc.shape != (len(t),):
            raise ShapeError("sway", f"({len(t)},)", vc.shape)
        if self.override is None:
            from tubekit.plant.compiled_dynamic import omega_at_ticks

            return omega_at_ticks(np.asarray(t, dtype=float), np.asarray(states, dtype=float),
                                  np.asarray(inputs, dtype=float), body, self._packed()[4], np.ascontiguousarray(vc))
        out = np.full((len(t), 3), np.nan)
        for i, ti in enumerate(t):
            if i < len(body) and np.isfinite(inputs[i, 0]) and np.isfinite(inputs[i, 2]):
                c1, c2, c3 = self.current_at(float(ti))
                du, vb = body[i, 0] - inputs[i, 0], body[i, 1] - vc[i]
                cp, sp = math.cos(states[i, 3]), math.sin(states[i, 3])
                out[i] = (c1 + du * cp - vb * sp, c2 + du * sp + vb * cp, c3 + body[i, 2] - inputs[i, 1])
        return out
