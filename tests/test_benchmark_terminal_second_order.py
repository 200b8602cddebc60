"""benchmarks/terminal_second_order.py: sizing a rate-limited completion by the minimal robust invariant set."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from .scripts import load_script

STUDY = load_script("benchmarks/terminal_second_order.py", "bench_terminal_second_order")
DT = 0.1


@functools.lru_cache(maxsize=None)
def _study(rate_scale: float = 1.0) -> dict:
    """The study at the shipped plans' rates times ``rate_scale``, once per worker (two tests read the shipped one)."""
    return STUDY.study(rate_scale=rate_scale)


@pytest.mark.parametrize("w, m", [(0.01, 0.0), (0.0, 0.002), (0.0118, 0.0021)])
def test_the_deadbeat_gains_give_the_hand_solved_set(w, m):
    """k1 = 1/delta, k2 = 1 make A nilpotent: x' = -delta m and s' = -(x + w)/delta - m, so by hand
    sup|x| = delta M, sup|s| = W/delta + 2M and sup|Delta| = 2W/delta + 3M."""
    x, s, change = STUDY.support_sums(np.array(1 / DT), np.array(1.0), DT, w, m)
    assert math.isclose(float(x), DT * m, abs_tol=1e-15)
    assert math.isclose(float(s), w / DT + 2 * m, rel_tol=1e-12)
    assert math.isclose(float(change), 2 * w / DT + 3 * m, rel_tol=1e-12)


def test_an_unstable_pair_of_gains_has_no_invariant_set():
    """k2 = 2.5 puts an eigenvalue of A below -1: every sum is infinite."""
    assert all(math.isinf(float(v)) for v in STUDY.support_sums(np.array(0.1), np.array(2.5), DT, 0.01, 0.0))


def test_the_narrowest_band_keeps_its_command_change_within_j_and_none_without_room():
    """The band found changes the command by at most J; a J below the deviation's own share k1 W of every searched
    gain leaves none."""
    band = STUDY.smallest_band(DT, 0.0065, 0.0, 0.003)
    assert band is not None and band.change <= 0.003 and 0 < band.x < 1.0
    assert STUDY.smallest_band(DT, 0.0065, 0.0, 1e-6) is None


@pytest.mark.slow
def test_a_narrower_rate_limit_never_narrows_the_band():
    """Property: the set that fits J fits any larger J, so the narrowest band is monotone in J."""
    widths = [STUDY.smallest_band(DT, 0.0065, 0.0005, j).x for j in (0.003, 0.006, 0.012)]
    assert widths[0] >= widths[1] >= widths[2]


@pytest.mark.slow
def test_at_the_tracking_tiers_own_loop_bound_every_channel_fits_on_the_slow_scenario():
    """On examples/bluerov2_slow.toml as shipped, read at the tracking design's plans-only loop bound (docs/verify.md
    step 17d: smaller deviations than the fixed point's E gave), every channel's band fits its room with its
    command changes within J, whichever surge law: the memoryless law's row faces (step 17c) fit there too."""
    res = _study()
    ch = res["channels"]
    assert res["failed"] == ""
    for key in ("heading", "radial", "radial_plain", "depth"):
        assert ch[key]["fits"] and ch[key]["band"]["change"] <= ch[key]["J"], key
    assert math.isclose(ch["radial"]["J"], 0.03 * DT)


@pytest.mark.slow
def test_with_the_rates_doubled_the_bands_narrow():
    """Plans' rates x2 (the safe tier still certified): every band fits and the heading's and the radial one's are
    narrower than at the shipped rates (a larger J lets the command absorb the deviation faster)."""
    shipped, doubled = _study()["channels"], _study(2.0)["channels"]
    assert all(doubled[k]["fits"] for k in ("heading", "radial", "radial_plain", "depth"))
    assert doubled["heading"]["band"]["x"] < shipped["heading"]["band"]["x"]
    assert doubled["radial"]["band"]["x"] < shipped["radial"]["band"]["x"]
