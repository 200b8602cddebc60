"""benchmarks/compiled_step.py: a short alternation reports both sides with the same plans and puts the routines
back; the numpy side's tube runs log the very floats of the compiled side's (timings not asserted)."""

from __future__ import annotations

import pytest

from tubekit.fhocp import compiled_rows

from .scripts import load_script

BENCH = load_script("benchmarks/compiled_step.py", "bench_compiled_step")


@pytest.mark.slow
def test_a_short_alternation_reports_both_sides_and_restores_the_routines():
    before = {name: getattr(compiled_rows, name) for name in BENCH.NUMPY}
    out = BENCH.measure(duration=1.0, rounds=1, backends=("clarabel",))
    assert [r["side"] for r in out["rounds"]] == ["compiled", "numpy"]
    assert out["clarabel_same_last_plan"] is True
    assert out["clarabel_alone_compiled_ms"] > 0 and out["clarabel_round_robin_numpy_ms"] > 0
    assert {name: getattr(compiled_rows, name) for name in BENCH.NUMPY} == before


def test_the_numpy_rows_log_the_very_floats_of_the_compiled_rows():
    """Over 3 s tube runs of Section VI and paper_currents every logged array (states, v_hat, inputs, rejections,
    slacks, nominal) is the same on both sides."""
    out = BENCH.compare_logs(duration=3.0)
    assert set(out) == {"section_vi", "paper_currents"}
    for name, row in out.items():
        assert len(row["compared"]) == 6
        assert row["differ"] == [], name
