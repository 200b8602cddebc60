"""tubekit.loop.memory: the last accepted plan, its replay and the backup's anchor."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.loop.memory import ZERO_INPUT, PlanMemory

PLAN = np.column_stack([np.linspace(0.1, 0.4, 4), np.zeros(4), np.full(4, 0.2)])


def test_nothing_to_replay_is_exhausted_with_no_anchor():
    memory = PlanMemory()
    assert memory.exhausted and memory.anchor is None
    np.testing.assert_array_equal(memory.replacement(), 0.0)


def test_an_accepted_plan_sets_the_anchor_and_replays_for_its_length_minus_one():
    memory = PlanMemory()
    memory.remember(PLAN, False, accepted=True, end=np.array([1.0, 2.0, 3.0, 0.5]))
    np.testing.assert_array_equal(memory.anchor, [1.0, 2.0, 3.0])
    replayed = [memory.replacement() for _ in range(3)]
    np.testing.assert_array_equal(replayed, PLAN[1:])
    assert not memory.exhausted
    memory.replacement()
    assert memory.exhausted and memory.age == 4


def test_a_plan_remembered_without_acceptance_keeps_the_old_anchor():
    memory = PlanMemory(anchor=np.array([5.0, 5.0, 0.0]))
    memory.remember(PLAN, False, accepted=False, end=np.array([1.0, 2.0, 3.0, 0.0]))
    np.testing.assert_array_equal(memory.anchor, [5.0, 5.0, 0.0])
    assert not memory.exhausted and memory.age == 0


def test_a_flagged_or_non_finite_plan_is_not_kept_and_ages_the_old_one():
    memory = PlanMemory()
    memory.remember(PLAN, False, accepted=True, end=np.zeros(4))
    assert memory.remember(PLAN, True) is True and memory.age == 1
    bad = PLAN.copy()
    bad[2, 0] = np.nan
    memory.remember(bad, False, accepted=True, end=np.ones(4))
    assert memory.age == 2 and np.all(memory.anchor == 0.0)


def test_the_zero_input_is_read_only():
    with pytest.raises(ValueError, match="read-only"):
        ZERO_INPUT[0] = 1.0
