"""verify.theorem.completion_bounds: what the completion's proof reads, as ``terminal_bounds`` fills it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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


def _lateral_run(law, sc, t: float, d: float, phi: float, alpha: float) -> float:
    """|q'_y| (m): one row of ``law`` held over delta from distance d, bearing phi and heading angle alpha to the
    line of sight, the relative position's component across the start's line of sight one period later."""
    import numpy as np
    from tubekit.model.kinematics import unicycle_step
    dt, tr = sc.controller.dt, sc.trajectory
    p, v = (np.asarray(g(t), float).reshape(3) for g in (tr.position, tr.velocity))
    los = math.atan2(v[1], v[0]) - phi
    x = np.array([p[0] - d * math.cos(los), p[1] - d * math.sin(los), p[2], los + alpha])
    end = unicycle_step(x, law.command(x, p, v, dt), dt)
    q = np.asarray(tr.position(t + dt), float).reshape(3)[:2] - end[:2]
    return abs(-math.sin(los) * q[0] + math.cos(los) * q[1])


@pytest.fixture(scope="module")
def faced():
    """keep_moving_tracked's certified law (with its bearing face), its bounds and completion arc."""
    from verify.theorem.completion_bounds import completion_arc
    sc = load_scenario(ROOT / "examples" / "keep_moving_tracked.toml")
    cert = verify.certify(sc)
    law = cert.design.terminal
    b = terminal_bounds(sc, cert.design, cert.region)
    return sc, law, b, completion_arc(b, law)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(t=st.floats(0.0, 50.0), u=st.floats(0.0, 1.0), f=st.floats(-1.0, 1.0), a=st.floats(-1.0, 1.0))
def test_under_a_bearing_face_the_lateral_run_stays_within_the_narrowed_bound(faced, t, u, f, a):
    """Property (step 17b, the lateral bound Y): from any start the completion's proof admits (distance within the
    deviation of X_f's band, bearing within Phi_0, heading within A_0 of the line of sight), one row of the law
    moves the relative position across the start's line of sight by at most Y, which the bearing face narrows
    from delta P / cos(beta) to delta P sin(Phi_0 + beta) / cos(beta)."""
    from verify.kernel.intervals import upper
    from verify.theorem.completion_bounds import start_bearing
    sc, law, b, arc = faced
    lo, hi = law.d_lo - b.dev_xy, law.d_hi + b.dev_xy
    phi0, a0 = float(start_bearing(b, law).mid()), float(arc.a0.mid())
    assert phi0 + float(arc.beta.mid()) < math.pi / 2      # the narrowed branch is the one exercised
    run = _lateral_run(law, sc, t, lo + u * (hi - lo), f * phi0 * (1 - 1e-9), a * a0 * (1 - 1e-9))
    assert run <= upper(arc.lateral) + 1e-12


def test_the_narrowed_lateral_bound_needs_the_bearing_face(faced):
    """Counterexample: a start beside the target (bearing pi/2, at d*, pointing at it) runs further across the line
    of sight than the face's Y: the narrowing holds only because X_f keeps the bearing within phi_f."""
    from verify.kernel.intervals import upper
    sc, law, b, arc = faced
    wide = _without_face(b, law)
    assert upper(arc.lateral) < upper(wide.lateral)
    run = _lateral_run(law, sc, 10.0, law.d_star, math.pi / 2, 0.0)
    assert upper(arc.lateral) < run <= upper(wide.lateral)


def _without_face(b, law):
    """The completion's arc of ``law`` with its bearing face removed."""
    import dataclasses
    from tubekit.model.terminal_law import NO_BEARING
    from verify.theorem.completion_bounds import completion_arc
    return completion_arc(b, dataclasses.replace(law, bearing_max=NO_BEARING))
