"""tubekit.app.tiers: the tiers in the study's summary and metrics.json (issue 21)."""

from __future__ import annotations

from tubekit.tiers import Tiers

from types import SimpleNamespace

from tubekit.app.tiers import activity_line, report_title, tier_lines, tier_report

SAFE_ONLY = SimpleNamespace(tiers=Tiers(True, False),
                            tier_failures={"safe": (), "tracking": ("keep_up", "yaw_budget")})
PROMISES = [
    {"name": "tube", "tier": "tracking", "depends_on": ["disturbance", "recursive_feasibility"]},
    {"name": "clearance", "tier": "safe", "depends_on": ["disturbance"]},
    {"name": "inputs", "tier": "safe", "depends_on": ["disturbance"]},
    {"name": "disturbance", "tier": "premise", "depends_on": []},
]


def test_the_report_says_which_tier_holds_and_what_each_depends_on():
    report = tier_report(SAFE_ONLY, {"promises": PROMISES})
    assert report["safe"]["certified"] is True and report["tracking"]["certified"] is False
    assert report["safe"]["promises"] == ["clearance", "inputs"]
    assert report["safe"]["depends_on"] == ["disturbance"]
    assert report["tracking"]["depends_on"] == ["disturbance", "recursive_feasibility"]
    assert report["tracking"]["failed_conditions"] == ["keep_up", "yaw_budget"]


def test_the_title_is_the_issue_s_sentence():
    report = tier_report(SAFE_ONLY, {"promises": PROMISES})
    assert report_title(report) == "safe: certified; tracking: not certified (keep_up, yaw_budget)"
    lines = tier_lines(report)
    assert lines[0] == "tiers: safe: certified; tracking: not certified (keep_up, yaw_budget)"
    assert "NOT given" in lines[2] and "depends on disturbance, recursive_feasibility" in lines[2]


def test_a_run_without_tier_promises_says_so():
    report = tier_report(SAFE_ONLY, {"promises": []})
    assert "promises none" in tier_lines(report)[1]


def test_activity_line_reports_replaced_steps_and_backup_time():
    line = activity_line({"steps": 200, "replaced_steps": 37, "backup_s": 5.0, "backup_engagements": 2,
                          "duration_s": 20.0})
    assert line == "replaced steps 37 of 200; backup active 5 s (2 times, 25 % of the run)"
