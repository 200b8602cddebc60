"""benchmarks/pier_spread.py: the share of the published spread each current leaves certified at the pier."""

from __future__ import annotations

import pytest

from tubekit.model.vehicles import vehicle_params

from .scripts import load_script

STUDY = load_script("benchmarks/pier_spread.py", "bench_pier_spread")


def test_a_share_is_the_published_box_shrunk_about_its_midpoints_with_the_current_and_rates_set():
    """at_share(0.5, ...): every interval of the vehicle table is the bundled one's midpoint ± half its half-width
    (worked out here from the bundled box), the horizontal current and the plans' rates are the ones given, the
    vertical current and the loop's bandwidth the file's."""
    sc = STUDY.at_share(0.5, 0.04, (0.1, 0.03, 0.2))
    published = vehicle_params("bluerov2_heavy")
    for name, (lo, hi) in ((k, v) for k, v in sc.plant.overrides if isinstance(v, tuple)):
        p_lo, p_hi = published.interval(name)
        mid, quarter = (p_lo + p_hi) / 2, (p_hi - p_lo) / 4
        assert (lo, hi) == pytest.approx((mid - quarter, mid + quarter), rel=1e-12, abs=1e-12), name
    assert dict(sc.plant.overrides)["loop_bandwidth"] == 20.0
    assert sc.disturbance.amplitude == (0.04, 0.04, 0.1) and sc.limits.rate == (0.1, 0.03, 0.2)


@pytest.mark.slow(8)
def test_in_six_hundredths_of_current_about_half_the_spread_keeps_both_tiers_and_the_whole_does_not():
    """The share found is certified and is a lower bound of the frontier. At 0.06 m/s per axis with
    plans at (0.15, 0.03, 0.26) two halvings find 0.525 of the spread (the frontier measured apart from the study
    is 0.55): the whole box is refused, and the share reported certifies both tiers."""
    found = STUDY.largest_share(0.06, steps=2, rates=((0.15, 0.03, 0.26),))
    assert 0.5 <= found["share"] < 0.55 and found["rates"] == (0.15, 0.03, 0.26)
    assert all(0.0 < e < 0.1 for e in found["error"][:2])
    assert STUDY.certified(STUDY.at_share(found["share"], 0.06, found["rates"]))[0]
    assert not STUDY.certified(STUDY.at_share(1.0, 0.06, found["rates"]))[0]
