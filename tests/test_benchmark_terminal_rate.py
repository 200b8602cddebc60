"""benchmarks/terminal_rate.py: the memoryless terminal law against the rate rows on the shipped dynamic scenario."""

from __future__ import annotations

import math

from .scripts import load_script


def _module():
    return load_script("benchmarks/terminal_rate.py", "bench_terminal_rate")


def test_the_invariant_sets_move_their_rows_by_more_than_j_per_period():
    """On ``examples/bluerov2_slow.toml`` the finer grid finds terminal sets meeting every law condition, and for each
    of them one period's replay deviation alone moves the surge row by more than J = rho delta: what keeps
    ``terminal_rate`` refused there (docs/verify.md, step 17). Since the sway loop shrank omega_bar the yaw row's
    least change is below J_r: the surge row alone stands in the way."""
    mod = _module()
    res = mod.study()
    assert res["invariant"] > 0 and res["sets"] > res["invariant"]
    j_u, _, j_r = res["jump"]
    assert math.isclose(j_u, 0.03 * 0.1) and math.isclose(j_r, 0.06 * 0.1)
    assert 0.0 < res["least_yaw_change"] < j_r and res["least_surge_change"] > j_u


def test_the_finer_grid_is_put_back():
    import verify.theorem.terminal as terminal
    mod = _module()
    before = terminal.LOWER_ENDS, terminal.WIDTHS
    with mod.finer_grid():
        assert terminal.LOWER_ENDS == mod.LOWER_ENDS and terminal.WIDTHS == mod.WIDTHS
    assert (terminal.LOWER_ENDS, terminal.WIDTHS) == before
