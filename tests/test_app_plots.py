"""The app's figure files: every file is written from logged columns, the dynamic panel set for a dynamic run,
the tier line in every title, the legends of drawn artists only, the animation. (The drawing itself is
tested per module in tests/test_plotting_*.py.)"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from PIL import Image

from tubekit.app.plots import DYNAMIC_FIGURE, FIGURE_FILES, plot_all
from tubekit.loop.closed_loop import run_closed_loop
from tubekit.scenario import paper_scenario
from tubekit.tightening import Tightening

from .test_plotting_style import orphan_legend_entries


@pytest.fixture(scope="module")
def short_run():
    sc = replace(paper_scenario(), duration=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_closed_loop(sc, tightening=Tightening.untightened(sc), tube=False, progress=False)
    return sc, run.columns()


def _dynamic_columns(cols):
    """``cols`` with the dynamic plant's columns added (body velocities = applied inputs, small thrusts)."""
    n = len(cols["t"])
    extra = {"u_b": np.nan_to_num(cols["u"]), "v_b": np.full(n, 0.01), "w_b": np.nan_to_num(cols["w"]),
             "r_b": np.nan_to_num(cols["r"]), "X": np.full(n, 5.0), "Z": np.full(n, -2.0), "N": np.full(n, 0.5)}
    return {**cols, **extra}


def test_plot_all_writes_every_figure(tmp_path, short_run):
    sc, cols = short_run
    paths = plot_all(tmp_path, sc, [("baseline", cols)], dpi=50)
    assert [p.name for p in paths] == list(FIGURE_FILES)
    assert all(p.stat().st_size > 5_000 for p in paths)


def test_plot_all_adds_the_dynamic_panel_set_for_a_dynamic_run(tmp_path, short_run):
    """Issue 35 item 4: `simulate` of a dynamic scenario writes the thrust, loop-error and sway figure too."""
    sc, cols = short_run
    dyn = sc.with_changes(plant=replace(sc.plant, kind="dynamic", vehicle="bluerov2_heavy"))
    paths = plot_all(tmp_path, dyn, [("tube", _dynamic_columns(cols))], dpi=50, tiers="safe: certified, kept")
    assert [p.name for p in paths] == [*FIGURE_FILES, DYNAMIC_FIGURE]
    with Image.open(tmp_path / DYNAMIC_FIGURE) as png:
        assert png.size[0] > 500


def test_every_figure_carries_the_tier_line_and_no_orphan_legend_entry(tmp_path, short_run, monkeypatch):
    """The tier line is a title line of every figure; every legend entry names an artist with data."""
    from tubekit.app import plots

    sc, cols = short_run
    seen = []

    def keep(fig, path, **kw):
        seen.append(fig)
        return original(fig, path, **kw)

    original = plots.save_figure
    monkeypatch.setattr(plots, "save_figure", keep)
    tight = replace(Tightening.untightened(sc), obstacle_margin=0.1, tube=np.array([0.05, 0.01, 0.02]))
    plots.plot_all(tmp_path, sc, [("tube", cols), ("baseline", cols)], dpi=40, tightening=tight,
                   tiers="safe: certified, kept; tracking: not certified")
    assert len(seen) == len(FIGURE_FILES)
    for fig in seen:
        assert "tracking: not certified" in fig.get_suptitle()
        assert orphan_legend_entries(fig) == [], fig.get_suptitle()


def test_the_tube_box_is_certified_only_with_the_tracking_tier(tmp_path, short_run, monkeypatch):
    """rho.png's box says "certified" only when the tightening gives tracking (not the safe tier alone)."""
    from tubekit.app import plots
    from tubekit.tiers import Tiers

    sc, cols = short_run
    titles = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, path, **kw: titles.append(
        [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]) or path)
    base = replace(Tightening.untightened(sc), obstacle_margin=0.1, tube=np.array([0.05, 0.01, 0.02]))
    for tiers in (Tiers(True, False), Tiers(True, True)):
        plots.plot_all(tmp_path, sc, [("tube", cols)], tightening=replace(base, tiers=tiers))
    rho = FIGURE_FILES.index("rho.png")
    safe_only, both = titles[rho], titles[len(FIGURE_FILES) + rho]
    assert any("NOT certified" in s for s in safe_only) and not any(", certified" in s for s in safe_only)
    assert any(", certified" in s for s in both)


def test_the_old_homes_still_export_what_tutorials_and_the_app_import():
    from tubekit.app import plots
    from tubekit.plotting.summary import plot_run
    from tubekit.plotting.titles import tier_title

    assert plots.plot_run is plot_run and plots.tier_title is tier_title
    assert callable(plots.envelope_figure) and callable(plots.plot_envelope)  # tutorial 08


def test_animation_gif(tmp_path, short_run):
    from tubekit.app.animate import ANIMATION_GIF, animate_top_view

    sc, cols = short_run
    paths = animate_top_view(tmp_path, sc, [("baseline", cols)], frames=8)
    assert paths[0].name == ANIMATION_GIF
    with Image.open(paths[0]) as gif:
        assert gif.n_frames == 8
        first = np.asarray(gif.convert("RGB"))
        gif.seek(7)
        last = np.asarray(gif.convert("RGB"))
    assert first.shape == last.shape and not np.array_equal(first, last)  # the vehicle moved


def test_animation_legend_is_readable_and_below_the_view(short_run):
    """The GIF's legend: at least 9 pt, below the axes and inside the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from tubekit.app.animate import _build_frame

    sc, cols = short_run
    fig, lines, balls, _, _, _ = _build_frame(sc, [("baseline", cols)])
    legend = fig.legends[0]
    assert min(t.get_fontsize() for t in legend.get_texts()) >= 9  # readable at the GIF's size
    FigureCanvasAgg(fig).draw()
    assert legend.get_window_extent().y1 <= fig.axes[0].get_window_extent().y0  # below the axes, inside
