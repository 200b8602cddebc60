"""tubekit.model.hold: the hold backup law (surge and sway toward the anchor, the nose turned toward the pull)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BACKUP_LAWS, BackupLaw, StationKeeping, backup_law_from_dict
from tubekit.model.hold import Hold, hold_input
from tubekit.model.loiter import Loiter

LAW = Hold(gain=0.2, speed=0.15, heave=0.1, heave_band=0.5, ramp=4.0, turn=0.05, turn_band=0.2, release=1e-3)
ANCHOR = (1.0, -2.0, -1.0)


def test_the_law_is_registered_a_backup_law_and_the_only_one_with_sway():
    assert BACKUP_LAWS["hold"] is Hold and isinstance(LAW, BackupLaw)
    assert Hold.lateral and not StationKeeping.lateral and not Loiter.lateral
    assert LAW.bounds == (0.15, 0.1, 0.05) and LAW.sway_bound == 0.15 and LAW.min_surge == -0.15
    assert LAW.blends and LAW.sway_release == 1e-3
    assert LAW.within(0.15, 0.1, 0.05) and not LAW.within(0.15, 0.1, 0.04)
    assert backup_law_from_dict(LAW.to_dict()) == LAW and LAW.to_dict()["kind"] == "hold"


@pytest.mark.parametrize("state, want", [
    # 0.5 m east of the anchor, heading east: pulled back west at k d = 0.1 m/s, all surge (astern), no sway
    ((1.5, -2.0, -1.0, 0.0), (-0.1, 0.0, 0.0, 0.0)),
    # heading north: the pull west is to the left, all sway (+), and the nose turns left (r = r_t v / v_t > 0)
    ((1.5, -2.0, -1.0, math.pi / 2), (0.0, 0.0, 0.025, 0.1)),
    # 2 m south: k d = 0.4 > s, the pull is saturated at s = 0.15 m/s north; heading east: sway left
    ((1.0, -4.0, -1.0, 0.0), (0.0, 0.0, 0.0375, 0.15)),
    # heading south, the pull north: the sway command is 0 but the surge astern, the nose does not turn (the
    # unstable end: any sway moves it off)
    ((1.0, -4.0, -1.0, -math.pi / 2), (-0.15, 0.0, 0.0, 0.0)),
    # 0.25 m too deep (z below z*): heave up at w_b 0.25 / 0.5
    ((1.0, -2.0, -1.25, 0.3), (0.0, 0.05, 0.0, 0.0)),
])
def test_the_pull_points_at_the_anchor_in_the_body_frame(state, want):
    got = hold_input(LAW, state, ANCHOR)
    assert got == pytest.approx(want, abs=1e-12)
    assert LAW.command(state, ANCHOR) == pytest.approx(want[:3], abs=1e-12)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(x=st.floats(-20, 20), y=st.floats(-20, 20), z=st.floats(-5, 5), psi=st.floats(-7, 7),
       elapsed=st.floats(0.0, 10.0), u_h=st.floats(-0.15, 0.15), w_h=st.floats(-0.1, 0.1),
       r_h=st.floats(-0.05, 0.05))
def test_the_command_is_in_v_and_blends_from_the_hand_over(x, y, z, psi, elapsed, u_h, w_h, r_h):
    """Property: every command lies in V = (s, w_b, r_t) and |v| <= s; at the hand-over (elapsed 0) it is the
    command applied then with no sway; after the ramp it is the law's, and the pull's world-frame speed is
    min(k d, s), toward the anchor."""
    state, start = (x, y, z, psi), (u_h, w_h, r_h)
    u, w, r, v = hold_input(LAW, state, ANCHOR, elapsed, start)
    assert abs(u) <= 0.15 and abs(w) <= 0.1 and abs(r) <= 0.05 and abs(v) <= 0.15 + 1e-15
    assert hold_input(LAW, state, ANCHOR, 0.0, start) == (u_h, w_h, r_h, 0.0)
    u, _, _, v = hold_input(LAW, state, ANCHOR, 4.0, start)
    world = (u * math.cos(psi) - v * math.sin(psi), u * math.sin(psi) + v * math.cos(psi))
    d = (x - ANCHOR[0], y - ANCHOR[1])
    dist = math.hypot(*d)
    assert math.hypot(*world) == pytest.approx(min(0.2 * dist, 0.15), abs=1e-12)
    if dist > 1e-6:
        assert world[0] * d[0] + world[1] * d[1] == pytest.approx(-math.hypot(*world) * dist, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("kwargs, field", [
    ({"gain": 0.0}, "backup.gain"), ({"speed": -0.1}, "backup.speed"), ({"ramp": 0.0}, "backup.ramp"),
    ({"heave_band": math.nan}, "backup.heave_band"), ({"turn": -1.0}, "backup.turn"),
    ({"turn_band": 0.0}, "backup.turn_band"), ({"release": 0.0}, "backup.release"),
])
def test_bad_gains_are_refused(kwargs, field):
    base = dict(gain=0.2, speed=0.15, heave=0.1, heave_band=0.5, ramp=4.0)
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        Hold(**{**base, **kwargs})


def test_a_negative_time_since_the_hand_over_is_refused():
    with pytest.raises(ConfigError, match="elapsed"):
        hold_input(LAW, (0.0, 0.0, 0.0, 0.0), ANCHOR, -1.0)
