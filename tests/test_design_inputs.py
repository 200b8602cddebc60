"""tubekit.design_inputs: what the theorem reads, its key, the σ rules, and the one check every run makes."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from tubekit.design_inputs import DYNAMIC_SIGMA_SOURCE, THEOREM_VERSION, DesignInputs, handed_sigma
from tubekit.exceptions import ConfigError
from tubekit.model.trajectory import Circle
from tubekit.scenario import Obstacle, paper_scenario
from tubekit.tiers import Tiers
from tubekit.tightening import Tightening

SC = paper_scenario()


def _design(scenario=SC, law="corrected", sigma=3.125) -> DesignInputs:
    return DesignInputs.of(scenario, law, sigma)


def _tight(scenario=SC, law="corrected", sigma=3.125, tiers=Tiers(True, True), **changes) -> Tightening:
    base = dict(v_max=np.ones(3), e_d_min=0.5, e_o_max=0.4, e_z_max=0.9, e_d_max=2.9, obstacle_margin=0.1,
                sigma=sigma, design=_design(scenario, law, sigma), tiers=tiers)
    base.update(changes)
    return Tightening(**base)


def test_fields_name_what_the_theorem_reads():
    f = _design().fields()
    assert f["theorem_version"] == THEOREM_VERSION and f["law"] == "corrected" and f["sigma"] == 3.125
    assert f["limits.u_max"] == 0.4 and f["epsilon"] == 0.1 and f["trajectory.rate"] == pytest.approx(np.pi / 25)
    assert f["obstacles[0].center"] == [3.0, 0.0, 0.0] and f["obstacles[1].radius"] == 0.4
    assert f["disturbance.sway.bound"] == 0.02 and f["controller.ancillary_rate_hz"] == 100.0
    assert f["plant.kind"] == "kinematic" and f["workspace"] == [[-10.0, -10.0, -5.0], [10.0, 10.0, 5.0]]
    assert f["duration"] == 100.0                       # target_in_workspace reads it
    assert f["initial_state"] == [-0.5, 3.0, 0.2, 0.0]  # initial_workspace and backup_initial read it
    for absent in ("name", "disturbance.period", "disturbance.sway.period", "controller.Q",
                   "controller.terminal_level", "controller.fhocp_mode", "controller.sigma", "controller.law"):
        assert absent not in f


def test_the_key_is_the_sha256_of_the_sorted_json():
    f = _design(sigma=0.0).fields()
    text = json.dumps(f, sort_keys=True, separators=(",", ":"))
    assert _design(sigma=0.0).key() == hashlib.sha256(text.encode()).hexdigest()


def test_the_derived_values_come_from_the_scenario():
    d = DesignInputs.of(SC.with_changes(**{"limits.rate": (0.1, 0.2, 0.3)}))
    assert d.dt == 0.1 and d.horizon_steps == 8 and d.ticks_per_period == 10 and d.tick == pytest.approx(0.01)
    assert d.v_max.tolist() == [0.4, 0.3, 0.5] and d.jump == pytest.approx([0.01, 0.02, 0.03])
    assert not d.dynamic and d.start == SC.initial_state and d.sigma is None and d.law == "corrected"


CHANGED = [
    ("law", lambda s: (s, "paper", 3.125)),
    ("sigma", lambda s: (s, "corrected", 6.25)),
    ("limits.u_max", lambda s: (replace(s, limits=type(s.limits)(0.1, 0.3, 0.5)), "corrected", 3.125)),
    ("trajectory.rate", lambda s: (replace(s, trajectory=Circle(radius=3.0, rate=3 * np.pi / 25)), "corrected",
                                   3.125)),
    ("epsilon", lambda s: (replace(s, epsilon=0.2), "corrected", 3.125)),
    ("disturbance.amplitude", lambda s: (replace(s, disturbance=replace(s.disturbance, amplitude=(0.3, 0.3, 0.3))),
                                         "corrected", 3.125)),
    ("controller.ancillary_rate_hz", lambda s: (replace(s, controller=replace(s.controller, ancillary_rate_hz=20.0)),
                                                "corrected", 3.125)),
    ("obstacles[2].center", lambda s: (replace(s, obstacles=s.obstacles + (Obstacle((0.0, 8.0, 0.0), 0.4),)),
                                       "corrected", 3.125)),
    ("sensing_range", lambda s: (replace(s, sensing_range=2.0), "corrected", 3.125)),
    ("duration", lambda s: (replace(s, duration=150.0), "corrected", 3.125)),
    ("initial_state", lambda s: (replace(s, initial_state=(0.0, 2.0, 0.0, 0.3)), "corrected", 3.125)),
]


@pytest.mark.parametrize("name, change", CHANGED, ids=[c[0] for c in CHANGED])
def test_a_changed_input_changes_the_key_and_is_named(name, change):
    sc, law, sigma = change(SC)
    mine, other = _design(sc, law, sigma), _design()
    assert mine.key() != other.key()
    assert other.first_difference(mine)[0] == name


UNREAD = [
    lambda s: replace(s, name="other"),
    lambda s: replace(s, disturbance=replace(s.disturbance, period=3.0)),
    lambda s: replace(s, controller=replace(s.controller, Q=(2.0, 2.0, 1.0), fhocp_mode="converged")),
    lambda s: replace(s, controller=replace(s.controller, terminal_level=1.0, terminal_mode="hard")),
]


@pytest.mark.parametrize("change", UNREAD, ids=["name", "period", "weights", "terminal"])
def test_what_the_theorem_does_not_read_is_reset_and_keeps_the_key(change):
    """Property: a field certify does not read never reaches the theorem (it is reset to its default)."""
    d = _design(change(SC))
    assert d.key() == _design().key()
    assert d.scenario.disturbance.period == 15.0 and d.scenario.controller.Q == (1.0, 1.0, 0.5)


def test_the_dict_round_trip_is_exact_and_another_theorem_version_is_refused():
    d = DesignInputs.of(SC, "paper", 6.25, region_override={"e_o": (-0.5, 0.5)})
    back = DesignInputs.from_dict(json.loads(json.dumps(d.to_dict())))
    assert back == d and back.key() == d.key()
    old = dict(d.to_dict(), theorem_version="sampled-data-tube+backup+velocity-loop/6")
    with pytest.raises(ConfigError, match=r"design\.theorem_version: expected sampled-data-tube.*terminal/19"):
        DesignInputs.from_dict(old)


ERRORS = [
    (lambda: DesignInputs("paper", "corrected"), r"design\.scenario: expected a tubekit\.Scenario"),
    (lambda: DesignInputs(SC, ""), r"design\.law"),
    (lambda: DesignInputs(SC, "corrected", -1.0), r"design\.sigma: expected a finite number >= 0"),
    (lambda: DesignInputs(SC, "corrected", float("nan")), r"design\.sigma"),
    (lambda: DesignInputs.from_dict([]), r"design: expected a JSON object"),
    (lambda: DesignInputs.from_dict({"law": "corrected"}), r"design\.theorem_version: expected present"),
]


@pytest.mark.parametrize("build, match", ERRORS)
def test_bad_design_inputs_are_refused_naming_the_field(build, match):
    with pytest.raises(ConfigError, match=match):
        build()


def test_the_sigma_rules_live_in_one_place():
    assert _design(sigma=7.5).sigma_candidates() == ((7.5,), "controller.sigma")
    free = DesignInputs.of(SC)
    sigmas, _ = free.sigma_candidates()
    assert sigmas == (0.0, 3.125, 6.25, 12.5, 25.0, 50.0, 100.0)
    dynamic = DesignInputs.of(SC.with_changes(plant=type(SC.plant)(kind="dynamic", vehicle="bluerov2_heavy")))
    assert dynamic.sigma_candidates() == ((0.0,), DYNAMIC_SIGMA_SOURCE)
    assert handed_sigma(Tiers(True, False), 12.5) == 0.0 and handed_sigma(Tiers(True, True), 12.5) == 12.5


def test_a_matching_tightening_and_the_baseline_pass():
    _tight().require(SC)
    Tightening.untightened(SC).require(replace(SC, initial_state=(0.0, 2.5, 0.0, 0.0)))  # no design: not checked
    _tight().require(replace(SC, duration=3.0, name="renamed"))


def test_a_longer_run_than_certified_is_refused_a_shorter_one_is_covered():
    """The target stays in the workspace over [0, 100 s], hence over any shorter run, not a longer one."""
    _tight().require(replace(SC, duration=99.9))
    with pytest.raises(ConfigError, match=r"design_key\.duration: .*100\.0.*received 100\.1"):
        _tight().require(replace(SC, duration=100.1))


def test_another_start_is_refused_before_any_tick():
    """Issue 30, attack 1: the start is part of the design, so a certificate never covers another start."""
    with pytest.raises(ConfigError, match=r"design_key\.initial_state: .*-0\.5, 3\.0, 0\.2, 0\.0.*received "
                                          r"\[0\.0, 2\.5, 0\.0, 0\.0\]"):
        _tight().require(replace(SC, initial_state=(0.0, 2.5, 0.0, 0.0)))


def test_a_safe_only_tightening_runs_at_its_own_sigma_zero():
    """A safe-only tightening (sigma = 0, no feedback) is bound to sigma 0 even when the scenario declares one."""
    declared = replace(SC, controller=replace(SC.controller, sigma=6.25))
    _tight(SC, sigma=0.0, tiers=Tiers(True, False)).require(declared)
    with pytest.raises(ConfigError, match=r"design_key\.sigma"):
        _tight(SC, sigma=0.0, tiers=Tiers(True, True)).require(declared)


MISMATCH = [
    ("paper law", lambda: (replace(SC, controller=replace(SC.controller, law="paper")), _tight()),
     r"design_key\.law: expected the certificate's value 'corrected'.*received 'paper'"),
    ("a third of the current", lambda: (SC, _tight(replace(SC, disturbance=replace(
        SC.disturbance, amplitude=(0.1 / 3, 0.1 / 3, 0.1 / 3))))),
     r"design_key\.disturbance\.amplitude: .*0\.0333.*received \[0\.1, 0\.1, 0\.1\]"),
    ("sigma replaced", lambda: (SC, replace(_tight(), sigma=1.0)), r"design_key\.sigma: .*3\.125.*received 1\.0"),
    ("declared sigma", lambda: (replace(SC, controller=replace(SC.controller, sigma=6.25)), _tight()),
     r"design_key\.sigma"),
]


@pytest.mark.parametrize("label, case, match", MISMATCH, ids=[m[0] for m in MISMATCH])
def test_a_tightening_of_another_design_is_refused(label, case, match):
    sc, tight = case()
    with pytest.raises(ConfigError, match=match):
        tight.require(sc)


def test_the_core_module_loads_no_verify():
    code = ("import sys, tubekit.design_inputs; "
            "print(any(m == 'verify' or m.startswith('verify.') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
