"""Tests of verify.certificate.report: the certificate as text."""

from __future__ import annotations

from pathlib import Path

from tubekit.scenario import load_scenario, paper_scenario
from verify import certify
import pytest

from verify.certificate.certify import assumptions_of
from verify.certificate.knobs import failure_knobs
from verify.certificate.record import ASSUMPTIONS
from verify.certificate.report import (FAILURE_LINES, LOOP_NOT_CLOSED, certificate_text, compare, knob_text,
                                       summary_text, tiers_line, tried_lines, verdict_line)

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


@pytest.fixture(scope="module")
def remus_cert():
    """A dynamic certificate with many failed conditions (examples/remus100_currents.toml)."""
    return certify(load_scenario(EXAMPLES / "remus100_currents.toml"))


def test_certified_text(pc_cert):
    text = pc_cert.summary(verbose=True)
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
    text = paper_cert.summary(verbose=True)
    n = len(paper_cert.failures)
    assert f"NOT CERTIFIED ({n} failed conditions)" in text.splitlines()[0]
    assert text.count("[FAIL]") == n
    knobs = failure_knobs(paper_cert)
    for f in paper_cert.failures:
        line = next(ln for ln in text.splitlines() if f"] {f.condition}:" in ln)
        assert line.startswith("  [FAIL]") and compare(f.lhs, f.rhs) in line
        assert f.detail in line and line.endswith(f"({f.detail}){knob_text(knobs[f.condition])}")


def test_the_summary_is_short_and_says_what_to_change(paper_cert):
    """Issue 35 item 6: the verdict, each failure with its knob, the tube, the backup, the key; the rest with -v."""
    text = paper_cert.summary()
    lines = text.splitlines()
    assert text == summary_text(paper_cert) and len(lines) <= 25
    assert lines[0] == verdict_line(paper_cert) and lines[0].endswith(tiers_line(paper_cert))
    assert ("  keep_up[u]: u_bar >= horizontal target speed + omega_bar_xy: 0.4 < 0.496991 — set limits.u_max >= "
            "0.503 m/s or |trajectory.rate| <= 0.0933 rad/s") in lines
    assert not any(ln.startswith("  yaw_budget: ") for ln in lines)         # a screen step 17 supersedes
    assert "  e_bar[e_o]: M_o < e_o_max (last arc): 0.962319 > 0.9" in lines        # no single field decides it
    assert sum(ln.startswith("sigma = 0 1/s") for ln in lines) == 1
    assert sum(ln.startswith("backup (station keeping): certified; safe radius 0.750 m") for ln in lines) == 1
    assert f"Design key: {paper_cert.design_key}" in text and "summary(verbose=True)" in lines[-1]
    for absent in ("Premises", "Assumptions", "Region R", "[ok  ]", "paper's route"):
        assert absent not in text
    assert len(paper_cert.summary(verbose=True).splitlines()) > 50


def test_a_certified_summary(pc_cert):
    lines = pc_cert.summary().splitlines()
    assert lines[0].endswith(": CERTIFIED -- safe: certified; tracking: certified") and len(lines) <= 10
    assert lines[1] == f"Every condition holds ({len(pc_cert.conditions)}; each with its numbers: tubekit certify -v)."


def test_a_summary_of_many_failures_stays_short(remus_cert):
    lines = remus_cert.summary().splitlines()
    failed = [c for c in remus_cert.conditions if c.ok is not True]
    assert len(failed) > FAILURE_LINES and len(lines) <= 25
    assert lines[2].startswith("  rate_authority[u]: ") and "— set limits.rate[0] <= " in lines[2]   # knobs first
    more = next(ln for ln in lines if ln.startswith("  ... and "))
    assert more.startswith(f"  ... and {len(failed) - FAILURE_LINES} more: ")
    assert sum(ln.startswith("velocity loop (derived bound): NOT certified") for ln in lines) == 1


def test_the_assumptions_follow_the_plant(paper_cert, remus_cert):
    """Issue 35 item 6: a dynamic certificate does not say the plant is the kinematic model."""
    assert paper_cert.assumptions == ASSUMPTIONS == assumptions_of(False, paper_cert.disturbance)
    assert ASSUMPTIONS[0].startswith("The plant is the kinematic model eq. (11)")
    dyn = remus_cert.assumptions
    assert dyn == assumptions_of(True, remus_cert.disturbance)
    assert dyn[0].startswith("Dynamic plant: the 4-DOF model")
    assert not any("kinematic model" in a or "eq. (11)" in a or "not covered" in a for a in dyn)
    assert dyn[-1] == ASSUMPTIONS[-1]                 # exact sensing, whatever the plant


def test_text_without_a_tube():
    sc = paper_scenario()
    c = certify(sc.with_changes(disturbance=type(sc.disturbance)(amplitude=(2.0, 2.0, 2.0))))
    assert "one-period tube: none (" in c.summary() and "diverge" in c.summary()
    text = c.summary(verbose=True)
    assert "One-period tube: none (" in text and "diverge" in text
    assert "V_bar = [" not in text and "Per-arc margins" not in text   # no V-bar line of the tracking design
    assert "[FAIL] tube" in text


def test_the_tiers_and_the_backup_are_printed(pc_cert, paper_cert):
    assert tiers_line(pc_cert) == "safe: certified; tracking: certified"
    text = paper_cert.summary()
    failed = ", ".join(paper_cert.tier_failures["tracking"])
    assert tiers_line(paper_cert) == f"safe: certified; tracking: not certified ({failed})"
    assert failed == "keep_up[u], e_bar[e_o]"
    assert text.splitlines()[0].endswith(tiers_line(paper_cert))
    text = paper_cert.summary(verbose=True)
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
    text = paper_cert.summary(verbose=True)
    assert not any(t.certified for t in paper_cert.tried)
    assert "among the certified ones tried" not in text
    assert "none tried certified" in text


def test_tried_lines_give_every_design_s_failures(paper_cert):
    lines = tried_lines(paper_cert)
    assert lines[0] == f"Designs tried ({len(paper_cert.tried)}):" and len(lines) == 1 + len(paper_cert.tried)
    for trial, line in zip(paper_cert.tried, lines[1:]):
        assert all(name in line for name in trial.failed) and f"{len(trial.failed)} failed" in line


def test_a_path_clearance_failure_says_where_when_and_how_much():
    """The tracking theorem's refusal on a path too close to an obstacle prints the distance needed, the distance
    the path has and the time, on the failure's line (the summary ``tubekit certify`` prints)."""
    import re

    import verify
    from tubekit.scenario import Obstacle
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml").with_changes(
        obstacles=(Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((-5.3, 0.0, 0.0), 0.4)))
    text = certify(sc).summary()
    line = next(x for x in text.splitlines() if x.strip().startswith("path_clearance[0]:"))
    found = re.search(r"needs (\d\.\d+) m, has (\d(?:\.\d+)?) m at t = (\d+\.\d) s", line)
    assert found and float(found[2]) < float(found[1]) and 0.0 < float(found[3]) <= 40.0, line
    assert "tracking: not certified (path_clearance[0])" in text.splitlines()[0]


def test_where_the_loop_bound_did_not_close_the_summary_names_it_as_the_root_cause_first(remus_cert, pc_cert):
    """examples/remus100_currents.toml: the loop's fixed point does not close, so ω̄ (and every condition reading it)
    rests on an unconfirmed loop error; the failures end with one line saying so. A certificate whose loop closed, or
    without a loop, has no such line."""
    assert any(c.condition == "loop_fixed_point" and c.ok is False for c in remus_cert.conditions)
    lines = remus_cert.summary().splitlines()
    last = max(i for i, ln in enumerate(lines) if ln.startswith("  "))
    assert lines[last] == f"  root cause first: {LOOP_NOT_CLOSED}" and "keep_up" in LOOP_NOT_CLOSED
    closed = certify(load_scenario(EXAMPLES / "bluerov2_pier_brisk.toml"))
    for cert in (pc_cert, closed):
        assert LOOP_NOT_CLOSED not in cert.summary()
