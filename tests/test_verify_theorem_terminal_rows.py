"""verify.theorem.terminal_rows: X_f's row faces under rate-limited plans (docs/verify.md, step 17c)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from flint import arb
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit import load_scenario
from tubekit.model.kinematics import unicycle_step
from tubekit.model.terminal_law import line_of_sight
from tubekit.model.trajectory import Circle
from verify.theorem.terminal import law_conditions, terminal_bounds
from verify.theorem.completion_bounds import completion_arc
from verify.theorem.terminal_rows import feedforward_change, gentle_law, row_changes

ROOT = Path(__file__).resolve().parents[1]
SMOOTH = load_scenario(ROOT / "examples" / "smooth_line.toml")
#: The same plans after a target on a 10 m circle at 0.2 m/s (its velocity turns 0.002 rad a period).
CIRCLING = SMOOTH.with_changes(trajectory=Circle(radius=10.0, rate=0.02, center=(0.0, -10.0, 0.0), phase=0.0),
                               obstacles=(), workspace=((-30.0, -30.0, -10.0), (30.0, 30.0, 10.0)))
SCENARIOS = {"line": SMOOTH, "circle": CIRCLING}
ROWS = ("terminal_rate[u]", "terminal_rate[w]", "terminal_rate[r]",
        "terminal_invariant[row_u]", "terminal_invariant[row_w]", "terminal_invariant[row_r]")


@pytest.fixture(scope="module")
def certs():
    return {name: verify.certify(sc) for name, sc in SCENARIOS.items()}


def test_rate_limited_plans_on_a_line_or_a_circle_get_both_tiers_with_row_faces(certs):
    for name, cert in certs.items():
        law = cert.design.terminal
        assert cert.tiers.safe and cert.tiers.tracking, name
        assert law is not None and law.has_rows and min(law.row_u, law.row_w, law.row_r) > 0.0
        assert set(ROWS) <= {c.condition for c in cert.design.conditions}
        assert cert.tightening.terminal_law == law and cert.tightening.plan_always_available
        assert cert.backup.law.blends, "under rate-limited plans the backup ramps from the last command"


def _end_state(p: np.ndarray, v: np.ndarray, d: float, phi: float, a: float, z: float) -> np.ndarray:
    """x_N at distance d behind the target at p (the line of sight at phi from its velocity v), heading a off the
    line of sight, depth error z."""
    los = math.atan2(v[1], v[0]) - phi
    where = p[:2] - d * np.array([math.cos(los), math.sin(los)])
    return np.array([where[0], where[1], p[2] + z, los + a])


@settings(max_examples=150, deadline=None, derandomize=True)
@given(which=st.sampled_from(sorted(SCENARIOS)), t=st.floats(0.0, 30.0), u=st.floats(0.0, 1.0),
       phi=st.floats(-math.pi, math.pi), a=st.floats(-1.0, 1.0), z=st.floats(-1.0, 1.0),
       off=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
       dev=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)))
def test_one_completion_stays_within_the_jump_and_meets_the_faces_again(certs, which, t, u, phi, a, z, off, dev):
    """Property (step 17c): a plan ending at x_N in X_f with its last row within S of the law's row there; the
    completion from x_N moved by the replay's deviation changes the command by at most J, and one period later
    along the exact arc it ends in X_f again with its own row within S of the law's row at its end."""
    sc, cert = SCENARIOS[which], certs[which]
    law, b = cert.design.terminal, terminal_bounds(sc, cert.design, cert.region)
    _, row, end, p1, v1 = _one_completion(sc, b, law, t, (u, phi, a, z), off, dev)
    assert law.contains(end, p1, v1)
    assert min(law.row_slacks(end, p1, v1, row, sc.controller.dt).values()) >= 0.0


def _one_completion(sc, b, law, t: float, where: tuple[float, float, float, float], off, dev):
    """A plan ending at x_N in X_f (``where`` = (u, φ, a, z): distance fraction, bearing, heading and depth fractions)
    with its last row within the faces (``off``), the completion's start x_N moved by the replay's deviation
    (``dev``), its row (asserted within J of the last) and its exact arc: (start, row, end, p_d and ṗ_d at the end)."""
    dt, tr = sc.controller.dt, sc.trajectory
    u, phi, a, z = where
    p, v = np.asarray(tr.position(t), float).reshape(3), np.asarray(tr.velocity(t), float).reshape(3)
    x_n = _end_state(p, v, law.d_lo + u * (law.d_hi - law.d_lo), phi, a * law.alpha_max, z * law.z_max)
    last = law.command(x_n, p, v, dt) + np.asarray(off) * np.array([law.row_u, law.row_w, law.row_r])
    shift = np.array(dev[:2]) / max(1.0, float(np.hypot(*dev[:2]))) * b.dev_xy
    x_start = x_n + np.array([shift[0], shift[1], dev[2] * b.dev_z, dev[3] * b.dev_psi])
    row = law.command(x_start, p, v, dt)
    assert np.all(np.abs(row - last) <= np.asarray(b.jumps) + 1e-12), (row - last, b.jumps)
    p1, v1 = (np.asarray(g(t + dt), float).reshape(3) for g in (tr.position, tr.velocity))
    return x_start, row, unicycle_step(x_start, row, dt), p1, v1


@pytest.fixture(scope="module")
def fed(certs):
    """(bounds, law) per scenario: the certified set with the line-of-sight feedforward (step 17e) and its own
    gentle gains and faces, every condition of the completion holding."""
    out = {}
    for name, cert in certs.items():
        b = terminal_bounds(SCENARIOS[name], cert.design, cert.region)
        law = gentle_law(b, dataclasses.replace(cert.design.terminal, los_feedforward=True), 1.02)
        assert law is not None and all(c.ok for c in law_conditions(b, law)), name
        out[name] = (b, law)
    return out


@settings(max_examples=150, deadline=None, derandomize=True)
@given(which=st.sampled_from(sorted(SCENARIOS)), t=st.floats(0.0, 30.0), u=st.floats(0.0, 1.0),
       phi=st.floats(-math.pi, math.pi), a=st.floats(-1.0, 1.0), z=st.floats(-1.0, 1.0),
       off=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
       dev=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)))
def test_with_the_feedforward_one_completion_stays_within_the_jump_and_its_heading_within_the_residual(
        fed, which, t, u, phi, a, z, off, dev):
    """Property (step 17e): with the line-of-sight feedforward, from x_N in X_f moved by the replay's deviation, the
    completion's row is within J of a last row in the faces, its exact arc turns the heading's angle to the line of
    sight to (1 − g) α̃ within the residual E, and it ends in X_f with its row within the faces."""
    sc, (b, law) = SCENARIOS[which], fed[which]
    x_start, row, end, p1, v1 = _one_completion(sc, b, law, t, (u, phi, a, z), off, dev)
    p = np.asarray(sc.trajectory.position(t), float).reshape(3)
    alpha0, alpha1 = line_of_sight(x_start, p)[1], line_of_sight(end, p1)[1]
    assert abs(alpha1 - (1 - law.turn) * alpha0) <= float(completion_arc(b, law).residual.upper()) + 1e-12
    assert law.contains(end, p1, v1)
    assert min(law.row_slacks(end, p1, v1, row, sc.controller.dt).values()) >= 0.0


def test_the_feedforward_shrinks_the_heading_residual_and_the_yaw_row_on_the_smooth_line(certs, fed):
    """On ``examples/smooth_line.toml`` the residual the turn must absorb falls from the line of sight's turn
    atan(Y / x_min) to E, more than tenfold, so the gentlest invariant turn g falls and with it the yaw row's change
    over an arc, more than threefold; the feedforward's own change is part of that bound."""
    cert = certs["line"]
    b, ff = fed["line"]
    plain = cert.design.terminal
    arc_plain, arc_ff = completion_arc(b, plain), completion_arc(b, ff)
    assert float(arc_ff.residual.upper()) < 0.1 * float(arc_plain.residual.lower())
    assert ff.turn < 0.5 * plain.turn
    k_plain, k_ff = row_changes(b, plain, arc_plain).arc[2], row_changes(b, ff, arc_ff).arc[2]
    assert float(k_ff.upper()) < float(k_plain.lower()) / 3
    assert float(arc_plain.omega.upper()) == 0.0 < float(arc_ff.omega.lower())


@pytest.mark.parametrize("part", ["across", "closing", "alpha", "distance"])
def test_the_feedforwards_change_grows_with_each_of_its_inputs(fed, part):
    """feedforward_change is increasing in each difference it is given (the bound adds them with positive weights)
    and is 0 when nothing differs."""
    b, law = fed["line"]
    arc = completion_arc(b, law)
    base = {"across": arb(0.01), "closing": arb(0.01), "alpha": arb(0.01), "distance": arb(0.01)}
    zero = {k: arb(0) for k in base}
    assert float(feedforward_change(b, law, arc, nearest=arc.start_min, **zero).upper()) == 0.0
    more = {**base, part: arb(0.02)}
    assert (float(feedforward_change(b, law, arc, nearest=arc.start_min, **more).lower())
            > float(feedforward_change(b, law, arc, nearest=arc.start_min, **base).upper()))


def test_faces_half_as_wide_as_the_proof_needs_are_refuted_and_left_by_a_completion(certs):
    """Counterexample: S_r at half the narrowest face the proof admits, K_r(arc) (the shipped face is as wide as
    the jump allows). The face's invariance fails, and a completion from X_f's heading edge, where the law turns
    hardest, with the target crossing so that the line of sight turns the other way, changes its yaw row across
    the period by more than that face."""
    sc, cert = SMOOTH, certs["line"]
    b = terminal_bounds(sc, cert.design, cert.region)
    law = cert.design.terminal
    k_arc = float(row_changes(b, law, completion_arc(b, law)).arc[2].upper())
    narrow = dataclasses.replace(law, row_r=0.5 * k_arc)
    assert "terminal_invariant[row_r]" in {c.condition for c in law_conditions(b, narrow) if not c.ok}
    dt, tr = sc.controller.dt, sc.trajectory
    p, v = np.asarray(tr.position(10.0), float).reshape(3), np.asarray(tr.velocity(10.0), float).reshape(3)
    p1, v1 = (np.asarray(g(10.0 + dt), float).reshape(3) for g in (tr.position, tr.velocity))
    slacks = []
    for phi in np.linspace(-math.pi, math.pi, 73):
        for edge in (-1.0, 1.0):
            x = _end_state(p, v, narrow.d_lo, phi, edge * narrow.alpha_max, 0.0)
            row = narrow.command(x, p, v, dt)
            end = unicycle_step(x, row, dt)
            slacks.append(narrow.row_slacks(end, p1, v1, row, dt)["terminal set: |v_r - kappa_f|"])
    assert min(slacks) < 0.0


def test_each_face_is_as_wide_as_the_jump_leaves(certs):
    """S = J − K(deviation) less a thousandth of J, which is wider than the arc's K(arc): the rate condition holds
    with that thousandth to spare and the face's invariance with room."""
    cert = certs["line"]
    b = terminal_bounds(SMOOTH, cert.design, cert.region)
    law = cert.design.terminal
    ch = row_changes(b, law, completion_arc(b, law))
    for face, dev, along, jump in zip((law.row_u, law.row_w, law.row_r), ch.deviation, ch.arc, b.jumps):
        assert face + float(dev.upper()) == pytest.approx(0.999 * jump, rel=1e-9)
        assert face > float(along.upper())


def test_the_gentle_gains_are_the_smallest_that_keep_the_set_invariant(certs):
    """Nine tenths of the chosen turn or radial gain lose X_f's heading or radial faces: the search took the
    smallest gains the invariance admits (times its factor), because the row's change grows with them."""
    cert = certs["line"]
    b = terminal_bounds(SMOOTH, cert.design, cert.region)
    law = cert.design.terminal
    for change, face in (({"turn": 0.9 * law.turn}, "terminal_invariant[alpha]"),
                         ({"gain_d": 0.9 * law.gain_d}, "terminal_invariant[d_lo]"),
                         ({"gain_z": 0.9 * law.gain_z}, "terminal_invariant[e_z]")):
        slower = dataclasses.replace(law, **change)
        assert face in {c.condition for c in law_conditions(b, slower) if not c.ok}, change
    again = gentle_law(b, dataclasses.replace(law, turn=1.0, gain_d=1.0, gain_z=1.0), 1.02)
    assert again is not None and again.turn == pytest.approx(law.turn) and again.row_r == pytest.approx(law.row_r)
    assert law.turn < 0.2 and law.gain_d < 0.2      # gentle: under a fifth of alpha turned a period


def test_the_smallest_gains_read_the_set_and_not_the_laws_own_gains_or_faces(certs):
    """The memo of ``_smallest_gains`` is keyed on the bounds and X_f's set only: computed afresh, the sizing gives
    the same gains whatever the law's own turn, gains and row faces are, and other gains for a narrower heading
    room (a field of the key)."""
    from verify.theorem.terminal_rows import _sized_gains, _smallest_gains
    cert = certs["line"]
    b = terminal_bounds(SMOOTH, cert.design, cert.region)
    law = cert.design.terminal
    fresh = _sized_gains(b, law)
    assert fresh is not None and _smallest_gains(b, law) == fresh
    for change in ({"turn": 1.0}, {"gain_d": 0.5, "gain_z": 0.5}, {"row_u": 9.0, "row_w": 9.0, "row_r": 9.0}):
        assert _sized_gains(b, dataclasses.replace(law, **change)) == fresh, change
    narrower = dataclasses.replace(law, alpha_max=0.8 * law.alpha_max)
    assert _smallest_gains(b, narrower) == _sized_gains(b, narrower) != fresh


def test_the_row_changes_grow_with_the_deviation(certs):
    """The deviation-side bounds K(deviation) are increasing in D_xy and D_psi (the sum is what terminal_rate
    reads): doubling the replay's deviation raises every channel's bound that reads it."""
    cert = certs["line"]
    b = terminal_bounds(SMOOTH, cert.design, cert.region)
    law = cert.design.terminal
    base = row_changes(b, law, completion_arc(b, law)).deviation
    wide = dataclasses.replace(b, dev_xy=2 * b.dev_xy, dev_z=2 * b.dev_z, dev_psi=2 * b.dev_psi + 0.001)
    more = row_changes(wide, law, completion_arc(wide, law)).deviation
    assert all(float(m.upper()) > float(x.upper()) for m, x in zip(more, base))


def test_a_backup_that_does_not_blend_refuses_rate_limited_tracking_by_name():
    """The loiter starts from its own surge, so rate-limited plans must end within J of it; the terminal law's row
    does not end there: ``terminal_rate`` names the backup."""
    sc = load_scenario(ROOT / "examples" / "keep_moving_tracked.toml").with_changes(**{"limits.rate": (0.5, 0.5, 1.0)})
    cert = verify.certify(sc)
    failed = {c.condition: c for c in cert.failures}
    assert cert.tiers.safe and not cert.tiers.tracking
    assert list(failed) == ["terminal_rate"] and "'loiter'" in failed["terminal_rate"].detail


def test_where_the_faces_do_not_fit_the_rate_conditions_name_the_channel():
    """The paper's scenario with plans limited to (0.1, 0.1, 0.1) per second: the surge row would move by more
    than J a period over every set whose other conditions hold, the refinement's and the feedforward's included.
    The yaw row is not named: the line-of-sight feedforward (step 17e) keeps it within J (theorem terminal/18 named
    both)."""
    sc = load_scenario(ROOT / "verify" / "scenarios" / "paper_currents.toml").with_changes(
        **{"limits.rate": (0.1, 0.1, 0.1)})
    cert = verify.certify(sc)
    assert cert.tiers.safe and not cert.tiers.tracking
    assert {c.condition for c in cert.failures} == {"terminal_rate[u]"}


def test_a_channel_without_current_still_gets_a_gain_that_keeps_its_face():
    """A steady horizontal current and none in depth: the depth channel has no deviation (D_z = 0), and its
    smallest invariant gain would be 0, which fails the face by the float slack; the gains close each face by a
    little more than the deviation needs, so tracking holds with a positive λ_z."""
    sc = SMOOTH.with_changes(**{"disturbance.amplitude": (0.0, 0.0, 0.0), "disturbance.constant": (0.0, 0.045, 0.0)})
    cert = verify.certify(sc)
    b = terminal_bounds(sc, cert.design, cert.region)
    assert b.dev_z == 0.0 and cert.tiers.tracking and cert.design.terminal.gain_z > 0.0
