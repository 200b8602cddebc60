"""benchmarks/safe_radius.py: what the backup's safe radius costs (a what-if) and the two floors on it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import verify
from tubekit.scenario import load_scenario

from .scripts import load_script

SAFE_RADIUS = load_script("benchmarks/safe_radius.py", "safe_radius_benchmark")


def test_the_physical_floor_is_the_drift_while_turning_a_quarter():
    # ∫_0^{π/2} ω̄ sin χ dχ / r̄ = ω̄ / r̄: 0.12 m/s at 0.5 rad/s drifts 0.24 m
    assert SAFE_RADIUS.physical_floor(0.12, 0.5) == pytest.approx(0.24)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(omega=st.floats(0.02, 0.3), yaw=st.floats(0.2, 1.0))
def test_no_shape_below_the_floor_meets_the_abeam_condition(omega, yaw):
    """Property: below the returned level no β on a fine grid has β k > ω̄ √(1 + (β/d)²) at d = c − β, and at the
    returned (c, β) with 1 mm more distance the condition holds (the floor is attained, not just bounded)."""
    level, beta = SAFE_RADIUS.shape_floor(omega, yaw)
    assert math.isfinite(level) and 0.0 < beta < level
    below = 0.995 * level
    for b in np.linspace(1e-3, below - 1e-3, 400):
        d = below - b
        assert not b * yaw > omega * math.sqrt(1.0 + (b / d) ** 2)
    d = level - beta + 1e-3
    assert beta * yaw > omega * math.sqrt(1.0 + (beta / d) ** 2)
    assert level > SAFE_RADIUS.physical_floor(omega, yaw)   # the shape pays more than physics asks


def test_a_what_if_radius_changes_only_the_safe_set_level_and_caps_the_shape():
    cert = verify.certify(load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml"))
    tight = cert.best_effort_tightening()
    small = SAFE_RADIUS.with_radius(tight, 0.2)
    assert small.backup.safe_set.level == 0.2 and small.backup.safe_set.shape == pytest.approx(0.1)
    assert small.backup.law == tight.backup.law and small.backup.handover == tight.backup.handover
    assert small.backup.safe_set.depth == tight.backup.safe_set.depth
    assert tight.backup.safe_set.level == pytest.approx(0.75)     # the certified one is untouched
