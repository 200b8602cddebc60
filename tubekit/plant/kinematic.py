"""The plant of eq. (11) as simulated: disturbance, sway, integrator and exact nominal arc.

The simulated vehicle is ẋ = f(x) v + [ω(t, x, v), 0] (eq. 11) with the total
inertial disturbance (m/s)

* ω = δ(t) + g(x, v_s), where
* δ(t) = amplitude · [sin a, cos a, sin a] + constant, a = 2π t / period
  (the current of :class:`tubekit.scenario.Disturbance`),
* v_s = gain · u · r + amplitude_s · sin(2π t / period_s), the sway of
  :class:`tubekit.model.kinematics.SwayModel` (no clip: its bound γ̄ = gain ū r̄ + amplitude_s
  over V is derived by the verifier, and every run checks the sway it applied), and
* g(x, v_s) = v_s · [−sin ψ, cos ψ, 0] (eq. 2).

Everything here is evaluated in one place, :class:`Plant`, whose inner loop is
scalar and allocation-free (plain float tuples, :mod:`math`): the closed loop
integrates it with classical RK4 at a fixed step (:meth:`Plant.step_tuple`; without an override, the same
operations compiled, :mod:`tubekit.plant.compiled_kinematic`).
:func:`nominal_arc` is the exact solution of the nominal kinematics (eq. 3)
under a constant input, used to propagate the nominal state between samples.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.plant.base import OmegaOverride, PiecewiseOmega
from tubekit.scenario import Disturbance, Scenario

__all__ = [
    "Plant",
    "nominal_arc",
    "plant_rhs",
    "rk4_hold",
    "rk4_tuple",
    "sway_velocity_term",
]

Floats3 = tuple[float, float, float]
Floats4 = tuple[float, float, float, float]


class Plant:
    """ẋ = f(x) v + [ω(t, x, v), 0] (eq. 11) with ω = current δ(t) + sway term g(x, v_s).

    Parameters
    ----------
    disturbance : Disturbance
        Current and sway model (m/s, s).
    override : callable, optional
        ``override(t) -> omega`` (3,) replacing current + sway (e.g. a
        :class:`verify.falsify.strategies.DisturbanceSignal` in property tests).

    Notes
    -----
    States are [x, y, z, psi] (m, rad), inputs [u, w, r] (m/s, m/s, rad/s).
    The public methods take and return arrays; :meth:`step_tuple` is the
    allocation-free form the closed loop uses.
    """

    def __init__(self, disturbance: Disturbance, override: OmegaOverride | None = None) -> None:
        self.disturbance = disturbance
        self.override = override
        self._amplitude = tuple(float(a) for a in disturbance.amplitude)
        self._constant = tuple(float(c) for c in disturbance.constant)
        self._current_rate = 2.0 * math.pi / disturbance.period
        sway = disturbance.sway
        self._sway_gain, self._sway_amplitude = float(sway.gain), float(sway.amplitude)
        self._sway_rate = 2.0 * math.pi / sway.period
        self._current_parameters = (*self._amplitude, *self._constant, self._current_rate)
        self._table: tuple[np.ndarray, float] | None = None  # the compiled routines' (table, period), packed once
        self._peak = [0.0, 0.0]  # largest ||omega_xy||, |omega_z| over every evaluation (m/s)

    @classmethod
    def of(cls, scenario: Scenario, override: OmegaOverride | None = None) -> Plant:
        """The plant of ``scenario`` (its :attr:`Scenario.disturbance`)."""
        return cls(scenario.disturbance, override)

    # ---- scalar core (the only place the formulas are written) ------------------------
    def _current(self, t: float) -> Floats3:
        """δ(t) (m/s) as floats."""
        a = self._current_rate * t
        sa, ca = math.sin(a), math.cos(a)
        amp, const = self._amplitude, self._constant
        return amp[0] * sa + const[0], amp[1] * ca + const[1], amp[2] * sa + const[2]

    def _sway(self, t: float, u: float, r: float) -> float:
        """v_s (m/s): side-slip plus wave sway (the model as it is; no clip)."""
        return self._sway_gain * u * r + self._sway_amplitude * math.sin(self._sway_rate * t)

    def _omega(self, t: float, psi: float, u: float, r: float) -> Floats3:
        """ω (m/s) as floats: override, or δ(t) + v_s [−sin ψ, cos ψ, 0]."""
        if self.override is not None:
            o = self.override(t)
            return float(o[0]), float(o[1]), float(o[2])
        d1, d2, d3 = self._current(t)
        vs = self._sway(t, u, r)
        return d1 - vs * math.sin(psi), d2 + vs * math.cos(psi), d3

    def _rhs(self, t: float, x: Sequence[float], v: Sequence[float]) -> Floats4:
        """ẋ (eq. 11) as floats."""
        u, w, r = v
        psi = x[3]
        o1, o2, o3 = self._omega(t, psi, u, r)
        peak = self._peak
        oxy = math.sqrt(o1 * o1 + o2 * o2)  # the compiled RK4 takes the same operations
        if oxy > peak[0]:
            peak[0] = oxy
        if abs(o3) > peak[1]:
            peak[1] = abs(o3)
        return (u * math.cos(psi) + o1, u * math.sin(psi) + o2, w + o3, r)

    # ---- public API ---------------------------------------------------------------------
    @property
    def current_parameters(self) -> tuple[float, float, float, float, float, float, float]:
        """(a_1, a_2, a_3, c_1, c_2, c_3, ω_c) of δ(t) = (a_1 sin ω_c t + c_1, a_2 cos ω_c t + c_2, a_3 sin ω_c t + c_3)
        (m/s, rad/s): the current as the compiled RK4s take it."""
        return self._current_parameters

    def sway_parameters(self, u: float, r: float) -> Floats3:
        """(g u r, A_s, ω_s) of v_s(t) = g u r + A_s sin ω_s t at the input's ``u`` (m/s) and ``r`` (rad/s): the sway as
        the compiled RK4 takes it (m/s, m/s, rad/s)."""
        return self._sway_gain * u * r, self._sway_amplitude, self._sway_rate

    def current_at(self, t: float) -> Floats3:
        """δ(t) (m/s) as three floats; ``t`` in s."""
        return self._current(t)

    def omega_series(self, t: np.ndarray, states: np.ndarray, inputs: np.ndarray,
                     sway: np.ndarray | None = None) -> np.ndarray:
        """ω (m/s) at every logged tick (len(t), 3); NaN where the input is NaN (without an override or under a
        :class:`~tubekit.plant.base.PiecewiseOmega`, compiled: :func:`tubekit.plant.compiled_kinematic.omega_at_ticks`,
        the same floats as :meth:`omega` tick by tick). ``sway`` is not read: the kinematic plant takes no sway
        command."""
        if self.override is None or isinstance(self.override, PiecewiseOmega):
            from tubekit.plant.compiled_kinematic import omega_at_ticks

            table, period = self._override_table()
            return omega_at_ticks(np.asarray(t, dtype=float), np.asarray(states, dtype=float),
                                  np.asarray(inputs, dtype=float), self.current_parameters,
                                  (self._sway_gain, self._sway_amplitude, self._sway_rate), table, period)
        out = np.full((len(t), 3), np.nan)
        for i, ti in enumerate(t):
            if np.isfinite(inputs[i, 0]) and np.isfinite(inputs[i, 2]):
                out[i] = self.omega(float(ti), states[i], inputs[i])
        return out

    def current(self, t: float | np.ndarray) -> np.ndarray:
        """Current δ(t) (m/s), shape ``np.shape(t) + (3,)``; ``t`` in s."""
        t = np.asarray(t, dtype=float)
        flat = [self._current(float(ti)) for ti in t.ravel()]
        return np.array(flat, dtype=float).reshape(t.shape + (3,))

    def sway_velocity(self, t: float, x: np.ndarray, v: np.ndarray) -> float:
        """The sway velocity v_s (m/s) applied at time ``t`` (s), state ``x`` and input ``v``.

        With v in V, ``|v_s| <= gain u_max r_max + amplitude`` (the bound the certificate uses).
        NaN when an ``override`` replaces the model (the sway is not separable then).
        """
        if self.override is not None:
            return math.nan
        return self._sway(float(t), float(v[0]), float(v[2]))

    def omega(self, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Total disturbance ω(t, x, v) (3,), m/s, inertial frame."""
        return np.array(self._omega(float(t), float(x[3]), float(v[0]), float(v[2])))

    def rhs(self, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """ẋ = f(x) v + [ω, 0] (4,) at time ``t`` (s)."""
        return np.array(self._rhs(float(t), tuple(map(float, x)), tuple(map(float, v))))

    def step(self, t: float, x: np.ndarray, v: np.ndarray, h: float, n: int, sway: float = 0.0) -> np.ndarray:
        """State (4,) after ``n`` classical RK4 steps of ``h`` (s) from ``x`` at ``t``, ``v`` held."""
        return np.array(self.step_tuple(float(t), tuple(map(float, x)), tuple(map(float, v)), float(h), n, sway))

    def step_tuple(self, t: float, x: Sequence[float], v: Sequence[float], h: float, n: int,
                   sway: float = 0.0) -> Floats4:
        """:meth:`step` on float tuples, without arrays (the closed loop's inner loop). The kinematic model (eq. 11)
        takes no sway command: ``sway`` other than 0 is a ConfigError.

        Without an override this is :meth:`_compiled_step`: :func:`rk4_tuple` of :meth:`_rhs` as one compiled
        routine, the same floating-point operations in the same order (bit-identical results).
        """
        if sway != 0.0:
            raise ConfigError("sway", "0 on the kinematic plant (eq. 11 has no sway command)", sway)
        if self.override is None or isinstance(self.override, PiecewiseOmega):
            return self._compiled_step(t, tuple(x), v, h, n)
        return rk4_tuple(self._rhs, t, tuple(x), v, h, n)

    def _compiled_step(self, t: float, y: tuple, v: Sequence[float], h: float, n: int) -> Floats4:
        """``n`` RK4 steps of :meth:`_rhs` (no override) in one compiled routine,
        :func:`tubekit.plant.compiled_kinematic.rk4_current` (the same floats as :func:`rk4_tuple` of :meth:`_rhs`)."""
        from tubekit.plant.compiled_kinematic import rk4_current

        u, w, r = v
        table, period = self._override_table()
        state, peak = rk4_current(t, y, (u, w, r), h, n, self.current_parameters, self.sway_parameters(u, r),
                                  (self._peak[0], self._peak[1]), table, period)
        self._peak[0], self._peak[1] = peak
        return state

    def _override_table(self) -> tuple[np.ndarray, float]:
        """The compiled routines' (table, period), packed once: a :class:`~tubekit.plant.base.PiecewiseOmega`
        override's rows (K, 3) and period (s), or no rows (the scenario's current and sway) without an override."""
        if self._table is None:
            from tubekit.plant.compiled_kinematic import NO_TABLE

            self._table = ((NO_TABLE, 1.0) if self.override is None else
                           (np.array(self.override.table, dtype=float).reshape(-1, 3), float(self.override.period)))
        return self._table

    def omega_peak(self) -> tuple[float, float]:
        """Largest ‖ω_xy‖ and |ω_z| (m/s) over every evaluation the integrator made (every RK4 stage)."""
        return self._peak[0], self._peak[1]

    def history(self) -> tuple[None, None]:
        """No body velocities or thrusts: the kinematic plant has no hull."""
        return None, None

    def current_series(self, t: np.ndarray) -> None:
        """None: ω (current + the sway model, or the override) is what the certificate assumes, not split."""
        return None

    def current_peak(self) -> None:
        """None: the run's premise reads the total ω (:meth:`omega_peak`), not the current apart."""
        return None


def rk4_tuple(f: Callable, t: float, y: tuple, v: Sequence[float], h: float, n: int) -> tuple:
    """``n`` classical RK4 steps of ``h`` (s) of ``y' = f(t, y, v)`` on float tuples, ``v`` held (both plants)."""
    for _ in range(n):
        k1 = f(t, y, v)
        k2 = f(t + 0.5 * h, tuple(a + 0.5 * h * b for a, b in zip(y, k1)), v)
        k3 = f(t + 0.5 * h, tuple(a + 0.5 * h * b for a, b in zip(y, k2)), v)
        k4 = f(t + h, tuple(a + h * b for a, b in zip(y, k3)), v)
        y = tuple(a + h / 6.0 * (b + 2.0 * c + 2.0 * d + e) for a, b, c, d, e in zip(y, k1, k2, k3, k4))
        t += h
    return y


def sway_velocity_term(x: np.ndarray, v_sway: float) -> np.ndarray:
    """The inner disturbance g(x, v_s) = v_s [−sin ψ, cos ψ, 0] (3,), m/s (eq. 2)."""
    psi = float(x[3])
    return float(v_sway) * np.array([-math.sin(psi), math.cos(psi), 0.0])


def plant_rhs(scenario: Scenario, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """ẋ = f(x) v + ω (eq. 11) with ω = δ(t) + g(x, v_s) of ``scenario`` (array (4,))."""
    return Plant.of(scenario).rhs(t, x, v)


def rk4_hold(plant: Plant | Scenario, t0: float, x0: np.ndarray, v: np.ndarray,
             duration: float, substeps: int) -> np.ndarray:
    """Integrate the plant over ``duration`` (s) with input ``v`` held, RK4 with ``substeps`` steps."""
    p = plant if isinstance(plant, Plant) else Plant.of(plant)
    return p.step(t0, x0, v, duration / substeps, substeps)


def nominal_arc(x0: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Exact solution of the nominal kinematics (eq. 3) under a constant input.

    Parameters
    ----------
    x0 : array (4,)
        State [x, y, z, psi] at tau = 0 (m, rad).
    v : array (3,)
        Constant input [u, w, r] (m/s, m/s, rad/s).
    tau : array (n,)
        Elapsed times (s).

    Returns
    -------
    array (n, 4)
        States at ``tau``.
    """
    from tubekit.model import compiled_arcs

    return compiled_arcs.arc(np.asarray(x0, dtype=float), np.asarray(v, dtype=float),
                             np.asarray(tau, dtype=float).reshape(-1))

