"""verify.theorem.completion_bounds: what the completion's proof reads, as ``terminal_bounds`` fills it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import verify
from tubekit import load_scenario
from verify.theorem.completion_bounds import TerminalBounds
from verify.theorem.terminal import terminal_bounds

ROOT = Path(__file__).resolve().parents[1]


def test_a_surge_floor_and_the_targets_least_speed_reach_the_bounds():
    """keep_moving_tracked: a 0.4 m/s line (its least speed is its speed) and u_min 0.2 m/s at sigma = 0 (no
    feedback reserve, kappa_u = 0): surge floor 0.2 m/s."""
    sc = load_scenario(ROOT / "examples" / "keep_moving_tracked.toml")
    cert = verify.certify(sc)
    b = terminal_bounds(sc, cert.design, cert.region)
    assert isinstance(b, TerminalBounds) and cert.sigma.value == 0.0
    assert b.speed_floor_xy == pytest.approx(0.4) and b.surge_floor == pytest.approx(0.2, abs=1e-12)


def test_without_a_surge_floor_the_bounds_carry_none(pc_cert):
    """paper_currents: no u_min; the circle's least speed is its speed 3 pi / 50 m/s (rate pi / 50 on 3 m)."""
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    b = terminal_bounds(sc, pc_cert.design, pc_cert.region)
    assert b.surge_floor is None and b.speed_floor_xy == pytest.approx(3 * math.pi / 50)


@pytest.mark.parametrize("lhs, rhs, ok", [
    ("1.0", "1.0000000011", True),        # beyond the 1e-9 slack
    ("1.0", "1.0000000009", False),       # within it: refused, so the float check cannot disagree
    ("inf", "2.0", False),                # an unbounded side never holds
])
def test_a_completion_condition_holds_only_with_the_float_slack(lhs, rhs, ok):
    from flint import arb
    from verify.theorem.completion_bounds import FLOAT_SLACK, slack_condition
    c = slack_condition("x", "lhs <= rhs", arb(lhs), arb(rhs))
    assert FLOAT_SLACK == 1e-9 and c.ok is ok and c.condition == "x"
