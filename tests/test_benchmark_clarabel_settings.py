"""benchmarks/clarabel_settings.py: Clarabel's settings compared on the FHOCP's recorded subproblems."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verify
from tubekit.scenario import load_scenario

from .scripts import load_script

STUDY = load_script("benchmarks/clarabel_settings.py", "clarabel_settings_benchmark")


@pytest.fixture(scope="module")
def recorded():
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    return STUDY.record(sc, 1.0)


def test_every_subproblem_of_the_run_is_recorded_with_the_plans_input_columns(recorded):
    problems, compiled, inputs = recorded
    assert len(problems) >= 10                      # at least one solve per period of the 1 s run (dt 0.1 s)
    P, q, A, b = problems[0]
    assert A.shape == (b.size, q.size) and P.shape == (q.size, q.size)
    assert inputs.size == 3 * 8 and len(set(inputs.tolist())) == inputs.size and inputs.max() < q.size


def test_each_setting_is_compared_with_the_shipped_one_and_solves_the_short_run(recorded):
    problems, compiled, inputs = recorded
    out = STUDY.compare(problems, compiled, inputs)
    assert set(out) == set(STUDY.SETTINGS)
    assert out["shipped"]["max_x_diff"] == 0.0      # the shipped setting against itself: deterministic
    for name, row in out.items():
        assert row["failed"] == 0 and row["almost_solved"] == 0, name
        assert math.isfinite(row["max_input_diff"]) and row["max_input_diff"] < 1e-3, name


def test_the_scenarios_are_the_shipped_ones_and_the_examples():
    names = set(STUDY._scenarios())
    assert {"section_vi", "paper_currents", "transit", "circle", "helix", "line", "waypoints"} <= names
    assert all(np.isfinite(s.duration) for s in STUDY._scenarios().values())


def test_the_closed_loop_comparison_restores_the_shipped_settings():
    import tubekit.fhocp.convex as convex

    shipped = dict(convex.DEFAULT_CLARABEL_SETTINGS)
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    out = STUDY.closed_loop(sc, 1.0)
    assert set(out) == set(STUDY.SETTINGS) and convex.DEFAULT_CLARABEL_SETTINGS == shipped
    for row in out.values():
        assert row["broken"] == [] and row["min_clearance"] > 0 and row["backup_s"] == 0.0
