"""benchmarks/terminal_rate.py: how far the row faces' rate conditions are from J on the shipped scenarios."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from .scripts import load_script

ROOT = Path(__file__).resolve().parents[1]


def _module():
    return load_script("benchmarks/terminal_rate.py", "bench_terminal_rate")


def test_on_the_slow_bluerov2_the_finer_grid_finds_row_faced_sets_that_fit_at_the_tracking_tiers_bound():
    """On ``examples/bluerov2_slow.toml``, at the tracking design's plans-only loop bound (docs/verify.md step 17d),
    the finer grid finds row-faced sets whose every law condition holds: the nearest needs (S + K(deviation)) / J at
    most 1 in every channel (the face is as wide as J leaves, so 0.999); the shipped grid's nearest set misses the
    yaw row (the certificate's ``terminal_rate[r]``)."""
    mod = _module()
    res = mod.study()
    assert res["failed"] == [] and res["candidates"] > 0 and res["sets"] > res["candidates"]
    assert res["worst"] <= 1.0 and math.isclose(res["jump"][0], 0.03 * 0.1)
    assert res["best"]["r"] == pytest.approx(0.999, rel=1e-6)


def test_on_the_smooth_line_the_nearest_set_fits_every_channel():
    res = _module().study(ROOT / "examples" / "smooth_line.toml")
    assert res["worst"] <= 1.0 and all(0.0 < r <= 1.0 for r in res["best"].values())


def test_the_finer_grid_is_put_back():
    import verify.theorem.terminal as terminal
    mod = _module()
    before = terminal.LOWER_ENDS, terminal.WIDTHS
    with mod.finer_grid():
        assert terminal.LOWER_ENDS == mod.LOWER_ENDS and terminal.WIDTHS == mod.WIDTHS
    assert (terminal.LOWER_ENDS, terminal.WIDTHS) == before
