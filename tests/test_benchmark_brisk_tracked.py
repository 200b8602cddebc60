"""benchmarks/brisk_tracked.py: the variants of the brisk tracked BlueROV2, certified on their own and flown."""

from __future__ import annotations

from .scripts import load_script


def _module():
    return load_script("benchmarks/brisk_tracked.py", "bench_brisk_tracked")


def test_the_variants_change_what_their_names_say():
    """The steady currents lie on the certified bound along their axis, the rocks are mirrored across the path or
    moved back along it, and the corners put every interval's end into the simulated hull."""
    variants = _module().variants()
    base = variants["as shipped"]
    assert variants["steady -y"].disturbance.constant == (0.0, -0.1, 0.0)
    assert variants["steady -y"].disturbance.amplitude == (0.0, 0.0, 0.0)
    rocks = [o.center for o in base.obstacles]
    assert [o.center for o in variants["rocks mirrored"].obstacles] == [(x, -y, z) for x, y, z in rocks]
    assert [o.center for o in variants["rocks moved along"].obstacles] == [(x - 10.0, y, z) for x, y, z in rocks]
    lower = dict(variants["hull at the lower corner"].plant.truth)
    assert lower["X_uu"] == base.plant.params.X_uu[0] and lower["X_uu"] != dict(
        variants["hull at the upper corner"].plant.truth)["X_uu"]


def test_a_scenario_with_a_smaller_current_bound_gets_its_own_steady_current():
    """The steady variants take the scenario's own horizontal bound (0.04 m/s on the published-spread example), so
    each variant stays inside what its certificate assumes."""
    from pathlib import Path
    published = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_published.toml"
    variants = _module().variants(published)
    assert variants["steady +x"].disturbance.constant == (0.04, 0.0, 0.0)
    assert variants["steady -y"].disturbance.constant == (0.0, -0.04, 0.0)


def test_a_short_flight_reports_both_tiers_kept_with_a_plan_at_every_period():
    row = _module().fly("as shipped", _module().variants()["as shipped"], duration=3.0)
    assert row["certified"] == [True, True] and row["broken"] == [] and row["backup_s"] == 0.0
    assert row["steps"] == 30 and row["plan_available"].endswith("periods without an accepted plan 0")
    assert row["e_d"][0] > 4.0   # the plans end in X_f, 4.48 m or more behind the target: trailing is the price
