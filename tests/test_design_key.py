"""tubekit.design_key: what the theorem reads, its hash, and the one check every run path makes."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from tubekit.design_key import THEOREM_VERSION, design_fields, design_key, first_difference, require_matching
from tubekit.exceptions import ConfigError
from tubekit.model.trajectory import Circle
from tubekit.scenario import Obstacle, paper_scenario
from tubekit.tightening import Tightening

SC = paper_scenario()


def _tight(scenario=SC, law="corrected", sigma=3.125, **changes) -> Tightening:
    fields = design_fields(scenario, law, sigma)
    base = dict(v_max=np.ones(3), e_d_min=0.5, e_o_max=0.4, e_z_max=0.9, e_d_max=2.9, obstacle_margin=0.1,
                rho_tilde=0.0, sigma=sigma, law=law, design_key=design_key(fields), design_fields=fields)
    base.update(changes)
    return Tightening(**base)


def test_fields_name_what_the_theorem_reads():
    f = design_fields(SC, "corrected", 3.125)
    assert f["theorem_version"] == THEOREM_VERSION and f["law"] == "corrected" and f["sigma"] == 3.125
    assert f["limits.u_max"] == 0.4 and f["epsilon"] == 0.1 and f["trajectory.rate"] == pytest.approx(np.pi / 25)
    assert f["obstacles[0].center"] == [3.0, 0.0, 0.0] and f["obstacles[1].radius"] == 0.4
    assert f["disturbance.sway.bound"] == 0.02 and f["controller.ancillary_rate_hz"] == 100.0
    assert f["plant.kind"] == "kinematic" and f["workspace"] == [[-10.0, -10.0, -5.0], [10.0, 10.0, 5.0]]
    assert f["duration"] == 100.0     # target_in_workspace reads it
    for absent in ("name", "initial_state", "disturbance.period", "disturbance.sway.period",
                   "controller.Q", "controller.terminal_level", "controller.fhocp_mode"):
        assert absent not in f


def test_the_key_is_the_sha256_of_the_sorted_json():
    f = design_fields(SC, "corrected", 0.0)
    text = json.dumps(f, sort_keys=True, separators=(",", ":"))
    assert design_key(f) == hashlib.sha256(text.encode()).hexdigest()
    assert design_key(design_fields(SC, "corrected", 0.0)) == design_key(f)


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
]


@pytest.mark.parametrize("name, change", CHANGED, ids=[c[0] for c in CHANGED])
def test_a_changed_input_changes_the_key_and_is_named(name, change):
    sc, law, sigma = change(SC)
    mine, other = design_fields(sc, law, sigma), design_fields(SC, "corrected", 3.125)
    assert design_key(mine) != design_key(other)
    assert first_difference(mine, other)[0] == name


UNREAD = [
    lambda s: replace(s, name="other"),
    lambda s: replace(s, initial_state=(0.0, 2.0, 0.0, 0.3)),
    lambda s: replace(s, disturbance=replace(s.disturbance, period=3.0)),
    lambda s: replace(s, controller=replace(s.controller, Q=(2.0, 2.0, 1.0), fhocp_mode="converged")),
]


@pytest.mark.parametrize("change", UNREAD, ids=["name", "initial_state", "period", "weights"])
def test_what_the_theorem_does_not_read_keeps_the_key(change):
    assert design_key(design_fields(change(SC), "corrected", 3.125)) == design_key(design_fields(SC, "corrected",
                                                                                                 3.125))


def test_a_matching_tightening_and_the_baseline_pass():
    require_matching(SC, _tight())
    require_matching(SC, Tightening.untightened(SC))                     # no key: not checked
    require_matching(replace(SC, duration=3.0, initial_state=(0.0, 2.5, 0.0, 0.0)), _tight())


def test_a_longer_run_than_certified_is_refused_a_shorter_one_is_covered():
    """The target stays in the workspace over [0, 100 s], hence over any shorter run, not a longer one."""
    require_matching(replace(SC, duration=99.9), _tight())
    with pytest.raises(ConfigError, match=r"design_key\.duration: .*100\.0.*received 100\.1"):
        require_matching(replace(SC, duration=100.1), _tight())


def test_a_safe_only_tightening_runs_at_its_own_sigma_zero():
    """A safe-only tightening (sigma = 0, no feedback) is bound to sigma 0 even when the scenario declares one."""
    declared = replace(SC, controller=replace(SC.controller, sigma=6.25))
    safe = _tight(SC, sigma=0.0, tiers={"safe": True, "tracking": False})
    require_matching(declared, safe)
    with pytest.raises(ConfigError, match=r"design_key\.sigma"):
        require_matching(declared, _tight(SC, sigma=0.0, tiers={"safe": True, "tracking": True}))


MISMATCH = [
    ("paper law", lambda: (replace(SC, controller=replace(SC.controller, law="paper")), _tight(), {}),
     r"design_key\.law: expected the certificate's value 'corrected'.*received 'paper'"),
    ("a third of the current", lambda: (SC, _tight(replace(SC, disturbance=replace(
        SC.disturbance, amplitude=(0.1 / 3, 0.1 / 3, 0.1 / 3)))), {}),
     r"design_key\.disturbance\.amplitude: .*0\.0333.*received \[0\.1, 0\.1, 0\.1\]"),
    ("sigma override", lambda: (SC, _tight(), {"sigma": 1.0}), r"design_key\.sigma: .*3\.125.*received 1\.0"),
    ("declared sigma", lambda: (replace(SC, controller=replace(SC.controller, sigma=6.25)), _tight(), {}),
     r"design_key\.sigma"),
    ("law argument", lambda: (SC, _tight(), {"law": "paper"}), r"design_key\.law"),
    ("key without its fields", lambda: (SC, _tight(design_key="0" * 64), {}), r"^design_key: .*edited"),
]


@pytest.mark.parametrize("label, case, match", MISMATCH, ids=[m[0] for m in MISMATCH])
def test_a_tightening_of_another_design_is_refused(label, case, match):
    sc, tight, kw = case()
    with pytest.raises(ConfigError, match=match):
        require_matching(sc, tight, **kw)


def test_the_core_module_loads_no_verify():
    code = "import sys, tubekit.design_key; print(any(m == 'verify' or m.startswith('verify.') for m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
