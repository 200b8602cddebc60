"""verify.theorem.workspace: designs empty by construction are refused as named conditions with numbers.

Expected ranges are computed by hand from the trajectories' formulas (sin / cos over an angle interval, a
line's end points), not read from the module.
"""

from __future__ import annotations

from tubekit.tiers import Tiers

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import verify
from tubekit.model.trajectory import Circle, Helix, Line, Waypoints
from tubekit.scenario import load_scenario, paper_scenario
from verify.theorem.workspace import TARGET_SAMPLES, initial_workspace, target_in_workspace, target_range

PC = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


def test_a_full_circle_spans_its_diameter():
    lo, hi, how = target_range(paper_scenario())       # radius 3, pi/25 rad/s for 100 s: four turns
    np.testing.assert_allclose(lo, [-3.0, -3.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(hi, [3.0, 3.0, 0.0], atol=1e-12)
    assert how == "analytic (circle)"


def test_an_eighth_of_a_circle_is_enclosed_tightly():
    """phase 0, angle 0 .. pi/4: x = 3 sin a in [0, 3 / sqrt 2], y = 3 cos a in [3 / sqrt 2, 3]."""
    sc = paper_scenario().with_changes(trajectory=Circle(radius=3.0, rate=math.pi / 40), duration=10.0)
    lo, hi, _ = target_range(sc)
    r = 3 / math.sqrt(2)
    assert lo[0] <= 0.0 and lo[0] == pytest.approx(0.0, abs=1e-12) and hi[0] >= r and hi[0] == pytest.approx(r)
    assert lo[1] <= r and lo[1] == pytest.approx(r) and hi[1] >= 3.0 and hi[1] == pytest.approx(3.0)


def test_a_helix_leaving_the_workspace_is_refused_with_its_excursion():
    """climb 0.06 m/s for 100 s from z = 0: z = 6 m against the workspace top at 5 m, 1 m out."""
    sc = paper_scenario().with_changes(trajectory=Helix(radius=3.0, rate=math.pi / 25, climb=0.06))
    c = target_in_workspace(sc)
    assert c.condition == "target_in_workspace" and c.ok is False
    assert c.lhs == pytest.approx(1.0) and c.rhs == 0.0 and "analytic (helix)" in c.detail


def test_a_helix_inside_passes_with_its_slack():
    sc = paper_scenario().with_changes(trajectory=Helix(radius=3.0, rate=math.pi / 25, climb=0.02))
    c = target_in_workspace(sc)
    assert c.ok is True and c.lhs == pytest.approx(max(-(10.0 - 3.0), 2.0 - 5.0))   # x/y slack 7 m, z 2 vs 5


def test_a_line_is_evaluated_at_its_ends():
    sc = paper_scenario().with_changes(trajectory=Line(start=(0.0, 0.0, 0.0), direction_velocity=(0.2, 0.0, 0.0)))
    c = target_in_workspace(sc)
    assert c.ok is False and c.lhs == pytest.approx(20.0 - 10.0) and "analytic (line)" in c.detail


def test_waypoints_use_the_sampled_route_with_a_lipschitz_bound():
    sc = paper_scenario().with_changes(trajectory=Waypoints(points=((0.0, 0.0, 0.0), (12.0, 0.0, 0.0)), speed=0.5))
    c = target_in_workspace(sc)
    # 12 m at 0.5 m/s with the 15/8 time law takes 45 s < 100 s: the target reaches x = 12
    slack = 0.5 * (100.0 / (TARGET_SAMPLES - 1)) / 2      # v_bar h / 2 with v_bar = 0.5 m/s along x
    assert c.ok is False and 2.0 <= c.lhs <= 2.0 + slack + 1e-9
    assert f"sampled at {TARGET_SAMPLES} points" in c.detail


def test_without_a_workspace_nothing_is_refused():
    sc = paper_scenario().with_changes(workspace=None)
    for c in (target_in_workspace(sc), initial_workspace(sc, 0.1)):
        assert c.ok is True and c.lhs is None and c.detail == "no workspace"


@pytest.mark.parametrize("x0, margin, out", [(9.9, 0.0, 0.1), (9.9, 0.05, 0.15), (0.0, 0.0, -4.8)])
def test_the_start_ball_is_checked_against_the_box(x0, margin, out):
    """vehicle radius 0.2: a start at x = 9.9 sticks out of x <= 10 by 0.1 (+ the margin); at the origin the
    tightest side is the depth, 5 - 0.2 = 4.8 m inside."""
    sc = paper_scenario().with_changes(initial_state=(x0, 0.0, 0.0, 0.0))
    c = initial_workspace(sc, margin)
    assert c.lhs == pytest.approx(out) and c.ok is (out <= 0)


def test_certify_refuses_a_start_outside_the_workspace_by_name(pc_cert):
    c = verify.certify(PC.with_changes(initial_state=(9.95, 0.0, 0.0, 0.0)))
    f = next(f for f in c.failures if f.condition == "initial_workspace")
    assert f.lhs == pytest.approx(0.15 + pc_cert.margins.position[0])
    assert "initial_workspace" in c.tier_failures["tracking"]


def test_certify_refuses_a_helix_leaving_the_workspace_in_the_tracking_tier_only():
    c = verify.certify(PC.with_changes(trajectory=Helix(radius=3.0, rate=math.pi / 50, climb=0.06)))
    assert c.tiers == Tiers(True, False)
    assert c.tier_failures["tracking"] == ("target_in_workspace",)
    assert next(f for f in c.failures if f.condition == "target_in_workspace").lhs == pytest.approx(1.0)
    assert "tracking: not certified (target_in_workspace)" in c.summary()


def test_a_trajectory_kind_without_a_formula_is_not_special_cased():
    """A subclass of Waypoints goes the sampled route, whatever it is called."""
    class Zigzag(Waypoints):
        pass
    sc = replace(paper_scenario(), trajectory=Zigzag(points=((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), speed=0.2))
    assert "sampled" in target_range(sc)[2]


@given(st.floats(-20.0, 20.0), st.floats(0.0, 12.0))
def test_the_sine_range_encloses_every_sample(a0, width):
    """Property: sin over [a0, a0 + width] at 2001 points lies in the enclosure, and the enclosure is attained
    up to the sample spacing (it is not a loose [-1, 1] unless the interval reaches the extremes)."""
    from verify.theorem.workspace import _sin_range
    a1 = a0 + width
    lo, hi = _sin_range(a0, a1)
    s = np.sin(np.linspace(a0, a1, 2001))
    assert lo <= s.min() + 1e-12 and s.max() <= hi + 1e-12
    step = width / 2000
    assert hi - s.max() <= step + 1e-9 and s.min() - lo <= step + 1e-9
