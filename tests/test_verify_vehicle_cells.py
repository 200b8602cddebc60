"""verify/vehicle/cells.py: step 5c of the velocity loop's bound, the channel's own coefficients in cells."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from flint import arb
from hypothesis import given, settings, strategies as st

from tubekit.scenario import load_scenario
from tubekit.model.vehicle_sets import BLUEROV2_HEAVY
from tubekit.tiers import Tiers
from verify.certificate.certify import certify
from verify.studies.recheck import recheck
from verify.kernel.intervals import enclose, lower, upper
from verify.vehicle.bound import velocity_loop_bound
from verify.vehicle.cells import (CELL_BUDGET, CellInputs, _cell_matrix, _rest, cell_inputs, channel_bounds,
                                  own_splits, split_ball)
from verify.vehicle.model import velocity_box
from verify.vehicle.loop_data import loop_data_of, loop_matrix

from .corners import flown_at_corner
from .loop_steps import STEP_5C, certified_with_steps_off

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


_SIZES = st.one_of(st.just(0.0), st.floats(1e-9, 1e3), st.just(math.inf))


@settings(derandomize=True, max_examples=40, deadline=None)
@given(jumps=st.tuples(st.floats(0.0, 0.5), st.floats(0.0, 0.5)), w_n=st.floats(0.0, 50.0), seed=st.integers(0, 2**16),
       sizes=st.lists(st.tuples(_SIZES, _SIZES, _SIZES, _SIZES), min_size=1, max_size=4))
def test_a_channels_bound_is_every_cells_own_bound_at_its_largest(jumps, w_n, seed, sizes):
    """Property: over the published box's yaw cells (36 of them) and any residual inputs (zero, tiny, large or
    infinite, drawn per cell), each output of ``channel_bounds`` (which forms a cell's ball only where a float
    screen cannot rule it out) equals the largest over the cells of that cell's ball, formed here term by term from
    the module doc's row o and rounded up, to the last bit."""
    cells = loop_data_of(_published(), (0.35, 0.15, 0.2), H, TICKS).cells[3]
    rng = np.random.default_rng(seed)
    pick = rng.integers(len(sizes), size=len(cells))
    inputs = [CellInputs(*(x * (1 + rng.random()) for x in sizes[i])) for i in pick]
    j_tick, j_period = arb(min(jumps)), arb(max(jumps))
    expected = []
    for o in range(4):
        best = -math.inf
        for cell, ins in zip(cells, inputs):
            g = cell.gains[o]
            x = (j_tick * g[0] + (j_period - j_tick) * g[1] + g[2] * arb(ins.rate) + g[3] * arb(w_n)
                 + g[5] * arb(ins.mass) + g[4] * arb(ins.start))
            x = x + arb(ins.mismatch) if o == 1 else x
            best = max(best, upper(abs(x * cell.mu if o == 3 else x)))
        expected.append(best)
    assert len(cells) > 10 and channel_bounds(cells, j_tick, j_period, w_n, inputs) == tuple(expected)


@pytest.mark.parametrize("channel", [0, 3])
def test_each_cells_residuals_are_its_own_damping_and_mass_residual_over_the_box(channel):
    """Cells that share their damping's pieces share the residuals formed for them: every cell's inputs equal the
    module doc's, formed here for that cell alone (its Δa, Δb, δ_k and μ), to the last bit (surge: 32 cells over 4
    mass pieces; yaw: 36 over 3)."""
    loop = loop_data_of(_published(), (0.35, 0.15, 0.2), H, TICKS)
    nu, rates, accel = velocity_box(0.4, 0.05, 0.2, 0.3), (arb(0.3), arb(0.1), arb(0.2), arb(0.5)), 0.7
    cells, own, m_hat = loop.cells[channel], loop.own[channel], loop.m_hat[channel]
    d_rest, g_rest = _rest(loop, channel, nu)
    cross = sum((abs(g) * x for j, (g, x) in enumerate(zip(g_rest, rates)) if j != own), arb(0)) / m_hat
    speed = nu[own]
    size = arb.union(speed.abs_lower(), speed.abs_upper())
    expected = []
    for cell in cells:
        d_a, d_b = cell.damping
        d_own, g_own = -(d_a + d_b * size) * speed, -(d_a + 2 * d_b * size)
        mismatch = upper(abs(d_rest + d_own) / m_hat)
        rate = abs((g_rest[own] + g_own) / m_hat - arb(cell.slope)) * arb(accel) + cross
        expected.append(CellInputs(rate=upper(rate), mass=upper(cell.mass_residual * arb(accel)), mismatch=mismatch,
                                   start=mismatch))
    assert len({c.pieces[0] for c in cells}) > 1 and len(cells) > 30
    assert cell_inputs(loop, channel, nu, rates, accel, None) == tuple(expected)


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
    monkeypatch.setattr(bound, STEP_5C, lambda *args: (math.inf,) * 4)
    without = velocity_loop_bound(_published(), **kwargs)
    assert not without.certified and "diverged" in next(c for c in without.conditions
                                                        if c.condition == "loop_fixed_point").detail


# ---- what step 5c opens: the published spread at the owners' speed (examples/bluerov2_published_brisk.toml) -------

PUBLISHED_BRISK = "examples/bluerov2_published_brisk.toml"


@pytest.fixture(scope="module")
def brisk_cert():
    return certify(load_scenario(PUBLISHED_BRISK))


def test_the_published_spread_certifies_both_tiers_at_the_owners_speed_and_current(brisk_cert, monkeypatch):
    """examples/bluerov2_published_brisk.toml: the bundled box as it is (no interval narrowed), a 0.2 m/s target in
    0.1 m/s of current per axis, epsilon 1 m, no backup: both tiers, recheck agreeing number for number; with the
    cells switched off the loop's fixed point does not close and nothing is certified."""
    sc = load_scenario(PUBLISHED_BRISK)
    assert all(sc.plant.params.interval(k) == BLUEROV2_HEAVY.interval(k) for k in BLUEROV2_HEAVY.interval_fields)
    assert sc.trajectory.direction_velocity[0] >= 0.2 and min(sc.disturbance.amplitude[:2]) >= 0.1
    assert sc.epsilon <= 1.0
    assert brisk_cert.tiers == Tiers(True, True)
    assert recheck(json.loads(json.dumps(brisk_cert.to_dict()))).ok
    without = certified_with_steps_off(monkeypatch, sc, (STEP_5C,))
    assert without.tiers == Tiers(False, False) and "loop_fixed_point" in [c.condition for c in without.failures]


@pytest.mark.parametrize("end", [0, 1])
def test_at_the_owners_speed_a_hull_at_either_corner_of_the_published_box_keeps_every_promise(brisk_cert, end):
    """20 s of examples/bluerov2_published_brisk.toml with the hull at the box's lower, then upper corner: every
    promise of both tiers kept (the loop's error within the cells' E among them), a plan at every period."""
    promises, run = flown_at_corner(load_scenario(PUBLISHED_BRISK), end, brisk_cert)
    assert all(p.ok for p in promises.values() if p.given), [p for p in promises.values() if p.given and not p.ok]
    assert promises["plan_available"].ok and promises["velocity_loop"].ok and not run.backup_active.any()


@settings(derandomize=True, max_examples=4, deadline=None)
@given(fraction=st.floats(0.05, 0.3))
def test_a_box_about_the_nominal_vehicle_is_never_bounded_below_the_nominal_vehicle_itself(fraction):
    """Property: over von Benzon's values ± ``fraction`` (the cells of step 5c in use) E is, channel by channel, at
    least the bound of the nominal point vehicle alone, whose loop has no mismatch (its E is the exact L1 sums of the
    jumps and the nominal drag): a cell's centre in the loop's matrix never makes the box look better than its own
    centre."""
    nominal = BLUEROV2_HEAVY.nominal.with_overrides({"loop_bandwidth": 20.0})
    names = ("X_uu", "Y_vv", "Z_ww", "N_rr", "X_udot", "Y_vdot", "Z_wdot", "N_rdot", "X_u", "Z_w")
    box = nominal.with_overrides({k: tuple(sorted((getattr(nominal, k) * (1 - fraction),
                                                   getattr(nominal, k) * (1 + fraction)))) for k in names})
    kwargs = dict(v_max=_V, tick=H, period=H * TICKS, jump_tick=(0.0, 0.0, 0.0), jump_period=_PLANS,
                  first_command=_FIRST)
    point, wide = velocity_loop_bound(nominal, **kwargs), velocity_loop_bound(box, **kwargs)
    assert point.certified and wide.certified, wide.reason
    assert any(cells for cells in loop_data_of(box, _V, H, TICKS).cells)
    assert all(w >= p for w, p in zip(wide.error, point.error)), (wide.error, point.error)


def test_at_the_owners_speed_a_run_started_under_way_at_the_targets_speed_is_not_bounded():
    """The same file started under way at the target's 0.2 m/s instead of 0.08 m/s: the start transient
    d(ν(0))/m̂ over the first command's box grows with its speed, and the plans-only loop bound diverges (what the
    example's ``limits.initial`` avoids; docs/plant.md section 4)."""
    from verify.vehicle.compose import plans_only_bound
    sc = load_scenario(PUBLISHED_BRISK)
    assert plans_only_bound(sc).certified
    under_way = plans_only_bound(sc.with_changes(**{"limits.initial": (0.2, 0.0, 0.0)}))
    assert not under_way.certified and "diverged" in next(c for c in under_way.conditions
                                                          if c.condition == "loop_fixed_point").detail
