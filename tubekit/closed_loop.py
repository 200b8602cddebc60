"""The closed loop: plant + sensing + FHOCP + ancillary feedback (issue 5, items 1-3).

Timeline (dt = FHOCP period, h = 1 / ancillary_rate_hz, m = dt / h ticks):

* at every sampling instant t_k = k dt the position is sensed
  (:class:`tubekit.sensing.ObstacleMap`), the FHOCP is solved from the measured
  state (nominal reset, ê(t_k) = e(t_k), paper eq. diff_mpc) and its first input
  v̂ is held over [t_k, t_k + dt);
* the nominal state x̂ is propagated from x(t_k) with v̂ and the nominal
  kinematics (eq. 3), in closed form (exact unicycle arcs);
* at every tick t_i = i h the ancillary law gives κ(e, ê) (zero-order hold over
  [t_i, t_i + h)), the applied input is v = v̂ + κ; only when v leaves V is it
  clipped to V (saturation, counted per tick and per sampling period);
* the plant ẋ = f(x) v + ω(t, x, v) (eq. 11, ω = current δ(t) + sway term
  g(x, v_s)) is integrated with classical RK4 at a fixed step h / plant_substeps
  (5 ms by default: 100 Hz ticks, 2 substeps).

Fallbacks: a FHOCP result flagged ``fallback`` is used (its first input) and
counted; a result whose first input is not finite, or a :class:`SolverError`,
is replaced by the previous successful plan shifted by the steps elapsed (zero
input once that plan is exhausted) and counted as ``replaced``. A non-finite κ
(J singular) is replaced by zero and counted. Nothing non-finite reaches the
plant.

Logging: one row per tick plus a final row at t = duration (inputs NaN there).
The nominal x̂ logged at a sampling instant is the left limit x̂(t_k⁻), before the
reset, so ‖ρ‖ = ‖e - ê‖ shows the largest deviation of every interval; the κ
applied at that tick uses the reset nominal (ρ = 0).
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .ancillary import AncillaryLaw, get_law
from .derivation import error_coordinates
from .exceptions import ConfigError, SolverError
from .scenario import Scenario
from .sensing import ObstacleMap
from .tightening import Tightening

__all__ = [
    "SimulationResult",
    "simulate",
    "nominal_arc",
    "plant_rhs",
    "rk4_hold",
    "CSV_COLUMNS",
]

#: Column order of ``trajectory.csv`` (see :meth:`SimulationResult.columns`).
CSV_COLUMNS: tuple[str, ...] = (
    "t", "step", "x", "y", "z", "psi", "u", "w", "r", "x_d", "y_d", "z_d",
    "e_d", "e_z", "e_o", "x_hat", "y_hat", "z_hat", "psi_hat", "rho_d", "rho_z", "rho_o", "rho_norm",
    "u_hat", "w_hat", "r_hat", "kappa_u", "kappa_w", "kappa_r", "omega_1", "omega_2", "omega_3",
    "saturated", "fallback", "replaced", "n_detected", "solve_ms", "step_ms", "plan_violation", "wall_s",
)


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
    x0 = np.asarray(x0, dtype=float)
    u, w, r = (float(c) for c in v)
    tau = np.asarray(tau, dtype=float)
    psi0 = x0[3]
    psi = psi0 + r * tau
    if abs(r) * float(np.max(np.abs(tau), initial=0.0)) > 1e-9:
        with np.errstate(invalid="ignore", divide="ignore"):
            dx = u * (np.sin(psi) - np.sin(psi0)) / r
            dy = -u * (np.cos(psi) - np.cos(psi0)) / r
    else:  # straight line (second-order accurate in r tau, exact for r = 0)
        mid = psi0 + 0.5 * r * tau
        dx = u * tau * np.cos(mid)
        dy = u * tau * np.sin(mid)
    return np.stack([x0[0] + dx, x0[1] + dy, x0[2] + w * tau, psi], axis=-1)


class _Plant:
    """Scalar, allocation-free right-hand side of eq. (11) (fast inner loop)."""

    def __init__(self, scenario: Scenario, override: Callable[[float], Any] | None = None) -> None:
        self.override = override
        d = scenario.disturbance
        self.amp = tuple(float(a) for a in d.amplitude)
        self.const = tuple(float(c) for c in d.constant)
        self.omega_c = 2.0 * math.pi / d.period
        s = d.sway
        self.gain, self.s_amp, self.s_bound = float(s.gain), float(s.amplitude), float(s.bound)
        self.omega_s = 2.0 * math.pi / s.period

    def omega(self, t: float, psi: float, u: float, r: float) -> tuple[float, float, float]:
        if self.override is not None:
            o = self.override(t)
            return float(o[0]), float(o[1]), float(o[2])
        a = self.omega_c * t
        sa, ca = math.sin(a), math.cos(a)
        vs = self.gain * u * r + self.s_amp * math.sin(self.omega_s * t)
        vs = min(max(vs, -self.s_bound), self.s_bound)
        return (self.amp[0] * sa + self.const[0] - vs * math.sin(psi),
                self.amp[1] * ca + self.const[1] + vs * math.cos(psi),
                self.amp[2] * sa + self.const[2])

    def rhs(self, t: float, x: tuple, v: tuple) -> tuple[float, float, float, float]:
        u, w, r = v
        psi = x[3]
        o1, o2, o3 = self.omega(t, psi, u, r)
        return (u * math.cos(psi) + o1, u * math.sin(psi) + o2, w + o3, r)


def plant_rhs(scenario: Scenario, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """ẋ = f(x) v + ω (eq. 11) with ω = δ(t) + g(x, v_s) of ``scenario`` (array (4,))."""
    return np.array(_Plant(scenario).rhs(float(t), tuple(map(float, x)), tuple(map(float, v))))


def rk4_hold(plant: _Plant | Scenario, t0: float, x0: np.ndarray, v: np.ndarray,
             duration: float, substeps: int) -> np.ndarray:
    """Integrate the plant over ``duration`` (s) with input ``v`` held, RK4 with ``substeps`` steps."""
    p = plant if isinstance(plant, _Plant) else _Plant(plant)
    return np.array(_rk4(p, float(t0), tuple(map(float, x0)), tuple(map(float, v)), duration / substeps,
                         substeps))


def _rk4(p: _Plant, t: float, x: tuple, v: tuple, h: float, n: int) -> tuple:
    f = p.rhs
    for _ in range(n):
        k1 = f(t, x, v)
        k2 = f(t + 0.5 * h, tuple(xi + 0.5 * h * ki for xi, ki in zip(x, k1)), v)
        k3 = f(t + 0.5 * h, tuple(xi + 0.5 * h * ki for xi, ki in zip(x, k2)), v)
        k4 = f(t + h, tuple(xi + h * ki for xi, ki in zip(x, k3)), v)
        x = tuple(xi + h / 6.0 * (a + 2.0 * b + 2.0 * c + d) for xi, a, b, c, d in zip(x, k1, k2, k3, k4))
        t += h
    return x


@dataclass
class SimulationResult:
    """A closed-loop run: per-tick log, per-step solver data, counts, timings and checks.

    Per-tick arrays have K + 1 rows (K = steps * ticks per step; the last row is
    the final state at t = duration with NaN inputs). Units: m, rad, s, m/s, rad/s.
    """

    scenario: Scenario
    tube: bool
    law: str
    sigma: float
    tightening: Tightening
    plant_step_s: float
    ticks_per_step: int
    t: np.ndarray
    step: np.ndarray
    states: np.ndarray
    desired: np.ndarray
    nominal: np.ndarray
    v_hat: np.ndarray
    kappa: np.ndarray
    inputs: np.ndarray
    omega: np.ndarray
    saturated: np.ndarray
    fallback: np.ndarray
    replaced: np.ndarray
    n_detected: np.ndarray
    solve_ms: np.ndarray
    step_ms: np.ndarray
    wall: np.ndarray
    statuses: list[str] = field(default_factory=list)
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0))
    max_violation: np.ndarray = field(default_factory=lambda: np.zeros(0))
    kappa_failures: int = 0
    wall_s: float = 0.0

    # ---- derived -------------------------------------------------------------------
    @property
    def errors(self) -> np.ndarray:
        """e = [e_d, e_z, e_o] of the real state, (K+1, 3)."""
        return error_coordinates(self.states, self.desired)

    @property
    def nominal_errors(self) -> np.ndarray:
        """ê of the logged nominal, (K+1, 3)."""
        return error_coordinates(self.nominal, self.desired)

    @property
    def rho(self) -> np.ndarray:
        """ρ = e - ê, (K+1, 3)."""
        return self.errors - self.nominal_errors

    @property
    def steps(self) -> int:
        """Number of FHOCP sampling periods."""
        return int(round((len(self.t) - 1) / self.ticks_per_step))

    @property
    def saturated_ticks(self) -> int:
        """Ticks at which v̂ + κ left V and was clipped."""
        return int(np.sum(self.saturated))

    @property
    def saturated_steps(self) -> int:
        """Sampling periods containing at least one clipped tick."""
        return int(np.unique(self.step[self.saturated.astype(bool)]).size)

    @property
    def fallback_steps(self) -> int:
        """Sampling periods whose FHOCP result was a fallback (flagged or replaced)."""
        first = np.arange(0, len(self.t) - 1, self.ticks_per_step)
        return int(np.sum(self.fallback[first] | self.replaced[first]))

    @property
    def replaced_steps(self) -> int:
        """Sampling periods whose FHOCP input was not finite (or raised) and was replaced."""
        first = np.arange(0, len(self.t) - 1, self.ticks_per_step)
        return int(np.sum(self.replaced[first]))

    @property
    def checks(self) -> dict[str, bool]:
        """Self-checks of the run: finiteness and input admissibility of what reached the plant."""
        applied = self.inputs[:-1]
        lim = self.scenario.limits.vector
        return {
            "inputs_finite": bool(np.all(np.isfinite(applied))),
            "states_finite": bool(np.all(np.isfinite(self.states))),
            "inputs_within_limits": bool(np.all(np.abs(applied) <= lim + 1e-12)),
        }

    def columns(self) -> dict[str, np.ndarray]:
        """The log as named columns, in :data:`CSV_COLUMNS` order."""
        e, eh = self.errors, self.nominal_errors
        rho = e - eh
        c: dict[str, np.ndarray] = {"t": self.t, "step": self.step}
        for i, n in enumerate(("x", "y", "z", "psi")):
            c[n] = self.states[:, i]
        for i, n in enumerate(("u", "w", "r")):
            c[n] = self.inputs[:, i]
        for i, n in enumerate(("x_d", "y_d", "z_d")):
            c[n] = self.desired[:, i]
        for i, n in enumerate(("e_d", "e_z", "e_o")):
            c[n] = e[:, i]
        for i, n in enumerate(("x_hat", "y_hat", "z_hat", "psi_hat")):
            c[n] = self.nominal[:, i]
        for i, n in enumerate(("rho_d", "rho_z", "rho_o")):
            c[n] = rho[:, i]
        c["rho_norm"] = np.linalg.norm(rho, axis=1)
        for i, n in enumerate(("u_hat", "w_hat", "r_hat")):
            c[n] = self.v_hat[:, i]
        for i, n in enumerate(("kappa_u", "kappa_w", "kappa_r")):
            c[n] = self.kappa[:, i]
        for i, n in enumerate(("omega_1", "omega_2", "omega_3")):
            c[n] = self.omega[:, i]
        c["saturated"] = self.saturated.astype(int)
        c["fallback"] = self.fallback.astype(int)
        c["replaced"] = self.replaced.astype(int)
        c["n_detected"] = self.n_detected
        c["solve_ms"] = self.solve_ms
        c["step_ms"] = self.step_ms
        pv = np.full(len(self.t), np.nan)
        pv[0:-1:self.ticks_per_step] = self.max_violation
        c["plan_violation"] = pv
        c["wall_s"] = self.wall
        return {k: np.asarray(c[k]) for k in CSV_COLUMNS}

    def write_csv(self, path: str | Path) -> Path:
        """Write :meth:`columns` as CSV (header row, ``nan`` for missing values)."""
        path = Path(path)
        cols = self.columns()
        data = np.column_stack([np.asarray(v, dtype=float) for v in cols.values()])
        np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.12g")
        return path

    def summary(self) -> str:
        """A few lines for the terminal."""
        ch = self.checks
        return (f"{'tube' if self.tube else 'baseline'}: {self.steps} steps, law={self.law}, sigma={self.sigma:.4g}, "
                f"saturated ticks={self.saturated_ticks}, fallback steps={self.fallback_steps}, "
                f"wall={self.wall_s:.2f} s, checks={'ok' if all(ch.values()) else ch}")


def _default_factory(mode: str | None) -> Callable[[Scenario, Tightening], Any]:
    def build(scenario: Scenario, tightening: Tightening):
        from .fhocp import FHOCP  # imported lazily: the solver is optional for tests with fakes
        return FHOCP(scenario, tightening, mode=mode)
    return build


def _silence_fallback_warnings() -> None:
    try:
        from .fhocp import FallbackWarning
    except ImportError:  # pragma: no cover - a stand-in solver without the real module
        return
    warnings.simplefilter("ignore", FallbackWarning)


def _progress(total: int, enabled: bool, label: str):
    if not enabled or not sys.stderr.isatty():
        return None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return None
    return tqdm(total=total, desc=label, unit="step", leave=False, dynamic_ncols=True)


def simulate(scenario: Scenario, *, tightening: Tightening | None = None,
             law: str | AncillaryLaw | None = None, sigma: float | None = None, tube: bool = True,
             progress: bool = True, solver_factory: Callable[[Scenario, Tightening], Any] | None = None,
             mode: str | None = None, plant_substeps: int = 2, remember_obstacles: bool = True,
             label: str | None = None,
             disturbance: Callable[[float], Any] | None = None) -> SimulationResult:
    """Run the closed loop on ``scenario`` for ``scenario.duration`` seconds.

    Parameters
    ----------
    scenario : Scenario
        What to simulate.
    tightening : Tightening, optional
        Sets of the FHOCP. Required when ``tube``; the baseline defaults to
        :meth:`Tightening.untightened`.
    law : str or AncillaryLaw, optional
        Ancillary law; default ``scenario.controller.law``.
    sigma : float, optional
        Ancillary gain (1/s); default ``tightening.sigma``. Ignored (0) when not ``tube``.
    tube : bool
        ``False`` runs the baseline: nominal MPC alone, κ = 0.
    progress : bool
        Show a tqdm bar (only on a TTY).
    solver_factory : callable, optional
        ``factory(scenario, tightening)`` returning an object with
        ``solve(t, state, obstacles)``; default :class:`tubekit.fhocp.FHOCP`.
    mode : str, optional
        FHOCP mode for the default factory; default ``scenario.controller.fhocp_mode``.
    plant_substeps : int
        RK4 steps per ancillary tick (plant step = 1 / (rate * substeps) s).
    remember_obstacles : bool
        Keep obstacles in the map once detected (see :mod:`tubekit.sensing`).
    label : str, optional
        Progress-bar label.
    disturbance : callable, optional
        ``disturbance(t) -> omega`` (3,) replacing the scenario's current + sway
        (e.g. a :class:`verify.strategies.DisturbanceSignal` in property tests).

    Returns
    -------
    SimulationResult
    """
    wall0 = time.perf_counter()
    ctrl = scenario.controller
    if not isinstance(plant_substeps, int) or plant_substeps < 1:
        raise ConfigError("plant_substeps", "an integer >= 1", plant_substeps)
    if scenario.steps < 1:
        raise ConfigError("duration", f"at least one FHOCP period (dt = {ctrl.dt:g} s)", scenario.duration)
    if tightening is None:
        if tube:
            raise ConfigError("tightening", "a Tightening (e.g. verify.certify(...).tightening()) for the tube run",
                              None)
        tightening = Tightening.untightened(scenario)
    law_obj = law if isinstance(law, AncillaryLaw) else get_law(law if law is not None else ctrl.law)
    if tube:
        sig = float(tightening.sigma if sigma is None else sigma)
        if not math.isfinite(sig) or sig < 0:
            raise ConfigError("sigma", "a finite number >= 0", sig)
    else:
        sig = 0.0
    factory = solver_factory or _default_factory(mode)
    solver = factory(scenario, tightening)

    m = int(round(ctrl.ancillary_rate_hz * ctrl.dt))
    h = ctrl.dt / m
    steps = scenario.steps
    K = steps * m
    t_all = np.round(np.arange(K + 1) * h, 9)
    desired = np.asarray(scenario.trajectory.position(t_all), dtype=float)
    lim = scenario.limits.vector
    plant = _Plant(scenario, disturbance)
    omap = ObstacleMap(scenario.obstacles, scenario.sensing_range, remember=remember_obstacles)
    tau = np.arange(m + 1) * h
    zeros3 = np.zeros(3)

    states = np.empty((K + 1, 4))
    nominal = np.empty((K + 1, 4))
    v_hat_log = np.full((K + 1, 3), np.nan)
    kappa_log = np.full((K + 1, 3), np.nan)
    inputs = np.full((K + 1, 3), np.nan)
    saturated = np.zeros(K + 1, dtype=bool)
    fallback = np.zeros(K + 1, dtype=bool)
    replaced = np.zeros(K + 1, dtype=bool)
    n_detected = np.zeros(K + 1, dtype=int)
    solve_ms = np.full(K + 1, np.nan)
    step_ms = np.full(K + 1, np.nan)
    wall = np.zeros(K + 1)
    step_idx = np.minimum(np.arange(K + 1) // m, steps)
    statuses: list[str] = []
    iterations = np.zeros(steps)
    max_violation = np.full(steps, np.nan)
    kappa_failures = 0

    x = tuple(float(c) for c in scenario.initial_state)
    prev_plan: np.ndarray | None = None
    plan_age = 0
    bar = _progress(steps, progress, label or ("tube" if tube else "baseline"))
    nom_end = np.asarray(x)
    with warnings.catch_warnings():
        _silence_fallback_warnings()  # fallbacks are counted; one warning each would flood the terminal
        try:
            for k in range(steps):
                i0 = k * m
                tk = float(t_all[i0])
                xk = np.asarray(x)
                c0 = time.perf_counter()
                known = omap.update(xk[:3])
                res = None
                try:
                    res = solver.solve(tk, xk.copy(), known)
                    vh = np.asarray(res.first_input, dtype=float).reshape(3)
                    ok = bool(np.all(np.isfinite(vh)))
                except SolverError:
                    vh, ok = zeros3, False
                c1 = time.perf_counter()
                if ok:
                    is_fb, rep = bool(getattr(res, "fallback", False)), False
                    plan = np.asarray(getattr(res, "inputs", vh[None, :]), dtype=float)
                    if not is_fb and plan.ndim == 2 and np.all(np.isfinite(plan)):
                        prev_plan, plan_age = plan, 0
                    else:
                        plan_age += 1
                else:  # never pass NaN on: shift the last good plan, or stop
                    is_fb, rep = True, True
                    plan_age += 1
                    if prev_plan is not None and plan_age < len(prev_plan):
                        vh = prev_plan[plan_age].copy()
                    else:
                        vh = zeros3.copy()
                if res is not None:
                    statuses.append(str(getattr(res, "status", "")))
                    iterations[k] = float(getattr(res, "iterations", 0) or 0)
                    mv = getattr(res, "max_violation", None)
                    max_violation[k] = float(mv) if mv is not None else np.nan
                    solve_ms[i0] = 1e3 * float(getattr(res, "solve_time_s", c1 - c0))
                else:
                    statuses.append("exception")
                    solve_ms[i0] = 1e3 * (c1 - c0)
                nom = nominal_arc(xk, vh, tau)
                ctrl_s = time.perf_counter() - c0
                fallback[i0:i0 + m] = is_fb
                replaced[i0:i0 + m] = rep
                n_detected[i0:i0 + m] = omap.count
                nominal[i0] = nom_end if k > 0 else xk
                nominal[i0 + 1:i0 + m] = nom[1:m]
                v_hat_log[i0:i0 + m] = vh
                vh_t = tuple(float(c) for c in vh)
                for j in range(m):
                    i = i0 + j
                    xs = np.asarray(x)
                    states[i] = xs
                    if sig > 0.0:
                        a0 = time.perf_counter()
                        try:
                            kap = law_obj(xs, nom[j], desired[i], sig)
                        except (ConfigError, FloatingPointError, np.linalg.LinAlgError):
                            kap = zeros3
                            kappa_failures += 1
                        ctrl_s += time.perf_counter() - a0
                        kappa_log[i] = kap
                        v = (vh_t[0] + kap[0], vh_t[1] + kap[1], vh_t[2] + kap[2])
                    else:
                        kappa_log[i] = 0.0
                        v = vh_t
                    if abs(v[0]) > lim[0] or abs(v[1]) > lim[1] or abs(v[2]) > lim[2]:
                        v = (min(max(v[0], -lim[0]), lim[0]), min(max(v[1], -lim[1]), lim[1]),
                             min(max(v[2], -lim[2]), lim[2]))
                        saturated[i] = True
                    inputs[i] = v
                    x = _rk4(plant, float(t_all[i]), x, v, h / plant_substeps, plant_substeps)
                nom_end = nom[m]
                step_ms[i0] = 1e3 * ctrl_s
                wall[i0:i0 + m] = time.perf_counter() - wall0
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
    states[K] = np.asarray(x)
    nominal[K] = nom_end
    omega = _omega_log(plant, t_all, states, inputs)
    wall_s = time.perf_counter() - wall0
    wall[K] = wall_s
    return SimulationResult(
        scenario=scenario, tube=tube, law=law_obj.name if tube else "none", sigma=sig, tightening=tightening,
        plant_step_s=h / plant_substeps, ticks_per_step=m, t=t_all, step=step_idx, states=states,
        desired=desired, nominal=nominal, v_hat=v_hat_log, kappa=kappa_log, inputs=inputs, omega=omega,
        saturated=saturated, fallback=fallback, replaced=replaced, n_detected=n_detected, solve_ms=solve_ms,
        step_ms=step_ms, wall=wall, statuses=statuses, iterations=iterations, max_violation=max_violation,
        kappa_failures=kappa_failures, wall_s=wall_s)


def _omega_log(plant: _Plant, t: np.ndarray, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    """ω (m/s) at the start of every tick (NaN where the input is NaN)."""
    out = np.full((len(t), 3), np.nan)
    for i in range(len(t)):
        u, r = inputs[i, 0], inputs[i, 2]
        if np.isfinite(u) and np.isfinite(r):
            out[i] = plant.omega(float(t[i]), float(states[i, 3]), float(u), float(r))
    return out

