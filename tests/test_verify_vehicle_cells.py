"""verify/vehicle/cells.py: step 5c of the velocity loop's bound, the channel's own coefficients in cells."""

from __future__ import annotations

import math

import numpy as np
from flint import arb
from hypothesis import given, settings, strategies as st

from tubekit.model.vehicle_sets import BLUEROV2_HEAVY
from verify.kernel.intervals import enclose, lower, upper
from verify.vehicle.bound import velocity_loop_bound
from verify.vehicle.cells import CELL_BUDGET, _cell_matrix, own_splits, split_ball
from verify.vehicle.loop_data import loop_data_of, loop_matrix

H, TICKS = 0.01, 10


@settings(derandomize=True, max_examples=60, deadline=None)
@given(lo=st.floats(-1e3, 1e3), width=st.floats(1e-6, 1e3), pieces=st.integers(1, 7))
def test_the_pieces_of_a_ball_cover_it_end_to_end(lo, width, pieces):
    """Property: the sub-balls of [lo, lo + width] start at or below lo, end at or above lo + width, and each
    starts at or below where the one before ends (no gap, so every θ lies in some cell)."""
    hi = lo + width
    parts = split_ball(enclose(lo, hi), pieces)
    assert len(parts) == (pieces if lo < hi else 1)
    assert lower(parts[0]) <= lo and upper(parts[-1]) >= hi
    assert all(lower(b) <= upper(a) for a, b in zip(parts, parts[1:]))


def test_a_point_coefficient_is_not_split():
    assert split_ball(arb(3.5), 4) == [arb(3.5)]


def _published(bandwidth: float = 20.0):
    return BLUEROV2_HEAVY.with_overrides({"loop_bandwidth": bandwidth})


def test_the_splits_keep_within_the_budget_and_leave_points_whole():
    """Over the published box every own coefficient has a width; over von Benzon's point values with only the added
    masses widened, the damping coefficients are points and every split goes to the mass."""
    loop = loop_data_of(_published(), (0.35, 0.15, 0.2), H, TICKS)
    for c in range(len(loop.names)):
        splits = own_splits(loop, c)
        assert math.prod(splits) <= CELL_BUDGET and min(splits) >= 1
        assert len(loop.cells[c]) == math.prod(splits)
    nominal = BLUEROV2_HEAVY.nominal
    masses_only = nominal.with_overrides({"X_udot": (1.2 * nominal.X_udot, 0.8 * nominal.X_udot),
                                          "loop_bandwidth": 20.0})
    loop = loop_data_of(masses_only, (0.35, 0.15, 0.2), H, TICKS)
    assert own_splits(loop, 0)[1:] == (1, 1) and own_splits(loop, 0)[0] > 1
    assert loop.cells[2] == ()  # heave: nothing of its own to split


def test_the_cell_matrix_has_the_eigenvalues_of_the_loop_in_its_plain_coordinates():
    """A channel with linear drag (true κ, nominal κ̂), mass m against m̂, actuator lag T under the PI law with
    feedforward: in (y, I, τ) its matrix is written here from the plant's equations; A_k with μ_k = m̂/m and
    δ_k = (κ̂ − κ)/m̂ (exact: the residuals vanish) is the same loop in other coordinates, so the spectra agree."""
    k_p, k_i, lag, m_hat, m, kap_hat, kap = 20.0, 100.0, 0.05, 18.0, 15.0, 10.0, 14.0
    plain = np.array([[-kap / m, 0.0, 1.0 / m], [-1.0, 0.0, 0.0],
                      [(kap_hat - m_hat * k_p) / lag, m_hat * k_i / lag, -1.0 / lag]])
    lam = kap_hat / m_hat
    base = loop_matrix(k_p, k_i, lag, lam)
    a_k = _cell_matrix(base, arb(k_i), arb(k_p), arb(lam), arb(m_hat / m), arb((kap_hat - kap) / m_hat))
    cell = np.array([[float(x.mid()) for x in row] for row in a_k])
    assert np.allclose(np.sort_complex(np.linalg.eigvals(cell)), np.sort_complex(np.linalg.eigvals(plain)),
                       rtol=1e-9, atol=1e-9)
    wrong = _cell_matrix(base, arb(k_i), arb(k_p), arb(lam), arb(1.0), arb(0.0))  # the nominal loop
    nominal = np.array([[float(x.mid()) for x in row] for row in wrong])
    assert not np.allclose(np.sort_complex(np.linalg.eigvals(nominal)), np.sort_complex(np.linalg.eigvals(plain)),
                           rtol=1e-3)


#: the published box's command box at the owners' speed, the plans' jumps (rate (0.03, 0.03, 0.06) m/s², rad/s² over
#: 0.1 s) and the first command within J of 0.2 m/s
_V, _PLANS, _FIRST = (0.35, 0.15, 0.2), (0.003, 0.003, 0.006), (0.203, 0.003, 0.006)


def test_over_the_published_spread_the_cells_close_the_loop_where_the_other_two_decompositions_diverge(monkeypatch):
    """The BlueROV2 Heavy's bundled box (no interval narrowed) on a 20 rad/s loop with the command box V = (0.35, 0.15,
    0.2): with step 5c the fixed point closes; without it (the first two decompositions only) it diverges."""
    import verify.vehicle.bound as bound
    kwargs = dict(v_max=_V, tick=H, period=H * TICKS, jump_tick=(0.0, 0.0, 0.0), jump_period=_PLANS,
                  first_command=_FIRST)
    with_cells = velocity_loop_bound(_published(), **kwargs)
    assert with_cells.certified, with_cells.reason
    assert with_cells.error[0] < 0.1 and with_cells.error[2] < 0.06
    monkeypatch.setattr(bound, "_in_cells", lambda *args: math.inf)
    without = velocity_loop_bound(_published(), **kwargs)
    assert not without.certified and "diverged" in next(c for c in without.conditions
                                                        if c.condition == "loop_fixed_point").detail
