"""tubekit.plotting.style: the backup's stretches and shading, time ticks, distances at a readable scale; and
:func:`orphan_legend_entries`, the check every figure test uses (no legend entry without an artist with data)."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import Collection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon

from tubekit.plotting.style import backup_stretches, distance_text, run_style, shade_backup, tick_interval, tick_rows


def _has_data(artist) -> bool:
    """A line with a finite point, a collection with a path, a polygon with a side; any other patch."""
    if isinstance(artist, Line2D):
        x = np.asarray(artist.get_xdata(), dtype=float)
        return bool(x.size) and bool(np.any(np.isfinite(x)))
    if isinstance(artist, Collection):
        return len(artist.get_paths()) > 0
    if isinstance(artist, Polygon):
        return len(artist.get_xy()) > 1
    return True


def orphan_legend_entries(fig: Figure) -> list[str]:
    """The legend texts of ``fig`` that no artist with data carries as its label (a proxy, an empty plot)."""
    FigureCanvasAgg(fig).draw()  # 3-D collections get their paths when drawn
    axes = list(fig.axes) + [child for ax in fig.axes for child in ax.child_axes]
    drawn = {a.get_label() for ax in axes for a in ax.get_children() if _has_data(a)}
    legends = [ax.get_legend() for ax in axes] + list(fig.legends)
    return [t.get_text() for legend in legends if legend for t in legend.get_texts() if t.get_text() not in drawn]


def test_the_orphan_check_catches_a_proxy_entry():
    ax = Figure().add_subplot()
    ax.plot([0, 1], [0, 1], label="data")
    ax.plot([], [], ls="none", label="a note as a legend entry")
    ax.fill([], [], label="a proxy patch")
    ax.legend()
    assert orphan_legend_entries(ax.figure) == ["a note as a legend entry", "a proxy patch"]


def _backup_columns():
    t = np.arange(0.0, 10.01, 0.5)
    active = np.zeros(t.size)
    active[4:8] = 1.0    # 2.0 s .. 4.0 s (ends at the first tick following a plan)
    active[-3:] = 1.0    # 9.0 s .. the end
    return {"t": t, "backup_active": active}


def test_backup_stretches_are_the_active_intervals():
    assert backup_stretches(_backup_columns()) == [(2.0, 4.0), (9.0, 10.0)]
    assert backup_stretches({"t": np.arange(3.0)}) == []


def test_the_backup_is_shaded_once_per_stretch_with_one_legend_entry():
    ax = Figure().add_subplot()
    shade_backup(ax, backup_stretches(_backup_columns()))
    assert len(ax.patches) == 2
    labels = [p.get_label() for p in ax.patches if p.get_label() and not p.get_label().startswith("_")]
    assert labels == ["backup law active (station keeping)"]


def test_time_ticks_are_round_and_at_most_about_eight():
    assert tick_interval(10.0) == 2.0 and tick_interval(20.0) == 5.0 and tick_interval(100.0) == 20.0
    t = np.arange(0.0, 10.001, 0.01)
    rows = tick_rows(t, 2.0)
    assert t[rows] == pytest.approx([2.0, 4.0, 6.0, 8.0, 10.0])


def test_distances_read_in_mm_below_a_metre_and_in_m_above():
    """Issue 35 item 4: a 15 m clearance is '+15.48 m', not '+15480.0 mm'."""
    assert distance_text(15.48) == "+15.48 m" and distance_text(0.409) == "+409.0 mm"
    assert distance_text(-0.0042) == "-4.2 mm" and distance_text(float("inf")) == "none"


def test_the_tube_run_and_the_baseline_differ_in_colour():
    assert run_style(0)["color"] != run_style(1)["color"] and "color" not in run_style(2)
