"""tubekit.plotting.clearance: distances by hand, mm penetrations visible, the minimum at a readable scale."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tubekit.plotting.clearance import CLEARANCE_LINEAR_M, clearance_figure, clearance_of, obstacle_gaps
from tubekit.scenario import paper_scenario

from .test_plotting_style import orphan_legend_entries


def _cols(x, y, z):
    return {"t": np.arange(len(x)) * 0.1, "x": np.asarray(x, float), "y": np.asarray(y, float),
            "z": np.asarray(z, float)}


def test_clearance_by_hand():
    sc = paper_scenario()  # obstacles at (+-3, 0, 0), radius 0.4; vehicle radius 0.2
    cols = _cols([3.0, 0.0], [1.0, 0.0], [0.0, 0.0])
    assert obstacle_gaps(cols, sc) == pytest.approx(np.array([[0.4, np.hypot(6.0, 1.0) - 0.6], [2.4, 2.4]]))
    assert clearance_of(cols, sc) == pytest.approx([0.4, 2.4])
    assert np.all(np.isinf(clearance_of(cols, replace(sc, obstacles=()))))


def test_clearance_axis_shows_mm_penetration():
    sc = paper_scenario()
    fig = clearance_figure(sc, [("baseline", _cols([2.0, 2.405, 2.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]))])
    ax = fig.axes[0]
    assert ax.get_yscale() == "symlog" and ax.get_ylim()[0] <= -CLEARANCE_LINEAR_M
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "baseline: min -5.0 mm at t = 0.1 s" in labels and orphan_legend_entries(fig) == []


def test_a_far_run_reads_in_metres():
    sc = paper_scenario()
    fig = clearance_figure(sc, [("tube", _cols([0.0, 0.0], [18.0, 18.0], [0.0, 0.0]))])
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(s.startswith("tube: min +17.65 m") for s in labels)
