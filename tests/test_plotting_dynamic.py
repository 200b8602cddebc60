"""tubekit.plotting.dynamic: thrust over its limit, the loop error over E, sway against γ̄, the clearance; bounds
labelled "certified" only with the safe tier."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tubekit.plotting.dynamic import dynamic_figure, thrust_ratios
from tubekit.scenario import paper_scenario
from tubekit.tightening import DisturbanceBound, Tightening
from tubekit.tiers import Tiers

from .test_plotting_framing import path_columns
from .test_plotting_style import orphan_legend_entries


def dynamic_scenario():
    """The paper's scenario on the BlueROV2 Heavy (thrusters: limits independent of the speed)."""
    sc = paper_scenario()
    return sc.with_changes(plant=replace(sc.plant, kind="dynamic", vehicle="bluerov2_heavy"))


def dynamic_columns(seconds: float = 4.0) -> dict[str, np.ndarray]:
    """A straight run with the dynamic plant's columns: the body follows the input with a small error."""
    cols = path_columns((-0.5, 3.0, 0.0), (0.2, 0.0, 0.0), seconds, rate_hz=100.0)
    n = cols["t"].size
    cols.update(u=np.full(n, 0.2), w=np.zeros(n), r=np.zeros(n), u_b=np.full(n, 0.21), v_b=np.full(n, 0.03),
                w_b=np.full(n, -0.002), r_b=np.full(n, 0.01), X=np.linspace(0.0, 20.0, n), Z=np.zeros(n),
                N=np.full(n, -1.0))
    return cols


def _tight(sc, tiers=Tiers(True, False)):
    return replace(Tightening.untightened(sc), tiers=tiers, velocity_loop=(0.05, 0.02, 0.04),
                   disturbance=DisturbanceBound(0.1, 0.05, 0.06))


def test_thrust_over_its_limit_by_hand():
    sc = dynamic_scenario()
    limits = sc.plant.truth_params.thrust_limits_at(0.21)
    ratio = thrust_ratios(sc, dynamic_columns())
    assert ratio[-1] == pytest.approx([20.0 / limits[0], 0.0, -1.0 / limits[2]])


def test_the_panel_set_draws_each_quantity_against_its_bound():
    sc = dynamic_scenario()
    fig = dynamic_figure(sc, ("tube", dynamic_columns()), _tight(sc))
    titles = [ax.get_title() for ax in fig.axes]
    assert titles == ["thrust against its limits", "velocity-loop error against its bound E", "sway against its bound",
                      "clearance (nearest obstacle)"]
    loop = [ln for ln in fig.axes[1].get_lines() if ln.get_label().startswith("|u_b - u|")][0]
    assert np.allclose(loop.get_ydata(), 0.01 / 0.05)  # |0.21 - 0.2| / E_u
    labels = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert r"$\pm\bar\gamma$ = 0.06 m/s (certified)" in labels and "derived bound E (certified)" in labels
    assert orphan_legend_entries(fig) == []


def test_without_the_safe_tier_the_bounds_are_not_certified_and_without_E_the_error_is_raw():
    sc = dynamic_scenario()
    fig = dynamic_figure(sc, ("tube", dynamic_columns()), replace(_tight(sc, Tiers()), velocity_loop=None))
    labels = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert r"$\pm\bar\gamma$ = 0.06 m/s (not certified)" in labels
    assert "no derived bound E" in fig.axes[1].get_title()
    assert orphan_legend_entries(fig) == []
