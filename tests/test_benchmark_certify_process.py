"""benchmarks/certify_process.py: the run order interleaves, the summary's medians and ratios, the scenario list,
and one real (tiny) measurement's keys (timings not asserted)."""

from __future__ import annotations


import pytest

from .scripts import ROOT, load_script


def _module():
    return load_script("benchmarks/certify_process.py", "bench_certify_process")


BENCH = _module()


def test_every_repetition_runs_every_pair_with_the_tree_order_rotated():
    order = BENCH.interleaved_order(["a", "b"], ["x", "y"], 2)
    assert order == [(0, "x", "a"), (0, "x", "b"), (0, "y", "a"), (0, "y", "b"),
                     (1, "x", "b"), (1, "x", "a"), (1, "y", "b"), (1, "y", "a")]


def test_the_summary_is_the_median_and_its_ratio_to_the_first_tree():
    walls = {"s.toml": {"before": [1.0, 3.0, 2.0], "after": [0.5, 0.4, 2.0]}}
    out = BENCH.summarise(walls, ["before", "after"])["s.toml"]
    assert out["before"] == {"median_s": 2.0, "min_s": 1.0, "max_s": 3.0, "runs": 3, "ratio": 1.0}
    assert out["after"]["median_s"] == 0.5 and out["after"]["ratio"] == 0.25


def test_the_scenarios_are_the_shipped_ones_without_the_campaign_specs():
    names = {p.name for p in BENCH.scenario_files()}
    assert {"paper_currents.toml", "certifiable.toml", "circle.toml", "bluerov2_currents.toml"} <= names
    assert not names & {"campaign_paper_currents.toml", "backup_campaign.toml"}


@pytest.mark.slow
def test_one_measurement_reports_every_key():
    res = BENCH.measure({"current": ROOT}, [ROOT / "verify" / "scenarios" / "certifiable.toml"], 1)
    assert set(res) >= {"load_before", "load_after", "probe", "walls_s", "summary", "exit_codes"}
    assert res["probe"]["current"]["loaded"] == [] and res["exit_codes"]["certifiable.toml"]["current"] == 0
    assert len(res["walls_s"]["certifiable.toml"]["current"]) == 1
