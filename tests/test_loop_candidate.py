"""tubekit.loop.candidate: the shifted candidate and its completion law."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit import paper_scenario
from tubekit.loop.candidate import candidate_plan, pursuit_input

SC = paper_scenario()
V = SC.limits.vector


def test_the_candidate_is_the_plan_shifted_by_its_age_plus_one_then_completed():
    plan = np.column_stack([np.linspace(0.1, 0.3, 8), np.zeros(8), np.full(8, 0.1)])
    x0 = np.asarray(SC.initial_state, dtype=float)
    cand = candidate_plan(SC, plan, 2, x0, 0.3, V, None, 0.5)
    assert cand.shape == (8, 3)
    np.testing.assert_array_equal(cand[:5], plan[3:])                 # rows age + 1 .. N - 1, unchanged
    assert np.all(np.abs(cand[5:]) <= V)                              # the completion stays in V_bar
    assert candidate_plan(SC, plan, 7, x0, 0.8, V, None, 0.5) is None  # nothing left to shift


def test_the_completion_respects_the_rate_rows():
    plan = np.tile([0.0, 0.0, 0.0], (8, 1))
    jump = np.array([0.01, 0.01, 0.02])
    cand = candidate_plan(SC, plan, 0, np.asarray(SC.initial_state, dtype=float), 0.1, V, jump, 0.5)
    assert np.all(np.abs(np.diff(cand, axis=0)) <= jump + 1e-15)


@pytest.mark.parametrize("state, want", [
    ((-0.5, 3.0, 0.2, 0.0), "ahead"),      # the target (0, 3, 0) dead ahead: surge, no turn, dive to its depth
    ((0.5, 3.0, 0.0, 0.0), "behind"),      # the target behind: turn towards it, no surge while facing away
])
def test_pursuit_turns_onto_the_line_of_sight_and_closes_in(state, want):
    """Property of the completion law: it turns towards the target within a period and surges only facing it."""
    u, w, r = pursuit_input(SC, np.asarray(state), 0.0, V, 0.1)
    if want == "ahead":
        assert u > 0 and abs(r) < 1e-9 and w < 0
    else:
        assert u == 0.0 and abs(r) == pytest.approx(V[2])
