"""The record of a closed-loop run (:func:`tubekit.loop.closed_loop.run_closed_loop`) and its CSV form."""

from __future__ import annotations

from dataclasses import dataclass, make_dataclass
from dataclasses import field as dc_field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tubekit.model.errors import error_coordinates
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

if TYPE_CHECKING:  # matplotlib's Figure, named through the plotting role (imported by plot() on use only)
    from tubekit.plotting.summary import Figure

__all__ = [
    "SimulationResult",
    "LogField",
    "LOG_FIELDS",
    "LogArrays",
    "allocate_log",
    "CSV_COLUMNS",
    "DYNAMIC_COLUMNS",
]


@dataclass(frozen=True)
class LogField:
    """One array of the closed-loop log: name, rows, width, dtype, initial fill, CSV columns, meaning.

    ``per`` is ``"tick"`` (K + 1 rows: every ancillary tick plus the final state) or
    ``"period"`` (one row per FHOCP sampling period); ``width`` 0 means one value per row.
    ``csv`` names its columns in ``trajectory.csv`` (empty: not written); a per-period
    field is written on the first tick of each period, NaN elsewhere.
    """

    name: str
    per: str
    width: int
    dtype: type
    fill: Any
    csv: tuple[str, ...]
    doc: str

    def allocate(self, ticks: int, periods: int) -> np.ndarray:
        """A new array for a run of ``ticks`` log rows (K + 1) and ``periods`` sampling periods."""
        rows = ticks if self.per == "tick" else periods
        return np.full((rows, self.width) if self.width else (rows,), self.fill, dtype=self.dtype)


#: The one list of the closed loop's logged arrays: the loop's buffer, :class:`SimulationResult`
#: (through :class:`LogArrays`) and the columns of ``trajectory.csv`` all derive from it.
LOG_FIELDS: tuple[LogField, ...] = (
    LogField("states", "tick", 4, float, np.nan, ("x", "y", "z", "psi"), "real state x, y, z (m), psi (rad)"),
    LogField("nominal", "tick", 4, float, np.nan, ("x_hat", "y_hat", "z_hat", "psi_hat"),
             "nominal state (left limit at each sample)"),
    LogField("v_hat", "tick", 3, float, np.nan, ("u_hat", "w_hat", "r_hat"), "nominal input held (m/s, m/s, rad/s)"),
    LogField("kappa", "tick", 3, float, np.nan, ("kappa_u", "kappa_w", "kappa_r"), "ancillary feedback kappa"),
    LogField("inputs", "tick", 3, float, np.nan, ("u", "w", "r"), "applied input v (after any clipping)"),
    LogField("saturated", "tick", 0, bool, False, ("saturated",), "v left V and was clipped"),
    LogField("fallback", "tick", 0, bool, False, ("fallback",), "the period's FHOCP result was a fallback"),
    LogField("replaced", "tick", 0, bool, False, ("replaced",), "the period's FHOCP input was replaced"),
    LogField("backup_active", "tick", 0, bool, False, ("backup_active",),
             "the backup law ran at this tick (the replayed plan was exhausted)"),
    LogField("recovery", "tick", 0, bool, False, ("recovery",),
             "a recovery plan is followed (accepted for safety alone, its error left R: tracking not in force)"),
    LogField("backup_anchor", "tick", 3, float, np.nan, ("anchor_x", "anchor_y", "anchor_z"),
             "the backup's anchor p* (m) while it runs, NaN otherwise"),
    LogField("sway_command", "tick", 0, float, 0.0, (),
             "the sway command v_c (m/s): a backup law with lateral thrust (tubekit.model.hold) only, else 0"),
    LogField("n_detected", "tick", 0, int, 0, ("n_detected",), "obstacles known to the map"),
    LogField("solve_ms", "tick", 0, float, np.nan, ("solve_ms",), "FHOCP solve time (ms), first tick of a period"),
    LogField("step_ms", "tick", 0, float, np.nan, ("step_ms",), "controller time per period (ms), first tick"),
    LogField("wall", "tick", 0, float, 0.0, ("wall_s",), "elapsed wall time of the run (s)"),
    LogField("iterations", "period", 0, float, 0.0, (), "solver iterations"),
    LogField("max_violation", "period", 0, float, np.nan, ("plan_violation",),
             "largest constraint violation of the returned plan"),
    LogField("rejected", "period", 0, bool, False, (), "the plan failed the arc check"),
    LogField("plan_age", "period", 0, int, 0, (), "periods since the plan in use was computed"),
    LogField("candidate", "period", 0, bool, False, (),
             "the shifted candidate (tubekit.loop.candidate) was accepted in place of the solver's plan"),
    LogField("plan_slack", "period", 0, float, np.nan, (), "smallest slack of the arc check"),
)

_BY_NAME = {f.name: f for f in LOG_FIELDS}


def allocate_log(ticks: int, periods: int) -> dict[str, np.ndarray]:
    """Fresh arrays of every :data:`LOG_FIELDS` entry for ``ticks`` log rows and ``periods`` periods."""
    return {f.name: f.allocate(ticks, periods) for f in LOG_FIELDS}


#: The logged arrays as dataclass fields (keyword-only; per-period ones default to empty), built from
#: :data:`LOG_FIELDS`; :class:`SimulationResult` (and the loop's buffer) derive from it.
LogArrays = make_dataclass(
    "LogArrays",
    [(f.name, np.ndarray, dc_field(default_factory=partial(f.allocate, 0, 0))) if f.per == "period"
     else (f.name, np.ndarray) for f in LOG_FIELDS],
    kw_only=True)
LogArrays.__module__ = __name__
LogArrays.__doc__ = "The closed loop's logged arrays:\n\n" + "\n".join(
    f"* ``{f.name}`` ({f.per}{f', {f.width} columns' if f.width else ''}): {f.doc}" for f in LOG_FIELDS)

#: Columns computed from the log (not stored in it), by the attribute of :class:`SimulationResult` they come from.
_DERIVED: dict[str, tuple[str, ...]] = {
    "t": ("t",), "step": ("step",), "desired": ("x_d", "y_d", "z_d"), "errors": ("e_d", "e_z", "e_o"),
    "rho": ("rho_d", "rho_z", "rho_o"), "rho_norm": ("rho_norm",), "omega": ("omega_1", "omega_2", "omega_3"),
}
#: Where each group of ``trajectory.csv`` columns comes from, in column order.
_CSV_ORDER: tuple[str, ...] = ("t", "step", "states", "inputs", "desired", "errors", "nominal", "rho", "rho_norm",
                               "v_hat", "kappa", "omega", "saturated", "fallback", "replaced", "backup_active",
                               "backup_anchor", "n_detected",
                               "solve_ms", "step_ms", "max_violation", "wall")
_CSV_SOURCES: tuple[tuple[str, tuple[str, ...]], ...] = tuple(
    (src, _DERIVED[src] if src in _DERIVED else _BY_NAME[src].csv) for src in _CSV_ORDER)

#: Column order of ``trajectory.csv`` (see :meth:`SimulationResult.columns`).
CSV_COLUMNS: tuple[str, ...] = tuple(name for _, names in _CSV_SOURCES for name in names)

#: Columns appended to ``trajectory.csv`` by a dynamic-plant run (absent for the kinematic plant):
#: body velocities reached (m/s, m/s, m/s, rad/s) and thrusts (N, N, N m) at the start of each tick, then
#: the water current the plant applied there (m/s, inertial x, y, z; NaN when not logged): the part of
#: ``omega_1..3`` the certificate assumes (the rest is the hull's sway and the loop error).
DYNAMIC_COLUMNS: tuple[str, ...] = ("u_b", "v_b", "w_b", "r_b", "X", "Z", "N", "current_1", "current_2", "current_3")


@dataclass
class SimulationResult(LogArrays):
    """A closed-loop run: per-tick log (:data:`LOG_FIELDS`), per-step solver data, counts, timings and checks.

    Per-tick arrays have K + 1 rows (K = steps * ticks per step; the last row is
    the final state at t = duration with NaN inputs). Units: m, rad, s, m/s, rad/s.
    ``body`` (u_b, v_b, w_b, r_b) and ``thrust`` (X, Z, N) are set by the dynamic plant only.
    ``omega_peak`` is the largest ‖ω_xy‖ and |ω_z| (m/s) over every evaluation of ω the plant's
    integrator made (every RK4 stage, between ticks included): the disturbance the plant received.
    ``current`` (K + 1, 3) and ``current_peak`` are the water current alone (m/s), at the ticks and
    over every evaluation, set by a plant whose ω holds more than the current (the dynamic plant:
    ω = current + hull sway + loop error); None on the kinematic plant, whose ω is what the certificate
    assumes.
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
    desired: np.ndarray
    omega: np.ndarray
    statuses: list[str] = dc_field(default_factory=list)
    kappa_failures: int = 0
    wall_s: float = 0.0
    omega_overridden: bool = False
    body: np.ndarray | None = None
    thrust: np.ndarray | None = None
    omega_peak: tuple[float, float] | None = None
    current: np.ndarray | None = None
    current_peak: tuple[float, float] | None = None

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
        return {
            "inputs_finite": bool(np.all(np.isfinite(applied))),
            "states_finite": bool(np.all(np.isfinite(self.states))),
            "inputs_within_limits": self.scenario.limits.contains(applied, tol=1e-12),
        }

    @property
    def facts(self) -> dict[str, Any]:
        """What the run was: tube or baseline, its law (None for the baseline), σ (1/s), κ failures, checks."""
        return {"tube": self.tube, "law": self.law if self.tube else None, "sigma": self.sigma,
                "kappa_failures": self.kappa_failures, "checks": self.checks}

    def _csv_source(self, source: str, derived: dict[str, np.ndarray]) -> np.ndarray:
        """The array behind one group of CSV columns (per-period fields on the first tick of each period)."""
        if source in derived:
            return derived[source]
        values = np.asarray(getattr(self, source))
        spec = _BY_NAME.get(source)
        if spec is not None and spec.per == "period":
            spread = np.full(len(self.t), np.nan)
            spread[0:-1:self.ticks_per_step] = values
            return spread
        return values.astype(int) if values.dtype == bool else values

    def columns(self) -> dict[str, np.ndarray]:
        """The log as named columns, in :data:`CSV_COLUMNS` order (then :data:`DYNAMIC_COLUMNS` if any)."""
        e = self.errors
        rho = e - self.nominal_errors
        derived = {"t": self.t, "step": self.step, "desired": self.desired, "errors": e, "rho": rho,
                   "rho_norm": np.linalg.norm(rho, axis=1), "omega": self.omega}
        c: dict[str, np.ndarray] = {}
        for source, names in _CSV_SOURCES:
            values = self._csv_source(source, derived)
            for i, name in enumerate(names):
                c[name] = np.asarray(values[:, i] if values.ndim == 2 else values)
        if self.body is not None and self.thrust is not None:
            current = np.full((len(self.t), 3), np.nan) if self.current is None else self.current
            dynamic = np.column_stack([self.body, self.thrust, current])
            c.update({name: dynamic[:, i] for i, name in enumerate(DYNAMIC_COLUMNS)})
        return c

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
    def metrics(self) -> dict[str, Any]:
        """The run's metrics, exactly as ``metrics.json`` holds them (:func:`tubekit.loop.metrics.run_metrics`)."""
        from tubekit.loop.metrics import run_metrics
        return run_metrics(self)

    def plot(self, kind: str = "summary") -> Figure:
        """The run's figure, the verdict (its tiers and their outcome on the run) in its title.

        Parameters
        ----------
        kind : str
            ``"summary"`` (default): the top view with the target's end marked, the errors, the inputs and, on
            the dynamic plant, the thrust against its limits; or one figure: ``"top_view"``, ``"errors"``,
            ``"inputs"``, ``"deviation"``, ``"clearance"``, ``"view_3d"``, ``"dynamic"``
            (:data:`tubekit.plotting.summary.KINDS`).

        Returns
        -------
        matplotlib.figure.Figure
            No pyplot state, nothing shown: ``run.plot().savefig("run.png")``.

        Raises
        ------
        ConfigError
            An unknown ``kind`` (or ``"dynamic"`` on the kinematic plant).
        """
        from tubekit.plotting.summary import plot_run  # matplotlib is loaded here, never by `import tubekit`
        return plot_run(self, kind)

    def summary(self) -> str:
        """A few lines for the terminal."""
        ch = self.checks
        return (f"{'tube' if self.tube else 'baseline'}: {self.steps} steps, law={self.law}, sigma={self.sigma:.4g}, "
                f"saturated ticks={self.saturated_ticks}, fallback steps={self.fallback_steps}, "
                f"wall={self.wall_s:.2f} s, checks={'ok' if all(ch.values()) else ch}")
