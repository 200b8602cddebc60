"""verify.theorem.tiers: the safe and tracking tiers, the safe-only design at sigma = 0 and the certificate's backup.

Numbers are recomputed by hand from the scenarios: the paper's current 0.1 m/s per axis plus the sway bound
0.1 * 0.4 * 0.5 = 0.02 gives omega_xy = 0.12 m/s, omega_z = 0.1 m/s; delta = 0.1 s.
"""

from __future__ import annotations

from tubekit.tiers import Tiers

import math
from pathlib import Path

import pytest

from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.scenario import Obstacle, paper_scenario
from tubekit.design_inputs import handed_sigma
from verify.theorem.tiers import SAFE_PREFIX, initial_backup, is_safe_condition, position_tube, tiers_of


def test_paper_currents_certifies_both_tiers_with_a_backup(pc_cert):
    c = pc_cert
    assert c.tiers == Tiers(True, True) and c.certified and c.safe_design is None
    b = c.backup
    assert b.certified and b.omega_xy == c.disturbance.omega_xy and b.omega_z == c.disturbance.omega_z
    assert b.tick == pytest.approx(0.01)                                      # 100 Hz
    m = c.margins
    room = b.safe_set.level - b.safe_set.shape - m.position[-1]               # c − β − M_pos: where the anchor may go
    assert 0.0 < b.anchor_reach <= room and b.anchor_reach == pytest.approx(room, rel=1e-6)
    assert b.handover == (m.position[-1] + b.anchor_reach, m.e_z[-1])         # the last arc's margins + the reach
    assert b.safe_set.handover_radius >= b.handover[0] and b.safe_set.depth >= m.e_z[-1]
    names = [x.condition for x in b.conditions]
    assert {"backup_level_set", "backup_handover", "backup_initial"} <= set(names)
    assert all(n.startswith("backup") for n in names)
    safe = {x.condition for x in c.tier_conditions["safe"]}
    tracking = {x.condition for x in c.tier_conditions["tracking"]}
    assert safe < tracking                                                    # tracking needs everything safety does
    assert {"sensing", "tube", "v_bar[u]", "sway_bound", "obstacles[0,1]", "backup_level_set"} <= safe
    assert not {"keep_up[u]", "yaw_budget", "e_bar[e_o]", "initial", "target_in_workspace"} & safe


def test_the_paper_scenario_certifies_the_safe_tier_only(paper_cert):
    c = paper_cert
    assert c.tiers == Tiers(True, False) and not c.certified
    assert set(c.tier_failures["tracking"]) == {"keep_up[u]", "e_bar[e_o]"}
    s = c.safe_design
    assert s.sigma == 0.0 and all(x.condition.startswith(SAFE_PREFIX) for x in s.conditions)
    # sigma = 0: ||dp_xy|| <= omega_xy delta = 0.012 m, |dz| <= omega_z delta = 0.01 m per period; the replay's
    # position margin grows by hypot(0.012, 0.01) per arc (no heading error on the kinematic plant)
    assert s.tube.p_xy == pytest.approx(0.012) and s.tube.p_z == pytest.approx(0.01) and s.tube.psi == 0.0
    step = math.hypot(0.012, 0.01)
    assert s.margins.position == pytest.approx([step * (j + 1) for j in range(8)])
    assert s.v_bar == (0.4, 0.3, 0.5)                                         # no feedback: V_bar = V
    reach = c.backup.anchor_reach                                             # c − β − M_pos, the room left
    assert reach == pytest.approx(c.backup.safe_set.level - c.backup.safe_set.shape - s.margins.position[-1], rel=1e-6)
    assert (c.backup.safe_set.level, c.backup.safe_set.shape) == (0.75, 0.4) and reach == pytest.approx(0.35 - 8 * step)
    assert c.backup.certified and c.backup.handover == (s.margins.position[-1] + reach, s.margins.e_z[-1])
    assert "safe: certified; tracking: not certified (keep_up[u], e_bar[e_o])" in c.summary()
    assert c.inputs.sigma == 0.0


def test_the_position_tube_at_sigma_zero_is_the_disturbance_times_the_period(paper_cert):
    p = paper_cert.safe_design.problem
    t = position_tube(p)
    assert t.certified and t.kappa == (0.0, 0.0, 0.0)
    assert t.rho[0] == t.p_xy and t.rho[1] == t.p_z
    assert t.theta == pytest.approx(math.asin(0.012 / 0.1))                   # the angle at the target, eps = 0.1


@pytest.mark.parametrize("name, safe", [("sensing", True), ("tube", True), ("v_bar[r]", True),
                                        ("obstacles[0,3]", True), ("sway_bound", True),
                                        ("safe_only.sensing", True), ("keep_up[u]", False), ("yaw_budget", False),
                                        ("e_bar[e_d]", False), ("initial", False), ("initial_workspace", False),
                                        ("target_in_workspace", False), ("tube_extra", False)])
def test_which_design_conditions_the_safe_tier_reads(name, safe):
    assert is_safe_condition(name) is safe


LAW = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.04)
SAFE = SafeSet(level=0.75, shape=0.4, depth=0.08)


def test_the_backup_at_the_start_is_checked_against_obstacles():
    """An obstacle 1.5 m from the start at its depth, radius 0.4: slack 1.5 - (0.75 + 0.2) - 0.4 = 0.15 m."""
    sc = paper_scenario()
    x0, y0, z0 = sc.initial_state[:3]
    near = sc.with_changes(obstacles=(Obstacle((x0 + 1.5, y0, z0), 0.4),))
    c = initial_backup(near, LAW, SAFE)
    assert c.ok is True and c.lhs == pytest.approx(0.15)
    closer = sc.with_changes(obstacles=(Obstacle((x0 + 1.2, y0, z0), 0.4),))
    c = initial_backup(closer, LAW, SAFE)
    assert c.ok is False and c.lhs == pytest.approx(-0.15)


def test_the_backup_at_the_start_is_checked_against_the_workspace():
    """Start 0.5 m below the top of the box: the cylinder's half height 0.08 + 0.2 fits (slack 0.22 m)."""
    sc = paper_scenario().with_changes(initial_state=(0.0, 6.0, 4.5, 0.0), obstacles=())
    c = initial_backup(sc, LAW, SAFE)
    assert c.ok is True and c.lhs == pytest.approx(0.5 - 0.28)
    c = initial_backup(sc.with_changes(initial_state=(0.0, 6.0, 4.8, 0.0)), LAW, SAFE)
    assert c.ok is False and c.lhs == pytest.approx(0.2 - 0.28)


def test_an_obstacle_over_the_start_breaks_the_safe_tier():
    import verify
    sc = paper_scenario()
    x0, y0, z0 = sc.initial_state[:3]
    c = verify.certify(sc.with_changes(obstacles=sc.obstacles + (Obstacle((x0 + 1.0, y0, z0), 0.3),)))
    assert c.tiers.safe is False and "backup_initial" in c.tier_failures["safe"]


def test_the_key_sigma_is_zero_only_for_a_safe_only_design(paper_cert):
    """certifiable.toml declares sigma = 100 and certifies both tiers: its key holds 100."""
    import verify
    ok = verify.certify(verify.certifiable_scenario())
    assert ok.tiers == Tiers(True, True)
    assert handed_sigma(tiers_of(ok.design, ok.safe_design, ok.backup), ok.design.sigma) == 100.0 == ok.inputs.sigma
    assert handed_sigma(tiers_of(paper_cert.design, paper_cert.safe_design, paper_cert.backup), paper_cert.design.sigma) == 0.0


def test_the_backup_is_designed_and_re_proved_through_the_registry(pc_cert):
    """backup_of designs station keeping by default (the certificate's backup, number for number); recertify_backup
    proves the stored law by its kind; a kind without a proof is refused by name (issue 30)."""
    from tubekit.exceptions import ConfigError
    from verify.theorem.tiers import backup_of, recertify_backup
    sc, dist, margins = pc_cert.inputs.scenario, pc_cert.disturbance, pc_cert.design.margins
    assert backup_of(sc, dist, margins) == pc_cert.backup
    b = pc_cert.backup
    assert recertify_backup(sc, b.law, b.safe_set, dist, margins, b.anchor_reach) == b
    with pytest.raises(ConfigError, match=r"backup\.kind"):
        backup_of(sc, dist, margins, kind="hover")


# ---- a minimum surge: the backup must keep moving ---------------------------------------------------------------

def test_under_a_surge_floor_station_keeping_is_refused_by_name_and_the_loiter_keeps_its_surge(keep_moving_cert):
    """examples/keep_moving.toml (u_min 0.2 m/s): station keeping backs up at -u_b, a loiter at u_l >= u_min
    passes; the certified backup is the loiter and its condition holds with both numbers."""
    from tubekit.model.loiter import Loiter
    from verify.theorem.tiers import surge_floor_condition
    sc = keep_moving_cert.inputs.scenario
    keep = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.05, heave=0.3, heave_band=0.01)
    refused = surge_floor_condition(sc, keep)
    assert refused.condition == "backup_min_surge" and refused.ok is False
    assert (refused.lhs, refused.rhs) == (-0.2, 0.2) and "loiter" in refused.detail
    gains = dict(yaw_rate=0.5, yaw_band=0.1, heave=0.3, heave_band=0.04)
    assert surge_floor_condition(sc, Loiter(surge=0.2, **gains)).ok is True          # at the floor
    assert surge_floor_condition(sc, Loiter(surge=0.19, **gains)).ok is False
    b = keep_moving_cert.backup
    held = {x.condition: x for x in b.conditions}
    assert b.certified and b.law.kind == "loiter" and held["backup_min_surge"].ok and b.law.min_surge >= 0.2


def test_a_station_keeping_backup_under_a_surge_floor_leaves_no_tier(keep_moving_cert):
    """The same scenario with controller.backup = "station_keeping": backup_min_surge fails, the safe tier too."""
    import verify
    sc = keep_moving_cert.inputs.scenario
    cert = verify.certify(sc.with_changes(**{"controller.backup": "station_keeping"}))
    assert cert.tiers == Tiers(False, False)
    assert "backup_min_surge" in {x.condition for x in cert.tier_conditions["safe"] if x.ok is False}


KEEP_MOVING = Path(__file__).resolve().parent.parent / "examples" / "keep_moving_tracked.toml"


def test_the_yaw_screen_is_a_condition_only_where_no_step_17_proves_a_plan_at_every_period(paper_cert):
    """tracking_design drops the screens of FEASIBILITY_SCREENS where proves_feasibility holds, and only there."""
    from verify.kernel.region import Region
    from verify.theorem.design import FEASIBILITY_SCREENS, evaluate_design
    from verify.theorem.tiers import tracking_design
    sc, gains, dist = paper_cert.inputs.scenario, paper_cert.gains, paper_cert.disturbance
    for heading, screened in (("toward", False), ("away", True)):
        s = sc.with_changes(**{"region.heading": heading})
        region = Region.from_scenario(s)
        names = [c.condition for c in tracking_design(s, region, gains, 0.0, dist).conditions]
        assert ("yaw_budget" in names) is screened
        full = [c.condition for c in evaluate_design(s, region, gains, 0.0, dist).conditions]
        assert [n for n in full if n not in FEASIBILITY_SCREENS or screened] == names[:len(names) - 2]


def test_the_yaw_budget_is_not_necessary_a_loop_that_turns_slower_than_the_line_of_sight_at_epsilon_tracks():
    """Counterexample to the yaw budget read as a necessary condition (r_bar >= omega_bar_xy / epsilon): with
    epsilon = 0.12 m the current may turn the line of sight at e_d = epsilon at 0.1 / 0.12 = 0.83 rad/s, beyond
    r_max = 0.5 rad/s, yet both tiers are proved (the plans keep the vehicle in X_f, metres behind the target),
    a 30 s run keeps every promise with a plan accepted at every period, and the closed-loop falsifier finds
    nothing."""
    import verify
    import tubekit
    from verify.falsify.closed_loop import falsify_closed_loop
    sc = tubekit.load_scenario(KEEP_MOVING).with_changes(epsilon=0.12)
    cert = verify.certify(sc)
    assert cert.tiers == Tiers(True, True)
    assert cert.disturbance.omega_xy / sc.epsilon > 1.6 * sc.limits.r_max
    assert "yaw_budget" not in {c.condition for c in cert.conditions}
    run = tubekit.simulate(sc.with_changes(duration=30.0), cert)
    promises = {p.name: p for p in tubekit.check_promises(run)}
    assert all(p.given and p.ok for p in promises.values()) and promises["plan_available"].ok
    res = falsify_closed_loop(sc, budget=4, seed=0, duration=3.0, certificate=cert)
    assert res.check() and not res.found
