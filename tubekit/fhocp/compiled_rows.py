"""The real-time step's row numerics as compiled routines (numba): the SCP subproblem's state, obstacle, input and
cost rows, its data's mat-vecs, and the plan's violations.

Each routine performs the floating-point operations of the numpy code it replaced in the same order (no fast-math,
no reassociation), so its results are bit for bit that code's (``tests/test_fhocp_compiled_rows.py`` checks each
against its numpy reference, kept in ``benchmarks/compiled_step.py``):

=========================  ============================================================================
routine                    what it computes
=========================  ============================================================================
:func:`state_rows`         the e_d half-spaces' normals and bounds and the e_z rows at a plan (6, N)
:func:`obstacle_rows`      each obstacle slot's half-space normal and bound per node (M, 4, N)
:func:`input_bounds`       the input box intersected with the trust region (6, N)
:func:`cost_rows`          the cost's linear block (3, N) and the e_o model's rows (4, N)
:func:`subproblem_rows`    all of the above and the step's Jacobian, written into the parameter vector at once
:func:`scatter_matvec`     one CSR mat-vec of the stacked parameter maps, scattered into A's values, b, q, d
:func:`violation_rows`     the per-node violations (4, N), the input box's and the dynamics' violations
=========================  ============================================================================

Importing this module imports numba; the FHOCP imports it when it builds its first subproblem (``tubekit certify``
loads no numba). The machine code is cached (:func:`tubekit.model.jit.routine`).
"""

from __future__ import annotations

import math

import numpy as np

from tubekit.model.compiled_arcs import eo_linearisation, step_linearisation, unicycle_steps
from tubekit.model.jit import routine

__all__ = ["state_rows", "obstacle_rows", "input_bounds", "cost_rows", "subproblem_rows", "scatter_matvec",
           "violation_rows"]

#: e_d below this (m) has no direction: the rows use the direction behind the heading
_TINY = 1e-9


@routine
def _maximum(a: float, b: float) -> float:
    """``np.maximum(a, b)``: a NaN in either gives NaN (``a`` when both are)."""
    return a if (a >= b or a != a) else b


@routine
def _minimum(a: float, b: float) -> float:
    """``np.minimum(a, b)``: a NaN in either gives NaN (``a`` when both are)."""
    return a if (a <= b or a != a) else b


@routine
def _dot3(a0: float, a1: float, a2: float, b0: float, b1: float, b2: float) -> float:
    """a'b of two 3-vectors summed as numpy's ``einsum`` sums three products here, (a0 b0 + a2 b2) + a1 b1 (its
    two-lane loop; an implementation detail of numpy, which the tests allow a few ulps of)."""
    return (a0 * b0 + a2 * b2) + a1 * b1


@routine
def state_rows(s: np.ndarray, r1: np.ndarray, e_d_lo: np.ndarray, e_d_hi: np.ndarray, e_z: np.ndarray,
               z_lo: float, z_hi: float) -> np.ndarray:
    """Rows (6, N): the unit error direction (n_x, n_y) at nodes 1..N, n'p_d + e_d_lo, n'p_d + e_d_hi and
    p_d,z ∓ e_z clamped to [z_lo, z_hi] (m; ±inf without a workspace).

    ``s`` (N+1, 4) is the plan and ``r1`` (N, 3) p_d at nodes 1..N, both relative to the measured position. Where
    any node's e_d is below 1e-9 m that node uses the direction behind its heading (as the code it replaced).
    """
    n = r1.shape[0]
    ex = np.empty(n)
    ey = np.empty(n)
    ed = np.empty(n)
    tiny = False
    for k in range(n):
        ex[k] = s[k + 1, 0] - r1[k, 0]
        ey[k] = s[k + 1, 1] - r1[k, 1]
        ed[k] = math.sqrt(ex[k] * ex[k] + ey[k] * ey[k])
        tiny = tiny or ed[k] < _TINY
    if tiny:
        for k in range(n):
            if ed[k] < _TINY:
                ex[k] = -math.cos(s[k + 1, 3])
                ey[k] = -math.sin(s[k + 1, 3])
            ed[k] = math.sqrt(ex[k] * ex[k] + ey[k] * ey[k])
    st = np.empty((6, n))
    for k in range(n):
        nx = ex[k] / ed[k]
        ny = ey[k] / ed[k]
        npd = nx * r1[k, 0] + ny * r1[k, 1]
        st[0, k], st[1, k] = nx, ny
        st[2, k] = e_d_lo[k] + npd
        st[3, k] = e_d_hi[k] + npd
        st[4, k] = _maximum(r1[k, 2] - e_z[k], z_lo)
        st[5, k] = _minimum(r1[k, 2] + e_z[k], z_hi)
    return st


@routine
def obstacle_rows(s: np.ndarray, centres: np.ndarray, radii: np.ndarray, clearance: float, slots: int) -> np.ndarray:
    """Rows (slots, 4, N): per obstacle the unit direction n from its centre to each node 1..N and the bound
    r + clearance + n'c of n'p >= bound; empty slots 0 >= -1.

    ``centres`` (K, 3) are relative to the measured position, as the plan ``s`` (N+1, 4). Where any node is within
    1e-9 m of a centre, that node's direction is (0, 0, 1) (as the code it replaced).
    """
    n = s.shape[0] - 1
    k_obs = centres.shape[0]
    ob = np.zeros((slots, 4, n))
    for j in range(slots):
        for k in range(n):
            ob[j, 3, k] = -1.0
    d = np.empty((k_obs, n, 3))
    dist = np.empty((k_obs, n))
    tiny = False
    for j in range(k_obs):
        for k in range(n):
            for c in range(3):
                d[j, k, c] = s[k + 1, c] - centres[j, c]
            dist[j, k] = math.sqrt(_dot3(d[j, k, 0], d[j, k, 1], d[j, k, 2], d[j, k, 0], d[j, k, 1], d[j, k, 2]))
            tiny = tiny or dist[j, k] < _TINY
    for j in range(k_obs):
        for k in range(n):
            if tiny and dist[j, k] < _TINY:
                d[j, k, 0], d[j, k, 1], d[j, k, 2] = 0.0, 0.0, 1.0
                dist[j, k] = 1.0
            n0 = d[j, k, 0] / dist[j, k]
            n1 = d[j, k, 1] / dist[j, k]
            n2 = d[j, k, 2] / dist[j, k]
            ob[j, 0, k], ob[j, 1, k], ob[j, 2, k] = n0, n1, n2
            ob[j, 3, k] = radii[j] + clearance + _dot3(n0, n1, n2, centres[j, 0], centres[j, 1], centres[j, 2])
    return ob


@routine
def input_bounds(v: np.ndarray, radius: float, v_min: np.ndarray, v_max: np.ndarray) -> np.ndarray:
    """Rows (6, N): lower and upper bound of u, w, r in turn, [v_min, v_max] ∩ |v_new − v| <= radius v_max."""
    n = v.shape[0]
    bd = np.empty((6, n))
    for c in range(3):
        reach = radius * v_max[c]
        for k in range(n):
            bd[2 * c, k] = _maximum(v_min[c], v[k, c] - reach)
            bd[2 * c + 1, k] = _minimum(v_max[c], v[k, c] + reach)
    return bd


@routine
def cost_rows(wref: np.ndarray, r1: np.ndarray, eo_all: np.ndarray, psi0: float) -> tuple[np.ndarray, np.ndarray]:
    """The cost's linear block −2 W p_d (3, N) and the e_o model's rows gx, gy, gψ, h (4, N) at nodes 1..N with
    h shifted for the heading variable ψ − ψ_0 (``eo_all`` (5, N+1) from the bearing error's model)."""
    n = r1.shape[0]
    blk = np.empty((3, n))
    eo = np.empty((4, n))
    for c in range(3):
        for k in range(n):
            blk[c, k] = (-2.0 * wref[c, k]) * r1[k, c]
    for row in range(4):
        for k in range(n):
            eo[row, k] = eo_all[row, k + 1]
    for k in range(n):
        eo[3, k] = eo[3, k] + eo[2, k] * psi0
    return blk, eo


@routine
def subproblem_rows(pv: np.ndarray, write_at: np.ndarray, s: np.ndarray, v: np.ndarray, ref: np.ndarray, psi0: float,
                    dt: float, wref: np.ndarray, nodes: np.ndarray, z_lo: float, z_hi: float, centres: np.ndarray,
                    radii: np.ndarray, clearance: float, slots: int, radius: float, v_min: np.ndarray,
                    v_max: np.ndarray, floor: float) -> float:
    """The subproblem's rows at the plan (s, v) (relative to the measured position, ``ref`` (N+1, 3) likewise),
    written into ``pv`` at ``write_at``, in this order: the step's Jacobian (8, N) with its offsets shifted for
    ψ − ψ_0, :func:`cost_rows`, :func:`state_rows` (``nodes`` (3, N): e_d_lo, e_d_hi, e_z), :func:`obstacle_rows`
    (none without slots), :func:`input_bounds`, each C-ordered. Returns e_o at node 0 (the cost's constant term)."""
    n = v.shape[0]
    dyn = step_linearisation(s, v, dt)
    for k in range(n):
        dyn[3, k] = dyn[3, k] + dyn[0, k] * psi0
        dyn[7, k] = dyn[7, k] + dyn[4, k] * psi0
    eo_all = eo_linearisation(s, ref, floor)
    r1 = ref[1:]
    blk, eo = cost_rows(wref, r1, eo_all, psi0)
    at = _write(pv, write_at, 0, dyn.ravel())
    at = _write(pv, write_at, at, blk.ravel())
    at = _write(pv, write_at, at, eo.ravel())
    at = _write(pv, write_at, at, state_rows(s, r1, nodes[0], nodes[1], nodes[2], z_lo, z_hi).ravel())
    if slots:
        at = _write(pv, write_at, at, obstacle_rows(s, centres, radii, clearance, slots).ravel())
    _write(pv, write_at, at, input_bounds(v, radius, v_min, v_max).ravel())
    return eo_all[4, 0]


@routine
def _write(pv: np.ndarray, write_at: np.ndarray, start: int, values: np.ndarray) -> int:
    """pv[write_at[start + i]] = values[i]; returns the next start."""
    for i in range(values.shape[0]):
        pv[write_at[start + i]] = values[i]
    return start + values.shape[0]


@routine
def scatter_matvec(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, pv: np.ndarray, a_values: np.ndarray,
                   a_par: np.ndarray, b: np.ndarray, b_rows: np.ndarray, q: np.ndarray) -> float:
    """y = M pv for the stacked CSR map M = [A's parametric entries; b's; q with d last], scattered:
    A's values at ``a_par`` get −y, b (zeroed first) at ``b_rows`` its part, q the rest; returns d."""
    n_a = a_par.shape[0]
    n_b = b_rows.shape[0]
    b[:] = 0.0
    for i in range(indptr.shape[0] - 1):
        acc = 0.0
        for jj in range(indptr[i], indptr[i + 1]):
            acc += data[jj] * pv[indices[jj]]
        if i < n_a:
            a_values[a_par[i]] = -acc
        elif i < n_a + n_b:
            b[b_rows[i - n_a]] = acc
        elif i < n_a + n_b + q.shape[0]:
            q[i - n_a - n_b] = acc
        else:
            return acc
    return 0.0


@routine
def violation_rows(states: np.ndarray, inputs: np.ndarray, e: np.ndarray, obstacles: np.ndarray, dt: float,
                   bounds: np.ndarray, workspace: np.ndarray, v_min: np.ndarray,
                   v_max: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Per node 1..N the violations (4, N) of e_d >= e_d_min, the obstacles, |e_o| <= e_o_max and the box
    (e_d <= e_d_max, |e_z| <= e_z_max, the workspace's walls), then the inputs' and the dynamics' largest.

    ``bounds`` = (e_d_min, e_d_max, e_z_max, e_o_max, clearance); ``workspace`` (2, 3) its corners, or (0, 3).
    """
    n = inputs.shape[0]
    e_d_min, e_d_max, e_z_max, e_o_max, clearance = bounds[0], bounds[1], bounds[2], bounds[3], bounds[4]
    viol = np.zeros((4, n))
    for k in range(n):
        viol[0, k] = _maximum(e_d_min - e[k + 1, 0], 0.0)
        if obstacles.shape[0]:
            worst = -np.inf
            for j in range(obstacles.shape[0]):
                dx = states[k + 1, 0] - obstacles[j, 0]
                dy = states[k + 1, 1] - obstacles[j, 1]
                dz = states[k + 1, 2] - obstacles[j, 2]
                worst = _maximum(worst, obstacles[j, 3] + clearance - math.sqrt(_dot3(dx, dy, dz, dx, dy, dz)))
            viol[1, k] = _maximum(worst, 0.0)
        viol[2, k] = _maximum(abs(e[k + 1, 2]) - e_o_max, 0.0)
        box = _maximum(e[k + 1, 0] - e_d_max, abs(e[k + 1, 1]) - e_z_max)
        if workspace.shape[0]:
            wall = -np.inf
            for c in range(3):
                p = states[k + 1, c]
                wall = _maximum(wall, _maximum(workspace[0, c] + clearance - p, p - workspace[1, c] + clearance))
            box = _maximum(box, wall)
        viol[3, k] = _maximum(box, 0.0)
    worst_input = -np.inf
    for k in range(n):
        for c in range(3):
            worst_input = _maximum(worst_input, _maximum(inputs[k, c] - v_max[c], v_min[c] - inputs[k, c]))
    inp = worst_input if worst_input > 0.0 else 0.0  # Python's max(0.0, x): a NaN gives 0.0, as it did
    steps = unicycle_steps(states[:n], inputs, dt)
    dyn = -np.inf
    for k in range(n):
        for c in range(4):
            dyn = _maximum(dyn, abs(states[k + 1, c] - steps[k, c]))
    return viol, inp, dyn
