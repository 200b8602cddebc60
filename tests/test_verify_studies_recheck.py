"""verify.studies.recheck / `tubekit recheck`: a certificate re-checked from its stored scenario up.

Every tampering below edits one block of a real certificate's JSON. Most re-stamp the checksum
(and where noted the design key), so what refuses them is the re-derivation, not the checksum;
a few leave the checksum stale, to show it catches an edit first. Each must be refused with
the field named.
"""

from __future__ import annotations

import copy
import json

import pytest

import verify
from tubekit.app.cli import main
from tubekit.design_inputs import DesignInputs
from tubekit.exceptions import ConfigError
from verify.certificate.jsonio import checksum_of
from verify.studies.recheck import recheck, recheck_file


@pytest.fixture(scope="module")
def pc_json(pc_cert):
    return json.loads(json.dumps(pc_cert.to_dict()))


@pytest.fixture(scope="module")
def ok_json():
    """certifiable.toml: sigma = 100 (kappa_bar > 0)."""
    return json.loads(json.dumps(verify.certify(verify.certifiable_scenario()).to_dict()))


@pytest.fixture(scope="module")
def paper_json(paper_cert):
    return json.loads(json.dumps(paper_cert.to_dict()))


def test_a_certified_certificate_is_confirmed(pc_json, ok_json):
    for d in (pc_json, ok_json):
        res = recheck(d)
        assert res.ok and res.confirmed and res.certified_claim and not res.edited and not res.notes
        names = {c["name"] for c in res.checks}
        assert {"checksum", "design_key", "disturbance.omega_xy", "gains.k_abs[0][0]", "tube.rho[0]",
                "margins.e_d[7]", "v_bar[0]", "kappa_bar[0]", "e_bar.e_d[0]", "arc_rates[0]", "certified",
                "conditions[sensing].ok", "region.v_max", "inputs", "theorem_version", "sigma.value"} <= names
        res.check()  # raises nothing
        assert "CONFIRMED" in res.summary()


def test_an_uncertified_certificate_agrees_but_is_not_confirmed(paper_json):
    res = recheck(paper_json)
    assert res.ok and not res.confirmed and not res.certified_claim
    assert "agrees (not certified)" in res.summary()


# --------------------------------------------------------------------------- tampering
def _set(d: dict, path: tuple, value) -> None:
    node = d
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value


def _get(d: dict, path: tuple):
    for k in path:
        d = d[k]
    return d


def _scale(path, factor):
    return lambda d: _set(d, path, [x * factor for x in _get(d, path)] if isinstance(_get(d, path), list)
                          else _get(d, path) * factor)


def _rekey(d: dict) -> None:
    """A tamperer who also recomputes the design key from the edited design inputs."""
    d["design_key"] = DesignInputs.from_dict(d["inputs"]).key()


def _scenario_and_key(path: tuple, value):
    """Edit the stored design's scenario, then recompute the key."""
    def change(d):
        _set(d, ("inputs", "scenario") + path, value)
        _rekey(d)
    return change


def _cond(name, **changes):
    return lambda d: _set(d, ("conditions",), [dict(c, **changes) if c["condition"] == name else c
                                               for c in d["conditions"]])


# (certificate, change, field named, re-stamp the checksum)
TAMPERING = [
    # the design's scenario edited, the key left: caught by the design key (the hash of the stored inputs)
    ("pc", lambda d: _set(d, ("inputs", "scenario", "limits", "u_max"), 0.1), "design_key", True),
    ("pc", _scale(("inputs", "scenario", "trajectory", "rate"), 3.0), "design_key", True),
    ("pc", lambda d: _set(d, ("inputs", "scenario", "epsilon"), 0.1), "design_key", True),
    ("pc", lambda d: _set(d, ("inputs", "scenario", "initial_state"), [0.0, 2.5, 0.0, 0.0]), "design_key", True),
    ("pc", lambda d: _set(d, ("inputs", "scenario", "controller", "dt"), 0.2), "design_key", True),
    # the design edited and the key recomputed: the re-derivation catches it
    ("pc", _scenario_and_key(("limits", "u_max"), 0.3), "region.v_max", True),
    ("pc", _scenario_and_key(("epsilon",), 0.3), "region.e_d", True),
    ("pc", _scenario_and_key(("controller", "ancillary_rate_hz"), 20.0), "problem.ticks", True),
    ("pc", _scenario_and_key(("controller", "horizon_steps"), 12), "margins.e_d (length)", True),
    # the design key itself, the theorem's version
    ("pc", lambda d: _set(d, ("design_key",), "0" * 64), "design_key", True),
    ("pc", lambda d: _set(d, ("theorem_version",), "sampled-data-tube/0"), "theorem_version", True),
    # the law (key recomputed too: the gains of the paper's law refute the stored bounds)
    ("pc", lambda d: _set(d, ("law",), "paper"), "law", True),
    ("pc", lambda d: (_set(d, ("inputs", "law"), "paper"), _rekey(d)), "gains.", True),
    # problem, region, disturbance, gains, sigma
    ("pc", _scale(("problem", "omega_xy"), 0.5), "problem.omega_xy", True),
    ("pc", lambda d: _set(d, ("problem", "u_max"), 0.5), "problem.u_max", True),
    ("pc", lambda d: _set(d, ("problem", "ticks"), 5), "problem.ticks", True),
    ("pc", lambda d: _set(d, ("region", "e_d"), [0.5, 4.0]), "region.e_d", True),
    ("pc", _scale(("region", "pd_dot_max"), 0.5), "region.pd_dot_max", True),
    ("pc", _scale(("disturbance", "omega_xy"), 0.5), "disturbance.omega_xy", True),
    ("pc", _scale(("disturbance", "gamma"), 0.5), "disturbance.gamma", True),
    ("pc", lambda d: _set(d, ("gains", "k_abs"), [[0.95 * x for x in row] for row in d["gains"]["k_abs"]]),
     "gains.k_abs", True),
    ("ok", lambda d: _set(d, ("gains", "g_hi"), [0.95 * x for x in d["gains"]["g_hi"]]), "gains.g_hi", True),
    ("pc", lambda d: _set(d, ("sigma", "value"), 3.125), "problem.sigma", True),
    ("pc", lambda d: (_set(d, ("inputs", "sigma"), 3.125), _rekey(d)), "inputs.sigma", True),
    ("pc", lambda d: (_set(d, ("sigma", "value"), 7.0), _set(d, ("inputs", "sigma"), 7.0), _rekey(d)),
     "sigma.value", True),
    # the tracking theorem's terminal set widened: the loop would accept plans the proof does not cover
    ("pc", lambda d: _set(d, ("terminal", "d_hi"), 2.5), "terminal", True),
    ("pc", lambda d: _set(d, ("terminal", "alpha_max"), 0.3), "terminal", True),
    # the tube, margins, V_bar, kappa_bar, E_bar, arc rates
    ("pc", _scale(("tube", "rho"), 0.9), "tube.rho", True),
    ("pc", _scale(("tube", "theta"), 0.5), "tube.theta", True),
    ("ok", _scale(("tube", "kappa"), 0.5), "tube.kappa", True),
    # one arc's margins (numpy would broadcast them over the horizon)
    ("pc", lambda d: _set(d, ("margins",), {k: v[-1:] for k, v in d["margins"].items()}), "margins.e_d (length)",
     True),
    ("pc", _scale(("margins", "e_o"), 0.5), "margins.e_o", True),
    ("ok", lambda d: _set(d, ("v_bar",), [x + 0.05 for x in d["v_bar"]]), "v_bar", True),
    ("ok", _scale(("kappa_bar",), 0.5), "kappa_bar", True),
    ("pc", lambda d: _set(d, ("e_bar", "e_d"), [0.5, 3.0]), "e_bar.e_d", True),
    ("pc", _scale(("arc_rates",), 0.5), "arc_rates", True),
    # conditions, verdict, premises
    ("paper", _cond("keep_up[u]", ok=True), "conditions[keep_up[u]].ok", True),
    ("pc", lambda d: _set(d, ("conditions",), [c for c in d["conditions"] if c["condition"] != "sensing"]),
     "conditions[sensing]", True),
    ("paper", lambda d: _set(d, ("certified",), True), "certified", True),
    ("paper", lambda d: _set(d, ("failures",), []), "failures", True),
    ("pc", lambda d: _set(d, ("assumptions",), d["assumptions"][:1]), "assumptions", True),
    ("pc", lambda d: _set(d, ("premises",), []), "premises", True),
    # the backup (stored law and safe set re-certified with the derived bounds and margins), the tiers
    ("pc", lambda d: _set(d, ("backup", "safe_set", "level"), 0.3), "backup.safe_set", True),
    ("pc", lambda d: _set(d, ("backup", "law", "surge"), 0.1), "backup.law", True),
    ("pc", _scale(("backup", "omega_xy"), 0.5), "backup.omega_xy", True),
    ("pc", _scale(("backup", "handover"), 0.5), "backup.handover", True),
    # the anchor's reach widened: the hand-over it implies (margin + reach) leaves the proved c − β
    ("pc", _scale(("backup", "anchor_reach"), 2.0), "backup.certified", True),
    ("paper", _scale(("backup", "anchor_reach"), 1.5), "backup.certified", True),
    ("pc", _scale(("backup", "rate_bound"), 2.0), "backup.rate_bound", True),
    ("pc", lambda d: _set(d, ("backup",), None), "backup", True),
    ("paper", lambda d: _set(d, ("tiers", "tracking"), True), "tiers.tracking", True),
    ("paper", _scale(("safe_design", "margins", "position"), 0.5), "safe_design.margins.position", True),
    ("paper", _scale(("safe_design", "tube", "p_xy"), 0.5), "safe_design.tube.p_xy", True),
    ("paper", lambda d: _set(d, ("safe_design",), None), "safe_design", True),
    ("paper", lambda d: _set(d, ("safe_design", "conditions"), [c for c in d["safe_design"]["conditions"]
                                                                if c["condition"] != "safe_only.sensing"]),
     "conditions[safe_only.sensing]", True),
    # the checksum left stale: it speaks first
    ("pc", lambda d: _set(d, ("inputs", "scenario", "limits", "u_max"), 0.1), "checksum", False),
    ("pc", _scale(("tube", "rho"), 0.9), "checksum", False),
    ("pc", lambda d: _set(d, ("scenario",), "another name"), "checksum", False),
]


@pytest.mark.parametrize("which, change, field, restamp", TAMPERING,
                         ids=[f"{t[2]}{'' if t[3] else ' (stale checksum)'}" for t in TAMPERING])
def test_tampering_is_refused_naming_the_field(pc_json, ok_json, paper_json, which, change, field, restamp):
    d = copy.deepcopy({"pc": pc_json, "ok": ok_json, "paper": paper_json}[which])
    change(d)
    if restamp:
        d["checksum"] = checksum_of(d)
    res = recheck(d)
    failed = [c["name"] for c in res.failed]
    assert any(n.startswith(field) for n in failed), failed
    assert not res.confirmed and "DISAGREES" in res.summary()
    assert res.edited is not restamp
    if not restamp:
        assert res.summary().splitlines()[1] == "  edited after issue: the checksum does not match the content"
    with pytest.raises(ConfigError, match=r"certificate\."):
        res.check()


def test_the_table_covers_every_block():
    heads = {t[2].split(".")[0].split("[")[0].split(" ")[0] for t in TAMPERING}
    assert {"inputs", "design_key", "theorem_version", "law", "problem", "region", "disturbance", "gains", "sigma",
            "tube", "margins", "v_bar", "kappa_bar", "e_bar", "arc_rates", "conditions", "certified",
            "failures", "assumptions", "premises", "checksum", "backup", "tiers", "safe_design", "terminal"} <= heads
    assert len(TAMPERING) >= 25


def test_a_weaker_number_is_a_note_not_an_error(pc_json):
    d = copy.deepcopy(pc_json)
    d["tube"]["rho"] = [2 * x for x in d["tube"]["rho"]]
    d["checksum"] = checksum_of(d)
    res = recheck(d)
    assert res.ok and res.confirmed
    assert any(n.startswith("tube.rho[0]: stored") and "weaker" in n for n in res.notes)


def test_the_wall_time_is_outside_the_checksum(pc_json):
    d = copy.deepcopy(pc_json)
    d["elapsed_s"] = 99.0
    assert recheck(d).confirmed


# --------------------------------------------------------------------------- the command
def test_cli_exit_codes(pc_json, paper_json, tmp_path, capsys):
    good, bad, edited = tmp_path / "pc.json", tmp_path / "paper.json", tmp_path / "edited.json"
    good.write_text(json.dumps(pc_json))
    bad.write_text(json.dumps(paper_json))
    d = copy.deepcopy(pc_json)
    d["inputs"]["scenario"]["limits"]["u_max"] = 0.1
    edited.write_text(json.dumps(d))
    assert main(["recheck", str(good)]) == 0
    assert "CONFIRMED" in capsys.readouterr().out
    assert main(["recheck", str(bad)]) == 3
    assert main(["recheck", str(edited)]) == 3
    out = capsys.readouterr().out
    assert "edited after issue" in out and "[FAIL] design_key" in out and "DISAGREES" in out


def _drop(key):
    def change(d):
        d = copy.deepcopy(d)
        del d[key]
        return json.dumps(d).encode()
    return change


BAD_FILES = [
    (lambda d: b"\x89PNG\x00\x01", "CERT"),
    (lambda d: b"[1, 2, 3]", "CERT"),
    (lambda d: b"{not json", "CERT"),
    (lambda d: b"{\"certified\": true}", "certificate.checksum"),
    (_drop("inputs"), "certificate.inputs"),
    (_drop("tube"), "certificate.tube"),
    (lambda d: json.dumps(dict(d, margins={"e_d": "wide"})).encode(), "certificate.margins.e_d"),
    (lambda d: json.dumps(dict(d, inputs=dict(d["inputs"], scenario=dict(d["inputs"]["scenario"], epsilon=-1.0))
                               )).encode(), "certificate.inputs.scenario.epsilon"),
]


@pytest.mark.parametrize("content, field", BAD_FILES, ids=["binary", "array", "syntax", "missing-keys", "no-inputs",
                                                           "no-tube", "wrong-type", "bad-scenario"])
def test_bad_files_exit_2_with_one_line(pc_json, content, field, tmp_path, capsys):
    f = tmp_path / "c.json"
    f.write_bytes(content(pc_json))
    with pytest.raises(ConfigError, match=field):
        recheck_file(f)
    assert main(["recheck", str(f)]) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_the_gain_re_proof_is_in_arb_within_a_budget():
    """The paper's law needs a few hundred boxes for its K_oo bound: proved within the default budget,
    unresolved (a disagreement, never a pass) within 2 boxes."""
    from tubekit.scenario import paper_scenario
    d = json.loads(json.dumps(verify.certify(paper_scenario(), "paper").to_dict()))
    assert recheck(d).ok
    res = recheck(d, gain_boxes=2)
    unresolved = [c for c in res.failed if c["name"].startswith("gains.")]
    assert unresolved and all(c["derived"].startswith("unresolved") for c in unresolved)


# --------------------------------------------------------------------------- the dynamic plant (issue 30 item 4)
SLOW = "examples/bluerov2_slow.toml"


@pytest.fixture(scope="module")
def slow_json():
    """examples/bluerov2_slow.toml: the safe tier certified on the dynamic plant (certified once per module)."""
    from tubekit.scenario import load_scenario
    return json.loads(json.dumps(verify.certify(load_scenario(SLOW)).to_dict()))


def _fast_law(d: dict) -> None:
    """The ramp, the fades and both bands made fast: the stored geometry still certifies, its command does not."""
    law = d["backup"]["law"]
    for k in ("ramp", "surge_fade", "yaw_fade", "heave_band", "yaw_band"):
        law[k] *= 0.01


def _drop_conditions(path: tuple):
    return lambda d: _set(d, path, [])


# (change, field named): each edit re-stamps the checksum; before issue 30 every one was CONFIRMED
DYNAMIC_TAMPERING = [
    # the stored law's command rate, which the loop bound must cover (E re-derived for the stored law)
    (_scale(("backup", "law", "heave_band"), 0.01), "velocity_loop.error"),
    (_fast_law, "velocity_loop.error"),
    (_scale(("backup", "law", "heave_band"), 0.01), "conditions[loop_consistent].ok"),
    # the loop bound's own fields, each in its direction
    (_scale(("velocity_loop", "jump_tick"), 0.1), "velocity_loop.jump_tick"),
    (_scale(("velocity_loop", "jump_period"), 0.5), "velocity_loop.jump_period"),
    (lambda d: _set(d, ("velocity_loop", "assumed"), [[0.5 * x for x in row] for row in d["velocity_loop"]["assumed"]]),
     "velocity_loop.assumed"),
    (_scale(("velocity_loop", "w_rate"), 0.5), "velocity_loop.w_rate"),
    (_scale(("velocity_loop", "first_command"), 0.0), "velocity_loop.first_command"),
    (_scale(("velocity_loop", "authority"), 2.0), "velocity_loop.authority"),
    (_scale(("velocity_loop", "thrust_floor"), 2.0), "velocity_loop.thrust_floor"),
    (lambda d: _set(d, ("velocity_loop", "gains", 2, "tick", "e"),
                    [0.5 * x for x in d["velocity_loop"]["gains"][2]["tick"]["e"]]), "velocity_loop.gains[2]"),
    (_drop_conditions(("velocity_loop", "conditions")), "velocity_loop.conditions[loop_fixed_point]"),
    # the backup's yaw-rate error, and the plant's conditions (a missing one is a disagreement)
    (_scale(("backup", "yaw_rate_error"), 0.5), "backup.yaw_rate_error"),
    (_drop_conditions(("plant_conditions",)), "plant_conditions[loop_consistent]"),
]


def test_a_dynamic_certificate_is_confirmed(slow_json):
    """The slow BlueROV2's certificate (the safe tier; tracking refused at the start, ``initial_terminal``): every
    re-check agrees, and it claims no more than that."""
    res = recheck(slow_json)
    assert res.ok and not res.notes and not res.certified_claim, (res.failed, res.notes)
    assert slow_json["tiers"]["safe"] is True and slow_json["tiers"]["failed"]["tracking"] == ["initial_terminal"]
    names = {c["name"] for c in res.checks}
    assert {"velocity_loop.error[0]", "velocity_loop.jump_tick[2]", "velocity_loop.assumed[2][3]",
            "velocity_loop.authority[0]", "backup.yaw_rate_error", "plant_conditions[loop_consistent].ok",
            "velocity_loop.conditions[loop_fixed_point].ok"} <= names


@pytest.mark.parametrize("change, field", DYNAMIC_TAMPERING, ids=[t[1] for t in DYNAMIC_TAMPERING])
def test_dynamic_tampering_is_refused_naming_the_field(slow_json, change, field):
    d = copy.deepcopy(slow_json)
    change(d)
    d["checksum"] = checksum_of(d)
    res = recheck(d)
    failed = [c["name"] for c in res.failed]
    assert any(n.startswith(field) for n in failed), failed
    assert not res.confirmed and not res.edited and "DISAGREES" in res.summary()


def test_the_dynamic_table_covers_every_stored_loop_block():
    heads = {t[1].split(".")[0].split("[")[0] for t in DYNAMIC_TAMPERING}
    assert {"velocity_loop", "backup", "plant_conditions", "conditions"} <= heads
