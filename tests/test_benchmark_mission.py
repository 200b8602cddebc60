"""benchmarks/mission.py: what safety costs the mission, three ways, measured on the run."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verify
from tubekit.loop.pipeline import certified_run

from .scripts import load_script

MISSION = load_script("benchmarks/mission.py", "mission_benchmark")


def test_the_scenarios_are_the_issues_and_the_transit_is_as_described():
    names = set(MISSION.scenarios())
    assert names == {"section_vi", "paper_currents", "paper_currents_fast", "paper_currents_steady", "transit"}
    transit = MISSION.transit()
    assert transit.disturbance.constant == (0.0, 0.12, 0.0) and transit.epsilon == 0.5
    assert [o.center[1] for o in transit.obstacles] == [0.9, -0.9]          # 0.9 m off the path, either side


def test_one_row_has_every_figure_for_the_three_ways():
    row = MISSION.measure("paper_currents_fast", MISSION.scenarios()["paper_currents_fast"], 1.0)
    assert row["tiers"] == {"safe": True, "tracking": True} and row["baseline_rmse"] > 0
    for way in ("shipped", "no_recovery", "replay_only"):
        r = row[way]
        assert set(r) >= {"backup_s", "recovery_s", "candidate_periods", "tracking_rmse", "rmse_ratio", "broken"}
        assert r["backup_s"] >= 0 and math.isfinite(r["rmse_ratio"]) and r["broken"] == []


@pytest.mark.slow
def test_counterexample_the_transit_certifies_tracking_yet_the_vehicle_is_pinned_behind_the_rock():
    """Counterexample (issue 31, open): the transit certifies both tiers, yet the real-time FHOCP pins the vehicle
    behind the first rock. Its heading must stay within e_o_max = 0.5 rad of the line of sight and it has no sway,
    so once the rock's terminal footprint lies between vehicle and target, forward motion leads into the footprint
    and reverse motion away from the target; the cross current holds it there. Plans are rejected from t = 37.6 s, the backup takes over, tracking is
    reported not in force (``recursive_feasibility``), and safety is kept. When the tracking tier becomes a
    theorem (or is refused for this path by name) this test must change."""
    sc = MISSION.transit().with_changes(duration=42.0)
    cert = verify.certify(sc)
    assert cert.tiers.safe and cert.tiers.tracking
    done = certified_run(sc, cert.tightening, progress=False)
    run = done.run
    rock = np.asarray(sc.obstacles[0].center[:2])
    assert run.rejected.any() and run.backup_active.any()
    assert run.states[-1, 0] < rock[0] - 1.0 < run.desired[-1, 0] - 2.0      # stuck behind it; the target went on
    assert done.metrics["outcome"]["safe"] == "certified, kept"
    assert done.metrics["outcome"]["tracking"].startswith("certified, not in force")


def test_the_spread_certifies_each_start_and_summarises_min_median_max():
    row = MISSION.spread("paper_currents", MISSION.scenarios()["paper_currents"], 1.0, starts=2)
    assert row["starts"] == 2 and row["tiers"] == ['{"safe": true, "tracking": true}']
    assert 0 <= row["plan_throughout"] <= 2 and row["broken"] == 0
    low, mid, high = row["rmse_ratio"]
    assert 0 < low <= mid <= high
