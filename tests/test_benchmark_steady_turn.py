"""benchmarks/steady_turn.py: the steady turn of a fin-steered hull at full rudder, over its box's corners."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from tubekit.model.vehicle_sets import REMUS100
from tubekit.plant.dynamic import body_acceleration

from .scripts import load_script

TURN = load_script("benchmarks/steady_turn.py", "steady_turn_benchmark")


@st.composite
def remus_points(draw):
    """A point hull of the bundled REMUS 100 box: each steady field drawn inside its interval."""
    point = {name: draw(st.floats(*REMUS100.interval(name))) for name in TURN.steady_fields(REMUS100)}
    return REMUS100.with_point(point)


@settings(max_examples=15, deadline=None, derandomize=True)
@given(params=remus_points(), u=st.floats(0.3, 2.0), rudder=st.floats(0.2, 1.0))
def test_the_turn_is_an_equilibrium_of_the_hull_and_its_radius_does_not_depend_on_the_speed(params, u, rudder):
    """Property: at the returned (v, r) the hull's accelerations under the rudder's moment vanish (read from
    body_acceleration, M^-1 (tau - n), not from the rows the search solved), and at twice the surge the turn rate
    doubles (no linear damping: every term scales as u^2)."""
    turn = TURN.steady_turn(params, u, rudder)
    assert turn is not None and turn.r > 0.0
    _, v_dot, _, r_dot = body_acceleration(params, (u, turn.v, 0.0, turn.r), (0.0, 0.0, turn.moment))
    assert abs(v_dot) < 1e-9 and abs(r_dot) < 1e-9
    assert TURN.steady_turn(params, 2.0 * u, rudder).r == pytest.approx(2.0 * turn.r, rel=1e-7)


def test_a_hull_with_linear_damping_only_turns_as_its_two_by_two_system_says():
    """With the quadratic damping removed and linear damping added, both rows are linear in (v, r): the turn is the
    2 x 2 solve of M (v, r) = (0, N) written out by hand from the rows' terms."""
    p = dataclasses.replace(REMUS100.nominal, Y_vv=0.0, Y_rr=0.0, N_vv=0.0, N_rr=0.0, Y_v=-30.0, N_r=-8.0)
    u = 0.8
    m11, m22, _, _, m24, _ = p.mass_entries
    # n2 = m11 u r - Y_v v - Y_uv u v - Y_ur u r;  n4 = (m22 v + m24 r) u - m11 u v - N_r r - N_uv u v - N_ur u r
    rows = np.array([[-p.Y_v - p.Y_uv * u, m11 * u - p.Y_ur_lift * u],
                     [m22 * u - m11 * u - p.N_uv_lift * u, m24 * u - p.N_r - p.N_ur_lift * u]])
    moment = abs(p.N_uudr) * u * u * p.fin_max
    v, r = np.linalg.solve(rows, [0.0, moment])
    turn = TURN.steady_turn(p, u)
    assert r > 0.0 and turn.r == pytest.approx(r, rel=1e-9) and turn.v == pytest.approx(v, rel=1e-9)


def test_the_slowest_corner_turns_slower_than_the_midpoint_and_a_weaker_rudder_slower_still():
    """Over the bundled box at 0.57 m/s: every corner turns, the slowest below the midpoint hull, the fastest above;
    half the rudder turns the slowest corner more slowly."""
    corners = TURN.corner_turns(REMUS100, 0.57)
    rates = [t.r for _, t in corners]
    mid = TURN.steady_turn(REMUS100.nominal, 0.57).r
    assert len(corners) == 2 ** 8 and min(rates) < mid < max(rates)
    slow, _ = min(corners, key=lambda c: c[1].r)
    assert TURN.steady_turn(REMUS100.with_point(slow), 0.57, 0.5).r < min(rates)


@pytest.mark.parametrize("argv, message", [
    (["--speed", "0"], "--speed: expected positive"),
    (["--rudder", "1.5"], "--rudder: expected a fraction"),
    (["--vehicle", "bluerov2_heavy"], "--vehicle: expected a vehicle with fins"),
])
def test_a_bad_argument_is_refused_before_any_turn(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        TURN.main(argv)
    assert exit_.value.code == 2 and message in capsys.readouterr().err
