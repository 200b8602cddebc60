"""tubekit.plotting.side_view: distances by hand, the zoom on the closest approach only when it shows more, the
runs that stay away named instead of drawn."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from matplotlib.figure import Figure

from tubekit.plotting.side_view import NEAR_M, draw_obstacle_side_view, obstacle_frame
from tubekit.scenario import paper_scenario


def test_obstacle_frame_by_hand():
    sc = paper_scenario()  # obstacles at (+-3, 0, 0), radius 0.4; vehicle radius 0.2
    f = obstacle_frame({"x": np.array([3.0, -3.3]), "y": np.array([0.5, 0.0]), "z": np.array([0.3, -0.4])}, sc)
    assert f["h"] == pytest.approx([0.5, 0.3]) and f["dz"] == pytest.approx([0.3, -0.4])
    assert f["gap"] == pytest.approx([np.sqrt(0.34) - 0.6, 0.5 - 0.6])


def test_the_zoom_is_centred_on_the_smallest_clearance():
    sc = paper_scenario()
    cols = {"x": np.array([2.0, 3.0, 3.7]), "y": np.zeros(3), "z": np.array([0.0, 0.59, 0.0])}  # 2nd: -10 mm
    ax = Figure().add_subplot()
    draw_obstacle_side_view(ax, sc, [("run", cols)], [{"color": "C0"}])
    zoom = ax.child_axes[0]
    assert np.mean(zoom.get_xlim()) == pytest.approx(0.0) and np.mean(zoom.get_ylim()) == pytest.approx(0.59)
    assert ax.get_legend_handles_labels()[1] == ["run: min clearance -10.0 mm"]


def test_no_zoom_when_the_view_already_shows_the_closest_approach():
    """Issue 35 item 4: a 0.4 m pass was zoomed into an inset 2 m wide, wider than the view itself."""
    sc = paper_scenario()
    cols = {"x": np.array([1.9, 3.0, 4.1]), "y": np.zeros(3), "z": np.array([0.0, 1.0, 0.0])}  # 2nd: +400 mm
    ax = Figure().add_subplot()
    draw_obstacle_side_view(ax, sc, [("run", cols)], [{"color": "C0"}])
    assert not ax.child_axes
    assert ax.get_legend_handles_labels()[1] == ["run: min clearance +400.0 mm"]


def test_a_run_that_stays_away_is_named_not_drawn():
    """Issue 35 item 4: a 15 m clearance was a marker outside the view, 'zoom: 77400 mm wide', '+15480.0 mm'."""
    sc = paper_scenario()
    far = {"x": np.array([3.0, 3.0]), "y": np.array([16.0, 17.0]), "z": np.zeros(2)}  # 15.4 m and more
    ax = Figure().add_subplot()
    draw_obstacle_side_view(ax, sc, [("tube", far)], [{"color": "C0"}])
    assert not ax.child_axes and ax.get_legend_handles_labels()[1] == []
    note = " ".join(t.get_text() for t in ax.texts)
    assert f"never within {NEAR_M:g} m" in note and "tube +15.40 m" in note


def test_no_obstacles_no_side_view():
    ax = Figure().add_subplot()
    draw_obstacle_side_view(ax, replace(paper_scenario(), obstacles=()), [("run", {})], [{}])
    assert not ax.axison
