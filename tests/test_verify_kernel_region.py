"""Tests of verify.kernel.region: defaults, validation, semantics of the heading hemispheres."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.model.errors import error_coordinates
from tubekit.exceptions import ConfigError
from tubekit.scenario import paper_scenario
from verify.kernel.region import Region


def _paper_region(**kw) -> Region:
    return Region.from_scenario(paper_scenario(), **kw)


def test_defaults_follow_the_paper_scenario():
    r = _paper_region()
    speed = 3 * math.pi / 25  # Section VI: p_d = 3 [sin(pi t/25), cos(pi t/25), 0]
    assert r.e_d == (0.1, 3.0)
    assert r.e_z == (-1.0, 1.0)
    assert r.e_o == (-0.9, 0.9)
    assert r.heading == "toward"
    assert r.pd_dot_max == pytest.approx((speed, speed, 0.0))
    assert r.pd_dot_xy_max == pytest.approx(speed)
    # omega_bar = current bound sqrt(0.1^2 + 0.1^2) + sway bound 0.02 (eq. Wset)
    assert r.omega_bar == pytest.approx(math.sqrt(0.02) + 0.02)
    assert r.v_max == (0.4, 0.3, 0.5)
    assert r.hemisphere_signs == (-1,)
    assert r.epsilon == 0.1


def test_overrides_and_both_hemispheres():
    r = _paper_region(heading="both", e_o=(-0.3, 0.6))
    assert r.hemisphere_signs == (-1, 1)
    assert r.e_o == (-0.3, 0.6)
    with pytest.raises(ConfigError, match="region.bogus"):
        _paper_region(bogus=1)


def test_horizontal_speed_is_clipped_to_the_componentwise_box():
    r = _paper_region(pd_dot_max=(0.1, 0.2, 0.0), pd_dot_xy_max=5.0)
    assert r.pd_dot_xy_max == pytest.approx(math.hypot(0.1, 0.2))


@pytest.mark.parametrize("change, field", [
    ({"e_d": (0.0, 3.0)}, "region.e_d"),
    ({"e_d": (-0.1, 3.0)}, "region.e_d"),
    ({"e_d": (2.0, 1.0)}, "region.e_d"),
    ({"e_d": (1.0, 1.0)}, "region.e_d"),
    ({"e_z": (float("nan"), 1.0)}, r"region.e_z\[0\]"),
    ({"e_o": (-1.0, 0.5)}, "region.e_o"),
    ({"e_o": (-0.5, 1.2)}, "region.e_o"),
    ({"heading": "sideways"}, "region.heading"),
    ({"omega_bar": -0.1}, "region.omega_bar"),
    ({"omega_bar": float("inf")}, "region.omega_bar"),
    ({"v_max": (0.4, 0.0, 0.5)}, "region.v_max"),
    ({"v_max": (0.4, 0.3)}, "region.v_max"),
    ({"pd_dot_max": (0.1, -0.1, 0.0)}, "region.pd_dot_max"),
])
def test_bad_regions_are_named(change, field):
    with pytest.raises(ConfigError, match=field):
        _paper_region(**change)


def test_to_dict_has_the_issue_keys():
    d = _paper_region().to_dict()
    for key in ("e_d", "e_z", "e_o", "heading", "pd_dot_max", "omega_bar", "v_max"):
        assert key in d
    assert d["e_d"] == [0.1, 3.0] and d["heading"] == "toward"
    assert len(d["pd_dot_max"]) == 3 and len(d["v_max"]) == 3


def test_describe_prints_the_set():
    text = _paper_region().describe()
    assert "e_d in [0.1, 3]" in text and "toward" in text and "omega_bar" in text


def _cartesian(e_d: float, e_o: float, theta: float, s: int) -> tuple[np.ndarray, np.ndarray]:
    """State and target position with error (e_d, ., e_o), bearing theta, hemisphere s."""
    phi = math.asin(e_o) if s > 0 else math.pi - math.asin(e_o)
    p_d = np.array([0.3, -1.2, 0.0])
    state = np.array([p_d[0] + e_d * math.cos(theta), p_d[1] + e_d * math.sin(theta), 0.5, theta + phi])
    return state, p_d


@settings(derandomize=True, max_examples=150, deadline=None)
@given(e_d=st.floats(0.1, 3.0), e_o=st.floats(-0.9, 0.9), theta=st.floats(-math.pi, math.pi),
       s=st.sampled_from([-1, 1]))
def test_hemisphere_semantics_match_the_derivation(e_d, e_o, theta, s):
    """Property: a point built in hemisphere s has error (e_d, e_o) under tubekit's error
    coordinates and cos(psi - atan2(e_y, e_x)) has sign s; the 'toward' region contains it iff s = -1."""
    state, p_d = _cartesian(e_d, e_o, theta, s)
    e = error_coordinates(state, p_d)
    assert e[0] == pytest.approx(e_d, rel=1e-9, abs=1e-12)
    assert e[2] == pytest.approx(e_o, abs=1e-9)
    bearing = math.atan2(state[1] - p_d[1], state[0] - p_d[0])
    cos_rel = math.cos(state[3] - bearing)
    assert np.sign(cos_rel) == s
    r = _paper_region()
    assert r.contains(e_d, 0.0, e_o, cos_rel) == (s == -1)
    assert _paper_region(heading="both").contains(e_d, 0.0, e_o, cos_rel)
