"""tubekit.plotting.titles: the tier line, wrapped; a run's verdict with the outcome of each tier."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tubekit.plotting.titles import BASELINE_VERDICT, run_verdict, tier_title, title_lines
from tubekit.tiers import Tiers


def test_tier_title_names_the_failed_conditions_of_a_tier_not_given():
    assert tier_title(Tiers(True, False), {"tracking": ["keep_up", "yaw_budget"]}) == \
        "safe: certified; tracking: not certified (keep_up, yaw_budget)"
    assert tier_title(Tiers(True, True)) == "safe: certified; tracking: certified"
    assert "nothing is promised" in tier_title(None)


def test_tier_title_says_what_happened_to_a_given_tier():
    outcomes = {"safe": "certified, kept", "tracking": "certified, not in force (recursive_feasibility failed)"}
    assert tier_title({"safe": True, "tracking": True}, outcomes=outcomes) == \
        "safe: certified, kept; tracking: certified, not in force (recursive_feasibility failed)"


def test_a_long_tier_line_is_wrapped_below_the_title():
    tiers = "safe: certified; tracking: not certified (" + ", ".join(f"condition_{k}" for k in range(20)) + ")"
    text = title_lines("Tracking errors", tiers, width=60)
    lines = text.splitlines()
    assert lines[0] == "Tracking errors" and all(len(line) <= 60 for line in lines[1:])
    assert " ".join(lines[1:]) == tiers
    assert title_lines("Tracking errors", None) == "Tracking errors"


def _run(tube: bool, metrics: dict) -> SimpleNamespace:
    return SimpleNamespace(tube=tube, metrics=metrics, tightening=SimpleNamespace(tiers=Tiers(True, False)),
                           scenario=None, body=None, columns=lambda: {"t": np.zeros(1)})


def test_the_verdict_of_a_run_is_its_tiers_and_their_outcome():
    run = _run(True, {"tiers": {"safe": True, "tracking": False}, "outcome": {"safe": "certified, kept",
                                                                              "tracking": "not certified"}})
    assert run_verdict(run) == "safe: certified, kept; tracking: not certified"
    assert run_verdict(_run(False, {})) == BASELINE_VERDICT == "baseline: nothing is promised"
