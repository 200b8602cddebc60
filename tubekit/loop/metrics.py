"""Metrics of a closed-loop run: pure functions of the logged trajectory.

Every metric in ``metrics.json`` is computed by :func:`compute_metrics` from the
columns of ``trajectory.csv`` plus the scenario constants that ``metrics.json``
itself records (obstacles, vehicle radius, epsilon, input limits, circle
centre), so each can be recomputed from the two files. Definitions (units m, s):

* ``min_clearance``: min over logged samples and obstacles of
  ‖p − c_m‖ − r_m − r̄ (vehicle ball to obstacle surface, 3-D); < 0 is a collision.
* ``min_e_d``: min over samples of e_d = ‖(x − x_d, y − y_d)‖.
* ``max_input_ratio``: max over samples and axes of |v_i| / v̄_i (applied input).
* ``saturated_steps``: sampling periods with at least one clipped tick;
  ``saturated_ticks``: clipped ticks.
* ``encirclements``: unwrapped angle of the vehicle about the circle centre,
  ``−sign(rate) Δθ / 2π`` (turns in the direction of the desired motion); null
  for trajectories other than circle/helix.
* ``obstacle_passes``: per obstacle, net passes of its bearing about the
  circle centre (see :func:`obstacle_passes`); null like ``encirclements``.
* ``tracking_rmse``: sqrt(mean ‖p − p_d‖²) over samples (3-D position error).
* ``max_rho``: max over samples of ‖ρ‖ = ‖e − ê‖ (error units, see closed_loop; the ticks while
  the backup law runs have no nominal and are skipped).
* ``backup_s``, ``backup_engagements``: seconds the backup law ran and how many times it took
  over (column ``backup_active``; :func:`backup_figures`).
* ``sway_max``: max over samples of |sway| (m/s): the hull's v_b on the dynamic plant (column
  ``v_b``), else the component of ω − δ(t) normal to the heading (the sway model's v_s);
  ``sway_bound``: the certificate's γ̄ (null when none was given).
* ``velocity_error_max``: max over samples of |u_b − u|, |w_b − w|, |r_b − r| (the dynamic plant's
  velocity loop, from the columns ``u_b``, ``w_b``, ``r_b``); null on the kinematic plant.
* ``sign_flips_per_s``: per input channel {"u", "w", "r"} of the applied input, the sign changes
  between consecutive logged samples per second of the run (:func:`sign_flips_per_s`), samples with
  |v_c| below :data:`FLIP_THRESHOLD` × v̄_c ignored (a chattering command flips often; a smooth one
  a few times per turn).
* ``command_jump_max``: per channel, the largest change of v̂ (columns ``u_hat``, ``w_hat``, ``r_hat``:
  the plan's node, or the backup's command) between consecutive ticks (m/s, rad/s); with
  ``limits.rate`` every jump of a plan's or a replayed node, and the hand-over to and from the
  backup, is at most J = rate · dt (the backup's own per-tick changes follow its rate bound).
* ``fhocp_max_violation``: largest nonlinear-constraint violation of the
  nominal plans the FHOCP returned (its ``max_violation``; 0 when every plan
  is feasible for the tightened problem).
* ``step_ms_*``: controller time per sampling period (sensing + FHOCP + nominal
  propagation + ancillary law; the plant simulation excluded); ``solve_ms_*``:
  the FHOCP's own solve time; ``wall_s``: elapsed time of the whole run
  (solver construction included), the last value of the ``wall_s`` column.

The one convention for a run's metrics is :func:`run_metrics` (what
:attr:`SimulationResult.metrics <tubekit.loop.result.SimulationResult.metrics>` and the
run's part of ``metrics.json`` hold): :func:`compute_metrics` with ``rho_bound`` = ρ̃ of a
certified tightening (else null) and ``sway_bound`` = the tightening's γ̄ on a tube run (null
for the baseline), plus the run's facts (tube, law, σ, κ failures, checks), ``certified``,
``rho_tilde_used``, ``tube_box`` and the promises (:data:`RUN_KEYS`).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from tubekit.jsonable import json_number
from tubekit.loop.promises import Promise, RunLog, broken_promises, check_promises, tier_outcomes
from tubekit.plant.kinematic import Plant
from tubekit.scenario import Obstacle, Scenario
from tubekit.model.trajectory import Circle
from tubekit.model.errors import error_coordinates

__all__ = [
    "rho_period_peaks",
    "backup_figures",
    "clearance",
    "input_ratio",
    "encirclements",
    "obstacle_passes",
    "tracking_rmse",
    "sign_flips_per_s",
    "command_jumps",
    "FLIP_THRESHOLD",
    "intervals_below",
    "percentile_ms",
    "sway_series",
    "compute_metrics",
    "run_metrics",
    "promise_figures",
    "read_trajectory_csv",
    "METRIC_KEYS",
    "RUN_KEYS",
]

#: Fraction of the channel's limit v̄_c below which a sample's sign is ignored by :func:`sign_flips_per_s`.
FLIP_THRESHOLD = 0.01
_CHANNELS = ("u", "w", "r")

#: Keys every metrics dictionary has (the issue's list plus a few more).
METRIC_KEYS: tuple[str, ...] = (
    "scenario", "duration_s", "steps", "obstacles", "vehicle_radius", "min_clearance", "min_e_d",
    "epsilon", "max_input_ratio", "saturated_steps", "encirclements", "tracking_rmse", "max_rho",
    "rho_bound", "step_ms_median", "step_ms_p95", "wall_s", "sway_max", "sway_bound", "backup_s",
    "backup_engagements", "sign_flips_per_s", "command_jump_max",
)
#: Keys :func:`run_metrics` adds to :func:`compute_metrics` (every run has them; the baseline's promises are empty).
RUN_KEYS: tuple[str, ...] = ("tube", "law", "sigma", "kappa_failures", "checks", "certified", "rho_tilde_used",
                             "tube_box", "promises", "promises_kept", "promises_broken", "max_rho_ratio",
                             "tiers", "outcome")


def clearance(positions: np.ndarray, obstacles: Sequence[Obstacle | Mapping[str, Any]],
              vehicle_radius: float) -> np.ndarray:
    """Distance (m) from the vehicle ball to the nearest obstacle surface, shape (n,).

    ``+inf`` everywhere when there are no obstacles; negative means overlap.
    """
    p = np.asarray(positions, dtype=float)[:, :3]
    if len(obstacles) == 0:
        return np.full(len(p), np.inf)
    centers = np.array([_center(o) for o in obstacles], dtype=float)
    radii = np.array([_radius(o) for o in obstacles], dtype=float)
    d = np.linalg.norm(p[:, None, :] - centers[None, :, :], axis=2) - radii[None, :] - vehicle_radius
    return d.min(axis=1)


def rho_period_peaks(columns: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Per sampling period: the time it ends (s) and the max of ||rho|| over it (its pre-reset peak).

    ``columns`` needs ``t``, ``step`` and ``rho_norm`` (as in ``trajectory.csv`` or
    :meth:`tubekit.loop.closed_loop.SimulationResult.columns`). Falls back to the raw
    series when the log is not a whole number of periods.
    """
    step = np.asarray(columns["step"])
    m = int(np.sum(step == step[0]))
    rho = np.asarray(columns["rho_norm"], dtype=float)
    n = (len(rho) - 1) // m if m else 0
    if m < 1 or n < 1 or n * m + 1 != len(rho):
        return np.asarray(columns["t"]), rho
    return np.asarray(columns["t"])[m::m][:n], rho[1:n * m + 1].reshape(n, m).max(axis=1)


def input_ratio(inputs: np.ndarray, limits: Sequence[float]) -> np.ndarray:
    """max_i |v_i| / v̄_i per sample, shape (n,) (NaN rows stay NaN)."""
    v = np.asarray(inputs, dtype=float)
    return np.max(np.abs(v) / np.asarray(limits, dtype=float), axis=1)


def encirclements(positions: np.ndarray, center: Sequence[float], rate_sign: float = 1.0) -> float:
    """Turns of the horizontal position about ``center`` (x, y), positive in the desired direction.

    ``rate_sign`` is the sign of the circle's angular rate; a :class:`Circle`
    p = c + R[sin a, cos a] with rate > 0 turns clockwise (θ = atan2 decreasing).
    """
    p = np.asarray(positions, dtype=float)
    theta = np.unwrap(np.arctan2(p[:, 1] - center[1], p[:, 0] - center[0]))
    return float(-math.copysign(1.0, rate_sign) * (theta[-1] - theta[0]) / (2.0 * math.pi))


def obstacle_passes(positions: np.ndarray, center: Sequence[float], rate_sign: float,
                    obstacles: Sequence[Obstacle | Mapping[str, Any]]) -> list[int]:
    """Net number of times the vehicle passes each obstacle's bearing about ``center``.

    With φ = −sign(rate) θ the unwrapped angle in the direction of travel and
    φ_m the obstacle's angle, the count is the number of crossings of
    φ_m + 2πn between the first and last sample:
    ``floor((φ(T) − φ_m) / 2π) − floor((φ(0) − φ_m) / 2π)``. The paper's "two
    encirclements, avoiding the obstacles twice each" is every count >= 2.
    """
    p = np.asarray(positions, dtype=float)
    s = -math.copysign(1.0, rate_sign)
    phi = s * np.unwrap(np.arctan2(p[:, 1] - center[1], p[:, 0] - center[0]))
    out = []
    for o in obstacles:
        c = _center(o)
        phi_m = s * math.atan2(c[1] - center[1], c[0] - center[0])
        out.append(int(math.floor((phi[-1] - phi_m) / (2 * math.pi))
                       - math.floor((phi[0] - phi_m) / (2 * math.pi))))
    return out


def tracking_rmse(positions: np.ndarray, desired: np.ndarray) -> float:
    """sqrt(mean ‖p − p_d‖²) (m)."""
    d = np.asarray(positions, dtype=float)[:, :3] - np.asarray(desired, dtype=float)[:, :3]
    return float(np.sqrt(np.mean(np.sum(d * d, axis=1))))


def sign_flips_per_s(t: np.ndarray, values: np.ndarray, floor: Sequence[float]) -> dict[str, float | None]:
    """Sign changes per second of each column of ``values`` (n, 3) (keys "u", "w", "r").

    Non-finite samples and samples with |v_c| < ``floor[c]`` are dropped; a flip is a sign change
    between consecutive kept samples; the count is divided by the logged span t[-1] − t[0] (s).
    None for a log shorter than one sample step.
    """
    t = np.asarray(t, dtype=float)
    v = np.asarray(values, dtype=float)
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    out: dict[str, float | None] = {}
    for c, name in enumerate(_CHANNELS):
        x = v[:, c]
        kept = np.sign(x[np.isfinite(x) & (np.abs(x) >= floor[c])])
        out[name] = float(np.count_nonzero(kept[1:] != kept[:-1]) / span) if span > 0 else None
    return out


def command_jumps(values: np.ndarray) -> dict[str, float | None]:
    """Largest |v_c(i+1) − v_c(i)| over consecutive finite samples of ``values`` (n, 3), per channel."""
    d = np.abs(np.diff(np.asarray(values, dtype=float), axis=0))
    return {name: _nanmax_or_none(d[:, c]) if len(d) else None for c, name in enumerate(_CHANNELS)}


def intervals_below(t: np.ndarray, values: np.ndarray, threshold: float) -> list[dict[str, float]]:
    """Maximal runs of consecutive samples with ``values < threshold``.

    Returns a list of ``{t_start, t_end, t_min, min, depth}`` (``depth`` =
    threshold − min > 0), in time order; empty when the bound always holds.
    """
    t = np.asarray(t, dtype=float)
    v = np.asarray(values, dtype=float)
    below = v < threshold
    out: list[dict[str, float]] = []
    if not np.any(below):
        return out
    edges = np.flatnonzero(np.diff(np.concatenate([[0], below.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):  # [a, b) rows below
        k = a + int(np.argmin(v[a:b]))
        out.append({"t_start": float(t[a]), "t_end": float(t[b - 1]), "t_min": float(t[k]),
                    "min": float(v[k]), "depth": float(threshold - v[k])})
    return out


def backup_figures(t: np.ndarray, active: np.ndarray | None) -> dict[str, Any]:
    """``backup_s`` (s the backup law ran: active ticks × tick length) and ``backup_engagements``
    (times it took over); zeros for a log without the ``backup_active`` column."""
    if active is None or len(t) < 2:
        return {"backup_s": 0.0, "backup_engagements": 0}
    on = np.asarray(active[:-1], dtype=float) > 0.5
    starts = int(on[0]) + int(np.sum(on[1:] & ~on[:-1])) if on.size else 0
    return {"backup_s": float(np.sum(on) * (t[1] - t[0])), "backup_engagements": starts}


def percentile_ms(values: np.ndarray, q: float) -> float | None:
    """Percentile ``q`` of the finite entries (None when there are none)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return float(np.percentile(v, q)) if v.size else None


def _center(o: Obstacle | Mapping[str, Any]) -> Sequence[float]:
    return o.center if isinstance(o, Obstacle) else o["center"]


def _radius(o: Obstacle | Mapping[str, Any]) -> float:
    return o.radius if isinstance(o, Obstacle) else o["radius"]


def _nanmax_or_none(x: np.ndarray | None) -> float | None:
    if x is None or not np.any(np.isfinite(x)):
        return None
    return float(np.nanmax(x))


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def sway_series(columns: Mapping[str, np.ndarray], scenario: Scenario) -> np.ndarray | None:
    """Sway (m/s) per sample: column ``v_b`` if logged, else (ω − δ(t)) · (−sin ψ, cos ψ); None without ω."""
    if "v_b" in columns:
        return np.asarray(columns["v_b"], dtype=float)
    if not all(k in columns for k in ("psi", "omega_1", "omega_2")):
        return None
    t, psi = np.asarray(columns["t"], dtype=float), np.asarray(columns["psi"], dtype=float)
    current = Plant.of(scenario).current(t)
    d1 = np.asarray(columns["omega_1"], dtype=float) - current[:, 0]
    d2 = np.asarray(columns["omega_2"], dtype=float) - current[:, 1]
    return -d1 * np.sin(psi) + d2 * np.cos(psi)


def _sway_metrics(columns: Mapping[str, np.ndarray], scenario: Scenario,
                  sway_bound: float | None) -> dict[str, float | None]:
    """``sway_max`` (m/s, :func:`sway_series`) and ``sway_bound`` (γ̄, m/s, or None)."""
    sway = sway_series(columns, scenario)
    return {"sway_max": _nanmax_or_none(None if sway is None else np.abs(sway)),
            "sway_bound": None if sway_bound is None else float(sway_bound)}


def _velocity_error_max(c: Mapping[str, np.ndarray]) -> list[float | None] | None:
    """max |u_b - u|, |w_b - w|, |r_b - r| (m/s, m/s, rad/s) over the samples; None without body columns."""
    if not all(k in c for k in ("u_b", "w_b", "r_b")):
        return None
    err = np.column_stack([c["u_b"] - c["u"], c["w_b"] - c["w"], c["r_b"] - c["r"]])
    return [_nanmax_or_none(np.abs(err[:, j])) for j in range(3)]


def _circle_figures(pos: np.ndarray, des: np.ndarray, scenario: Scenario) -> tuple[Any, Any, Any, Any]:
    """(centre, encirclements, desired encirclements, obstacle passes) of a circular target; Nones otherwise."""
    traj = scenario.trajectory
    if not isinstance(traj, Circle):  # Helix is a Circle
        return None, None, None, None
    center = [float(traj.center[0]), float(traj.center[1])]
    return (center, encirclements(pos, center, traj.rate), encirclements(des, center, traj.rate),
            obstacle_passes(pos, center, traj.rate, scenario.obstacles))


def compute_metrics(columns: Mapping[str, np.ndarray], scenario: Scenario, *,
                    rho_bound: float | None = None, sway_bound: float | None = None,
                    extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """All metrics of one run from its logged columns (see module doc for definitions).

    Parameters
    ----------
    columns : mapping
        The columns of ``trajectory.csv`` (:meth:`SimulationResult.columns`).
    scenario : Scenario
        Supplies the constants (recorded in the output too).
    rho_bound, sway_bound : float, optional
        Certified tube radius ρ̃ (``None`` when not certified) and sway bound γ̄ (m/s, ``None``: none).
    extra : mapping, optional
        Added verbatim (e.g. law, sigma, tube flag).
    """
    c = {k: np.asarray(v, dtype=float) for k, v in columns.items()}
    t = c["t"]
    pos = np.column_stack([c["x"], c["y"], c["z"]])
    des = np.column_stack([c["x_d"], c["y_d"], c["z_d"]])
    inputs = np.column_stack([c["u"], c["w"], c["r"]])
    applied = np.all(np.isfinite(inputs), axis=1)
    lim = scenario.limits.vector
    obstacles = [{"center": list(o.center), "radius": o.radius} for o in scenario.obstacles]

    clr = clearance(pos, scenario.obstacles, scenario.vehicle_radius)
    i_clr = int(np.argmin(clr))
    e_d = error_coordinates(np.column_stack([pos, np.zeros(len(pos))]), des)[:, 0]  # e_d does not read psi
    i_ed = int(np.argmin(e_d))
    ratio = input_ratio(inputs[applied], lim)
    sat = c["saturated"] > 0.5
    center, enc, enc_d, passes = _circle_figures(pos, des, scenario)
    first = np.isfinite(c["step_ms"])
    m = {
        "scenario": scenario.name,
        "duration_s": float(t[-1] - t[0]),
        "steps": int(np.sum(first)), "obstacles": obstacles,
        "vehicle_radius": scenario.vehicle_radius,
        "min_clearance": _finite_or_none(float(clr[i_clr])),
        "min_clearance_t": float(t[i_clr]),
        "collision": bool(np.any(clr < 0.0)),
        "collisions": intervals_below(t, clr, 0.0),
        "min_e_d": float(e_d[i_ed]),
        "min_e_d_t": float(t[i_ed]),
        "epsilon": scenario.epsilon,
        "e_d_below_epsilon": intervals_below(t, e_d, scenario.epsilon),
        "max_input_ratio": float(np.max(ratio)) if ratio.size else None,
        "input_limits": [float(x) for x in lim],
        "inputs_within_limits": bool(np.all(ratio <= 1.0 + 1e-9) and np.all(inputs[applied] >= scenario.limits.lower
                                                                               - 1e-9)),
        "saturated_steps": int(np.unique(c["step"][sat]).size),
        "saturated_ticks": int(np.sum(sat)),
        "fallback_steps": int(np.sum((c["fallback"] > 0.5) & first)),
        "replaced_steps": int(np.sum((c["replaced"] > 0.5) & first)),
        **backup_figures(t, c.get("backup_active")),
        "encirclements": enc,
        "desired_encirclements": enc_d,
        "encirclement_center": center,
        "obstacle_passes": passes,
        "tracking_rmse": tracking_rmse(pos, des),
        "max_rho": float(np.nanmax(c["rho_norm"])),
        "rho_bound": rho_bound,
        "step_ms_median": percentile_ms(c["step_ms"], 50),
        "step_ms_p95": percentile_ms(c["step_ms"], 95),
        "solve_ms_median": percentile_ms(c["solve_ms"], 50),
        "solve_ms_p95": percentile_ms(c["solve_ms"], 95),
        "fhocp_max_violation": _nanmax_or_none(c.get("plan_violation")),
        "wall_s": float(np.nanmax(c["wall_s"])),
    }
    m.update(_sway_metrics(c, scenario, sway_bound))
    m["velocity_error_max"] = _velocity_error_max(c)
    m["sign_flips_per_s"] = sign_flips_per_s(t, inputs, FLIP_THRESHOLD * np.asarray(lim, dtype=float))
    if all(k in c for k in ("u_hat", "w_hat", "r_hat")):
        m["command_jump_max"] = command_jumps(np.column_stack([c["u_hat"], c["w_hat"], c["r_hat"]]))
    else:
        m["command_jump_max"] = None
    if extra:
        m.update(extra)
    return m


def promise_figures(promises: Sequence[Promise]) -> dict[str, Any]:
    """``promises`` (JSON-ready), ``promises_kept``, ``promises_broken`` and ``max_rho_ratio`` of a tube run.

    ``promises_kept``: every figure (premises included) held; ``promises_broken``: the names
    :func:`tubekit.loop.promises.broken_promises` gives (a given tier, its premises held: exit 4);
    ``max_rho_ratio`` null when infinite. The baseline (no promises) has ``promises`` and
    ``promises_broken`` empty and the other two null.
    """
    if not promises:
        return {"promises": [], "promises_kept": None, "promises_broken": [], "max_rho_ratio": None}
    tube = [p for p in promises if p.name == "tube"]
    return {"promises": [p.to_dict() for p in promises], "promises_kept": all(p.ok for p in promises),
            "promises_broken": list(broken_promises(promises)),
            "max_rho_ratio": json_number(tube[0].observed) if tube else None}


def run_metrics(run: RunLog, promises: Sequence[Promise] | None = None) -> dict[str, Any]:
    """The metrics of one run in the one convention (module doc); ``promises`` default: measured here.

    Parameters
    ----------
    run : SimulationResult
        The run (anything with its ``columns()``, ``facts``, ``scenario``, ``tightening`` and ``tube``).
    promises : sequence of Promise, optional
        :func:`tubekit.loop.promises.check_promises` of ``run`` when already measured (ignored for the baseline).
    """
    tight = run.tightening
    certified = bool(tight.certified)
    if not run.tube:
        promises = ()
    elif promises is None:
        promises = check_promises(run, uncertified=True)
    m = compute_metrics(run.columns(), run.scenario, rho_bound=float(tight.rho_tilde) if certified else None,
                        sway_bound=float(tight.disturbance.sway) if run.tube else None, extra=run.facts)
    m.update(certified=certified, rho_tilde_used=float(tight.rho_tilde), tiers=tight.tiers.to_dict(),
             outcome=tier_outcomes(promises, tight.tiers) if run.tube else None,
             tube_box=[float(x) for x in np.asarray(tight.tube, dtype=float)], **promise_figures(promises))
    return m


def read_trajectory_csv(path: str | Path) -> dict[str, np.ndarray]:
    """Read a ``trajectory.csv`` into float columns keyed by header name."""
    with open(path, newline="") as fh:
        reader = csv.reader(fh)
        header = next(reader)
        rows = [[float(x) for x in row] for row in reader if row]
    data = np.asarray(rows, dtype=float).reshape(-1, len(header))
    return {name: data[:, i] for i, name in enumerate(header)}
