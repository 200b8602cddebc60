"""benchmarks/published_frontier.py: REMUS 100 over its published box, the thrust tied, per speed and current."""

from __future__ import annotations

import pytest

from .scripts import load_script


def _module():
    return load_script("benchmarks/published_frontier.py", "bench_published_frontier")


def test_a_cell_is_the_shipped_file_with_the_surge_band_about_the_target_and_the_rock_out_of_the_way():
    """1.25 m/s in 0.3 m/s: u in [1.25 − 0.3 − 0.13, 1.25 + 0.3 + 0.1] = [0.82, 1.65] m/s (by hand), the current on
    both horizontal axes, the box still the published one with its thrust tied, the rock 1 km off the line."""
    scenario = _module().survey(1.25, 0.3, 0.006, 200.0)
    assert (scenario.limits.u_min, scenario.limits.u_max, scenario.limits.r_max) == (0.82, 1.65, 0.006)
    assert scenario.disturbance.amplitude == (0.3, 0.3, 0.005) and scenario.initial_state[0] == -200.0
    assert scenario.plant.params.tied and abs(scenario.obstacles[0].center[1]) >= 1000.0


def test_around_the_file_each_row_changes_one_field_and_untied_drops_only_the_top_speed():
    rows = _module().around()
    base = rows["as shipped"]
    assert rows["u_min 0.58"].limits.u_min == 0.58 and rows["r_max 0.005"].limits.r_max == 0.005
    assert rows["started trimmed"].plant.start == "trimmed" and base.plant.settled
    untied = dict(rows["untied"].plant.overrides)
    assert "top_speed" not in untied and not rows["untied"].plant.params.tied
    assert {k: v for k, v in base.plant.overrides if k != "top_speed"} == untied


@pytest.mark.parametrize("argv", [["--speed", "-1"], ["--current", "0"], ["--r-max", "nan"], ["--probe", "0"]])
def test_a_bad_argument_is_refused_before_any_certificate(argv):
    with pytest.raises(SystemExit) as exit_:
        _module().main(argv)
    assert exit_.value.code == 2
