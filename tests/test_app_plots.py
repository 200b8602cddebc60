"""Figures: every file is written from logged columns, and plotted data match the log."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from tubekit.closed_loop import simulate
from tubekit.metrics import rho_period_peaks
from tubekit.app.plots import FIGURE_FILES, errors_figure, plot_all, top_view
from tubekit.scenario import paper_scenario
from tubekit.tightening import Tightening


@pytest.fixture(scope="module")
def short_run():
    sc = replace(paper_scenario(), duration=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = simulate(sc, tightening=Tightening.untightened(sc), tube=False, progress=False)
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
