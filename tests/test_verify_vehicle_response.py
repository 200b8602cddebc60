"""Rigorous impulse-response sums (verify.vehicle.response) against closed forms and scipy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.linalg import expm

from verify.vehicle.response import impulse_sums


@pytest.mark.parametrize("k, h, n", [(2.0, 0.01, 10), (8.0, 0.02, 5), (0.5, 0.05, 4)])
def test_first_order_sums_match_their_closed_form(k, h, n):
    # ṡ = −k s, c = b = 1: g(i) = sup_θ e^{−k (i h + θ)} = e^{−k i h}, so Σ g = 1/(1 − e^{−kh}),
    # the worst phase of one jump per n ticks is p = 0: 1/(1 − e^{−k n h}); the peak is g(0) = 1.
    s = impulse_sums([[-k]], [[1.0]], [[1.0]], tick=h, ticks_per_period=n, tol=1e-12)
    tick, period = 1.0 / (1.0 - math.exp(-k * h)), 1.0 / (1.0 - math.exp(-k * n * h))
    assert tick <= s.tick[0][0] <= tick * (1 + 1e-6)
    assert period <= s.period[0][0] <= period * (1 + 1e-6)
    assert 1.0 <= s.peak[0][0] <= 1.0 + 1e-6
    assert s.stable and s.rho < 1e-12


def test_the_l1_gain_of_a_pi_loop_bounds_the_integral_computed_by_scipy():
    kp, ki, lag, h = 5.0, 6.25, 0.1, 0.01
    a = [[0, 1, 0], [-ki, -kp, -1], [kp * ki, kp * kp - ki, kp - 1 / lag]]
    b, c = np.array([0.0, 1.0, -kp]), np.array([0.0, 1.0, 0.0])
    s = impulse_sums(a, [b.tolist()], [c.tolist()], tick=h, ticks_per_period=10)
    exact, _ = quad(lambda t: abs(c @ expm(np.array(a) * t) @ b), 0.0, 20.0, limit=400)
    assert h * s.tick[0][0] >= exact
    assert h * s.tick[0][0] <= 1.1 * exact   # the sup over each tick costs a few per cent at h = 0.01


def test_the_worst_phase_is_at_least_every_phase_and_at_most_the_full_sum():
    a = [[0.0, 1.0], [-4.0, -1.0]]   # a lightly damped oscillator: the phases differ
    s = impulse_sums(a, [[0.0, 1.0]], [[1.0, 0.0]], tick=0.05, ticks_per_period=7)
    ad, x = expm(np.array(a) * 0.05), np.array([0.0, 1.0])
    g = []
    for _ in range(3000):
        g.append(abs(x[0]))
        x = ad @ x
    g = np.array(g)   # samples at the tick starts: a lower bound of each tick's sup
    assert max(g[p::7].sum() for p in range(7)) <= s.period[0][0] <= s.tick[0][0]
    assert g.sum() <= s.tick[0][0]


def test_an_unstable_system_gives_infinite_sums():
    s = impulse_sums([[0.5]], [[1.0]], [[1.0]], tick=0.1, ticks_per_period=2, max_terms=200)
    assert not s.stable and s.tick[0][0] == math.inf and s.period[0][0] == math.inf


def test_equal_balls_get_the_sums_formed_for_them_and_different_balls_their_own(monkeypatch):
    """The memo of impulse_sums keys on the exact balls: a repeated call returns the sums formed for it without
    summing again; A one ulp away, or the same midpoint with a radius, is summed afresh and gets what a cold call
    gives."""
    from flint import arb

    import verify.vehicle.response as response
    monkeypatch.setattr(response, "_MEMO", {})
    a = [[0.0, 1.0], [-4.0, -1.0]]
    kwargs = dict(tick=0.05, ticks_per_period=7)
    first = impulse_sums(a, [[0.0, 1.0]], [[1.0, 0.0]], **kwargs)
    monkeypatch.setattr(response, "_sums", lambda *args: pytest.fail("summed again for the same balls"))
    assert impulse_sums([[0, 1], [-4, -1]], [[0, 1]], [[1, 0]], **kwargs) is first
    monkeypatch.undo()
    nudged = [[0.0, 1.0], [-4.0, math.nextafter(-1.0, 0.0)]]
    widened = [[0.0, 1.0], [-4.0, arb(-1.0, 1e-3)]]
    for other in (nudged, widened):
        warm = impulse_sums(other, [[0.0, 1.0]], [[1.0, 0.0]], **kwargs)
        monkeypatch.setattr(response, "_MEMO", {})
        assert warm == impulse_sums(other, [[0.0, 1.0]], [[1.0, 0.0]], **kwargs) != first


def test_the_memo_keeps_at_most_its_size(monkeypatch):
    import verify.vehicle.response as response
    monkeypatch.setattr(response, "_MEMO", {})
    monkeypatch.setattr(response, "MEMO_SIZE", 3)
    for k in (1.0, 2.0, 3.0, 4.0, 5.0):
        impulse_sums([[-k]], [[1.0]], [[1.0]], tick=0.1, ticks_per_period=2)
    assert len(response._MEMO) == 3


def test_the_weighted_sums_weigh_each_ticks_response_by_the_jumps_its_age_holds():
    """Property: for ṡ = −k s (c = b = 1, g(i) = e^{−k i h} exactly), the weighted sums are Σ g(i)(i + 2) and
    Σ g(i)(⌊(i + 1)/N⌋ + 1), summed here term by term to 1e-14, and the worst phase's weighted sum lies between a
    single phase's and the full weighted sum; the unweighted sums are unchanged by asking for the weights."""
    k, h, n = 3.0, 0.01, 4
    s = impulse_sums([[-k]], [[1.0]], [[1.0]], tick=h, ticks_per_period=n, tol=1e-12, moments=True)
    plain = impulse_sums([[-k]], [[1.0]], [[1.0]], tick=h, ticks_per_period=n, tol=1e-12)
    g = [math.exp(-k * i * h) for i in range(20000)]
    by_ticks = sum(x * (i + 2) for i, x in enumerate(g))
    by_periods = sum(x * ((i + 1) // n + 1) for i, x in enumerate(g))
    assert by_ticks <= s.moment_tick[0][0][0] <= by_ticks * (1 + 1e-6)
    assert by_periods <= s.moment_tick[1][0][0] <= by_periods * (1 + 1e-6)
    phase0 = sum(x * ((i + 1) // n + 1) for i, x in enumerate(g) if i % n == 0)
    assert phase0 <= s.moment_period[1][0][0] <= s.moment_tick[1][0][0]
    assert (s.tick, s.period, s.peak) == (plain.tick, plain.period, plain.peak)


@settings(derandomize=True, max_examples=200, deadline=None)
@given(mid=st.floats(1e-12, 4.0), rad_share=st.sampled_from([0.0, 1e-30, 1e-12, 1e-3, 0.005, 0.0101, 0.5]),
       tol=st.sampled_from([1e-8, 1e-4, 0.3]))
def test_the_stopping_rule_read_from_floats_decides_as_the_exact_bounds_do(mid, rad_share, tol):
    """Property: ``_done`` with the ball's float top decides as the exact rule ‖A_d^i‖ < tol, or < 1/2 with the
    radius above 1 % of it, decides on the exact upper bounds, near both thresholds too."""
    from flint import arb
    from verify.kernel.intervals import upper
    from verify.kernel.intervals import float_top
    from verify.vehicle.response import _done
    for norm in (arb(mid, mid * rad_share), arb(tol, tol * rad_share), arb(0.5, 0.5 * rad_share)):
        exact = upper(norm) < tol or (upper(norm) < 0.5 and upper(norm.rad()) > 0.01 * upper(norm))
        assert _done(norm, float_top(norm), tol) is exact



def test_the_peaks_are_the_exact_running_maxima_of_every_ticks_response():
    """The peak of each output and input is the largest exact upper bound of g(i) over the ticks summed (a lightly
    damped loop whose response rises, then rings down), though most ticks pass an entry over on its norm bound."""
    from flint import arb, arb_mat, ctx
    from verify.kernel.intervals import upper
    from verify.vehicle import response
    a = [[0.0, 1.0, 0.0], [-40.0, -1.5, 1.0], [0.0, 0.0, -8.0]]
    inputs, outputs = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, -1.0, 0.5]]
    sums = response.impulse_sums(a, inputs, outputs, tick=0.01, ticks_per_period=10)
    with ctx.workprec(response.RESPONSE_PREC):
        A, h = arb_mat(a), arb(0.01)
        B, C = arb_mat([list(col) for col in zip(*inputs)]), arb_mat(outputs)
        stacked = response._stacked(response._intra_tick_rows(A, C, h, response.INTRA_TICK_PIECES))
        ad, best = (A * h).exp(), [0.0] * 6
        power = arb_mat(3, 3, [arb(int(r == c)) for r in range(3) for c in range(3)])
        for _ in range(sums.terms):
            g = response._tick_maxima(stacked, power * B, response.INTRA_TICK_PIECES)
            best = [max(p, upper(x)) for p, x in zip(best, g)]
            power = power * ad
    assert [list(row) for row in sums.peak] == [best[o * 2:(o + 1) * 2] for o in range(3)]
    assert sums.terms > 300 and best[0] > 0.01
