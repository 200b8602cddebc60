"""The envelope: the certified frontier agrees with direct certification and never exceeds physical necessity."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import verify
from tubekit.app.plots import plot_envelope
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario
from verify.studies.envelope import EnvelopeResult, frontier_verdict, necessary_omega, scenario_at

ROOT = Path(__file__).resolve().parent.parent

PAPER_CURRENTS = verify.SCENARIOS_DIR / "paper_currents.toml"


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(PAPER_CURRENTS)


@pytest.fixture(scope="module")
def env(scenario):
    return verify.envelope(scenario, "corrected", speeds=[0.1, 0.19, 0.3], quick=True)


def test_contains_paper_currents_point(env):
    """paper_currents' own point (0.19 m/s, omega_bar_xy = 0.1 current + 0.02 sway) is certified."""
    assert env.epsilon == 0.5
    assert env.certifies(0.19, 0.12)
    i = int(np.flatnonzero(np.isclose(env.speeds, 0.19))[0])
    assert env.certified_omega[i] >= 0.12


def test_certified_below_necessity(env):
    assert env.check() == []
    ok = np.isfinite(env.certified_omega)
    assert ok.any()
    assert np.all(env.certified_omega[ok] <= env.necessary_omega[ok] + 1e-9)
    assert 0 < env.ratio_min <= env.ratio_median <= 1.0 + 1e-9


def test_necessity_formula():
    """Keep-up alone: a current holding against the target outruns a vehicle slower than both."""
    assert necessary_omega(0.19, 0.4) == pytest.approx(0.21)
    assert necessary_omega(0.1, 0.4) == pytest.approx(0.3)      # the old yaw bound r_max eps = 0.15 is gone


def test_bisection_brackets_certify(env, scenario):
    """certify holds at the returned amplitude and fails at the refuted one (value * (1 + tol))."""
    i = int(np.flatnonzero(np.isclose(env.speeds, 0.3))[0])
    lo, hi = env.certified_amplitude[i], env.refuted_amplitude[i]
    assert math.isfinite(lo) and math.isfinite(hi) and lo < hi
    assert (hi - lo) / hi < 0.01
    assert frontier_verdict(verify.certify(scenario_at(scenario, speed=0.3, amplitude_xy=lo, epsilon=0.5),
                                           "corrected"))[0]
    assert not frontier_verdict(verify.certify(scenario_at(scenario, speed=0.3, amplitude_xy=hi, epsilon=0.5),
                                               "corrected"))[0]


def test_plot_summary_json(env, tmp_path):
    path = plot_envelope(env, tmp_path / "env.png")
    assert path.stat().st_size > 10_000
    assert "ratio certified / necessary" in env.summary()
    d = env.to_dict()
    assert d["epsilon"] == 0.5 and len(d["certified_omega"]) == 3 and d["problems"] == []


def test_the_scenarios_own_point_and_verdict(env, scenario):
    """The result carries the scenario's own speed, omega_bar_xy and verdict (certify of the scenario as it is)."""
    assert env.own_speed == pytest.approx(3.0 * math.pi / 50)          # radius 3 m, rate pi/50
    assert env.own_omega == pytest.approx(0.12)                        # 0.1 current + 0.02 sway
    assert env.own_current == pytest.approx(0.1) and env.own_epsilon == 0.5
    assert env.own_certified is True and env.own_safe is True and env.own_failure == ""
    assert env.own_certified == verify.certify(scenario, "corrected").certified
    assert env.own_verdict() == "certified"
    point = env.to_dict()["scenario_point"]
    assert point == {"speed": pytest.approx(env.own_speed), "omega_bar_xy": pytest.approx(0.12),
                     "current": pytest.approx(0.1), "epsilon": 0.5, "certified": True, "safe": True,
                     "first_failure": ""}
    assert "your scenario: target 0.1885 m/s, current 0.1 m/s (omega_bar_xy 0.12) at epsilon 0.5 m: certified" \
        in env.summary()


def test_the_own_verdict_is_at_the_envelopes_epsilon(scenario):
    """With eps given, the scenario's point is judged at that epsilon; its own epsilon is kept beside it."""
    env = verify.envelope(scenario, "corrected", eps=0.3, speeds=[0.1], quick=True)
    direct = verify.certify(scenario.with_changes(epsilon=0.3), "corrected")
    assert env.epsilon == 0.3 and env.own_epsilon == 0.5
    assert env.own_certified == direct.certified and env.own_safe == direct.tiers.safe
    assert env.own_failure == (direct.failures[0].condition if direct.failures else "")


def test_a_constant_current_enters_the_own_point():
    """A 0.12 m/s constant cross current (no oscillation): omega_bar_xy = 0.12 + gamma, the verdict certify's."""
    base = verify.certifiable_scenario()
    dist = dataclasses.replace(base.disturbance, amplitude=(0.0, 0.0, 0.0), constant=(0.0, 0.12, 0.0))
    sc = base.with_changes(disturbance=dist)
    env = verify.envelope(sc, "corrected", speeds=[0.1], quick=True)
    direct = verify.certify(sc, "corrected")
    assert env.own_current == pytest.approx(0.12) and env.current_offset == pytest.approx(0.12)
    assert env.own_omega == pytest.approx(0.12 + env.gamma)
    assert env.own_certified == direct.certified
    assert env.own_failure == (direct.failures[0].condition if direct.failures else "")
    assert env.to_dict()["scenario_point"]["current"] == pytest.approx(0.12)


def test_a_result_without_its_own_point_says_so():
    result = EnvelopeResult(
        scenario_name="hand", law="corrected", epsilon=0.5, speeds=np.array([0.1]), certified_omega=np.array([0.2]),
        certified_amplitude=np.array([0.18]), refuted_amplitude=np.array([0.19]), necessary_omega=np.array([0.25]))
    assert result.own_certified is None and result.own_verdict() == "not recorded"
    assert result.to_dict()["scenario_point"]["speed"] is None
    assert "your scenario" not in result.summary()


def test_paper_scenario_speed_is_physically_out_of_reach():
    """At the paper's 0.377 m/s only 0.023 m/s of horizontal disturbance is physically admissible (< gamma)."""
    env = verify.envelope(verify.certifiable_scenario(), "corrected", speeds=[0.377], quick=True)
    assert env.necessary_omega[0] == pytest.approx(0.023)
    assert env.check() == []


@pytest.mark.parametrize("kwargs, field", [
    (dict(eps=-0.1), "eps"),
    (dict(eps=5.0), "eps"),
    (dict(speeds=[0.5]), "speeds"),
    (dict(speeds=["fast"]), "speeds"),
    (dict(speeds=[]), "speeds"),
    (dict(speeds=[0.1], steps=0), "steps"),
    (dict(speeds=[0.1], steps=2.5), "steps"),
])
def test_bad_inputs(scenario, kwargs, field):
    with pytest.raises(ConfigError, match=field):
        verify.envelope(scenario, **kwargs)


def test_bad_law():
    with pytest.raises(ConfigError, match="law"):
        verify.envelope(verify.certifiable_scenario(), "pid")


@pytest.mark.slow
def test_a_dynamic_scenario_has_an_envelope_of_dynamic_certificates():
    """Issue 32: ``tubekit envelope`` on the BlueROV2 Heavy (examples/bluerov2_slow.toml) at its own speed: every
    point a dynamic certificate; its tracking design's omega_bar_xy holds the sway (the BlueROV2 Heavy's sway loop
    error) and the velocity loop's error under plans alone (docs/verify.md step 17d) on top of the current."""
    sc = load_scenario(ROOT / "examples" / "bluerov2_slow.toml")
    env = verify.envelope(sc, speeds=[0.079], steps=2)
    assert env.dynamic and env.to_dict()["dynamic"] is True and env.check() == []
    lo, hi = env.certified_amplitude[0], env.refuted_amplitude[0]
    assert 0.0 < lo < hi <= env.necessary_omega[0]                 # a current certifies, a larger one does not
    assert env.gamma > 0.005                 # ||(E_u, E_v)|| at zero current, plans only: about a centimetre per second
    # omega_bar holds the current and the derived part on top (not monotone in the current: the backup designed at
    # each point sets the command's jumps, and so E; measured: 0.042 at a = 0.075 against 0.047 at a = 0)
    assert env.certified_omega[0] > lo + 0.5 * env.gamma
    assert env.own_certified is True and env.own_current == pytest.approx(0.04, abs=1e-9)
    assert "sway + loop error" in env.summary()


def test_progress_is_reported_once_per_speed_and_changes_nothing(scenario):
    """``on_speed(done, total)`` after each speed; the result is the one without it."""
    seen = []
    with_progress = verify.envelope(scenario, speeds=[0.05, 0.1], steps=2, on_speed=lambda d, t: seen.append((d, t)))
    plain = verify.envelope(scenario, speeds=[0.05, 0.1], steps=2)
    assert seen == [(1, 2), (2, 2)]
    assert with_progress.to_dict() == plain.to_dict()
