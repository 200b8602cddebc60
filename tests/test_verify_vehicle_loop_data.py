"""The velocity loop's fixed data (verify.vehicle.loop_data): built once per vehicle, its sums and slopes."""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from tubekit.model.vehicle_sets import BLUEROV2_HEAVY
from verify.vehicle.loop_data import loop_data_of, loop_matrix

V, H, TICKS = (0.4, 0.3, 0.5), 0.01, 10


def test_the_data_is_built_once_per_vehicle_box_and_tick():
    """The fixed point calls loop_data_of every round; the response sums are summed once (the same object)."""
    first = loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS)
    assert loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS) is first
    assert loop_data_of(BLUEROV2_HEAVY.nominal, (0.3, 0.3, 0.5), H, TICKS) is not first


def test_each_channel_has_a_stable_loop_and_the_heavy_regulates_its_sway():
    """The BlueROV2 Heavy has lateral thrust: four channels (u, v, w, r), each sampled loop stable, its slope the
    midpoint of the nominal drag's slope over V (>= 0: drag damps)."""
    loop = loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS)
    assert loop.lateral and loop.names == "uvwr" and loop.stable
    assert len(loop.sums) == 4 and all(lam >= 0.0 for lam in loop.slope)
    assert loop.k_i == 0.25 * loop.k_p ** 2


def test_the_jump_sum_bounds_the_sampled_response_of_the_matrix():
    """Property: Σ_i |e| of the response to a unit jump, sampled at the ticks by scipy's expm (an independent
    computation), never exceeds the Arb sum of the supremum over each tick."""
    loop = loop_data_of(BLUEROV2_HEAVY.nominal, V, H, TICKS)
    for c, lam in enumerate(loop.slope):
        a = np.array([[float(x.mid()) for x in row] for row in loop_matrix(loop.k_p, loop.k_i, loop.lag, lam)])
        ad, x, total = expm(a * H), np.array([0.0, 1.0, -loop.k_p]), 0.0
        for _ in range(2000):
            total += abs(x[1])
            x = ad @ x
        assert total <= loop.sums[c].tick[0][0]
        assert total > 0.5 * loop.sums[c].tick[0][0]  # and the sum is not loose: the sup over a tick is near it


def test_a_channel_with_a_bandwidth_of_its_own_gets_its_own_gains_and_sums():
    """REMUS 100 (no lateral thrust: channels u, w, r) with its yaw loop at 10 rad/s against the loop_bandwidth's 5:
    the yaw channel's gains are (10, 25), the others' (5, 6.25), and only the yaw channel's response sums change."""
    from tubekit.model.vehicle_sets import REMUS100

    base = loop_data_of(REMUS100.nominal, (1.5, 0.015, 0.02), H, TICKS)
    own = loop_data_of(REMUS100.nominal.with_overrides({"yaw_loop_bandwidth": 10.0}), (1.5, 0.015, 0.02), H, TICKS)
    assert base.gains == ((5.0, 6.25),) * 3 and own.gains == ((5.0, 6.25), (5.0, 6.25), (10.0, 25.0))
    assert own.sums[:2] == base.sums[:2] and own.sums[2] != base.sums[2]
    assert own.sums[2].tick[0][0] < base.sums[2].tick[0][0]   # a faster loop: less error per unit jump
