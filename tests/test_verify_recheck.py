"""verify.recheck / `tubekit recheck`: a certificate re-checked from its JSON alone, and tampering caught."""

from __future__ import annotations

import copy
import json

import pytest

from tubekit.app.cli import main
from tubekit.exceptions import ConfigError
from verify.recheck import recheck, recheck_file


@pytest.fixture(scope="module")
def pc_json(pc_cert):
    return json.loads(json.dumps(pc_cert.to_dict()))


def test_a_certified_certificate_is_confirmed(pc_json):
    res = recheck(pc_json)
    assert res.ok and res.confirmed and res.certified_claim
    names = {c["name"] for c in res.checks}
    assert {"disturbance", "gains_sampled", "tube_post_fixed_point", "kappa_bar", "margins", "verdict"} <= names
    assert any(n.startswith("condition ") for n in names)
    res.check()  # raises nothing


def test_an_uncertified_certificate_agrees_but_is_not_confirmed(paper_cert):
    res = recheck(json.loads(json.dumps(paper_cert.to_dict())))
    assert res.ok and not res.confirmed and not res.certified_claim
    assert "agrees (not certified)" in res.summary()


def _tampered(d: dict, path: tuple, value) -> dict:
    d = copy.deepcopy(d)
    node = d
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return d


TAMPERING = [
    # a tube 10 % smaller than certified is no longer a post-fixed point of the one-period map
    (("tube", "rho"), lambda d: [0.9 * x for x in d["tube"]["rho"]], "tube_post_fixed_point"),
    # a smaller disturbance bound than the stored scenario produces
    (("problem", "omega_xy"), lambda d: 0.5 * d["problem"]["omega_xy"], "disturbance"),
    # a gain bound below what K attains
    (("gains", "k_abs"), lambda d: [[0.5 * x for x in row] for row in d["gains"]["k_abs"]], "gains_sampled"),
    # per-arc margins shrunk below what the tube implies
    (("margins", "e_o"), lambda d: [0.5 * x for x in d["margins"]["e_o"]], "margins"),
    # a condition's verdict flipped
    (("conditions",), lambda d: [dict(c, ok=(not c["ok"]) if c["condition"] == "yaw_budget" else c["ok"])
                                 for c in d["conditions"]], "condition yaw_budget"),
]


@pytest.mark.parametrize("path, change, caught_by", TAMPERING, ids=[t[2] for t in TAMPERING])
def test_tampering_is_caught(pc_json, path, change, caught_by):
    res = recheck(_tampered(pc_json, path, change(pc_json)))
    failed = {c["name"] for c in res.checks if not c["ok"]}
    assert caught_by in failed and not res.confirmed
    with pytest.raises(ConfigError, match="certificate"):
        res.check()


def test_cli_exit_codes(pc_cert, paper_cert, tmp_path, capsys):
    good, bad = tmp_path / "pc.json", tmp_path / "paper.json"
    good.write_text(json.dumps(pc_cert.to_dict()))
    bad.write_text(json.dumps(paper_cert.to_dict()))
    assert main(["recheck", str(good)]) == 0
    assert "CONFIRMED" in capsys.readouterr().out
    assert main(["recheck", str(bad)]) == 3


BAD_FILES = [
    (b"\x89PNG\x00\x01", "CERT"),
    (b"[1, 2, 3]", "CERT"),
    (b"{\"certified\": true}", "certificate"),
    (b"{not json", "CERT"),
]


@pytest.mark.parametrize("content, field", BAD_FILES, ids=["binary", "array", "missing-keys", "syntax"])
def test_bad_files_exit_2_naming_the_field(content, field, tmp_path, capsys):
    f = tmp_path / "c.json"
    f.write_bytes(content)
    with pytest.raises(ConfigError, match=field):
        recheck_file(f)
    assert main(["recheck", str(f)]) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
