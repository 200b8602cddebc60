"""Tests of verify.certificate.report: the certificate as text."""

from __future__ import annotations

from tubekit.scenario import paper_scenario
from verify import certify
import pytest

from verify.certificate.report import certificate_text, compare, tiers_line, tried_lines


def test_certified_text(pc_cert):
    text = pc_cert.summary()
    assert text == certificate_text(pc_cert)
    first = text.splitlines()[0]
    assert "'paper-currents'" in first and "'corrected'" in first
    assert first.endswith(": CERTIFIED -- safe: certified; tracking: certified")
    assert "FAIL" not in text and text.count("[ok  ]") == len(pc_cert.conditions)
    for c in pc_cert.conditions:
        assert f"{c.condition}: {c.inequality}" in text
    assert "Premises" in text and "Assumptions" in text and "Elapsed:" in text
    rho = pc_cert.tube.rho
    assert f"|rho| <= [{rho[0]:.4g}, {rho[1]:.4g}, {rho[2]:.4g}]" in text
    assert "sigma = 0 1/s" in text and "0*" in text and "3.125*" in text
    assert f"Design key: {pc_cert.design_key}" in text and len(pc_cert.design_key) == 64


def test_uncertified_text_names_every_failure(paper_cert):
    text = paper_cert.summary()
    n = len(paper_cert.failures)
    assert f"NOT CERTIFIED ({n} failed conditions)" in text.splitlines()[0]
    assert text.count("[FAIL]") == n
    for f in paper_cert.failures:
        line = next(ln for ln in text.splitlines() if f"] {f.condition}:" in ln)
        assert line.startswith("  [FAIL]") and compare(f.lhs, f.rhs) in line
        assert f.detail in line


def test_text_without_a_tube():
    sc = paper_scenario()
    c = certify(sc.with_changes(disturbance=type(sc.disturbance)(amplitude=(2.0, 2.0, 2.0))))
    text = c.summary()
    assert "One-period tube: none (" in text and "diverge" in text
    assert "V_bar = [" not in text and "Per-arc margins" not in text   # no V-bar line of the tracking design
    assert "[FAIL] tube" in text


def test_the_tiers_and_the_backup_are_printed(pc_cert, paper_cert):
    assert tiers_line(pc_cert) == "safe: certified; tracking: certified"
    text = paper_cert.summary()
    failed = ", ".join(paper_cert.tier_failures["tracking"])
    assert tiers_line(paper_cert) == f"safe: certified; tracking: not certified ({failed})"
    assert failed.startswith("keep_up[u], yaw_budget")
    assert text.splitlines()[0].endswith(tiers_line(paper_cert))
    b = paper_cert.backup
    assert "backup (station keeping): certified" in text
    assert f"horizontal radius {b.safe_set.radius:.3f} m" in text and "Safe-only design (sigma = 0" in text
    assert f"hand-over: within {b.handover[0]:.4g} m horizontally" in text
    for c in paper_cert.tier_conditions["safe"]:
        assert c.condition in text.split("depends on: ")[1].splitlines()[0]


def test_a_certificate_without_the_safe_tier_names_its_failures():
    c = certify(paper_scenario().with_changes(sensing_range=0.6))
    assert tiers_line(c).startswith("safe: not certified (safe_only.sensing")


@pytest.mark.parametrize("lhs, rhs, text", [
    (0.9999996, 1.0, "0.9999996 < 1"),          # strict tube condition: never "1 vs 1"
    (1.0, 1.0, "1 = 1"),
    (-0.293, 0.0, "-0.293 < 0"),                # the direction is printed
    (0.4, 0.496991, "0.4 < 0.496991"),
    (6.0, 1.44993, "6 > 1.44993"),
    (1.0 + 2.0 ** -52, 1.0, "1.0000000000000002 > 1"),
    (None, 1.0, "n/a vs 1"),
    (float("inf"), 1.0, "inf vs 1"),
])
def test_compare_prints_the_relation(lhs, rhs, text):
    """Issue 24 item 9: a condition prints its two numbers with their relation, distinct when they differ."""
    assert compare(lhs, rhs) == text


def test_uncertified_text_does_not_speak_of_certified_designs(paper_cert):
    text = paper_cert.summary()
    assert not any(t.certified for t in paper_cert.tried)
    assert "among the certified ones tried" not in text
    assert "none tried certified" in text


def test_tried_lines_give_every_design_s_failures(paper_cert):
    lines = tried_lines(paper_cert)
    assert lines[0] == f"Designs tried ({len(paper_cert.tried)}):" and len(lines) == 1 + len(paper_cert.tried)
    for trial, line in zip(paper_cert.tried, lines[1:]):
        assert all(name in line for name in trial.failed) and f"{len(trial.failed)} failed" in line
