"""verify.theorem.terminal_bearing: the bearing face of X_f under a minimum surge (docs/verify.md, step 17b)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit import load_scenario
from tubekit.model.kinematics import unicycle_step
from tubekit.model.terminal_law import NO_BEARING, bearing, line_of_sight
from tubekit.model.trajectory import Circle, Waypoints
from verify.kernel.intervals import upper
from verify.theorem.completion_bounds import completion_arc
from verify.theorem.terminal import (FINE_LOWER_ENDS, FINE_WIDTHS, LOWER_ENDS, WIDTHS, _grid, _grid_points, law_conditions,
                                     terminal_bounds)
from verify.theorem.terminal_bearing import (BEARING_STEP, bearing_row_sets, bearing_sets, lateral_chord,
                                             smallest_bearing)
from verify.theorem.terminal_rows import row_changes, row_sets

TRACKED = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_tracked.toml")
#: The same vehicle after a target on a 10 m circle at 0.4 m/s (curvature: the velocity turns 0.004 rad a period).
CIRCLING = TRACKED.with_changes(trajectory=Circle(radius=10.0, rate=0.04, center=(0.0, -10.0, 0.0), phase=0.0),
                                obstacles=())
SCENARIOS = {"line": TRACKED, "circle": CIRCLING}


@pytest.fixture(scope="module")
def certs():
    return {name: verify.certify(sc) for name, sc in SCENARIOS.items()}


def test_a_line_or_a_circle_under_a_surge_floor_gets_both_tiers_with_a_bearing_face(certs):
    for name, cert in certs.items():
        law = cert.design.terminal
        assert cert.tiers.safe and cert.tiers.tracking, name
        assert law is not None and law.has_bearing and 0 < law.bearing_max < math.pi / 2
        names = {c.condition for c in cert.design.conditions}
        assert {"terminal_invariant[bearing]", "terminal_invariant[bearing_cross]", "terminal_surge_floor"} <= names
        assert cert.tightening.terminal_law == law and cert.tightening.plan_always_available


def test_a_target_that_may_stop_leaves_tracking_refused_by_the_surge_floor_by_name():
    """Waypoints rest at their corners: no speed floor, so the law's surge cannot be kept above u_min."""
    sc = TRACKED.with_changes(trajectory=Waypoints(points=((0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (20.0, 5.0, 0.0)),
                                                   speed=0.4), obstacles=())
    cert = verify.certify(sc)
    assert cert.tiers.safe and not cert.tiers.tracking
    failed = {c.condition: c for c in cert.failures}
    assert list(failed) == ["terminal_surge_floor"] and "no speed floor" in failed["terminal_surge_floor"].detail


def _state(law, b, p: np.ndarray, v: np.ndarray, d: float, phi: float, a: float, z: float,
           shift: tuple[float, float], dpsi: float) -> np.ndarray:
    """A state of X_f (distance d, bearing phi, heading error a, depth error z against the target at p moving at
    v), moved by the replay's deviation: ``shift`` (a direction, scaled to D_xy) and ``dpsi`` (in units of D_psi)."""
    los = math.atan2(v[1], v[0]) - phi                      # phi: from the line of sight to the velocity
    where = p[:2] - d * np.array([math.cos(los), math.sin(los)])
    x = np.array([where[0], where[1], p[2] + z, los + a])
    s = np.asarray(shift, dtype=float)
    s = s / max(1.0, float(np.hypot(*s))) * b.dev_xy
    return x + np.array([s[0], s[1], math.copysign(b.dev_z, z), dpsi * b.dev_psi])


@settings(max_examples=120, deadline=None, derandomize=True)
@given(which=st.sampled_from(sorted(SCENARIOS)), t=st.floats(0.0, 60.0), u=st.floats(0.0, 1.0),
       f=st.floats(-1.0, 1.0), a=st.floats(-1.0, 1.0), z=st.floats(-1.0, 1.0),
       dx=st.floats(-1.0, 1.0), dy=st.floats(-1.0, 1.0), dpsi=st.floats(-1.0, 1.0))
def test_one_completion_keeps_the_cone_and_the_surge_above_its_floor(certs, which, t, u, f, a, z, dx, dy, dpsi):
    """Property (step 17b): from any state of X_f (the bearing face included) moved by the replay's deviation, one
    row of the certified law held over delta along the exact arc commands a surge of at least u_min + kappa_u and
    ends in X_f again, its bearing measured against the target's velocity one period later."""
    sc, cert = SCENARIOS[which], certs[which]
    law, dt = cert.design.terminal, sc.controller.dt
    b = terminal_bounds(sc, cert.design, cert.region)
    tr = sc.trajectory
    p, v = np.asarray(tr.position(t), float).reshape(3), np.asarray(tr.velocity(t), float).reshape(3)
    x = _state(law, b, p, v, law.d_lo + u * (law.d_hi - law.d_lo), f * law.bearing_max, a * law.alpha_max,
               z * law.z_max, (dx, dy), dpsi)
    row = law.command(x, p, v, dt)
    assert row[0] >= b.surge_floor - 1e-12 and np.all(np.abs(row) <= np.asarray(cert.design.v_bar) + 1e-12)
    end = unicycle_step(x, row, dt)
    p1, v1 = (np.asarray(g(t + dt), float).reshape(3) for g in (tr.position, tr.velocity))
    assert law.contains(end, p1, v1), (line_of_sight(end, p1), bearing(end, p1, v1), law)


def test_a_cone_narrower_than_the_proof_allows_is_refuted_and_left_by_a_completion(certs):
    """Counterexample: 0.3 of the smallest admissible phi_f. The condition fails, and a start on the cone's edge at
    d_lo pushed outward by the deviation (the vehicle moved sideways, its heading turned outward) ends outside it."""
    sc, cert = TRACKED, certs["line"]
    b = terminal_bounds(sc, cert.design, cert.region)
    narrow = dataclasses.replace(cert.design.terminal, bearing_max=0.3 * smallest_bearing(b, cert.design.terminal))
    failed = {c.condition for c in law_conditions(b, narrow) if not c.ok}
    assert "terminal_invariant[bearing]" in failed
    dt, tr = sc.controller.dt, sc.trajectory
    p, v = np.asarray(tr.position(10.0), float).reshape(3), np.asarray(tr.velocity(10.0), float).reshape(3)
    phi = narrow.bearing_max
    los = math.atan2(v[1], v[0]) - phi
    outward = (-math.sin(los), math.cos(los))     # the vehicle moved to the line of sight's left: the bearing grows
    x = _state(narrow, b, p, v, narrow.d_lo, phi, narrow.alpha_max, 0.0, outward, 0.0)  # heading left of it too
    assert bearing(x, p, v) > phi                           # the deviation alone already left the cone
    end = unicycle_step(x, narrow.command(x, p, v, dt), dt)
    p1, v1 = (np.asarray(g(10.0 + dt), float).reshape(3) for g in (tr.position, tr.velocity))
    assert abs(bearing(end, p1, v1)) > narrow.bearing_max


def test_the_smallest_bearing_is_the_first_grid_point_the_condition_admits(certs):
    """The grid point below the one returned fails the float inequality, the one returned passes it in Arb."""
    cert = certs["line"]
    b = terminal_bounds(TRACKED, cert.design, cert.region)
    law = cert.design.terminal
    phi = smallest_bearing(b, law)
    assert phi is not None and phi == pytest.approx(law.bearing_max)
    below = dataclasses.replace(law, bearing_max=phi - BEARING_STEP)
    assert not {c.condition: c.ok for c in law_conditions(b, below)}["terminal_invariant[bearing]"]


def test_without_a_speed_floor_no_bearing_is_admitted(certs):
    cert = certs["line"]
    b = dataclasses.replace(terminal_bounds(TRACKED, cert.design, cert.region), speed_floor_xy=0.0)
    assert smallest_bearing(b, cert.design.terminal) is None


#: The torpedo survey's kinematic half (examples/keep_moving_survey.toml): 1 m/s in 0.3 m/s of current per horizontal
#: axis, u_min 0.5 m/s, no backup, a rock 5 m off the path, plans limited to (0.5 m/s², 0.5 m/s², 1 rad/s²).
SURVEY_RATED = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_survey.toml")


@pytest.fixture(scope="module")
def rated():
    return verify.certify(SURVEY_RATED)


def test_under_rate_limited_plans_the_row_faces_and_the_bearing_face_hold_together(rated):
    """Both tiers, with a terminal set that has both the row faces (step 17c) and the bearing face (step 17b), and
    every condition of both steps holding in the certificate."""
    law = rated.design.terminal
    assert rated.tiers.safe and rated.tiers.tracking
    assert law is not None and law.has_rows and law.has_bearing
    names = {c.condition for c in rated.design.conditions}
    assert {"terminal_rate[u]", "terminal_rate[r]", "terminal_invariant[row_r]", "terminal_invariant[bearing]",
            "terminal_surge_floor"} <= names


def _first_admitted_by_a_scan(b, law) -> float | None:
    """The reference: the grid φ_f = i · BEARING_STEP scanned upward from i = 1, stopping where φ_f + asin(D_xy /
    d_lo) reaches π/2; the first point where δ P_min sin Φ_0 − L_c − A δ²/2 > 0 and Φ_0 + η − atan(that / x_max) <=
    φ_f − 1e-6 (the float inequality of ``terminal_invariant[bearing]``)."""
    arc = completion_arc(b, law)
    if arc is None:
        return None
    dev = math.asin(min(1.0, b.dev_xy / law.d_lo))
    loss = upper(lateral_chord(b, law, arc)) + b.accel_xy * b.dt ** 2 / 2
    eta = b.accel_xy * b.dt / b.speed_floor_xy
    for i in range(1, int(math.pi / 2 / BEARING_STEP)):
        phi = i * BEARING_STEP
        if phi + dev >= math.pi / 2:
            return None
        lateral = b.dt * b.speed_floor_xy * math.sin(phi + dev) - loss
        if lateral > 0 and phi + dev + eta - math.atan(lateral / upper(arc.x_max)) <= phi - 1e-6:
            return phi
    return None


def test_the_smallest_bearing_found_by_bisection_is_the_one_a_scan_upward_finds(rated):
    """Every gentlest law of the survey's coarse grid at each heading room (the laws ``bearing_row_sets`` searches a
    face for), and each with a tenth of its radial gain: the bisection returns the grid point an upward scan finds,
    None where the scan finds none, and both outcomes occur."""
    b = terminal_bounds(SURVEY_RATED, rated.design, rated.region)
    laws = [gentle for law in _grid(b, _grid_points(WIDTHS, LOWER_ENDS)) for fa in (1.0, 0.3, 0.05)
            for gentle in row_sets(b, [dataclasses.replace(law, alpha_max=law.alpha_max * fa)])]
    laws += [dataclasses.replace(law, gain_d=law.gain_d / 10) for law in laws]
    found = [(smallest_bearing(b, law), _first_admitted_by_a_scan(b, law)) for law in laws]
    assert len(found) > 100
    assert all(bisected == scanned for bisected, scanned in found)
    assert any(scanned is None for _, scanned in found) and any(scanned is not None for _, scanned in found)


@pytest.mark.slow
def test_the_bearing_sets_of_the_gentlest_laws_meet_their_conditions_nowhere(rated):
    """Counterexample (what ``bearing_row_sets`` replaces): the bearing face searched on each gentlest law with
    ``bearing_sets``' fractions of its gains and its turn taken from r_bar_bar breaks the row faces or the band's
    invariance in every set of the grid and its refinement, so the survey was refused; the composed sets certify it."""
    b = terminal_bounds(SURVEY_RATED, rated.design, rated.region)
    grid = _grid(b, sorted(set(_grid_points(WIDTHS, LOWER_ENDS)) | set(_grid_points(FINE_WIDTHS, FINE_LOWER_ENDS))))
    broken = bearing_sets(b, row_sets(b, grid))
    assert broken and not any(all(c.ok for c in law_conditions(b, law)) for law in broken)
    assert any(all(c.ok for c in law_conditions(b, law)) for law in bearing_row_sets(b, grid))


@settings(max_examples=100, deadline=None, derandomize=True)
@given(t=st.floats(0.0, 50.0), u=st.floats(0.0, 1.0), f=st.floats(-1.0, 1.0), a=st.floats(-1.0, 1.0),
       z=st.floats(-1.0, 1.0), off=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
       dx=st.floats(-1.0, 1.0), dy=st.floats(-1.0, 1.0), dpsi=st.floats(-1.0, 1.0))
def test_under_rate_limits_one_completion_keeps_the_jump_the_cone_and_the_faces(rated, t, u, f, a, z, off, dx, dy,
                                                                                dpsi):
    """Property (steps 17b and 17c together): a plan ending at x_N in X_f (bearing face included) with its last
    row within S of the law's row there; the completion from x_N moved by the replay's deviation changes the
    command by at most J, keeps the surge above u_min + kappa_u, and one period later along the exact arc ends in
    X_f again, inside the cone, with its own row within S of the law's row at its end."""
    law, dt = rated.design.terminal, SURVEY_RATED.controller.dt
    b = terminal_bounds(SURVEY_RATED, rated.design, rated.region)
    tr = SURVEY_RATED.trajectory
    p, v = np.asarray(tr.position(t), float).reshape(3), np.asarray(tr.velocity(t), float).reshape(3)
    d = law.d_lo + u * (law.d_hi - law.d_lo)
    x_n = _state(law, b, p, v, d, f * law.bearing_max, a * law.alpha_max, z * law.z_max, (0.0, 0.0), 0.0)
    x_n[2] -= math.copysign(b.dev_z, z)                     # x_N itself, without the replay's deviation
    last = law.command(x_n, p, v, dt) + np.asarray(off) * np.array([law.row_u, law.row_w, law.row_r])
    x_start = _state(law, b, p, v, d, f * law.bearing_max, a * law.alpha_max, z * law.z_max, (dx, dy), dpsi)
    row = law.command(x_start, p, v, dt)
    assert np.all(np.abs(row - last) <= np.asarray(b.jumps) + 1e-12), (row - last, b.jumps)
    assert row[0] >= b.surge_floor - 1e-12
    end = unicycle_step(x_start, row, dt)
    p1, v1 = (np.asarray(g(t + dt), float).reshape(3) for g in (tr.position, tr.velocity))
    assert law.contains(end, p1, v1), (line_of_sight(end, p1), bearing(end, p1, v1))
    assert min(law.row_slacks(end, p1, v1, row, dt).values()) >= 0.0


def test_the_bearing_face_lowers_only_the_surge_rows_change(rated):
    """With the face, V_r = P cos(phi) moves by at most P sin(Phi_0) per radian of line-of-sight turn: the surge
    row's change over the deviation and the arc is smaller than without the face; heave and yaw are unchanged."""
    law = rated.design.terminal
    b = terminal_bounds(SURVEY_RATED, rated.design, rated.region)
    arc = completion_arc(b, law)
    faced = row_changes(b, law, arc)
    bare = row_changes(b, dataclasses.replace(law, bearing_max=NO_BEARING), arc)
    for part in ("deviation", "arc"):
        with_face, without = getattr(faced, part), getattr(bare, part)
        assert upper(with_face[0]) < upper(without[0])
        assert upper(with_face[1]) == upper(without[1]) and upper(with_face[2]) == upper(without[2])


def test_on_the_published_bluerov2_at_the_owners_speed_no_cone_fits_the_row_faces():
    """Counterexample (docs/plant.md section 4, the pier): examples/bluerov2_published_brisk.toml (0.2 m/s in 0.1 m/s
    of current, omega_bar_xy about 0.15 m/s) with the cone behind the target and the row faces composed: no set of
    the grid or its refinement meets its own conditions, the surge or yaw row's rate failing in each, so a sector
    narrow enough for a pier 3 m off the path is out of reach there."""
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_published_brisk.toml")
    cert = verify.certify(sc)
    b = terminal_bounds(sc, cert.design, cert.region)
    grid = _grid(b, sorted(set(_grid_points(WIDTHS, LOWER_ENDS)) | set(_grid_points(FINE_WIDTHS, FINE_LOWER_ENDS))))
    laws = bearing_row_sets(b, grid)
    assert laws and b.speed_floor_xy > 0.0
    for law in laws:
        failed = {c.condition for c in law_conditions(b, law) if not c.ok}
        assert failed & {"terminal_rate[u]", "terminal_rate[r]"}, (law, failed)
