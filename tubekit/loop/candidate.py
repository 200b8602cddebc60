"""The shifted candidate: the last accepted plan, shifted by the periods elapsed and completed at its end.

Tube MPC keeps a plan available by the *candidate* (Chisci et al. 2001): the previous plan shifted by
one period, completed by a terminal input. The loop tries it whenever the solver's plan is refused or
rejected (:meth:`tubekit.loop.closed_loop._ClosedLoop.solve`): the candidate goes through the same exact
check as any plan (:func:`tubekit.loop.plan_check.check_plan`) and, if it passes, it is accepted — a new
plan, followed from now on — instead of replaying the old one towards its end and the backup.

Why the shifted part passes. A plan accepted at t_k satisfies every constraint of arc j + 1 with the
margin M_{j+1} (``verify.theorem.sampled.horizon_margins``). At t_{k+1} the measured state lies within
the one-period tube of the plan's first node, and the same inputs from there deviate from the old arcs
by at most M_{j+1} − M_j (the start offset plus the heading offset times the distance run), so the
shifted arc j meets its constraint with the margin M_j the check asks for. The completion: with the tracking
tier, the certified terminal law (:class:`tubekit.model.terminal_law.TerminalLaw`), under which
``verify.theorem.terminal`` proves that the candidate passes the check (a plan is always available, also at
t = 0, where the candidate is the law's own N rows); otherwise a pursuit of the target, clipped to V̄ and to
the rate rows, and the check decides (no tolerance is added: a candidate that fails is not used).

:func:`candidate_plan` builds it; :func:`completion_row` is the completion (:func:`pursuit_input` without a law).
"""

from __future__ import annotations

import math

import numpy as np

from tubekit.loop.plan_check import plan_arcs
from tubekit.model.terminal_law import TerminalLaw
from tubekit.scenario import Scenario

__all__ = ["candidate_plan", "completion_row", "pursuit_input", "settle_last_row", "PURSUIT_GAIN", "SETTLE_MARGIN",
           "SETTLE_ROUNDS"]

#: Gain (1/s) of the completion law on the distance and depth errors (a period's worth of correction at δ = 0.1 s
#: over about four periods).
PURSUIT_GAIN = 2.5
#: :func:`settle_last_row` aims this fraction inside the row faces, and iterates this many rounds.
SETTLE_MARGIN = 0.1
SETTLE_ROUNDS = 3


def _lower(v_max: np.ndarray, v_min: np.ndarray | None) -> np.ndarray:
    """The box's lower corner (3,): ``v_min``, or −``v_max`` for the symmetric box (m/s, m/s, rad/s)."""
    return -np.asarray(v_max, dtype=float) if v_min is None else np.asarray(v_min, dtype=float)


def pursuit_input(scenario: Scenario, state: np.ndarray, t: float, v_max: np.ndarray, e_d_goal: float, *,
                  v_min: np.ndarray | None = None) -> np.ndarray:
    """The completion law at the nominal ``state`` [x, y, z, ψ] and time ``t`` (s): turn onto the line of sight
    within one period, surge to bring e_d to ``e_d_goal`` (m) on top of the target's speed along the line of
    sight, heave to the target's depth; clipped to V̄ = [``v_min``, ``v_max``] (3,) each (m/s, m/s, rad/s;
    ``v_min`` None: −``v_max``)."""
    dt = scenario.controller.dt
    p = np.asarray(scenario.trajectory.position(t), dtype=float).reshape(3)
    pd_dot = np.asarray(scenario.trajectory.velocity(t), dtype=float).reshape(3)
    dx, dy = p[0] - state[0], p[1] - state[1]
    e_d = math.hypot(dx, dy)
    los = math.atan2(dy, dx)
    alpha = math.atan2(math.sin(los - state[3]), math.cos(los - state[3]))
    r = alpha / dt
    along = (pd_dot[0] * dx + pd_dot[1] * dy) / e_d if e_d > 0.0 else 0.0
    facing = math.cos(alpha)
    u = (along + PURSUIT_GAIN * (e_d - e_d_goal)) / facing if facing > 0.1 else 0.0
    w = pd_dot[2] + PURSUIT_GAIN * (p[2] - state[2])
    return np.clip(np.array([u, w, r]), _lower(v_max, v_min), np.asarray(v_max, dtype=float))


def completion_row(scenario: Scenario, law: TerminalLaw | None, end: np.ndarray, t: float, v_max: np.ndarray,
                   e_d_goal: float, *, v_min: np.ndarray | None = None) -> np.ndarray:
    """One completion row from the nominal ``end`` (4,) at ``t`` (s): the certified terminal ``law`` when given
    (inside V̄ by the theorem; the clip to [``v_min``, ``v_max``] only absorbs round-off), else
    :func:`pursuit_input`. ``v_min`` (3,): V̄'s lower corner (m/s, m/s, rad/s; None: −``v_max``)."""
    if law is None:
        return pursuit_input(scenario, end, t, v_max, e_d_goal, v_min=v_min)
    p = np.asarray(scenario.trajectory.position(t), dtype=float).reshape(3)
    v = np.asarray(scenario.trajectory.velocity(t), dtype=float).reshape(3)
    bound = np.asarray(v_max, dtype=float)
    return np.clip(law.command(end, p, v, scenario.controller.dt), _lower(bound, v_min), bound)


def candidate_plan(scenario: Scenario, plan: np.ndarray | None, age: int, x0: np.ndarray, t0: float,
                   v_max: np.ndarray, jump: np.ndarray | None, e_d_goal: float,
                   law: TerminalLaw | None = None, *, v_min: np.ndarray | None = None,
                   v_last: np.ndarray | None = None) -> np.ndarray | None:
    """The candidate at ``t0`` (s) from the measured ``x0`` (4,): rows ``age + 1 ..`` of the last accepted
    ``plan`` (N, 3), ``age`` periods old, completed row by row (:func:`completion_row`, inside V̄ =
    [``v_min``, ``v_max``], ``v_min`` None: −``v_max``; each completion row within ``jump`` (3,) of the row
    before it, when the plans are rate-limited). With the certified terminal ``law`` and no plan (``plan`` None,
    e.g. at t = 0), the candidate is the law's own N rows, the first within ``jump`` of ``v_last`` (3,; the command
    before it) when both are given; without a law, None when nothing of the plan is left to shift."""
    n = scenario.controller.horizon_steps
    if plan is None:
        if law is None:
            return None
        rows: list[np.ndarray] = []
    else:
        plan = np.asarray(plan, dtype=float)
        n = len(plan)
        rows = [row for row in plan[age + 1:]]
        if not rows and law is None:
            return None
    dt = scenario.controller.dt
    for _ in range(n - len(rows)):
        end = plan_arcs(x0, np.asarray(rows), dt, 1)[-1, -1] if rows else np.asarray(x0, dtype=float)
        v = completion_row(scenario, law, end, t0 + dt * len(rows), v_max, e_d_goal, v_min=v_min)
        before = rows[-1] if rows else v_last
        if jump is not None and before is not None:
            v = np.clip(np.clip(v, before - jump, before + jump), _lower(v_max, v_min), np.asarray(v_max, dtype=float))
        rows.append(v)
    return np.asarray(rows, dtype=float)


def settle_last_row(scenario: Scenario, law: TerminalLaw | None, plan: np.ndarray, x0: np.ndarray, t0: float,
                    v_max: np.ndarray, jump: np.ndarray | None, *, v_min: np.ndarray | None = None) -> np.ndarray:
    """``plan`` (N, 3) from the measured ``x0`` (4,) at ``t0`` (s) with its last row moved onto the row faces of
    the certified ``law`` (within (1 − :data:`SETTLE_MARGIN`) S of the law's row at the plan's end, a few
    fixed-point rounds: the end moves with the row), within ``jump`` of the row before it and inside
    V̄ = [``v_min``, ``v_max``]. Where the face and the jump about the row before it do not meet (the measured start
    moved the law's row by more than the solver's box allowed), the last row goes onto the face and the rows before
    it follow, each within ``jump`` of the next (:func:`_chain_back`). The solver does not know the faces
    (``docs/verify.md`` step 17c); the exact check still decides. ``plan`` itself when the law has no row faces."""
    plan = np.asarray(plan, dtype=float)
    if law is None or not law.has_rows or len(plan) < 2:
        return plan
    dt = scenario.controller.dt
    out = plan.copy()
    t_end = t0 + dt * len(out)
    p = np.asarray(scenario.trajectory.position(t_end), dtype=float).reshape(3)
    v = np.asarray(scenario.trajectory.velocity(t_end), dtype=float).reshape(3)
    faces = (1.0 - SETTLE_MARGIN) * np.array([law.row_u, law.row_w, law.row_r])
    low, high = _lower(np.asarray(v_max, dtype=float), v_min), np.asarray(v_max, dtype=float)
    head = plan_arcs(x0, out[:-1], dt, 1)[-1, -1]  # the state before the last row; moves only with a chain-back
    for _ in range(SETTLE_ROUNDS):
        end = plan_arcs(head, out[-1:], dt, 1)[-1, -1]
        target = law.command(end, p, v, dt)
        on_face = np.clip(np.clip(out[-1], target - faces, target + faces), low, high)
        if jump is None:
            out[-1] = on_face
            continue
        near = np.clip(on_face, np.maximum(low, out[-2] - jump), np.minimum(high, out[-2] + jump))
        if np.all(np.abs(near - target) <= faces):
            out[-1] = near
        else:
            out[-1] = on_face
            out = _chain_back(out, np.asarray(jump, dtype=float), low, high)
            head = plan_arcs(x0, out[:-1], dt, 1)[-1, -1]
    return out


def _chain_back(rows: np.ndarray, jump: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """``rows`` (N, 3) with each row from the second last down moved within ``jump`` of the row after it (and into
    [``low``, ``high``]): the last row stays where it is, the others move no more than it takes."""
    out = rows.copy()
    for i in range(len(out) - 2, -1, -1):
        out[i] = np.clip(np.clip(out[i], out[i + 1] - jump, out[i + 1] + jump), low, high)
    return out
