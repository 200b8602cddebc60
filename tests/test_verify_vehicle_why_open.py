"""Why the velocity loop's bound did not close (verify.vehicle.why_open): own loop gains and the root cause."""

from __future__ import annotations

from tubekit.model.vehicle_sets import BLUEROV2_HEAVY
from verify.vehicle.loop_data import loop_data_of
from verify.vehicle.why_open import open_cause, own_gains

V, H, TICKS = (0.4, 0.3, 0.5), 0.01, 10


def test_a_point_vehicle_has_no_mismatch_and_no_mass_part_in_its_own_gain():
    """At a point of the coefficient box the controller's model is the plant: the own loop gain's mismatch part is
    exactly 0 (the mismatch is the model at the coefficients' differences), its mass part 0 up to the balls' rounding,
    and only the nominal drag's slope over V remains (> 0: quadratic drag)."""
    loop = loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS)
    gains = own_gains(loop, (0.01, 0.01, 0.01, 0.01) if loop.lateral else (0.01, 0.01, 0.01))
    assert all(mism == 0.0 and 0.0 <= mass < 1e-12 and drag >= 0.0 for mism, drag, mass in gains)
    assert max(drag for _, drag, _ in gains) > 0.0


def test_a_loop_that_closed_or_never_ran_a_round_has_no_cause():
    loop = loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS)
    assert open_cause(loop, True, "", [[1.0] * 4] * 3) == ""
    assert open_cause(loop, False, "no closing after 60 rounds", None) == ""


def test_a_channel_whose_own_gain_reaches_one_is_named_with_its_three_parts():
    """At a box 50 m/s wide the nominal drag's slope alone makes each channel's own gain far above 1 (the Heavy's
    quadratic drag, 2 x 217 kg/m x 50 m/s over m22 ~ 18 kg, times the loop's L1 gain): the cause names the channel
    whose gain is largest, sway, with its three parts, and the first round's growth."""
    loop = loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS)
    n = len(loop.names)
    wide = tuple(50.0 for _ in range(n))
    gains = own_gains(loop, wide)
    assert min(sum(g) for g in gains) > 1.0 and max(range(n), key=lambda c: sum(gains[c])) == loop.names.index("v")
    text = open_cause(loop, False, "no closing after 60 rounds", [[2.0] * 4 for _ in range(n)], wide)
    assert text.startswith("diverged (no closing after 60 rounds)") and "multiplied the bounds by up to 2" in text
    assert "channel v cannot close on its own" in text and "from the nominal drag's slope" in text
