"""verify.backup.loiter: the loiter's safe set proved in Arb, its design, and its invariance against a current
that pushes at its bound in the worst direction (simulated here independently of the proof)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.model.loiter import Loiter
from tubekit.scenario import paper_scenario
from verify.backup import proof_for
from verify.backup.loiter import (LOITER_PROOF, certify_loiter, design_loiter, loiter_rate_sampled, loiter_surges,
                                  loiter_tick_change, shape_floor)

# The paper's vehicle and current: V = (0.4, 0.3, 0.5), ω̄ = (0.12, 0.1) m/s, tick 10 ms, hand-over 0.125 m.
LIMITS, WXY, WZ, TICK, HAND = (0.4, 0.3, 0.5), 0.12, 0.1, 0.01, (0.125, 0.08)


@pytest.fixture(scope="module")
def designed():
    return design_loiter(omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK, handover=HAND)


def test_the_design_certifies_a_loiter_that_never_slows(designed):
    assert designed.certified and proof_for("loiter") is LOITER_PROOF
    law, safe = designed.law, designed.safe_set
    assert isinstance(law, Loiter) and law.surge > WXY and law.within(*LIMITS)
    assert {c.condition for c in designed.conditions} == {
        "backup_inputs", "backup_surge", "backup_tick", "backup_ridge", "backup_level_set", "backup_heave",
        "backup_depth_hold", "backup_handover", "backup_handover_depth"}
    # the ridge (pointing away) needs β (k / L) > u_l + ω̄: β >= L (u_l + ω̄) / k, L = π − φ_s / 2
    floor = (math.pi - 0.25) * (law.surge + WXY) / law.yaw_rate
    assert shape_floor(law, WXY) == pytest.approx(floor) and safe.shape >= floor
    assert designed.rate_bound < 0.0 and designed.rate_sampled < 0.0
    assert designed.handover == HAND and safe.handover_radius >= HAND[0]


def test_a_shape_below_the_ridges_floor_is_refuted_by_the_level_set(designed):
    """Pointing away from the anchor, V = d + β grows at u_l + ω̄ − β k / L > 0 when β < the floor."""
    law = designed.law
    beta = 0.9 * shape_floor(law, WXY)
    safe = SafeSet(level=beta + 1.5, shape=beta, depth=designed.safe_set.depth)
    cert = certify_loiter(law, safe, omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK, handover=HAND)
    assert not cert.certified and "backup_level_set" in {c.condition for c in cert.failures}
    length = math.pi - 0.5 * law.bend
    at_ridge = law.surge + WXY * math.sqrt(1 + (beta / length / 1.5) ** 2) - beta * law.yaw_rate / length
    assert loiter_rate_sampled(law, safe, WXY) >= at_ridge - 1e-12 > 0.0


def test_a_current_faster_than_the_surge_is_refused_by_name(designed):
    cert = certify_loiter(designed.law, designed.safe_set, omega_xy=0.25, omega_z=WZ, limits=LIMITS, tick=TICK,
                          handover=HAND)
    assert "backup_surge" in {c.condition for c in cert.failures}


def test_a_station_keeping_law_is_refused_by_the_loiters_proof(designed):
    sk = StationKeeping(0.2, 0.5, 0.05, 0.3, 0.04)
    with pytest.raises(ConfigError, match="backup.kind"):
        certify_loiter(sk, designed.safe_set, omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK)


def test_the_tick_change_charges_the_yaw_flip_at_the_ridge(designed):
    du, dw, dr = loiter_tick_change(designed.law, designed.safe_set, omega_xy=WXY, omega_z=WZ, limits=LIMITS,
                                    loop_error=(0.0, 0.0, 0.0), tick=TICK)
    assert du == 0.0 and dr == 2 * designed.law.yaw_rate and 0.0 < dw <= 2 * designed.law.heave


def test_a_scenario_asks_for_the_loiter_by_name_and_the_certificate_proves_it():
    sc = paper_scenario().with_changes(**{"controller.backup": "loiter"})
    assert sc.to_dict()["controller"]["backup"] == "loiter" and "backup" not in paper_scenario().to_dict()["controller"]
    cert = verify.certify(sc)
    assert cert.tiers.safe and isinstance(cert.backup.law, Loiter)
    assert cert.design_key != verify.certify(paper_scenario()).design_key
    assert cert.summary(verbose=True).count("backup (loiter): certified") == 1
    with pytest.raises(ConfigError, match=r"controller\.backup"):
        paper_scenario().with_changes(**{"controller.backup": "hover"})


# ------------------------------------------------------------------ invariance against the worst current

def _value(law: Loiter, safe: SafeSet, p: np.ndarray, psi: np.ndarray | float) -> np.ndarray:
    """V = d + β a(φ) at positions ``p`` (..., 2) and headings ``psi``, written here from the module doc."""
    p = np.asarray(p, dtype=float)
    d = np.hypot(p[..., 0], p[..., 1])
    phi = np.angle(np.exp(1j * (psi - np.arctan2(-p[..., 1], -p[..., 0]))))
    x, s = np.abs(phi), law.bend
    length = math.pi - s / 2
    return d + safe.shape * np.where(x <= s, x * x / (2 * s * length), (x - s / 2) / length)


#: 36 directions of the current (unit vectors).
DIRECTIONS = np.stack([np.cos(np.linspace(0, 2 * math.pi, 36, endpoint=False)),
                       np.sin(np.linspace(0, 2 * math.pi, 36, endpoint=False))], axis=1)


def _worst_current(law, safe, p, psi, r, bound):
    """The current of norm ``bound`` (of 36 directions) along which V grows fastest at this instant."""
    eps = 1e-6
    moved = p[None, :] + eps * (law.surge * np.array([math.cos(psi), math.sin(psi)])[None, :] + bound * DIRECTIONS)
    return bound * DIRECTIONS[int(np.argmax(_value(law, safe, moved, psi + eps * r)))]


@settings(derandomize=True, max_examples=8, deadline=None)
@given(bearing=st.floats(-math.pi, math.pi), phi=st.floats(-math.pi, math.pi), inside=st.floats(0.9, 1.0))
def test_the_loiter_never_leaves_its_set_against_the_worst_current(designed, bearing, phi, inside):
    """Property: from a start in S (on a level set at 90-100 % of c, any heading), the sampled-data loop with the
    law held over each 10 ms tick, pushed at every substep by a current of norm ω̄_xy in the direction that grows
    V fastest, keeps V <= c for 30 s, and its surge command is u_l at every tick."""
    law, safe = designed.law, designed.safe_set
    assert _largest_value(law, safe, bearing, phi, inside, 3000) <= safe.level


def _largest_value(law: Loiter, safe: SafeSet, bearing: float, phi: float, inside: float, ticks: int) -> float:
    """The largest V over ``ticks`` 10 ms ticks (4 Euler substeps each, the worst current at every one) from the
    start on the level set ``inside`` c at ``bearing`` from the anchor with heading angle ``phi``."""
    length = math.pi - law.bend / 2
    x = abs(phi)
    shape = x * x / (2 * law.bend * length) if x <= law.bend else (x - law.bend / 2) / length
    d = max(0.05, inside * safe.level - safe.shape * shape)
    p = d * np.array([math.cos(bearing), math.sin(bearing)])
    psi = math.atan2(-p[1], -p[0]) + phi
    worst = -math.inf
    for _ in range(ticks):
        u, _, r = law.command((p[0], p[1], 0.0, psi), (0.0, 0.0, 0.0))
        assert u == law.surge
        for _ in range(4):
            w = _worst_current(law, safe, p, psi, r, WXY)
            p = p + 0.0025 * (u * np.array([math.cos(psi), math.sin(psi)]) + w)
            psi += 0.0025 * r
            worst = max(worst, float(_value(law, safe, p, psi)))
    return worst


def test_the_same_current_pushes_a_refuted_shape_out_of_its_set(designed):
    """The simulation has teeth: with β at half the ridge's floor (refuted by the proof), the vehicle pointing away
    from the anchor on the level set leaves it within a second."""
    law = designed.law
    beta = 0.5 * shape_floor(law, WXY)
    safe = SafeSet(level=beta + 1.5, shape=beta, depth=designed.safe_set.depth)
    assert _largest_value(law, safe, 0.3, math.pi, 1.0, 100) > safe.level


@pytest.mark.parametrize("u_max, floor, expected", [
    (1.0, 0.2, (0.2, 0.3, 0.4, 0.5, 0.625, 0.75, 0.875, 1.0)),    # the floor is a grid point: once
    (2.0, 0.5, (0.5, 0.6, 0.8, 1.0, 1.25, 1.5, 1.75, 2.0)),       # the floor first, then 0.3 u_max and up
    (0.4, None, (0.08, 0.12, 0.16, 0.2, 0.25, 0.3, 0.35, 0.4)),   # no floor: the fractions of u_max
])
def test_the_loiters_surges_start_at_the_plans_floor_and_never_go_below_it(u_max, floor, expected):
    assert loiter_surges(u_max, floor) == pytest.approx(expected)


def test_a_surge_floor_gives_the_slowest_loiter_it_allows_and_its_smaller_set():
    """examples/keep_moving.toml's loiter (u 1 m/s, r 0.5 rad/s, the current 0.1 m/s): at the floor u_min = 0.2 m/s
    the loiter turns on a 0.4 m radius instead of 1 m at u_max / 2, and its certified set is smaller."""
    limits, hand = (1.0, 0.3, 0.5), (1.0, 0.04)
    slow = design_loiter(omega_xy=0.1, omega_z=0.05, limits=limits, tick=TICK, handover=hand, surge_floor=0.2)
    half = design_loiter(omega_xy=0.1, omega_z=0.05, limits=limits, tick=TICK, handover=hand, surge_floor=0.5)
    assert slow.certified and half.certified
    assert slow.law.surge == pytest.approx(0.2) and half.law.surge >= 0.5
    assert slow.safe_set.radius < half.safe_set.radius
