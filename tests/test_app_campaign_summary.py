"""tubekit.app.campaign_summary: the throughput of a campaign (issue 23) and its place in the result line."""

from __future__ import annotations

import pytest

from tubekit.app.campaign_summary import summary_line, throughput


def test_throughput_by_hand():
    # 16 runs of 15 s with one falsification sequence each (30 simulated s per run) in 20 s of wall time,
    # the runs' own wall times summing to 24 s: 480 s simulated, 24 per wall second, 48 runs per minute,
    # 20 simulated seconds per second of a worker's run.
    rate = throughput(16, 30.0, 20.0, 24.0)
    assert rate == {"simulated_s": 480.0, "wall_s": 20.0, "simulated_s_per_wall_s": pytest.approx(24.0),
                    "runs_per_minute": pytest.approx(48.0), "simulated_s_per_run_s": pytest.approx(20.0)}


def test_a_resumed_campaign_that_computed_nothing_has_no_rates():
    rate = throughput(0, 15.0, 1.5, 0.0)
    assert rate["simulated_s"] == 0.0
    assert rate["simulated_s_per_wall_s"] is rate["runs_per_minute"] is rate["simulated_s_per_run_s"] is None


def _summary(rate: dict) -> dict:
    return {"runs": 4, "computed_runs": 4, "certified_runs": 4, "violations": 0, "violations_certified": 0,
            "largest_max_rho_ratio": {"max_rho_ratio": 0.5, "run": 2, "seed": 7}, "safety_broken_safe_tier": 0,
            "safe_tier_runs": 4, "backup": {"runs_engaged": 0, "seconds_total": 0.0}, "throughput": rate}


def test_the_result_line_gives_the_throughput_only_when_runs_were_computed():
    line = summary_line(_summary(throughput(4, 10.0, 2.0, 3.0)), "OUT")
    assert "2 s wall: 20 simulated s per wall s, 120 runs/min; wrote OUT" in line
    assert "runs/min" not in summary_line(_summary(throughput(0, 10.0, 2.0, 0.0)), "OUT")
