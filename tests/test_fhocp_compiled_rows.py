"""Tests of tubekit.fhocp.compiled_rows: each routine gives the floats of the numpy code it replaced (kept in
benchmarks/compiled_step.py), the rows mean what the subproblem needs (a half-space through the linearisation
point's own distance), and NaN is passed on as numpy passed it."""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tubekit.fhocp import compiled_rows
from tubekit.model import compiled_arcs

from .scripts import load_script

BENCH = load_script("benchmarks/compiled_step.py", "bench_compiled_step")

#: numpy's einsum sums three products in an order of its own (an implementation detail): those rows may differ
#: from the routine's by a few ulps on another machine
EINSUM_ULPS = 4


@st.composite
def plans(draw, max_steps: int = 10) -> tuple[np.ndarray, np.ndarray, float]:
    """A plan (N+1, 4) rolled out from a drawn start under drawn inputs (N, 3), and its step dt (s)."""
    n = draw(st.integers(1, max_steps))
    s0 = draw(hnp.arrays(float, 4, elements=st.floats(-5.0, 5.0)))
    inputs = draw(hnp.arrays(float, (n, 3), elements=st.floats(-1.0, 1.0)))
    dt = draw(st.floats(0.05, 0.5))
    return compiled_arcs.rollout(s0, inputs, dt), inputs, dt


@st.composite
def references(draw, plan: np.ndarray, hit: bool) -> np.ndarray:
    """p_d at nodes 1..N (N, 3) near the plan; with ``hit`` one node's p_d is that node's position exactly."""
    n = plan.shape[0] - 1
    r1 = plan[1:, :3] + draw(hnp.arrays(float, (n, 3), elements=st.floats(-3.0, 3.0)))
    if hit:
        k = draw(st.integers(0, n - 1))
        r1[k, :2] = plan[k + 1, :2]
    return r1


@given(plans(), st.booleans(), st.data())
def test_the_state_rows_are_the_replaced_numpy_rows_and_pass_through_the_nodes_error(plan, hit, data):
    """Property: state_rows equals the numpy rows bit for bit (a node on its target included, which takes the
    direction behind the heading), and at the linearisation point n'(p − p_d) is the node's e_d."""
    s, _, _ = plan
    n = s.shape[0] - 1
    r1 = data.draw(references(s, hit))
    lo, hi, ez = np.full(n, 0.4), np.full(n, 3.0), np.full(n, 0.5)
    z_lo, z_hi = data.draw(st.sampled_from([(-math.inf, math.inf), (-1.0, 1.0)]))
    rows = compiled_rows.state_rows(s, r1, lo, hi, ez, z_lo, z_hi)
    np.testing.assert_array_equal(rows, BENCH.numpy_state_rows(s, r1, lo, hi, ez, z_lo, z_hi))
    e_d = np.hypot(s[1:, 0] - r1[:, 0], s[1:, 1] - r1[:, 1])
    along = rows[0] * s[1:, 0] + rows[1] * s[1:, 1] - (rows[2] - lo)
    np.testing.assert_allclose(along, e_d, atol=1e-12)
    np.testing.assert_allclose(np.hypot(rows[0], rows[1]), 1.0, rtol=1e-14)
    assert np.all(rows[4] >= z_lo) and np.all(rows[5] <= z_hi)


@given(plans(), st.integers(0, 3), st.integers(0, 2), st.booleans(), st.data())
def test_the_obstacle_rows_are_the_replaced_rows_and_tangent_at_the_nodes_distance(plan, k, extra, on_centre, data):
    """Property: obstacle_rows equals the numpy rows (to a few ulps: einsum's order), empty slots read 0 >= -1,
    and at the linearisation point n'p − bound = ‖p − c‖ − (r + clearance) (a node on a centre: direction z)."""
    s, _, _ = plan
    n = s.shape[0] - 1
    centres = s[1:, :3][data.draw(hnp.arrays(int, k, elements=st.integers(0, n - 1)))] + data.draw(
        hnp.arrays(float, (k, 3), elements=st.floats(-2.0, 2.0)))
    if on_centre and k:
        centres[0] = s[1, :3]
    radii = data.draw(hnp.arrays(float, k, elements=st.floats(0.1, 1.0)))
    rows = compiled_rows.obstacle_rows(s, centres, radii, 0.2, k + extra)
    np.testing.assert_array_max_ulp(rows, BENCH.numpy_obstacle_rows(s, centres, radii, 0.2, k + extra),
                                    maxulp=EINSUM_ULPS)
    assert np.all(rows[k:, :3] == 0.0) and np.all(rows[k:, 3] == -1.0)
    for j in range(k):
        gap = np.linalg.norm(s[1:, :3] - centres[j], axis=1)
        reach = np.einsum("cn,nc->n", rows[j, :3], s[1:, :3]) - rows[j, 3]
        np.testing.assert_allclose(reach, gap - radii[j] - 0.2, atol=1e-12)


@given(hnp.arrays(float, (6, 3), elements=st.floats(-1.0, 1.0)), st.floats(0.0, 2.0))
def test_the_input_bounds_are_the_box_cut_by_the_trust_region(v, radius):
    """Property: input_bounds equals the numpy rows bit for bit, and every bound lies in the box and within
    radius · v_max of the linearisation input."""
    v_min, v_max = np.array([-0.2, -0.3, -0.5]), np.array([0.4, 0.3, 0.5])
    bd = compiled_rows.input_bounds(v, radius, v_min, v_max)
    np.testing.assert_array_equal(bd, BENCH.numpy_input_bounds(v, radius, v_min, v_max))
    assert np.all(bd[0::2] >= v_min[:, None]) and np.all(bd[1::2] <= v_max[:, None])
    assert np.all(bd[0::2].T >= v - radius * v_max - 1e-15) and np.all(bd[1::2].T <= v + radius * v_max + 1e-15)


@given(plans(), st.floats(-3.0, 3.0), st.data())
def test_the_cost_rows_are_the_replaced_rows(plan, psi0, data):
    """Property: cost_rows equals the numpy block and e_o rows bit for bit and leaves its input alone."""
    s, _, _ = plan
    n = s.shape[0] - 1
    ref = np.vstack([s[:1, :3], data.draw(references(s, False))])
    wref = data.draw(hnp.arrays(float, (3, n), elements=st.floats(0.01, 10.0)))
    eo_all = compiled_arcs.eo_linearisation(s, ref, 1e-9)
    kept = eo_all.copy()
    blk, eo = compiled_rows.cost_rows(wref, ref[1:], eo_all, psi0)
    blk_ref, eo_ref = BENCH.numpy_cost_rows(wref, ref[1:], eo_all.copy(), psi0)
    np.testing.assert_array_equal(blk, blk_ref)
    np.testing.assert_array_equal(eo, eo_ref)
    np.testing.assert_array_equal(eo_all, kept)


@given(st.integers(1, 6), st.integers(0, 6), st.integers(1, 8), st.integers(2, 12), st.integers(0, 2 ** 32 - 1))
def test_the_scattered_mat_vec_is_scipys(n_a, n_b, n_q, n_p, seed):
    """Property: scatter_matvec puts −(M_a pv) at A's parametric entries, M_b pv at b's rows (zeros elsewhere), M_q pv
    in q and the last row as d, the very floats of scipy's mat-vecs."""
    rng = np.random.default_rng(seed)
    maps = [sp.random(rows, n_p + 1, density=0.5, format="csr", random_state=rng) for rows in (n_a, n_b, n_q + 1)]
    stacked = sp.vstack(maps, format="csr")
    pv = rng.normal(size=n_p + 1)
    a_par = rng.choice(3 * n_a, size=n_a, replace=False)
    b_rows = rng.choice(n_b + 3, size=n_b, replace=False)
    a_values, b, q = np.full(3 * n_a, 7.0), np.full(n_b + 3, np.nan), np.empty(n_q)
    d = compiled_rows.scatter_matvec(stacked.indptr.astype(np.int64), stacked.indices.astype(np.int64),
                                     stacked.data, pv, a_values, a_par, b, b_rows, q)
    np.testing.assert_array_equal(a_values[a_par], -(maps[0] @ pv))
    assert np.all(np.delete(a_values, a_par) == 7.0)
    b_ref = np.zeros(n_b + 3)
    b_ref[b_rows] = maps[1] @ pv
    np.testing.assert_array_equal(b, b_ref)
    qd = maps[2] @ pv
    np.testing.assert_array_equal(q, qd[:n_q])
    assert d == qd[n_q]


def _violations(plan, obstacles, workspace):
    s, inputs, dt = plan
    ref = s[:, :3] + np.array([1.0, -0.5, 0.3])
    e = compiled_arcs.error_coordinates(s, ref, 1e-9)
    bounds = np.array([0.5, 2.0, 0.3, 0.4, 0.2])
    v_min, v_max = np.array([-0.3, -0.3, -0.5]), np.array([0.3, 0.3, 0.5])
    return (s, inputs, e, obstacles, dt, bounds, workspace, v_min, v_max)


@given(plans(), st.integers(0, 3), st.booleans(), st.data())
def test_the_violations_are_the_replaced_numpys(plan, k, walls, data):
    """Property: violation_rows gives numpy's per-node violations (a few ulps: einsum's order for the distances),
    and its input and dynamics violations exactly; all of them >= 0."""
    obstacles = np.column_stack([data.draw(hnp.arrays(float, (k, 3), elements=st.floats(-6.0, 6.0))),
                                 data.draw(hnp.arrays(float, k, elements=st.floats(0.1, 1.0)))])
    workspace = np.array([[-4.0, -4.0, -1.0], [4.0, 4.0, 1.0]]) if walls else np.zeros((0, 3))
    args = _violations(plan, obstacles, workspace)
    viol, inp, dyn = compiled_rows.violation_rows(*args)
    viol_ref, inp_ref, dyn_ref = BENCH.numpy_violation_rows(*args)
    np.testing.assert_array_max_ulp(viol, viol_ref, maxulp=EINSUM_ULPS)
    assert (inp, dyn) == (inp_ref, dyn_ref)
    assert np.all(viol >= 0.0) and inp >= 0.0 and dyn >= 0.0


def test_a_nan_in_a_plan_reaches_the_violations_as_numpy_passed_it_on():
    """A NaN state makes the per-node and dynamics violations NaN (np.maximum's rule) and a NaN input leaves the
    input violation 0 (Python's max(0.0, nan), as the replaced code): evaluate's finiteness check still sees it."""
    s = compiled_arcs.rollout(np.zeros(4), np.full((4, 3), 0.1), 0.1)
    s[2, 0] = np.nan
    inputs = np.full((4, 3), 0.1)
    inputs[3, 2] = np.nan
    args = _violations((s, inputs, 0.1), np.array([[1.0, 1.0, 0.0, 0.3]]), np.array([[-4.0, -4, -1], [4, 4, 1]]))
    viol, inp, dyn = compiled_rows.violation_rows(*args)
    viol_ref, inp_ref, dyn_ref = BENCH.numpy_violation_rows(*args)
    assert np.isnan(viol[:, 1]).all() and not np.isnan(viol[:, 0]).any()
    np.testing.assert_array_equal(np.isnan(viol), np.isnan(viol_ref))
    assert inp == inp_ref == 0.0
    assert math.isnan(dyn) and math.isnan(dyn_ref)


@given(plans(), st.integers(0, 2), st.floats(-3.0, 3.0), st.booleans(), st.data())
def test_the_fused_rows_write_the_replaced_codes_values_where_it_wrote_them(plan, k, psi0, walls, data):
    """Property: subproblem_rows writes the replaced code's blocks (Jacobian, cost, e_o, state, obstacle and input
    rows; a few ulps where einsum chose the order) at the same positions of the parameter vector, touches no
    other entry, and returns e_o at node 0."""
    s, v, dt = plan
    n = v.shape[0]
    ref = s[:, :3] + data.draw(hnp.arrays(float, (n + 1, 3), elements=st.floats(-2.0, 2.0)))
    centres = data.draw(hnp.arrays(float, (k, 3), elements=st.floats(-4.0, 4.0)))
    radii = np.full(k, 0.4)
    slots = k + 1 if k else 0
    size = (8 + 3 + 4 + 6 + 6) * n + 4 * n * slots
    write_at = np.random.default_rng(n + k).permutation(size + 5)[:size]
    wref, nodes = np.full((3, n), 0.7), np.vstack([np.full(n, 0.4), np.full(n, 3.0), np.full(n, 0.5)])
    z_lo, z_hi = (-1.0, 1.0) if walls else (-math.inf, math.inf)
    args = (write_at, s, v, ref, psi0, dt, wref, nodes, z_lo, z_hi, centres, radii, 0.2, slots, 0.3,
            np.array([-0.2, -0.3, -0.5]), np.array([0.4, 0.3, 0.5]), 1e-9)
    pv, pv_ref = np.full(size + 5, 9.0), np.full(size + 5, 9.0)
    eo0 = compiled_rows.subproblem_rows(pv, *args)
    eo0_ref = BENCH.numpy_subproblem_rows(pv_ref, *args)
    np.testing.assert_array_max_ulp(pv, pv_ref, maxulp=EINSUM_ULPS)
    untouched = np.setdiff1d(np.arange(size + 5), write_at)
    assert np.all(pv[untouched] == 9.0)
    assert eo0 == eo0_ref == compiled_arcs.error_coordinates(s[:1], ref[:1], 1e-9)[0, 2]
