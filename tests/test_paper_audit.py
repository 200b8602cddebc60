"""The audit of the paper's printed terms."""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

from tubekit.paper.audit import audit
from tubekit.app.cli import main
from tubekit.model.derivation import SYMBOL_NAMES, symbols
from tubekit.exceptions import ConfigError
from tubekit.paper.equations import TERM_NAMES


@pytest.fixture(scope="module")
def report():
    return audit(samples=400, hemisphere_samples=300)


def test_flags_exactly_the_hand_derived_differences(report):
    # By hand: d/dt e_o loses u in its numerator, so J[2,0] = -e_o c/e_d, J[2,2] = c, and the
    # third rows of zeta and xi carry c/e_d instead of sin(psi)cos(psi)/e_d^2 (c = cos(psi - bearing)).
    assert sorted(report.mismatches) == sorted(["J[2,0]", "J[2,2]", "zeta[2]", "xi[2]"])


def test_matching_terms_are_proved_symbolically(report):
    for t in report.terms:
        if t.match:
            assert t.symbolic_zero is True, t.name


def test_deliberately_wrong_expression_is_flagged():
    s = symbols()
    wrong = {"J[0,0]": sp.cos(s["psi"]), "zeta[1]": s["zdot_d"]}  # dropped bearing; wrong sign
    rep = audit(wrong, samples=200, hemisphere_samples=50)
    assert "J[0,0]" in rep.mismatches and "zeta[1]" in rep.mismatches


def test_correct_expression_in_another_form_matches():
    s = symbols()
    ex, ey, psi = s["e_x"], s["e_y"], s["psi"]
    other_form = {"J[2,2]": sp.cos(psi - sp.atan2(ey, ex))}
    rep = audit(other_form, samples=200, hemisphere_samples=50)
    assert "J[2,2]" not in rep.mismatches


def test_unknown_term_name_rejected():
    with pytest.raises(ConfigError, match="paper_terms"):
        audit({"J[3,3]": 0}, samples=20, hemisphere_samples=10)


def test_remark_1_sign_per_hemisphere(report):
    rows = {(h.source, h.heading): h for h in report.hemispheres}
    # toward: c < 0, eigenvalue c(1 + |e_o|/(2 e_d)) < 0 everywhere
    assert rows[("derived", "toward")].negative_fraction == 1.0
    assert rows[("derived", "toward")].lambda_min_max < 0
    away = rows[("derived", "away")]
    assert 0 < away.negative_fraction < 1 and away.lambda_min_max > 0


def test_cli_json_lists_15_parsable_terms(tmp_path, capsys):
    out = tmp_path / "audit.json"
    assert main(["audit", "--json", str(out), "--samples", "200"]) == 0
    data = json.loads(out.read_text())
    names = [t["name"] for t in data["terms"]]
    assert names == list(TERM_NAMES) and len(names) == 15
    local = {n: sp.Symbol(n, real=True) for n in SYMBOL_NAMES}
    rng = np.random.default_rng(3)
    point = {local[n]: rng.uniform(0.2, 1.0) for n in SYMBOL_NAMES}
    for t in data["terms"]:
        p = sp.sympify(t["paper"], locals=local)
        d = sp.sympify(t["derived"], locals=local)
        assert p.free_symbols <= set(local.values()) and d.free_symbols <= set(local.values())
        same = abs(float(p.subs(point)) - float(d.subs(point))) < 1e-9
        if not same:
            assert t["match"] is False
    assert "J[2,0]" in capsys.readouterr().out


def test_cli_rejects_bad_samples(capsys):
    assert main(["audit", "--samples", "1"]) == 2
    assert "--samples" in capsys.readouterr().err
