"""Exact acceptance of a FHOCP plan along its arcs (the step the sampled-data theorem relies on).

The FHOCP enforces its constraints at the nodes, linearised and softened. The
certificate does not rely on that: a plan is *accepted* only when
:func:`check_plan` verifies, along every arc j of the exact nominal trajectory
(the unicycle arcs of :func:`tubekit.plant.kinematic.nominal_arc`, the same the loop
follows), that

* the plan has exactly N rows and v̂_j is in V̄ = [``tightening.v_low``, ``tightening.v_max``] (both corners:
  with a minimum surge the lower one is a surge floor; compared exactly: the loop projects a solver's plan onto
  V̄ first, so no tolerance stands outside the proof);
* with a rate limit (``scenario.limits.rate``, J = rate · dt per component), the rate rows
  (:func:`check_rates`): |v̂_{j+1} − v̂_j| <= J, |v̂_0 − v_last| <= J (v_last the command applied in the
  last tick before the plan, when given) and, when the tightening gates plans by a certified backup that
  does not blend (``tightening.terminal_rest``: no ramp to blend from the last command), the terminal
  rest |v̂_{n−1} − c| <= J about the backup's hand-over command c = ``tightening.terminal_command`` (0 for station
  keeping, (u_l, 0, 0) for the loiter), each up to the absolute tolerance :data:`RATE_TOLERANCE`;
* ε + M_d[j] <= e_d <= e_d_max - M_d[j], |e_z| <= e_z_max - M_z[j],
  |e_o| <= e_o_max - M_o[j], and the heading stays in the certified hemisphere;
* the vehicle ball inflated by M_pos[j] is clear of every known obstacle and
  inside the workspace;
* with the tracking theorem's terminal law (``tightening.terminal_law``), the plan's nominal end lies in its
  terminal set X_f ("terminal set: ...", :meth:`tubekit.model.terminal_law.TerminalLaw.slacks`), and under
  rate-limited plans its last row within the row faces of the law's row there
  (:meth:`tubekit.model.terminal_law.TerminalLaw.row_slacks`);
* when the tightening has a certified backup (``tightening.terminal_backup``), the plan's nominal end position
  meets the terminal condition (:func:`tubekit.loop.terminal.terminal_condition`: the backup's
  safe set there, inflated by the vehicle ball, is clear of every known obstacle, inside the
  workspace and inside the region sensed from ``x0``);

at ``samples_per_arc + 1`` points per arc, each constraint tightened further by
rate · spacing / 2 with the certificate's bound on its rate along an arc
(:attr:`Tightening.rates`), so the check covers the whole arc, not only its
samples. A plan that fails is replaced by the previous accepted plan, replayed.

When ``tightening.tiers`` does not give tracking (the safe-only design, or a best-effort run), only the
position constraints are checked (V̄, obstacles, workspace, terminal condition,
sensing), not e ∈ R nor the hemisphere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from tubekit.design_inputs import ARC_SAMPLES, RATE_TOLERANCE
from tubekit.model.errors import heading_cosine
from tubekit.model.kinematics import unicycle_step
from tubekit.scenario import Obstacle, Scenario
from tubekit.loop.terminal import terminal_condition
from tubekit.tightening import Tightening

__all__ = ["PlanCheck", "check_plan", "check_rates", "rate_slacks", "box_excess", "plan_arcs", "tracking_checked",
           "RATE_TOLERANCE", "check_sway"]

#: Points per arc of the check (plus the arc's end).
SAMPLES_PER_ARC = ARC_SAMPLES


@dataclass(frozen=True)
class PlanCheck:
    """Outcome of :func:`check_plan`: ``ok``, the smallest slack (error units or m), where it is, and
    the plan's nominal end state ``end`` (4,) over the certified horizon (None when not rolled out) and the
    backup's ``anchor`` (3,) the terminal condition was met about (None without a backup).

    ``safe`` says whether every constraint the safe tier rests on holds (V̄, the rate rows, the
    positions, the terminal condition, the sensed region): a plan that is not ``ok`` only because its
    error leaves R is still ``safe`` (what a recovery plan needs, :attr:`Tightening.recovers`)."""

    ok: bool
    slack: float
    where: str
    end: np.ndarray | None = None
    safe: bool = False
    anchor: tuple[float, float, float] | None = None


def plan_arcs(x0: np.ndarray, inputs: np.ndarray, dt: float, samples: int) -> np.ndarray:
    """States (N, samples + 1, 4) along the exact nominal arcs of ``inputs`` (N, 3) from ``x0``.

    One compiled pass (:func:`tubekit.model.compiled_arcs.plan_arcs`): each arc starts at the running sum (the
    same sequential additions as chaining :func:`~tubekit.plant.kinematic.nominal_arc` arc by arc) of the
    previous arcs' exact increments, and is evaluated with the same formula.
    """
    from tubekit.model import compiled_arcs

    tau = np.linspace(0.0, dt, samples + 1)
    return compiled_arcs.plan_arcs(np.asarray(x0, dtype=float), np.asarray(inputs, dtype=float).reshape(-1, 3), tau)


def _plan_arcs_chained(x0: np.ndarray, inputs: np.ndarray, dt: float, samples: int) -> np.ndarray:
    """:func:`plan_arcs` arc by arc with the model's numpy formula, :func:`tubekit.model.kinematics.unicycle_step`
    (the reference the compiled pass must equal)."""
    tau = np.linspace(0.0, dt, samples + 1)
    out = np.empty((len(inputs), samples + 1, 4))
    x = np.asarray(x0, dtype=float)
    for j, v in enumerate(np.asarray(inputs, dtype=float)):
        out[j] = unicycle_step(x, v, tau)
        x = out[j, -1]
    return out


def rate_slacks(inputs: np.ndarray, jump: np.ndarray, v_last: np.ndarray | None,
                rest: bool, *, target: np.ndarray | None = None) -> dict[str, float]:
    """Smallest slack (J − |jump|, >= 0 is fine) of each rate row of ``inputs`` (n, 3): "rate: between
    nodes", "rate: first node" (with ``v_last``) and "rate: terminal rest" (with ``rest``: J − |v̂_{n−1} − c|,
    c = ``target`` (3,), m/s, m/s, rad/s; None: 0, the plan ends at rest)."""
    v = np.asarray(inputs, dtype=float)
    j = np.asarray(jump, dtype=float)
    out = {"rate: between nodes": float(np.min(j - np.abs(v[1:] - v[:-1]), initial=math.inf))}
    if v_last is not None:
        out["rate: first node"] = float(np.min(j - np.abs(v[0] - np.asarray(v_last, dtype=float))))
    if rest:
        end = v[-1] if target is None else v[-1] - np.asarray(target, dtype=float)
        out["rate: terminal rest"] = float(np.min(j - np.abs(end)))
    return out


def check_rates(scenario: Scenario, tight: Tightening, inputs: np.ndarray,
                v_last: np.ndarray | None = None) -> PlanCheck:
    """The rate rows alone (module doc) on the first ``tight.horizon_arcs`` inputs (all without margins).

    ``ok`` without a rate limit; otherwise ok when every slack is >= −:data:`RATE_TOLERANCE`, and
    ``where`` names the tightest row.
    """
    jump = scenario.limits.jump(scenario.controller.dt)
    v = np.asarray(inputs, dtype=float)
    if jump is None:
        return PlanCheck(True, math.inf, "no rate limit")
    if v.ndim != 2 or v.shape[1] != 3 or len(v) == 0 or not np.all(np.isfinite(v)):
        return PlanCheck(False, -math.inf, "plan shape or values")
    if tight.horizon_arcs:
        v = v[:tight.horizon_arcs]
    slacks = rate_slacks(v, jump, v_last, tight.terminal_rest, target=tight.terminal_command)
    where, worst = min(slacks.items(), key=lambda kv: kv[1])
    return PlanCheck(worst >= -RATE_TOLERANCE, worst, where)


def check_sway(sway_last: float, release: float) -> PlanCheck | None:
    """None when a plan may take over from the last sway command ``sway_last`` (m/s), else the refusal: a plan never
    commands sway, so the sway command jumps to 0 when one is accepted, and the velocity loop's bound charges that
    jump at most the backup law's ``release`` (m/s; :mod:`tubekit.model.hold` turns the nose until its sway command
    is that small; ∞ for a law without sway)."""
    if abs(float(sway_last)) <= release:
        return None
    return PlanCheck(False, release - abs(float(sway_last)),
                     f"sway: the last sway command {sway_last:.4g} m/s is more than {release:.4g} m/s from 0")


def box_excess(inputs: np.ndarray, tight: Tightening) -> float:
    """The largest amount (m/s or rad/s; <= 0: inside) by which a row of ``inputs`` (n, 3) leaves V̄ =
    [``tight.v_low``, ``tight.v_max``], above the upper corner or below the lower one (a surge floor)."""
    high = np.asarray(tight.v_max, dtype=float)[None, :]
    return float(np.max(np.maximum(inputs - high, tight.v_low[None, :] - inputs)))  # |v̂| - v_max when symmetric


def _error_slacks(tight: Tightening, e: np.ndarray, cos_rel: np.ndarray, margins: np.ndarray,
                  pad: np.ndarray, sign: int) -> dict[str, np.ndarray]:
    """Per-sample slack (>= 0 is fine) of each error constraint; ``margins``, ``pad`` are (N, 1) columns."""
    reg = tight.region
    eps, ed_max, ez_max, eo_max = reg.epsilon, reg.e_d_max, reg.e_z_max, reg.e_o_max
    md, mz, mo = (margins[:, k:k + 1] + pad[k] for k in range(3))
    return {"e_d >= epsilon": e[..., 0] - eps - md, "e_d <= e_d_max": ed_max - md - e[..., 0],
            "|e_z|": ez_max - mz - np.abs(e[..., 1]), "|e_o|": eo_max - mo - np.abs(e[..., 2]),
            "hemisphere": sign * cos_rel if sign else np.abs(cos_rel)}


def _position_slacks(scenario: Scenario, pos: np.ndarray, margin: np.ndarray,
                     obstacles: Sequence[Obstacle]) -> dict[str, np.ndarray]:
    r = scenario.vehicle_radius + margin
    out: dict[str, np.ndarray] = {}
    for i, o in enumerate(obstacles):
        out[f"obstacle {i}"] = np.linalg.norm(pos - np.asarray(o.center), axis=-1) - o.radius - r
    if scenario.workspace is not None:
        lo, hi = (np.asarray(b) for b in scenario.workspace)
        out["workspace"] = np.minimum((pos - lo).min(axis=-1), (hi - pos).min(axis=-1)) - r
    return out


def tracking_checked(tight: Tightening) -> bool:
    """True when ``tight.tiers`` gives tracking (otherwise e ∈ R is not checked, only the positions)."""
    return tight.tiers.tracking


def _terminal_slack(scenario: Scenario, tight: Tightening, x0: np.ndarray, end: np.ndarray,
                    obstacles: Sequence[Obstacle]) -> tuple[dict[str, np.ndarray], tuple[float, float, float] | None]:
    """The terminal condition's slack (m) under "terminal: <part>" and the anchor it holds about (empty and None
    without a backup)."""
    if tight.terminal_backup is None:
        return {}, None
    check = terminal_condition(end[:3], tight.terminal_backup, scenario.vehicle_radius, obstacles, scenario.workspace,
                               np.asarray(x0, dtype=float)[:3], scenario.sensing_range)
    slack = np.array([check.slack if check.ok else min(check.slack, -1e-12)])
    return {f"terminal: {check.reason}": slack}, check.anchor


def check_plan(scenario: Scenario, tight: Tightening, t0: float, x0: np.ndarray, inputs: np.ndarray,
               obstacles: Sequence[Obstacle], sign: int, samples: int = SAMPLES_PER_ARC, *,
               v_last: np.ndarray | None = None) -> PlanCheck:
    """Verify a plan (module doc). ``sign`` is the certified hemisphere (-1 toward, +1 away, 0 both);
    ``v_last`` (3,) the command before the plan (rate row (b); None: not checked)."""
    from tubekit.model import compiled_arcs

    inputs = np.asarray(inputs, dtype=float)
    n = tight.horizon_arcs
    if inputs.ndim != 2 or inputs.shape[1] != 3 or inputs.shape[0] != n or not np.all(np.isfinite(inputs)):
        return PlanCheck(False, -math.inf, "plan shape or values")
    over = box_excess(inputs, tight)
    if over > 0.0:
        return PlanCheck(False, -float(over), "input outside V_bar")
    rates = check_rates(scenario, tight, inputs, v_last)
    if not rates.ok:
        return rates
    dt = scenario.controller.dt
    arcs = plan_arcs(x0, inputs, dt, samples)
    times = t0 + dt * (np.arange(n)[:, None] + np.linspace(0.0, 1.0, samples + 1)[None, :])
    desired = np.asarray(scenario.trajectory.position(times.reshape(-1)), dtype=float).reshape(n, samples + 1, 3)
    e = compiled_arcs.error_coordinates(arcs.reshape(-1, 4), desired.reshape(-1, 3), 0.0).reshape(n, samples + 1, 3)
    cos_rel = heading_cosine(arcs, desired)
    pad = 0.5 * (dt / samples) * np.asarray(tight.rates, dtype=float)
    m = np.asarray(tight.margins, dtype=float)
    safety, anchor = _terminal_slack(scenario, tight, x0, arcs[-1, -1], obstacles)
    safety.update(_position_slacks(scenario, arcs[..., :3], m[:, 3:4] + pad[3], obstacles))
    safe_name, safe_worst = _worst(safety)
    slacks = _error_slacks(tight, e, cos_rel, m, pad, sign) if tracking_checked(tight) else {}
    if tight.terminal_law is not None and tracking_checked(tight):
        end_time = t0 + dt * n
        end_target = np.asarray(scenario.trajectory.position(end_time), dtype=float).reshape(3)
        law = tight.terminal_law
        end_velocity = (np.asarray(scenario.trajectory.velocity(end_time), dtype=float).reshape(3)
                        if law.has_bearing or law.has_rows else None)  # only the bearing and row faces read it
        faces = law.slacks(arcs[-1, -1], end_target, end_velocity)
        if law.has_rows:
            faces.update(law.row_slacks(arcs[-1, -1], end_target, end_velocity, inputs[n - 1], dt))
        slacks.update({k: np.array([v]) for k, v in faces.items()})
    worst_name, worst = _worst(slacks)
    if safe_worst < worst or math.isnan(safe_worst):
        worst_name, worst = safe_name, safe_worst
    return PlanCheck(ok=worst >= 0.0 and not math.isnan(worst), slack=worst, where=worst_name, end=arcs[-1, -1],
                     safe=safe_worst >= 0.0 and not math.isnan(safe_worst), anchor=anchor)


def _worst(slacks: dict[str, np.ndarray]) -> tuple[str, float]:
    """The name and value of the smallest slack ("nothing to check", inf without any)."""
    return min(((k, float(np.min(v))) for k, v in slacks.items()), key=lambda kv: kv[1],
               default=("nothing to check", math.inf))
