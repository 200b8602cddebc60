"""One campaign run on a worker (tubekit.app.campaign_task): the row is the worst of its simulations,
its disturbance sequences come from its seed, a run that cannot be simulated is recorded."""

from __future__ import annotations

import math

import pytest

from tubekit.app import campaign_task
from tubekit.app.campaign_task import RunTask, simulate_all, simulate_task
from tubekit.app.certified import certify_design
from tubekit.exceptions import TubekitError
from tubekit.scenario import paper_scenario


@pytest.fixture(scope="module")
def task() -> RunTask:
    """A 2 s paper run with one random disturbance sequence, under its own certificate's tightening."""
    scenario = paper_scenario().with_changes(duration=2.0)
    return RunTask(run=7, seed=123, scenario=scenario, tightening=certify_design(scenario).tightening, sequences=1)


def test_the_row_keeps_the_worst_figure_of_each_simulation(task):
    sims = simulate_all(task)
    row = simulate_task(task)
    assert len(sims) == 2  # the scenario's current, then one sequence
    ratios = [sim.ratio for sim in sims]
    assert row["max_rho_ratio"] == max(ratios) and row["worst_sequence"] == ratios.index(max(ratios))
    assert row["min_clearance"] == min(float(sim.metrics["min_clearance"]) for sim in sims)
    assert row["tracking_rmse"] == max(float(sim.metrics["tracking_rmse"]) for sim in sims)
    assert row["violated"] == any(sim.broken for sim in sims)
    assert (row["run"], row["seed"], row["error"]) == (7, 123, "")
    assert row["wall_s"] > 0


def test_the_disturbance_sequences_are_drawn_from_the_seed_within_the_bounds(task):
    first, again = campaign_task._disturbances(task), campaign_task._disturbances(task)
    other = campaign_task._disturbances(RunTask(7, 124, task.scenario, task.tightening, 1))
    assert first[0] is None and len(first) == 2
    assert first[1].table == again[1].table and first[1].table != other[1].table
    bound = task.tightening.disturbance
    for wx, wy, wz in first[1].table:
        assert math.hypot(wx, wy) <= bound.omega_xy * (1 + 1e-12) and abs(wz) <= bound.omega_z * (1 + 1e-12)


@pytest.mark.slow
def test_on_the_dynamic_plant_the_sequences_replace_the_current_within_its_own_bound():
    """The dynamic plant's override replaces the water current only (the sway and the loop error are the plant's), so
    the sequences stay within the current's bound, the premise the certificate assumes (0.1 m/s per axis here), not
    within ω̄ (which adds the sway and the loop error the certificate derives)."""
    from pathlib import Path

    from tubekit.scenario import load_scenario
    scenario = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_pier.toml").with_changes(
        duration=2.0)
    tight = certify_design(scenario).tightening
    seq = campaign_task._disturbances(RunTask(3, 5, scenario, tight, 1))[1]
    assert tight.disturbance.omega_xy > 0.15 > 0.1
    biggest = max(math.hypot(wx, wy) for wx, wy, _ in seq.table)
    assert 0.05 < biggest <= 0.1 * (1 + 1e-12) and max(abs(wz) for _, _, wz in seq.table) <= 0.1 * (1 + 1e-12)


def test_a_run_that_cannot_be_simulated_is_recorded_not_raised(task, monkeypatch):
    def fail(_task):
        raise TubekitError("the plan cannot start here\nsecond line")

    monkeypatch.setattr(campaign_task, "simulate_all", fail)
    row = simulate_task(task)
    assert row["error"] == "the plan cannot start here"
    assert row["max_rho_ratio"] is None and row["worst_sequence"] == -1 and row["violated"] is False
