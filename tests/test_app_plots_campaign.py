"""Campaign figures: units on every ECDF axis; the worst runs on a log axis of the margin 1 - ratio."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.app.plots_campaign import ECDF_PANELS, MARGIN_FLOOR, ecdf_figure, ratio_label, worst_runs_figure


@pytest.mark.parametrize("margin, label", [(1e-1, "0.9"), (1e-3, "0.999"), (1e-4, "0.9999"), (1e-6, "0.999999"),
                                           (0.0, "1")])
def test_ratio_label_reads_the_margin_as_the_ratio(margin, label):
    assert ratio_label(margin) == label


def _rows():
    return [{"run": k, "seed": 10 + k, "max_rho_ratio": r, "violated": r > 1, "min_clearance": 0.1 * k,
             "min_e_d": 0.5 + 0.01 * k, "tracking_rmse": 0.6, "saturated_steps": 0, "replaced_steps": k,
             "backup_s": 0.0, "wall_s": 1.0} for k, r in enumerate((0.993, 0.9999, 0.99999, 1.002))]


def test_worst_runs_are_drawn_as_margins_on_a_log_axis():
    fig = worst_runs_figure(_rows())
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    x = ax.collections[0].get_offsets()[:, 0]
    # reversed order (the worst on top); 1.002 is at or above 1: drawn at the floor
    assert np.allclose(x, [MARGIN_FLOOR, 1e-5, 1e-4, 7e-3], rtol=1e-6)
    lo, hi = ax.get_xlim()
    assert hi < 1e-4 < 7e-3 < lo  # 0.993 and 0.9999 both inside the axis, far apart


def test_every_ecdf_axis_names_its_unit():
    fig = ecdf_figure(_rows(), epsilon=0.5)
    labels = [ax.get_xlabel() for ax in fig.axes]
    assert len(labels) == len(ECDF_PANELS)
    assert all(label.endswith(")") and "(" in label for label in labels)
    assert "(m)" in labels[1] and "(s)" in labels[-1]
