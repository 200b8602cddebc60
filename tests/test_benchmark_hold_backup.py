"""benchmarks/hold_backup.py: the hold backup's disc against station keeping's, and the pier example's variants."""

from __future__ import annotations

import math

import pytest

from .scripts import load_script

HOLD = load_script("benchmarks/hold_backup.py", "hold_backup_benchmark")


@pytest.mark.slow
def test_near_the_pier_only_the_hold_certifies_and_its_disc_is_a_third_of_station_keepings():
    """The pier example: the hold backup certifies the safe tier with a disc below 4 m; station keeping, whose safe
    set at the start reaches the pier, is refused by name (``backup_initial``). On the same scenario without the
    pier (bluerov2_brisk_current with the pier's thrusters) station keeping certifies, with a set over 3 times the
    hold's."""
    pier = HOLD.load_scenario(HOLD.PIER)
    hold = HOLD.certificate_row("pier", pier)
    keeping = HOLD.certificate_row("pier", pier.with_changes(**{"controller.backup": "station_keeping"}))
    assert hold["tiers"]["safe"] and hold["law"]["kind"] == "hold" and hold["safe_radius"] < 4.0
    assert not keeping["tiers"]["safe"] and "backup_initial" in keeping["failed"]
    brisk = HOLD.with_pier_thrusters(HOLD.load_scenario(HOLD.BRISK)).with_changes(
        **{"controller.backup": "station_keeping"})
    far = HOLD.certificate_row("brisk", brisk)
    assert far["tiers"]["safe"] and far["safe_radius"] > 3.0 * hold["safe_radius"]


def test_every_variant_keeps_the_pier_3_m_from_the_targets_path_or_changes_only_the_current():
    """The variants move the pier about the 3 m circle (its centre 3 m from the nearest point of the path) or replace
    the current by a steady one of 0.1 m/s; nothing else of the shipped scenario changes but the start of the one
    with the pier at the centre."""
    variants = HOLD.variants()
    shipped = variants["shipped"]
    assert len(variants) == 9
    for name, sc in variants.items():
        (pier,) = sc.obstacles
        assert pier.radius == 0.5
        gap = abs(math.hypot(pier.center[0], pier.center[1]) - sc.trajectory.radius)
        assert math.isclose(gap, 3.0, abs_tol=1e-9), name
        if name.startswith("steady"):
            assert sc.disturbance.amplitude == (0.0, 0.0, 0.0) and math.hypot(*sc.disturbance.constant) == 0.1
            assert sc.obstacles == shipped.obstacles
        assert sc.controller == shipped.controller and sc.plant == shipped.plant
