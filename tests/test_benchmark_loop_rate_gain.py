"""benchmarks/loop_rate_gain.py: the invariant-ellipsoid gain of the velocity loop (a study, floats)."""

from __future__ import annotations

import numpy as np
import pytest

from .scripts import load_script

STUDY = load_script("benchmarks/loop_rate_gain.py", "loop_rate_gain_benchmark")


@pytest.mark.parametrize("a, b", [(2.0, 1.0), (5.0, 3.0)])
def test_a_first_order_lag_driven_by_a_bounded_input_has_the_gain_b_over_a(a, b):
    """ẋ = −a x + b w with |w| <= 1 peaks at b/a (a constant input from rest): the ellipsoid's bound, whose best
    multiplier is α = a (1/p <= b²/(α (2a − α))), reaches it within 2 % and never goes below it."""
    mats = [np.diag([-a, -10 * a, -10 * a])]
    gain = STUDY.ellipsoid_gain(mats, [np.array([b, 0.0, 0.0])], np.array([1.0, 0.0, 0.0]), alphas=(a,))
    assert b / a * (1 - 1e-6) <= gain <= 1.02 * b / a


def test_a_vertex_that_is_unstable_leaves_no_bound():
    mats = [np.diag([-1.0, -1.0, -1.0]), np.diag([0.5, -1.0, -1.0])]
    assert STUDY.ellipsoid_gain(mats, [np.array([1.0, 0.0, 0.0])], np.array([1.0, 0.0, 0.0])) == float("inf")
