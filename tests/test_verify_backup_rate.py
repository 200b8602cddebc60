"""verify.backup.rate: the backup command's rate bound against finite differences along simulated trajectories."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping, axis_angle, line_of_sight_angle, station_keeping_input
from verify.backup.rate import backup_command_rate, backup_tick_change

LIMITS = (0.4, 0.3, 0.5)
SAFE = SafeSet(level=0.75, shape=0.4, depth=0.4)
SMOOTH = StationKeeping(surge=0.2, yaw_rate=0.5, yaw_band=0.5, heave=0.3, heave_band=0.1,
                        surge_fade=0.4, yaw_fade=0.2, ramp=2.0)
ARGS = dict(omega_xy=0.12, omega_z=0.1, limits=LIMITS, loop_error=(0.0, 0.0, 0.05))


def test_the_bound_by_hand():
    # the ramp blends the hand-over's command (anywhere in V): S = max(0.2, 0.4) + 0.12 = 0.52,
    # S_z = 0.3 + 0.1 = 0.4, Y = 0.5 + 0.05 = 0.55, and the blend adds V / t_r = (0.2, 0.15, 0.25) (module doc):
    # surge 0.2 (max(0.52/0.4, 1/2) + 0.55 + 0.52/0.4) + 0.2 = 0.2 * 3.15 + 0.2
    # heave 0.3 (0.4/0.1 + 1/2) + 0.15 = 0.3 * 4.5 + 0.15
    # yaw   0.5 (max(0.52/0.2, 1/2) + (0.55 + 0.52/0.2)/0.5) + 0.25 = 0.5 * (2.6 + 6.3) + 0.25
    surge, heave, yaw = backup_command_rate(SMOOTH, SAFE, **ARGS)
    assert surge == pytest.approx(0.83, rel=1e-12) and surge >= 0.83
    assert heave == pytest.approx(1.5, rel=1e-12) and heave >= 1.5
    assert yaw == pytest.approx(4.7, rel=1e-12) and yaw >= 4.7


@pytest.mark.parametrize("changes, finite", [
    ({"surge_fade": 0.0, "yaw_fade": 0.0, "ramp": 0.0}, (False, False, False)),  # the unfaded law
    ({"ramp": 0.0}, (False, False, False)),          # no ramp: the command jumps at the hand-over
    ({"surge_fade": 0.0}, (False, True, True)),      # the line of sight's 1/d is not cancelled in surge
    ({"yaw_fade": 0.0}, (True, True, False)),
])
def test_without_fade_or_ramp_the_rate_is_infinite(changes, finite):
    law = StationKeeping(**{**SMOOTH.__dict__, **changes})
    rates = backup_command_rate(law, SAFE, **ARGS)
    assert tuple(math.isfinite(r) for r in rates) == finite


def _run(rng: np.random.Generator, seconds: float = 3.0, dt: float = 1e-3, tick: float = 0.01, law=SMOOTH):
    """A random trajectory of the plant inside the speed bounds: the law held per tick (blending a random
    hand-over command in V), body velocities off by up to E, random piecewise-constant currents at up to ω̄;
    returns the law's command at every step, the held commands at every tick and whether the axis angle
    wrapped in each step."""
    d, bearing = rng.uniform(0.0, 0.7), rng.uniform(-math.pi, math.pi)
    start = tuple(float(v) for v in rng.uniform(-1.0, 1.0, 3) * np.array(LIMITS))
    x = np.array([d * math.cos(bearing), d * math.sin(bearing), rng.uniform(-0.3, 0.3), rng.uniform(-4, 4)])
    per_tick = int(round(tick / dt))
    cmds, held, wraps = [], [], []
    chi_prev = None
    for i in range(int(round(seconds / dt))):
        s = i * dt
        cmd = station_keeping_input(law, tuple(x), (0.0, 0.0, 0.0), s, start)
        if i % per_tick == 0:
            v = cmd
            held.append(cmd)
            if i % (20 * per_tick) == 0:  # a new current and loop error every 0.2 s
                a, mag = rng.uniform(0, 2 * math.pi), 0.12 * math.sqrt(rng.uniform(0, 1))
                wxy = mag * np.array([math.cos(a), math.sin(a)])
                wz, er = rng.uniform(-0.1, 0.1), rng.uniform(-0.05, 0.05)
        chi = axis_angle(line_of_sight_angle(x[0], x[1], x[3], 0.0, 0.0))
        wraps.append(chi_prev is not None and abs(chi - chi_prev) > 1.0)
        chi_prev = chi
        cmds.append(cmd)
        x = x + dt * np.array([v[0] * math.cos(x[3]) + wxy[0], v[0] * math.sin(x[3]) + wxy[1], v[1] + wz, v[2] + er])
    return np.array(cmds), np.array(held), np.array(wraps)


def test_finite_differences_never_exceed_the_bound():
    """Along 30 random trajectories (3 s each, starting anywhere within 0.7 m of the anchor, the ramp included)
    every channel's finite difference stays below its bound; yaw away from the ridge's wrap."""
    rate = np.array(backup_command_rate(SMOOTH, SAFE, **ARGS))
    rng = np.random.default_rng(7)
    worst = np.zeros(3)
    for _ in range(30):
        cmds, _, wraps = _run(rng)
        diff = np.abs(np.diff(cmds, axis=0)) / 1e-3
        diff[wraps[1:], 2] = 0.0  # a wrap of χ: the yaw command's jump, counted by backup_tick_change
        worst = np.maximum(worst, diff.max(axis=0))
    assert np.all(worst <= rate * (1 + 1e-6)), (worst, rate)
    assert np.all(worst > 0.05 * rate)  # the bound is not vacuous: within a factor 20 of what is seen


def test_the_held_command_changes_per_tick_within_the_tick_bound():
    jump = np.array(backup_tick_change(SMOOTH, SAFE, tick=0.01, **ARGS))
    rng = np.random.default_rng(11)
    for _ in range(10):
        _, held, _ = _run(rng)
        assert np.all(np.abs(np.diff(held, axis=0)) <= jump * (1 + 1e-9) + 1e-15)


def test_crossing_the_ridge_flips_the_yaw_command():
    """Abeam at d = 0.1 m the line of sight turns at up to ω̄_xy/d = 1.2 rad/s, faster than the faded yaw rate
    k d/d_1 = 0.25 rad/s: within one tick χ crosses π/2 and the command jumps by 2 k d/d_1 = 0.5 rad/s,
    far more than the rate bound × h. backup_tick_change counts it."""
    before = station_keeping_input(SMOOTH, (0.1, 0.0, 0.0, math.pi / 2 + 1e-4), (0.0, 0.0, 0.0), 10.0)
    after = station_keeping_input(SMOOTH, (0.1, 0.0, 0.0, math.pi / 2 - 1e-4), (0.0, 0.0, 0.0), 10.0)
    jump = abs(after[2] - before[2])
    assert jump == pytest.approx(0.5, rel=1e-6)
    assert jump > backup_command_rate(SMOOTH, SAFE, **ARGS)[2] * 0.01
    assert jump <= backup_tick_change(SMOOTH, SAFE, tick=0.01, **ARGS)[2]


@pytest.mark.parametrize("kwargs, match", [
    ({"omega_xy": -0.1}, "omega_xy"),
    ({"loop_error": (0.0, 0.0, -1.0)}, r"loop_error\[2\]"),
    ({"limits": (0.4, 0.0, 0.5)}, r"limits\[1\]"),
    ({"limits": (0.4, 0.3)}, "limits"),
])
def test_bad_arguments_are_refused(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        backup_command_rate(SMOOTH, SAFE, **{**ARGS, **kwargs})


def test_a_bad_tick_is_refused():
    with pytest.raises(ConfigError, match="tick"):
        backup_tick_change(SMOOTH, SAFE, tick=0.0, **ARGS)


# ---- the continuous yaw law (issue 22): no jump abeam ------------------------------------------------

CONTINUOUS = StationKeeping(**{**SMOOTH.__dict__, "yaw_law": "continuous", "unstable": 0.4})


def test_the_continuous_law_has_the_same_rate_and_a_tick_change_of_rate_times_h():
    # ρ is Lipschitz 1/χ_0 like sat(χ/χ_0), so the yaw rate is 4.7 rad/s² as by hand above, and it now
    # holds across the ridge: the tick change is 4.7 × 0.01 = 0.047 rad/s instead of 2 r_max = 1 rad/s
    rates = backup_command_rate(CONTINUOUS, SAFE, **ARGS)
    assert rates[2] == pytest.approx(4.7, rel=1e-12)
    jump = backup_tick_change(CONTINUOUS, SAFE, tick=0.01, **ARGS)
    assert jump[2] == pytest.approx(0.047, rel=1e-12) and jump[2] >= 0.047
    assert backup_tick_change(SMOOTH, SAFE, tick=0.01, **ARGS)[2] == 1.0


def test_the_continuous_law_is_continuous_along_trajectories_that_cross_the_ridge():
    """Along 30 random trajectories every finite difference, yaw included and the ridge's crossings included,
    stays below the rate bound, and every held command's change per tick below the tick bound. The same
    trajectories cross the ridge (measured), where the ridge law jumps by far more than its rate × h."""
    rate = np.array(backup_command_rate(CONTINUOUS, SAFE, **ARGS))
    jump = np.array(backup_tick_change(CONTINUOUS, SAFE, tick=0.01, **ARGS))
    rng = np.random.default_rng(7)
    worst, worst_tick, crossings = np.zeros(3), np.zeros(3), 0
    for _ in range(30):
        cmds, held, wraps = _run(rng, law=CONTINUOUS)
        worst = np.maximum(worst, (np.abs(np.diff(cmds, axis=0)) / 1e-3).max(axis=0))
        worst_tick = np.maximum(worst_tick, np.abs(np.diff(held, axis=0)).max(axis=0))
        crossings += int(wraps.sum())
    assert crossings > 0
    assert np.all(worst <= rate * (1 + 1e-6)), (worst, rate)
    assert np.all(worst_tick <= jump * (1 + 1e-9) + 1e-15), (worst_tick, jump)
    assert worst[2] > 0.05 * rate[2]  # the yaw bound is not vacuous


def test_abeam_the_continuous_yaw_command_does_not_flip():
    """The crossing of test_crossing_the_ridge_flips_the_yaw_command: with the continuous law both sides of the
    ridge turn the same way (ρ = −1 there, r = +k d/d_1 = 0.25 rad/s), the command changes by nothing."""
    before = station_keeping_input(CONTINUOUS, (0.1, 0.0, 0.0, math.pi / 2 + 1e-4), (0.0, 0.0, 0.0), 10.0)
    after = station_keeping_input(CONTINUOUS, (0.1, 0.0, 0.0, math.pi / 2 - 1e-4), (0.0, 0.0, 0.0), 10.0)
    assert before[2] == pytest.approx(0.25, rel=1e-9) and after[2] == pytest.approx(0.25, rel=1e-9)
