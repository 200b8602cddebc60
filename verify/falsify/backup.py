"""Falsifiers of the backup law (issue 21): disturbance sequences against station keeping.

:func:`verify.backup.certify_backup` proves that S = {V = d + β(1 − cos χ) <= c, |z − z*| <= Z}
(with the continuous yaw law, V = d + β a(χ), a of :func:`tubekit.model.backup.axis_shape`)
is invariant under the station-keeping law held at the ancillary tick, for every current with
‖ω_xy‖ <= ω̄_xy, |ω_z| <= ω̄_z, from every hand-over state (d <= handover radius, any heading).
This module attacks that claim by simulation, independently of the Arb proof:

* **starts** on the hand-over boundary: distance = the hand-over radius, any heading, depth error
  up to the hand-over depth (:func:`handover_start`);
* **greedy**: at every tick the current (of ``directions`` on the circle ‖ω_xy‖ = ω̄_xy, heave
  away from the anchor depth) that ends the tick at the largest V;
* **evolution**: piecewise-constant currents (one ω per ``piece`` seconds) and the start,
  optimised by a seeded (1 + λ) evolution strategy on the largest V / c.

The plant is the kinematic model the proof covers (x' = u cos ψ + ω_x, y' = u sin ψ + ω_y,
z' = w + ω_z, ψ' = r + ε_r, |ε_r| <= E_r the yaw-rate error), RK4 over each tick with the law's input
held; the law sees the time since the hand-over (its ramp starts at the start of each run). The budget counts
simulations, never seconds; the search is deterministic for a seed. The closed-loop attack on
runs in which the backup engages is :func:`verify.falsify.backup_loop.falsify_backup_loop`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.backup import (BackupPlan, StationKeeping, axis_angle, axis_shape, line_of_sight_angle,
                                  station_keeping_input)
from tubekit.plant.kinematic import rk4_tuple
from verify.falsify.outcome import SearchOutcome

__all__ = ["backup_lyapunov", "handover_start", "simulate_backup", "BackupRun", "BackupAttack",
           "falsify_backup", "BACKUP_START_DIM"]

#: Unit numbers of a hand-over start: bearing, heading, depth error.
BACKUP_START_DIM = 3
#: Offspring per generation of the evolution strategy, and its mutation step (unit cube).
_LAMBDA, _STEP = 4, 0.2
#: RK4 sub-steps per tick.
_SUBSTEPS = 4

#: ``disturbance(t, state, v) -> (ω_x, ω_y, ω_z, ε_r)`` (m/s, rad/s) for one tick.
Adversary = Callable[[float, np.ndarray, tuple[float, float, float]], np.ndarray]


def backup_lyapunov(state: np.ndarray, anchor: np.ndarray, shape: float, law: StationKeeping | None = None) -> float:
    """V = d + β a(χ) (m) of ``state`` [x, y, z, ψ] about ``anchor`` [x*, y*, z*] with β = ``shape``:
    a = 1 − cos χ, or the continuous law's a(χ) when ``law`` has ``yaw_law="continuous"``."""
    d = math.hypot(state[0] - anchor[0], state[1] - anchor[1])
    phi = line_of_sight_angle(float(state[0]), float(state[1]), float(state[3]), float(anchor[0]), float(anchor[1]))
    if law is None:
        return d + shape * (1.0 - math.cos(axis_angle(phi)))
    return d + shape * axis_shape(law, phi)


def handover_start(plan: BackupPlan, unit: np.ndarray) -> np.ndarray:
    """A state on the hand-over boundary about the origin: d = the hand-over radius, any heading.

    ``unit`` in [0, 1]^3: bearing, heading (both over a full turn), depth error in [−Z_h, Z_h]
    with Z_h the hand-over depth (``plan.handover[1]``, else the safe set's depth).
    """
    u = np.clip(np.asarray(unit, dtype=float), 0.0, 1.0)
    radius = plan.handover[0] if plan.handover[0] > 0 else plan.safe_set.handover_radius
    depth = plan.handover[1] if plan.handover[1] > 0 else plan.safe_set.depth
    bearing = 2 * math.pi * u[0]
    return np.array([radius * math.cos(bearing), radius * math.sin(bearing), depth * (2 * u[2] - 1),
                     2 * math.pi * u[1]])


def _rk4_tick(state: np.ndarray, v: tuple[float, float, float], omega: np.ndarray, tick: float) -> np.ndarray:
    """The kinematic plant ẋ = f(x) v + ω over one tick, ``v`` and ``omega`` held (a fourth entry of
    ``omega``, when present, is the yaw-rate error ε_r): the plant's own RK4
    (:func:`tubekit.plant.kinematic.rk4_tuple`, :data:`_SUBSTEPS` steps)."""
    w1, w2, w3 = (float(c) for c in omega[:3])
    w4 = float(omega[3]) if len(omega) > 3 else 0.0

    def rhs(t: float, x: tuple, vv: tuple) -> tuple[float, float, float, float]:
        return (vv[0] * math.cos(x[3]) + w1, vv[0] * math.sin(x[3]) + w2, vv[1] + w3, vv[2] + w4)

    return np.array(rk4_tuple(rhs, 0.0, tuple(map(float, state)), v, tick / _SUBSTEPS, _SUBSTEPS))


def simulate_backup(plan: BackupPlan, start: np.ndarray, adversary: Adversary, *, tick: float,
                    seconds: float, command: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> tuple[float, float]:
    """Run the law about the origin under ``adversary`` for ``seconds``, blending ``command`` (the command applied
    at the hand-over, m/s, m/s, rad/s) when the law has a ramp; (max V / c, max |z| / Z) over the ticks."""
    law, safe = plan.law, plan.safe_set
    state = np.asarray(start, dtype=float)
    anchor = np.zeros(3)
    level = backup_lyapunov(state, anchor, safe.shape, law)
    depth = abs(state[2])
    for k in range(int(round(seconds / tick))):
        v = station_keeping_input(law, tuple(map(float, state)), (0.0, 0.0, 0.0), k * tick, command)
        state = _rk4_tick(state, v, adversary(k * tick, state, v), tick)
        level = max(level, backup_lyapunov(state, anchor, safe.shape, law))
        depth = max(depth, abs(state[2]))
    return level / safe.level, depth / safe.depth


def _greedy(plan: BackupPlan, omega_xy: float, omega_z: float, tick: float, directions: int,
            yaw_error: float = 0.0) -> Adversary:
    """Each tick, the current on ‖ω_xy‖ = ω̄_xy (of ``directions``), and the yaw error ε_r ∈ {−E_r, 0, E_r}
    (0 alone when E_r = 0), that ends the tick at the largest V."""
    angles = np.linspace(0.0, 2 * math.pi, directions, endpoint=False)
    errors = (-yaw_error, 0.0, yaw_error) if yaw_error > 0 else (0.0,)
    shape = plan.safe_set.shape

    def omega(t: float, state: np.ndarray, v: tuple[float, float, float]) -> np.ndarray:
        wz = omega_z if state[2] >= 0 else -omega_z
        options = [np.array([omega_xy * math.cos(a), omega_xy * math.sin(a), wz, e]) for a in angles
                   for e in errors]
        return max(options, key=lambda w: backup_lyapunov(_rk4_tick(state, v, w, tick), np.zeros(3), shape, plan.law))
    return omega


def _piecewise(omega_xy: float, omega_z: float, piece: float, units: np.ndarray, yaw_error: float = 0.0) -> Adversary:
    """One ω per ``piece`` seconds from ``units`` (pieces, 3 or 4) in [0, 1]: direction, magnitude, heave
    and, with a fourth column, the yaw-rate error ε_r = E_r (2 u − 1)."""
    table = []
    for u in np.clip(units, 0.0, 1.0):
        a, mag = 2 * math.pi * u[0], omega_xy * min(1.0, 2.0 * u[1])
        eps = yaw_error * (2.0 * u[3] - 1.0) if len(u) > 3 else 0.0
        table.append(np.array([mag * math.cos(a), mag * math.sin(a), omega_z * (2.0 * u[2] - 1.0), eps]))

    def omega(t: float, state: np.ndarray, v: tuple[float, float, float]) -> np.ndarray:
        return table[min(int(t / piece + 1e-9), len(table) - 1)]
    return omega


@dataclass(frozen=True)
class BackupRun:
    """One simulated backup run: its strategy, start and the largest V / c and |z − z*| / Z reached."""

    strategy: str
    start: tuple[float, float, float, float]
    level_ratio: float
    depth_ratio: float

    @property
    def left(self) -> bool:
        """The run left the certified safe set (V > c or |z − z*| > Z)."""
        return self.level_ratio > 1.0 or self.depth_ratio > 1.0

    @property
    def counterexample(self) -> bool:
        """The run left the safe set: a counterexample to the backup certificate."""
        return self.left

    def to_dict(self) -> dict:
        """JSON form."""
        return {"strategy": self.strategy, "start": list(self.start), "level_ratio": self.level_ratio,
                "depth_ratio": self.depth_ratio, "left": self.left}


@dataclass(frozen=True)
class BackupAttack(SearchOutcome):
    """Outcome of :func:`falsify_backup`: the worst run (largest V / c) over ``simulations`` runs."""

    omega_bar: tuple[float, float]
    tick: float
    seconds: float
    seed: int
    worst: BackupRun
    runs: tuple[BackupRun, ...] = field(repr=False, default=())

    def summary(self) -> str:
        """Readable text."""
        w = self.worst
        return (("COUNTEREXAMPLE found" if self.found else "no counterexample")
                + f" (backup law, {len(self.runs)} simulations of {self.seconds:g} s, seed {self.seed}, "
                f"||omega_xy|| <= {self.omega_bar[0]:.4g}, |omega_z| <= {self.omega_bar[1]:.4g}): largest V / c = "
                f"{w.level_ratio:.6f}, |z - z*| / Z = {max(r.depth_ratio for r in self.runs):.4f}, by {w.strategy}")

    def to_dict(self) -> dict:
        """JSON form."""
        return {"mode": "backup", "found": self.found, "omega_bar": list(self.omega_bar), "tick": self.tick,
                "seconds": self.seconds, "seed": self.seed, "simulations": len(self.runs),
                "worst": self.worst.to_dict()}


def _validate(budget: int, seconds: float, piece: float, tick: float) -> None:
    if not isinstance(budget, int) or isinstance(budget, bool) or budget < 1:
        raise ConfigError("budget", "an integer >= 1 (simulations)", budget)
    for name, value in (("seconds", seconds), ("piece", piece), ("tick", tick)):
        if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise ConfigError(name, "a positive number of seconds", value)


def falsify_backup(plan: BackupPlan, *, omega_xy: float, omega_z: float, tick: float, budget: int = 12,
                   seconds: float = 20.0, piece: float = 1.0, seed: int = 0, directions: int = 8,
                   yaw_rate_error: float = 0.0, command: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> BackupAttack:
    """Search hand-over starts and currents within (ω̄_xy, ω̄_z) for a run that leaves the safe set.

    Parameters
    ----------
    plan : BackupPlan
        The certified backup (law, safe set, hand-over).
    omega_xy, omega_z : float
        The disturbance bounds (m/s) the backup was certified for.
    tick : float
        The ancillary tick (s) the law is held over.
    budget : int
        Simulations (>= 1): a quarter greedy from hand-over starts, the rest a (1 + 4) evolution
        strategy on piecewise-constant currents.
    seconds, piece : float
        Seconds per run, and per constant piece of the evolved currents.
    seed : int
        Seed; the search is deterministic for a seed.
    directions : int
        Current directions the greedy adversary compares each tick.
    yaw_rate_error : float
        E_r (rad/s): the adversary also chooses ψ̇ − r in [−E_r, E_r] (0: the kinematic plant's exact yaw).
    command : (float, float, float)
        The command applied at the hand-over (m/s, m/s, rad/s; a ramped law blends it out over its ramp): a corner
        of V is the hardest start; the greedy runs alternate its surge and yaw signs.
    """
    _validate(budget, seconds, piece, tick)
    if not isinstance(yaw_rate_error, (int, float)) or not math.isfinite(yaw_rate_error) or yaw_rate_error < 0:
        raise ConfigError("yaw_rate_error", "a finite number >= 0 (rad/s)", yaw_rate_error)
    cols = 4 if yaw_rate_error > 0 else 3
    rng = np.random.default_rng(seed)
    runs: list[BackupRun] = []
    greedy = _greedy(plan, omega_xy, omega_z, tick, directions, yaw_rate_error)
    for _ in range(max(1, budget // 4)):
        start = handover_start(plan, rng.uniform(0, 1, BACKUP_START_DIM))
        sign = 1.0 if len(runs) % 2 == 0 else -1.0
        cmd = (sign * command[0], command[1], sign * command[2])
        runs.append(BackupRun("greedy", tuple(map(float, start)),
                              *simulate_backup(plan, start, greedy, tick=tick, seconds=seconds, command=cmd)))
    pieces = max(1, int(math.ceil(seconds / piece)))

    def evaluate(genome: np.ndarray) -> BackupRun:
        start = handover_start(plan, genome[:BACKUP_START_DIM])
        adversary = _piecewise(omega_xy, omega_z, piece, genome[BACKUP_START_DIM:].reshape(pieces, cols),
                               yaw_rate_error)
        return BackupRun("evolution", tuple(map(float, start)),
                         *simulate_backup(plan, start, adversary, tick=tick, seconds=seconds, command=command))

    if len(runs) < budget:
        parent = rng.uniform(0, 1, BACKUP_START_DIM + cols * pieces)
        parent[BACKUP_START_DIM + 1::cols] = 1.0  # every piece on the circle ‖ω_xy‖ = ω̄_xy
        best = evaluate(parent)
        runs.append(best)
        while len(runs) < budget:
            for _ in range(min(_LAMBDA, budget - len(runs))):
                child = np.clip(parent + rng.normal(0, _STEP, parent.size), 0, 1)
                run = evaluate(child)
                runs.append(run)
                if run.level_ratio >= best.level_ratio:
                    parent, best = child, run
    worst = max(runs, key=lambda r: (r.left, r.level_ratio))
    return BackupAttack(omega_bar=(float(omega_xy), float(omega_z)), tick=float(tick), seconds=float(seconds),
                        seed=seed, worst=worst, runs=tuple(runs))
