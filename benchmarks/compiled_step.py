"""What the compiled rows buy the real-time step: the numba routines of :mod:`tubekit.fhocp.compiled_rows` against
the numpy code they replaced, alternated in one process.

Usage::

    python benchmarks/compiled_step.py [--duration 100] [--rounds 3] [--backends clarabel qocogen] [--logs]
                                       [--json FILE]

The numpy functions below are the code the routines replaced (the subproblem's row writes and data mat-vecs and the
plan's violations, as they were in commit 5cded9e), with the routines' signatures; :func:`numpy_rows` puts them in
the routines' place (every caller looks them up at the call). ``tests/test_fhocp_compiled_rows.py`` checks each
routine against its reference here, float for float.

Reported per round and backend: the median real-time step alone along the closed loop's states (``benchmarks/
qp_backends.py --steps``'s loop: one method at a time, its caches warm) and the median step of benchmark v2's round
robin (every method at every state in turn, the order rotated), each side alternated, and whether both sides' last
plans are the very same floats. ``--logs`` also runs 100 s tube runs of Section VI and ``paper_currents`` on each
side and compares every logged array.

A benchmark, not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import math
import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fhocp as v2  # noqa: E402  (the sibling benchmark: its closed loop, methods and replay)
from compiled_period import swapped  # noqa: E402  (the sibling benchmark's attribute swap)

from tubekit import paper_scenario  # noqa: E402
from tubekit.fhocp import compiled_rows  # noqa: E402
from tubekit.model import compiled_arcs  # noqa: E402

__all__ = ["numpy_state_rows", "numpy_obstacle_rows", "numpy_input_bounds", "numpy_cost_rows", "numpy_subproblem_rows",
           "numpy_scatter_matvec", "numpy_violation_rows", "NUMPY", "numpy_rows", "measure", "compare_logs", "main"]


def numpy_state_rows(s: np.ndarray, r1: np.ndarray, e_d_lo: np.ndarray, e_d_hi: np.ndarray, e_z: np.ndarray,
                     z_lo: float, z_hi: float) -> np.ndarray:
    """``ConvexSubproblem._write_state_rows``'s numpy rows (6, N) before the routine."""
    n = r1.shape[0]
    ex = s[1:, 0] - r1[:, 0]
    ey = s[1:, 1] - r1[:, 1]
    ed = np.sqrt(ex * ex + ey * ey)
    if ed.min() < 1e-9:
        tiny = ed < 1e-9
        ex = np.where(tiny, -np.cos(s[1:, 3]), ex)
        ey = np.where(tiny, -np.sin(s[1:, 3]), ey)
        ed = np.sqrt(ex * ex + ey * ey)
    st = np.empty((6, n))
    st[0] = ex / ed
    st[1] = ey / ed
    npd = st[0] * r1[:, 0] + st[1] * r1[:, 1]
    st[2] = e_d_lo + npd
    st[3] = e_d_hi + npd
    st[4] = r1[:, 2] - e_z
    st[5] = r1[:, 2] + e_z
    if math.isfinite(z_lo) or math.isfinite(z_hi):
        np.maximum(st[4], z_lo, out=st[4])
        np.minimum(st[5], z_hi, out=st[5])
    return st


def numpy_obstacle_rows(s: np.ndarray, centres: np.ndarray, radii: np.ndarray, clearance: float,
                        slots: int) -> np.ndarray:
    """``ConvexSubproblem._write_obstacles``'s numpy rows (slots, 4, N) before the routine."""
    ob = np.zeros((slots, 4, s.shape[0] - 1))
    ob[:, 3] = -1.0
    k = len(centres)
    if k:
        c = centres
        d = s[None, 1:, :3] - c[:, None, :]
        dist = np.sqrt(np.einsum("jnc,jnc->jn", d, d))
        if dist.min() < 1e-9:
            bad = dist < 1e-9
            d[bad] = (0.0, 0.0, 1.0)
            dist[bad] = 1.0
        n = d / dist[..., None]
        ob[:k, :3] = n.transpose(0, 2, 1)
        ob[:k, 3] = radii[:, None] + clearance + np.einsum("jnc,jc->jn", n, c)
    return ob


def numpy_input_bounds(v: np.ndarray, radius: float, v_min: np.ndarray, v_max: np.ndarray) -> np.ndarray:
    """``ConvexSubproblem._write_input_bounds``'s numpy rows (6, N) before the routine."""
    bd = np.empty((6, v.shape[0]))
    bd[0::2] = np.maximum(v_min, v - radius * v_max).T
    bd[1::2] = np.minimum(v_max, v + radius * v_max).T
    return bd


def numpy_cost_rows(wref: np.ndarray, r1: np.ndarray, eo_all: np.ndarray, psi0: float) -> tuple[np.ndarray, np.ndarray]:
    """``ConvexSubproblem._write_cost_and_eo``'s linear block and e_o rows before the routine."""
    blk = -2.0 * wref * r1.T
    eo = eo_all[:4, 1:].copy()
    eo[3] += eo[2] * psi0
    return blk, eo


def numpy_subproblem_rows(pv: np.ndarray, write_at: np.ndarray, s: np.ndarray, v: np.ndarray, ref: np.ndarray,
                          psi0: float, dt: float, wref: np.ndarray, nodes: np.ndarray, z_lo: float, z_hi: float,
                          centres: np.ndarray, radii: np.ndarray, clearance: float, slots: int, radius: float,
                          v_min: np.ndarray, v_max: np.ndarray, floor: float) -> float:
    """``ConvexSubproblem.linearise``'s numpy row writes before the routine (the Jacobian and the e_o model from
    :mod:`tubekit.model.compiled_arcs`, as then)."""
    dyn = compiled_arcs.step_linearisation(s, v, dt)
    dyn[3] += dyn[0] * psi0
    dyn[7] += dyn[4] * psi0
    eo_all = compiled_arcs.eo_linearisation(s, ref, floor)
    blk, eo = numpy_cost_rows(wref, ref[1:], eo_all.copy(), psi0)
    blocks = [dyn.ravel(), blk.ravel(), eo.ravel(),
              numpy_state_rows(s, ref[1:], nodes[0], nodes[1], nodes[2], z_lo, z_hi).ravel()]
    if slots:
        blocks.append(numpy_obstacle_rows(s, centres, radii, clearance, slots).ravel())
    blocks.append(numpy_input_bounds(v, radius, v_min, v_max).ravel())
    start = 0
    for block in blocks:  # one write per parameter group, as the replaced code
        pv[write_at[start:start + block.size]] = block
        start += block.size
    return float(eo_all[4, 0])


_SPLIT: dict[tuple[int, int, int], tuple] = {}


def numpy_scatter_matvec(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, pv: np.ndarray,
                         a_values: np.ndarray, a_par: np.ndarray, b: np.ndarray, b_rows: np.ndarray,
                         q: np.ndarray) -> float:
    """``CompiledConeProgram._vectors``' three scipy mat-vecs before the routine, on the stacked map's blocks (split
    once per map, as the replaced code held them)."""
    n_a, n_b = len(a_par), len(b_rows)
    key = (id(data), n_a, n_b)
    if key not in _SPLIT:
        m = sp.csr_matrix((data, indices, indptr), shape=(len(indptr) - 1, len(pv)))
        _SPLIT[key] = (m[:n_a], m[n_a:n_a + n_b], m[n_a + n_b:], data)  # data kept: its id stays its own
    m_a, m_b, m_q, _ = _SPLIT[key]
    a_values[a_par] = -(m_a @ pv)
    b[:] = 0.0
    b[b_rows] = m_b @ pv
    qd = m_q @ pv
    q[:] = qd[:len(q)]
    return float(qd[len(q)])


def numpy_violation_rows(states: np.ndarray, inputs: np.ndarray, e: np.ndarray, obstacles: np.ndarray, dt: float,
                         bounds: np.ndarray, workspace: np.ndarray, v_min: np.ndarray,
                         v_max: np.ndarray) -> tuple[np.ndarray, float, float]:
    """``FhocpNlp.evaluate``'s numpy violations before the routine."""
    e_d_min, e_d_max, e_z_max, e_o_max, clearance = bounds
    n = inputs.shape[0]
    viol = np.zeros((4, n))
    e1 = e[1:]
    np.maximum(e_d_min - e1[:, 0], 0.0, out=viol[0])
    if len(obstacles):
        diff = states[1:, None, :3] - obstacles[None, :, :3]
        dist = np.sqrt(np.einsum("kjc,kjc->kj", diff, diff))
        np.maximum((obstacles[:, 3] + clearance - dist).max(axis=1), 0.0, out=viol[1])
    np.maximum(np.abs(e1[:, 2]) - e_o_max, 0.0, out=viol[2])
    box = np.maximum(e1[:, 0] - e_d_max, np.abs(e1[:, 1]) - e_z_max)
    if len(workspace):
        p1 = states[1:, :3]
        wall = np.maximum(workspace[0] + clearance - p1, p1 - workspace[1] + clearance)
        box = np.maximum(box, wall.max(axis=1))
    np.maximum(box, 0.0, out=viol[3])
    inp = max(0.0, float(np.maximum(inputs - v_max, v_min - inputs).max()))
    dyn = float(np.abs(states[1:] - compiled_arcs.unicycle_steps(states[:-1], inputs, dt)).max())
    return viol, inp, dyn


#: the routines of :mod:`tubekit.fhocp.compiled_rows` the step calls and the numpy code each replaced (the row
#: routines inside ``subproblem_rows`` are swapped with it: its reference is made of theirs)
NUMPY = {"subproblem_rows": numpy_subproblem_rows, "scatter_matvec": numpy_scatter_matvec,
         "violation_rows": numpy_violation_rows}


def numpy_rows() -> contextlib.AbstractContextManager:
    """The numpy functions in the compiled routines' place (every caller looks them up at the call)."""
    return swapped(compiled_rows, NUMPY)


def measure(duration: float = 100.0, rounds: int = 3, backends: tuple[str, ...] = ("clarabel", "qocogen")) -> dict:
    """Alternate the two sides ``rounds`` times each; a JSON-ready dict (module doc)."""
    sc = paper_scenario()
    tg = v2.benchmark_tightening(sc)
    states = v2.closed_loop(sc, tg, duration, v2.DEFAULT_RATE_PENALTY)
    opt_in = tuple(b for b in backends if b != "clarabel")
    keys = {b: "scp_realtime" if b == "clarabel" else v2.OPT_IN[b][0] for b in backends}
    out: dict = {"states": len(states), "rounds": []}
    last: dict[str, dict[str, np.ndarray]] = {}
    for k in range(2 * rounds):
        side = ("compiled", "numpy")[(k + k // 2) % 2]  # compiled, numpy, numpy, compiled, ...
        row: dict = {"side": side}
        with numpy_rows() if side == "numpy" else contextlib.nullcontext():
            for b in backends:
                ctrl = v2.make_methods(sc, tg, with_casadi=False, opt_in=opt_in)[keys[b]][0]
                row[f"{b}_alone_ms"] = v2.median_step_alone(ctrl, states)
                last.setdefault(side, {})[b] = ctrl.plan_inputs
            methods = {name: m for name, m in v2.make_methods(sc, tg, with_casadi=False, opt_in=opt_in).items()
                       if name in keys.values()}
            gc.disable()
            try:
                rec = v2.replay(methods, states)
            finally:
                gc.enable()
            for b in backends:
                row[f"{b}_round_robin_ms"] = float(1e3 * np.median(rec[keys[b]]["step"]))
        out["rounds"].append(row)
    for b in backends:
        for what in ("alone", "round_robin"):
            for side in ("compiled", "numpy"):
                out[f"{b}_{what}_{side}_ms"] = float(np.median([r[f"{b}_{what}_ms"] for r in out["rounds"]
                                                                if r["side"] == side]))
        out[f"{b}_same_last_plan"] = bool(np.array_equal(last["compiled"][b], last["numpy"][b]))
    return out


def compare_logs(duration: float = 100.0) -> dict:
    """Tube runs of Section VI and ``paper_currents`` on both sides: per scenario the logged arrays compared and
    the names of those that differ."""
    import verify  # noqa: PLC0415  (a benchmark joins tubekit and verify as the app does)
    from tubekit import load_scenario  # noqa: PLC0415
    from tubekit.loop.closed_loop import run_closed_loop  # noqa: PLC0415

    root = Path(__file__).resolve().parents[1]
    scenarios = {"section_vi": paper_scenario(), "paper_currents": load_scenario(root / "verify" / "scenarios"
                                                                                 / "paper_currents.toml")}
    fields = ("states", "v_hat", "inputs", "rejected", "plan_slack", "nominal")
    out = {}
    for name, sc in scenarios.items():
        sc = sc.with_changes(duration=float(duration))
        tightening = verify.certify(sc, law=sc.controller.law).best_effort_tightening()
        runs = {}
        for side in ("compiled", "numpy"):
            with numpy_rows() if side == "numpy" else contextlib.nullcontext():
                runs[side] = run_closed_loop(sc, tightening, tube=True, progress=False)
        out[name] = {"compared": list(fields),
                     "differ": [f for f in fields if not np.array_equal(getattr(runs["compiled"], f),
                                                                        getattr(runs["numpy"], f), equal_nan=True)]}
    return out


def main(argv: list[str] | None = None) -> int:
    """CLI entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=100.0, help="closed-loop seconds (one state per period)")
    parser.add_argument("--rounds", type=int, default=3, help="rounds per side, alternated (default 3)")
    parser.add_argument("--backends", nargs="*", default=["clarabel", "qocogen"], help="QP backends (default both)")
    parser.add_argument("--logs", action="store_true", help="also compare 100 s tube runs' logs (module doc)")
    parser.add_argument("--json", default=None, help="write the figures to this file")
    args = parser.parse_args(argv)
    out = measure(args.duration, args.rounds, tuple(args.backends))
    for r in out["rounds"]:
        print("  ".join(f"{k} {v:.3f}" if isinstance(v, float) else f"{v:9s}" for k, v in r.items()), flush=True)
    if args.logs:
        out["logs"] = compare_logs()
    print(json.dumps({k: v for k, v in out.items() if k != "rounds"}, indent=2))
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
