"""benchmarks/compiled_period.py: the numpy functions it puts back are the compiled routines' floats, and a short
alternation reports both sides with the same plans (timings not asserted)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tubekit.model import compiled_arcs

from .scripts import load_script

BENCH = load_script("benchmarks/compiled_period.py", "bench_compiled_period")


@given(hnp.arrays(float, 4, elements=st.floats(-20, 20)),
       hnp.arrays(float, (8, 3), elements=st.one_of(st.just(0.0), st.floats(-1e-3, 1e-3), st.floats(-2.0, 2.0))),
       st.floats(0.01, 0.4))
def test_the_numpy_side_computes_the_compiled_sides_floats(s0, inputs, dt):
    """Property: rollout, the step's Jacobian and the bearing error's model of the numpy side equal the compiled
    routines bit for bit (the benchmark times the same arithmetic twice)."""
    states = compiled_arcs.rollout(s0, inputs, dt)
    ref = states[:, :3] + np.array([0.9, -0.3, 0.2])
    np.testing.assert_array_equal(BENCH.numpy_rollout(s0, inputs, dt), states)
    np.testing.assert_array_equal(BENCH.numpy_step_linearisation(states, inputs, dt),
                                  compiled_arcs.step_linearisation(states, inputs, dt))
    np.testing.assert_array_equal(BENCH.numpy_eo_linearisation(states, ref, 1e-9),
                                  compiled_arcs.eo_linearisation(states, ref, 1e-9))


@pytest.mark.slow
def test_a_short_alternation_reports_both_sides_and_restores_the_routines():
    before = compiled_arcs.rollout
    out = BENCH.measure(duration=1.0, rounds=1)
    assert [r["side"] for r in out["rounds"]] == ["compiled", "numpy"]
    assert out["same_last_plan"] is True
    assert out["scp_realtime_compiled_median_ms"] > 0 and out["scp_realtime_numpy_median_ms"] > 0
    assert compiled_arcs.rollout is before
