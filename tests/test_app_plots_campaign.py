"""Campaign figures: units on every ECDF axis; the worst runs on a log axis of the margin 1 - ratio; a panel saying
why where there is nothing to draw (no tube at σ = 0, no runs, failed runs); uncertified runs named (issue 35)."""

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


# ---- issue 35: every campaign draws its figures (no tube at σ = 0, safe tier only, uncertified runs) ----------

def _tier_rows(tiers: tuple[tuple[bool, bool], ...], ratio=None) -> list[dict]:
    """Rows of runs whose certificates give (safe, tracking); ``ratio`` None: no tube (σ = 0)."""
    return [{"run": k, "seed": 100 + k, "certified": safe, "safe_tier": safe, "tracking_tier": tracking,
             "max_rho_ratio": ratio, "min_clearance": 1.9 + 0.01 * k, "min_e_d": 0.2 + 0.01 * k,
             "tracking_rmse": 0.39, "saturated_steps": 0, "replaced_steps": 0, "backup_s": 0.0,
             "backup_engagements": 0, "violated": False, "safety_broken": "", "premises_held": True, "broken": "",
             "worst_sequence": 0, "error": "", "wall_s": 0.3} for k, (safe, tracking) in enumerate(tiers)]


SAFE_ONLY = ((True, False),) * 4  # the paper's scenario: safe tier only, no tube


def _texts(ax) -> str:
    return " ".join(t.get_text() for t in ax.texts)


def test_tiers_of_rows():
    from tubekit.app.plots_campaign import tier_counts, tier_of, uncertified_runs

    rows = _tier_rows(((True, True), (True, False), (False, False), (False, False)))
    assert [tier_of(r) for r in rows] == ["both", "safe_only", "none", "none"]
    assert tier_counts(rows) == {"both": 1, "safe_only": 1, "none": 2}
    assert tier_counts([]) == {"both": 0, "safe_only": 0, "none": 0}
    assert uncertified_runs(rows) == [2, 3]
    assert tier_of({"certified": True}) == "both"  # a row of an older campaign: its verdict alone


def test_an_all_null_tube_ratio_gets_a_panel_saying_why(tmp_path):
    fig = ecdf_figure(_tier_rows(SAFE_ONLY), epsilon=0.1)
    ratio = fig.axes[0]
    assert not ratio.lines and "no tube" in _texts(ratio) and "σ = 0" in _texts(ratio)
    assert ratio.get_title() == "max_rho_ratio (0 runs)"
    assert "4 runs: 0 both tiers, 4 safe tier only, 0 uncertified" in fig._suptitle.get_text()
    assert all(ax.lines for ax in fig.axes[1:])  # every other metric is drawn
    fig.savefig(tmp_path / "ecdf.png", dpi=50)
    assert (tmp_path / "ecdf.png").stat().st_size > 0
    empty = worst_runs_figure([])
    assert "no run has a tube ratio" in _texts(empty.axes[0])
    empty.savefig(tmp_path / "worst.png", dpi=50)
    assert (tmp_path / "worst.png").stat().st_size > 0


def test_no_runs_and_failed_runs_draw_too(tmp_path):
    from tubekit.app.plots_campaign import empty_reason

    fig = ecdf_figure([], epsilon=0.1)
    assert all("no runs" in _texts(ax) for ax in fig.axes)
    fig.savefig(tmp_path / "none.png", dpi=50)
    failed = [{**r, "error": "boom", **{k: None for k, *_ in ECDF_PANELS if k != "wall_s"}}
              for r in _tier_rows(SAFE_ONLY)]
    assert "every run failed" in empty_reason(failed, "min_clearance")
    fig = ecdf_figure(failed, epsilon=0.1)
    assert "every run failed" in _texts(fig.axes[1]) and fig.axes[-1].lines  # wall_s is still known
    fig.savefig(tmp_path / "failed.png", dpi=50)


def test_uncertified_runs_are_named_and_marked_on_the_curves():
    rows = _tier_rows(((True, True), (True, True), (False, False), (True, False)), ratio=0.5)
    rows[1]["max_rho_ratio"] = 0.9
    fig = ecdf_figure(rows, epsilon=0.1)
    title = fig._suptitle.get_text()
    assert "2 both tiers, 1 safe tier only, 1 uncertified" in title and "runs 2: they claim nothing" in title
    marks = [line for line in fig.axes[1].lines if line.get_marker() == "x"]
    assert len(marks) == 1 and list(marks[0].get_xdata()) == [rows[2]["min_clearance"]]
    assert any("uncertified (1)" in t.get_text() for t in fig.axes[1].get_legend().get_texts())
    assert any("certified radius 1, 2 runs" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    safe_only = ecdf_figure(_tier_rows(SAFE_ONLY, ratio=0.0), epsilon=0.1)  # the backup ran throughout
    assert any("no run has the tracking tier" in t.get_text() for t in safe_only.axes[0].get_legend().get_texts())
    worst = worst_runs_figure(sorted(rows, key=lambda r: -r["max_rho_ratio"]))
    labels = [t.get_text() for t in worst.axes[0].get_yticklabels()]
    assert any("uncertified" in label for label in labels) and any("both tiers" in label for label in labels)


def test_values_close_together_print_no_axis_offset():
    """Values within 1e-5 of each other (ratios near 1, an RMSE, wall times near 1000 s): the tick labels carry
    the digits; no offset text ("1e-5+9.999e-1") overprints the axis label."""
    rows = _tier_rows(((True, True),) * 5)
    for k, row in enumerate(rows):
        row.update(max_rho_ratio=0.99998 + 2e-6 * k, tracking_rmse=0.39008 + 1e-6 * k, wall_s=1000.001 + 1e-4 * k)
    fig = ecdf_figure(rows, epsilon=0.1)
    fig.draw_without_rendering()
    assert [ax.xaxis.get_offset_text().get_text() for ax in fig.axes] == [""] * len(ECDF_PANELS)
