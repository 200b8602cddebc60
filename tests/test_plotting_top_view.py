"""tubekit.plotting.top_view: the logged path, the tube "(certified)" only with the tracking tier, the target at
the end and the lag, a frame that scales with the scenario, a legend of drawn artists only."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from tubekit.plotting.top_view import top_view, tube_label
from tubekit.scenario import load_scenario, paper_scenario
from tubekit.tightening import Tightening
from tubekit.tiers import Tiers

from .test_plotting_framing import path_columns
from .test_plotting_style import orphan_legend_entries

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def paper_run():
    return paper_scenario(), path_columns((-0.5, 3.0, 0.0), (0.25, -0.2, 0.01), 10.0)


def _tight(sc, tiers=Tiers()):
    return replace(Tightening.untightened(sc), obstacle_margin=0.15, tiers=tiers)


def _labels(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]


def test_top_view_plots_the_logged_path(paper_run):
    sc, cols = paper_run
    fig = top_view(sc, [("baseline", cols)])
    lines = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label() == "baseline"]
    assert lines and np.allclose(lines[0].get_xdata(), cols["x"]) and np.allclose(lines[0].get_ydata(), cols["y"])


def test_the_target_at_the_end_is_marked_with_the_lag(paper_run):
    """Issue 35 item 4: the target's position at the end is marked, and the first run's distance to it."""
    sc, cols = paper_run
    fig = top_view(sc, [("tube", cols)])
    ax = fig.axes[0]
    end = next(ln for ln in ax.get_lines() if ln.get_label() == "target at t = 10 s")
    want = sc.trajectory.position(np.array([10.0]))[0]
    assert np.allclose([end.get_xdata()[0], end.get_ydata()[0]], want[:2])
    lag = next(ln for ln in ax.get_lines() if ln.get_label().startswith("tube's lag at the end"))
    d = np.linalg.norm(want - [cols["x"][-1], cols["y"][-1], cols["z"][-1]])
    assert lag.get_label().endswith(f"{d:.3g} m")


@pytest.mark.parametrize("tiers, said", [(Tiers(True, True), "(certified)"), (Tiers(True, False), "(not certified)"),
                                         (Tiers(), "(not certified)")])
def test_the_tube_is_certified_only_with_the_tracking_tier(paper_run, tiers, said):
    """Issue 35 item 4: the band said "(certified)" on a run whose tracking tier was not given."""
    sc, cols = paper_run
    labels = _labels(top_view(sc, [("tube", cols)], tightening=_tight(sc, tiers)))
    band = [s for s in labels if s.startswith("position tube")]
    assert len(band) == 1 and band[0].endswith(said)
    assert tube_label(0.15, _tight(sc, tiers)).endswith(said)


def test_a_legend_entry_for_every_drawn_artist_and_none_other(paper_run):
    sc, cols = paper_run
    fig = top_view(sc, [("tube", cols), ("baseline", cols)], tightening=_tight(sc))
    assert orphan_legend_entries(fig) == []
    labels = _labels(fig)
    for text in ("position tube", "start", "end of tube", "end of baseline", "sensing range", "target at t = 10 s"):
        assert any(s.startswith(text) for s in labels), text


def test_the_legend_sits_beside_the_view_with_time_ticks_on_the_path(paper_run):
    sc, cols = paper_run
    fig = top_view(sc, [("baseline", cols)], tightening=_tight(sc))
    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    assert any(t.get_text().endswith(" s") for t in ax.texts)  # time ticks on the path
    legend = next(a.get_legend() for a in fig.axes if a.get_legend())
    assert legend.get_window_extent().x0 >= ax.get_window_extent().x1  # the legend sits beside the view
    assert max(t.get_fontsize() for t in legend.get_texts()) <= 7  # small: the view keeps the canvas


def test_a_15_m_sensing_scenario_zooms_on_the_path_and_names_what_it_leaves_out():
    """Issue 35 item 4: bluerov2_slow's top view was a blob in a 30 m circle; now the axes hold the path."""
    sc = load_scenario(ROOT / "examples" / "bluerov2_slow.toml")
    cols = path_columns((-1.0, 3.0, 0.2), (0.08, 0.0, 0.0), 20.0)
    fig = top_view(sc, [("tube", cols)], tightening=_tight(sc, Tiers(True, True)))
    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    target = sc.trajectory.position(np.linspace(0.0, 20.0, 50))
    xs = np.r_[cols["x"], target[:, 0]]
    ys = np.r_[cols["y"], target[:, 1]]
    assert xs.min() - 3.0 < x0 < xs.min() and xs.max() < x1 < xs.max() + 3.0
    assert y0 < ys.min() and y1 > ys.max() and (x1 - x0) < 8.0 and (y1 - y0) < 8.0
    assert not any("sensing range" in s for s in _labels(fig))  # not drawn ...
    note = " ".join(t.get_text() for t in ax.texts)
    assert "wider than the view" in note and "2 obstacles outside the view" in note  # ... but named
    assert orphan_legend_entries(fig) == []
