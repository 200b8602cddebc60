"""verify.theorem.path_clearance: the candidate's footprint along the target's path, against obstacles and walls."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit import load_scenario
from tubekit.model.trajectory import Line
from tubekit.scenario import Obstacle
from verify.theorem.path_clearance import (PathFootprint, _cylinder_distance, _sector_distance, contains,
                                          horizon_end, path_clearance, path_workspace)

BASE = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
FOOT = PathFootprint(reach=1.0, rise=0.5, ball=0.3, outer=1.5, outer_height=0.8)


def _line(offset: float, z: float = 0.0, radius: float = 0.4):
    """A target on the x axis at 0.2 m/s for 100 s; one obstacle ``offset`` m to its side at x = 5, depth ``z``."""
    return BASE.with_changes(trajectory=Line(start=(0.0, 0.0, 0.0), direction_velocity=(0.2, 0.0, 0.0)),
                             obstacles=(Obstacle((5.0, offset, z), radius), Obstacle((-30.0, 30.0, 0.0), 0.4)))


@pytest.mark.parametrize("offset, ok", [(2.0, True), (1.85, False), (1.0, False), (3.0, True)])
def test_the_binding_distance_is_the_footprint_plus_the_radius(offset, ok):
    """By hand: the footprint needs max(reach + ball, outer) + r_o = max(1.3, 1.5) + 0.4 = 1.9 m of horizontal
    distance between path and centre (same depth); the slack is the distance minus 1.9, less the sampling
    allowance (0.2 m/s x spacing / 2 <= 5e-4 m)."""
    sc = _line(offset)
    cond = path_clearance(sc, FOOT, horizon_end(sc))[0]
    assert cond.ok is ok and cond.condition == "path_clearance[0]"
    assert cond.lhs == pytest.approx(offset - 1.9, abs=6e-4) and cond.lhs <= offset - 1.9
    assert "needs 1.9 m" in cond.detail and f"has {offset:.3g} m" in cond.detail and "t = 25.0 s" in cond.detail


def test_an_obstacle_deep_below_the_path_is_clear():
    """Vertically the footprint reaches max(rise + ball, outer_height) = 0.8 m: an obstacle 1.3 m below the
    path's depth with radius 0.4 clears it by hypot(0, 1.3 − 0.8) − 0.4 = 0.1 m, though it lies under it."""
    cond = path_clearance(_line(0.0, z=1.3), FOOT, 100.0)[0]
    assert cond.ok and cond.lhs == pytest.approx(0.1, abs=6e-4)


def test_the_workspace_walls_by_hand():
    sc = _line(10.0).with_changes(workspace=((-3.0, -2.0, -5.0), (40.0, 2.0, 5.0)))
    cond = path_workspace(sc, FOOT, horizon_end(sc))[0]
    # the wall 2 m to each side, the footprint reaches max(1.0 + 0.3, 1.5) = 1.5 m: 0.5 m left (x: 3 and 40 − 20.8)
    assert cond.ok and cond.lhs == pytest.approx(0.5, abs=6e-4)
    assert path_workspace(sc.with_changes(workspace=None), FOOT, 10.0) == ()


def test_the_horizon_end_is_the_duration_plus_a_horizon():
    assert horizon_end(BASE) == pytest.approx(BASE.duration + BASE.controller.horizon_steps * BASE.controller.dt)
    assert math.isfinite(horizon_end(BASE))


# ---- the sector behind the target (a bearing face, step 17b) --------------------------------------------------

def _sector_samples(p: np.ndarray, back: np.ndarray, cone: float, radius: float, n: int = 400) -> np.ndarray:
    """Dense points (m, 2-D) of the sector of half-angle ``cone`` and ``radius`` about ``p`` around ``back``."""
    angles = np.linspace(-cone, cone, n)
    rays = np.stack([np.cos(angles) * back[0] - np.sin(angles) * back[1],
                     np.sin(angles) * back[0] + np.cos(angles) * back[1]], axis=1)
    lengths = np.linspace(0.0, radius, n)
    return p[None, None, :2] + lengths[None, :, None] * rays[:, None, :]


@settings(max_examples=60, deadline=None, derandomize=True)
@given(cx=st.floats(-8, 8), cy=st.floats(-8, 8), heading=st.floats(-math.pi, math.pi), cone=st.floats(0.05, math.pi),
       radius=st.floats(0.5, 6.0))
def test_the_sector_distance_is_the_distance_to_the_sector(cx, cy, heading, cone, radius):
    """Property: horizontally, :func:`_sector_distance` is the Euclidean distance from the centre to the sector
    (dense samples of it: never below the computed value by more than round-off, and within the samples' spacing
    above it); a point inside the sector gets a value <= 0."""
    p = np.array([[0.3, -0.2, 0.0]])
    back = np.array([[math.cos(heading), math.sin(heading)]])
    centre = np.array([cx, cy, 0.0])
    got = float(_sector_distance(centre, p, back, cone, radius, half=1.0)[0])
    pts = _sector_samples(p[0], back[0], cone, radius).reshape(-1, 2)
    sampled = float(np.min(np.hypot(pts[:, 0] - cx, pts[:, 1] - cy)))
    spacing = radius * (2 * cone / 399 + 1 / 399)
    if got > 0.0:
        assert got <= sampled + 1e-9 and sampled <= got + spacing
    else:
        assert sampled <= spacing


@settings(max_examples=60, deadline=None, derandomize=True)
@given(heading=st.floats(-math.pi, math.pi), cone=st.floats(0.05, 1.5), radius=st.floats(1.0, 6.0),
       bearing=st.floats(-1.0, 1.0), reach=st.floats(0.05, 0.95))
def test_inside_the_sector_the_distance_is_minus_the_distance_to_its_nearest_side(heading, cone, radius, bearing,
                                                                                   reach):
    """Property: a point of a convex sector (half-angle < π/2) at bearing ``bearing`` × ``cone`` from its axis and
    ``reach`` × ``radius`` from its apex gets minus its distance to the nearest side, by hand: the arc
    (radius − |w|) or an edge (|w| sin(cone − |bearing|)); so the value is continuous across the edges (1-Lipschitz)
    instead of jumping to |w| − radius inside."""
    phi, dist = bearing * cone, reach * radius
    p = np.array([[0.3, -0.2, 0.0]])
    axis = np.array([math.cos(heading), math.sin(heading)])
    ray = np.array([math.cos(phi) * axis[0] - math.sin(phi) * axis[1],
                    math.sin(phi) * axis[0] + math.cos(phi) * axis[1]])
    centre = np.array([p[0, 0] + dist * ray[0], p[0, 1] + dist * ray[1], 0.0])
    got = float(_sector_distance(centre, p, axis[None, :], cone, radius, half=math.inf)[0])
    assert got == pytest.approx(-min(radius - dist, dist * math.sin(cone - abs(phi))), abs=1e-9)


def test_a_shortfall_capped_by_the_depth_face_names_the_horizontal_overlap():
    """By hand: a target on the x axis at 0.2 m/s, the sector of half-angle 0.3 rad and radius 10 m behind it, no
    pads, half-height 0.5 m; a rock of radius 0.4 m 1 m off the path at the target's depth. Where it lies deep in the
    sector the clearance is the depth face's, −0.5 − 0.4 − ball 0.3 = −1.2 m; horizontally it lies up to
    min(10 − |w|, |w| sin(0.3 − φ)) + 0.7 inside, largest where the edge and the arc are equally near (2.23 m
    with the pads, from a dense search), which the detail names when asked to explain (a certificate's report; not
    the search's pass)."""
    sc = _line(1.0)
    sector = PathFootprint(reach=10.0, rise=0.5, ball=0.3, outer=10.0, outer_height=0.5, cone=0.3, cone_reach=10.0,
                           cone_outer=10.0)
    quiet, cond = (path_clearance(sc, sector, horizon_end(sc), explain=explain)[0] for explain in (False, True))
    assert not cond.ok and cond.lhs == pytest.approx(-1.2, abs=6e-4)
    assert quiet == dataclasses.replace(cond, detail=quiet.detail) and "horizontally" not in quiet.detail
    along = np.linspace(1e-3, 10.0, 200001)  # the target's distance past the rock (m), the rock 1 m to its side
    w, phi = np.hypot(along, 1.0), np.arctan2(1.0, along)
    deepest = float(np.max(np.where(phi < 0.3, np.minimum(10.0 - w, w * np.sin(0.3 - phi)), -np.inf))) + 0.7
    found = float(re.search(r"horizontally it lies up to ([0-9.]+) m inside", cond.detail).group(1))
    assert found == pytest.approx(deepest, abs=5e-3) and "the shortfall shown is the depth face's" in cond.detail


def test_a_half_turn_sector_is_the_disc():
    """``cone`` = π: the sector is the disc of the same radius, the cylinder distance's horizontal part."""
    rng = np.random.default_rng(7)
    p = rng.uniform(-5, 5, (50, 3))
    back = np.tile([[1.0, 0.0]], (50, 1))
    centre = np.array([1.0, 2.0, 0.5])
    np.testing.assert_allclose(_sector_distance(centre, p, back, math.pi, 2.0, 0.7),
                               _cylinder_distance(centre, p, 2.0, 0.7), atol=1e-12)


def test_a_narrow_sector_behind_a_line_target_clears_a_rock_beside_the_path_that_the_disc_does_not():
    """By hand: a target on the x axis, the sector of half-angle 0.2 rad and radius 4 m behind it, pads 0.3 m (arc)
    and the ball 0.3 m: it reaches sin(0.2) × 4 + 0.6 = 1.39 m sideways, so a rock of radius 0.4 m 2.2 m off the
    path clears it by about 0.4 m; the disc of the same reach (4.3 m + ball) does not."""
    sc = _line(2.2)
    disc = PathFootprint(reach=4.3, rise=0.5, ball=0.3, outer=4.3, outer_height=0.8)
    sector = PathFootprint(reach=4.3, rise=0.5, ball=0.3, outer=4.3, outer_height=0.8, cone=0.2, cone_reach=4.0,
                           cone_outer=4.0)
    assert not path_clearance(sc, disc, horizon_end(sc))[0].ok
    cond = path_clearance(sc, sector, horizon_end(sc))[0]
    assert cond.ok and cond.lhs == pytest.approx(2.2 - 0.4 - 4.0 * math.sin(0.2) - 0.6, abs=6e-3)
    assert "within 0.2 rad of behind the target" in cond.detail


def _foot(reach: float, pad: float, cone: float | None, ball: float, rise: float) -> PathFootprint:
    """A footprint with the sector radius ``reach`` and the pad ``pad`` (m), a disc when ``cone`` is None."""
    sector = {} if cone is None else {"cone": cone, "cone_reach": reach, "cone_outer": reach}
    return PathFootprint(reach=reach + pad, rise=rise, ball=ball, outer=reach + pad, outer_height=rise + 0.3, **sector)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(reach=st.floats(0.5, 5.0), pad=st.floats(0.0, 0.5), cone=st.one_of(st.none(), st.floats(0.05, 3.0)),
       ball=st.floats(0.1, 0.5), rise=st.floats(0.2, 1.0), shrink=st.tuples(*[st.floats(0.3, 1.0)] * 5),
       offset=st.floats(0.5, 8.0))
def test_a_footprint_that_contains_another_clears_no_more(reach, pad, cone, ball, rise, shrink, offset):
    """Property: a footprint shrunk in every extent is contained in the original (:func:`contains`), and the path's
    clearance of every obstacle is no larger for the original (the premise of the search's shortcut)."""
    big = _foot(reach, pad, cone, ball, rise)
    small = _foot(reach * shrink[0], pad * shrink[1], None if cone is None else cone * shrink[2], ball * shrink[3],
                  rise * shrink[4])
    assert contains(big, small)
    sc = _line(offset)
    for wide, narrow in zip(path_clearance(sc, big, 40.0), path_clearance(sc, small, 40.0)):
        assert wide.lhs <= narrow.lhs + 1e-9
