"""The side view at the nearest obstacle: distances by hand, the zoom on the closest approach."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from tubekit.app.plots_obstacle import draw_obstacle_side_view, obstacle_frame
from tubekit.scenario import paper_scenario


def test_obstacle_frame_by_hand():
    from tubekit.app.plots_obstacle import obstacle_frame

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
    labels = ax.get_legend_handles_labels()[1]
    assert labels == ["run: min clearance -10.0 mm"]


def test_no_obstacles_no_side_view():
    from dataclasses import replace

    ax = Figure().add_subplot()
    draw_obstacle_side_view(ax, replace(paper_scenario(), obstacles=()), [("run", {})], [{}])
    assert not ax.axison
