"""The record of a closed-loop run (:func:`tubekit.loop.closed_loop.simulate`) and its CSV form."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tubekit.model.errors import error_coordinates
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

__all__ = [
    "SimulationResult",
    "CSV_COLUMNS",
    "DYNAMIC_COLUMNS",
]

#: Column order of ``trajectory.csv`` (see :meth:`SimulationResult.columns`).
CSV_COLUMNS: tuple[str, ...] = (
    "t", "step", "x", "y", "z", "psi", "u", "w", "r", "x_d", "y_d", "z_d",
    "e_d", "e_z", "e_o", "x_hat", "y_hat", "z_hat", "psi_hat", "rho_d", "rho_z", "rho_o", "rho_norm",
    "u_hat", "w_hat", "r_hat", "kappa_u", "kappa_w", "kappa_r", "omega_1", "omega_2", "omega_3",
    "saturated", "fallback", "replaced", "n_detected", "solve_ms", "step_ms", "plan_violation", "wall_s",
)

#: Columns appended to ``trajectory.csv`` by a dynamic-plant run (absent for the kinematic plant):
#: body velocities reached (m/s, m/s, m/s, rad/s) and thrusts (N, N, N m) at the start of each tick.
DYNAMIC_COLUMNS: tuple[str, ...] = ("u_b", "v_b", "w_b", "r_b", "X", "Z", "N")


@dataclass
class SimulationResult:
    """A closed-loop run: per-tick log, per-step solver data, counts, timings and checks.

    Per-tick arrays have K + 1 rows (K = steps * ticks per step; the last row is
    the final state at t = duration with NaN inputs). Units: m, rad, s, m/s, rad/s.
    ``body`` (u_b, v_b, w_b, r_b) and ``thrust`` (X, Z, N) are set by the dynamic plant only.
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
    rejected: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    plan_age: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    plan_slack: np.ndarray = field(default_factory=lambda: np.zeros(0))
    omega_overridden: bool = False
    body: np.ndarray | None = None
    thrust: np.ndarray | None = None

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
    def velocity_error(self) -> np.ndarray | None:
        """Velocity-loop error (u_b - u, w_b - w, r_b - r) per tick (K+1, 3); None on the kinematic plant."""
        if self.body is None:
            return None
        return self.body[:, [0, 2, 3]] - self.inputs

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
        names = CSV_COLUMNS
        if self.body is not None and self.thrust is not None:
            for i, n in enumerate(DYNAMIC_COLUMNS):
                c[n] = self.body[:, i] if i < 4 else self.thrust[:, i - 4]
            names = CSV_COLUMNS + DYNAMIC_COLUMNS
        return {k: np.asarray(c[k]) for k in names}

    def write_csv(self, path: str | Path) -> Path:
        """Write :meth:`columns` as CSV (header row, ``nan`` for missing values)."""
        path = Path(path)
        cols = self.columns()
        data = np.column_stack([np.asarray(v, dtype=float) for v in cols.values()])
        np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.12g")
        return path

    def to_csv(self, path: str | Path) -> Path:
        """Write the log as CSV (the columns of ``trajectory.csv``); alias of :meth:`write_csv`."""
        return self.write_csv(path)

    @property
    def metrics(self) -> dict:
        """The run's metrics (:func:`tubekit.loop.metrics.compute_metrics`; units in ``docs/reproduce.md``)."""
        from tubekit.loop.metrics import compute_metrics
        certified = bool(self.tightening.certified)
        return compute_metrics(self.columns(), self.scenario,
                               rho_bound=self.tightening.rho_tilde if certified else None,
                               sway_bound=float(self.tightening.disturbance[2]) if certified else None,
                               extra={"tube": self.tube, "law": self.law if self.tube else None, "sigma": self.sigma})

    def plot(self):
        """The top view of the run (a matplotlib Figure; plotting lives in :mod:`tubekit.app.plots`)."""
        from tubekit.app.plots import top_view  # the one delegation from the core to the app layer
        return top_view(self.scenario, [("tube" if self.tube else "baseline", self.columns())],
                        tightening=self.tightening if self.tube else None)

    def summary(self) -> str:
        """A few lines for the terminal."""
        ch = self.checks
        return (f"{'tube' if self.tube else 'baseline'}: {self.steps} steps, law={self.law}, sigma={self.sigma:.4g}, "
                f"saturated ticks={self.saturated_ticks}, fallback steps={self.fallback_steps}, "
                f"wall={self.wall_s:.2f} s, checks={'ok' if all(ch.values()) else ch}")
