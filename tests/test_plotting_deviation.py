"""tubekit.plotting.deviation: the per-axis peak of |e_j − ê_j| / tube_j per period, by hand."""

from __future__ import annotations

import numpy as np

from tubekit.plotting.deviation import rho_figure


def _rho_columns():
    """Two periods of 4 ticks (9 rows); the pre-reset peak of a period is logged on its last row."""
    t = np.arange(9) * 0.025
    step = np.array([0, 0, 0, 0, 1, 1, 1, 1, 2])
    rho = {"rho_d": [0, .01, -.05, .02, .03, 0, .04, -.08, .06], "rho_z": [0, .1, .1, .1, .1, .2, .2, .2, .2],
           "rho_o": [0, 0, 0, 0, .3, 0, 0, 0, -.1]}
    return {"t": t, "step": step, **{k: np.array(v) for k, v in rho.items()}, "backup_active": np.zeros(9)}


def test_rho_figure_plots_the_per_axis_box_ratio():
    """Per axis, the per-period peak of |rho_j| / tube_j: rows 1..4 and 5..8, by hand."""
    fig = rho_figure([("tube", _rho_columns())], (0.1, 0.25, 0.4), True)
    want = {0: [0.5, 0.8], 1: [0.4, 0.8], 2: [0.75, 0.25]}
    for j, ax in enumerate(fig.axes):
        data = [ln.get_ydata() for ln in ax.get_lines() if ln.get_label().startswith("tube")]
        assert np.allclose(data[0], want[j])
        assert any(np.allclose(ln.get_ydata(), 1.0) for ln in ax.get_lines())  # the box the promise checks
    assert "largest 0.8" in fig.get_suptitle()


def test_the_box_is_labelled_not_certified_without_the_tracking_tier():
    fig = rho_figure([("tube", _rho_columns())], (0.1, 0.25, 0.4), False)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(s.endswith("NOT certified") for s in labels)


def test_rho_figure_without_a_tube_shows_the_deviation_itself():
    fig = rho_figure([("tube", _rho_columns())], (0.0, 0.0, 0.0), False)
    data = [ln.get_ydata() for ln in fig.axes[0].get_lines() if ln.get_label().startswith("tube")]
    assert np.allclose(data[0], [0.05, 0.08]) and "(m)" in fig.axes[0].get_ylabel()
    assert "nothing promised" in fig.get_suptitle()


def test_rho_figure_leaves_out_the_backup_ticks():
    cols = _rho_columns()
    cols["backup_active"][7] = 1.0  # the -0.08 of e_d is under the backup law: not promised, not drawn
    data = [ln.get_ydata() for ln in rho_figure([("tube", cols)], (0.1, 0.25, 0.4), True).axes[0].get_lines()
            if ln.get_label().startswith("tube")]
    assert np.allclose(data[0], [0.5, 0.6])
