"""benchmarks/dynamic_frontier.py: one cell of the frontier, each verdict from verify.certify itself."""

from __future__ import annotations

from .scripts import load_script


def _module():
    return load_script("benchmarks/dynamic_frontier.py", "bench_dynamic_frontier")


def test_the_shipped_point_certifies_and_the_paper_current_does_not():
    """u_max 0.3 m/s with 0.04 m/s of current is the shipped scenario (the safe tier; tracking refused only for
    ``terminal_rate``); at the paper's current the target and the current outrun u_max (``keep_up[u]`` among the
    named failures)."""
    mod = _module()
    assert mod.cell(0.3, 0.04) == "safe"
    lines = mod.table([0.3], [0.1])
    assert lines[0].startswith("| u_max") and len(lines) == 3
    assert lines[2].startswith("| 0.3 | keep_up[u], ")
