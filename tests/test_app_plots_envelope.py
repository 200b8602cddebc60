"""The envelope figure: the scenario's own point with its verdict, no paper point on another scenario, every
legend entry drawn, the sway floor named for the scenario, and no region under necessity left unexplained."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.collections import Collection
from matplotlib.lines import Line2D

import verify
from tubekit.app.plots_envelope import envelope_figure, plot_envelope
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario
from verify.studies.envelope import EnvelopeResult

CIRCLE = Path(__file__).resolve().parents[1] / "examples" / "circle.toml"
GAMMA = r"$\bar\gamma$"


def cross_current_scenario():
    """examples/circle.toml (the paper's Section VI) with a 0.12 m/s constant cross current and no oscillation."""
    base = load_scenario(CIRCLE)
    dist = dataclasses.replace(base.disturbance, amplitude=(0.0, 0.0, 0.0), constant=(0.0, 0.12, 0.0))
    return base.with_changes(disturbance=dist, name="circle-cross-current")


@pytest.fixture(scope="module")
def env_cross():
    return verify.envelope(cross_current_scenario(), "corrected", speeds=[0.1, 0.3], quick=True)


@pytest.fixture(scope="module")
def env_paper():
    """The paper's own scenario (examples/circle.toml): its point is the paper's Section VI point."""
    return verify.envelope(load_scenario(CIRCLE), "corrected", speeds=[0.2, 0.32, 0.377], quick=True)


@pytest.fixture(scope="module")
def env_currents():
    return verify.envelope(load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml"), "corrected",
                           speeds=[0.1, 0.3], quick=True)


def labelled(fig):
    """(artist, label) of every legend entry of the figure's axes."""
    handles, labels = fig.axes[0].get_legend_handles_labels()
    return list(zip(handles, labels))


def own_marker(fig):
    hits = [(h, lab) for h, lab in labelled(fig) if lab.startswith("your scenario")]
    assert len(hits) == 1, [lab for _, lab in labelled(fig)]
    return hits[0]


def test_plot_envelope_refuses_a_missing_directory_before_drawing(tmp_path):
    with pytest.raises(ConfigError, match=r"^--plot: expected a file in an existing directory"):
        plot_envelope(object(), tmp_path / "missing" / "env.png")
    assert not (tmp_path / "missing").exists()


def test_the_old_home_still_exports_it():
    from tubekit.app import plots

    assert plots.plot_envelope is plot_envelope
    assert plots.envelope_figure is envelope_figure  # tutorial 08 imports it from there


def test_the_users_point_is_drawn_where_it_is_and_labelled_with_its_verdict(env_cross):
    fig = envelope_figure(env_cross)
    line, label = own_marker(fig)
    assert isinstance(line, Line2D)
    assert np.allclose(line.get_xydata(), [[env_cross.own_speed, env_cross.own_omega]])
    assert env_cross.own_speed == pytest.approx(0.377, abs=5e-4)
    assert env_cross.own_omega == pytest.approx(0.14)          # 0.12 current + 0.02 sway
    assert label.startswith("your scenario: target 0.377 m/s, current 0.12 m/s")
    assert "not certified (keep_up[u]" in label.replace("\n", " ")
    assert "beyond physics" in label.replace("\n", " ")         # 0.14 > 0.023 m/s admissible at 0.377 m/s
    title = fig.axes[0].get_title().replace("\n", " ")
    assert "your scenario (target 0.377 m/s, current 0.12 m/s): NOT CERTIFIED (keep_up[u]" in title


def test_a_certified_point_says_so(env_currents):
    fig = envelope_figure(env_currents)
    line, label = own_marker(fig)
    assert label.replace("\n", " ").endswith(": certified")
    assert line.get_color() == "tab:green"
    assert "CERTIFIED" in fig.axes[0].get_title() and "NOT CERTIFIED" not in fig.axes[0].get_title()


def test_no_paper_point_on_another_scenario(env_cross):
    labels = [lab for _, lab in labelled(envelope_figure(env_cross))]
    assert not any("paper" in lab for lab in labels), labels


def test_the_paper_point_is_the_users_point_on_the_papers_scenario(env_paper):
    fig = envelope_figure(env_paper)
    _, label = own_marker(fig)
    assert label.startswith("your scenario (= the paper Section VI point): target 0.377 m/s, current 0.1 m/s")
    assert sum("paper" in lab for _, lab in labelled(fig)) == 1   # no second, separate paper marker


@pytest.mark.parametrize("name", ["env_cross", "env_paper", "env_currents"])
def test_every_legend_label_has_an_artist_with_data(name, request):
    fig = envelope_figure(request.getfixturevalue(name))
    entries = labelled(fig)
    assert entries
    for artist, label in entries:
        if isinstance(artist, Line2D):
            xy = artist.get_xydata()
            assert len(xy) and np.isfinite(xy).all(axis=1).any(), label
        else:
            assert isinstance(artist, Collection), (label, artist)
            boxes = [p.get_extents() for p in artist.get_paths() if len(p.vertices)]
            assert any(b.width > 0 and b.height > 0 for b in boxes), label   # a fill with area, not a flat line
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == [lab for _, lab in entries]


def test_nothing_certified_draws_no_certified_entries(env_cross):
    assert not np.isfinite(env_cross.certified_omega).any()
    fig = envelope_figure(env_cross)
    assert not any(lab.startswith("certified") for _, lab in labelled(fig))
    assert "nothing certifies at any searched speed" in fig.axes[0].get_title().replace("\n", " ")


def test_the_floor_names_the_scenarios_sway_bound_and_its_constant_current(env_cross):
    fig = envelope_figure(env_cross)
    floors = {lab.replace("\n", " "): artist.get_ydata()[0] for artist, lab in labelled(fig)
              if isinstance(artist, Line2D) and GAMMA in lab}
    sway = [lab for lab in floors if lab.startswith(f"sway bound {GAMMA} = 0.02 m/s of this scenario")]
    assert len(sway) == 1 and floors[sway[0]] == pytest.approx(env_cross.gamma)
    assert "current allowed at a speed is the certified" in sway[0]
    const = [lab for lab in floors if "constant current 0.12 m/s" in lab]
    assert len(const) == 1 and floors[const[0]] == pytest.approx(env_cross.gamma + env_cross.current_offset)
    assert not any("no current" in lab for lab in floors)


def test_no_floor_for_a_constant_current_the_scenario_lacks(env_currents):
    labels = [lab for _, lab in labelled(envelope_figure(env_currents))]
    assert not any("constant current" in lab for lab in labels)


@pytest.mark.parametrize("name", ["env_cross", "env_paper", "env_currents"])
def test_no_unexplained_region_under_necessity(name, request):
    """Every point under the necessity frontier is in the certified fill or the hatched not-certified fill
    (the old figure left a white wedge between the last searched speeds and beyond them)."""
    result = request.getfixturevalue(name)
    ax = envelope_figure(result).axes[0]
    fills = [a for a, lab in labelled(ax.figure) if isinstance(a, Collection)
             and (lab.startswith("certified") or lab.startswith("physically possible"))]
    u_max = result.limits[0]
    for s in np.linspace(0.003, u_max - 0.003, 57):
        need = u_max - s
        for y in np.linspace(0.002, need - 0.002, 7):
            assert any(p.contains_point((s, y)) for f in fills for p in f.get_paths()), (s, y)


def test_a_result_without_its_scenarios_point_still_draws():
    """An EnvelopeResult built by hand (no own_* fields) draws its frontiers and no 'your scenario' entry."""
    result = EnvelopeResult(scenario_name="hand", law="corrected", epsilon=0.5, speeds=np.array([0.0, 0.2]),
                            certified_omega=np.array([0.25, math.nan]), certified_amplitude=np.array([0.23, math.nan]),
                            refuted_amplitude=np.array([0.24, 0.0]), necessary_omega=np.array([0.25, 0.2]),
                            first_failure=["", "keep_up[u]"], gamma=0.02)
    labels = [lab for _, lab in labelled(envelope_figure(result))]
    assert not any(lab.startswith("your scenario") for lab in labels)
    assert any(lab.startswith("certified frontier") for lab in labels)


def test_plot_envelope_writes_the_file(env_cross, tmp_path):
    path = plot_envelope(env_cross, tmp_path / "env.png")
    assert path.stat().st_size > 10_000
