"""tubekit.plotting.series: Fig. 3 marks ε; Fig. 4 draws v̂, the applied envelope, V and V̄, and no legend
entry without a line."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tubekit.plotting.series import errors_figure, inputs_figure, period_envelope
from tubekit.scenario import paper_scenario
from tubekit.tightening import Tightening

from .test_plotting_style import orphan_legend_entries


def _columns(seconds: float = 2.0) -> dict[str, np.ndarray]:
    """Ten ticks per 0.1 s period; errors and inputs that vary within a period."""
    t = np.arange(0.0, seconds + 1e-9, 0.01)
    wave = np.sin(3.0 * t)
    cols = {"t": t, "step": np.minimum(np.arange(t.size) // 10, int(round(seconds / 0.1)) - 1),
            "e_d": 0.5 + 0.2 * wave, "e_z": 0.1 * wave, "e_o": 0.05 * wave, "backup_active": np.zeros(t.size)}
    for k, key in enumerate(("u", "w", "r")):
        cols[f"{key}_hat"] = 0.1 * np.cos(t + k)
        cols[key] = cols[f"{key}_hat"] + 0.01 * wave
    return cols


def test_errors_figure_marks_epsilon():
    sc = paper_scenario()
    fig = errors_figure(sc, [("tube", _columns())])
    ys = [ln.get_ydata() for ax in fig.axes for ln in ax.get_lines()]
    assert any(np.allclose(y, sc.epsilon) for y in ys)
    assert fig.axes[0].get_yscale() == "log" and orphan_legend_entries(fig) == []


def test_period_envelope_is_min_max_per_period():
    cols = _columns()
    t, lo, hi = period_envelope(cols, "u")
    first = cols["step"] == cols["step"][0]
    assert t[0] == cols["t"][0] and t[-1] == cols["t"][-1]
    assert lo[0] == pytest.approx(np.min(cols["u"][first])) and hi[0] == pytest.approx(np.max(cols["u"][first]))
    assert np.all(lo <= hi)


def test_inputs_figure_draws_v_hat_and_both_bounds():
    sc = paper_scenario()
    base = Tightening.untightened(sc)
    fig = inputs_figure(sc, [("tube", _columns())], tightening=replace(base, v_max=base.v_max * 0.8))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("hat v" in s for s in labels) and any("min-max per period" in s for s in labels)
    assert any("bound of $V$" in s for s in labels) and any("bar V" in s for s in labels)
    assert orphan_legend_entries(fig) == []


def test_an_untightened_axis_is_a_note_not_an_empty_legend_entry():
    """Issue 35 item 4: fig4_inputs.png had a legend entry "V̄ = V on this axis" for nothing on the plot."""
    sc = paper_scenario()
    fig = inputs_figure(sc, [("tube", _columns())], tightening=Tightening.untightened(sc))
    assert orphan_legend_entries(fig) == []
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert not any("bar V" in s for s in labels)
    assert all(any("no tightening" in t.get_text() for t in ax.texts) for ax in fig.axes)


def test_a_surge_floor_is_drawn_where_the_lower_bounds_are():
    """With u_min = 0.1 m/s and V_bar's surge floor 0.15 m/s the surge axis draws V's lower bound at u_min and V_bar's
    at its floor, not at -u_max and -V_bar_u; the other axes keep the symmetric lines."""
    sc = paper_scenario().with_changes(**{"limits.u_min": 0.1})
    base = Tightening.untightened(sc)
    floor = np.array([0.15, -0.8 * sc.limits.w_max, -0.8 * sc.limits.r_max])
    tight = replace(base, v_max=base.v_max * 0.8, v_min=floor)
    fig = inputs_figure(sc, [("tube", _columns())], tightening=tight)
    levels = [float(ln.get_ydata()[0]) for ln in fig.axes[0].get_lines() if len(set(ln.get_ydata())) == 1]
    assert 0.1 in levels and 0.15 in levels and -sc.limits.u_max not in levels
    heave = [float(ln.get_ydata()[0]) for ln in fig.axes[1].get_lines() if len(set(ln.get_ydata())) == 1]
    assert -sc.limits.w_max in heave and orphan_legend_entries(fig) == []
