"""Pre-run validation: everything a run needs is checked before any work or output (issue 16).

:func:`check_run_inputs` raises :class:`~tubekit.exceptions.ConfigError` naming
the field to fix, before certification, simulation or any file is written:

* geometry of the start: clear of every obstacle inflated by the vehicle
  radius r̄, inside the workspace box, and at e_d(0) >= ε (e_o is undefined at
  e_d = 0 and the certified region starts at ε);
* the target path: p_d(t) inside the workspace box over the run (:func:`check_target`);
* size: the per-tick log of a run (:func:`log_bytes`) fits
  :data:`MEMORY_BUDGET_BYTES`;
* horizon and limits: N <= :data:`MAX_HORIZON_STEPS`, and the farthest
  horizontal travel of one horizon, u_max N δt, leaves room between the walls
  of the workspace (the FHOCP keeps one wall row per axis). When that fails
  the error names the field whose paper value would make it fit
  (``controller.horizon_steps``, then ``limits.u_max``), else ``workspace``.

Rules used elsewhere too, written once here: :func:`require_one_period` (a run lasts at
least one FHOCP period), :func:`horizon_reach`, :func:`workspace_fits` and
:func:`workspace_rule` (one horizon's travel fits between the walls; the FHOCP checks
the same rule with its tightened speed and clearance). "duration > 0" is
:func:`tubekit.validation.duration_seconds`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tubekit.model.errors import error_coordinates
from tubekit.exceptions import ConfigError
from tubekit.scenario import ControllerSettings, Scenario, paper_scenario
from tubekit.validation import duration_seconds, period_count

__all__ = ["unit_hints", "check_run_inputs", "check_start", "check_target", "TARGET_SAMPLES", "check_log_size",
           "check_horizon_and_limits", "log_bytes", "require_one_period", "horizon_reach", "workspace_fits",
           "workspace_rule", "MEMORY_BUDGET_BYTES", "LOG_BYTES_PER_TICK", "RUNS_PER_STUDY", "MAX_HORIZON_STEPS"]

#: Memory a study may spend on its per-tick logs (bytes): 2 GiB.
MEMORY_BUDGET_BYTES = 2 * 1024 ** 3
#: Bytes per ancillary tick of one run: the loop's log (about 25 numbers), the result's
#: derived columns (40) and the copies made for metrics and CSV, rounded up.
LOG_BYTES_PER_TICK = 1024
#: Runs held in memory together by a study (tube and baseline).
RUNS_PER_STUDY = 2
#: Instants at which :func:`check_target` samples the target path.
TARGET_SAMPLES = 4001
#: Largest FHOCP horizon N accepted (the convex subproblem grows linearly in N; beyond this
#: one build takes minutes and the horizon dwarfs any workspace).
MAX_HORIZON_STEPS = 500


def _fmt_bytes(n: float) -> str:
    """``n`` bytes in the largest binary unit that keeps it >= 1."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover


def log_bytes(scenario: Scenario, duration: float | None = None) -> float:
    """Estimated bytes of the per-tick logs of one study (tube + baseline) of ``duration`` s.

    ``duration`` defaults to ``scenario.duration``; ticks = duration x ancillary rate + 1.
    """
    seconds = scenario.duration if duration is None else float(duration)
    ticks = seconds * scenario.controller.ancillary_rate_hz + 1
    return RUNS_PER_STUDY * LOG_BYTES_PER_TICK * ticks


def check_log_size(scenario: Scenario, duration: float | None = None) -> None:
    """Raise ``ConfigError('duration', ...)`` when the logs would exceed :data:`MEMORY_BUDGET_BYTES`."""
    need = log_bytes(scenario, duration)
    if need > MEMORY_BUDGET_BYTES:
        rate = scenario.controller.ancillary_rate_hz
        longest = (MEMORY_BUDGET_BYTES / (RUNS_PER_STUDY * LOG_BYTES_PER_TICK) - 1) / rate
        raise ConfigError("duration", f"at most {longest:.6g} s at {rate:g} Hz (the per-tick log must fit "
                          f"{_fmt_bytes(MEMORY_BUDGET_BYTES)})",
                          scenario.duration if duration is None else duration,
                          f"It would need about {_fmt_bytes(need)}")


def check_start(scenario: Scenario) -> None:
    """The start: clear of every inflated obstacle, inside the workspace, e_d(0) >= epsilon."""
    x0 = np.asarray(scenario.initial_state, dtype=float)
    position = x0[:3]
    for index, obstacle in enumerate(scenario.obstacles):
        gap = float(np.linalg.norm(position - np.asarray(obstacle.center))) - obstacle.radius
        if gap <= scenario.vehicle_radius:
            raise ConfigError("initial_state", f"a start clear of obstacles[{index}] inflated by vehicle_radius "
                              f"(distance to its surface > {scenario.vehicle_radius:g} m)",
                              [float(v) for v in x0], f"It is {gap:.4g} m from the surface")
    if scenario.workspace is not None:
        lower, upper = (np.asarray(side, dtype=float) for side in scenario.workspace)
        if np.any(position < lower) or np.any(position > upper):
            raise ConfigError("initial_state", f"a position inside the workspace {[lower.tolist(), upper.tolist()]} m",
                              [float(v) for v in x0])
    target = np.asarray(scenario.trajectory.position(np.array([0.0])), dtype=float).reshape(-1, 3)[0]
    e_d0 = float(error_coordinates(x0, target)[0])
    if not e_d0 >= scenario.epsilon:
        raise ConfigError("initial_state", f"a start at horizontal distance e_d(0) >= epsilon = "
                          f"{scenario.epsilon:g} m from the target p_d(0)", [float(v) for v in x0],
                          f"e_d(0) = {e_d0:.4g} m")


def check_target(scenario: Scenario) -> None:
    """The target path p_d(t), t in [0, duration], stays inside the workspace box.

    Checked on :data:`TARGET_SAMPLES` evenly spaced instants: a refusal is certain (a sampled
    target lies outside); an excursion shorter than one sample spacing may pass (verify's
    ``target_in_workspace`` condition bounds every instant).
    """
    if scenario.workspace is None:
        return
    t = np.linspace(0.0, scenario.duration, TARGET_SAMPLES)
    p = np.asarray(scenario.trajectory.position(t), dtype=float).reshape(-1, 3)
    lower, upper = (np.asarray(side, dtype=float) for side in scenario.workspace)
    out = np.maximum(lower - p, p - upper).max(axis=1)
    k = int(np.argmax(out))
    if not out[k] <= 0.0:
        raise ConfigError("trajectory", f"a target path p_d(t) inside the workspace {[lower.tolist(), upper.tolist()]}"
                          f" m for t in [0, duration = {scenario.duration:g} s]",
                          scenario.trajectory.kind, f"p_d({t[k]:.4g} s) = [{', '.join(f'{x:.4g}' for x in p[k])}] m "
                          f"is {out[k]:.4g} m outside it")


def require_one_period(field: str, duration: float, dt: float) -> None:
    """Raise ``ConfigError(field, ...)`` unless ``duration`` (s) holds at least one FHOCP period ``dt`` (s).

    The loop runs ``round(duration / dt)`` periods; a duration that rounds to none, or to more than
    :data:`tubekit.validation.MAX_PERIODS`, is refused (the count is checked before it is made an int).
    """
    if not round(period_count(field, duration, dt)) >= 1:
        raise ConfigError(field, f"at least one FHOCP period ({dt:g} s)", duration)


def horizon_reach(speed: float, dt: float, horizon_steps: int) -> float:
    """Farthest horizontal travel within one horizon, ``speed`` N δt (m)."""
    return speed * dt * horizon_steps


def workspace_fits(workspace: Any, clearance: float, reach: float) -> bool:
    """Whether both horizontal extents of ``workspace`` [lower, upper] exceed 2 (clearance + reach) (m)."""
    lower, upper = (np.asarray(side, dtype=float) for side in workspace)
    width = upper[:2] - lower[:2] - 2 * clearance
    return bool(np.all(width > 2 * reach))


def workspace_rule(clearance: float, reach: float, terms: str = "vehicle_radius + u_max N dt") -> str:
    """The text of :func:`workspace_fits`' rule, with its right-hand side 2 (clearance + reach) in m."""
    return f"x and y extents > 2 ({terms}) = {2 * (clearance + reach):.4g} m"


def _fits_workspace(scenario: Scenario, u_max: float, horizon_steps: int) -> bool:
    """Whether both horizontal workspace extents exceed 2 (r̄ + u_max N δt)."""
    reach = horizon_reach(u_max, scenario.controller.dt, horizon_steps)
    return workspace_fits(scenario.workspace, scenario.vehicle_radius, reach)


def check_horizon_and_limits(scenario: Scenario) -> None:
    """N within :data:`MAX_HORIZON_STEPS`; one horizon's travel fits the workspace, blaming its own field."""
    steps = scenario.controller.horizon_steps
    if steps > MAX_HORIZON_STEPS:
        raise ConfigError("controller.horizon_steps", f"an integer in [1, {MAX_HORIZON_STEPS}]", steps)
    if scenario.workspace is None:
        return
    u_max = scenario.limits.u_max
    if _fits_workspace(scenario, u_max, steps):
        return
    reach = horizon_reach(u_max, scenario.controller.dt, steps)
    rule = f"u_max N dt small enough for the workspace's {workspace_rule(scenario.vehicle_radius, reach)}"
    default_steps = ControllerSettings().horizon_steps
    if steps > default_steps and _fits_workspace(scenario, u_max, default_steps):
        raise ConfigError("controller.horizon_steps", f"a smaller horizon: {rule}", steps)
    if _fits_workspace(scenario, paper_scenario().limits.u_max, steps):
        raise ConfigError("limits.u_max", f"a smaller speed: {rule}", u_max)
    extents = np.subtract(scenario.workspace[1], scenario.workspace[0])[:2]
    raise ConfigError("workspace", rule, f"x, y extents {extents[0]:.4g} m, {extents[1]:.4g} m")


def _degrees(value: float, unit: str) -> str:
    """``value`` read as degrees, in radians: ``30 deg/s = 0.5236 rad/s``."""
    return f"{value:g} deg{unit} = {math.radians(value):.4g} rad{unit}"


def unit_hints(scenario: Scenario) -> tuple[str, ...]:
    """Values that look like degrees where radians are meant (a hint, not an error: each is still a valid number).

    A yaw-rate limit above π rad/s (a half turn per second), a yaw-rate rate limit above 2π rad/s², or a heading
    outside [−2π, 2π] is far outside what the vehicles here do and the usual sign of a value written in degrees.
    """
    hints = []
    r_max = scenario.limits.r_max
    if r_max > math.pi:
        hints.append(f"limits.r_max = {r_max:g} rad/s is above pi rad/s; it is in rad/s, not deg/s "
                     f"(if you meant {_degrees(r_max, '/s')})")
    rate = scenario.limits.rate
    if rate is not None and rate[2] > 2 * math.pi:
        hints.append(f"limits.rate[2] = {rate[2]:g} rad/s^2 is above 2 pi rad/s^2; it is in rad/s^2 "
                     f"(if you meant {_degrees(rate[2], '/s^2')})")
    psi = scenario.initial_state[3]
    if abs(psi) > 2 * math.pi:
        hints.append(f"initial_state[3] (the heading) = {psi:g} rad is outside [-2 pi, 2 pi]; it is in rad "
                     f"(if you meant {_degrees(psi, '')})")
    return tuple(hints)


def check_run_inputs(scenario: Scenario, duration: float | None = None) -> None:
    """Every check of this module, cheapest first; raises the first :class:`ConfigError`.

    Parameters
    ----------
    scenario : Scenario
        The scenario to run.
    duration : float, optional
        Simulated time (s) if it differs from ``scenario.duration``.
    """
    duration_seconds("duration", scenario.duration if duration is None else duration)
    check_log_size(scenario, duration)
    check_horizon_and_limits(scenario)
    check_start(scenario)
    check_target(scenario)
