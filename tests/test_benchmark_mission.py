"""benchmarks/mission.py: what safety costs the mission, three ways, measured on the run."""

from __future__ import annotations

import math
import re

import verify
from tubekit.loop.pipeline import certified_run

from .scripts import load_script

MISSION = load_script("benchmarks/mission.py", "mission_benchmark")


def test_the_scenarios_are_the_issues_and_the_transit_is_as_described():
    names = set(MISSION.scenarios())
    shipped = {f"{n}{v}" for n in ("paper_currents", "certifiable", "paper_law") for v in ("", "_fast", "_steady")}
    assert names == {"section_vi", "transit"} | shipped
    transit = MISSION.transit()
    assert transit.disturbance.constant == (0.0, 0.12, 0.0) and transit.epsilon == 0.5
    assert [o.center[1] for o in transit.obstacles] == [0.9, -0.9]          # 0.9 m off the path, either side


def test_the_variants_hold_the_amplitude_steady_and_speed_the_current_up():
    base = MISSION.scenarios()["paper_law"]
    out = MISSION.variants("x", base)
    assert set(out) == {"x", "x_fast", "x_steady"} and out["x"] is base
    assert out["x_fast"].disturbance.period == 3.0 and out["x_fast"].disturbance.amplitude == base.disturbance.amplitude
    assert out["x_steady"].disturbance.amplitude == (0.0, 0.0, 0.0)
    assert out["x_steady"].disturbance.constant == base.disturbance.amplitude


def test_one_row_has_every_figure_for_the_three_ways():
    row = MISSION.measure("paper_currents_fast", MISSION.scenarios()["paper_currents_fast"], 1.0)
    assert row["tiers"] == {"safe": True, "tracking": True} and row["baseline_rmse"] > 0
    for way in ("shipped", "no_recovery", "replay_only"):
        r = row[way]
        assert set(r) >= {"backup_s", "recovery_s", "candidate_periods", "tracking_rmse", "rmse_ratio", "broken"}
        assert r["backup_s"] >= 0 and math.isfinite(r["rmse_ratio"]) and r["broken"] == []


def test_the_transit_past_two_rocks_is_refused_the_tracking_tier_by_name():
    """Issue 31 (was a counterexample: the transit certified both tiers, yet the real-time FHOCP pinned the vehicle
    behind the first rock for 62 s). The tracking theorem asks the candidate's footprint — X_f about the target
    plus the backup's safe set — to clear every obstacle along the target's path; the rocks lie 0.9 m off the line,
    so the certificate refuses the tracking tier by name and number and gives the safe tier alone."""
    cert = verify.certify(MISSION.transit())
    assert cert.tiers.safe and not cert.tiers.tracking
    failed = {c.condition: c for c in cert.failures}
    assert {"path_clearance[0]", "path_clearance[1]"} <= set(failed)
    assert all(n.startswith(("path_", "initial_terminal")) for n in failed)
    assert re.search(r"has 0\.9\d* m", failed["path_clearance[0]"].detail) and failed["path_clearance[0]"].lhs < 0


def test_the_spread_certifies_each_start_and_summarises_min_median_max():
    row = MISSION.spread("paper_currents", MISSION.scenarios()["paper_currents"], 1.0, starts=2)
    assert row["starts"] == 2 and row["tiers"] == ['{"safe": true, "tracking": true}']
    assert 0 <= row["plan_throughout"] <= 2 and row["broken"] == 0
    low, mid, high = row["rmse_ratio"]
    assert 0 < low <= mid <= high


def test_the_transits_safe_tier_goes_past_the_first_rock_instead_of_holding_behind_it():
    """Was a counterexample: the safe-only tightening shrank R's heading room by the margins of the tracking design
    that did not certify (|e_o| <= 0.19 of R's 0.5), so from t ≈ 30 s every plan could only move into the first
    rock's terminal footprint or away from the target, and the backup held the vehicle behind the rock (30 s of
    the first 60). With R's bounds at the FHOCP's nodes the plans go round the rock. Measured: 3.5 s of backup in
    150 s (``benchmarks/mission.py --only transit``); asserted here on the first 60 s, with room."""
    sc = MISSION.transit().with_changes(duration=60.0)
    cert = verify.certify(sc)
    tight = cert.best_effort_tightening()
    assert cert.tiers.safe_only and tight.e_o_max == sc.region.e_o_max
    done = certified_run(sc, tight, progress=False)
    assert done.broken == () and done.metrics["min_clearance"] > 0.0
    assert done.metrics["backup_s"] < 10.0
    assert float(done.run.states[-1, 0]) > -4.0 + 2.0       # past the first rock (x = -4 m) by t = 60 s
