"""tubekit.app.campaign_summary: the throughput of a campaign (issue 23), its place in the result line, and the
runs per tier (issue 35): no run is called certified on the safe tier alone; the figures of any campaign."""

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
    return {"runs": 4, "computed_runs": 4, "runs_by_tier": {"both": 4, "safe_only": 0, "none": 0}, "violations": 0,
            "violations_certified": 0,
            "largest_max_rho_ratio": {"max_rho_ratio": 0.5, "run": 2, "seed": 7}, "safety_broken_safe_tier": 0,
            "safe_tier_runs": 4, "backup": {"runs_engaged": 0, "seconds_total": 0.0}, "throughput": rate}


def test_the_result_line_gives_the_throughput_only_when_runs_were_computed():
    line = summary_line(_summary(throughput(4, 10.0, 2.0, 3.0)), "OUT")
    assert "2 s wall: 20 simulated s per wall s, 120 runs/min; wrote OUT" in line
    assert "runs/min" not in summary_line(_summary(throughput(0, 10.0, 2.0, 0.0)), "OUT")


# ---- issue 35: runs per tier, never "certified" on the safe tier alone; the figures of any campaign ----------

def test_the_result_line_counts_runs_per_tier_and_says_when_there_is_no_tube():
    summary = {**_summary(throughput(4, 10.0, 2.0, 3.0)), "largest_max_rho_ratio": None,
               "runs_by_tier": {"both": 0, "safe_only": 4, "none": 0}}
    line = summary_line(summary, "OUT")
    assert "4 runs (4 computed): 0 with both tiers, 4 with the safe tier only, 0 uncertified" in line
    assert "no tube ratio" in line and " 4 certified" not in line
    backup_only = {**summary, "largest_max_rho_ratio": {"max_rho_ratio": 0.0, "run": 1, "seed": 9}}
    assert "0.0 (run 1, seed 9) (no run has the tracking tier: no tube is promised)" in summary_line(backup_only, "O")
    assert "vs certified radius 1" in summary_line(_summary(throughput(4, 10.0, 2.0, 3.0)), "OUT")


@pytest.fixture(scope="module")
def paper_tightening():
    """The paper's own scenario: the safe tier only, σ = 0, no tube."""
    import tubekit
    from tubekit.app.certified import certify_design

    return certify_design(tubekit.paper_scenario()).tightening


def test_a_safe_tier_only_campaign_is_summarised_honestly_and_drawn(tmp_path, paper_tightening):
    from tubekit.app.campaign_spec import spec_from_dict
    from tubekit.app.campaign_summary import FIGURES, summarise, write_figures

    from .test_app_plots_campaign import SAFE_ONLY, _tier_rows

    spec = spec_from_dict({"scenario": "paper", "runs": 4, "seed": 7, "duration": 2.0})
    rows = _tier_rows(SAFE_ONLY)
    facts = {"computed_runs": 4, "campaign_wall_s": 3.0, "computed_runs_wall_s": 1.2}
    summary = summarise(rows, spec, {"key": paper_tightening}, facts)
    assert "certified_runs" not in summary and "certified_certificates" not in summary
    assert summary["runs_by_tier"] == {"both": 0, "safe_only": 4, "none": 0}
    assert summary["certificates_by_tier"] == {"both": 0, "safe_only": 1, "none": 0}
    assert summary["safe_tier_runs"] == 4 and summary["tracking_tier_runs"] == 0
    assert summary["certificate_tube_box"] == {"min": None, "max": None}  # no tube: not a "certified" box of 0
    assert summary["largest_max_rho_ratio"] is None and summary["largest_max_rho_ratio_certified"] is None
    paths = write_figures(tmp_path, rows, epsilon=0.1)
    assert [p.name for p in paths] == list(FIGURES) and all(p.stat().st_size > 0 for p in paths)
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == sorted(FIGURES)  # no temporary left
    mixed = _tier_rows(((True, True), (False, False)), ratio=0.5)
    assert summarise(mixed, spec, {}, facts)["runs_by_tier"] == {"both": 1, "safe_only": 0, "none": 1}
    assert all(p.stat().st_size > 0 for p in write_figures(tmp_path, mixed, epsilon=0.1))
