"""Figures: every file is written from logged columns, and plotted data match the log."""

from __future__ import annotations

from tubekit.tiers import Tiers

import warnings
from dataclasses import replace

import numpy as np
import pytest

from tubekit.loop.closed_loop import run_closed_loop
from tubekit.loop.metrics import rho_period_peaks
from tubekit.app.plots import (FIGURE_FILES, clearance_figure, errors_figure, inputs_figure, period_envelope, plot_all,
                               top_view, view_3d)
from tubekit.scenario import paper_scenario
from tubekit.tightening import Tightening


@pytest.fixture(scope="module")
def short_run():
    sc = replace(paper_scenario(), duration=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_closed_loop(sc, tightening=Tightening.untightened(sc), tube=False, progress=False)
    return sc, run.columns()


def test_plot_all_writes_every_figure(tmp_path, short_run):
    sc, cols = short_run
    paths = plot_all(tmp_path, sc, [("baseline", cols)], rho_tilde=None, certified=False, dpi=50)
    assert [p.name for p in paths] == list(FIGURE_FILES)
    assert all(p.stat().st_size > 5_000 for p in paths)


def test_top_view_plots_the_logged_path(short_run):
    sc, cols = short_run
    fig = top_view(sc, [("baseline", cols)])
    lines = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label() == "baseline"]
    assert lines and np.allclose(lines[0].get_xdata(), cols["x"]) and np.allclose(lines[0].get_ydata(), cols["y"])


def test_errors_figure_marks_epsilon(short_run):
    sc, cols = short_run
    fig = errors_figure(sc, [("baseline", cols)])
    ys = [ln.get_ydata() for ax in fig.axes for ln in ax.get_lines()]
    assert any(np.allclose(y, sc.epsilon) for y in ys)


def test_rho_period_peaks_are_the_maxima(short_run):
    _, cols = short_run
    t, peaks = rho_period_peaks(cols)
    m = int(np.sum(cols["step"] == cols["step"][0]))
    assert len(peaks) == (len(cols["rho_norm"]) - 1) // m
    assert peaks[0] == pytest.approx(np.max(cols["rho_norm"][1:m + 1]))


def _tightening(sc, margin=0.1):
    base = Tightening.untightened(sc)
    return replace(base, obstacle_margin=margin, v_max=base.v_max * 0.8, tube=np.array([0.05, 0.0, 0.0]))


def _legend_texts(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]


def test_top_view_tube_time_ticks_markers_and_a_legend_beside_the_view(short_run):
    sc, cols = short_run
    fig = top_view(sc, [("baseline", cols)], tightening=_tightening(sc))
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    labels = _legend_texts(fig)
    assert any("position tube" in s for s in labels)
    assert any(s.startswith("start") for s in labels) and any(s.startswith("end of baseline") for s in labels)
    assert any("sensing range" in s for s in labels)
    assert any(t.get_text().endswith(" s") for t in ax.texts)  # time ticks on the path
    legend = next(a.get_legend() for a in fig.axes if a.get_legend())
    assert legend.get_window_extent().x0 >= ax.get_window_extent().x1  # the legend sits beside the view
    assert max(t.get_fontsize() for t in legend.get_texts()) <= 7  # small: the view keeps the canvas


def test_top_view_side_view_shows_the_closest_approach_in_mm(short_run):
    """The side view's marker sits at the run's smallest clearance, computed here from the positions."""
    sc, cols = short_run
    fig = top_view(sc, [("baseline", cols)])
    p = np.column_stack([cols["x"], cols["y"], cols["z"]])
    gaps = np.min([np.linalg.norm(p - np.asarray(o.center), axis=1) - o.radius - sc.vehicle_radius
                   for o in sc.obstacles], axis=0)
    label = f"baseline: min clearance {1e3 * gaps.min():+.1f} mm"
    assert label in _legend_texts(fig)
    side = [a for a in fig.axes if a.get_xlabel().startswith("horizontal distance")]
    assert side and side[0].child_axes, "no zoomed inset on the closest approach"


def _rho_columns():
    """Two periods of 4 ticks (9 rows); the pre-reset peak of a period is logged on its last row."""
    t = np.arange(9) * 0.025
    step = np.array([0, 0, 0, 0, 1, 1, 1, 1, 2])
    rho = {"rho_d": [0, .01, -.05, .02, .03, 0, .04, -.08, .06], "rho_z": [0, .1, .1, .1, .1, .2, .2, .2, .2],
           "rho_o": [0, 0, 0, 0, .3, 0, 0, 0, -.1]}
    return {"t": t, "step": step, **{k: np.array(v) for k, v in rho.items()}, "backup_active": np.zeros(9)}


def test_rho_figure_plots_the_per_axis_box_ratio():
    """Per axis, the per-period peak of |rho_j| / tube_j: rows 1..4 and 5..8, by hand."""
    from tubekit.app.plots import rho_figure

    fig = rho_figure([("tube", _rho_columns())], (0.1, 0.25, 0.4), True)
    want = {0: [0.5, 0.8], 1: [0.4, 0.8], 2: [0.75, 0.25]}
    for j, ax in enumerate(fig.axes):
        data = [ln.get_ydata() for ln in ax.get_lines() if ln.get_label().startswith("tube")]
        assert np.allclose(data[0], want[j])
        assert any(np.allclose(ln.get_ydata(), 1.0) for ln in ax.get_lines())  # the box the promise checks
    assert "largest 0.8" in fig.get_suptitle()


def test_rho_figure_without_a_tube_shows_the_deviation_itself():
    from tubekit.app.plots import rho_figure

    fig = rho_figure([("tube", _rho_columns())], (0.0, 0.0, 0.0), False)
    data = [ln.get_ydata() for ln in fig.axes[0].get_lines() if ln.get_label().startswith("tube")]
    assert np.allclose(data[0], [0.05, 0.08]) and "(m)" in fig.axes[0].get_ylabel()
    assert "nothing promised" in fig.get_suptitle()


def test_rho_figure_leaves_out_the_backup_ticks():
    from tubekit.app.plots import rho_figure

    cols = _rho_columns()
    cols["backup_active"][7] = 1.0  # the -0.08 of e_d is under the backup law: not promised, not drawn
    data = [ln.get_ydata() for ln in rho_figure([("tube", cols)], (0.1, 0.25, 0.4), True).axes[0].get_lines()
            if ln.get_label().startswith("tube")]
    assert np.allclose(data[0], [0.5, 0.6])


def test_period_envelope_is_min_max_per_period(short_run):
    _, cols = short_run
    t, lo, hi = period_envelope(cols, "u")
    first = cols["step"] == cols["step"][0]
    assert t[0] == cols["t"][0] and t[-1] == cols["t"][-1]
    assert lo[0] == pytest.approx(np.nanmin(cols["u"][first])) and hi[0] == pytest.approx(np.nanmax(cols["u"][first]))
    assert np.all(lo[np.isfinite(lo)] <= hi[np.isfinite(hi)])


def test_inputs_figure_draws_v_hat_and_both_bounds(short_run):
    sc, cols = short_run
    fig = inputs_figure(sc, [("baseline", cols)], tightening=_tightening(sc))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("hat v" in s for s in labels) and any("min-max per period" in s for s in labels)
    assert any("bound of $V$" in s for s in labels) and any("bar V" in s for s in labels)


def test_clearance_axis_shows_mm_penetration(short_run):
    sc, cols = short_run
    fig = clearance_figure(sc, [("baseline", cols)])
    ax = fig.axes[0]
    assert ax.get_yscale() == "symlog" and ax.get_ylim()[0] <= -0.01


def test_view_3d_true_aspect(short_run):
    sc, cols = short_run
    ax = view_3d(sc, [("baseline", cols)]).axes[0]
    spans = np.array([np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim()), np.ptp(ax.get_zlim())])
    box = np.asarray(ax.get_box_aspect())
    assert np.allclose(box / box[0], spans / spans[0], rtol=1e-6)


def test_animation_gif(tmp_path, short_run):
    from PIL import Image

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


def test_plot_run_is_the_figure_of_a_run():
    """The app draws a run (the core's SimulationResult has no plot method)."""
    from tubekit.app.plots import plot_run
    from tubekit.exceptions import ConfigError

    sc = replace(paper_scenario(), duration=1.0)
    tight = replace(Tightening.untightened(sc), sigma=0.5, obstacle_margin=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_closed_loop(sc, tightening=tight, tube=True, progress=False)
    fig = plot_run(run)
    lines = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label() == "tube"]
    assert lines and np.allclose(lines[0].get_xdata(), run.states[:, 0])
    labels = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert any("position tube" in text for text in labels)  # a tube run shows its tube
    with pytest.raises(ConfigError, match="run: expected a tubekit.SimulationResult"):
        plot_run(run.columns())


# ---- the backup and the tiers on the figures (issue 21) -----------------------------------------------------
def _backup_columns():
    t = np.arange(0.0, 10.01, 0.5)
    active = np.zeros(t.size)
    active[4:8] = 1.0    # 2.0 s .. 4.0 s (ends at the first tick following a plan)
    active[-3:] = 1.0    # 9.0 s .. the end
    return {"t": t, "backup_active": active}


def test_backup_stretches_are_the_active_intervals():
    from tubekit.app.plots import backup_stretches

    assert backup_stretches(_backup_columns()) == [(2.0, 4.0), (9.0, 10.0)]
    assert backup_stretches({"t": np.arange(3.0)}) == []


def test_the_backup_is_shaded_once_per_stretch_with_one_legend_entry():
    from matplotlib.figure import Figure

    from tubekit.app.plots import backup_stretches, shade_backup

    ax = Figure().add_subplot()
    shade_backup(ax, backup_stretches(_backup_columns()))
    assert len(ax.patches) == 2
    labels = [p.get_label() for p in ax.patches if p.get_label() and not p.get_label().startswith("_")]
    assert labels == ["backup law active (station keeping)"]


def test_tier_title_names_the_failed_conditions_of_a_tier_not_given():
    from tubekit.app.plots import tier_title

    assert tier_title(Tiers(True, False), {"tracking": ["keep_up", "yaw_budget"]}) == \
        "safe: certified; tracking: not certified (keep_up, yaw_budget)"
    assert tier_title(Tiers(True, True)) == "safe: certified; tracking: certified"
    assert "nothing is promised" in tier_title(None)


def test_a_long_tier_line_is_wrapped_below_the_title():
    from tubekit.app.plots import title_lines

    tiers = "safe: certified; tracking: not certified (" + ", ".join(f"condition_{k}" for k in range(20)) + ")"
    text = title_lines("Tracking errors", tiers, width=60)
    lines = text.splitlines()
    assert lines[0] == "Tracking errors" and all(len(line) <= 60 for line in lines[1:])
    assert " ".join(lines[1:]) == tiers
    assert title_lines("Tracking errors", None) == "Tracking errors"
