"""tubekit.plotting.summary: the figure behind SimulationResult.plot(): the panel set, the verdict in the title,
the thrust panel of a dynamic run, every kind, and a ConfigError for an unknown one."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from tubekit.exceptions import ConfigError
from tubekit.plotting.summary import KINDS, plot_run
from tubekit.scenario import paper_scenario
from tubekit.tiers import Tiers

from .test_plotting_dynamic import _tight, dynamic_columns, dynamic_scenario
from .test_plotting_style import orphan_legend_entries

OUTCOME = {"safe": "certified, kept", "tracking": "certified, not in force (recursive_feasibility failed)"}


class FakeRun:
    """A PlottedRun by hand: a straight 4 s run with errors and inputs (and the dynamic plant's columns)."""

    def __init__(self, *, tube: bool = True, dynamic: bool = False):
        self.scenario = dynamic_scenario() if dynamic else paper_scenario()
        self.tightening = _tight(self.scenario, Tiers(True, True))
        self.tube = tube
        cols = dynamic_columns()
        n = cols["t"].size
        cols.update(step=np.minimum(np.arange(n) // 10, 39), e_d=np.full(n, 0.5), e_z=np.zeros(n), e_o=np.zeros(n),
                    u_hat=np.full(n, 0.2), w_hat=np.zeros(n), r_hat=np.zeros(n), rho_d=np.zeros(n),
                    rho_z=np.zeros(n), rho_o=np.zeros(n))
        if not dynamic:
            for key in ("u_b", "v_b", "w_b", "r_b", "X", "Z", "N"):
                cols.pop(key)
        self._columns = cols
        self.body = np.zeros((n, 4)) if dynamic else None

    @property
    def metrics(self) -> dict:
        return {"tiers": {"safe": True, "tracking": True}, "outcome": OUTCOME if self.tube else None}

    def columns(self) -> dict:
        return dict(self._columns)


def test_the_summary_carries_the_verdict_and_the_panel_set():
    fig = plot_run(FakeRun())
    assert isinstance(fig, Figure)
    assert "safe: certified, kept; tracking: certified, not in force (recursive_feasibility failed)" \
        in fig.get_suptitle()
    titles = [ax.get_title() for ax in fig.axes]
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert "top view" in titles and {"$e_d$ (m)", "u (m/s)", "r (rad/s)"} <= set(labels)
    assert "thrust / limit" not in labels  # a kinematic run has no thrust
    view = fig.axes[titles.index("top view")]
    assert any(ln.get_label() == "target at t = 4 s" for ln in view.get_lines())  # the target's end marked
    assert orphan_legend_entries(fig) == []


def test_a_dynamic_runs_summary_has_the_thrust_panel():
    fig = plot_run(FakeRun(dynamic=True))
    assert "thrust / limit" in [ax.get_ylabel() for ax in fig.axes]
    assert orphan_legend_entries(fig) == []


def test_a_baseline_is_promised_nothing_and_drawn_without_a_tube():
    fig = plot_run(FakeRun(tube=False))
    assert fig.get_suptitle().endswith("baseline: nothing is promised")
    labels = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert not any(s.startswith("position tube") for s in labels) and "baseline" in labels


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_kind_is_a_figure_with_the_verdict(kind):
    fig = plot_run(FakeRun(dynamic=True), kind)
    assert isinstance(fig, Figure) and "recursive_feasibility failed" in fig.get_suptitle()


def test_an_unknown_kind_or_a_dynamic_figure_of_a_kinematic_run_is_refused():
    with pytest.raises(ConfigError, match=r"^kind: expected one of summary, top_view"):
        plot_run(FakeRun(), "histogram")
    with pytest.raises(ConfigError, match=r"^kind: expected 'dynamic' only for a run on the dynamic plant"):
        plot_run(FakeRun(), "dynamic")
    with pytest.raises(ConfigError, match=r"^run: expected a tubekit.SimulationResult"):
        plot_run({"x": np.zeros(2)})
