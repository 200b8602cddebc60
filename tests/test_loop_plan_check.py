"""Tests of tubekit.loop.plan_check: exact acceptance of a plan along its arcs (built by hand).

Geometry of the hand-built cases: a stationary target at p_d = (0, 3, 0); the vehicle at (-2, 3, 0)
heading +x (toward the target, e_o = 0); the plan is u = 0.4 m/s for 8 arcs of 0.1 s, so the nodes are at
x = -2 + 0.04 j on the line y = 3. An obstacle centred 0.5 m beside the midpoint of arc 3 with
radius + vehicle radius = 0.5002 m is missed at the nodes (distance sqrt(0.5^2 + 0.02^2) = 0.50040 m)
but hit half-way (0.5 m).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit.tiers import Tiers
from tubekit.loop.plan_check import RATE_TOLERANCE, PlanCheck, check_plan, check_rates, check_sway, plan_arcs
from tubekit.model.backup import BackupPlan, SafeSet, StationKeeping
from tubekit.scenario import Obstacle
from tubekit.tightening import Tightening

X0 = np.array([-2.0, 3.0, 0.0, 0.0])
PLAN = np.tile([0.4, 0.0, 0.0], (8, 1))
GRAZE = Obstacle((-2.0 + 0.14, 3.5, 0.0), 0.3002)


def _tight(**changes) -> Tightening:
    base = dict(v_max=np.array([0.4, 0.3, 0.5]), e_d_min=0.5, e_o_max=0.5, e_z_max=1.0, e_d_max=3.0,
                obstacle_margin=0.0, sigma=1.0, margins=np.zeros((8, 4)), rates=np.zeros(4),
                tube=np.zeros(3), region=np.array([0.5, 3.0, 1.0, 0.5]), tiers=Tiers(True, True))
    base.update(changes)
    return Tightening(**base)


def test_grazing_between_nodes_is_rejected(stationary):
    nodes = X0[:2] + np.outer(np.arange(9) * 0.04, [1.0, 0.0])
    clear_at_nodes = np.linalg.norm(nodes - GRAZE.center[:2], axis=1) - GRAZE.radius - stationary.vehicle_radius
    assert np.all(clear_at_nodes > 1e-4)        # the nodes are clear ...
    res = check_plan(stationary, _tight(), 0.0, X0, PLAN, [GRAZE], sign=-1)
    assert isinstance(res, PlanCheck)
    assert not res.ok and res.where == "obstacle 0"   # ... the arc is not
    assert res.slack == pytest.approx(0.5 - 0.5002, abs=1e-9)


def test_input_outside_v_bar_is_rejected(stationary):
    plan = PLAN.copy()
    plan[5, 2] = -0.51
    res = check_plan(stationary, _tight(), 0.0, X0, plan, [], sign=-1)
    assert not res.ok and res.where == "input outside V_bar" and res.slack == pytest.approx(-0.01)
    res = check_plan(stationary, _tight(v_max=np.array([0.39, 0.3, 0.5])), 0.0, X0, PLAN, [], sign=-1)
    assert not res.ok and res.where == "input outside V_bar"


def test_a_plan_far_from_everything_is_accepted(stationary):
    far = Obstacle((-6.0, -6.0, 0.0), 0.4)
    res = check_plan(stationary, _tight(), 0.0, X0, PLAN, [far], sign=-1)
    # the tightest constraint: |e_o| = 0 against 0.5, e_d = 1.68 against 3 - 1.68 = 1.32 and 1.68 - 0.5 = 1.18
    assert res.ok and res.slack == pytest.approx(0.5)
    assert res.where == "|e_o|"


@pytest.mark.parametrize("plan, why", [
    (PLAN[:7], "fewer rows than arcs"),
    (np.full((8, 3), np.nan), "not finite"),
    (PLAN.ravel(), "one dimension"),
])
def test_malformed_plans_are_rejected(stationary, plan, why):
    res = check_plan(stationary, _tight(), 0.0, X0, plan, [], sign=-1)
    assert not res.ok and res.where == "plan shape or values" and res.slack == -math.inf, why


def test_a_plan_with_two_columns_is_rejected(stationary):
    res = check_plan(stationary, _tight(), 0.0, X0, PLAN[:, :2], [], sign=-1)
    assert not res.ok and res.where == "plan shape or values"


@pytest.mark.parametrize("changes, where", [
    (dict(margins=np.column_stack([np.full(8, 1.2), np.zeros((8, 3))]), region=np.array([0.5, 5.0, 1.0, 0.5])),
     "e_d >= epsilon"),
    (dict(margins=np.column_stack([np.zeros((8, 2)), np.full(8, 0.6), np.zeros(8)])), "|e_o|"),
    (dict(region=np.array([0.5, 1.9, 1.0, 0.5])), "e_d <= e_d_max"),
])
def test_margins_tighten_the_error_constraints(stationary, changes, where):
    res = check_plan(stationary, _tight(**changes), 0.0, X0, PLAN, [], sign=-1)
    assert not res.ok and res.where == where


def test_rates_pad_the_samples(stationary):
    """An obstacle missed by 0.01 m everywhere is rejected once ||p'|| * spacing / 2 exceeds 0.01 m."""
    side = Obstacle((-1.84, 3.0 + 0.2 + 0.3 + 0.01, 0.0), 0.3)
    assert check_plan(stationary, _tight(), 0.0, X0, PLAN, [side], sign=-1).ok
    pad = np.array([0.0, 0.0, 0.0, 0.5 / (0.5 * 0.01)])   # spacing 0.01 s -> pad 0.5 * 0.01 * rate = 0.5 m
    res = check_plan(stationary, _tight(rates=pad), 0.0, X0, PLAN, [side], sign=-1)
    assert not res.ok and res.where == "obstacle 0"


def test_the_hemisphere_is_checked(stationary):
    away = X0.copy()
    away[3] = math.pi                               # heading -x: away from the target
    back = np.tile([-0.1, 0.0, 0.0], (8, 1))        # reversing toward it keeps e_d in R
    res = check_plan(stationary, _tight(), 0.0, away, back, [], sign=-1)
    assert not res.ok and res.where == "hemisphere"
    assert check_plan(stationary, _tight(), 0.0, away, back, [], sign=1).ok


def test_the_workspace_is_checked(stationary):
    small = stationary.with_changes(workspace=((-2.1, 2.5, -1.0), (1.0, 3.5, 1.0)))
    res = check_plan(small, _tight(), 0.0, X0, PLAN, [], sign=-1)
    assert not res.ok and res.where == "workspace"
    assert res.slack == pytest.approx((-2.0 - -2.1) - 0.2, abs=1e-9)    # x - x_lo - vehicle radius at x0


@given(u=st.floats(-0.4, 0.4), r=st.floats(-0.5, 0.5), w=st.floats(-0.3, 0.3), psi0=st.floats(-3.0, 3.0))
def test_plan_arcs_are_the_exact_unicycle(u, r, w, psi0):
    """Property: the sampled arcs follow x = x0 + u (sin(psi0 + r t) - sin psi0) / r,
    y = y0 - u (cos(psi0 + r t) - cos psi0) / r (straight line when r = 0), z = z0 + w t, and chain."""
    x0 = np.array([1.0, -2.0, 0.5, psi0])
    inputs = np.tile([u, w, r], (3, 1))
    arcs = plan_arcs(x0, inputs, 0.1, 4)
    assert arcs.shape == (3, 5, 4)
    t = (np.arange(3)[:, None] * 0.1 + np.linspace(0, 0.1, 5)[None, :])
    psi = psi0 + r * t
    if abs(r) > 1e-6:
        x = 1.0 + u * (np.sin(psi) - math.sin(psi0)) / r
        y = -2.0 - u * (np.cos(psi) - math.cos(psi0)) / r
    else:
        x, y = 1.0 + u * t * np.cos(psi0), -2.0 + u * t * np.sin(psi0)
    np.testing.assert_allclose(arcs[..., 0], x, atol=1e-9)
    np.testing.assert_allclose(arcs[..., 1], y, atol=1e-9)
    np.testing.assert_allclose(arcs[..., 2], 0.5 + w * t, atol=1e-12)
    np.testing.assert_allclose(arcs[..., 3], psi, atol=1e-12)


@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(1, 12), samples=st.integers(1, 12))
def test_plan_arcs_equal_the_arcs_chained_one_by_one(seed, n, samples):
    """Property: the vectorised plan_arcs returns the very floats of nominal_arc chained arc by arc."""
    from tubekit.loop.plan_check import _plan_arcs_chained
    rng = np.random.default_rng(seed)
    x0 = rng.normal(size=4) * [5.0, 5.0, 1.0, 3.0]
    inputs = rng.uniform(-1.0, 1.0, (n, 3)) * [0.4, 0.2, 0.6]
    inputs[rng.random(n) < 0.3, 2] = 0.0  # straight arcs too
    np.testing.assert_array_equal(plan_arcs(x0, inputs, 0.1, samples), _plan_arcs_chained(x0, inputs, 0.1, samples))


# ---- the terminal condition (tightening.backup) and the safe-only tier ------------------------------------
# PLAN ends at p* = (-1.68, 3, 0), sensed from X0 (0.32 m away). The backup's footprint with the 0.2 m vehicle
# radius is R_f = 0.8 + 0.2 = 1.0 m, H_f = 0.1 + 0.2 = 0.3 m; its sensed spread hypot(0.32 + 0.8, 0.1).

BACKUP = BackupPlan(StationKeeping(0.2, 0.5, 0.05, 0.3, 0.05), SafeSet(0.8, 0.45, 0.1), handover=(0.35, 0.1))
END = np.array([-1.68, 3.0, 0.0])


def test_a_plan_meeting_the_terminal_condition_is_accepted(stationary):
    far = Obstacle((-6.0, -6.0, 0.0), 0.4)
    res = check_plan(stationary, _tight(backup=BACKUP), 0.0, X0, PLAN, [far], sign=-1)
    assert res.ok and res.where == "terminal: sensed region"
    assert res.slack == pytest.approx(1.5 - 0.2 - math.hypot(0.32 + 0.8, 0.1))


def test_an_obstacle_inside_the_terminal_cylinder_rejects_the_plan(stationary):
    # 1.29 m beside the end: 0.29 m from the cylinder, radius 0.3 -> -0.01; the path itself passes 0.79 m clear
    near_end = Obstacle((END[0], END[1] + 1.29, 0.0), 0.3)
    assert check_plan(stationary, _tight(), 0.0, X0, PLAN, [near_end], sign=-1).ok
    res = check_plan(stationary, _tight(backup=BACKUP), 0.0, X0, PLAN, [near_end], sign=-1)
    assert not res.ok and res.where == "terminal: obstacle 0" and res.slack == pytest.approx(-0.01)


def test_a_terminal_cylinder_across_a_wall_rejects_the_plan(stationary):
    walled = stationary.with_changes(workspace=((-10.0, -10.0, -5.0), (-0.69, 10.0, 5.0)))
    assert check_plan(walled, _tight(), 0.0, X0, PLAN, [], sign=-1).ok
    res = check_plan(walled, _tight(backup=BACKUP), 0.0, X0, PLAN, [], sign=-1)
    assert not res.ok and res.where == "terminal: workspace" and res.slack == pytest.approx(-0.01)


def test_a_terminal_set_beyond_the_sensed_region_rejects_the_plan(stationary):
    short_sight = stationary.with_changes(sensing_range=1.3)
    assert check_plan(short_sight, _tight(), 0.0, X0, PLAN, [], sign=-1).ok
    res = check_plan(short_sight, _tight(backup=BACKUP), 0.0, X0, PLAN, [], sign=-1)
    assert not res.ok and res.where == "terminal: sensed region"
    assert res.slack == pytest.approx(1.3 - 0.2 - math.hypot(1.12, 0.1))


def test_without_the_tracking_tier_only_position_constraints_are_checked(stationary):
    # e_o_max = 0.01 against a plan heading 0.2 rad off the line of sight: e ∈ R fails, positions are fine
    x0 = np.array([-2.0, 3.0, 0.0, 0.2])
    tight = _tight(e_o_max=0.01, region=np.array([0.5, 3.0, 1.0, 0.01]), backup=BACKUP)
    assert check_plan(stationary, tight, 0.0, x0, PLAN, [], sign=-1).where == "|e_o|"
    safe_only = _tight(e_o_max=0.01, region=np.array([0.5, 3.0, 1.0, 0.01]), backup=BACKUP,
                       tiers=Tiers(True, False))
    res = check_plan(stationary, safe_only, 0.0, x0, PLAN, [], sign=-1)
    assert res.ok and res.where.startswith("terminal")
    blocked = Obstacle((-1.5, 4.2, 0.0), 0.3)  # 0.15 m from the footprint about the end (-1.686, 3.064)
    res = check_plan(stationary, safe_only, 0.0, x0, PLAN, [blocked], sign=-1)
    assert not res.ok and res.where == "terminal: obstacle 0"


# ---- the rate rows (issue 22 design (1)): J = rate dt = (0.1, 0.1, 0.2) with rate (1, 1, 2) ----------------

RAMP = np.array([[u, 0.0, 0.0] for u in (0.05, 0.1, 0.15, 0.2, 0.2, 0.15, 0.1, 0.05)])  # steps 0.05, rests at 0.05


def _rated(sc):
    return sc.with_changes(**{"limits.rate": [1.0, 1.0, 2.0]})


def _with_u(u):
    plan = np.zeros((8, 3))
    plan[:, 0] = u
    return plan


@pytest.mark.parametrize("plan, v_last, where, slack", [
    (_with_u([0.05, 0.1, 0.3, 0.3, 0.2, 0.1, 0.05, 0.0]), None, "rate: between nodes", -0.1),   # 0.1 -> 0.3
    (RAMP, [0.3, 0.0, 0.0], "rate: first node", -0.15),                                          # 0.3 -> 0.05
    (_with_u([0.05, 0.1, 0.15, 0.2, 0.25, 0.25, 0.2, 0.15]), None, "rate: terminal rest", -0.05),  # ends at 0.15
    (RAMP + [0.0, 0.0, 0.2 + 1e-8], [0.0, 0.0, 0.0], "rate: first node", -1e-8),                 # r: just over J
])
def test_a_plan_breaking_a_rate_row_is_rejected_naming_it(stationary, plan, v_last, where, slack):
    res = check_plan(_rated(stationary), _tight(backup=BACKUP), 0.0, X0, plan, [], sign=-1, v_last=v_last)
    assert not res.ok and res.where == where and res.slack == pytest.approx(slack, abs=1e-12)


def test_rate_rows_pass_within_the_tolerance_and_only_the_rows_that_apply(stationary):
    sc = _rated(stationary)
    assert check_rates(sc, _tight(backup=BACKUP), RAMP, v_last=[0.0, 0.0, 0.0]).ok
    # r = 0.2 + 5e-10 from rest: over J by less than RATE_TOLERANCE = 1e-9
    assert check_rates(sc, _tight(backup=BACKUP), RAMP + [0.0, 0.0, 0.2 + 5e-10], v_last=[0.0, 0.0, 0.0]).ok
    ends_moving = _with_u([0.05, 0.1, 0.15, 0.2, 0.25, 0.25, 0.2, 0.15])
    assert check_rates(sc, _tight(), ends_moving).ok                 # no backup: no terminal rest
    assert check_rates(sc, _tight(backup=BACKUP), RAMP).ok           # no v_last: no first-node row
    assert check_rates(stationary, _tight(backup=BACKUP), _with_u([0.0, 0.4] * 4)).where == "no rate limit"
    assert check_plan(sc, _tight(backup=BACKUP), 0.0, X0, RAMP, [], sign=-1, v_last=[0.0, 0.0, 0.0]).ok
    assert 0.0 < RATE_TOLERANCE <= 1e-9


def test_a_ramped_backup_blends_so_plans_need_not_end_at_rest(stationary):
    """A backup with a ramp starts from the last applied command: the terminal-rest row is dropped."""
    import dataclasses
    ramped = dataclasses.replace(BACKUP, law=dataclasses.replace(BACKUP.law, surge_fade=0.1, yaw_fade=0.1, ramp=1.0))
    ends_moving = _with_u([0.05, 0.1, 0.15, 0.2, 0.25, 0.25, 0.2, 0.15])
    sc = _rated(stationary)
    assert _tight(backup=BACKUP).terminal_rest and not _tight(backup=ramped).terminal_rest
    assert check_rates(sc, _tight(backup=BACKUP), ends_moving).where == "rate: terminal rest"
    assert check_rates(sc, _tight(backup=ramped), ends_moving).ok


# ---- a minimum surge (limits.u_min): V_bar's lower corner is a surge floor, checked like its upper corner ------

FLOOR = np.array([0.15, -0.3, -0.5])   # v_hat_u >= 0.15 m/s (u_min = 0.1 plus kappa_bar_u = 0.05)


def test_a_plan_slowing_below_the_surge_floor_is_rejected_and_at_the_floor_accepted(stationary):
    keep_moving = stationary.with_changes(**{"limits.u_min": 0.1})
    floored = _tight(v_min=FLOOR)
    slow = PLAN.copy()
    slow[5, 0] = 0.14                                  # 0.01 m/s below the floor in one row
    res = check_plan(keep_moving, floored, 0.0, X0, slow, [], sign=-1)
    assert not res.ok and res.where == "input outside V_bar" and res.slack == pytest.approx(0.14 - 0.15, abs=1e-12)
    assert check_plan(keep_moving, _tight(), 0.0, X0, slow, [], sign=-1).ok   # the symmetric box lets it pass
    at_floor = PLAN.copy()
    at_floor[5, 0] = 0.15                              # exactly on the floor: inside V_bar
    assert check_plan(keep_moving, floored, 0.0, X0, at_floor, [], sign=-1).ok


def test_the_terminal_rest_is_about_the_loiters_surge(stationary):
    """With the loiter (no ramp: it starts at its own surge u_l = 0.25 m/s) a plan ends within J of (u_l, 0, 0)
    instead of at rest: the ramp down to rest that station keeping needs is refused, one ending at u_l passes."""
    from tubekit.model.loiter import Loiter
    loiter = BackupPlan(Loiter(0.25, 0.3, 0.5, 0.05, 0.3), BACKUP.safe_set, handover=BACKUP.handover)
    sc = _rated(stationary)                         # J = (0.1, 0.1, 0.2)
    tight = _tight(backup=loiter)
    assert tight.terminal_rest and np.array_equal(tight.terminal_command, [0.25, 0.0, 0.0])
    res = check_rates(sc, tight, RAMP)              # ends at 0.05 m/s: 0.2 below u_l, J = 0.1
    assert not res.ok and res.where == "rate: terminal rest" and res.slack == pytest.approx(0.1 - 0.2, abs=1e-12)
    cruise = _with_u([0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.3, 0.3])   # ends 0.05 above u_l
    assert check_rates(sc, tight, cruise).ok
    assert check_rates(sc, _tight(backup=BACKUP), cruise).where == "rate: terminal rest"   # station keeping: at rest


@pytest.mark.parametrize("sway, release, ok", [
    (0.0, math.inf, True), (0.3, math.inf, True),          # a law without sway: never holds a plan back
    (4e-4, 5e-4, True), (-5e-4, 5e-4, True),              # within the release: the jump to 0 is charged
    (6e-4, 5e-4, False), (-0.1, 5e-4, False),
])
def test_a_plan_takes_over_only_once_the_sway_command_is_within_the_release(sway, release, ok):
    gate = check_sway(sway, release)
    assert (gate is None) is ok
    if not ok:
        assert not gate.ok and not gate.safe and gate.where.startswith("sway")
        assert gate.slack == pytest.approx(release - abs(sway))
