"""The tracking theorem at t = 0: the terminal law's own plan from the start passes the exact check.

At t = 0 there is no previous plan to shift; the loop's candidate is then the terminal law's N rows from the
measured start, each clipped to V̄ (``tubekit.loop.candidate.candidate_plan`` with no plan). The start and the
target's path are known exactly, so :func:`initial_plan_condition` evaluates that plan once, at certify time,
exactly as the acceptance check does (``tubekit.loop.plan_check``, whose rows it re-states here: ``verify`` does
not import the loop): every arc at ``ARC_SAMPLES`` + 1 points, e inside R shrunk by the arc's margin M_j and
the pad rate · (δ / ARC_SAMPLES) / 2, the heading toward the target, the vehicle ball (r̄ + M_pos,j + pad)
clear of every obstacle of the scenario and inside the workspace, the end in X_f (with its row faces, against the
plan's last row, under rate-limited plans: then the rows start from rest and move by at most J), the backup's footprint
about the end clear and inside the workspace, its safe set within the region sensed from the start. The
smallest slack must exceed :data:`verify.theorem.completion_bounds.FLOAT_SLACK` (the same floats, computed by two
codes). Condition ``initial_terminal``: then a plan exists at t = 0, and by the completion's invariance at
every period after it.
"""

from __future__ import annotations

import math

import numpy as np

from tubekit.design_inputs import ARC_SAMPLES
from tubekit.model.backup import SafeSet
from tubekit.model.errors import error_coordinates, heading_cosine
from tubekit.model.kinematics import unicycle_step
from tubekit.model.terminal_law import TerminalLaw
from tubekit.scenario import Scenario

from verify.kernel.region import Region
from verify.theorem.design import Condition, Design

__all__ = ["law_plan", "initial_plan_condition", "start_distance"]


def law_plan(scenario: Scenario, law: TerminalLaw, v_bar: np.ndarray, v_low: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rows (N, 3), arcs (N, ARC_SAMPLES + 1, 4), times (N, ARC_SAMPLES + 1)) of the law's plan from the start,
    each row clipped to [``v_low``, ``v_bar``] (``v_low`` None: −``v_bar``); with rate-limited plans each row first
    clipped to within the jump J of the row before it, the first of the command before t = 0 (``limits.initial``,
    else rest: the loop's first ``v_last``), as the loop's candidate is."""
    low = -np.asarray(v_bar, dtype=float) if v_low is None else np.asarray(v_low, dtype=float)
    jump = scenario.limits.jump(float(scenario.controller.dt))
    last = np.clip(scenario.limits.start_command, low, v_bar)
    ctrl = scenario.controller
    dt, n = float(ctrl.dt), int(ctrl.horizon_steps)
    tau = np.linspace(0.0, dt, ARC_SAMPLES + 1)
    x = np.asarray(scenario.initial_state, dtype=float)
    rows, arcs = np.empty((n, 3)), np.empty((n, ARC_SAMPLES + 1, 4))
    for j in range(n):
        t = j * dt
        p = np.asarray(scenario.trajectory.position(t), dtype=float).reshape(3)
        v = np.asarray(scenario.trajectory.velocity(t), dtype=float).reshape(3)
        row = law.command(x, p, v, dt)
        if jump is not None:
            row = np.clip(row, last - jump, last + jump)
        rows[j] = last = np.clip(row, low, v_bar)
        arcs[j] = unicycle_step(np.broadcast_to(x, (ARC_SAMPLES + 1, 4)), np.broadcast_to(rows[j], (ARC_SAMPLES + 1, 3)),
                                tau)
        x = arcs[j, -1]
    times = dt * (np.arange(n)[:, None] + np.linspace(0.0, 1.0, ARC_SAMPLES + 1)[None, :])
    return rows, arcs, times


def _lower_corner(scenario: Scenario, v_bar: np.ndarray) -> np.ndarray | None:
    """The plans' lower corner as the loop clips to it (``Tightening.v_low``): under a minimum surge
    u_min + (u_max − ū̄), −w̄, −r̄ (``verify.certificate.handoff``); None for the symmetric box."""
    limits = scenario.limits
    if limits.u_min is None:
        return None
    corner = np.asarray(limits.lower, dtype=float) + (np.array([limits.u_max, limits.w_max, limits.r_max]) - v_bar)
    return np.minimum(corner, v_bar)


def _footprint_slacks(scenario: Scenario, end: np.ndarray, safe: SafeSet) -> dict[str, float]:
    """The terminal condition at the plan's end (step 11): footprint clear, inside the walls, S sensed."""
    rv = scenario.vehicle_radius
    r_f, h_f = safe.radius + rv, safe.depth + rv
    out: dict[str, float] = {}
    for i, o in enumerate(scenario.obstacles):
        h = max(0.0, math.hypot(o.center[0] - end[0], o.center[1] - end[1]) - r_f)
        v = max(0.0, abs(o.center[2] - end[2]) - h_f)
        out[f"terminal: obstacle {i}"] = math.hypot(h, v) - o.radius
    if scenario.workspace is not None:
        lo, hi = (np.asarray(b, dtype=float) for b in scenario.workspace)
        pad = np.array([r_f, r_f, h_f])
        out["terminal: workspace"] = float(min(np.min(end[:3] - pad - lo), np.min(hi - end[:3] - pad)))
    start = np.asarray(scenario.initial_state, dtype=float)
    spread = math.hypot(math.hypot(end[0] - start[0], end[1] - start[1]) + safe.radius,
                        abs(end[2] - start[2]) + safe.depth)
    out["terminal: sensed region"] = scenario.sensing_range - rv - spread
    return out


def _arc_slacks(scenario: Scenario, design: Design, region: Region, arcs: np.ndarray, times: np.ndarray
                ) -> dict[str, float]:
    """e in R shrunk by M_j + pad, the heading toward the target, the vehicle ball clear and inside the walls."""
    m = design.margins
    pad = 0.5 * (float(scenario.controller.dt) / ARC_SAMPLES) * np.asarray(design.rates, dtype=float)
    desired = np.asarray(scenario.trajectory.position(times.reshape(-1)), dtype=float).reshape(times.shape + (3,))
    e = error_coordinates(arcs, desired)
    col = {k: np.asarray(getattr(m, k), dtype=float)[:, None] for k in ("e_d", "e_z", "e_o", "position")}
    out = {"e_d >= epsilon": float(np.min(e[..., 0] - region.e_d[0] - col["e_d"] - pad[0])),
           "e_d <= e_d_max": float(np.min(region.e_d[1] - col["e_d"] - pad[0] - e[..., 0])),
           "|e_z|": float(np.min(min(-region.e_z[0], region.e_z[1]) - col["e_z"] - pad[1] - np.abs(e[..., 1]))),
           "|e_o|": float(np.min(min(-region.e_o[0], region.e_o[1]) - col["e_o"] - pad[2] - np.abs(e[..., 2]))),
           "hemisphere": float(np.min(-heading_cosine(arcs, desired)))}
    ball = scenario.vehicle_radius + col["position"] + pad[3]
    for i, o in enumerate(scenario.obstacles):
        out[f"obstacle {i}"] = float(np.min(np.linalg.norm(arcs[..., :3] - np.asarray(o.center), axis=-1)
                                            - o.radius - ball))
    if scenario.workspace is not None:
        lo, hi = (np.asarray(b, dtype=float) for b in scenario.workspace)
        pos = arcs[..., :3]
        out["workspace"] = float(np.min(np.minimum((pos - lo).min(axis=-1), (hi - pos).min(axis=-1)) - ball))
    return out


def initial_plan_condition(scenario: Scenario, design: Design, region: Region, law: TerminalLaw,
                           safe: SafeSet) -> Condition:
    """``initial_terminal``: the law's clipped plan from the start passes the exact check (module doc)."""
    v_bar = np.asarray(design.v_bar, dtype=float)
    rows, arcs, times = law_plan(scenario, law, v_bar, _lower_corner(scenario, v_bar))
    end = arcs[-1, -1]
    end_target = np.asarray(scenario.trajectory.position(times[-1, -1]), dtype=float).reshape(3)
    end_velocity = np.asarray(scenario.trajectory.velocity(times[-1, -1]), dtype=float).reshape(3)
    slacks = _arc_slacks(scenario, design, region, arcs, times)
    slacks.update(_footprint_slacks(scenario, end, safe))
    slacks.update(law.slacks(end, end_target, end_velocity))
    slacks.update(law.row_slacks(end, end_target, end_velocity, rows[-1], float(scenario.controller.dt)))
    where, worst = min(slacks.items(), key=lambda kv: kv[1])
    d0 = start_distance(scenario)
    ok = bool(math.isfinite(worst) and worst > 0.0 and worst - 1e-9 > 0.0)
    return Condition("initial_terminal", "the terminal law's plan from the start (rows clipped to V_bar) passes the "
                     "exact check at t = 0: smallest slack > 0", worst, 1e-9, ok,
                     f"tightest: {where}; start {d0:.4g} m from the target; X_f d in [{law.d_lo:.4g}, "
                     f"{law.d_hi:.4g}] m, |alpha| <= {law.alpha_max:.4g} rad after {len(rows)} rows")


def start_distance(scenario: Scenario) -> float:
    """The start's horizontal distance from the target at t = 0 (m)."""
    start = scenario.initial_state
    p0 = np.asarray(scenario.trajectory.position(0.0), dtype=float).reshape(3)
    return math.hypot(p0[0] - start[0], p0[1] - start[1])
