"""verify.backup.hold: the hold law's disc proved in Arb, its design, its command rate, and its invariance against a
current that pushes at its bound straight away from the anchor (simulated here independently of the proof)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.model.hold import Hold, hold_input
from verify.backup import BackupCertificate, proof_for
from verify.backup.hold import HOLD_PROOF, certify_hold, design_hold, hold_command_rate, hold_reach

# V = (0.35, 0.15, 0.2), ω̄ = (0.13, 0.12) m/s, tick 10 ms, hand-over (0.17, 0.11) m, E_r 0.03 rad/s.
LIMITS, WXY, WZ, TICK, HAND, E_R = (0.35, 0.15, 0.2), 0.13, 0.12, 0.01, (0.17, 0.11), 0.03


@pytest.fixture(scope="module")
def designed() -> BackupCertificate:
    return design_hold(omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK, handover=HAND, yaw_rate_error=E_R)


def _adversary(law: Hold, safe: SafeSet, omega: tuple[float, float], limits: tuple[float, float, float],
               handover: tuple[float, float], yaw_err: float, seconds: float, substeps: int = 10
               ) -> tuple[float, float]:
    """(largest ρ, largest |e_z|) (m) of the law held over ticks of 10 ms on ṗ = R(ψ)(u, v) + η, ż = w + η_z,
    ψ̇ = r + E_r, the disturbance on its bound pushing straight away from the anchor; the hand-over at the
    distance and depth error given, heading straight away at the full speed, depth rate and yaw rate of V."""
    x, y, z, psi = handover[0], 0.0, handover[1], 0.0
    start = limits
    top, top_z, dt = 0.0, 0.0, TICK / substeps
    for j in range(int(round(seconds / TICK))):
        u, w, r, v = hold_input(law, (x, y, z, psi), (0.0, 0.0, 0.0), j * TICK, start)
        for _ in range(substeps):
            rho = math.hypot(x, y)
            push = (omega[0] * x / rho, omega[0] * y / rho) if rho > 0 else (omega[0], 0.0)
            c, s = math.cos(psi), math.sin(psi)
            x += dt * (c * u - s * v + push[0])
            y += dt * (s * u + c * v + push[1])
            z += dt * (w + math.copysign(omega[1], z))
            psi += dt * (r + yaw_err)
            top, top_z = max(top, math.hypot(x, y)), max(top_z, abs(z))
    return top, top_z


def test_the_design_certifies_a_disc_and_names_every_step(designed):
    assert designed.certified and proof_for("hold") is HOLD_PROOF
    law, safe = designed.law, designed.safe_set
    assert isinstance(law, Hold) and law.within(*LIMITS) and safe.shape == 0.0
    assert {c.condition for c in designed.conditions} == {
        "backup_inputs", "backup_tick", "backup_level_set", "backup_ramp", "backup_depth_level",
        "backup_depth_ramp"}
    # the disc holds against ω̄ after the ramp: k c (1 − Y h / 2) > ω̄ with Y = r_t + E_r
    y_post = law.turn + E_R
    assert min(law.gain * safe.level, law.speed) * (1 - y_post * TICK / 2) > WXY
    assert designed.handover == HAND


def test_the_certificate_round_trips_and_speaks_for_itself(designed):
    again = BackupCertificate.from_dict(designed.to_dict())
    assert again == designed and again.law.to_dict()["kind"] == "hold"
    text = "\n".join(designed.summary_lines())
    assert "hold, lateral thrust" in text and f"{designed.safe_set.level:.3f} m" in text


def test_a_disc_inside_the_equilibrium_is_refuted_and_left_by_the_adversary(designed):
    """Counterexample: the pull k ρ balances an outward current ω̄ at ρ* = ω̄ / k. A disc of 0.9 ρ* fails
    ``backup_level_set``, and the simulated adversary, started inside it, ends outside."""
    law = designed.law
    small = SafeSet(level=0.9 * WXY / law.gain, shape=0.0, depth=designed.safe_set.depth)
    cert = certify_hold(law, small, omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK, handover=(0.0, 0.0),
                        yaw_rate_error=E_R)
    assert "backup_level_set" in {c.condition for c in cert.failures}
    top, _ = _adversary(law, small, (WXY, WZ), (0.0, 0.0, 0.0), (0.0, 0.0), E_R, seconds=6.0 / law.gain)
    assert top > small.level


def test_a_disc_smaller_than_the_ramps_reach_is_refuted_by_the_ramp(designed):
    law = designed.law
    reach = hold_reach(HAND[0], gain=law.gain, cap=law.speed, contraction_slack=0.99, push=WXY, rest=LIMITS[0],
                          ramp=law.ramp, tick=TICK)
    assert reach >= HAND[0] + 0.5 * LIMITS[0] * law.ramp * 0.5  # the hand-over's surge alone carries it that far
    small = SafeSet(level=0.5 * designed.safe_set.level, shape=0.0, depth=designed.safe_set.depth)
    cert = certify_hold(law, small, omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK, handover=HAND,
                        yaw_rate_error=E_R)
    assert "backup_ramp" in {c.condition for c in cert.failures}


@settings(max_examples=8, deadline=None, derandomize=True)
@given(omega=st.floats(0.0, 0.12), omega_z=st.floats(0.0, 0.1), hand=st.floats(0.0, 0.3),
       yaw_err=st.floats(0.0, 0.05))
def test_the_adversary_on_the_bound_never_leaves_the_designed_disc(omega, omega_z, hand, yaw_err):
    """Property: for a designed hold law, a current on its bound pushing straight out, a yaw error on its bound and
    a hand-over at the full speed of V heading straight out never take the vehicle out of the disc or the depth
    band (the ramp and 30 s after it)."""
    cert = design_hold(omega_xy=omega, omega_z=omega_z, limits=LIMITS, tick=TICK, handover=(hand, 0.5 * hand),
                       yaw_rate_error=yaw_err)
    assert cert.certified
    top, top_z = _adversary(cert.law, cert.safe_set, (omega, omega_z), LIMITS, (hand, 0.5 * hand), yaw_err,
                            seconds=cert.law.ramp + 30.0, substeps=4)
    assert top <= cert.safe_set.level and top_z <= cert.safe_set.depth


def test_the_tick_change_bounds_the_simulated_command(designed):
    """The command's change from one tick to the next along the adversary's run never exceeds the proof's
    per-tick bound, in any channel (sway included)."""
    law = designed.law
    per_tick = HOLD_PROOF.tick_change(law, designed.safe_set, omega_xy=WXY, omega_z=WZ, limits=LIMITS,
                                      loop_error=(0.0, 0.0, E_R), tick=TICK)
    sway = HOLD_PROOF.sway_change(law, designed.safe_set, omega_xy=WXY, omega_z=WZ, limits=LIMITS,
                                  loop_error=(0.0, 0.0, E_R), tick=TICK)
    rates = hold_command_rate(law, omega_xy=WXY, omega_z=WZ, limits=LIMITS, loop_error=(0.0, 0.0, E_R), tick=TICK)
    assert per_tick == pytest.approx(tuple(r * TICK for r in rates[:3])) and sway == pytest.approx(rates[3] * TICK)
    x, y, z, psi, prev, worst = HAND[0], 0.0, HAND[1], 0.0, None, np.zeros(4)
    for j in range(int(round((law.ramp + 10.0) / TICK))):
        u, w, r, v = hold_input(law, (x, y, z, psi), (0.0, 0.0, 0.0), j * TICK, LIMITS)
        if prev is not None:
            worst = np.maximum(worst, np.abs(np.subtract((u, w, r, v), prev)))
        prev = (u, w, r, v)
        rho = math.hypot(x, y)
        c, s = math.cos(psi), math.sin(psi)
        x += TICK * (c * u - s * v + WXY * x / rho)
        y += TICK * (s * u + c * v + WXY * y / rho)
        z += TICK * (w + WZ)
        psi += TICK * (r + E_R)
    assert np.all(worst <= np.array([*per_tick, sway]) + 1e-15) and worst.max() > 0.0


def test_the_proof_refuses_another_kind_and_a_shaped_set(designed):
    other = StationKeeping(surge=0.2, yaw_rate=0.2, yaw_band=0.3, heave=0.1, heave_band=0.1)
    with pytest.raises(ConfigError, match="backup.kind"):
        certify_hold(other, designed.safe_set, omega_xy=WXY, omega_z=WZ, limits=LIMITS, tick=TICK)
    with pytest.raises(ConfigError, match="safe_set"):
        certify_hold(designed.law, SafeSet(level=3.0, shape=0.5, depth=1.0), omega_xy=WXY, omega_z=WZ,
                     limits=LIMITS, tick=TICK)
    assert proof_for("station_keeping").sway_change(other, designed.safe_set, omega_xy=WXY, omega_z=WZ,
                                                    limits=LIMITS, loop_error=(0, 0, 0), tick=TICK) == 0.0


@pytest.mark.slow
def test_with_the_bundled_thrust_shares_the_hold_is_refused_by_the_lateral_thrust_and_says_which_knob():
    """The bundled BlueROV2 Heavy keeps 10 % of its horizontal thrust for sway (Y_max 11.37 N): enough to regulate the
    sway to 0, not to push sideways against 0.1 m/s of current. The hold is then refused by ``loop_saturation[Y]``
    (not by a diverging fixed point: when no law's loop bound closes the design falls back to its gentlest law), and
    the detail names the thrust shares."""
    from pathlib import Path

    import verify
    from tubekit.scenario import load_scenario
    brisk = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_brisk_current.toml")
    cert = verify.certify(brisk.with_changes(**{"controller.backup": "hold"}))
    failed = {c.condition: c for c in cert.plant_conditions if not c.ok}
    assert not cert.tiers.safe and "loop_saturation[Y]" in failed and "loop_fixed_point" not in failed
    y = failed["loop_saturation[Y]"]
    assert y.lhs > y.rhs == pytest.approx(11.37) and "thrusters] shares" in y.detail
