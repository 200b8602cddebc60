"""tubekit.model.loiter: the loiter backup law (constant surge, turn onto the line of sight) and its shape."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BACKUP_LAWS, BackupLaw, backup_law_from_dict
from tubekit.model.loiter import Loiter, loiter_input, loiter_shape, loiter_shape_slope

LAW = Loiter(surge=0.2, yaw_rate=0.5, yaw_band=0.1, heave=0.3, heave_band=0.04, bend=0.5)
ANCHOR = (0.0, 0.0, -1.0)


def test_the_law_is_registered_and_a_backup_law():
    assert BACKUP_LAWS["loiter"] is Loiter and isinstance(LAW, BackupLaw)
    assert LAW.bounds == (0.2, 0.3, 0.5) and LAW.min_surge == 0.2 and not LAW.blends
    assert LAW.within(0.2, 0.3, 0.5) and not LAW.within(0.19, 0.3, 0.5)
    assert backup_law_from_dict(LAW.to_dict()) == LAW and LAW.to_dict()["kind"] == "loiter"


@pytest.mark.parametrize("state, want_r", [
    ((2.0, 0.0, -1.0, math.pi), 0.0),              # east of the anchor, heading west: pointing at it
    ((2.0, 0.0, -1.0, 0.0), 0.5),                  # heading east, away: φ = π, turn at k (the ridge's own side)
    ((2.0, 0.0, -1.0, math.pi + 0.05), -0.25),     # 0.05 rad left of the line of sight: r = -k 0.05/0.1
    ((2.0, 0.0, -1.0, math.pi - 0.05), 0.25),
    ((0.0, -3.0, -1.0, math.pi / 2), 0.0),         # south of it heading north
    ((0.0, -3.0, -1.0, 0.0), 0.5),                 # heading east: the anchor is 90° to the left, φ = -π/2
])
def test_the_yaw_turns_the_heading_onto_the_line_of_sight_and_the_surge_never_changes(state, want_r):
    u, w, r = loiter_input(LAW, state, ANCHOR)
    assert u == 0.2 and w == 0.0 and r == pytest.approx(want_r, abs=1e-12)


@pytest.mark.parametrize("z, want_w", [(-1.02, 0.15), (-0.5, -0.3), (-3.0, 0.3)])
def test_the_heave_holds_the_anchors_depth(z, want_w):
    assert loiter_input(LAW, (1.0, 1.0, z, 0.0), ANCHOR)[1] == pytest.approx(want_w)


def test_the_shape_by_hand():
    # bend 0.5: L = pi - 0.25; quadratic below the bend, linear above, a(pi) = 1
    length = math.pi - 0.25
    assert loiter_shape(0.5, 0.0) == 0.0 and loiter_shape(0.5, math.pi) == pytest.approx(1.0)
    assert loiter_shape(0.5, -math.pi) == pytest.approx(1.0)
    assert loiter_shape(0.5, 0.5) == pytest.approx(0.25 / length)
    assert loiter_shape(0.5, 0.25) == pytest.approx(0.0625 / length)
    assert loiter_shape(0.5, 2.0) == pytest.approx(1.75 / length)
    assert loiter_shape_slope(0.5, 0.25) == pytest.approx(0.5 / length)
    assert loiter_shape_slope(0.5, 2.0) == pytest.approx(1.0 / length)


@settings(derandomize=True, max_examples=80, deadline=None)
@given(bend=st.floats(0.05, math.pi / 2), phi=st.floats(0.0, math.pi - 1e-6))
def test_the_shape_is_even_nondecreasing_and_its_slope_is_its_derivative(bend, phi):
    """Property: a(φ) = a(−φ) in [0, 1], nondecreasing in |φ|, and ``loiter_shape_slope`` is its derivative
    (a central difference)."""
    a = loiter_shape(bend, phi)
    assert 0.0 <= a <= 1.0 + 1e-12 and a == loiter_shape(bend, -phi)
    assert loiter_shape(bend, min(math.pi, phi + 1e-3)) >= a
    h = 1e-6
    lo, hi = max(0.0, phi - h), phi + h
    numeric = (loiter_shape(bend, hi) - loiter_shape(bend, lo)) / (hi - lo)
    assert numeric == pytest.approx(loiter_shape_slope(bend, phi), abs=1e-5)


@pytest.mark.parametrize("kwargs, field", [
    ({"surge": 0.0}, "backup.surge"),
    ({"surge": -0.1}, "backup.surge"),
    ({"yaw_rate": 0.0}, "backup.yaw_rate"),
    ({"yaw_band": 2.0}, "backup.yaw_band"),
    ({"bend": 1.6}, "backup.bend"),
    ({"heave_band": 0.0}, "backup.heave_band"),
])
def test_bad_gains_are_refused(kwargs, field):
    params = dict(surge=0.2, yaw_rate=0.5, yaw_band=0.1, heave=0.3, heave_band=0.04) | kwargs
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        Loiter(**params)
