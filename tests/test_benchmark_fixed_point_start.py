"""benchmarks/fixed_point_start.py: the fixed point's first assumption and the backup it ends with."""

from __future__ import annotations

import verify.vehicle.compose as compose

from .scripts import load_script


def test_another_start_ends_with_another_certified_safe_set_and_the_start_is_put_back():
    """Property: on bluerov2_slow the shipped start (1.25 x the plans-only bound) and a start of 1.35 x both close
    with the safe tier, and they end with safe sets that differ by more than a quarter (measured: 4.5 m against
    7.5 m): the fixed point's path, not the physics, decides it. The module's start is restored."""
    mod = load_script("benchmarks/fixed_point_start.py", "bench_fixed_point_start")
    shipped = mod.cell(mod.SCENARIOS[0], 1.25)
    other = mod.cell(mod.SCENARIOS[0], 1.35)
    assert shipped[0] and other[0]
    assert shipped[3] == ["initial_terminal"] and other[3] == ["initial_terminal"]   # tracking: the start only
    assert min(shipped[1], other[1]) < 0.75 * max(shipped[1], other[1])
    assert compose._INFLATE == 1.25 and not compose._SOLVED
