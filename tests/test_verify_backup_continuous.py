"""verify.backup.continuous: the continuous yaw law's level-set proof (enclosures, the unstable point, bad χ_u)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping
from verify.backup import certify_backup
from verify.backup.continuous import (_rate_upper, cone_angle, continuous_rate_bound, shape_enclosure,
                                      unstable_condition, yaw_shape_enclosure)
from verify.kernel.intervals import lower, upper

LIMITS = (0.4, 0.3, 0.5)
TICK = 0.01
LAW = StationKeeping(surge=0.4, yaw_rate=0.5, yaw_band=math.pi / 4, heave=0.3, heave_band=0.5,
                     yaw_law="continuous", unstable=0.6)
SAFE = SafeSet(level=1.3, shape=0.55, depth=0.6)


def _rho(x: float, cut: float, band: float) -> float:
    """ρ written here from the module doc (lifted angle x ∈ [0, π))."""
    x = x % math.pi
    if x <= cut:
        return min(1.0, x / band, (cut - x) / band)
    return -min(1.0, (x - cut) / band, (math.pi - x) / band)


def _a(x: float, cut: float) -> float:
    x = x % math.pi
    wave = min(1.0, x / (0.75 * cut)) if x <= cut else (math.pi - x) / (math.pi - cut)  # plateau from 0.75 χ_u
    return 0.5 * (1.0 - math.cos(math.pi * wave))


@given(st.floats(-math.pi, 2 * math.pi - 0.2), st.floats(0.0, 0.2), st.floats(0.05, 1.5), st.floats(0.02, 1.0))
def test_the_enclosures_contain_the_sampled_profiles(lo, width, cut, band):
    """Property: for any interval of the lifted angle, the Arb enclosures of ρ, a and a' contain the values (and a
    central difference of a) at 9 points of it."""
    law = StationKeeping(0.4, 0.5, band, 0.3, 0.5, yaw_law="continuous", unstable=cut)
    rho = yaw_shape_enclosure(law, lo, lo + width)
    a, slope = shape_enclosure(law, lo, lo + width)
    for x in np.linspace(lo, lo + width, 9):
        assert lower(rho) <= _rho(x, cut, band) <= upper(rho)
        assert lower(a) - 1e-12 <= _a(x, cut) <= upper(a) + 1e-12
        h = 1e-6
        if lo + h <= x <= lo + width - h:
            diff = (_a(x + h, cut) - _a(x - h, cut)) / (2 * h)
            assert lower(slope) - 1e-4 <= diff <= upper(slope) + 1e-4


def test_the_profiles_by_hand():
    # a = 1 on the plateau [0.45, 0.6] and 0 at 0 and π, a(0.3) = (1 − cos(2π/3))/2 = 0.75;
    # ρ(χ_u/2) = min(1, 0.3/(π/4)) = 0.38197; ρ(π/2) = −1 (abeam: saturated)
    a, _ = shape_enclosure(LAW, 0.6, 0.6)
    assert lower(a) <= 1.0 <= upper(a) and upper(a) - lower(a) < 1e-12
    a, slope = shape_enclosure(LAW, 0.46, 0.59)
    assert lower(a) <= 1.0 <= upper(a) and upper(a) - lower(a) < 1e-12 and lower(slope) == upper(slope) == 0.0
    a, _ = shape_enclosure(LAW, 0.3, 0.3)
    assert lower(a) == pytest.approx(0.75, abs=1e-12)
    rho = yaw_shape_enclosure(LAW, 0.3, 0.3)
    assert lower(rho) == pytest.approx(0.3819718634, abs=1e-10) and upper(rho) - lower(rho) < 1e-9
    rho = yaw_shape_enclosure(LAW, math.pi / 2 - 0.01, math.pi / 2 + 0.01)
    assert lower(rho) == upper(rho) == -1.0
    # both sides of the ridge: −π/2 − 0.01 and π/2 − 0.01 are the same axis; ρ = −1 on both
    assert upper(yaw_shape_enclosure(LAW, -math.pi / 2 - 0.01, -math.pi / 2 + 0.01)) == -1.0


def test_at_the_unstable_point_the_rate_is_the_radial_speed():
    """At χ_u, a' = 0 and ρ = 0, so V̇ = ḋ = −u_b cos² χ_u + ω̄_xy: by hand cos 0.6 = 0.8253356, cos² = 0.6811788,
    −0.4 · 0.6811788 + 0.12 = −0.1524715 m/s (< 0: χ_u lies inside the cone χ_c = acos √0.3 = 0.9911566)."""
    bound = _rate_upper(LAW, SAFE, 0.12, 0.0, 0.6, 0.6, 0.0)
    assert bound == pytest.approx(-0.1524715, abs=1e-6)
    assert cone_angle(0.4, 0.12) == pytest.approx(0.9911566, abs=1e-6)
    cond = unstable_condition(LAW, 0.12)
    assert cond.ok and cond.rhs == pytest.approx(0.4 * 0.6811788, abs=1e-6)


def test_the_paper_currents_certify_the_continuous_law_and_the_bound_is_not_vacuous():
    cert = certify_backup(LAW, SAFE, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.125, 0.08))
    assert cert.certified, [c.condition for c in cert.failures]
    assert cert.rate_sampled <= cert.rate_bound < 0.0  # the sampled rate (no hold) lies below the bound
    # a level set with too small a shape: abeam β |a'| k cannot beat the current, the proof refuses it
    refused, _ = continuous_rate_bound(LAW, SafeSet(1.3, 0.1, 0.6), 0.12, 0.01, 512)
    assert refused > 0.0


@pytest.mark.parametrize("unstable", [0.0, -0.1, math.pi / 2, 2.0, math.nan])
def test_a_bad_unstable_angle_is_refused_by_the_law(unstable):
    with pytest.raises(ConfigError, match=r"backup\.unstable"):
        StationKeeping(0.4, 0.5, 0.5, 0.3, 0.5, yaw_law="continuous", unstable=unstable)


def test_the_ridge_law_takes_no_unstable_angle_and_the_yaw_law_is_named():
    with pytest.raises(ConfigError, match=r"backup\.unstable"):
        StationKeeping(0.4, 0.5, 0.5, 0.3, 0.5, unstable=0.5)
    with pytest.raises(ConfigError, match=r"backup\.yaw_law"):
        StationKeeping(0.4, 0.5, 0.5, 0.3, 0.5, yaw_law="spiral", unstable=0.5)


@pytest.mark.parametrize("unstable", [0.9912, 1.2, 1.5])
def test_an_unstable_angle_outside_the_cone_fails_its_condition(unstable):
    """χ_u >= χ_c = 0.9911566 (u_b = 0.4, ω̄_xy = 0.12): ḋ >= 0 at χ_u, so ``backup_unstable`` fails."""
    law = StationKeeping(0.4, 0.5, math.pi / 4, 0.3, 0.5, yaw_law="continuous", unstable=unstable)
    cert = certify_backup(law, SAFE, omega_xy=0.12, omega_z=0.1, limits=LIMITS, tick=TICK, handover=(0.125, 0.08),
                          max_boxes=256)
    assert "backup_unstable" in {c.condition for c in cert.failures}


@given(st.floats(0.0, math.pi), st.floats(-1.0, 1.0), st.floats(0.0, 2 * math.pi), st.floats(-1.0, 1.0),
       st.floats(0.0, 2 * math.pi))
def test_the_level_set_bound_exceeds_the_plant_s_rate(x, held, bearing, err, current):
    """Property: at a state on V = c (axis angle x, any bearing), with the command of a held heading within Δ = 0.01
    and any current ‖ω‖ <= ω̄_xy and yaw error |ε_r| <= 0.05, the rate of V along the kinematic plant (a central
    difference of V computed here) is below the Arb bound of a small interval of x around it."""
    beta, c, wxy, delta = SAFE.shape, SAFE.level, 0.12, 0.01
    d = c - beta * _a(x, LAW.unstable)
    pos = d * np.array([math.cos(bearing), math.sin(bearing)])
    psi = bearing + math.pi + x  # φ = ψ − θ − π = x
    u, _, r = LAW(np.array([pos[0], pos[1], 0.0, psi + held * delta]), np.zeros(3))
    w = wxy * np.array([math.cos(current), math.sin(current)])

    def level(t: float) -> float:
        p = pos + t * (u * np.array([math.cos(psi), math.sin(psi)]) + w)
        return math.hypot(*p) + beta * _a(psi + t * (r + 0.05 * err) - math.atan2(p[1], p[0]) - math.pi, LAW.unstable)

    h = 1e-7
    rate = (level(h) - level(-h)) / (2 * h)
    lo, hi = max(0.0, x - 1e-3), min(math.pi, x + 1e-3)
    assert rate <= _rate_upper(LAW, SAFE, wxy, delta, lo, hi, 0.05) + 1e-5


@settings(max_examples=25, deadline=None)
@given(level=st.floats(1.0, 12.0), omega=st.floats(0.0, 0.15), yaw_err=st.floats(0.0, 0.1))
def test_the_sampled_rate_is_the_formula_for_every_shape(level, omega, yaw_err):
    """Property: continuous_rate_sampled_shapes gives, for each β, the largest sampled
    −u_b cos²x + ω̄ √(1 + (g/d)²) + g (−k ρ(x) + u_b cos x sin x / d) + |g| E_r, d = c − β a(x), g = β a'(x), here
    from the model's own a (``axis_shape``, a' by central differences) and ρ (``yaw_shape``), one β at a time."""
    from tubekit.model.backup import axis_shape, yaw_shape
    from verify.backup.continuous import continuous_rate_sampled_shapes
    law = StationKeeping(0.2, 0.2, 0.3, 0.15, 0.1, 2.0, 2.0, 5.0, "continuous", 0.6)
    shapes = np.round(np.arange(0.05, level - 0.1, 0.35), 6)
    xs = np.linspace(0.0, math.pi, 1441)
    a = np.array([axis_shape(law, float(x)) for x in xs])
    h = 1e-7
    slope = np.array([(axis_shape(law, float(x) + h) - axis_shape(law, float(x) - h)) / (2 * h) for x in xs])
    rho = np.array([yaw_shape(law, float(x)) for x in xs])
    want = []
    for beta in shapes:
        d, g = level - beta * a, beta * slope
        rate = (-0.2 * np.cos(xs) ** 2 + omega * np.sqrt(1 + (g / d) ** 2)
                + g * (-0.2 * rho + 0.2 * np.cos(xs) * np.sin(xs) / d) + np.abs(g) * yaw_err)
        want.append(rate.max())
    got = continuous_rate_sampled_shapes(law, level, shapes, omega, yaw_err=yaw_err)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-5)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(level=st.floats(1.0, 12.0), omega=st.floats(0.0, 0.15), yaw_err=st.floats(0.0, 0.1),
       step=st.sampled_from([0.05, 0.1, 0.35]))
def test_the_pruned_best_shape_is_the_argmin_of_every_shape(level, omega, yaw_err, step):
    """Property: continuous_best_shape returns the first index of the smallest value of
    continuous_rate_sampled_shapes and that value, bit for bit (the pruning only skips shapes that cannot attain
    it)."""
    from verify.backup.continuous import continuous_best_shape, continuous_rate_sampled_shapes
    law = StationKeeping(0.2, 0.2, 0.3, 0.15, 0.1, 2.0, 2.0, 5.0, "continuous", 0.6)
    shapes = np.round(np.arange(0.05, level - 0.1, step), 6)
    every = continuous_rate_sampled_shapes(law, level, shapes, omega, yaw_err=yaw_err)
    i, value = continuous_best_shape(law, level, shapes, omega, yaw_err=yaw_err)
    assert i == int(np.argmin(every)) and value == float(every.min())
