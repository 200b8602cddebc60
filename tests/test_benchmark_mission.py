"""benchmarks/mission.py: what safety costs the mission, three ways, measured on the run."""

from __future__ import annotations

import math

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
