"""tubekit.plotting.view_3d: true aspect, framed on the path (far obstacles left out and named)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tubekit.plotting.view_3d import view_3d
from tubekit.scenario import load_scenario, paper_scenario

from .test_plotting_framing import path_columns
from .test_plotting_style import orphan_legend_entries

ROOT = Path(__file__).resolve().parents[1]


def test_view_3d_true_aspect():
    sc = paper_scenario()
    ax = view_3d(sc, [("baseline", path_columns((-0.5, 3.0, 0.0), (0.25, -0.2, 0.02), 10.0))]).axes[0]
    spans = np.array([np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim()), np.ptp(ax.get_zlim())])
    box = np.asarray(ax.get_box_aspect())
    assert np.allclose(box / box[0], spans / spans[0], rtol=1e-6)


def test_far_obstacles_do_not_set_the_frame_and_every_legend_entry_is_drawn():
    sc = load_scenario(ROOT / "examples" / "bluerov2_slow.toml")  # obstacles 17 m from the circle's centre
    fig = view_3d(sc, [("tube", path_columns((-1.0, 3.0, 0.2), (0.08, 0.0, -0.005), 20.0))])
    ax = fig.axes[0]
    assert np.ptp(ax.get_xlim()) < 5.0 and "2 obstacles far from the path not drawn" in ax.get_title()
    assert orphan_legend_entries(fig) == []


def test_near_obstacles_are_drawn_with_one_legend_entry():
    fig = view_3d(paper_scenario(), [("tube", path_columns((-0.5, 3.0, 0.0), (0.25, -0.2, 0.0), 10.0))])
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels.count("obstacle") == 1 and orphan_legend_entries(fig) == []
